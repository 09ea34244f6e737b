#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// Lit tree surfaces (bark and leaves): world-space normal and UV to the fragment stage;
// SHADOW_RECEIVER: also the position in the sun's shadow texture. AO: the vertex colour's red
// channel (ambient occlusion) to the fragment stage. INSTANCED: placed by the Forest's
// instance data first (TreeLodInstance.glsl). Every vertex moves with the wind (TreeLodWind.glsl).
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 inverseWorld;
uniform float windLeaf; // 1 in the leaf materials: the leaves flutter (TreeLodWind.glsl)
uniform mat4 normalMatrix;
uniform vec4 cameraPosition;
#ifdef SHADOW_RECEIVER
#include "TreeLodShadowReceiver.glsl"
#endif
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif
#include "TreeLodWind.glsl"

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec3 normal, NORMAL)
    IN(vec2 uv0, TEXCOORD0)
#ifdef AO
    IN(vec4 colour, COLOR)
#endif
#ifdef INSTANCED
    INSTANCE_IN
#endif
    OUT(vec3 vNormal, TEXCOORD0)
    OUT(vec3 vToCamera, TEXCOORD1)
    OUT(vec2 vUv, TEXCOORD2)
#ifdef AO
    OUT(float vAo, TEXCOORD3)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_OUT(TEXCOORD4, TEXCOORD5, TEXCOORD6)
#endif
    TRANSITION_OUT(TEXCOORD7)
MAIN_DECLARATION
{
#ifdef INSTANCED
    vTransition = transitionOf(uv4, uv5);
#else
    vTransition = NO_TRANSITION;
#endif
#ifdef INSTANCED
    vec4 rest = vec4(vertex.xyz + windInstanceOffset(vertex.xyz, uv4, uv5, world, inverseWorld, windLeaf > 0.5), 1.0);
    vec4 position = instancePosition(uv4, uv5, rest);
    vec3 objectNormal = instanceDirection(uv5, normal);
#else
    vec4 position = vec4(vertex.xyz + windObjectOffset(vertex.xyz, world, inverseWorld, windLeaf > 0.5), 1.0);
    vec3 objectNormal = normal;
#endif
    gl_Position = mul(worldViewProj, position);
    vNormal = mul(toMat3(normalMatrix), objectNormal);
    vToCamera = cameraPosition.xyz - mul(world, position).xyz;
    vUv = uv0;
#ifdef AO
    vAo = colour.r;
#endif
#ifdef SHADOW_RECEIVER
    passShadowPositions(mul(world, position));
#endif
}
