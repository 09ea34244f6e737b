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
// Billboard clouds with multi-layered indirect texturing (García et al. 2007 §5, Fig. 7), one pass.
// Addressing: techniques/billboard-cloud/include/TreeLod/BillboardCloudData.h (its
// BillboardCloudSampler does the same steps on the CPU); all atlas addressing is integer.
//   1. hash fetch: the cell of the billboard's hash grid under the fragment -> list start, length;
//   2. walk the list from its front end (camera on the +normal side) or its back end (§5),
//      each entry's tile-local position, Leaves Texture lookup, until an opaque leaf fragment;
//   3. shader LoD (§5.1, Fig. 9, [LB06]): entries walked = listFactor * projected hash-cell
//      diagonal; the same footprint picks the Leaves Texture mip; leaves left out by a short
//      walk come from the low-res texture; a fully walked list without a hit is transparent.
// Lighting (§5.2) as TreeLodLit.frag: albedo * (ambient * ao + sun * max(0, n.l) * shadow),
// n from the leaf normal map turned into the billboard frame, ao bilinear from the entry's
// AO texel (Fig. 11), or from the low-res texture's alpha.
// LOW_RES_ONLY: the far technique (material LoD): the low-res texture alone, no lists.
// CASTER: writes the shadow camera's window depth instead of a colour (TreeLodCaster.frag).
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
SAMPLER2D(lowRes, 0);
#ifndef LOW_RES_ONLY
SAMPLER2D(hashAtlas, 1);
#ifdef OGRE_GLSLES
// ES 3.00 has no 16-bit normalised textures: the list entries are RGBA16UI there
// (BillboardCloudResources picks the format with the language).
uniform highp usampler2D listsAtlas;
#define LIST_ENTRY(at) texelFetch(listsAtlas, at, 0)
#else
SAMPLER2D(listsAtlas, 2);
#define LIST_ENTRY(at) uvec4(TEX2D_FETCH(listsAtlas, at, 0) * 65535.0 + 0.5)
#endif
SAMPLER2D(aoAtlas, 3);
SAMPLER2D(leavesColour, 4);
SAMPLER2D(leavesNormal, 5);
uniform int listsAtlasWidth;
uniform float tileSize;      // texels per tile edge
uniform int tileColumns;
uniform int tileRows;
uniform int orientationCount;
uniform float leavesMaxLod;  // coarsest Leaves Texture mip that does not bleed between tiles
#endif
// Custom parameter 0. x: list factor with the LoD bias applied; y: weight of the AO term.
uniform vec4 lodParams;
#ifndef CASTER
uniform vec4 sunDirection;   // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
#endif

#ifdef LOW_RES_ONLY
#define SHADOW_UNIT0 1
#define SHADOW_UNIT1 2
#define SHADOW_UNIT2 3
#else
#define SHADOW_UNIT0 6
#define SHADOW_UNIT1 7
#define SHADOW_UNIT2 8
#endif
#include "TreeLodShading.glsl"

STATIC const float LOW_RES_ALPHA_CUTOFF = 0.25; // BillboardCloudData.h
STATIC const float LEAVES_COVERAGE_CUTOFF = 0.5; // BillboardCloudData.h: every leaf image, its material's cutoff baked in
STATIC const float TWO_PI = 6.28318530718;

// The low-res AO (§5.2): covered texels hold 0.5 + 0.5 * ao, empty ones 0, so a filtered alpha
// at a leaf's edge mixes coverage into the value (decoding it would darken every edge). Take
// ao from the covered texels of the bilinear footprint at the mip level the footprint selects.
float lowResAo(vec2 uv, vec2 dx, vec2 dy, float filtered)
{
    vec2 size0 = vec2(TEX2D_SIZE(lowRes, 0));
    float rho2 = max(dot(dx * size0, dx * size0), dot(dy * size0, dy * size0));
    float top = floor(log2(max(size0.x, size0.y)));
    int level = int(clamp(floor(0.5 * log2(max(rho2, 1e-12)) + 0.5), 0.0, top));
    ivec2 size = TEX2D_SIZE(lowRes, level);
    vec2 t = uv * vec2(size) - 0.5;
    vec2 f = fract(t);
    ivec2 base = ivec2(floor(t));
    float sum = 0.0, weight = 0.0;
    for (int k = 0; k < 4; ++k)
    {
        ivec2 o = ivec2(k & 1, k >> 1);
        float a = TEX2D_FETCH(lowRes, clamp(base + o, ivec2_splat(0), size - 1), level).a;
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y) + 1e-4;
        if (a >= 0.5)
        {
            sum += w * (2.0 * a - 1.0);
            weight += w;
        }
    }
    return weight > 0.0 ? clamp(sum / weight, 0.0, 1.0) : clamp(2.0 * filtered - 1.0, 0.0, 1.0);
}

MAIN_PARAMETERS
    IN(vec2 vUv, TEXCOORD0)
    IN(vec2 vLowResUv, TEXCOORD1)
    FLAT_IN(vec4 vHash, TEXCOORD2) // hashX, hashY, hashWidth, hashHeight
    IN(vec3 vNormal, TEXCOORD3)
    IN(vec3 vTangent, TEXCOORD4)
    IN(vec3 vToCamera, TEXCOORD5)
#ifdef CASTER
    IN(vec2 vClipZW, TEXCOORD6)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_IN(TEXCOORD7, TEXCOORD8, TEXCOORD9)
#endif
    TRANSITION_IN(TEXCOORD10)
MAIN_DECLARATION
{
    vec3 N = normalize(vNormal);
    // Camera (or light) on the billboard's +normal side: walk front to back, tiles of side 0.
    bool front = dot(N, vToCamera) > 0.0;
    // Footprints before any branch (derivatives are undefined in divergent control flow).
    vec2 lowResDx = dFdx(vLowResUv), lowResDy = dFdy(vLowResUv);

    // (Initialised for HLSL, which rejects reading a variable not set on every path.)
    vec3 albedo = vec3_splat(0.0);
    vec3 n = front ? N : -N;
    float ao = 1.0;
    bool found = false;
#ifndef LOW_RES_ONLY
    vec2 p = vUv * vHash.zw; // billboard coordinates: hash cells are unit squares
    float rho = max(length(dFdx(p)), length(dFdy(p))); // cells per pixel
    // 1. Hash fetch (§4.2): exact texel, 24-bit start and 8-bit length.
    ivec2 size = ivec2(vHash.zw + 0.5);
    ivec2 cell = clamp(ivec2(floor(p)), ivec2_splat(0), size - 1);
    uvec4 h = uvec4(TEX2D_FETCH(hashAtlas, ivec2(vHash.xy + 0.5) + cell, 0) * 255.0 + 0.5);
    uint start = h.r | (h.g << 8u) | (h.b << 16u);
    uint count = h.a;
    if (count == 0u)
        discard;
    // 3. Shader LoD (§5.1): listFactor times the projected cell diagonal, sqrt(2) / rho pixels.
    float walked = floor(lodParams.x * 1.41421356 / max(rho, 1e-6));
    uint walk = uint(clamp(walked, 0.0, float(count)));
    vec2 q0 = p - vec2(cell);
    uint width = uint(listsAtlasWidth);
    uint orientations = uint(orientationCount);
    uint side = front ? 0u : 1u;
    vec3 U = normalize(vTangent);
    vec3 V = cross(N, U);
    // 2. Walk the list from the viewer's end.
    for (uint k = 0u; k < walk; ++k)
    {
        uint e = front ? start + k : start + count - 1u - k;
        ivec2 at = ivec2(int(e % width), int(e / width));
        uvec4 w = LIST_ENTRY(at);
        vec2 q = q0 - (vec2(w.rg) / 65535.0 * 64.0 - 32.0);
        float psi = float(w.a >> 8u) * (TWO_PI / 256.0);
        float edge = exp2((float(w.a & 255u) - 128.0) / 32.0); // tile edge in cells
        float c = cos(psi), s = sin(psi);
        vec2 local = vec2(c * q.x + s * q.y, -s * q.x + c * q.y) / edge + 0.5; // R(-psi) q / side + 0.5
        uint m = w.b >> 15u;
        if (m == 1u)
            local.x = 1.0 - local.x;
        if (any(lessThan(local, vec2_splat(0.0))) || any(greaterThan(local, vec2_splat(1.0))))
            continue;
        uint orientation = w.b & 0x7fffu;
        uint tile = orientation + (side ^ m) * orientations;
        uint columns = uint(tileColumns);
        vec2 uv = (vec2(float(tile % columns), float(tile / columns)) + local) /
                  vec2(float(tileColumns), float(tileRows));
        // The Leaves Texture mip of this entry's footprint: texels per pixel = rho * tileSize / side.
        float lod = clamp(log2(max(rho * tileSize / edge, 1e-6)), 0.0, leavesMaxLod);
        vec4 leaf = TEX2D_LOD(leavesColour, uv, lod);
        if (leaf.a < LEAVES_COVERAGE_CUTOFF)
            continue;
        found = true;
#ifndef CASTER
        albedo = toLinear(leaf.rgb);
        // Normal map (tile frame) to the billboard frame (BillboardCloudData.h, Leaves Texture).
        vec3 nt = TEX2D_LOD(leavesNormal, uv, lod).xyz * 2.0 - 1.0;
        float mirror = m == 1u ? -1.0 : 1.0;
        nt.x *= mirror;
        nt.z *= mirror;
        vec2 r = vec2(c * nt.x - s * nt.y, s * nt.x + c * nt.y); // R(psi) nt.xy
        n = normalize(r.x * U + r.y * V + nt.z * N);
        if (dot(n, vToCamera) < 0.0)
            n = -n;
        // §5.2, Fig. 11: AO at the tile corners, bilinear at the local position.
        vec4 corners = TEX2D_FETCH(aoAtlas, at, 0);
        ao = mix(mix(corners.r, corners.g, local.x), mix(corners.b, corners.a, local.x), local.y);
#endif
        break;
    }
    if (!found && walk >= count)
        discard; // the whole list walked: no leaf here
#endif
    if (!found)
    {
        // §5.1: the leaves the walk left out (or, LOW_RES_ONLY, all of them) from the low-res
        // texture; its alpha holds coverage and AO (0.5 + 0.5 * ao where covered).
        vec4 texel = TEX2D_GRAD(lowRes, vLowResUv, lowResDx, lowResDy);
        if (texel.a < LOW_RES_ALPHA_CUTOFF)
            discard;
        albedo = toLinear(texel.rgb);
#ifndef CASTER
        ao = lowResAo(vLowResUv, lowResDx, lowResDy, texel.a);
#endif
    }
    TRANSITION_DISCARD
#ifdef CASTER
    float depth = 0.5 * vClipZW.x / vClipZW.y + 0.5; // as TreeLodCaster.frag
    fragColour = casterOutput(depth);
#else
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * SUN_VISIBILITY;
    vec3 colour = albedo * (ambientColour.rgb * mix(1.0, ao, lodParams.y) + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(colour), 1.0);
#endif
}
