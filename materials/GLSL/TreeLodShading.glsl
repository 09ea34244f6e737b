// Shading helpers shared by the fragment programs (lit leaves and bark, billboard clouds, the
// impostors): sRGB conversions, srgbScale and, with SHADOW_RECEIVER, the sun's visibility in the
// integrated texture shadow.

vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c)); }
vec3 toSrgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// toSrgb(toLinear(albedo) * k) ~= albedo * srgbScale(k), exact for a power-law transfer curve
// (the impostors light sRGB albedo without conversions, docs/impostor.md "Cost"): least-squares
// fit over 8-bit albedo and k in [0, 1.2], mean error 1.3/255, worst 6.5/255 (dark albedo at
// k < 0.1) against the exact conversions.
vec3 srgbScale(vec3 k)
{
    vec3 s1 = sqrt(k), s2 = sqrt(s1), s3 = sqrt(s2);
    return 0.5454 * s1 + 0.9485 * s2 - 0.4960 * s3;
}

#ifdef SHADOW_RECEIVER
// Integrated texture shadows (OGRE-NOTES.md "Shadows"): the casters wrote the shadow
// camera's window depth (TreeLodCaster.frag, TreeLodBillboardCloud.frag with CASTER), the
// receiver computes the same from texture_viewproj_matrix; 3x3 percentage-closer filtering.
uniform sampler2D shadowMap;
uniform vec4 shadowTexelSize;  // 1 / width, 1 / height
uniform float shadowBias;

// The sun's visibility at a point given in the shadow texture's clip space (texViewProj * world).
float sunVisibilityAt(vec4 shadowPos)
{
    vec3 p = shadowPos.xyz / shadowPos.w;
    float depth = 0.5 * p.z + 0.5 - shadowBias;
    if (p.x <= 0.0 || p.x >= 1.0 || p.y <= 0.0 || p.y >= 1.0 || depth >= 1.0)
        return 1.0;
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += depth <= texture(shadowMap, p.xy + vec2(x, y) * shadowTexelSize.xy).r ? 1.0 : 0.0;
    return lit / 9.0;
}

#ifndef SHADOW_POS_PER_FRAGMENT // the program computes the point itself (ray-cast surfaces)
in vec4 vShadowPos;
float sunVisibility() { return sunVisibilityAt(vShadowPos); }
#endif
#else
float sunVisibility() { return 1.0; }
#endif
