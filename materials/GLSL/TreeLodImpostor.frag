#version 330 core
// The one-quad impostor (ImpostorData.h): alpha test on the baked coverage, then lit as
// TreeLodLit.frag lights leaves: colour = albedo * (ambient * ao + sun * max(0, n.l)) in linear
// space, written as sRGB, with the baked normal (quad frame: x right, y up, z towards the
// viewer) turned with the quad and the baked ambient occlusion.
// CASTER: writes the shadow camera's window depth instead (as TreeLodCaster.frag).
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
uniform sampler2D colourMap;  // sRGB albedo, coverage in alpha
uniform float alphaCutoff;
#ifdef CASTER
in vec2 vClipZW;
#else
uniform sampler2D normalMap;  // normal x, y (n * 0.5 + 0.5), ambient occlusion
uniform vec4 sunDirection;    // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
in vec3 vRight;
in vec3 vUp;
in vec3 vTowards;
#endif

in vec2 vUv;

out vec4 fragColour;

#include "TreeLodShading.glsl"

void main()
{
    vec4 texel = texture(colourMap, vUv);
    if (texel.a < alphaCutoff)
        discard;
#ifdef CASTER
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5;
    fragColour = vec4(depth, depth, depth, 1.0);
#else
    vec3 baked = texture(normalMap, vUv).xyz;
    vec2 xy = baked.xy * 2.0 - 1.0;
    vec3 n = normalize(xy.x * normalize(vRight) + xy.y * normalize(vUp) +
                       sqrt(max(1.0 - dot(xy, xy), 0.0)) * normalize(vTowards));
    vec3 albedo = toLinear(texel.rgb);
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * sunVisibility();
    vec3 colour = albedo * (ambientColour.rgb * baked.z + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(colour), 1.0);
#endif
}
