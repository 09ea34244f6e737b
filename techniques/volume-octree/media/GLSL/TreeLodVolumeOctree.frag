#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
#ifdef CASTER
#include "TreeLodShadowCaster.glsl"
#endif
// The volumetric octree tree's billboard (TreeLodVolumeOctree.vert): the two input cameras'
// codewords sampled bilinearly inside their 4x4 blocks, premultiplied and weighted, for the over
// operator (scene_blend one one_minus_src_alpha). Colour is sRGB as stored; the framebuffer holds
// sRGB, so blending happens there as in renderVolumeOctree (VolumeOctreeBaker.h).
// CASTER: a depth caster has no blending, so each texel casts or not by a hashed threshold of its
// cell and texel: a light ray through cells of alphas a_i is blocked with probability
// 1 - prod(1 - a_i), the light camera's matte (the reconstruction's opacity, §2.1). Writes the
// shadow camera's window depth, as TreeLodCaster.frag.
SAMPLER2D(codebook, 0);
uniform vec4 octree;      // cameras, slot texture width, atlas blocks a row, atlas width
uniform float atlasHeight;

vec4 premultiplied(vec2 colourBlock, vec2 alphaBlock, vec2 texel)
{
    vec2 size = vec2(octree.w, atlasHeight);
    vec3 colour = TEX2D(codebook, (colourBlock + texel) / size).rgb;
    float alpha = TEX2D(codebook, (alphaBlock + texel) / size).a;
    return vec4(colour * alpha, alpha);
}

#ifdef CASTER
// A hash of two integers to [0, 1) (a 32-bit integer mix, Wang-style).
float hash01(uint a, uint b)
{
    uint h = a * 0x9E3779B9u ^ (b + 0x7F4A7C15u + (a << 6) + (a >> 2));
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    h *= 0xC2B2AE35u;
    h ^= h >> 16;
    return float(h >> 8) / 16777216.0;
}
#endif

MAIN_PARAMETERS
    IN(vec2 vTexel, TEXCOORD0)
    FLAT_IN(vec4 vColourBlocks, TEXCOORD1)
    FLAT_IN(vec4 vAlphaBlocks, TEXCOORD2)
    FLAT_IN(vec2 vWeights, TEXCOORD3)
#ifdef CASTER
    IN(vec2 vClipZW, TEXCOORD4)
    FLAT_IN(float vCell, TEXCOORD5)
#endif
    TRANSITION_IN(TEXCOORD6)
MAIN_DECLARATION
{
    vec2 texel = clamp(vTexel, vec2_splat(0.5), vec2_splat(3.5));
    vec4 colour = vWeights.x * premultiplied(vColourBlocks.xy, vAlphaBlocks.xy, texel) +
                  vWeights.y * premultiplied(vColourBlocks.zw, vAlphaBlocks.zw, texel);
#ifdef CASTER
    ivec2 cell = ivec2(clamp(floor(vTexel), vec2_splat(0.0), vec2_splat(3.0)));
    if (colour.a <= hash01(uint(vCell + 0.5), uint(cell.y * 4 + cell.x)))
        discard;
    TRANSITION_DISCARD
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
#else
    if (colour.a < 0.5 / 255.0)
        discard;
    TRANSITION_DISCARD
    fragColour = colour;
#endif
}
