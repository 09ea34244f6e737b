#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
// Conservative depth is a desktop extension (ES 3.00 writes gl_FragDepth without the hint).
#ifdef OGRE_GLSL
#extension GL_ARB_conservative_depth : enable
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
#ifdef CASTER
#include "TreeLodShadowCaster.glsl"
#endif
// Ray-ellipsoid intersection in the ellipsoid's unit-sphere frame (Sigg et al. 2006; the
// ellipsoids-and-lines paper (001) §5): the pixel's ray from + t dir (from on the near plane)
// becomes o + t k with o = toUnit * (from - centre), k = toUnit * dir, and |o + t k| = 1 is a
// quadratic in t, solved about the ray's point nearest the centre (no cancellation for small
// ellipsoids far away). The nearest hit past the near plane is drawn with its true depth (the
// far side when the near plane cuts the ellipsoid); the normal is the unit sphere's u brought
// back to view space by the inverse transpose, transpose(toUnit).
// Noise (§3.1, Fig. 6; EllipsoidNoise.h): the unit-sphere point u indexes the noise cube maps;
// where the alpha noise is below the level's threshold the surface has a hole and the far side
// is tested instead; the normal in the unit frame is blended towards the normal noise (§5: "add
// the normal noise to the normal vector before transforming it to eye space"). renderEllipsoids
// (EllipsoidTreeBaker.h) is the CPU twin the baker calibrates the noise with.
// colour = albedo * (ambient * ao + sun * max(0, n.l) * shadow) in linear space, written as sRGB,
// as TreeLodLit.frag lights the leaves (LightingSpec in TreeLod/Camera.h).
// CASTER: writes the shadow camera's window depth of the hit instead (as TreeLodCaster.frag).
// SHADOW_RECEIVER: the sun's visibility at the hit (its world position, inverseView * hit).
uniform mat4 projection;
#ifdef SHADOW_RECEIVER
SAMPLERCUBE(noiseAlpha, 3); // after the shadow textures
#else
SAMPLERCUBE(noiseAlpha, 0);
#endif
#ifndef CASTER
#ifdef SHADOW_RECEIVER
SAMPLERCUBE(noiseNormal, 4);
#else
SAMPLERCUBE(noiseNormal, 1);
#endif
uniform vec4 sunDirection; // view space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
#endif
#ifdef SHADOW_RECEIVER
#define SHADOW_POS_PER_FRAGMENT
uniform mat4 inverseView;
#endif

#ifdef GL_ARB_conservative_depth
// The quad lies at the ellipsoid box's nearest depth (TreeLodEllipsoid.vert): the hit is never
// nearer, so the depth test may run before the program.
layout(depth_greater) out float gl_FragDepth;
#endif

#define SHADOW_UNIT0 0
#define SHADOW_UNIT1 1
#define SHADOW_UNIT2 2
#include "TreeLodShading.glsl"

MAIN_PARAMETERS
    IN(vec4 vNear, TEXCOORD0)
    IN(vec4 vFar, TEXCOORD1)
    FLAT_IN(vec3 vCentre, TEXCOORD2)
    FLAT_IN(mat3 vToUnit, TEXCOORD3)
    FLAT_IN(vec4 vColour, TEXCOORD6)
    FLAT_IN(vec3 vNoise, TEXCOORD7) // lod, alpha threshold, normal blend
    TRANSITION_IN(TEXCOORD8)
MAIN_DECLARATION_DEPTH
{
    vec3 from = vNear.xyz / vNear.w;
    vec3 dir = normalize(vFar.xyz / vFar.w - from);
    vec3 k = mul(vToUnit, dir);
    float a = dot(k, k);
    vec3 start = mul(vToUnit, from - vCentre);
    float mid = -dot(start, k) / a;
    vec3 o = start + mid * k;
    float c = dot(o, o) - 1.0;
    if (c > 0.0)
        discard;
    float halfChord = sqrt(-c / a);
    // The near side; where the near plane cuts it or the noise opens a hole there, the far side.
    float t = mid - halfChord;
    vec3 u = o - halfChord * k;
    if (t < 0.0 || (vNoise.y > 0.0 && TEXCUBE_LOD(noiseAlpha, u, vNoise.x).r < vNoise.y))
    {
        t = mid + halfChord;
        u = o + halfChord * k;
        if (t < 0.0 || (vNoise.y > 0.0 && TEXCUBE_LOD(noiseAlpha, u, vNoise.x).r < vNoise.y))
            discard;
    }
    vec3 hit = from + t * dir;
    vec4 clip = mul(projection, vec4(hit, 1.0));
    float ndcDepth = clip.z / clip.w;
    if (ndcDepth > 1.0)
        discard; // beyond the far plane
    TRANSITION_DISCARD
    float depth = 0.5 * ndcDepth + 0.5; // the casters' shadow depth (TreeLodShadowCaster.glsl)
    gl_FragDepth = WINDOW_DEPTH(ndcDepth);
#ifdef CASTER
    fragColour = casterOutput(depth);
#else
    vec3 unitNormal = u;
    if (vNoise.z > 0.0)
        unitNormal = mix(u, TEXCUBE_LOD(noiseNormal, u, vNoise.x).rgb * 2.0 - 1.0, vNoise.z);
    vec3 n = normalize(mul(transpose(vToUnit), unitNormal));
    if (dot(n, dir) > 0.0) // seen from inside
        n = -n;
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
