#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// Shadow caster: passes clip-space z and w on; the fragment stage writes depth in 0..1.
// INSTANCED: placed by the Forest's instance data first (TreeLodInstance.glsl). Moved by the wind
// as the lit programs move the tree (TreeLodWind.glsl).
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 inverseWorld;
uniform float windLeaf; // 1 in the leaf materials: the leaves flutter (TreeLodWind.glsl)
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif
#include "TreeLodWind.glsl"

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec2 uv0, TEXCOORD0)
#ifdef INSTANCED
    INSTANCE_IN
#endif
    OUT(vec2 vClipZW, TEXCOORD0)
    OUT(vec2 vUv, TEXCOORD1)
    TRANSITION_OUT(TEXCOORD2)
MAIN_DECLARATION
{
#ifdef INSTANCED
    vTransition = transitionOf(uv4, uv5);
#else
    vTransition = NO_TRANSITION;
#endif
#ifdef INSTANCED
    vec4 rest = vec4(vertex.xyz + windInstanceOffset(vertex.xyz, uv4, uv5, world, inverseWorld, windLeaf > 0.5), 1.0);
    gl_Position = mul(worldViewProj, instancePosition(uv4, uv5, rest));
#else
    gl_Position = mul(worldViewProj, vec4(vertex.xyz + windObjectOffset(vertex.xyz, world, inverseWorld, windLeaf > 0.5), 1.0));
#endif
    vClipZW = gl_Position.zw;
    vUv = uv0;
}
