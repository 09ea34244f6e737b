#version 330 core
// Billboard cloud quads (paper 000 §4.2, §6; vertex layout in TreeLod/TreeAsset.h,
// BillboardCloudGpu): the billboard frame in world space, its (u, v), hash rectangle and
// low-res rectangle to the fragment stage.
// CASTER: the shadow camera's clip z and w, and the direction towards the light (the shadow
// camera's view +z, a directional light) instead of the camera.
// SHADOW_RECEIVER: the position in the sun's shadow texture.
uniform mat4 worldViewProj;
uniform mat4 world;
#ifdef CASTER
uniform mat4 view;
out vec2 vClipZW;
#else
uniform mat4 normalMatrix;
uniform vec4 cameraPosition;
#endif
#ifdef SHADOW_RECEIVER
uniform mat4 texViewProj; // the sun's shadow camera, clip space to texture space
out vec4 vShadowPos;
#endif

in vec4 vertex;
in vec3 normal;
in vec3 tangent;
in vec2 uv0;
in vec4 uv1;
in vec4 uv2;

out vec2 vUv;
out vec2 vLowResUv;
flat out vec4 vHash;
out vec3 vNormal;
out vec3 vTangent;
out vec3 vToCamera;

void main()
{
    gl_Position = worldViewProj * vertex;
    vec3 position = (world * vertex).xyz;
#ifdef CASTER
    vClipZW = gl_Position.zw;
    vNormal = mat3(world) * normal;
    vToCamera = vec3(view[0][2], view[1][2], view[2][2]);
#else
    vNormal = mat3(normalMatrix) * normal;
    vToCamera = cameraPosition.xyz - position;
#endif
    vTangent = mat3(world) * tangent;
    vUv = uv0;
    vHash = uv1;
    vLowResUv = mix(uv2.xy, uv2.zw, uv0);
#ifdef SHADOW_RECEIVER
    vShadowPos = texViewProj * vec4(position, 1.0);
#endif
}
