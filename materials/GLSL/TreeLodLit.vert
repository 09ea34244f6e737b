#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// Lit tree surfaces (bark and leaves): world-space normal and UV to the fragment stage;
// SHADOW_RECEIVER: also the position in the sun's shadow texture. AO: the vertex colour's red
// channel (ambient occlusion) to the fragment stage. INSTANCED: placed by the Forest's
// instance data first (TreeLodInstance.glsl).
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
#include "TreeLodShadowReceiver.glsl"
#endif
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif

void main()
{
#ifdef INSTANCED
    vec4 position = instancePosition(vertex);
    vec3 objectNormal = instanceDirection(normal);
#else
    vec4 position = vertex;
    vec3 objectNormal = normal;
#endif
    gl_Position = worldViewProj * position;
    vNormal = mat3(normalMatrix) * objectNormal;
    vToCamera = cameraPosition.xyz - (world * position).xyz;
    vUv = uv0;
#ifdef AO
    vAo = colour.r;
#endif
#ifdef SHADOW_RECEIVER
    passShadowPositions(world * position);
#endif
}
