// The ellipsoid tree (chunk "ellipsoids", the ellipsoids-and-lines paper (001) §3.1, §5): one leaf,
// coplanar leaves (a singular covariance), two identical leaves, EM from all starts on one point,
// 200,000 leaves, the level counts of Alg. 1, the CPU ray caster and the noise (§3.1, Fig. 6), the
// chunk round trip and every corruption named, determinism over seeds and thread counts, each
// level's coverage against the leaves', 0.5 m vs 500 m, the ellipsoids' ambient occlusion (§5),
// and the registered baker and descriptor.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/EllipsoidNoise.h"
#include "TreeLod/EllipsoidTreeBaker.h"
#include "TreeLod/EllipsoidTreeData.h"
#include "TreeLod/GaussianMixture.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/TechniqueDescriptor.h"
#include "TestTrees.h"
#include "../src/EllipsoidErrorViews.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace TreeLod
{
    namespace
    {
        using test::generatedOak;
        using test::scaled;

        EllipsoidTreeOptions fastOptions()
        {
            EllipsoidTreeOptions o;
            o.tries = 2;
            o.viewResolution = 64;
            return o;
        }

        EllipsoidTreeData bakeOrFail(const TreeModel& m, const EllipsoidTreeOptions& options = fastOptions())
        {
            Result<EllipsoidTreeData> r = bakeEllipsoidTree(m, options, "test tree");
            EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
            return r.ok() ? std::move(r).value() : EllipsoidTreeData();
        }

        /// The 256-leaf oak's bake (fastOptions), shared by the suite's tests.
        const EllipsoidTreeData& oakBake()
        {
            static const EllipsoidTreeData d = bakeOrFail(generatedOak(256));
            return d;
        }

        /// The 128-leaf oak's bake, shared by the tests that compare a variant of it with it.
        const EllipsoidTreeData& smallOakBake()
        {
            static const EllipsoidTreeData d = bakeOrFail(generatedOak(128));
            return d;
        }

        TreeModel emptyLeafModel()
        {
            TreeModel m;
            m.name = "leaves";
            Material leaf = test::leafMaterial("Leaves");
            leaf.baseColour = glm::vec4(0.2f, 0.5f, 0.1f, 1.0f);
            m.materials.push_back(leaf);
            return m;
        }

        bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        void expectAllFinite(const EllipsoidTreeData& d)
        {
            for (const Ellipsoid& e : d.ellipsoids)
            {
                EXPECT_TRUE(finite(e.centre));
                EXPECT_TRUE(finite(e.radii));
                EXPECT_TRUE(std::isfinite(e.rotation.x + e.rotation.y + e.rotation.z + e.rotation.w));
                EXPECT_GT(std::min({e.radii.x, e.radii.y, e.radii.z}), 0.0f);
            }
            for (const EllipsoidLevel& l : d.levels)
            {
                EXPECT_TRUE(std::isfinite(l.scale) && std::isfinite(l.imageError) && std::isfinite(l.targetHeightPx));
            }
        }

        /// The world direction of axis `k` of `e`.
        glm::vec3 axis(const Ellipsoid& e, int k) { return glm::mat3_cast(e.rotation)[k]; }

        /// Fraction of pixels covered (alpha) in a side view of `m` framing the box [lo, hi].
        double coverage(const TreeModel& m, const glm::vec3& lo, const glm::vec3& hi, float azimuth)
        {
            const ReferenceRenderer renderer(m);
            CameraSpec camera = CameraSpec::framing(lo, hi, azimuth, 10.0f);
            RenderOptions options = albedoRenderOptions(96, 96, 4);
            const RenderImages images = renderer.render(camera, options);
            double sum = 0.0;
            for (float a : images.alpha)
                sum += a;
            return sum / double(images.alpha.size());
        }

        /// The baker's image error (mean multi-scale RMSE of flat white coverage) of level `k` of `d`
        /// against `leaves` (flatColourLeaves), in two perspective side views the baker did not use,
        /// with the level's stored noise (its footprint at the level's target height) or none.
        double unseenError(const EllipsoidTreeData& d, std::size_t k, const TreeModel& leaves, bool noise)
        {
            const EllipsoidLevel& level = d.levels[k];
            const std::vector<Ellipsoid> ellipsoids(d.ellipsoids.begin() + level.first,
                                                    d.ellipsoids.begin() + level.first + level.count);
            EllipsoidNoiseSetting setting;
            if (noise)
            {
                setting.threshold = level.noiseThreshold;
                setting.normalBlend = level.normalBlend;
                setting.pixelSize = (leaves.boundsMax.y - leaves.boundsMin.y) / level.targetHeightPx;
            }
            const RenderOptions options = EllipsoidErrorViews::renderOptions(96);
            const ReferenceRenderer renderer(leaves);
            double sum = 0.0;
            for (float azimuth : {45.0f, 200.0f})
            {
                const CameraSpec camera = CameraSpec::framing(leaves.boundsMin, leaves.boundsMax, azimuth, 10.0f);
                Result<MultiScaleRmseResult> e = multiScaleRmse(renderer.render(camera, options).colour,
                                                                renderEllipsoids(ellipsoids, level.scale, setting, camera, options));
                EXPECT_TRUE(e.ok());
                sum += e.ok() ? e->combined : 1.0;
            }
            return sum / 2.0;
        }

        // One square leaf of 0.2 m: one level of one ellipsoid, a disc on the leaf: the two large
        // semi-axes equal (2 sqrt(var) of a uniform square of half-side 0.1 = 0.2 / sqrt 3), the
        // third the 2 % floor, the normal along the leaf's.
        TEST(EllipsoidTreeBake, oneLeafIsOneFlatEllipsoid)
        {
            TreeModel m = emptyLeafModel();
            test::addQuadLeaf(m, glm::vec3(0.3f, 2.0f, -0.1f), glm::vec3(0.1f, 0, 0), glm::vec3(0, 0.1f, 0),
                              glm::vec3(0, 0, 1));
            m.updateBounds();
            const EllipsoidTreeData d = bakeOrFail(m);
            ASSERT_EQ(d.levels.size(), 1u);
            ASSERT_EQ(d.ellipsoids.size(), 1u);
            const Ellipsoid& e = d.ellipsoids[0];
            EXPECT_NEAR(glm::distance(e.centre, glm::vec3(0.3f, 2.0f, -0.1f)), 0.0f, 1e-5f);
            const float expected = 2.0f * 0.1f / std::sqrt(3.0f);
            EXPECT_NEAR(e.radii.x, expected, 1e-4f);
            EXPECT_NEAR(e.radii.y, expected, 1e-4f);
            EXPECT_NEAR(e.radii.z, 0.02f * expected, 1e-5f);
            EXPECT_NEAR(std::abs(glm::dot(axis(e, 2), glm::vec3(0, 0, 1))), 1.0f, 1e-4f);
            // The calibrated scale of a square: the disc of its area has radius 0.1 * sqrt(4 / pi)
            // = 1.13 * 0.1, i.e. scale 1.13 / 1.155 = 0.98; the calibration's grid is 0.1 wide.
            EXPECT_NEAR(d.levels[0].scale, 1.0f, 0.15f);
            // A square against its disc: they differ at the corners (a tenth of the area), and the
            // view from above sees the leaf edge-on, the disc as a 2 % sliver.
            EXPECT_LT(d.levels[0].imageError, 0.15f);
            expectAllFinite(d);
        }

        // 64 leaves in one horizontal plane: every covariance (leaf and cluster) is singular along
        // Y. No NaN; every ellipsoid is a thin disc whose thin axis is Y.
        TEST(EllipsoidTreeBake, coplanarLeavesGiveFlatEllipsoids)
        {
            TreeModel m = emptyLeafModel();
            for (int i = 0; i < 8; ++i)
                for (int j = 0; j < 8; ++j)
                    test::addQuadLeaf(m, glm::vec3(0.3f * float(i), 1.5f, 0.3f * float(j) + 0.05f * float(i % 2)),
                                      glm::vec3(0.1f, 0, 0), glm::vec3(0, 0, 0.06f), glm::vec3(0, 1, 0));
            m.updateBounds();
            const EllipsoidTreeData d = bakeOrFail(m);
            ASSERT_EQ(d.levels.size(), 4u); // 64, 16, 4, 1
            expectAllFinite(d);
            for (const Ellipsoid& e : d.ellipsoids)
            {
                EXPECT_NEAR(e.centre.y, 1.5f, 1e-3f);
                EXPECT_NEAR(e.radii.z, 0.02f * e.radii.x, 1e-3f * e.radii.x);
                EXPECT_NEAR(std::abs(axis(e, 2).y), 1.0f, 1e-3f);
            }
            EXPECT_EQ(d.levels.back().count, 1u);
            // The one cluster spans the grid (2.1 m x 2.15 m): semi-axes about 2 sigma of a uniform
            // spread, sigma ~ 2.2 / sqrt 12 = 0.64.
            const Ellipsoid& top = d.ellipsoids.back();
            EXPECT_GT(top.radii.y, 1.0f);
            EXPECT_LT(top.radii.x, 1.6f);
        }

        // Two leaves on the same vertices: two identical level-0 ellipsoids, then one on both.
        TEST(EllipsoidTreeBake, twoIdenticalLeaves)
        {
            TreeModel m = emptyLeafModel();
            for (int k = 0; k < 2; ++k)
                test::addQuadLeaf(m, glm::vec3(0, 1, 0), glm::vec3(0.1f, 0, 0), glm::vec3(0, 0.05f, 0.05f),
                                  glm::vec3(0, -0.7071f, 0.7071f));
            m.updateBounds();
            const EllipsoidTreeData d = bakeOrFail(m);
            ASSERT_EQ(d.levels.size(), 2u);
            EXPECT_EQ(d.levels[0].count, 2u);
            EXPECT_EQ(d.levels[1].count, 1u);
            expectAllFinite(d);
            EXPECT_EQ(d.ellipsoids[0].centre, d.ellipsoids[1].centre);
            EXPECT_EQ(d.ellipsoids[0].radii, d.ellipsoids[1].radii);
            const Ellipsoid& both = d.ellipsoids[2];
            EXPECT_NEAR(glm::distance(both.centre, glm::vec3(0, 1, 0)), 0.0f, 1e-5f);
            EXPECT_NEAR(both.radii.x, d.ellipsoids[0].radii.x, 1e-4f);
            EXPECT_NEAR(both.leafWeight, 2.0f, 1e-4f);
        }

        // EM with every start on one point, three separate blobs of 40 points: the duplicates are
        // re-seeded, it converges without NaN and puts one component on each blob.
        TEST(EllipsoidTreeBake, emFromOnePointConverges)
        {
            GaussianMixtureInput input;
            const glm::dvec3 blobs[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5}};
            std::uint64_t state = 7;
            for (const glm::dvec3& b : blobs)
                for (int i = 0; i < 40; ++i)
                {
                    glm::dvec3 jitter;
                    for (int a = 0; a < 3; ++a)
                    {
                        state = state * 6364136223846793005ull + 1442695040888963407ull;
                        jitter[a] = 0.05 * (double(state >> 11) / 9007199254740992.0 - 0.5);
                    }
                    input.points.push_back(b + jitter);
                }
            for (std::uint32_t candidates : {12u, 2u}) // exact, then truncated
            {
                GaussianMixtureOptions options;
                options.candidates = candidates;
                options.initialVariance = 0.01;
                const GaussianMixtureResult r =
                    fitGaussianMixture(input, std::vector<glm::dvec3>(3, glm::dvec3(0.2, 0.2, 0.2)), options);
                EXPECT_TRUE(r.converged) << candidates;
                EXPECT_GT(r.reseeds, 0u);
                EXPECT_TRUE(std::isfinite(r.logLikelihood));
                for (double w : r.responsibility)
                    EXPECT_TRUE(std::isfinite(w));
                for (const glm::dvec3& b : blobs)
                {
                    double nearest = 1e9;
                    for (const glm::dvec3& mu : r.means)
                        nearest = std::min(nearest, glm::distance(mu, b));
                    EXPECT_LT(nearest, 0.02) << "blob " << b.x << " " << b.y << " " << b.z << ", " << candidates;
                }
                for (std::size_t i = 0; i < input.points.size(); ++i)
                {
                    double sum = 0.0;
                    for (std::uint32_t e = r.offsets[i]; e < r.offsets[i + 1]; ++e)
                        sum += r.responsibility[e];
                    EXPECT_NEAR(sum, 1.0, 1e-9);
                }
            }
        }

        // The truncated E-step's candidates are each point's nearest means, ties by index: after one
        // iteration (the means are the starts) every point's components are the brute-force nearest
        // 8 of 600 starts, on a grid of equal coordinates (ties on every axis) and off it.
        TEST(EllipsoidTreeBake, truncatedEStepTakesTheNearestMeans)
        {
            std::uint64_t state = 11;
            const auto next = [&state] {
                state = state * 6364136223846793005ull + 1442695040888963407ull;
                return double(state >> 11) / 9007199254740992.0;
            };
            for (const bool grid : {true, false})
            {
                std::vector<glm::dvec3> starts(600);
                for (glm::dvec3& m : starts)
                    m = grid ? glm::floor(glm::dvec3(next(), next(), next()) * 6.0) : glm::dvec3(next(), next(), next()) * 6.0;
                GaussianMixtureInput input;
                for (int i = 0; i < 3000; ++i)
                    input.points.push_back(glm::dvec3(next(), next(), next()) * 6.0);
                GaussianMixtureOptions options;
                options.maxIterations = 1;
                options.candidates = 8;
                const GaussianMixtureResult r = fitGaussianMixture(input, starts, options);
                ASSERT_EQ(r.means, starts);
                int wrong = 0;
                for (std::size_t i = 0; i < input.points.size(); ++i)
                {
                    std::vector<std::pair<double, std::uint32_t>> all;
                    for (std::uint32_t j = 0; j < starts.size(); ++j)
                    {
                        const glm::dvec3 d = starts[j] - input.points[i];
                        all.emplace_back(glm::dot(d, d), j);
                    }
                    std::partial_sort(all.begin(), all.begin() + 8, all.end());
                    std::vector<std::uint32_t> nearest;
                    for (int m = 0; m < 8; ++m)
                        nearest.push_back(all[std::size_t(m)].second);
                    std::sort(nearest.begin(), nearest.end());
                    const std::vector<std::uint32_t> taken(r.component.begin() + r.offsets[i],
                                                           r.component.begin() + r.offsets[i + 1]);
                    wrong += taken != nearest;
                }
                EXPECT_EQ(wrong, 0) << (grid ? "on the grid" : "off the grid");
            }
        }

        // With candidateRefresh 8 the candidates are searched on iterations 0 and 8 only: after 8
        // iterations every point still holds the 8 nearest of the starts (the means have moved),
        // after 9 the 8 nearest of the means returned.
        TEST(EllipsoidTreeBake, candidatesAreSearchedEveryRefresh)
        {
            std::uint64_t state = 5;
            const auto next = [&state] {
                state = state * 6364136223846793005ull + 1442695040888963407ull;
                return double(state >> 11) / 9007199254740992.0;
            };
            std::vector<glm::dvec3> starts(300);
            for (glm::dvec3& m : starts)
                m = glm::dvec3(next(), next(), next()) * 6.0;
            GaussianMixtureInput input;
            for (int i = 0; i < 3000; ++i)
                input.points.push_back(glm::dvec3(next(), next(), next()) * 6.0);
            const auto nearest = [](const std::vector<glm::dvec3>& means, const glm::dvec3& p) {
                std::vector<std::pair<double, std::uint32_t>> all;
                for (std::uint32_t j = 0; j < means.size(); ++j)
                    all.emplace_back(glm::dot(means[j] - p, means[j] - p), j);
                std::partial_sort(all.begin(), all.begin() + 8, all.end());
                std::vector<std::uint32_t> out;
                for (int m = 0; m < 8; ++m)
                    out.push_back(all[std::size_t(m)].second);
                std::sort(out.begin(), out.end());
                return out;
            };
            GaussianMixtureOptions options;
            options.candidates = 8;
            options.candidateRefresh = 8;
            options.maxReseedRounds = 0;
            options.tolerance = 0.0;
            for (const std::uint32_t iterations : {8u, 9u})
            {
                options.maxIterations = iterations;
                const GaussianMixtureResult r = fitGaussianMixture(input, starts, options);
                ASSERT_EQ(r.iterations, iterations);
                ASSERT_NE(r.means, starts);
                int fromStarts = 0, fromMeans = 0;
                for (std::size_t i = 0; i < input.points.size(); ++i)
                {
                    const std::vector<std::uint32_t> taken(r.component.begin() + r.offsets[i],
                                                           r.component.begin() + r.offsets[i + 1]);
                    fromStarts += taken == nearest(starts, input.points[i]);
                    fromMeans += taken == nearest(r.means, input.points[i]);
                }
                const int all = int(input.points.size());
                if (iterations == 8)
                {
                    EXPECT_EQ(fromStarts, all);
                    EXPECT_LT(fromMeans, all); // the means moved: some points' nearest changed
                }
                else
                    EXPECT_EQ(fromMeans, all);
            }
        }

        // 256 leaves, divisor 4: targets 64, 16, 4, 1 after the 256 leaves (dropping may only lower
        // them); divisor 8: 32, 4, 1 (the division stops at 4, one ellipsoid is added).
        TEST(EllipsoidTreeBake, levelCountsFollowTheDivisor)
        {
            const TreeModel& oak = generatedOak(256);
            const EllipsoidTreeData& d = oakBake();
            const std::uint32_t targets[] = {256, 64, 16, 4, 1};
            ASSERT_EQ(d.levels.size(), 5u);
            for (std::size_t k = 0; k < 5; ++k)
            {
                EXPECT_LE(d.levels[k].count, targets[k]) << "level " << k;
                EXPECT_GE(d.levels[k].count, (targets[k] + 1) / 2) << "level " << k;
            }
            EXPECT_EQ(d.levels[0].count, 256u);
            // Coarser levels are made for smaller trees on screen.
            for (std::size_t k = 1; k < d.levels.size(); ++k)
                EXPECT_LT(d.levels[k].targetHeightPx, d.levels[k - 1].targetHeightPx) << "level " << k;
            EllipsoidTreeOptions eight = fastOptions();
            eight.clustersDivisor = 8;
            eight.tries = 1;
            const EllipsoidTreeData e = bakeOrFail(oak, eight);
            ASSERT_EQ(e.levels.size(), 4u);
            EXPECT_LE(e.levels[1].count, 32u);
            EXPECT_LE(e.levels[2].count, 4u);
            EXPECT_EQ(e.levels[3].count, 1u);
        }

        // 200,000 leaves (one try, 32-pixel views, a divisor of 64, so 200,000 / 3125 / 48 / 1): every
        // leaf its ellipsoid, every level's leaf weights summing to the leaves its ellipsoids keep,
        // nothing but finite values, 28 bytes an ellipsoid, and the chunk round-trips.
        TEST(EllipsoidTreeBake, twoHundredThousandLeaves)
        {
            const TreeModel& oak = generatedOak(200000);
            EllipsoidTreeOptions options;
            options.tries = 1;
            options.viewResolution = 32;
            options.clustersDivisor = 64;
            const EllipsoidTreeData d = bakeOrFail(oak, options);
            ASSERT_EQ(d.levels.size(), 4u);
            EXPECT_EQ(d.levels[0].count, 200000u);
            EXPECT_LE(d.levels[1].count, 3125u);
            EXPECT_GE(d.levels[1].count, 1500u);
            EXPECT_LE(d.levels[2].count, 48u);
            EXPECT_EQ(d.levels[3].count, 1u);
            expectAllFinite(d);
            for (std::size_t k = 0; k < d.levels.size(); ++k)
            {
                double weight = 0.0;
                for (std::uint32_t i = d.levels[k].first; i < d.levels[k].first + d.levels[k].count; ++i)
                    weight += d.ellipsoids[i].leafWeight;
                // Ellipsoids under 1 % of the largest's area are dropped with their weight.
                EXPECT_LE(weight, 200000.0 * 1.0001) << "level " << k;
                EXPECT_GE(weight, 200000.0 * (k == 0 ? 0.9999 : 0.9)) << "level " << k;
            }
            const std::vector<std::uint8_t> bytes = encodeEllipsoidTreeChunk(d);
            EXPECT_EQ(bytes.size(), d.encodedBytes());
            EXPECT_LT(bytes.size(), 28u * d.ellipsoids.size() + 1024u);
            Result<EllipsoidTreeData> back = decodeEllipsoidTreeChunk(bytes, "200k");
            ASSERT_TRUE(back.ok()) << back.error().message();
            EXPECT_EQ(back->ellipsoids.size(), d.ellipsoids.size());
        }

        /// Mean white over an image (flat white on black: the covered share).
        double meanWhite(const Image& image)
        {
            double sum = 0.0;
            for (const glm::vec4& p : image.pixels)
                sum += srgbToLinear(p.r);
            return sum / double(std::max<std::size_t>(image.pixels.size(), 1));
        }

        /// A side view of the oak's ellipsoids, flat white on black (the baker's coverage images).
        RenderOptions coverageOptions(int size)
        {
            RenderOptions o = albedoRenderOptions(size, size, 4);
            o.transparentBackground = false;
            o.lighting.background = glm::vec3(0.0f);
            return o;
        }

        // Without noise, the CPU ray caster the noise is calibrated with covers what the
        // ellipsoids' icosphere meshes cover (which the scale calibration renders), level by level
        // and in a perspective view too.
        TEST(EllipsoidTreeBake, rayCastEllipsoidsCoverWhatTheirMeshesCover)
        {
            const EllipsoidTreeData& d = oakBake();
            const TreeModel& oak = generatedOak(256);
            for (std::size_t level = 0; level < d.levels.size(); ++level)
            {
                const EllipsoidLevel& l = d.levels[level];
                const std::vector<Ellipsoid> ellipsoids(d.ellipsoids.begin() + l.first,
                                                        d.ellipsoids.begin() + l.first + l.count);
                for (bool orthographic : {true, false})
                {
                    CameraSpec camera = CameraSpec::framing(oak.boundsMin, oak.boundsMax, 30.0f, 10.0f);
                    if (orthographic)
                    {
                        camera.orthographic = true;
                        camera.orthoHeight = 1.2f * glm::length(oak.boundsMax - oak.boundsMin);
                    }
                    const RenderOptions options = coverageOptions(96);
                    const TreeModel mesh = ellipsoidLevelMesh(d, level);
                    const double meshCover = meanWhite(ReferenceRenderer(mesh).render(camera, options).colour);
                    const double rayCover = meanWhite(renderEllipsoids(ellipsoids, l.scale, {}, camera, options));
                    EXPECT_GT(meshCover, 0.01) << "level " << level;
                    EXPECT_NEAR(rayCover, meshCover, 0.04 * meshCover + 0.002)
                        << "level " << level << (orthographic ? " orthographic" : " perspective");
                }
            }
        }

        // The noise (§3.1, Fig. 6): at the finest lod the texels are uniform and symmetric about
        // 0.5, so t = 0.5 opens half of the surface (the paper's "half of the texels are
        // discarded"); seen through, the far side fills part of each hole, so the covered share of
        // one large sphere lies between 1/2 and 3/4. Bilinear filtering concentrates the values
        // near 0.5, so t = 0.25 opens less than a quarter, but some. Coarser lods average the noise
        // towards 0.5: t = 0.25 then opens almost nothing. The normal blend changes the
        // shading but not the coverage. The maps are the same bytes on every call.
        TEST(EllipsoidTreeBake, noiseOpensHolesByThresholdAndLod)
        {
            const EllipsoidNoiseMaps& maps = ellipsoidNoiseMaps();
            ASSERT_EQ(&maps, &ellipsoidNoiseMaps());
            double mean = 0.0;
            for (std::uint8_t a : maps.alpha[0][0])
                mean += a / 255.0;
            EXPECT_NEAR(mean / double(maps.alpha[0][0].size()), 0.5, 0.01);
            EXPECT_EQ(maps.alpha[ELLIPSOID_NOISE_LEVELS - 1][0].size(), 1u);
            EXPECT_NEAR(ellipsoidNoiseBaseLod(1.0f), 7.5f, 1e-5f);    // l_j = 0.5
            EXPECT_NEAR(ellipsoidNoiseBaseLod(512.0f), 3.0f, 1e-5f);  // l_j = 5
            EXPECT_NEAR(ellipsoidNoiseBaseLod(0.0f), 8.0f, 1e-5f);    // clamped
            EXPECT_NEAR(ellipsoidNoiseFootprintLod(2.0f / 256.0f, 1.0f), 0.0f, 1e-5f);

            Ellipsoid sphere;
            sphere.radii = glm::vec3(1.0f);
            sphere.leafWeight = 1e6f; // the finest lod
            CameraSpec camera;
            camera.orthographic = true;
            camera.position = glm::vec3(0, 0, 5);
            camera.target = glm::vec3(0.0f);
            camera.orthoHeight = 1.0f; // the middle of the sphere, where the texels are about a pixel
            const RenderOptions options = coverageOptions(128);
            const double full = meanWhite(renderEllipsoids({sphere}, 1.0f, {}, camera, options));
            double covered[2];
            for (int k = 0; k < 2; ++k)
            {
                EllipsoidNoiseSetting noise;
                noise.threshold = k == 0 ? 0.25f : 0.5f;
                covered[k] = meanWhite(renderEllipsoids({sphere}, 1.0f, noise, camera, options)) / full;
            }
            EXPECT_GT(covered[1], 0.5 - 0.03);
            EXPECT_LT(covered[1], 0.75 + 0.03);
            EXPECT_LT(covered[0], 0.995);
            EXPECT_GT(covered[0], covered[1] + 0.1);
            sphere.leafWeight = 4.0f; // l_j = 1.5: 6.5 levels coarser, the noise near 0.5 everywhere
            EllipsoidNoiseSetting quarter;
            quarter.threshold = 0.25f;
            EXPECT_GT(meanWhite(renderEllipsoids({sphere}, 1.0f, quarter, camera, options)) / full, 0.97);
            // The footprint: pixels as large as the sphere average the noise as much.
            sphere.leafWeight = 1e6f;
            quarter.pixelSize = 0.5f;
            EXPECT_GT(meanWhite(renderEllipsoids({sphere}, 1.0f, quarter, camera, options)) / full, 0.97);

            RenderOptions shaded = options;
            shaded.lighting = LightingSpec{};
            shaded.lighting.background = glm::vec3(0.0f);
            EllipsoidNoiseSetting blend;
            blend.normalBlend = 0.7f;
            const Image smooth = renderEllipsoids({sphere}, 1.0f, {}, camera, shaded);
            const Image rough = renderEllipsoids({sphere}, 1.0f, blend, camera, shaded);
            double difference = 0.0;
            for (std::size_t i = 0; i < smooth.pixels.size(); ++i)
                difference += std::abs(smooth.pixels[i].r - rough.pixels[i].r);
            EXPECT_GT(difference / double(smooth.pixels.size()), 0.02);
            EXPECT_NEAR(meanWhite(renderEllipsoids({sphere}, 1.0f, blend, camera, options)), full, 1e-6);
        }

        // Each level's noise is calibrated (the chosen threshold, compensation and blend from the
        // candidates, stored and round-tripped) and holds beyond the baker's four views: in two views
        // it did not use, the levels with their noise sum to less error than the levels of a bake
        // without it (measured 0.351 against 0.370), none worse by more than 10 % (measured at most
        // +4 %, level 1). A threshold of 0.8 everywhere measured 0.18 a level. "noise=0" bakes none.
        TEST(EllipsoidTreeBake, calibratedNoiseIsStoredAndHoldsInOtherViews)
        {
            const EllipsoidTreeData& withNoise = oakBake();
            EllipsoidTreeOptions off = fastOptions();
            off.noise = false;
            const EllipsoidTreeData without = bakeOrFail(generatedOak(256), off);
            const TreeModel leaves = flatColourLeaves(generatedOak(256));
            ASSERT_EQ(withNoise.levels.size(), without.levels.size());
            int noisy = 0;
            double noisySum = 0.0, plainSum = 0.0;
            for (std::size_t k = 0; k < without.levels.size(); ++k)
            {
                const EllipsoidLevel& a = withNoise.levels[k];
                const EllipsoidLevel& b = without.levels[k];
                EXPECT_EQ(b.noiseThreshold, 0.0f);
                EXPECT_EQ(b.normalBlend, 0.0f);
                EXPECT_GE(a.noiseThreshold, 0.0f);
                EXPECT_LT(a.noiseThreshold, 1.0f);
                EXPECT_GE(a.scale, b.scale * 0.999f) << "the compensation only grows the ellipsoids";
                const double noisyError = unseenError(withNoise, k, leaves, true);
                const double plainError = unseenError(without, k, leaves, false);
                EXPECT_LT(noisyError, plainError * 1.1) << "level " << k;
                noisySum += noisyError;
                plainSum += plainError;
                noisy += a.noiseThreshold > 0.0f ? 1 : 0;
            }
            EXPECT_GT(noisy, 0) << "no level of the oak takes holes";
            EXPECT_LT(noisySum, plainSum);
            Result<EllipsoidTreeData> decoded = decodeEllipsoidTreeChunk(encodeEllipsoidTreeChunk(withNoise), "oak");
            ASSERT_TRUE(decoded.ok()) << decoded.error().message();
            for (std::size_t k = 0; k < withNoise.levels.size(); ++k)
            {
                EXPECT_EQ(decoded->levels[k].noiseThreshold, withNoise.levels[k].noiseThreshold);
                EXPECT_EQ(decoded->levels[k].normalBlend, withNoise.levels[k].normalBlend);
            }
        }

        // Encode, decode: equal to the quantisation (centre half a step of 65535 over the box, radii
        // 0.025 %, rotation 1/32767 per component), 28 bytes per ellipsoid, re-encoding identical.
        TEST(EllipsoidTreeBake, roundTripIsExactToTheQuantisation)
        {
            const EllipsoidTreeData& d = oakBake();
            const std::vector<std::uint8_t> bytes = encodeEllipsoidTreeChunk(d);
            EXPECT_EQ(bytes.size(), d.encodedBytes());
            const std::size_t header = bytes.size() - d.ellipsoids.size() * ELLIPSOID_RECORD_BYTES;
            EXPECT_LE(ELLIPSOID_RECORD_BYTES, 32u);
            EXPECT_EQ(header, 40u + ELLIPSOID_LEVEL_BYTES * d.levels.size());
            EXPECT_EQ(ELLIPSOID_LEVEL_BYTES, 28u);
            Result<EllipsoidTreeData> back = decodeEllipsoidTreeChunk(bytes, "round trip");
            ASSERT_TRUE(back.ok()) << back.error().message();
            ASSERT_EQ(back->ellipsoids.size(), d.ellipsoids.size());
            ASSERT_EQ(back->levels.size(), d.levels.size());
            for (std::size_t k = 0; k < d.levels.size(); ++k)
            {
                EXPECT_EQ(back->levels[k].first, d.levels[k].first);
                EXPECT_EQ(back->levels[k].count, d.levels[k].count);
                EXPECT_EQ(back->levels[k].scale, d.levels[k].scale);
                EXPECT_EQ(back->levels[k].targetHeightPx, d.levels[k].targetHeightPx);
                EXPECT_EQ(back->levels[k].imageError, d.levels[k].imageError);
                EXPECT_EQ(back->levels[k].noiseThreshold, d.levels[k].noiseThreshold);
                EXPECT_EQ(back->levels[k].normalBlend, d.levels[k].normalBlend);
            }
            for (std::size_t i = 0; i < d.ellipsoids.size(); ++i)
            {
                const Ellipsoid &a = d.ellipsoids[i], &b = back->ellipsoids[i];
                for (int k = 0; k < 3; ++k)
                {
                    EXPECT_LE(std::abs(a.centre[k] - b.centre[k]), ellipsoidCentreStep(d, k) * 1.01f + 1e-6f) << i;
                    EXPECT_LE(std::abs(a.radii[k] / b.radii[k] - 1.0f), ELLIPSOID_RADIUS_RELATIVE_STEP * 0.5f) << i;
                }
                const glm::mat3 ra = glm::mat3_cast(a.rotation), rb = glm::mat3_cast(b.rotation);
                for (int c = 0; c < 3; ++c)
                    for (int r = 0; r < 3; ++r)
                        EXPECT_NEAR(ra[c][r], rb[c][r], 4.0f / 32767.0f) << i;
                EXPECT_EQ(a.colour, b.colour);
                EXPECT_EQ(a.leafWeight, b.leafWeight);
            }
            // Re-encoding the decoded chunk gives the same bytes, but for a rotation code moved by one
            // where the decoder's normalisation rounds the other way.
            const std::vector<std::uint8_t> again = encodeEllipsoidTreeChunk(back.value());
            ASSERT_EQ(again.size(), bytes.size());
            for (std::size_t at = 0; at < bytes.size(); ++at)
            {
                const bool rotation = at >= header && (at - header) % ELLIPSOID_RECORD_BYTES >= 12 &&
                                      (at - header) % ELLIPSOID_RECORD_BYTES < 20;
                if (!rotation)
                    EXPECT_EQ(again[at], bytes[at]) << "byte " << at;
                else if (((at - header) % 2) == 0)
                {
                    const int was = std::int16_t(bytes[at] | bytes[at + 1] << 8);
                    const int now = std::int16_t(again[at] | again[at + 1] << 8);
                    EXPECT_LE(std::abs(was - now), 1) << "byte " << at;
                }
            }
        }

        void expectFailure(const std::vector<std::uint8_t>& bytes, const std::string& element, const std::string& reason)
        {
            Result<EllipsoidTreeData> r = decodeEllipsoidTreeChunk(bytes, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element;
            EXPECT_EQ(r.error().file, "bad.treelod");
            EXPECT_NE(r.error().element.find(element), std::string::npos) << r.error().message();
            EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
        }

        void putF32(std::vector<std::uint8_t>& bytes, std::size_t at, float v) { std::memcpy(&bytes[at], &v, 4); }
        void putU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t v) { std::memcpy(&bytes[at], &v, 4); }

        // Every kind of damage is an error that names the element (little-endian host assumed).
        TEST(EllipsoidTreeBake, corruptChunksAreNamed)
        {
            const EllipsoidTreeData& d = oakBake();
            const std::vector<std::uint8_t> good = encodeEllipsoidTreeChunk(d);
            const std::size_t levels = 36, records = 40 + ELLIPSOID_LEVEL_BYTES * d.levels.size();
            const std::size_t level1 = levels + ELLIPSOID_LEVEL_BYTES, record3 = records + 3 * ELLIPSOID_RECORD_BYTES;

            for (std::size_t cut : {std::size_t(0), std::size_t(10), levels + 2, level1 + 6, records - 2, record3 + 5,
                                    good.size() - 1})
                expectFailure(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(cut)), "chunk",
                              "needs"); // "truncated: needs N bytes" or "count N ... needs N bytes"
            std::vector<std::uint8_t> b = good;
            b.push_back(0);
            expectFailure(b, "chunk", "1 trailing bytes");
            b = good;
            putU32(b, 0, 4);
            expectFailure(b, "chunk", "unknown flags 4");
            b = good;
            putF32(b, 4, std::nanf(""));
            expectFailure(b, "bounds", "not finite");
            b = good;
            putF32(b, 28, 0.0f);
            expectFailure(b, "bounds", "radius unit");
            b = good;
            putU32(b, levels - 4 + 0, 0);
            expectFailure(b, "levels", "0 levels");
            b = good;
            putF32(b, level1 + 8, std::nanf(""));
            expectFailure(b, "level 1", "scale");
            b = good;
            putF32(b, level1 + 12, -3.0f);
            expectFailure(b, "level 1", "target height");
            b = good;
            putF32(b, level1 + 16, std::numeric_limits<float>::infinity());
            expectFailure(b, "level 1", "image error");
            b = good;
            putF32(b, level1 + 20, 1.0f);
            expectFailure(b, "level 1", "noise threshold");
            b = good;
            putF32(b, level1 + 24, std::nanf(""));
            expectFailure(b, "level 1", "normal blend");
            b = good;
            putU32(b, level1, d.levels[1].first + 1);
            expectFailure(b, "level 1", "contiguous");
            b = good;
            putU32(b, level1 + 4, 0);
            expectFailure(b, "level 1", "no ellipsoids");
            b = good;
            putU32(b, levels + ELLIPSOID_LEVEL_BYTES * (d.levels.size() - 1) + 4, d.levels.back().count + 1);
            expectFailure(b, "level " + std::to_string(d.levels.size() - 1), "run past");
            b = good;
            putU32(b, records - 4, std::uint32_t(d.ellipsoids.size() + 1));
            expectFailure(b, "ellipsoids", "count");
            b = good;
            std::fill(b.begin() + std::ptrdiff_t(record3 + 12), b.begin() + std::ptrdiff_t(record3 + 20), 0);
            expectFailure(b, "ellipsoid 3", "rotation");
            b = good;
            putF32(b, record3 + 24, std::nanf(""));
            expectFailure(b, "ellipsoid 3", "leaf weight");
            b = good;
            putF32(b, record3 + 24, -1.0f);
            expectFailure(b, "ellipsoid 3", "leaf weight");
        }

        // The same seed gives the same bytes, with 1 and 2 TBB threads; another seed moves the starts.
        TEST(EllipsoidTreeBake, deterministicForSeedAndThreads)
        {
            const TreeModel& oak = generatedOak(256);
            const std::vector<std::uint8_t> reference = encodeEllipsoidTreeChunk(oakBake());
            std::vector<std::uint8_t> one, two;
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
                one = encodeEllipsoidTreeChunk(bakeOrFail(oak));
            }
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
                two = encodeEllipsoidTreeChunk(bakeOrFail(oak));
            }
            EXPECT_EQ(one, reference);
            EXPECT_EQ(two, reference);
            EllipsoidTreeOptions other = fastOptions();
            other.seed = 99;
            EXPECT_NE(encodeEllipsoidTreeChunk(bakeOrFail(oak, other)), reference);
        }

        // Each level's rendered coverage (from two side views the baker did not use) against the
        // leaves': one ellipsoid per leaf measured 1.06 times it, the clusters 1.16 to 1.39 (opaque
        // ellipsoids against sparse leaves: the calibration minimises image error, not coverage).
        // The baker's own error of every level is at most 0.6 times that of an empty image in its
        // views (measured 0.11 to 0.49 times). Ellipsoids at 0.8 times their scale measured 0.75 to
        // 0.93 times the leaves' coverage.
        TEST(EllipsoidTreeBake, everyLevelCoversWhatTheLeavesCover)
        {
            const TreeModel& oak = generatedOak(256);
            const EllipsoidTreeData& d = oakBake();
            const TreeModel leaves = flatColourLeaves(oak);
            for (float azimuth : {45.0f, 200.0f})
            {
                const double reference = coverage(leaves, leaves.boundsMin, leaves.boundsMax, azimuth);
                ASSERT_GT(reference, 0.05);
                for (std::size_t k = 0; k < d.levels.size(); ++k)
                {
                    const double c = coverage(ellipsoidLevelMesh(d, k), leaves.boundsMin, leaves.boundsMax, azimuth);
                    if (k == 0)
                        EXPECT_NEAR(c / reference, 1.06, 0.1) << "azimuth " << azimuth << ": " << c << " vs " << reference;
                    else
                    {
                        EXPECT_GT(c / reference, 1.0) << "level " << k << ", azimuth " << azimuth;
                        EXPECT_LT(c / reference, 1.55) << "level " << k << ", azimuth " << azimuth;
                    }
                }
            }
            // The baker's own error, against an empty image's in the baker's views.
            const glm::vec3 lo = leaves.boundsMin, hi = leaves.boundsMax;
            const RenderOptions options = EllipsoidErrorViews::renderOptions(EllipsoidTreeOptions().viewResolution);
            const ReferenceRenderer renderer(leaves);
            double empty = 0.0;
            const std::vector<CameraSpec> views = EllipsoidErrorViews::cameras(0.5f * (lo + hi), 0.5f * glm::length(hi - lo));
            for (const CameraSpec& c : views)
            {
                const Image image = renderer.render(c, options).colour;
                Image black = image;
                for (glm::vec4& p : black.pixels)
                    p = glm::vec4(0, 0, 0, 1);
                Result<MultiScaleRmseResult> e = multiScaleRmse(image, black);
                ASSERT_TRUE(e.ok());
                empty += e->combined;
            }
            empty /= double(views.size());
            for (std::size_t k = 0; k < d.levels.size(); ++k)
            {
                EXPECT_GT(d.levels[k].imageError, 0.0f);
                EXPECT_LT(d.levels[k].imageError, 0.6 * empty) << "level " << k << ", an empty image: " << empty;
                EXPECT_GE(d.levels[k].scale, 0.3f); // leaves alpha-tested inside their quads: under 1
                EXPECT_LE(d.levels[k].scale, 1.5f);
            }
        }

        // A 0.5 m and a 500 m tree: the same levels, scales and errors, and the same ellipsoids
        // relative to the tree's size.
        TEST(EllipsoidTreeBake, scaleFree)
        {
            const TreeModel small = scaled(generatedOak(128), 0.5f / generatedOak(128).boundsMax.y);
            const TreeModel large = scaled(small, 1000.0f);
            const EllipsoidTreeData a = bakeOrFail(small), b = bakeOrFail(large);
            ASSERT_EQ(a.levels.size(), b.levels.size());
            for (std::size_t k = 0; k < a.levels.size(); ++k)
            {
                EXPECT_EQ(a.levels[k].count, b.levels[k].count) << "level " << k;
                EXPECT_NEAR(a.levels[k].scale, b.levels[k].scale, 1e-6f) << "level " << k;
                EXPECT_NEAR(a.levels[k].imageError, b.levels[k].imageError, 1e-3f) << "level " << k;
                EXPECT_NEAR(a.levels[k].targetHeightPx / b.levels[k].targetHeightPx, 1.0f, 1e-3f) << "level " << k;
            }
            ASSERT_EQ(a.ellipsoids.size(), b.ellipsoids.size());
            EXPECT_NEAR(b.radiusUnit / a.radiusUnit, 1000.0f, 0.01f);
            for (std::size_t i = 0; i < a.ellipsoids.size(); ++i)
            {
                EXPECT_LT(glm::distance(1000.0f * a.ellipsoids[i].centre, b.ellipsoids[i].centre), 1e-3f * b.radiusUnit) << i;
                for (int k = 0; k < 3; ++k)
                    EXPECT_NEAR(1000.0f * a.ellipsoids[i].radii[k] / b.ellipsoids[i].radii[k], 1.0f, 1e-3f) << i;
            }
        }

        // The oak 10 km from the origin (floats step by 1 mm there, a hundredth of a leaf's size):
        // the same levels, scales and image errors. Level 0 is one ellipsoid per leaf: the same
        // ones moved by the offset, the two large semi-axes as they were (the third, a leaf's
        // thickness, is the floor of 2 % of its size, which a millimetre of rounding doubles); the
        // coarser levels' clusters may settle elsewhere, as good.
        TEST(EllipsoidTreeBake, farFromTheOriginTheSameEllipsoids)
        {
            const glm::vec3 offset(1.0e4f, 0.0f, -1.0e4f);
            const EllipsoidTreeData& a = smallOakBake();
            const EllipsoidTreeData b = bakeOrFail(test::translated(generatedOak(128), offset));
            ASSERT_EQ(a.levels.size(), b.levels.size());
            for (std::size_t k = 0; k < a.levels.size(); ++k)
            {
                EXPECT_EQ(a.levels[k].count, b.levels[k].count) << "level " << k;
                EXPECT_NEAR(a.levels[k].scale, b.levels[k].scale, 0.02f) << "level " << k;
                EXPECT_NEAR(a.levels[k].imageError, b.levels[k].imageError, 2e-3f) << "level " << k;
            }
            ASSERT_EQ(a.ellipsoids.size(), b.ellipsoids.size());
            double worstCentre = 0.0, worstRadius = 0.0;
            for (std::uint32_t i = a.levels[0].first; i < a.levels[0].first + a.levels[0].count; ++i)
            {
                worstCentre = std::max(worstCentre, double(glm::distance(a.ellipsoids[i].centre + offset, b.ellipsoids[i].centre)));
                glm::vec3 ra = a.ellipsoids[i].radii, rb = b.ellipsoids[i].radii;
                std::sort(&ra[0], &ra[0] + 3);
                std::sort(&rb[0], &rb[0] + 3);
                for (int k = 1; k < 3; ++k)
                    worstRadius = std::max(worstRadius, double(std::abs(ra[k] / rb[k] - 1.0f)));
            }
            EXPECT_LT(worstCentre, 0.005); // measured 1.4 mm
            EXPECT_LT(worstRadius, 0.01);  // measured 0.1 %
        }

        // Leaves of zero area (a quad folded onto a line) among the oak's are left out: the bake is
        // the oak's alone, byte for byte.
        TEST(EllipsoidTreeBake, zeroAreaLeavesAmongNormalOnesAreLeftOut)
        {
            const TreeModel& oak = generatedOak(128);
            TreeModel withDegenerate = oak;
            const glm::vec3 centre = 0.5f * (oak.boundsMin + oak.boundsMax);
            for (int i = 0; i < 16; ++i)
                test::addQuadLeaf(withDegenerate, centre + glm::vec3(0.1f * float(i), 0.0f, 0.0f), glm::vec3(0.1f, 0, 0),
                                  glm::vec3(0.0f), glm::vec3(0, 0, 1));
            withDegenerate.updateBounds();
            ASSERT_EQ(withDegenerate.leaves.size(), oak.leaves.size() + 16);
            EXPECT_EQ(encodeEllipsoidTreeChunk(bakeOrFail(withDegenerate)), encodeEllipsoidTreeChunk(smallOakBake()));
        }

        // §5's AO: none without rays (255); with rays the crown's inside is darker than its rim, the
        // last level's single ellipsoid (only the bark inside it) is open, and the values do not
        // depend on the thread count.
        TEST(EllipsoidTreeBake, ambientOcclusionDarkensTheCrownsInside)
        {
            const TreeModel& oak = generatedOak(256);
            for (const Ellipsoid& e : oakBake().ellipsoids)
                ASSERT_EQ(e.colour[3], 255u);
            EllipsoidTreeData one = oakBake(), two = oakBake();
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
                addEllipsoidAmbientOcclusion(one, oak, 32, 1);
            }
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
                addEllipsoidAmbientOcclusion(two, oak, 32, 1);
            }
            for (std::size_t i = 0; i < one.ellipsoids.size(); ++i)
                ASSERT_EQ(one.ellipsoids[i].colour[3], two.ellipsoids[i].colour[3]) << "ellipsoid " << i;
            // Level 0: the quarter nearest the crown's centre against the farthest quarter.
            const EllipsoidLevel& leaves = one.levels[0];
            glm::vec3 centre(0.0f);
            for (std::uint32_t e = leaves.first; e < leaves.first + leaves.count; ++e)
                centre += one.ellipsoids[e].centre / float(leaves.count);
            std::vector<std::pair<float, float>> byDistance; // distance, AO
            for (std::uint32_t e = leaves.first; e < leaves.first + leaves.count; ++e)
                byDistance.emplace_back(glm::distance(one.ellipsoids[e].centre, centre),
                                        float(one.ellipsoids[e].colour[3]) / 255.0f);
            std::sort(byDistance.begin(), byDistance.end());
            const std::size_t quarter = byDistance.size() / 4;
            double inner = 0.0, outer = 0.0;
            for (std::size_t i = 0; i < quarter; ++i)
            {
                inner += byDistance[i].second / double(quarter);
                outer += byDistance[byDistance.size() - 1 - i].second / double(quarter);
            }
            const Ellipsoid& last = one.ellipsoids[one.levels.back().first];
            std::printf("AO: inner quarter %.3f, outer quarter %.3f, the last level's ellipsoid %.3f\n", inner, outer,
                        double(last.colour[3]) / 255.0);
            EXPECT_LT(inner, outer - 0.1);
            EXPECT_GT(outer, 0.5);
            EXPECT_GT(last.colour[3], 0.9 * 255);
        }

        // Points inside another ellipsoid are not counted (§5): two unit spheres overlapping by half
        // see the open sky from every point outside the other, bar the rays near the seam.
        TEST(EllipsoidTreeBake, ambientOcclusionSkipsPointsInsideOtherEllipsoids)
        {
            EllipsoidTreeData d;
            d.levels.push_back(EllipsoidLevel{0, 2, 1.0f, 10.0f, 0.0f});
            for (const float x : {-0.5f, 0.5f})
            {
                Ellipsoid e;
                e.centre = glm::vec3(x, 0.0f, 0.0f);
                e.radii = glm::vec3(1.0f);
                e.leafWeight = 1.0f;
                d.ellipsoids.push_back(e);
            }
            TreeModel empty = emptyLeafModel();
            addEllipsoidAmbientOcclusion(d, empty, 64, 1);
            const double a = d.ellipsoids[0].colour[3] / 255.0, b = d.ellipsoids[1].colour[3] / 255.0;
            std::printf("AO of two overlapping spheres: %.3f, %.3f\n", a, b);
            EXPECT_GT(a, 0.75);
            EXPECT_GT(b, 0.75);
            EXPECT_NEAR(a, b, 0.1);
        }

        // `treelod bake` finds the baker and its options; `treelod info` describes the chunk; bad
        // options and a leafless model are errors that name them.
        TEST(EllipsoidTreeBake, registeredAndErrorsNamed)
        {
            const BakeTechnique* baker = findBakeTechnique("ellipsoids");
            ASSERT_NE(baker, nullptr);
            std::vector<std::string> names;
            for (const BakeOptionInfo& o : baker->options)
                names.push_back(o.name);
            for (const char* name : {"tries", "seed", "clustersDivisor", "minAreaShare"})
                EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
            const TechniqueDescriptor* descriptor = findTechniqueDescriptor("ellipsoids");
            ASSERT_NE(descriptor, nullptr);
            EXPECT_EQ(descriptor->formatVersion, ELLIPSOID_TREE_CHUNK_FORMAT_VERSION);
            Result<ChunkSummary> summary = descriptor->inspect(encodeEllipsoidTreeChunk(oakBake()), "oak");
            ASSERT_TRUE(summary.ok()) << summary.error().message();
            EXPECT_NE(summary->text.find("256 (x"), std::string::npos) << summary->text;
            EXPECT_NE(summary->text.find("28 per ellipsoid"), std::string::npos) << summary->text;

            PackageWriter writer;
            Result<void> bad = baker->bake(writer, generatedOak(256), {{"tries", "0"}}, "oak.treelod", {});
            ASSERT_FALSE(bad.ok());
            EXPECT_NE(bad.error().element.find("ellipsoids.tries"), std::string::npos) << bad.error().message();
            bad = baker->bake(writer, generatedOak(256), {{"tries", "1.5"}}, "oak.treelod", {});
            ASSERT_FALSE(bad.ok());
            EXPECT_NE(bad.error().reason.find("whole"), std::string::npos) << bad.error().message();

            Result<EllipsoidTreeData> leafless = bakeEllipsoidTree(emptyLeafModel(), fastOptions(), "bare.glb");
            ASSERT_FALSE(leafless.ok());
            EXPECT_EQ(leafless.error().file, "bare.glb");
            EXPECT_NE(leafless.error().reason.find("no leaves"), std::string::npos);
        }
    }
}
