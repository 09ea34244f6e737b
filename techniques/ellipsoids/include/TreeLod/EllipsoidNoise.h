// EllipsoidNoise: the pair of mip-mapped white-noise cube maps that break up the ellipsoids'
// surfaces (the ellipsoids-and-lines paper (001) §3.1, Fig. 6; §5 for the lookup), one pair for
// every tree: a grey alpha map whose alpha test opens holes in an ellipsoid, and a normal map of
// random unit vectors blended into its normal. Both the baker (which calibrates the threshold,
// the area compensation and the normal blend by image error, EllipsoidTreeBaker.h) and the Ogre
// renderer (TreeLodEllipsoid.frag, which samples the same bytes uploaded as cube textures) use
// this definition, so what is calibrated is what is drawn.
//
// Texels: level 0 holds ELLIPSOID_NOISE_SIZE^2 texels a face, each alpha an independent uniform
// byte and each normal an independent uniform unit vector (0.5 + 0.5 v as bytes), from a fixed
// hash; level m + 1 is the 2 x 2 mean of level m, rounded to bytes. Faces in OpenGL's order and
// orientation (+X, -X, +Y, -Y, +Z, -Z; (s, t) from the major axis as in the GL specification,
// rows from t = 0). Sampling is trilinear, clamped at each face's edges.
//
// The level of detail of a cluster (§3.1): the paper's mip level l_j = 0.5 (1 + log2 sum_i w_ij)
// (the map of level l has 2^l x 2^l texels, so with t = 0.5 about sum_i w_ij holes), as an
// OpenGL lod log2(ELLIPSOID_NOISE_SIZE) - l_j; the renderer raises it to the pixel footprint's
// (§5, "limit the noise frequency ... like common mip-mapping").
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    constexpr int ELLIPSOID_NOISE_SIZE = 256; ///< texels a face side at level 0
    constexpr int ELLIPSOID_NOISE_LEVELS = 9; ///< 256 x 256 down to 1 x 1

    struct EllipsoidNoiseMaps
    {
        /// [level][face]: (SIZE >> level)^2 bytes, rows from t = 0.
        std::array<std::array<std::vector<std::uint8_t>, 6>, ELLIPSOID_NOISE_LEVELS> alpha;
        /// [level][face]: RGBA8, RGB = 0.5 + 0.5 v, A = 255.
        std::array<std::array<std::vector<std::uint8_t>, 6>, ELLIPSOID_NOISE_LEVELS> normal;

        /// Trilinear lookups in direction `dir` (any length > 0) at OpenGL lod `lod` (clamped to
        /// [0, LEVELS - 1]): alpha in [0, 1]; the normal map's vector 2 texel - 1 (shorter than 1
        /// at coarse levels, where random vectors average out).
        float sampleAlpha(const glm::vec3& dir, float lod) const;
        glm::vec3 sampleNormal(const glm::vec3& dir, float lod) const;
    };

    /// The maps (built on first call; thread-safe; the same bytes on every run).
    const EllipsoidNoiseMaps& ellipsoidNoiseMaps();

    /// The cluster's OpenGL lod: log2(SIZE) - 0.5 (1 + log2 leafWeight), in [0, LEVELS - 1].
    float ellipsoidNoiseBaseLod(float leafWeight);

    /// The lod whose texels are a pixel across on an ellipsoid of radius `radius` (the geometric
    /// mean of its two largest scaled semi-axes) seen with pixels `pixelSize` across at its centre
    /// (same unit): a face's SIZE texels span 2 units of the unit sphere's tangent plane, so
    /// log2(pixelSize * SIZE / (2 radius)). Not clamped.
    float ellipsoidNoiseFootprintLod(float pixelSize, float radius);
}
