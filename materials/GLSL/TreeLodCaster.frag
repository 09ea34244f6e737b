#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
#include "TreeLodShadowCaster.glsl"
// Shadow caster; ALPHA_TEST: leaves cast the shadow of their texture's shape.
#ifdef ALPHA_TEST
SAMPLER2D(diffuseMap, 0);
uniform float alphaCutoff;
uniform float alphaMaxLod;
#include "TreeLodLeafAlpha.glsl"
#endif

MAIN_PARAMETERS
    IN(vec2 vClipZW, TEXCOORD0)
    IN(vec2 vUv, TEXCOORD1)
    TRANSITION_IN(TEXCOORD2)
MAIN_DECLARATION
{
#ifdef ALPHA_TEST
    if (leafAlpha(SAMPLER2D_ARG(diffuseMap), vUv, alphaMaxLod) < alphaCutoff)
        discard;
#endif
    // The shadow camera's window depth, 0..1 (shadow textures clear to 1); the receiver computes
    // the same from texture_viewproj_matrix.
    TRANSITION_DISCARD
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
}
