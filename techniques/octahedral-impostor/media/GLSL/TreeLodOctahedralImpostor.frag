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
// The octahedral impostor (OctahedralImpostorData.h): the three frames TreeLodOctahedralImpostor.vert
// chose, each read at its frame coordinates shifted by its stored depth (one parallax step), blended
// by the barycentric weights with coverage as the weight of colour, normal and occlusion; alpha
// test on the blended coverage; lit as TreeLodImpostor.frag lights the quad,
//     colour = albedo * srgbScale(ambient * ao + sun * lambert),
// each frame's normal (x, y on the frame's axes, z towards its viewer) against the sun in that
// frame's axes. A frame whose weight is below 1/256 is not read.
// CASTER: coverage only (no parallax: the depth read would cost as much as the colour), writes the
// shadow camera's window depth. SHADOW_RECEIVER: the sun term scaled by the sun's visibility.
SAMPLER2D(colourMap, 0); // sRGB albedo, coverage in alpha
uniform float alphaCutoff;
uniform vec4 atlas;          // frames a side N, frame texels F, margin texels, 0
#ifndef CASTER
SAMPLER2D(normalMap, 1); // normal x, y (n * 0.5 + 0.5), ambient occlusion, depth
uniform vec4 sunColour;
uniform vec4 ambientColour;
#endif

#define SHADOW_UNIT0 2
#define SHADOW_UNIT1 3
#define SHADOW_UNIT2 4
#include "TreeLodShading.glsl"

/// Atlas coordinates of frame coordinates `uv` in frame `cell`, kept inside the frame's margin.
vec2 atlasUv(vec2 cell, vec2 uv)
{
    float inset = 0.5 * atlas.z / atlas.y;
    return (cell + clamp(uv, inset, 1.0 - inset)) / atlas.x;
}

// colourSum: rgb the sum of w a albedo, a the sum of w a; lightSum: sum of w a lambert, of w a ao.
#ifdef CASTER
void addFrame(float w, vec2 cell, vec2 uv, inout vec4 colourSum)
{
    if (w < 1.0 / 256.0)
        return;
    colourSum.a += w * TEX2D(colourMap, atlasUv(cell, uv)).a;
}
#else
void addFrame(float w, vec2 cell, vec2 uv, vec2 parallax, vec3 sun, inout vec4 colourSum, inout vec2 lightSum)
{
    if (w < 1.0 / 256.0)
        return;
    vec4 baked = TEX2D(normalMap, atlasUv(cell, uv));
    vec4 texel = TEX2D(colourMap, atlasUv(cell, uv + (baked.a - 0.5) * parallax));
    float wa = w * texel.a;
    vec2 xy = baked.xy * 2.0 - 1.0;
    xy *= inversesqrt(max(dot(xy, xy), 1.0)); // a filtered normal may leave the unit disc
    vec3 n = vec3(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
    colourSum += vec4(wa * texel.rgb, wa);
    lightSum += wa * vec2(max(dot(n, sun), 0.0), baked.b);
}
#endif

MAIN_PARAMETERS
    IN(vec4 vUv01, TEXCOORD0)
    IN(vec2 vUv2, TEXCOORD1)
    FLAT_IN(vec4 vFrame01, TEXCOORD2)
    FLAT_IN(vec2 vFrame2, TEXCOORD3)
    FLAT_IN(vec3 vWeights, TEXCOORD4)
#ifdef CASTER
    IN(vec2 vClipZW, TEXCOORD5)
#else
    IN(vec3 vSun0, TEXCOORD5)
    IN(vec3 vSun1, TEXCOORD6)
    IN(vec3 vSun2, TEXCOORD7)
    IN(vec4 vParallax01, TEXCOORD8)
    IN(vec2 vParallax2, TEXCOORD9)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_IN(TEXCOORD10, TEXCOORD11, TEXCOORD12)
#endif
    TRANSITION_IN(TEXCOORD13)
MAIN_DECLARATION
{
    vec4 colourSum = vec4_splat(0.0);
#ifdef CASTER
    addFrame(vWeights.x, vFrame01.xy, vUv01.xy, colourSum);
    addFrame(vWeights.y, vFrame01.zw, vUv01.zw, colourSum);
    addFrame(vWeights.z, vFrame2, vUv2, colourSum);
    if (colourSum.a < alphaCutoff)
        discard;
    TRANSITION_DISCARD
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
#else
    vec2 lightSum = vec2_splat(0.0);
    addFrame(vWeights.x, vFrame01.xy, vUv01.xy, vParallax01.xy, vSun0, colourSum, lightSum);
    addFrame(vWeights.y, vFrame01.zw, vUv01.zw, vParallax01.zw, vSun1, colourSum, lightSum);
    addFrame(vWeights.z, vFrame2, vUv2, vParallax2, vSun2, colourSum, lightSum);
    if (colourSum.a < alphaCutoff)
        discard;
    TRANSITION_DISCARD
    vec3 albedo = colourSum.rgb / colourSum.a;
    vec2 light = lightSum / colourSum.a;
    vec3 k = ambientColour.rgb * light.y + sunColour.rgb * (light.x * SUN_VISIBILITY);
    fragColour = vec4(min(albedo * srgbScale(k), 1.0), 1.0);
#endif
}
