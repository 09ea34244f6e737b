#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// Billboard cloud quads (García et al. 2007 §4.2, §6; vertex layout in TreeLod/TreeAsset.h,
// BillboardCloudGpu): the billboard frame in world space, its (u, v), hash rectangle and
// low-res rectangle to the fragment stage.
// CASTER: the shadow camera's clip z and w, and the direction towards the light (the shadow
// camera's view +z, a directional light) instead of the camera.
// SHADOW_RECEIVER: the position in the sun's shadow texture.
// INSTANCED: placed by the Forest's instance data first (TreeLodInstance.glsl).
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
#include "TreeLodShadowReceiver.glsl"
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
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif

void main()
{
#ifdef INSTANCED
    vec4 local = instancePosition(vertex);
    vec3 objectNormal = instanceDirection(normal);
    vec3 objectTangent = instanceDirection(tangent);
#else
    vec4 local = vertex;
    vec3 objectNormal = normal;
    vec3 objectTangent = tangent;
#endif
    gl_Position = worldViewProj * local;
    vec3 position = (world * local).xyz;
#ifdef CASTER
    vClipZW = gl_Position.zw;
    vNormal = mat3(world) * objectNormal;
    vToCamera = vec3(view[0][2], view[1][2], view[2][2]);
#else
    vNormal = mat3(normalMatrix) * objectNormal;
    vToCamera = cameraPosition.xyz - position;
#endif
    vTangent = mat3(world) * objectTangent;
    vUv = uv0;
    vHash = uv1;
    vLowResUv = mix(uv2.xy, uv2.zw, uv0);
#ifdef SHADOW_RECEIVER
    passShadowPositions(vec4(position, 1.0));
#endif
}
