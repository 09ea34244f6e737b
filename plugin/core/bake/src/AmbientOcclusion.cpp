// Ambient occlusion by ray casting, for the AO terms of:
//   García et al. 2007 §5.2: García, Patow, Szirmay-Kalos, Sbert, "Multi-layered indirect
//                   texturing for tree rendering": AO "computed for the original polygonal tree"
//                   per vertex, then extrapolated to billboard corners (the extrapolation is the
//                   baker's).
//   the ellipsoids-and-lines paper §5 ("A level-of-detail method for trees based on ellipsoids
//                   and lines"): per-vertex AO of the mesh "by path tracing random directions in
//                   the surface normal hemisphere until the ray leaves the model".
// Directions: cosine-weighted (Malley's method: a uniform point on the unit disc lifted to the
// hemisphere) over a Fibonacci disc lattice, stratified in radius, randomly rotated per point.
// The orthonormal basis follows Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017).
#include "TreeLod/AmbientOcclusion.h"

#include "EmbreeScene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr float Pi = 3.14159265358979f;
        constexpr float GoldenFraction = 0.61803398874989f; // 1 / golden ratio
        constexpr float RelativeEpsilon = 1e-4f;            // origin offset, times the bounds diagonal
        constexpr std::size_t ProgressChunk = 4096;         // points between progress reports

        std::uint64_t splitMix64(std::uint64_t x)
        {
            x += 0x9E3779B97F4A7C15ull;
            x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
            x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
            return x ^ (x >> 31);
        }

        /// Per-point random numbers from (seed, index) only.
        struct PointRng
        {
            std::uint64_t state;
            PointRng(std::uint32_t seed, std::uint64_t index)
                : state(splitMix64(splitMix64(std::uint64_t(seed) + 0x51ED27A1ull) ^ index))
            {
            }
            float next() // [0, 1)
            {
                state = splitMix64(state);
                return float(state >> 40) * (1.0f / 16777216.0f);
            }
        };

        /// Fraction of `count` cosine-weighted rays around unit `n` from `origin` that escape.
        float hemisphereVisibility(const EmbreeScene& scene, const glm::vec3& origin, const glm::vec3& n, int count,
                                   float maxDistance, PointRng& rng)
        {
            float sign = std::copysign(1.0f, n.z);
            float a = -1.0f / (sign + n.z);
            float b = n.x * n.y * a;
            glm::vec3 t1(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
            glm::vec3 t2(b, sign + n.y * n.y * a, -n.y);
            float rotation = rng.next(), jitter = rng.next();
            int open = 0;
            for (int k = 0; k < count; ++k)
            {
                float r2 = (float(k) + jitter) / float(count);
                float r = std::sqrt(r2);
                float turns = float(k) * GoldenFraction + rotation;
                float phi = 2.0f * Pi * (turns - std::floor(turns));
                glm::vec3 dir = t1 * (r * std::cos(phi)) + t2 * (r * std::sin(phi)) +
                                n * std::sqrt(std::max(0.0f, 1.0f - r2));
                if (!scene.occluded(origin, dir, 0.0f, maxDistance))
                    ++open;
            }
            return float(open) / float(count);
        }

        float pointVisibility(const EmbreeScene& scene, const AoPoint& point, std::uint64_t index,
                              const AoOptions& options, float epsilon, float maxDistance)
        {
            const glm::vec3& p = point.position;
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                return 1.0f; // no ray can start there
            PointRng rng(options.seed, index);
            glm::vec3 n = point.normal;
            float len = glm::length(n);
            bool twoSided = point.twoSided;
            if (len > 0.0f && std::isfinite(len))
                n /= len;
            else
            {
                n = glm::vec3(0.0f, 1.0f, 0.0f);
                twoSided = true;
            }
            int rays = std::max(options.raysPerPoint, 1);
            if (!twoSided)
                return hemisphereVisibility(scene, point.position + n * epsilon, n, rays, maxDistance, rng);
            // Thin leaves: half the rays per side, the mean of both sides' visibility.
            int front = (rays + 1) / 2, back = rays / 2;
            float v = hemisphereVisibility(scene, point.position + n * epsilon, n, front, maxDistance, rng);
            if (back == 0)
                return v;
            return 0.5f * (v + hemisphereVisibility(scene, point.position - n * epsilon, -n, back, maxDistance, rng));
        }

        /// AO of points[i] seeded by (seed, indices[i]); `skip[i]` points get 1.
        std::vector<float> castPoints(const EmbreeScene& scene, const std::vector<AoPoint>& points,
                                      const std::vector<char>& skip, const AoOptions& options,
                                      const ProgressCallback& progress)
        {
            float diagonal = scene.diagonal();
            float epsilon = RelativeEpsilon * diagonal;
            float maxDistance = options.maxDistance > 0.0f ? options.maxDistance : 0.5f * diagonal;
            if (!(maxDistance > 0.0f) || !std::isfinite(maxDistance))
                maxDistance = INFINITY;
            std::vector<float> ao(points.size(), 1.0f);
            report(progress, "ambient occlusion", 0.0f);
            for (std::size_t begin = 0; begin < points.size(); begin += ProgressChunk)
            {
                std::size_t end = std::min(points.size(), begin + ProgressChunk);
                tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 64),
                                  [&](const tbb::blocked_range<std::size_t>& range) {
                                      for (std::size_t i = range.begin(); i != range.end(); ++i)
                                          if (skip.empty() || !skip[i])
                                              ao[i] = pointVisibility(scene, points[i], i, options, epsilon,
                                                                      maxDistance);
                                  });
                report(progress, "ambient occlusion", float(end) / float(points.size()));
            }
            report(progress, "ambient occlusion", 1.0f);
            return ao;
        }

        bool usable(const glm::vec3& n)
        {
            float len = glm::length(n);
            return len > 1e-20f && std::isfinite(len);
        }
    }

    std::vector<float> computeAmbientOcclusionAt(const TreeModel& model, const std::vector<AoPoint>& points,
                                                 const AoOptions& options, const ProgressCallback& progress)
    {
        EmbreeScene scene(model);
        return castPoints(scene, points, {}, options, progress);
    }

    AmbientOcclusion computeAmbientOcclusion(const TreeModel& model, const AoOptions& options,
                                             const ProgressCallback& progress)
    {
        EmbreeScene scene(model);
        std::size_t barkCount = model.barkVertices.size(), leafCount = model.leafVertices.size();

        // Points: bark vertices then leaf vertices; vertices of no triangle are skipped (AO 1).
        // Fallback normals: the sum of the area-weighted face normals around the vertex.
        std::vector<AoPoint> points(barkCount + leafCount);
        std::vector<char> skip(points.size(), 1);
        std::vector<glm::vec3> faceSum(points.size(), glm::vec3(0.0f));
        const EmbreeScene::Part parts[2] = {EmbreeScene::Bark, EmbreeScene::Leaves};
        for (EmbreeScene::Part part : parts)
        {
            const std::vector<Vertex>& vs = part == EmbreeScene::Bark ? model.barkVertices : model.leafVertices;
            std::size_t base = part == EmbreeScene::Bark ? 0 : barkCount;
            for (const EmbreeScene::Triangle& tri : scene.triangles(part))
            {
                glm::vec3 n = glm::cross(vs[tri.v[1]].position - vs[tri.v[0]].position,
                                         vs[tri.v[2]].position - vs[tri.v[0]].position);
                for (std::uint32_t v : tri.v)
                {
                    skip[base + v] = 0;
                    if (usable(n))
                        faceSum[base + v] += n;
                }
            }
            for (std::size_t i = 0; i < vs.size(); ++i)
            {
                AoPoint& p = points[base + i];
                p.position = vs[i].position;
                p.normal = usable(vs[i].normal) ? vs[i].normal : faceSum[base + i];
                p.twoSided = part == EmbreeScene::Leaves;
            }
        }

        std::vector<float> ao = castPoints(scene, points, skip, options, progress);
        AmbientOcclusion result;
        result.barkVertex.assign(ao.begin(), ao.begin() + std::ptrdiff_t(barkCount));
        result.leafVertex.assign(ao.begin() + std::ptrdiff_t(barkCount), ao.end());
        return result;
    }
}
