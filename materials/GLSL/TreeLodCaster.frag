#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodShadowCaster.glsl"
// Shadow caster; ALPHA_TEST: leaves cast the shadow of their texture's shape.
#ifdef ALPHA_TEST
uniform sampler2D diffuseMap;
uniform float alphaCutoff;
uniform float alphaMaxLod;
#include "TreeLodLeafAlpha.glsl"
#endif

in vec2 vClipZW;
in vec2 vUv;

out vec4 fragColour;

void main()
{
#ifdef ALPHA_TEST
    if (leafAlpha(diffuseMap, vUv, alphaMaxLod) < alphaCutoff)
        discard;
#endif
    // The shadow camera's window depth, 0..1 (shadow textures clear to 1); the receiver computes
    // the same from texture_viewproj_matrix.
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
}
