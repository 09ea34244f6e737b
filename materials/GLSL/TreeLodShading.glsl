// Shading helpers shared by the fragment programs (lit leaves and bark, billboard clouds, the
// impostors): sRGB conversions, srgbScale and, with SHADOW_RECEIVER, the sun's visibility in its
// texture shadow. Programs that include it set SHADOW_UNIT0..2, the texture units of the shadow
// textures, first.

vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3_splat(2.4)), step(0.04045, c)); }
vec3 toSrgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3_splat(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

// toSrgb(toLinear(albedo) * k) ~= albedo * srgbScale(k), exact for a power-law transfer curve
// (the impostors light sRGB albedo without conversions, techniques/impostor/README.md "Cost"): least-squares
// fit over 8-bit albedo and k in [0, 1.2], mean error 1.3/255, worst 6.5/255 (dark albedo at
// k < 0.1) against the exact conversions.
vec3 srgbScale(vec3 k)
{
    vec3 s1 = sqrt(k), s2 = sqrt(s1), s3 = sqrt(s2);
    return 0.5454 * s1 + 0.9485 * s2 - 0.4960 * s3;
}

#ifdef SHADOW_RECEIVER
// Depth shadows (integrated texture shadows; OGRE-NOTES.md "Shadows", TreeLod/ShadowSetup.h): the
// casters wrote the shadow camera's window depth (TreeLodShadowCaster.glsl), the receiver computes
// the same from texture_viewproj_matrix; 3x3 percentage-closer filtering. Up to three shadow
// textures, one (focused, LiSPSM) or PSSM's three splits: a point is looked up in the first
// texture that holds it, the finest (units past the scene's texture count hold Ogre's null shadow
// texture, which is lit).
SAMPLER2D(shadowMap0, SHADOW_UNIT0);
SAMPLER2D(shadowMap1, SHADOW_UNIT1);
SAMPLER2D(shadowMap2, SHADOW_UNIT2);
uniform vec4 shadowTexelSize;  // 1 / width, 1 / height (the sun's shadow textures share a size)
uniform float shadowBias;

// The fraction of the 3x3 texels around p (texture coordinates, window depth) that p is not behind.
float filteredVisibility(SAMPLER2D_PARAM(map), vec3 p)
{
    float lit = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            lit += p.z <= TEX2D(map, p.xy + vec2(x, y) * shadowTexelSize.xy).r ? 1.0 : 0.0;
    return lit / 9.0;
}

// The point in texture coordinates and biased window depth; outside the texture when z >= 1.
vec3 shadowTexturePoint(vec4 shadowPos)
{
    vec3 p = shadowPos.xyz / shadowPos.w;
    bool inside = p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0;
    return vec3(p.xy, inside ? 0.5 * p.z + 0.5 - shadowBias : 1.0);
}

// The sun's visibility at a point given in each shadow texture's clip space (texViewProj[i] * world).
float sunVisibilityAt(vec4 shadowPos0, vec4 shadowPos1, vec4 shadowPos2)
{
    vec3 p = shadowTexturePoint(shadowPos0);
    if (p.z < 1.0)
        return filteredVisibility(SAMPLER2D_ARG(shadowMap0), p);
    p = shadowTexturePoint(shadowPos1);
    if (p.z < 1.0)
        return filteredVisibility(SAMPLER2D_ARG(shadowMap1), p);
    p = shadowTexturePoint(shadowPos2);
    return p.z < 1.0 ? filteredVisibility(SAMPLER2D_ARG(shadowMap2), p) : 1.0;
}

#ifdef SHADOW_POS_PER_FRAGMENT // the program computes the point itself (ray-cast surfaces)
uniform mat4 texViewProj[3];   // the sun's shadow cameras, world to texture clip space
float sunVisibilityAtWorld(vec4 world)
{
    return sunVisibilityAt(mul(texViewProj[0], world), mul(texViewProj[1], world), mul(texViewProj[2], world));
}
#else
// The inputs from TreeLodShadowReceiver.glsl (main's parameters, with the semantics of SHADOW_POSITIONS_OUT).
#define SHADOW_POSITIONS_IN(s0, s1, s2) IN(vec4 vShadowPos0, s0) IN(vec4 vShadowPos1, s1) IN(vec4 vShadowPos2, s2)
#define SUN_VISIBILITY sunVisibilityAt(vShadowPos0, vShadowPos1, vShadowPos2)
#endif
#else
#define SUN_VISIBILITY 1.0
#endif
