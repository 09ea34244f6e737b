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
// The one-quad impostor (ImpostorData.h): alpha test on the baked coverage, then lit as
// TreeLodLit.frag lights leaves, colour = albedo * (ambient * ao + sun * max(0, n.l)) in linear
// space written as sRGB, with the baked normal and ambient occlusion. It is the far level of every
// forest, so each step is the cheapest that keeps the picture (techniques/impostor/README.md, "Cost"):
// - the sun arrives in the quad frame of the baked normal (TreeLodImpostor.vert): no turning or
//   normalising per fragment;
// - no sRGB conversion: the light factor k scales the sRGB albedo directly,
//   toSrgb(toLinear(albedo) * k) ~= albedo * srgbScale(k) (exact for a power-law transfer curve;
//   sRGB's linear toe makes the error), three square roots instead of two pow per channel.
// CASTER: writes the shadow camera's window depth instead (as TreeLodCaster.frag).
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
SAMPLER2D(colourMap, 0);  // sRGB albedo, coverage in alpha
uniform float alphaCutoff;
#ifndef CASTER
SAMPLER2D(normalMap, 1);  // normal x, y (n * 0.5 + 0.5) in the quad frame, ambient occlusion
uniform vec4 sunColour;
uniform vec4 ambientColour;
#endif

#define SHADOW_UNIT0 2
#define SHADOW_UNIT1 3
#define SHADOW_UNIT2 4
#include "TreeLodShading.glsl"

MAIN_PARAMETERS
    IN(vec2 vUv, TEXCOORD0)
#ifdef CASTER
    IN(vec2 vClipZW, TEXCOORD1)
#else
    IN(vec3 vSunInQuad, TEXCOORD1)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_IN(TEXCOORD2, TEXCOORD3, TEXCOORD4)
#endif
    TRANSITION_IN(TEXCOORD5)
MAIN_DECLARATION
{
    vec4 texel = TEX2D(colourMap, vUv);
    if (texel.a < alphaCutoff)
        discard;
    TRANSITION_DISCARD
#ifdef CASTER
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
#else
    vec3 baked = TEX2D(normalMap, vUv).xyz;
    vec2 xy = baked.xy * 2.0 - 1.0;
    xy *= inversesqrt(max(dot(xy, xy), 1.0)); // a filtered normal may leave the unit disc
    vec3 n = vec3(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
    float lambert = max(dot(n, vSunInQuad), 0.0) * SUN_VISIBILITY;
    vec3 light = ambientColour.rgb * baked.z + sunColour.rgb * lambert;
    fragColour = vec4(min(texel.rgb * srgbScale(light), 1.0), 1.0);
#endif
}
