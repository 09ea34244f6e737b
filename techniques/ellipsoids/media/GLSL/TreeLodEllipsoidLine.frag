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
// Ray-capsule intersection for the lines of an EllipsoidTree (TreeLodEllipsoidLine.vert): the
// pixel's ray against the cylinder of radius r around start..end, then the sphere at the nearer
// end when the hit falls outside the segment. A line thinner than the pixel that the ray misses is
// drawn at the axis point nearest the ray, its normal across the axis towards the viewer (a
// one-pixel line). True depth out; lit as TreeLodEllipsoid.frag lights the ellipsoids.
// CASTER: writes the shadow camera's window depth instead. SHADOW_RECEIVER: the sun's visibility at
// the hit.
uniform mat4 projection;
#ifndef CASTER
uniform vec4 sunDirection; // view space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
#endif
#ifdef SHADOW_RECEIVER
#define SHADOW_POS_PER_FRAGMENT
uniform mat4 inverseView;
#endif

#define SHADOW_UNIT0 0
#define SHADOW_UNIT1 1
#define SHADOW_UNIT2 2
#include "TreeLodShading.glsl"

// Distance along rd from ro to the capsule (pa, pb, r), or -1 (Quilez's capsule intersection).
float capsule(vec3 ro, vec3 rd, vec3 pa, vec3 pb, float r)
{
    vec3 ba = pb - pa, oa = ro - pa;
    float baba = dot(ba, ba), bard = dot(ba, rd), baoa = dot(ba, oa), rdoa = dot(rd, oa), oaoa = dot(oa, oa);
    float a = baba - bard * bard, b = baba * rdoa - baoa * bard, c = baba * oaoa - baoa * baoa - r * r * baba;
    float h = b * b - a * c;
    if (baba > 0.0 && a > 1e-12 * baba && h >= 0.0)
    {
        float t = (-b - sqrt(h)) / a;
        float y = baoa + t * bard;
        if (y > 0.0 && y < baba)
            return t;
    }
    // The end caps (or the whole capsule, for a segment along the ray or of no length).
    float best = -1.0;
    for (int e = 0; e < 2; ++e)
    {
        vec3 oc = ro - (e == 0 ? pa : pb);
        float bb = dot(rd, oc), cc = dot(oc, oc) - r * r, hh = bb * bb - cc;
        if (hh >= 0.0)
        {
            float t = -bb - sqrt(hh);
            if (t >= 0.0 && (best < 0.0 || t < best))
                best = t;
        }
    }
    return best;
}

MAIN_PARAMETERS
    IN(vec3 vPosition, TEXCOORD0)
    FLAT_IN(vec3 vStart, TEXCOORD1)
    FLAT_IN(vec3 vEnd, TEXCOORD2)
    FLAT_IN(float vRadius, TEXCOORD3)
    FLAT_IN(float vPixel, TEXCOORD4)
    FLAT_IN(vec4 vColour, TEXCOORD5)
    FLAT_IN(vec4 vProjectionCentre, TEXCOORD6) // the eye (w = 1) or a parallel projection's depth direction (w = 0)
    TRANSITION_IN(TEXCOORD7)
MAIN_DECLARATION_DEPTH
{
    // From the eye through the pixel, or along a parallel projection's depth axis (into the scene).
    vec3 rd = normalize(vProjectionCentre.w > 0.0 ? vPosition - vProjectionCentre.xyz : vProjectionCentre.xyz);
    // Start the ray behind the quad by the capsule's reach, so hits in front of it count.
    float back = 2.0 * max(vRadius, vPixel) + length(vEnd - vStart);
    vec3 ro = vPosition - rd * back;
    float t = capsule(ro, rd, vStart, vEnd, vRadius);
    vec3 hit = vec3_splat(0.0), n = vec3_splat(0.0); // (initialised for HLSL: set on every path not discarded)
    vec3 ba = vEnd - vStart;
    float baba = max(dot(ba, ba), 1e-30);
    if (t >= 0.0)
    {
        hit = ro + t * rd;
        vec3 onAxis = vStart + clamp(dot(hit - vStart, ba) / baba, 0.0, 1.0) * ba;
        n = normalize(hit - onAxis);
    }
    else
    {
        if (vRadius >= vPixel)
            discard;
        // Thinner than a pixel: the axis point nearest the ray, within half a pixel of it.
        vec3 w0 = ro - vStart;
        float bd = dot(ba, rd), denom = baba - bd * bd;
        float s = denom > 1e-12 * baba ? clamp((dot(ba, w0) - bd * dot(rd, w0)) / denom, 0.0, 1.0) : 0.0;
        vec3 onAxis = vStart + s * ba;
        float along = dot(onAxis - ro, rd);
        if (length(ro + along * rd - onAxis) > 0.5 * vPixel)
            discard;
        hit = ro + along * rd;
        vec3 axis = ba / sqrt(baba);
        n = -rd + dot(rd, axis) * axis;
        n = dot(n, n) > 1e-12 ? normalize(n) : -rd;
    }
    vec4 clip = mul(projection, vec4(hit, 1.0));
    float ndcDepth = clip.z / clip.w;
    if (ndcDepth < NDC_NEAR || ndcDepth > 1.0)
        discard;
    TRANSITION_DISCARD
    float depth = 0.5 * ndcDepth + 0.5; // the casters' shadow depth (TreeLodShadowCaster.glsl)
    gl_FragDepth = WINDOW_DEPTH(ndcDepth);
#ifdef CASTER
    fragColour = casterOutput(depth);
#else
#ifdef SHADOW_RECEIVER
    float shadow = sunVisibilityAtWorld(mul(inverseView, vec4(hit, 1.0)));
#else
    float shadow = 1.0;
#endif
    vec3 albedo = toLinear(vColour.rgb);
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * shadow;
    vec3 lit = albedo * (ambientColour.rgb * vColour.a + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(lit), 1.0);
#endif
}
