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
// INSTANCED: placed by the Forest's instance data first (TreeLodInstance.glsl).
uniform mat4 worldViewProj;
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif

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
    gl_Position = mul(worldViewProj, instancePosition(uv4, uv5, vertex));
#else
    gl_Position = mul(worldViewProj, vertex);
#endif
    vClipZW = gl_Position.zw;
    vUv = uv0;
}
