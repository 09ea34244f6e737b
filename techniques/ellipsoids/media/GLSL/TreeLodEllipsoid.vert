#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// Ellipsoids of an EllipsoidTree (EllipsoidTreeData.h), ray cast per fragment (Sigg et al. 2006,
// as the ellipsoids-and-lines paper (001) §5 renders them): one quad per ellipsoid covering, in
// normalised device coordinates, the projection of the ellipsoid's box (centre +- the three
// semi-axes). That holds for any projection (the view's perspective, a directional light's
// orthographic shadow camera, a LiSPSM warp), the box clipped at w = 0 first. The
// fragment stage casts the ray of its pixel, from the near plane, against the ellipsoid in the
// frame where it is the unit sphere; the ray's two points are interpolated here exactly (inverse
// projection is linear in x, y and the quad has w = 1).
// Per vertex: vertex = the centre (tree space, metres), uv0 = the quad corner (+-1, +-1), the
// cluster's noise lod and the level's noise threshold, uv1..uv3 = the three semi-axes (rotation
// columns times radii times the level's scale), uv1.w = the level's normal blend, colour = sRGB
// colour, alpha = ambient occlusion. Per instance (TreeLodInstance.glsl): uv4, uv5.
// The noise lod is raised to the pixel footprint's at the centre (EllipsoidNoise.h: the paper
// (001) §5 limits the noise frequency by the screen-space derivatives; here once per ellipsoid).
// Wind (TreeLodWind.glsl): each ellipsoid moves rigidly with the mesh's points at its centre.
uniform mat4 world;
uniform mat4 inverseWorld;
uniform mat4 worldView;
uniform mat4 projection;
uniform mat4 inverseProjection;
uniform vec4 viewportSize; // pixels: width, height, 1 / width, 1 / height
uniform vec4 objectTransition; // custom 7 (TreeLod/ObjectTransition.h)

#include "TreeLodInstance.glsl"
#include "TreeLodWind.glsl"

STATIC const float NOISE_SIZE = 256.0; // EllipsoidNoise.h: ELLIPSOID_NOISE_SIZE
STATIC const float NOISE_MAX_LOD = 8.0;

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec4 uv0, TEXCOORD0)
    IN(vec4 uv1, TEXCOORD1)
    IN(vec3 uv2, TEXCOORD2)
    IN(vec3 uv3, TEXCOORD3)
    IN(vec4 colour, COLOR)
    INSTANCE_IN
    OUT(vec4 vNear, TEXCOORD0)        // view space, homogeneous: the pixel's point on the near plane
    OUT(vec4 vFar, TEXCOORD1)         // view space, homogeneous: a point further along the pixel's ray
    FLAT_OUT(vec3 vCentre, TEXCOORD2) // view space
    FLAT_OUT(mat3 vToUnit, TEXCOORD3) // view space -> the unit-sphere frame (about the centre); HLSL: TEXCOORD3..5
    FLAT_OUT(vec4 vColour, TEXCOORD6)
    FLAT_OUT(vec3 vNoise, TEXCOORD7)  // lod, alpha threshold, normal blend
    TRANSITION_OUT(TEXCOORD8)
MAIN_DECLARATION
{
    vTransition = drawTransition(uv4, uv5, objectTransition);
    vec3 rest = vertex.xyz + windInstanceOffset(vertex.xyz, uv4, uv5, world, inverseWorld, false);
    vec3 centre = mul(worldView, instancePosition(uv4, uv5, vec4(rest, 1.0))).xyz;
    mat3 toView = toMat3(worldView);
    vec3 axis0 = mul(toView, instanceDirection(uv5, uv4.w * uv1.xyz));
    vec3 axis1 = mul(toView, instanceDirection(uv5, uv4.w * uv2));
    vec3 axis2 = mul(toView, instanceDirection(uv5, uv4.w * uv3));
    mat3 axes = mtxFromCols(axis0, axis1, axis2);
    // The box's part where w > 0 (everything the clip volume can hold: -w <= x, y, z <= w): its
    // corners there and the points where its 12 edges cross w = eps; their NDC rectangle. Under a
    // LiSPSM warp casters can straddle w = 0; a box wholly before the near plane is dropped.
    vec4 clip[8];
    float reach = 0.0;
    bool beforeNear = true;
    for (int i = 0; i < 8; ++i)
    {
        vec3 s = vec3((i & 1) != 0 ? 1.0 : -1.0, (i & 2) != 0 ? 1.0 : -1.0, (i & 4) != 0 ? 1.0 : -1.0);
        clip[i] = mul(projection, vec4(centre + mul(axes, s), 1.0));
        reach = max(reach, abs(clip[i].w));
        beforeNear = beforeNear && clip[i].z - NDC_NEAR * clip[i].w < 0.0;
    }
    float eps = 1e-6 * reach + 1e-30;
    vec2 lo = vec2_splat(1e30), hi = vec2_splat(-1e30);
    float nearest = 1.0; // NDC depth of the box's nearest point (TreeLodEllipsoid.frag: depth_greater)
    for (int i = 0; i < 8; ++i)
    {
        if (clip[i].w >= eps)
        {
            vec3 ndc = clip[i].xyz / clip[i].w;
            lo = min(lo, ndc.xy);
            hi = max(hi, ndc.xy);
            nearest = min(nearest, ndc.z);
        }
        for (int bit = 1; bit <= 4; bit *= 2)
        {
            int j = i | bit;
            if ((i & bit) != 0 || (clip[i].w - eps) * (clip[j].w - eps) >= 0.0)
                continue;
            vec4 onPlane = mix(clip[i], clip[j], (clip[i].w - eps) / (clip[i].w - clip[j].w));
            vec3 ndc = onPlane.xyz / eps;
            lo = min(lo, ndc.xy);
            hi = max(hi, ndc.xy);
            nearest = min(nearest, ndc.z);
        }
    }
    vec2 corner = uv0.xy * 0.5 + 0.5;
    vec2 ndc = mix(clamp(lo, -1.0, 1.0), clamp(hi, -1.0, 1.0), corner);
    if (beforeNear || lo.x > hi.x)
        ndc = vec2_splat(2.0); // nothing of it can be seen: a point outside the view
    vNear = mul(inverseProjection, vec4(ndc, NDC_NEAR, 1.0));
    vFar = mul(inverseProjection, vec4(ndc, 0.5 * NDC_NEAR + 0.5, 1.0)); // finite also with an infinite far plane
    vCentre = centre;
    vToUnit = inverse(axes);
    vColour = colour;
    // A pixel's size at the centre over the noise radius (the geometric mean of the two largest
    // semi-axes), in texels of the finest level: log2 of it is the footprint's lod.
    vec3 r = vec3(length(axis0), length(axis1), length(axis2));
    float radius = sqrt(r.x * r.y * r.z / max(min(r.x, min(r.y, r.z)), 1e-30));
    float pixel = 2.0 * abs(mul(projection, vec4(centre, 1.0)).w) / max(abs(projection[1][1]) * viewportSize.y, 1e-30);
    float footprint = log2(max(pixel * NOISE_SIZE / (2.0 * radius), 1e-30));
    vNoise = vec3(clamp(max(uv0.z, footprint), 0.0, NOISE_MAX_LOD), uv0.w, uv1.w);
    // At the box's nearest depth (inside the clip volume): the fragment writes a depth at least
    // this, so the depth test can reject hidden fragments before they are shaded.
    gl_Position = vec4(ndc, clamp(nearest, NDC_NEAR, 1.0), 1.0);
}
