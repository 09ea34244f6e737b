// ForestInstances: culling, LoD selection and bucketing against brute-force references
// computed independently in double precision.
#include "TreeLod/ForestInstances.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// A random camera: anywhere within `extent` of the origin, perspective or orthographic.
        struct TestCamera
        {
            glm::mat4 view, projection;
            float width, height;
        };

        TestCamera randomCamera(std::mt19937& rng, float extent, bool orthographic)
        {
            std::uniform_real_distribution<float> u(-1.0f, 1.0f), unit(0.0f, 1.0f);
            glm::vec3 eye(extent * u(rng), 0.1f * extent * u(rng), extent * u(rng));
            glm::vec3 dir;
            do
                dir = glm::vec3(u(rng), 0.5f * u(rng), u(rng));
            while (glm::length(dir) < 0.1f);
            TestCamera c;
            c.width = 200.0f + 1800.0f * unit(rng);
            c.height = 200.0f + 1000.0f * unit(rng);
            c.view = glm::lookAt(eye, eye + dir, glm::vec3(0, 1, 0));
            const float nearClip = 0.05f + 5.0f * unit(rng), farClip = 50.0f + 20000.0f * unit(rng);
            const float aspect = c.width / c.height;
            if (orthographic)
            {
                const float h = 5.0f + 2000.0f * unit(rng);
                c.projection = glm::ortho(-h * aspect, h * aspect, -h, h, nearClip, farClip);
            }
            else
                c.projection = glm::perspective(glm::radians(15.0f + 90.0f * unit(rng)), aspect, nearClip, farClip);
            return c;
        }

        /// Frustum planes from the eight corners of the unprojected NDC cube (double), each
        /// oriented towards the frustum's centroid: a derivation independent of the matrix rows.
        std::array<glm::dvec4, 6> cornerPlanes(const TestCamera& c)
        {
            const glm::dmat4 inv = glm::inverse(glm::dmat4(c.projection) * glm::dmat4(c.view));
            glm::dvec3 corner[8];
            glm::dvec3 centroid(0.0);
            for (int i = 0; i < 8; ++i)
            {
                glm::dvec4 p = inv * glm::dvec4((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0, 1.0);
                corner[i] = glm::dvec3(p) / p.w;
                centroid += corner[i] / 8.0;
            }
            // Faces as corner indices: x = -1, x = 1, y = -1, y = 1, z = -1, z = 1.
            const int faces[6][3] = {{0, 2, 4}, {1, 3, 5}, {0, 1, 4}, {2, 3, 6}, {0, 1, 2}, {4, 5, 6}};
            std::array<glm::dvec4, 6> planes;
            for (int f = 0; f < 6; ++f)
            {
                const glm::dvec3 a = corner[faces[f][0]], b = corner[faces[f][1]], d = corner[faces[f][2]];
                glm::dvec3 n = glm::normalize(glm::cross(b - a, d - a));
                double w = -glm::dot(n, a);
                if (glm::dot(n, centroid) + w < 0.0)
                    n = -n, w = -w;
                planes[f] = glm::dvec4(n, w);
            }
            return planes;
        }

        /// Reference test: 1 visible, 0 culled, -1 too close to a plane to call in float.
        int referenceVisible(const std::array<glm::dvec4, 6>& planes, const glm::dvec3& centre, double radius,
                             double tolerance)
        {
            bool inside = true, borderline = false;
            for (const glm::dvec4& p : planes)
            {
                const double margin = glm::dot(glm::dvec3(p), centre) + p.w + radius;
                borderline |= std::abs(margin) < tolerance;
                inside &= margin >= 0.0;
            }
            return borderline ? -1 : (inside ? 1 : 0);
        }

        ForestKind pixelKind(const std::string& name, std::vector<float> thresholds)
        {
            ForestKind kind;
            kind.name = name;
            kind.boundsCentre = glm::vec3(0.3f, 5.0f, -0.2f);
            kind.boundsRadius = 6.0f;
            kind.thresholds = std::move(thresholds);
            return kind;
        }

        ForestKind distanceKind(const std::string& name, std::vector<float> thresholds)
        {
            ForestKind kind = pixelKind(name, std::move(thresholds));
            kind.lodMode = ForestLodMode::Distance;
            return kind;
        }

        /// Four kinds: three pixel-count tables and one distance table.
        void addKinds(ForestInstances& forest)
        {
            ASSERT_TRUE(forest.addKind(pixelKind("oak/lodf", {2e5f, 2e4f, 2e3f})));
            ASSERT_TRUE(forest.addKind(pixelKind("pine/billboard-cloud", {5e4f, 5e2f})));
            ASSERT_TRUE(forest.addKind(pixelKind("birch/mesh", {})));
            ASSERT_TRUE(forest.addKind(distanceKind("oak/distance", {1e4f, 1e5f, 1e6f})));
        }

        /// Random instances in a square of `extent` metres, scales 0.5 m-ish to 500 m-ish trees.
        std::vector<ForestInstance> randomInstances(std::mt19937& rng, std::size_t count, float extent,
                                                    std::uint32_t kinds)
        {
            std::uniform_real_distribution<float> u(-1.0f, 1.0f), unit(0.0f, 1.0f);
            std::vector<ForestInstance> out(count);
            for (ForestInstance& i : out)
            {
                i.position = glm::vec3(extent * u(rng), 0.05f * extent * u(rng), extent * u(rng));
                i.rotationY = glm::pi<float>() * u(rng);
                i.scale = std::pow(10.0f, -1.1f + 3.0f * unit(rng)); // radius 6 m x 0.08 .. 80
                i.kind = std::uint32_t(rng() % kinds);
            }
            return out;
        }

        /// Level from a table, in double: the header's rule.
        std::uint32_t referenceLevel(const ForestKind& kind, double value, bool& borderline)
        {
            borderline = false;
            std::uint32_t level = std::uint32_t(kind.thresholds.size());
            bool found = false;
            for (std::uint32_t l = 0; l < kind.thresholds.size(); ++l)
            {
                const double t = kind.thresholds[l];
                borderline |= std::abs(value - t) <= 1e-4 * std::max(t, 1e-3);
                const bool use = kind.lodMode == ForestLodMode::Distance ? value <= t : value >= t;
                if (use && !found)
                    level = l, found = true;
            }
            return level;
        }

        /// The header's LoD value, in double, from the matrices.
        double referenceValue(const ForestKind& kind, const ForestInstance& i, const TestCamera& c, double bias)
        {
            const glm::dvec3 eye = glm::dvec3(glm::inverse(glm::dmat4(c.view))[3]);
            const double d2 = glm::dot(glm::dvec3(i.position) - eye, glm::dvec3(i.position) - eye);
            if (kind.lodMode == ForestLodMode::Distance)
                return d2 / bias;
            const double r = double(kind.boundsRadius) * i.scale;
            const double pixels = glm::pi<double>() * r * r * c.width * c.height * double(c.projection[0][0]) *
                                  double(c.projection[1][1]) * bias;
            if (c.projection[3][3] != 0.0f)
                return pixels;
            return d2 > 1.1920929e-7 ? pixels / d2 : std::numeric_limits<double>::max();
        }

        /// Level of each instance from the buckets; -1 where culled. Checks the buckets' shape.
        std::vector<int> levelsFromBuckets(const ForestInstances& forest, const ForestVisibility& vis)
        {
            std::vector<int> level(forest.size(), -1);
            std::uint32_t expectedFirst = 0, b = 0;
            for (std::uint32_t k = 0; k < forest.getKindCount(); ++k)
                for (std::uint32_t l = 0; l < forest.getLevelCount(k); ++l, ++b)
                {
                    const ForestBucket& bucket = vis.getBucket(b);
                    EXPECT_EQ(bucket.kind, k);
                    EXPECT_EQ(bucket.level, l);
                    EXPECT_EQ(bucket.first, expectedFirst);
                    EXPECT_EQ(forest.getBucketIndex(k, l), b);
                    expectedFirst += bucket.count;
                    for (std::uint32_t j = 0; j < bucket.count; ++j)
                    {
                        const std::uint32_t index = vis.getBucketIndices(b)[j];
                        EXPECT_LT(index, forest.size());
                        if (index >= forest.size())
                            continue;
                        EXPECT_EQ(level[index], -1) << "instance " << index << " in two buckets";
                        EXPECT_EQ(forest.getAt(index).kind, k) << "instance " << index << " in another kind's bucket";
                        level[index] = int(l);
                    }
                }
            EXPECT_EQ(b, vis.getBucketCount());
            EXPECT_EQ(expectedFirst, vis.getVisibleCount());
            EXPECT_EQ(vis.getVisibleCount() + vis.getCulledCount(), forest.size());
            return level;
        }
    }

    TEST(ForestInstances, cullingMatchesPlanesBuiltFromTheFrustumCorners)
    {
        // Random instances (spheres 0.5 m to 500 m across) and random cameras, perspective and
        // orthographic, some kilometres away; the reference derives the planes from the corners.
        std::mt19937 rng(7);
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(randomInstances(rng, 4000, 3000.0f, forest.getKindCount())));
        ForestVisibility vis;
        std::size_t compared = 0, borderline = 0, visibleSeen = 0;
        for (int cam = 0; cam < 40; ++cam)
        {
            const TestCamera c = randomCamera(rng, cam < 30 ? 3000.0f : 8000.0f, cam % 4 == 3);
            const std::array<glm::dvec4, 6> planes = cornerPlanes(c);
            const glm::dvec3 eye = glm::dvec3(glm::inverse(glm::dmat4(c.view))[3]);
            ASSERT_TRUE(forest.cull(CullCamera::fromMatrices(c.view, c.projection, c.width, c.height), 1.0f, vis));
            const std::vector<int> level = levelsFromBuckets(forest, vis);
            for (std::size_t i = 0; i < forest.size(); ++i)
            {
                const glm::vec4 s = forest.getWorldSphere(i);
                const glm::dvec3 centre(s);
                const double tolerance = 1e-5 * (glm::length(centre) + glm::length(eye) + s.w) + 1e-4;
                const int expected = referenceVisible(planes, centre, s.w, tolerance);
                if (expected < 0)
                {
                    ++borderline;
                    continue;
                }
                ++compared;
                visibleSeen += expected;
                EXPECT_EQ(level[i] >= 0, expected == 1) << "camera " << cam << " instance " << i;
            }
        }
        EXPECT_GT(visibleSeen, 1000u);
        EXPECT_LT(borderline, compared / 1000 + 1);
    }

    TEST(ForestInstances, spheresStraddlingAPlaneAreVisibleAndJustOutsideAreCulled)
    {
        // Spheres placed on each face of the frustum, their centres moved outwards by u * r:
        // u < 1 straddles the plane (visible), u > 1 is outside (culled).
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> u(-0.7, 0.7);
        const TestCamera c{glm::lookAt(glm::vec3(10, 20, 30), glm::vec3(400, 10, -300), glm::vec3(0, 1, 0)),
                           glm::perspective(glm::radians(60.0f), 1.5f, 0.5f, 900.0f), 1500.0f, 1000.0f};
        const glm::dmat4 inv = glm::inverse(glm::dmat4(c.projection) * glm::dmat4(c.view));
        const std::array<glm::dvec4, 6> planes = cornerPlanes(c);
        ForestInstances forest;
        ASSERT_TRUE(forest.addKind(pixelKind("unit", {})));
        std::vector<bool> expectVisible;
        for (int face = 0; face < 6; ++face)
            for (double outward : {-0.9, -0.5, 0.0, 0.5, 0.9, 1.1, 1.5, 3.0})
                for (double scale : {0.05, 1.0, 40.0})
                {
                    // A point on the face, well inside the other faces.
                    glm::dvec3 ndc(u(rng), u(rng), u(rng));
                    ndc[face / 2] = (face % 2) ? 1.0 : -1.0;
                    glm::dvec4 p = inv * glm::dvec4(ndc, 1.0);
                    const glm::dvec3 onFace = glm::dvec3(p) / p.w;
                    const double r = 6.0 * scale;
                    const glm::dvec3 centre = onFace - glm::dvec3(planes[face]) * (outward * r);
                    ForestInstance instance;
                    instance.scale = float(scale);
                    // The kind's local centre is (0.3, 5, -0.2): place the origin so the sphere sits at `centre`.
                    instance.position = glm::vec3(centre - scale * glm::dvec3(0.3, 5.0, -0.2));
                    ASSERT_TRUE(forest.add(instance));
                    // A large sphere near a face may reach past another plane: trust the reference there.
                    const int ref = referenceVisible(planes, glm::dvec3(forest.getWorldSphere(forest.size() - 1)),
                                                     forest.getWorldSphere(forest.size() - 1).w, 1e-3);
                    ASSERT_GE(ref, 0);
                    if (outward < 1.0)
                    {
                        EXPECT_EQ(ref, 1) << "face " << face << " outward " << outward;
                    }
                    expectVisible.push_back(ref == 1);
                }
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(CullCamera::fromMatrices(c.view, c.projection, c.width, c.height), 1.0f, vis));
        const std::vector<int> level = levelsFromBuckets(forest, vis);
        std::size_t culled = 0;
        for (std::size_t i = 0; i < forest.size(); ++i)
        {
            EXPECT_EQ(level[i] >= 0, expectVisible[i]) << "instance " << i;
            culled += expectVisible[i] ? 0 : 1;
        }
        EXPECT_GT(culled, 6u * 3u);
    }

    TEST(ForestInstances, cameraInsideASphereSeesItAndFarPlaneAtInfinityCullsNothingBehindIt)
    {
        ForestInstances forest;
        ASSERT_TRUE(forest.addKind(pixelKind("tree", {1e3f})));
        ForestInstance big;
        big.scale = 100.0f; // radius 600 m around (30, 500, -20)
        ASSERT_TRUE(forest.add(big));
        ForestInstance far;
        far.position = glm::vec3(0.0f, 0.0f, -1e6f); // 1000 km ahead
        ASSERT_TRUE(forest.add(far));
        ForestInstance behind;
        behind.position = glm::vec3(0.0f, 0.0f, 1e3f);
        ASSERT_TRUE(forest.add(behind));

        // Camera inside the big sphere, looking away from its centre, along -Z.
        const glm::mat4 view = glm::lookAt(glm::vec3(0, 100, 0), glm::vec3(0, 100, -1), glm::vec3(0, 1, 0));
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(
            CullCamera::fromMatrices(view, glm::infinitePerspective(glm::radians(50.0f), 1.0f, 0.1f), 800, 800), 1.0f,
            vis));
        std::vector<int> level = levelsFromBuckets(forest, vis);
        EXPECT_EQ(level, (std::vector<int>{0, 1, -1}));

        // The same with a finite far plane at 10 km culls the tree 1000 km away.
        ASSERT_TRUE(forest.cull(
            CullCamera::fromMatrices(view, glm::perspective(glm::radians(50.0f), 1.0f, 0.1f, 1e4f), 800, 800), 1.0f,
            vis));
        level = levelsFromBuckets(forest, vis);
        EXPECT_EQ(level, (std::vector<int>{0, -1, -1}));
    }

    TEST(ForestInstances, pixelCountIsFourPiProjectedRadiusSquared)
    {
        // fov 90 degrees, square 100 x 100 viewport: P00 = P11 = 1. A sphere of radius 1 at 10 m
        // projects to r_px = 1 * 50 / 10 = 5 pixels; Ogre's value 4 pi r_px^2 = 100 pi.
        ForestInstances forest;
        ForestKind kind = pixelKind("tree", {400.0f, 300.0f, 200.0f});
        kind.boundsCentre = glm::vec3(0.0f);
        kind.boundsRadius = 1.0f;
        ASSERT_TRUE(forest.addKind(kind));
        ForestInstance tree;
        tree.position = glm::vec3(0.0f, 0.0f, -10.0f);
        ASSERT_TRUE(forest.add(tree));
        CameraSpec spec;
        spec.position = glm::vec3(0.0f);
        spec.target = glm::vec3(0.0f, 0.0f, -1.0f);
        spec.fovYDegrees = 90.0f;
        const CullCamera camera = CullCamera::fromSpec(spec, 100.0f, 100.0f);
        EXPECT_NEAR(forest.lodValue(0, camera, 1.0f), 100.0f * glm::pi<float>(), 1e-3f);
        EXPECT_EQ(forest.levelForValue(0, forest.lodValue(0, camera, 1.0f)), 1u);
        EXPECT_NEAR(forest.lodValue(0, camera, 2.0f), 200.0f * glm::pi<float>(), 1e-3f);
        EXPECT_EQ(forest.levelForValue(0, forest.lodValue(0, camera, 2.0f)), 0u);
        EXPECT_EQ(forest.levelForValue(0, forest.lodValue(0, camera, 0.5f)), 3u);

        // Orthographic, 20 m window over 100 pixels: r_px = 5 again, same value at any distance.
        spec.orthographic = true;
        spec.orthoHeight = 20.0f;
        EXPECT_NEAR(forest.lodValue(0, CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f), 100.0f * glm::pi<float>(),
                    1e-3f);
        tree.position.z = -1000.0f;
        ASSERT_TRUE(forest.update(forest.getHandleAt(0), tree));
        EXPECT_NEAR(forest.lodValue(0, CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f), 100.0f * glm::pi<float>(),
                    1e-3f);

        // Camera at the instance's origin: Ogre's base value, the finest level.
        spec.orthographic = false;
        spec.position = tree.position;
        spec.target = tree.position + glm::vec3(0, 0, -1);
        EXPECT_EQ(forest.lodValue(0, CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f), FLT_MAX);
    }

    TEST(ForestInstances, levelsMatchABruteForceEvaluation)
    {
        std::mt19937 rng(3);
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(randomInstances(rng, 3000, 2000.0f, forest.getKindCount())));
        ForestVisibility vis;
        std::size_t compared = 0, borderline = 0;
        std::set<std::pair<std::uint32_t, int>> levelsSeen;
        for (int cam = 0; cam < 30; ++cam)
        {
            const TestCamera c = randomCamera(rng, 2000.0f, cam % 5 == 4);
            const float bias = cam % 3 == 0 ? 1.0f : (cam % 3 == 1 ? 0.3f : 4.0f);
            const CullCamera camera = CullCamera::fromMatrices(c.view, c.projection, c.width, c.height);
            ASSERT_TRUE(forest.cull(camera, bias, vis));
            const std::vector<int> level = levelsFromBuckets(forest, vis);
            for (std::size_t i = 0; i < forest.size(); ++i)
            {
                if (level[i] < 0)
                    continue;
                const ForestInstance instance = forest.getAt(i);
                const ForestKind& kind = forest.getKind(instance.kind);
                // The same formula through the public helpers: bit for bit.
                EXPECT_EQ(std::uint32_t(level[i]),
                          forest.levelForValue(instance.kind, forest.lodValue(i, camera, bias)));
                bool near = false;
                const std::uint32_t expected = referenceLevel(kind, referenceValue(kind, instance, c, bias), near);
                if (near)
                {
                    ++borderline;
                    continue;
                }
                ++compared;
                levelsSeen.insert({instance.kind, int(expected)});
                EXPECT_EQ(std::uint32_t(level[i]), expected) << "camera " << cam << " instance " << i;
            }
        }
        EXPECT_GT(compared, 2000u);
        EXPECT_LT(borderline, compared / 100 + 1);
        // Every level of every kind was exercised.
        EXPECT_EQ(levelsSeen.size(), 4u + 3u + 1u + 4u);
    }

    TEST(ForestInstances, biasTwoPicksTheLevelOfAnInstanceRootTwoCloser)
    {
        // Pixel counts fall with d^2 and distance values are d^2 / bias: bias 2 at distance d
        // equals bias 1 at d / sqrt(2), for both kinds of table.
        for (bool distance : {false, true})
        {
            ForestInstances near, far;
            const ForestKind kind = distance ? distanceKind("d", {400.0f, 1e4f, 1e6f})
                                             : pixelKind("p", {2e5f, 2e4f, 2e3f});
            ASSERT_TRUE(near.addKind(kind));
            ASSERT_TRUE(far.addKind(kind));
            const glm::vec3 eye(5, 2, 7), dir = glm::normalize(glm::vec3(1, 0.1f, -2));
            for (int k = 0; k < 200; ++k)
            {
                const float d = 5.0f * std::pow(1.04f, float(k)); // 5 m .. 12 km
                ForestInstance i;
                i.position = eye + dir * (d / std::sqrt(2.0f));
                ASSERT_TRUE(near.add(i));
                i.position = eye + dir * d;
                ASSERT_TRUE(far.add(i));
            }
            const glm::mat4 view = glm::lookAt(eye, eye + dir, glm::vec3(0, 1, 0));
            const CullCamera camera =
                CullCamera::fromMatrices(view, glm::perspective(glm::radians(60.0f), 1.0f, 0.1f, 2e4f), 1000, 1000);
            ForestVisibility nearVis, farVis, farVisOne;
            ASSERT_TRUE(near.cull(camera, 1.0f, nearVis));
            ASSERT_TRUE(far.cull(camera, 2.0f, farVis));
            ASSERT_TRUE(far.cull(camera, 1.0f, farVisOne));
            const std::vector<int> nearLevel = levelsFromBuckets(near, nearVis);
            const std::vector<int> farLevel = levelsFromBuckets(far, farVis);
            const std::vector<int> farLevelOne = levelsFromBuckets(far, farVisOne);
            int compared = 0, finer = 0;
            for (std::size_t i = 0; i < near.size(); ++i)
            {
                // Skip values within 0.1 % of a threshold (float rounding of the two paths).
                const float v = near.lodValue(i, camera, 1.0f);
                bool border = false;
                for (float t : kind.thresholds)
                    border |= std::abs(v - t) <= 1e-3f * t;
                if (border)
                    continue;
                ASSERT_GE(nearLevel[i], 0);
                ASSERT_GE(farLevel[i], 0);
                EXPECT_EQ(farLevel[i], nearLevel[i]) << (distance ? "distance " : "pixels ") << i;
                EXPECT_LE(farLevel[i], farLevelOne[i]);
                finer += farLevel[i] < farLevelOne[i] ? 1 : 0;
                ++compared;
            }
            EXPECT_GT(compared, 190);
            // Each of the 3 switches moves by a factor sqrt(2) in distance: 1.04^k crosses it in ~9 steps.
            EXPECT_GE(finer, 3 * 7);
        }
    }

    TEST(ForestInstances, transformsAreTheInstancesWorldMatrices)
    {
        std::mt19937 rng(5);
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(randomInstances(rng, 500, 200.0f, forest.getKindCount())));
        ForestVisibility vis;
        const glm::mat4 view = glm::lookAt(glm::vec3(0, 800, 1), glm::vec3(0), glm::vec3(0, 1, 0));
        ASSERT_TRUE(forest.cull(
            CullCamera::fromMatrices(view, glm::perspective(glm::radians(60.0f), 1.0f, 1.0f, 2000.0f), 512, 512), 1.0f,
            vis));
        ASSERT_GT(vis.getVisibleCount(), 300u);
        for (std::uint32_t j = 0; j < vis.getVisibleCount(); ++j)
        {
            const ForestInstance i = forest.getAt(vis.getIndices()[j]);
            const glm::mat4 world = glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), i.position), i.rotationY,
                                                           glm::vec3(0, 1, 0)),
                                               glm::vec3(i.scale));
            const float* m = vis.getTransforms() + ForestVisibility::TRANSFORM_FLOATS * j;
            for (int row = 0; row < 3; ++row)
                for (int col = 0; col < 4; ++col)
                    EXPECT_NEAR(m[4 * row + col], world[col][row], 1e-4f * (1.0f + std::abs(world[col][row])))
                        << "visible " << j << " row " << row << " col " << col;
            // The world sphere is the kind's local sphere through the same matrix.
            const ForestKind& kind = forest.getKind(i.kind);
            const glm::vec3 centre = glm::vec3(world * glm::vec4(kind.boundsCentre, 1.0f));
            const glm::vec4 sphere = forest.getWorldSphere(vis.getIndices()[j]);
            EXPECT_LT(glm::length(centre - glm::vec3(sphere)), 1e-3f);
            EXPECT_FLOAT_EQ(sphere.w, kind.boundsRadius * i.scale);
        }
    }

    TEST(ForestInstances, bucketsComeNearFirst)
    {
        // Within each bucket, instances are ordered by distance class: a later one is never nearer
        // than an earlier one by more than a class spans (sqrt(1.25) in distance), so drawing a bucket
        // in order lets the depth test reject what nearer trees hide.
        std::mt19937 rng(21);
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(randomInstances(rng, 4000, 1500.0f, forest.getKindCount())));
        const glm::vec3 eye(-700.0f, 30.0f, 100.0f);
        const glm::mat4 view = glm::lookAt(eye, glm::vec3(500.0f, 0.0f, -200.0f), glm::vec3(0, 1, 0));
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(
            CullCamera::fromMatrices(view, glm::perspective(glm::radians(70.0f), 1.5f, 0.5f, 5000.0f), 768, 512), 1.0f,
            vis));
        ASSERT_GT(vis.getVisibleCount(), 800u);
        const float classSpan = std::sqrt(1.25f) * 1.0001f;
        std::size_t checked = 0, bucketsChecked = 0;
        for (std::size_t b = 0; b < vis.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = vis.getBucket(b);
            const std::uint32_t* indices = vis.getBucketIndices(b);
            float farthest = 0.0f;
            for (std::uint32_t j = 0; j < bucket.count; ++j)
            {
                const float d = glm::length(forest.getAt(indices[j]).position - eye);
                EXPECT_GE(std::max(d, 1.0f) * classSpan, farthest) << "bucket " << b << " position " << j;
                farthest = std::max(farthest, d);
                ++checked;
            }
            bucketsChecked += bucket.count > 10;
        }
        EXPECT_EQ(checked, vis.getVisibleCount());
        EXPECT_GE(bucketsChecked, 2u);
        // Input order is not near first (the test would pass trivially otherwise).
        const std::vector<ForestInstance> all = [&] {
            std::vector<ForestInstance> out;
            for (std::size_t i = 0; i < forest.size(); ++i)
                out.push_back(forest.getAt(i));
            return out;
        }();
        std::size_t inversions = 0;
        for (std::size_t i = 1; i < all.size(); ++i)
            inversions += glm::length(all[i].position - eye) * classSpan < glm::length(all[i - 1].position - eye);
        EXPECT_GT(inversions, all.size() / 10);
    }

    TEST(ForestInstances, secondCullWithTheSameCountsAllocatesNothing)
    {
        std::mt19937 rng(9);
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(randomInstances(rng, 5000, 1000.0f, forest.getKindCount())));
        const TestCamera wide{glm::lookAt(glm::vec3(0, 3000, 1), glm::vec3(0), glm::vec3(0, 1, 0)),
                              glm::perspective(glm::radians(60.0f), 1.0f, 1.0f, 5000.0f), 1024, 1024};
        const TestCamera narrow{wide.view, glm::perspective(glm::radians(5.0f), 1.0f, 1.0f, 5000.0f), 1024, 1024};
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(CullCamera::fromMatrices(wide.view, wide.projection, 1024, 1024), 1.0f, vis));
        const std::uint32_t visible = vis.getVisibleCount();
        ASSERT_EQ(visible, forest.size());
        const std::size_t capacity = vis.getCapacityBytes();
        const std::uint32_t* indices = vis.getIndices();
        const float* transforms = vis.getTransforms();
        ASSERT_TRUE(forest.cull(CullCamera::fromMatrices(narrow.view, narrow.projection, 1024, 1024), 1.0f, vis));
        EXPECT_LT(vis.getVisibleCount(), visible / 10);
        ASSERT_TRUE(forest.cull(CullCamera::fromMatrices(wide.view, wide.projection, 1024, 1024), 2.0f, vis));
        EXPECT_EQ(vis.getVisibleCount(), visible);
        EXPECT_EQ(vis.getCapacityBytes(), capacity);
        EXPECT_EQ(vis.getIndices(), indices);
        EXPECT_EQ(vis.getTransforms(), transforms);
    }

    TEST(ForestInstances, zeroOneAndTwoHundredThousandInstances)
    {
        std::mt19937 rng(13);
        const TestCamera c{glm::lookAt(glm::vec3(-5000, 40, -5000), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0)),
                           glm::perspective(glm::radians(70.0f), 16.0f / 9.0f, 0.5f, 8000.0f), 1920, 1080};
        const CullCamera camera = CullCamera::fromMatrices(c.view, c.projection, c.width, c.height);
        const std::array<glm::dvec4, 6> planes = cornerPlanes(c);
        for (std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(200000)})
        {
            ForestInstances forest;
            addKinds(forest);
            std::vector<ForestInstance> instances = randomInstances(rng, count, 5000.0f, forest.getKindCount());
            if (count == 1)
                instances[0].position = glm::vec3(0.0f); // in view
            ASSERT_TRUE(forest.add(instances));
            ASSERT_EQ(forest.size(), count);
            ForestVisibility vis;
            ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
            const std::vector<int> level = levelsFromBuckets(forest, vis);
            std::size_t mismatches = 0, borderline = 0;
            for (std::size_t i = 0; i < count; ++i)
            {
                const glm::vec4 s = forest.getWorldSphere(i);
                const double tolerance = 1e-5 * (glm::length(glm::vec3(s)) + 7100.0);
                const int ref = referenceVisible(planes, glm::dvec3(s), s.w, tolerance);
                if (ref < 0)
                    ++borderline;
                else
                    mismatches += (ref == 1) != (level[i] >= 0) ? 1 : 0;
            }
            EXPECT_EQ(mismatches, 0u) << count;
            EXPECT_LE(borderline, count / 1000) << count;
            if (count == 1)
            {
                EXPECT_EQ(vis.getVisibleCount(), 1u);
            }
            if (count == 200000)
            {
                EXPECT_GT(vis.getVisibleCount(), 10000u);
            }
        }
    }

    TEST(ForestInstances, badInstancesAreRejectedByNameAndNothingIsAdded)
    {
        ForestInstances forest;
        addKinds(forest);
        ASSERT_TRUE(forest.add(ForestInstance{}));
        ASSERT_TRUE(forest.add(ForestInstance{}));

        ForestInstance bad;
        bad.position.y = std::numeric_limits<float>::quiet_NaN();
        Result<ForestHandle> one = forest.add(bad);
        ASSERT_FALSE(one);
        EXPECT_EQ(one.error().element, "instance 2");
        EXPECT_NE(one.error().reason.find("position"), std::string::npos) << one.error().message();
        EXPECT_NE(one.error().reason.find("nan"), std::string::npos) << one.error().message();

        std::vector<ForestInstance> many(10);
        many[7] = bad;
        Result<std::vector<ForestHandle>> batch = forest.add(many);
        ASSERT_FALSE(batch);
        EXPECT_EQ(batch.error().element, "instance 7");
        EXPECT_EQ(forest.size(), 2u);

        ForestInstance other;
        other.scale = 0.0f;
        EXPECT_NE(forest.add(other).error().reason.find("scale"), std::string::npos);
        other.scale = 1.0f;
        other.rotationY = std::numeric_limits<float>::infinity();
        EXPECT_NE(forest.add(other).error().reason.find("rotation"), std::string::npos);
        other.rotationY = 0.0f;
        other.kind = 4;
        EXPECT_NE(forest.add(other).error().reason.find("kind 4 does not exist"), std::string::npos);
        other.kind = 0;
        other.scale = 1e30f; // radius 6e30: its square overflows
        EXPECT_FALSE(forest.add(other));
        EXPECT_EQ(forest.size(), 2u);

        Result<void> update = forest.update(forest.getHandleAt(1), bad);
        ASSERT_FALSE(update);
        EXPECT_EQ(update.error().element, "instance handle " + std::to_string(forest.getHandleAt(1)));
        EXPECT_EQ(forest.getAt(1).position, glm::vec3(0.0f));
        EXPECT_FALSE(forest.update(99, ForestInstance{}));
        EXPECT_FALSE(forest.remove(99));
    }

    TEST(ForestInstances, badKindsAndCamerasAreRejected)
    {
        ForestInstances forest;
        Result<std::uint32_t> r = forest.addKind(pixelKind("up", {10.0f, 20.0f}));
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().element, "kind 0 'up'");
        EXPECT_NE(r.error().reason.find("decrease"), std::string::npos) << r.error().message();
        EXPECT_FALSE(forest.addKind(distanceKind("down", {20.0f, 10.0f})));
        EXPECT_FALSE(forest.addKind(pixelKind("nan", {std::numeric_limits<float>::quiet_NaN()})));
        EXPECT_FALSE(forest.addKind(pixelKind("negative", {-1.0f})));
        EXPECT_FALSE(forest.addKind(pixelKind("many", std::vector<float>(16, 1.0f))));
        ForestKind flat = pixelKind("flat", {});
        flat.boundsRadius = 0.0f;
        EXPECT_FALSE(forest.addKind(flat));
        EXPECT_EQ(forest.getKindCount(), 0u);
        ASSERT_TRUE(forest.addKind(pixelKind("ok", std::vector<float>(15, 1.0f))));
        EXPECT_EQ(forest.getLevelCount(0), 16u);

        ASSERT_TRUE(forest.add(ForestInstance{}));
        CullCamera camera = CullCamera::fromSpec(CameraSpec{}, 640, 480);
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        ASSERT_EQ(vis.getVisibleCount(), 1u);
        EXPECT_FALSE(forest.cull(camera, 0.0f, vis));
        EXPECT_FALSE(forest.cull(camera, std::numeric_limits<float>::quiet_NaN(), vis));
        camera.planes[2].y = std::numeric_limits<float>::quiet_NaN();
        Result<void> bad = forest.cull(camera, 1.0f, vis);
        ASSERT_FALSE(bad);
        EXPECT_EQ(bad.error().element, "camera");
        EXPECT_EQ(vis.getVisibleCount(), 1u); // untouched
    }

    TEST(ForestInstances, handlesSurviveRemovalOfOthers)
    {
        ForestInstances forest;
        addKinds(forest);
        std::vector<ForestHandle> handles;
        for (int i = 0; i < 6; ++i)
        {
            ForestInstance instance;
            instance.position = glm::vec3(float(i), 0.0f, 0.0f);
            instance.kind = std::uint32_t(i % 4);
            Result<ForestHandle> h = forest.add(instance);
            ASSERT_TRUE(h);
            handles.push_back(*h);
        }
        ASSERT_TRUE(forest.remove(handles[1]));
        ASSERT_TRUE(forest.remove(handles[4]));
        EXPECT_FALSE(forest.contains(handles[1]));
        EXPECT_FALSE(forest.remove(handles[1]));
        EXPECT_EQ(forest.size(), 4u);
        for (int i : {0, 2, 3, 5})
        {
            ASSERT_TRUE(forest.contains(handles[i]));
            EXPECT_EQ(forest.get(handles[i]).position.x, float(i));
            EXPECT_EQ(forest.get(handles[i]).kind, std::uint32_t(i % 4));
            EXPECT_EQ(forest.getHandleAt(forest.getIndexOf(handles[i])), handles[i]);
        }
        ForestInstance moved;
        moved.position = glm::vec3(100.0f, 0.0f, 0.0f);
        moved.kind = 3;
        ASSERT_TRUE(forest.update(handles[5], moved));
        EXPECT_EQ(forest.get(handles[5]).position.x, 100.0f);
        EXPECT_FLOAT_EQ(forest.getWorldSphere(forest.getIndexOf(handles[5])).x, 100.3f);
        Result<ForestHandle> reused = forest.add(ForestInstance{});
        ASSERT_TRUE(reused);
        EXPECT_TRUE(*reused == handles[1] || *reused == handles[4]);
        EXPECT_EQ(forest.size(), 5u);
        forest.clear();
        EXPECT_EQ(forest.size(), 0u);
        EXPECT_FALSE(forest.contains(handles[0]));
    }

    // A million instances (no index overflow, memory linear at <= 32 bytes each), every
    // tree at one spot, and the camera 10 km away.
    TEST(ForestInstances, aMillionInstancesThirtyTwoBytesEach)
    {
        std::mt19937 rng(17);
        ForestInstances forest;
        addKinds(forest);
        std::vector<ForestInstance> instances = randomInstances(rng, 1000000, 5000.0f, forest.getKindCount());
        ASSERT_TRUE(forest.add(instances));
        ASSERT_EQ(forest.size(), 1000000u);
        const double perInstance = double(forest.getMemoryBytes()) / double(forest.size());
        std::printf("1 M instances: %.1f bytes each\n", perInstance);
        EXPECT_LE(perInstance, 32.0);
        ForestInstances small;
        addKinds(small);
        ASSERT_TRUE(small.add(randomInstances(rng, 10000, 5000.0f, small.getKindCount())));
        EXPECT_NEAR(double(small.getMemoryBytes()) / 10000.0, perInstance, 0.1 * perInstance); // linear
        // The last instance reads back (indices past 2^16, 2^20 are fine).
        const ForestInstance last = forest.getAt(999999);
        EXPECT_NEAR(last.position.x, instances.back().position.x, 1e-3f);
        EXPECT_NEAR(last.scale, instances.back().scale, 1e-5f * instances.back().scale);
        EXPECT_NEAR(std::cos(last.rotationY), std::cos(instances.back().rotationY), 1e-5f);
        EXPECT_NEAR(std::sin(last.rotationY), std::sin(instances.back().rotationY), 1e-5f);
        // An overview sees all of them; each is in exactly one bucket; a second cull allocates nothing.
        const TestCamera c{glm::lookAt(glm::vec3(0, 30000, 1), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0)),
                           glm::perspective(glm::radians(40.0f), 1.0f, 10.0f, 40000.0f), 1024, 1024};
        const CullCamera camera = CullCamera::fromMatrices(c.view, c.projection, c.width, c.height);
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        EXPECT_EQ(vis.getVisibleCount(), 1000000u);
        std::uint64_t total = 0;
        for (const ForestBucket& b : vis.getBuckets())
            total += b.count;
        EXPECT_EQ(total, 1000000u);
        const std::size_t capacity = vis.getCapacityBytes();
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
        EXPECT_EQ(vis.getCapacityBytes(), capacity);
        // Every tree at one spot.
        ForestInstances stacked;
        addKinds(stacked);
        std::vector<ForestInstance> same(5000, ForestInstance{glm::vec3(3.0f, 0.0f, -2.0f), 0.5f, 1.0f, 0});
        ASSERT_TRUE(stacked.add(same));
        ASSERT_TRUE(stacked.cull(camera, 1.0f, vis));
        EXPECT_EQ(vis.getVisibleCount(), 5000u);
        // ... of every kind, seen from 10 km: all at each kind's last level.
        for (std::size_t i = 0; i < same.size(); ++i)
            same[i].kind = std::uint32_t(i % stacked.getKindCount());
        stacked.clear();
        ASSERT_TRUE(stacked.add(same));
        const TestCamera far{glm::lookAt(glm::vec3(3, 10, 10000), glm::vec3(3, 0, -2), glm::vec3(0, 1, 0)),
                             glm::perspective(glm::radians(60.0f), 1.0f, 1.0f, 30000.0f), 1024, 1024};
        ASSERT_TRUE(stacked.cull(CullCamera::fromMatrices(far.view, far.projection, far.width, far.height), 1.0f, vis));
        EXPECT_EQ(vis.getVisibleCount(), 5000u);
        for (const ForestBucket& b : vis.getBuckets())
            EXPECT_EQ(b.count, b.level + 1 == stacked.getLevelCount(b.kind) ? 1250u : 0u) << b.kind << "/" << b.level;
    }

    // Blocks: a store in spatial order, whose culling skips whole blocks, sees exactly
    // what the per-instance test of a store in input order sees, camera after camera; removals and
    // updates keep the block boxes conservative.
    TEST(ForestInstances, blocksSkipNothingVisible)
    {
        std::mt19937 rng(23);
        ForestInstances plain, blocked;
        addKinds(plain);
        addKinds(blocked);
        std::vector<ForestInstance> instances = randomInstances(rng, 20000, 3000.0f, plain.getKindCount());
        for (ForestInstance& i : instances)
            i.scale = std::min(i.scale, 3.0f); // trees, not towers: blocks stay small
        const std::vector<std::uint32_t> order = ForestInstances::spatialOrder(instances);
        ASSERT_EQ(order.size(), instances.size());
        std::vector<ForestInstance> sorted;
        for (std::uint32_t i : order)
            sorted.push_back(instances[i]);
        ASSERT_TRUE(plain.add(instances));
        Result<std::vector<ForestHandle>> handles = blocked.add(sorted);
        ASSERT_TRUE(handles);
        // Move a few and remove a few in the blocked store (and the same in the plain one).
        for (int k = 0; k < 200; ++k)
        {
            const std::size_t s = std::size_t(rng() % sorted.size());
            ForestInstance moved = sorted[s];
            moved.position.x = -moved.position.x;
            ASSERT_TRUE(blocked.update((*handles)[s], moved));
            ASSERT_TRUE(plain.update(order[s], moved)); // plain handles are input indices
        }
        for (int k = 0; k < 100; ++k)
        {
            const std::size_t s = std::size_t(rng() % sorted.size());
            if (!blocked.contains((*handles)[s]))
                continue;
            ASSERT_TRUE(blocked.remove((*handles)[s]));
            ASSERT_TRUE(plain.remove(order[s]));
        }
        ForestVisibility a, b;
        std::size_t seen = 0;
        for (int cam = 0; cam < 60; ++cam)
        {
            const TestCamera c = randomCamera(rng, 3000.0f, cam % 5 == 0);
            const CullCamera camera = CullCamera::fromMatrices(c.view, c.projection, c.width, c.height);
            ASSERT_TRUE(plain.cull(camera, 1.0f, a));
            ASSERT_TRUE(blocked.cull(camera, 1.0f, b));
            ASSERT_EQ(a.getVisibleCount(), b.getVisibleCount()) << "camera " << cam;
            for (std::size_t k = 0; k < a.getBucketCount(); ++k)
                EXPECT_EQ(a.getBucket(k).count, b.getBucket(k).count) << "camera " << cam << " bucket " << k;
            seen += b.getVisibleCount();
        }
        EXPECT_GT(seen, 10000u);
    }

    // Cameras at the extremes: 1000 km out on every axis looking at the forest, and inside a
    // tree's bounding sphere. No NaN reaches the selection: every visible instance has a valid
    // level and a finite LoD value; the far forest is at each kind's last level (or culled by a
    // near far plane), the tree around the camera at its first.
    TEST(ForestInstances, camerasAMillionMetresOutAndInsideATreeSelectValidLevels)
    {
        std::mt19937 rng(29);
        ForestInstances forest;
        addKinds(forest);
        std::vector<ForestInstance> instances = randomInstances(rng, 20000, 2000.0f, forest.getKindCount());
        // One tree of each kind around the origin, where the second camera stands.
        for (std::uint32_t k = 0; k < forest.getKindCount(); ++k)
            instances[k] = ForestInstance{glm::vec3(0.0f), 0.3f * float(k), 1.0f, k};
        ASSERT_TRUE(forest.add(instances));

        // Every visible instance: a level of its kind and a finite, non-negative LoD value.
        auto checkSelection = [&](const CullCamera& camera, const ForestVisibility& vis,
                                  const std::string& what) -> std::vector<int> {
            const std::vector<int> level = levelsFromBuckets(forest, vis);
            std::size_t bad = 0;
            for (std::size_t i = 0; i < forest.size(); ++i)
            {
                if (level[i] < 0)
                    continue;
                const float value = forest.lodValue(i, camera, 1.0f);
                const std::uint32_t kind = forest.getAt(i).kind;
                bad += std::isfinite(value) && value >= 0.0f && std::uint32_t(level[i]) < forest.getLevelCount(kind) &&
                               forest.levelForValue(kind, value) == std::uint32_t(level[i])
                           ? 0
                           : 1;
            }
            EXPECT_EQ(bad, 0u) << what;
            std::size_t nonFinite = 0;
            for (std::size_t f = 0; f < ForestVisibility::TRANSFORM_FLOATS * vis.getVisibleCount(); ++f)
                nonFinite += std::isfinite(vis.getTransforms()[f]) ? 0 : 1;
            EXPECT_EQ(nonFinite, 0u) << what;
            return level;
        };

        // 1000 km out on every axis, looking at the forest: it fills a few pixels, all of it at each
        // kind's last level, with a far plane beyond it (finite or at infinity); culled whole by a
        // far plane at 10 km.
        CameraSpec spec;
        spec.position = glm::vec3(1e6f);
        spec.target = glm::vec3(0.0f);
        spec.nearClip = 1.0f;
        spec.farClip = 1e7f;
        const glm::mat4 view = spec.viewMatrix();
        const std::vector<std::pair<std::string, CullCamera>> farCameras = {
            {"far 1e7", CullCamera::fromSpec(spec, 1920.0f, 1080.0f)},
            {"far at infinity",
             CullCamera::fromMatrices(view, glm::infinitePerspective(glm::radians(45.0f), 16.0f / 9.0f, 1.0f), 1920.0f,
                                      1080.0f)},
            {"orthographic 8 km",
             CullCamera::fromMatrices(view, glm::ortho(-4000.0f, 4000.0f, -4000.0f, 4000.0f, 1.0f, 1e7f), 1024.0f,
                                      1024.0f)}};
        ForestVisibility vis;
        for (const auto& [what, camera] : farCameras)
        {
            ASSERT_TRUE(forest.cull(camera, 1.0f, vis)) << what;
            EXPECT_EQ(vis.getVisibleCount(), forest.size()) << what;
            const std::vector<int> level = checkSelection(camera, vis, what);
            if (what == "orthographic 8 km")
                continue; // an orthographic size does not fall with distance
            std::size_t notLast = 0;
            for (std::size_t i = 0; i < forest.size(); ++i)
                notLast += std::uint32_t(level[i]) + 1 == forest.getLevelCount(forest.getAt(i).kind) ? 0 : 1;
            EXPECT_EQ(notLast, 0u) << what;
        }
        spec.farClip = 1e4f;
        ASSERT_TRUE(forest.cull(CullCamera::fromSpec(spec, 1920.0f, 1080.0f), 1.0f, vis));
        EXPECT_EQ(vis.getVisibleCount(), 0u);

        // Inside the trees at the origin (their spheres: centre (0.3, 5, -0.2) turned, radius 6),
        // looking out in six directions, and at their common origin: each is drawn, at level 0.
        for (const glm::vec3& eye : {glm::vec3(0.0f, 5.0f, 0.0f), glm::vec3(0.0f), glm::vec3(1.0f, 2.0f, -1.0f)})
            for (const glm::vec3& look : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1),
                                          glm::vec3(0, 0, -1), glm::vec3(0.1f, 0.99f, 0), glm::vec3(0.1f, -0.99f, 0)})
            {
                CameraSpec inside;
                inside.position = eye;
                inside.target = eye + look;
                const CullCamera camera = CullCamera::fromSpec(inside, 1280.0f, 720.0f);
                ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
                const std::string what = "eye " + std::to_string(eye.x) + "," + std::to_string(eye.y) + "," +
                                         std::to_string(eye.z) + " looking " + std::to_string(look.x) + "," +
                                         std::to_string(look.y) + "," + std::to_string(look.z);
                const std::vector<int> level = checkSelection(camera, vis, what);
                for (std::uint32_t k = 0; k < forest.getKindCount(); ++k)
                    EXPECT_EQ(level[k], 0) << what << ", kind " << k;
            }
    }
}

namespace TreeLod
{
    namespace
    {
        /// One kind switching at 10 m (value 100 pi: pixelCountIsFourPiProjectedRadiusSquared) from
        /// cameras of fromSpec(..., 100, 100) at 90 degrees, and a tree of it at each of `zs` on the
        /// z axis.
        void addTreesSwitchingAtTenMetres(ForestInstances& forest, const std::vector<float>& zs)
        {
            ForestKind kind = pixelKind("tree", {100.0f * glm::pi<float>()});
            kind.boundsCentre = glm::vec3(0.0f);
            kind.boundsRadius = 1.0f;
            ASSERT_TRUE(forest.addKind(kind));
            for (float z : zs)
                ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(0.0f, 0.0f, z), 0.0f, 1.0f, 0}));
        }

        /// A distance kind switching at 10 m (d^2 = 100) and a tree of it at z = -10.
        void addTreeSwitchingAtTenMetresByDistance(ForestInstances& forest)
        {
            ForestKind kind = distanceKind("tree", {100.0f});
            kind.boundsCentre = glm::vec3(0.0f);
            kind.boundsRadius = 1.0f;
            ASSERT_TRUE(forest.addKind(kind));
            ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(0.0f, 0.0f, -10.0f), 0.0f, 1.0f, 0}));
        }

        /// The level `forest`'s only instance gets in each cull from cameras at `distances`.
        std::vector<std::uint32_t> levelsAlong(const ForestInstances& forest, const std::vector<float>& distances,
                                               float hysteresis)
        {
            ForestVisibility vis;
            std::vector<std::uint32_t> levels;
            for (const float d : distances)
            {
                CameraSpec spec;
                spec.position = glm::vec3(0.0f, 0.0f, -10.0f + d);
                spec.target = glm::vec3(0.0f, 0.0f, -10.0f);
                spec.fovYDegrees = 90.0f;
                EXPECT_TRUE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, hysteresis));
                for (const ForestBucket& bucket : vis.getBuckets())
                    if (bucket.count)
                        levels.push_back(bucket.level);
            }
            return levels;
        }
    }

    TEST(ForestInstances, hysteresisHoldsATreeStillUnderCameraJitter)
    {
        // The switch at 10 m: a camera jittering 1 % about 10 m crosses it every frame.
        ForestInstances forest;
        addTreesSwitchingAtTenMetres(forest, {-10.0f});
        std::vector<float> jitter;
        for (int f = 0; f < 20; ++f)
            jitter.push_back(f % 2 ? 10.1f : 9.9f);
        const std::vector<std::uint32_t> without = levelsAlong(forest, jitter, 0.0f);
        ASSERT_EQ(without.size(), jitter.size());
        EXPECT_EQ(std::count(without.begin(), without.end(), 0u), 10) << "no hysteresis: it flickers";
        const std::vector<std::uint32_t> with = levelsAlong(forest, jitter, 0.15f);
        ASSERT_EQ(with.size(), jitter.size());
        EXPECT_EQ(std::count(with.begin(), with.end(), with.front()), 20) << "hysteresis 0.15: it holds";

        // Beyond the band it switches: 10 m -> 12 m is a factor 1.44 in value (> 1.15).
        const std::vector<std::uint32_t> away = levelsAlong(forest, {9.9f, 12.0f, 9.9f, 8.0f}, 0.15f);
        EXPECT_EQ(away, (std::vector<std::uint32_t>{0u, 1u, 1u, 0u}));

        // A distance kind: the same hold, from the other side of the key's sign.
        ForestInstances byDistance;
        addTreeSwitchingAtTenMetresByDistance(byDistance);
        const std::vector<std::uint32_t> d0 = levelsAlong(byDistance, jitter, 0.0f);
        EXPECT_EQ(std::count(d0.begin(), d0.end(), 0u), 10);
        const std::vector<std::uint32_t> d1 = levelsAlong(byDistance, jitter, 0.15f);
        EXPECT_EQ(std::count(d1.begin(), d1.end(), d1.front()), 20);
        EXPECT_EQ(levelsAlong(byDistance, {9.9f, 12.0f, 10.1f, 8.0f}, 0.15f),
                  (std::vector<std::uint32_t>{0u, 1u, 1u, 0u}));

        ForestVisibility vis;
        CameraSpec spec;
        EXPECT_FALSE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, -0.1f));
        EXPECT_FALSE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, std::nanf("")));
        EXPECT_FALSE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, 1.5f));
    }
}

namespace TreeLod
{
    TEST(ForestInstances, switchesCountTheVisibleTreesThatChangedLevel)
    {
        // Level 0 nearer than 10 m, 1 farther. One tree at z = -10, another at z = -40 (beyond the
        // switch from every camera below).
        ForestInstances forest;
        addTreesSwitchingAtTenMetres(forest, {-10.0f, -40.0f});
        ForestVisibility vis;
        auto switchesFrom = [&](float z, float hysteresis, glm::vec3 target = glm::vec3(0.0f, 0.0f, -50.0f)) {
            CameraSpec spec;
            spec.position = glm::vec3(0.0f, 0.0f, z);
            spec.target = target;
            spec.fovYDegrees = 90.0f;
            EXPECT_TRUE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, hysteresis));
            return vis.getSwitchCount();
        };
        EXPECT_EQ(switchesFrom(-1.0f, 0.0f), 0u) << "first sight: no switch";
        EXPECT_EQ(switchesFrom(-0.5f, 0.0f), 0u) << "both keep their levels";
        EXPECT_EQ(switchesFrom(2.0f, 0.0f), 1u) << "the near tree crossed its switch (9 m to 12 m)";
        EXPECT_EQ(switchesFrom(2.0f, 0.0f), 0u);
        // With hysteresis a small step back over the switch holds the level; a large one switches.
        EXPECT_EQ(switchesFrom(-0.3f, 0.15f), 0u);
        EXPECT_EQ(switchesFrom(-2.0f, 0.15f), 1u);
        // Out of view and back at another level: counted when it is seen again.
        EXPECT_EQ(switchesFrom(30.0f, 0.0f, glm::vec3(0.0f, 0.0f, 100.0f)), 0u);
        EXPECT_EQ(vis.getVisibleCount(), 0u);
        EXPECT_EQ(switchesFrom(30.0f, 0.0f), 1u) << "the near tree, last seen at level 0, is at level 1";
    }

    TEST(ForestInstances, replacedTablesMoveTheBucketsAfterThemAndForgetLevelsTheyLack)
    {
        ForestInstances forest;
        addKinds(forest);
        std::mt19937 rng(7);
        ASSERT_TRUE(forest.add(randomInstances(rng, 2000, 400.0f, forest.getKindCount())));
        CameraSpec spec;
        spec.position = glm::vec3(0.0f, 30.0f, 0.0f);
        spec.target = glm::vec3(100.0f, 0.0f, 100.0f);
        const CullCamera camera = CullCamera::fromSpec(spec, 640.0f, 360.0f);
        ForestVisibility vis;
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis, 0.15f));
        const std::uint32_t before = vis.getVisibleCount();

        // Kind 0: four levels down to two; every bucket after it moves by two.
        ASSERT_EQ(forest.getBucketIndex(1, 0), 4u);
        ASSERT_TRUE(forest.setKindThresholds(0, {2e4f}));
        EXPECT_EQ(forest.getLevelCount(0), 2u);
        EXPECT_EQ(forest.getBucketIndex(1, 0), 2u);
        EXPECT_EQ(forest.getBucketIndex(3, 3), 2u + 3u + 1u + 3u);
        EXPECT_EQ(forest.getBucketCount(), 2u + 3u + 1u + 4u);
        // The same visibility culled again: the new layout, and the levels it remembered for
        // hysteresis forgotten (index 1 of kind 0 is another level now): as a fresh one's.
        ASSERT_TRUE(forest.cull(camera, 1.0f, vis, 0.15f));
        ForestVisibility fresh;
        ASSERT_TRUE(forest.cull(camera, 1.0f, fresh, 0.15f));
        EXPECT_EQ(vis.getVisibleCount(), before);
        ASSERT_EQ(vis.getBucketCount(), forest.getBucketCount());
        for (std::size_t b = 0; b < vis.getBucketCount(); ++b)
        {
            EXPECT_EQ(vis.getBucket(b).kind, fresh.getBucket(b).kind) << b;
            EXPECT_EQ(vis.getBucket(b).level, fresh.getBucket(b).level) << b;
            EXPECT_EQ(vis.getBucket(b).count, fresh.getBucket(b).count) << b;
        }

        // Refused as addKind refuses, the table unchanged; an unknown kind is named.
        Result<void> bad = forest.setKindThresholds(1, {5e2f, 5e4f});
        ASSERT_FALSE(bad);
        EXPECT_NE(bad.error().message().find("pine/billboard-cloud"), std::string::npos) << bad.error().message();
        EXPECT_EQ(forest.getKind(1).thresholds, (std::vector<float>{5e4f, 5e2f}));
        EXPECT_FALSE(forest.setKindThresholds(0, {std::nanf("")}));
        EXPECT_FALSE(forest.setKindThresholds(0, std::vector<float>(ForestInstances::MAX_THRESHOLDS + 1, 1.0f)));
        Result<void> unknown = forest.setKindThresholds(9, {});
        ASSERT_FALSE(unknown);
        EXPECT_NE(unknown.error().message().find("kind 9"), std::string::npos) << unknown.error().message();
        EXPECT_EQ(forest.getBucketCount(), 2u + 3u + 1u + 4u);
    }
}

namespace TreeLod
{
    namespace
    {
        /// One draw of a cull: its level and transition code.
        struct Draw
        {
            std::uint32_t level;
            float code;
        };

        /// The draws of `forest`'s only instance from a camera `d` metres from z = -10 (as levelsAlong).
        std::vector<Draw> drawsAt(const ForestInstances& forest, ForestVisibility& vis, float d, float transition,
                                  float hysteresis = 0.0f)
        {
            CameraSpec spec;
            spec.position = glm::vec3(0.0f, 0.0f, -10.0f + d);
            spec.target = glm::vec3(0.0f, 0.0f, -10.0f);
            spec.fovYDegrees = 90.0f;
            EXPECT_TRUE(forest.cull(CullCamera::fromSpec(spec, 100.0f, 100.0f), 1.0f, vis, hysteresis, transition));
            std::vector<Draw> draws;
            for (std::size_t b = 0; b < vis.getBucketCount(); ++b)
                for (std::uint32_t k = 0; k < vis.getBucket(b).count; ++k)
                    draws.push_back({vis.getBucket(b).level, vis.getBucketTransitionCodes(b)[k]});
            EXPECT_EQ(draws.size(), vis.getDrawCount());
            return draws;
        }

        /// The share of the 64 screen-door thresholds (TreeLodTransition.glsl) each level keeps.
        std::vector<double> levelShares(const std::vector<Draw>& draws, std::uint32_t levels)
        {
            std::vector<double> share(levels, 0.0);
            for (int t = 0; t < 64; ++t)
            {
                const float dither = (float(t) + 0.5f) / 64.0f;
                int kept = 0;
                for (const Draw& draw : draws)
                    if (transitionKeeps(draw.code, dither))
                    {
                        share[draw.level] += 1.0 / 64.0;
                        ++kept;
                    }
                EXPECT_EQ(kept, 1) << "threshold " << dither << ": each pixel drawn by exactly one level";
            }
            return share;
        }
    }

    TEST(ForestInstances, transitionsDrawATreeNearASwitchAtBothLevelsWithComplementaryMasks)
    {
        // The switch at 10 m; transition 0.2: screen sizes within 1.2 times the switch's, 8.33 m to 10 m.
        ForestInstances forest;
        addTreesSwitchingAtTenMetres(forest, {-10.0f});
        ForestVisibility vis;
        auto expectOne = [&](float d, std::uint32_t level) {
            const std::vector<Draw> draws = drawsAt(forest, vis, d, 0.2f);
            ASSERT_EQ(draws.size(), 1u) << d << " m";
            EXPECT_EQ(draws[0].level, level) << d << " m";
            EXPECT_EQ(draws[0].code, 0.0f) << d << " m: the whole tree";
            EXPECT_EQ(vis.getTransitionCount(), 0u);
        };
        expectOne(12.0f, 1u);
        expectOne(10.05f, 1u);
        expectOne(8.0f, 0u);
        expectOne(1.0f, 0u);

        // At 9.5 m the screen size is 10 / 9.5 = 1.0526 times the switch's: the coarse level keeps
        // (1.2 - 1.0526) / 0.2 = 0.737 of the pixels, the fine one the rest.
        const std::vector<Draw> mid = drawsAt(forest, vis, 9.5f, 0.2f);
        ASSERT_EQ(mid.size(), 2u);
        EXPECT_EQ(vis.getVisibleCount(), 1u);
        EXPECT_EQ(vis.getTransitionCount(), 1u);
        EXPECT_EQ(mid[0].level, 0u);
        EXPECT_EQ(mid[1].level, 1u);
        EXPECT_NEAR(mid[1].code, (1.2f - 10.0f / 9.5f) / 0.2f, 1e-4f);
        EXPECT_EQ(mid[0].code, -mid[1].code);
        EXPECT_EQ(vis.getIndices()[0], vis.getIndices()[1]);
        for (std::size_t k = 0; k < ForestVisibility::TRANSFORM_FLOATS; ++k)
            EXPECT_EQ(vis.getTransforms()[k], vis.getTransforms()[ForestVisibility::TRANSFORM_FLOATS + k]);
        const std::vector<double> shares = levelShares(mid, 2);
        EXPECT_NEAR(shares[1], 0.737, 1.0 / 64.0);

        // Walking through the band in 1 cm steps: the coarse share moves by at most 2/64 a step
        // (a screen-door step and rounding); a hard switch (transition 0) moves it by all of it at once.
        double worstSmooth = 0.0, worstHard = 0.0, previousSmooth = 0.0, previousHard = 0.0;
        for (int step = 0; step <= 500; ++step)
        {
            const float d = 7.0f + 0.01f * float(step);
            const double smooth = levelShares(drawsAt(forest, vis, d, 0.2f), 2)[1];
            const double hard = levelShares(drawsAt(forest, vis, d, 0.0f), 2)[1];
            if (step > 0)
            {
                worstSmooth = std::max(worstSmooth, std::abs(smooth - previousSmooth));
                worstHard = std::max(worstHard, std::abs(hard - previousHard));
            }
            previousSmooth = smooth;
            previousHard = hard;
        }
        EXPECT_LE(worstSmooth, 2.0 / 64.0);
        EXPECT_EQ(worstHard, 1.0);
        EXPECT_EQ(previousSmooth, 1.0);

        // A distance kind switching at 10 m: the same shares at the same distances.
        ForestInstances byDistance;
        addTreeSwitchingAtTenMetresByDistance(byDistance);
        const std::vector<Draw> distanceMid = drawsAt(byDistance, vis, 9.5f, 0.2f);
        ASSERT_EQ(distanceMid.size(), 2u);
        EXPECT_NEAR(distanceMid[1].code, mid[1].code, 1e-4f);
        EXPECT_EQ(drawsAt(byDistance, vis, 10.05f, 0.2f).size(), 1u);
        EXPECT_EQ(drawsAt(byDistance, vis, 8.0f, 0.2f).size(), 1u);

        // Hysteresis does not hold a level across a fading switch: 9.9 m after 10.1 m is in the band.
        drawsAt(forest, vis, 10.1f, 0.2f, 0.15f);
        EXPECT_EQ(drawsAt(forest, vis, 9.9f, 0.2f, 0.15f).size(), 2u);
        // It still holds a hard one (ForestKind::hardSwitches), transitions on or off.
        ASSERT_TRUE(forest.setKindThresholds(0, forest.getKind(0).thresholds, 1));
        drawsAt(forest, vis, 10.1f, 0.2f, 0.15f);
        const std::vector<Draw> held = drawsAt(forest, vis, 9.9f, 0.2f, 0.15f);
        ASSERT_EQ(held.size(), 1u);
        EXPECT_EQ(held[0].level, 1u) << "held at the coarse level";
        ASSERT_TRUE(forest.setKindThresholds(0, forest.getKind(0).thresholds, 0));

        // A second cull with transitions allocates nothing.
        const std::size_t capacity = vis.getCapacityBytes();
        drawsAt(forest, vis, 9.5f, 0.2f);
        EXPECT_EQ(vis.getCapacityBytes(), capacity);
    }

    TEST(ForestInstances, aTransitionTakesAtMostTheLowerHalfOfItsLevel)
    {
        // Switches at 10 m and 11 m: level 1 spans screen sizes 1.1 apart, so a transition of 0.5 into
        // level 2 ends at sqrt(1.1) = 1.0488 times the 11 m switch's (10.49 m), not at 1.5 (7.3 m).
        ForestInstances forest;
        ForestKind kind = pixelKind("tree", {100.0f * glm::pi<float>(), 100.0f * glm::pi<float>() / 1.21f});
        kind.boundsCentre = glm::vec3(0.0f);
        kind.boundsRadius = 1.0f;
        ASSERT_TRUE(forest.addKind(kind));
        ASSERT_TRUE(forest.add(ForestInstance{glm::vec3(0.0f, 0.0f, -10.0f), 0.0f, 1.0f, 0}));
        ForestVisibility vis;
        EXPECT_EQ(drawsAt(forest, vis, 10.6f, 0.5f).size(), 2u) << "11 / 10.6 = 1.038: in level 1's band";
        EXPECT_EQ(drawsAt(forest, vis, 10.4f, 0.5f).size(), 1u) << "11 / 10.4 = 1.058: level 1 alone";
        // Level 0 has no finer neighbour: its band is the whole 0.5 (10 m to 6.67 m).
        EXPECT_EQ(drawsAt(forest, vis, 7.0f, 0.5f).size(), 2u);
        EXPECT_EQ(drawsAt(forest, vis, 6.5f, 0.5f).size(), 1u);
        // The last level has no coarser neighbour: nothing fades beyond it.
        EXPECT_EQ(drawsAt(forest, vis, 30.0f, 0.5f).size(), 1u);
        // A hard switch (ForestKind::hardSwitches) does not fade; the others still do.
        ASSERT_TRUE(forest.setKindThresholds(0, forest.getKind(0).thresholds, 0b01));
        EXPECT_EQ(drawsAt(forest, vis, 7.0f, 0.5f).size(), 1u);
        EXPECT_EQ(drawsAt(forest, vis, 10.6f, 0.5f).size(), 2u);
    }

    TEST(ForestInstances, badTransitionsAreRefusedByName)
    {
        ForestInstances forest;
        addTreesSwitchingAtTenMetres(forest, {-10.0f});
        ForestVisibility vis;
        drawsAt(forest, vis, 9.5f, 0.2f);
        const CullCamera camera = CullCamera::fromSpec(CameraSpec(), 100.0f, 100.0f);
        for (const float bad : {-0.1f, std::nanf(""), 1.5f, std::numeric_limits<float>::infinity()})
        {
            const Result<void> culled = forest.cull(camera, 1.0f, vis, 0.0f, bad);
            ASSERT_FALSE(culled) << bad;
            EXPECT_NE(culled.error().message().find("LoD transition"), std::string::npos) << culled.error().message();
            EXPECT_EQ(vis.getDrawCount(), 2u) << "the last cull's result is kept";
        }
    }
}
