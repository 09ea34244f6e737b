#version 330 core
// colour = albedo * (ambient + sun * max(0, n.l)) in linear space, written as sRGB
// (LightingSpec in TreeLod/Camera.h; the CPU reference renderer uses the same formula).
// LEAF: alpha test by discard; two-sided, the back side with backColour instead of baseColour.
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
uniform sampler2D diffuseMap;
uniform vec4 sunDirection;  // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
uniform vec4 baseColour;    // linear
uniform vec4 backColour;    // linear
uniform float alphaCutoff;
uniform float alphaMaxLod;  // coarsest mip level the alpha test reads (see leafAlpha)

in vec3 vNormal;
in vec3 vToCamera;
in vec2 vUv;

out vec4 fragColour;

#ifdef SHADOW_RECEIVER
// Integrated texture shadows (OGRE-NOTES.md "Shadows"): the casters wrote the shadow
// camera's window depth (TreeLodCaster.frag); 3x3 percentage-closer filtering.
uniform sampler2D shadowMap;
uniform vec4 shadowTexelSize;  // 1 / width, 1 / height
uniform float shadowBias;
in vec4 vShadowPos;

float sunVisibility()
{
    vec3 p = vShadowPos.xyz / vShadowPos.w;
    float depth = 0.5 * p.z + 0.5 - shadowBias;
    if (p.x <= 0.0 || p.x >= 1.0 || p.y <= 0.0 || p.y >= 1.0 || depth >= 1.0)
        return 1.0;
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += depth <= texture(shadowMap, p.xy + vec2(x, y) * shadowTexelSize.xy).r ? 1.0 : 0.0;
    return lit / 9.0;
}
#else
float sunVisibility() { return 1.0; }
#endif

vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c)); }
vec3 toSrgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

#include "TreeLodLeafAlpha.glsl"

void main()
{
    vec4 texel = texture(diffuseMap, vUv);
#ifdef LEAF
    texel.a = leafAlpha(diffuseMap, vUv, alphaMaxLod);
#endif
    vec3 n = normalize(vNormal);
    vec3 tint = baseColour.rgb;
#ifdef LEAF
    if (baseColour.a * texel.a < alphaCutoff)
        discard;
    // Facing from the normal, not gl_FrontFacing: render-to-texture flips Y and with it
    // the winding that gl_FrontFacing reports.
    if (dot(n, vToCamera) < 0.0)
    {
        n = -n;
        tint = backColour.rgb;
    }
#endif
    vec3 albedo = tint * toLinear(texel.rgb);
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * sunVisibility();
    vec3 colour = albedo * (ambientColour.rgb + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(colour), 1.0);
}
