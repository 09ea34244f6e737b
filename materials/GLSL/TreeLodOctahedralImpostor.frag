#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
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
uniform sampler2D colourMap; // sRGB albedo, coverage in alpha
uniform float alphaCutoff;
uniform vec4 atlas;          // frames a side N, frame texels F, margin texels, 0
#ifdef CASTER
in vec2 vClipZW;
#else
uniform sampler2D normalMap; // normal x, y (n * 0.5 + 0.5), ambient occlusion, depth
uniform vec4 sunColour;
uniform vec4 ambientColour;
in vec3 vSun0;
in vec3 vSun1;
in vec3 vSun2;
in vec4 vParallax01;
in vec2 vParallax2;
#endif

in vec4 vUv01;
in vec2 vUv2;
flat in vec4 vFrame01;
flat in vec2 vFrame2;
flat in vec3 vWeights;

out vec4 fragColour;

#include "TreeLodShading.glsl"

/// Atlas coordinates of frame coordinates `uv` in frame `cell`, kept inside the frame's margin.
vec2 atlasUv(vec2 cell, vec2 uv)
{
    float inset = 0.5 * atlas.z / atlas.y;
    return (cell + clamp(uv, inset, 1.0 - inset)) / atlas.x;
}

vec4 colourSum = vec4(0.0); // rgb: sum of w a albedo, a: sum of w a
#ifndef CASTER
vec2 lightSum = vec2(0.0);  // sum of w a lambert, sum of w a ao
#endif

#ifdef CASTER
void addFrame(float w, vec2 cell, vec2 uv)
{
    if (w < 1.0 / 256.0)
        return;
    colourSum.a += w * texture(colourMap, atlasUv(cell, uv)).a;
}
#else
void addFrame(float w, vec2 cell, vec2 uv, vec2 parallax, vec3 sun)
{
    if (w < 1.0 / 256.0)
        return;
    vec4 baked = texture(normalMap, atlasUv(cell, uv));
    vec4 texel = texture(colourMap, atlasUv(cell, uv + (baked.a - 0.5) * parallax));
    float wa = w * texel.a;
    vec2 xy = baked.xy * 2.0 - 1.0;
    xy *= inversesqrt(max(dot(xy, xy), 1.0)); // a filtered normal may leave the unit disc
    vec3 n = vec3(xy, sqrt(max(1.0 - dot(xy, xy), 0.0)));
    colourSum += vec4(wa * texel.rgb, wa);
    lightSum += wa * vec2(max(dot(n, sun), 0.0), baked.b);
}
#endif

void main()
{
#ifdef CASTER
    addFrame(vWeights.x, vFrame01.xy, vUv01.xy);
    addFrame(vWeights.y, vFrame01.zw, vUv01.zw);
    addFrame(vWeights.z, vFrame2, vUv2);
    if (colourSum.a < alphaCutoff)
        discard;
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = casterOutput(depth);
#else
    addFrame(vWeights.x, vFrame01.xy, vUv01.xy, vParallax01.xy, vSun0);
    addFrame(vWeights.y, vFrame01.zw, vUv01.zw, vParallax01.zw, vSun1);
    addFrame(vWeights.z, vFrame2, vUv2, vParallax2, vSun2);
    if (colourSum.a < alphaCutoff)
        discard;
    vec3 albedo = colourSum.rgb / colourSum.a;
    vec2 light = lightSum / colourSum.a;
    vec3 k = ambientColour.rgb * light.y + sunColour.rgb * (light.x * sunVisibility());
    fragColour = vec4(min(albedo * srgbScale(k), 1.0), 1.0);
#endif
}
