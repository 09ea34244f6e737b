#version 330 core
// Lit tree surfaces (bark and leaves): world-space normal and UV to the fragment stage;
// SHADOW_RECEIVER: also the position in the sun's shadow texture. AO: the vertex colour's red
// channel (ambient occlusion) to the fragment stage.
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 normalMatrix;
uniform vec4 cameraPosition;

in vec4 vertex;
in vec3 normal;
in vec2 uv0;

out vec3 vNormal;
out vec3 vToCamera;
out vec2 vUv;
#ifdef AO
in vec4 colour;
out float vAo;
#endif
#ifdef SHADOW_RECEIVER
uniform mat4 texViewProj; // the sun's shadow camera, clip space to texture space
out vec4 vShadowPos;
#endif

void main()
{
    gl_Position = worldViewProj * vertex;
    vNormal = mat3(normalMatrix) * normal;
    vToCamera = cameraPosition.xyz - (world * vertex).xyz;
    vUv = uv0;
#ifdef AO
    vAo = colour.r;
#endif
#ifdef SHADOW_RECEIVER
    vShadowPos = texViewProj * (world * vertex);
#endif
}
