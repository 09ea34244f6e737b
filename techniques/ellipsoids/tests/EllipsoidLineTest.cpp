// The ellipsoid tree's lines (chunk "ellipsoid-lines", the ellipsoids-and-lines paper (001) §3.2, §5,
// §6): the chunk round trip and every corruption named, 16 bytes a line, a trunk without branches, a
// skeleton of one node, a mesh of one triangle, degenerate and absent bark, a skeleton extracted from
// a generated tree against the generator's own, the level counts, weights and targets, determinism
// over seeds and thread counts, 0.5 m vs 500 m, each level's coverage against the bark, and the
// registered bakers and descriptor.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/EllipsoidLineBaker.h"
#include "TreeLod/EllipsoidLineData.h"
#include "TreeLod/Package.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/SkeletonExtraction.h"
#include "TreeLod/TechniqueDescriptor.h"
#include "TestTrees.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace TreeLod
{
    namespace
    {
        using test::generatedOak;
        using test::scaled;
        constexpr float PI = 3.14159265358979f;

        EllipsoidLineData bakeOrFail(const TreeModel& m, const EllipsoidLineOptions& options = {},
                                     std::vector<double>* weights = nullptr)
        {
            Result<EllipsoidLineData> r = bakeEllipsoidLines(m, options, "test tree", {}, weights);
            EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message());
            return r.ok() ? std::move(r).value() : EllipsoidLineData();
        }

        const EllipsoidLineData& oakLines()
        {
            static const EllipsoidLineData d = bakeOrFail(generatedOak(256));
            return d;
        }

        Material barkMaterial()
        {
            Material bark;
            bark.name = "Bark";
            bark.baseColour = glm::vec4(0.4f, 0.3f, 0.2f, 1.0f);
            return bark;
        }

        /// A bark tube as the generator and glTF exporters make one: a ring of `sides` + 1 vertices
        /// (the seam duplicated for its UVs) around each axis point but the last, radius `radius(t)`
        /// (t = 0 at the base, 1 at the top), open at the base, closed by a cone to the last point
        /// (its apex one vertex per side, as UVs need).
        TreeModel tubeModel(const std::vector<glm::vec3>& axis, float baseRadius, float topRadius, int sides)
        {
            TreeModel m;
            m.name = "tube";
            m.materials.push_back(barkMaterial());
            const std::size_t rings = axis.size() - 1;
            for (std::size_t i = 0; i < rings; ++i)
            {
                const glm::vec3 t = glm::normalize(axis[std::min(i + 1, rings)] - axis[i == 0 ? 0 : i - 1]);
                const glm::vec3 u =
                    glm::normalize(glm::cross(t, std::abs(t.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1)));
                const glm::vec3 v = glm::cross(t, u);
                const float r = glm::mix(baseRadius, topRadius, float(i) / float(rings - 1));
                for (int k = 0; k <= sides; ++k)
                {
                    const float a = 2.0f * PI * float(k % sides) / float(sides);
                    const glm::vec3 out = std::cos(a) * u + std::sin(a) * v;
                    m.barkVertices.push_back({axis[i] + r * out, out, {float(k) / float(sides), float(i)}});
                }
            }
            const std::uint32_t apex = std::uint32_t(m.barkVertices.size());
            for (int k = 0; k < sides; ++k)
                m.barkVertices.push_back(
                    {axis.back(), glm::vec3(0, 1, 0), {(float(k) + 0.5f) / float(sides), float(rings)}});
            const std::uint32_t stride = std::uint32_t(sides) + 1;
            for (std::uint32_t i = 0; i + 1 < rings; ++i)
                for (std::uint32_t k = 0; k < std::uint32_t(sides); ++k)
                {
                    const std::uint32_t a = i * stride + k, b = a + 1, c = a + stride, d = c + 1;
                    m.barkIndices.insert(m.barkIndices.end(), {a, b, d, a, d, c});
                }
            const std::uint32_t last = std::uint32_t(rings - 1) * stride;
            for (std::uint32_t k = 0; k < std::uint32_t(sides); ++k)
                m.barkIndices.insert(m.barkIndices.end(), {last + k, last + k + 1, apex + k});
            m.barkTriangleMaterial.assign(m.barkIndices.size() / 3, 0);
            m.updateBounds();
            return m;
        }

        /// A trunk 3 m tall bending 0.5 m sideways, 0.15 m thick at the base and 0.06 m at the top
        /// ring, in 20 axis points.
        std::vector<glm::vec3> trunkAxis()
        {
            std::vector<glm::vec3> axis;
            for (int i = 0; i < 20; ++i)
            {
                const float t = float(i) / 19.0f;
                axis.push_back({0.5f * t * t, 3.0f * t, 0.1f * t});
            }
            return axis;
        }

        float segmentDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, float* along = nullptr)
        {
            const glm::vec3 ab = b - a;
            const float ll = glm::dot(ab, ab);
            const float t = ll > 0.0f ? std::clamp(glm::dot(p - a, ab) / ll, 0.0f, 1.0f) : 0.0f;
            if (along)
                *along = t;
            return glm::length(p - (a + t * ab));
        }

        /// Distance from `p` to the skeleton `s` (its segments, and its root nodes), and the
        /// skeleton's radius there.
        float skeletonDistance(const glm::vec3& p, const std::vector<SkeletonNode>& s, float* radius = nullptr)
        {
            float best = std::numeric_limits<float>::infinity();
            for (std::size_t j = 0; j < s.size(); ++j)
            {
                const std::int32_t q = s[j].parent;
                float t = 0.0f;
                const float d = q < 0 ? glm::length(p - s[j].position)
                                      : segmentDistance(p, s[std::size_t(q)].position, s[j].position, &t);
                if (d < best)
                {
                    best = d;
                    if (radius)
                        *radius = q < 0 ? s[j].radius : glm::mix(s[std::size_t(q)].radius, s[j].radius, t);
                }
            }
            return best;
        }

        float quantile(std::vector<float> v, float q)
        {
            std::sort(v.begin(), v.end());
            return v[std::min(v.size() - 1, std::size_t(q * float(v.size())))];
        }

        /// Fraction of pixels covered (alpha) in a side view of `m` framing the box [lo, hi].
        double coverage(const TreeModel& m, const glm::vec3& lo, const glm::vec3& hi, float azimuth)
        {
            const ReferenceRenderer renderer(m);
            const CameraSpec camera = CameraSpec::framing(lo, hi, azimuth, 10.0f);
            const RenderImages images = renderer.render(camera, albedoRenderOptions(128, 128, 4));
            double sum = 0.0;
            for (float a : images.alpha)
                sum += a;
            return sum / double(images.alpha.size());
        }

        bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        /// Level `level` of `d` is one chain from `base`: every line but one starts where another
        /// ends, that one at `base`, and no two start at the same end.
        void expectChain(const EllipsoidLineData& d, std::size_t level, const glm::vec3& base)
        {
            const EllipsoidLineLevel& l = d.levels[level];
            const float step =
                2.0f * std::max({ellipsoidLineEndStep(d, 0), ellipsoidLineEndStep(d, 1), ellipsoidLineEndStep(d, 2)});
            std::size_t first = 0;
            std::vector<std::uint32_t> from(l.count, 0);
            for (std::uint32_t i = l.first; i < l.first + l.count; ++i)
            {
                std::uint32_t ends = 0;
                for (std::uint32_t j = l.first; j < l.first + l.count; ++j)
                    if (j != i && glm::distance(d.lines[i].start, d.lines[j].end) < step)
                    {
                        ++ends;
                        ++from[j - l.first];
                    }
                if (ends == 0)
                {
                    ++first;
                    EXPECT_LT(glm::distance(d.lines[i].start, base), step) << "level " << level << ", line " << i;
                }
            }
            EXPECT_EQ(first, 1u) << "level " << level;
            for (std::uint32_t k = 0; k < l.count; ++k)
                EXPECT_LE(from[k], 1u) << "level " << level << ", line " << l.first + k;
        }

        // ---- The chunk ----------------------------------------------------------------------

        // Encode, decode: equal to the quantisation (ends half a step of 65535 over the box, radii
        // 0.025 %), 16 bytes a line, re-encoding identical.
        TEST(EllipsoidLineBake, roundTripIsExactToTheQuantisationAt16BytesALine)
        {
            static_assert(ELLIPSOID_LINE_RECORD_BYTES <= 16, "the issue's target: at most 16 bytes a line");
            const EllipsoidLineData& d = oakLines();
            ASSERT_GT(d.lines.size(), 1000u);
            const std::vector<std::uint8_t> bytes = encodeEllipsoidLineChunk(d);
            EXPECT_EQ(bytes.size(), d.encodedBytes());
            const std::size_t header = 48 + 4 * d.palette.size() + 16 * d.levels.size();
            EXPECT_EQ(bytes.size(), header + 16 * d.lines.size());
            Result<EllipsoidLineData> back = decodeEllipsoidLineChunk(bytes, "round trip");
            ASSERT_TRUE(back.ok()) << back.error().message();
            ASSERT_EQ(back->lines.size(), d.lines.size());
            ASSERT_EQ(back->levels.size(), d.levels.size());
            EXPECT_EQ(back->palette, d.palette);
            EXPECT_EQ(back->heightMetres, d.heightMetres);
            for (std::size_t k = 0; k < d.levels.size(); ++k)
            {
                EXPECT_EQ(back->levels[k].first, d.levels[k].first);
                EXPECT_EQ(back->levels[k].count, d.levels[k].count);
                EXPECT_EQ(back->levels[k].targetHeightPx, d.levels[k].targetHeightPx);
                EXPECT_EQ(back->levels[k].imageError, d.levels[k].imageError);
            }
            for (std::size_t i = 0; i < d.lines.size(); ++i)
            {
                const EllipsoidLine &a = d.lines[i], &b = back->lines[i];
                for (int k = 0; k < 3; ++k)
                {
                    EXPECT_LE(std::abs(a.start[k] - b.start[k]), ellipsoidLineEndStep(d, k) * 1.01f + 1e-6f) << i;
                    EXPECT_LE(std::abs(a.end[k] - b.end[k]), ellipsoidLineEndStep(d, k) * 1.01f + 1e-6f) << i;
                }
                EXPECT_LE(std::abs(a.radius / b.radius - 1.0f), ELLIPSOID_LINE_RADIUS_RELATIVE_STEP) << i;
                EXPECT_EQ(a.colour, b.colour);
                EXPECT_EQ(a.ambientOcclusion, b.ambientOcclusion);
            }
            EXPECT_EQ(encodeEllipsoidLineChunk(back.value()), bytes);
        }

        void expectFailure(const std::vector<std::uint8_t>& bytes, const std::string& element,
                           const std::string& reason)
        {
            Result<EllipsoidLineData> r = decodeEllipsoidLineChunk(bytes, "bad.treelod");
            ASSERT_FALSE(r.ok()) << element << ": " << reason;
            EXPECT_EQ(r.error().file, "bad.treelod");
            EXPECT_NE(r.error().element.find("chunk 'ellipsoid-lines' level 0"), std::string::npos)
                << r.error().message();
            EXPECT_NE(r.error().element.find(element), std::string::npos) << r.error().message();
            EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
        }

        void putF32(std::vector<std::uint8_t>& bytes, std::size_t at, float v) { std::memcpy(&bytes[at], &v, 4); }
        void putU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t v)
        {
            std::memcpy(&bytes[at], &v, 4);
        }

        // Every kind of damage is an error naming the element (little-endian host assumed).
        TEST(EllipsoidLineBake, corruptChunksAreNamed)
        {
            const EllipsoidLineData& d = oakLines();
            const std::vector<std::uint8_t> good = encodeEllipsoidLineChunk(d);
            const std::size_t palette = 40, levels = palette + 4 * d.palette.size() + 4, level1 = levels + 16;
            const std::size_t records = levels + 16 * d.levels.size() + 4, line3 = records + 3 * 16;

            for (std::size_t cut : {std::size_t(0), std::size_t(10), palette - 2, palette + 2, level1 + 6, records - 2,
                                    line3 + 5, good.size() - 1})
                expectFailure(std::vector<std::uint8_t>(good.begin(), good.begin() + std::ptrdiff_t(cut)), "",
                              "needs"); // "truncated: needs N bytes" or "count N ... needs N bytes"
            std::vector<std::uint8_t> b = good;
            b.push_back(0);
            expectFailure(b, "", "1 trailing bytes");
            b = good;
            putU32(b, 0, 4);
            expectFailure(b, "", "unknown flags 4");
            b = good;
            putF32(b, 4, std::nanf(""));
            expectFailure(b, "bounds", "not finite");
            b = good;
            putF32(b, 16, d.boundsMin.x - 1.0f);
            expectFailure(b, "bounds", "max >= min");
            b = good;
            putF32(b, 28, 0.0f);
            expectFailure(b, "bounds", "radius unit");
            b = good;
            putF32(b, 32, -1.0f);
            expectFailure(b, "bounds", "tree height");
            b = good;
            putU32(b, palette - 4, 0);
            expectFailure(b, "palette", "0 colours");
            b = good;
            putU32(b, palette - 4, 300);
            expectFailure(b, "palette", "300 colours");
            b = good;
            b[palette + 3] = 254;
            expectFailure(b, "palette entry 0", "alpha 254");
            b = good;
            putU32(b, levels - 4, 0);
            expectFailure(b, "levels", "0 levels");
            b = good;
            putF32(b, level1 + 8, std::nanf(""));
            expectFailure(b, "level 1", "target height");
            b = good;
            putF32(b, level1 + 12, 2.0f);
            expectFailure(b, "level 1", "image error");
            b = good;
            putU32(b, level1, d.levels[1].first + 1);
            expectFailure(b, "level 1", "contiguous");
            b = good;
            putU32(b, level1 + 4, 0);
            expectFailure(b, "level 1", "no lines");
            b = good;
            putU32(b, levels + 16 * (d.levels.size() - 1) + 4, d.levels.back().count + 1);
            expectFailure(b, "level " + std::to_string(d.levels.size() - 1), "run past");
            b = good;
            putU32(b, levels + 16 * (d.levels.size() - 1) + 4, d.levels.back().count + 1);
            putU32(b, records - 4, std::uint32_t(d.lines.size() + 1));
            expectFailure(b, "lines", "count");
            b = good;
            b[line3 + 14] = std::uint8_t(d.palette.size());
            expectFailure(b, "line 3", "colour index");
        }

        // ---- Skeletons ----------------------------------------------------------------------

        // One bent tube, no skeleton: the extracted skeleton is one chain from the base ring's centre
        // to the apex, on the axis within a fifth of the local radius, with radii within 15 % of the
        // tube's (bands cut the bend's rings slantwise; the tip node is the apex, radius 0). Every
        // level is a chain, every merge a straighten: the last line runs from the base to the apex.
        // With the axis as the model's own skeleton: the same chains, on the given nodes.
        TEST(EllipsoidLineBake, trunkWithoutBranches)
        {
            const std::vector<glm::vec3> axis = trunkAxis();
            TreeModel tube = tubeModel(axis, 0.15f, 0.06f, 12);
            const std::vector<SkeletonNode> s = extractSkeleton(tube);
            ASSERT_GE(s.size(), 6u);
            std::vector<SkeletonNode> given;
            for (std::size_t i = 0; i < axis.size(); ++i)
                given.push_back({axis[i], i + 1 < axis.size() ? glm::mix(0.15f, 0.06f, float(i) / 18.0f) : 0.0f,
                                 std::int32_t(i) - 1});
            EXPECT_LT(glm::distance(s.front().position, axis.front()), 1e-4f);
            EXPECT_LT(glm::distance(s.back().position, axis.back()), 1e-4f);
            EXPECT_EQ(s.back().radius, 0.0f);
            for (std::size_t i = 0; i < s.size(); ++i)
            {
                EXPECT_EQ(s[i].parent, std::int32_t(i) - 1) << "node " << i;
                float radius = 0.0f;
                const float d = skeletonDistance(s[i].position, given, &radius);
                if (i + 1 < s.size())
                {
                    EXPECT_LT(d, 0.2f * radius) << "node " << i;
                    EXPECT_NEAR(s[i].radius / radius, 1.0f, 0.15f) << "node " << i;
                }
            }

            for (bool own : {false, true})
            {
                tube.skeleton = own ? given : std::vector<SkeletonNode>{};
                const std::size_t nodes = own ? given.size() : s.size();
                const EllipsoidLineData d = bakeOrFail(tube);
                ASSERT_FALSE(d.levels.empty());
                EXPECT_EQ(d.levels[0].count, nodes - 1) << own;
                EXPECT_EQ(d.levels.back().count, 1u) << own;
                for (std::size_t k = 0; k < d.levels.size(); ++k)
                    expectChain(d, k, axis.front());
                const EllipsoidLine& last = d.lines.back();
                const float step = 2.0f * std::max({ellipsoidLineEndStep(d, 0), ellipsoidLineEndStep(d, 1),
                                                    ellipsoidLineEndStep(d, 2)});
                EXPECT_LT(glm::distance(last.start, axis.front()), step) << own;
                EXPECT_LT(glm::distance(last.end, axis.back()), step) << own;
                EXPECT_GT(last.radius, 0.06f) << own;
                EXPECT_LT(last.radius, 0.15f) << own;
            }
        }

        // A skeleton of one node: one level of one line of zero length on it, the node's radius.
        TEST(EllipsoidLineBake, skeletonOfOneNode)
        {
            TreeModel tube = tubeModel(trunkAxis(), 0.15f, 0.06f, 12);
            tube.skeleton = {{glm::vec3(0.1f, 1.5f, 0.0f), 0.12f, -1}};
            const EllipsoidLineData d = bakeOrFail(tube);
            ASSERT_EQ(d.levels.size(), 1u);
            ASSERT_EQ(d.lines.size(), 1u);
            EXPECT_EQ(d.lines[0].start, d.lines[0].end);
            EXPECT_LT(glm::distance(d.lines[0].start, glm::vec3(0.1f, 1.5f, 0.0f)), 1e-6f);
            EXPECT_NEAR(d.lines[0].radius, 0.12f, 1e-6f);
            EXPECT_TRUE(std::isfinite(d.levels[0].targetHeightPx) && d.levels[0].targetHeightPx > 0.0f);
            // A sphere of diameter 0.24 m: 1 px wide when the tube (3 m and its tilted base ring) is
            // its height / 0.24 px tall.
            EXPECT_NEAR(d.heightMetres, tube.boundsMax.y - tube.boundsMin.y, 1e-6f);
            EXPECT_NEAR(d.levels[0].targetHeightPx, d.heightMetres / 0.24f, 1e-3f);
            EXPECT_GT(d.levels[0].imageError, 0.0f);
        }

        // One triangle: one node at its centroid, radius the mean distance of its corners from it, one
        // line of zero length there.
        TEST(EllipsoidLineBake, meshOfOneTriangle)
        {
            TreeModel m;
            m.materials.push_back(barkMaterial());
            m.barkVertices = {{{0, 0, 0}, {0, 0, 1}, {}}, {{1, 0, 0}, {0, 0, 1}, {}}, {{0, 1, 0}, {0, 0, 1}, {}}};
            m.barkIndices = {0, 1, 2};
            m.barkTriangleMaterial = {0};
            m.updateBounds();
            const std::vector<SkeletonNode> s = extractSkeleton(m);
            ASSERT_EQ(s.size(), 1u);
            const glm::vec3 centre(1.0f / 3.0f, 1.0f / 3.0f, 0.0f);
            EXPECT_LT(glm::distance(s[0].position, centre), 1e-6f);
            const float radius = (glm::length(centre) + 2.0f * glm::distance(centre, glm::vec3(1, 0, 0))) / 3.0f;
            EXPECT_NEAR(s[0].radius, radius, 1e-6f);
            EXPECT_EQ(s[0].parent, -1);
            const EllipsoidLineData d = bakeOrFail(m);
            ASSERT_EQ(d.lines.size(), 1u);
            EXPECT_EQ(d.lines[0].start, d.lines[0].end);
            EXPECT_NEAR(d.lines[0].radius, radius, 1e-3f * radius);
        }

        // No bark, or bark of zero area only: no lines and no error (nor a chunk). Degenerate
        // triangles added to a tube change nothing: the same bytes, nothing non-finite.
        TEST(EllipsoidLineBake, degenerateAndAbsentBark)
        {
            const TreeModel& oak = generatedOak(256);
            TreeModel leavesOnly = oak;
            leavesOnly.barkVertices.clear();
            leavesOnly.barkIndices.clear();
            leavesOnly.barkTriangleMaterial.clear();
            leavesOnly.skeleton.clear();
            leavesOnly.updateBounds();
            TreeModel flat;
            flat.materials.push_back(barkMaterial());
            flat.barkVertices = {{{0, 0, 0}, {0, 1, 0}, {}}, {{1, 1, 1}, {0, 1, 0}, {}}, {{2, 2, 2}, {0, 1, 0}, {}}};
            flat.barkIndices = {0, 1, 2, 0, 0, 1, 2, 2, 2};
            flat.barkTriangleMaterial = {0, 0, 0};
            flat.updateBounds();
            for (const TreeModel* m : {&leavesOnly, &flat})
            {
                EXPECT_TRUE(extractSkeleton(*m).empty());
                const EllipsoidLineData d = bakeOrFail(*m);
                EXPECT_TRUE(d.lines.empty());
                EXPECT_TRUE(d.levels.empty());
                PackageWriter writer;
                ASSERT_TRUE(addEllipsoidLineChunk(writer, *m, {}, "bare", {}).ok());
                EXPECT_TRUE(writer.hasChunk(REFERENCE_CHUNK, 0));
                EXPECT_FALSE(writer.hasChunk(ELLIPSOID_LINES_CHUNK, 0));
            }

            const TreeModel tube = tubeModel(trunkAxis(), 0.15f, 0.06f, 12);
            TreeModel damaged = tube;
            const std::uint32_t n = std::uint32_t(damaged.barkVertices.size());
            damaged.barkVertices.push_back(
                {0.5f * (tube.barkVertices[0].position + tube.barkVertices[1].position), {}, {}});
            damaged.barkIndices.insert(damaged.barkIndices.end(), {0, 0, 1, 0, 1, n, 5, 5, 5, 13, 14, 13});
            damaged.barkTriangleMaterial.resize(damaged.barkIndices.size() / 3, 0);
            const EllipsoidLineData a = bakeOrFail(tube), b = bakeOrFail(damaged);
            EXPECT_EQ(extractSkeleton(damaged).size(), extractSkeleton(tube).size());
            EXPECT_EQ(encodeEllipsoidLineChunk(a), encodeEllipsoidLineChunk(b));
            for (const EllipsoidLine& l : b.lines)
                EXPECT_TRUE(finite(l.start) && finite(l.end) && std::isfinite(l.radius));
        }

        // The generated oak without its skeleton (its bark: one tube per stem, split at the UV seam,
        // not joined to its parent's): the extracted skeleton lies on the generator's. Measured (seed
        // 1): 99 % of the extracted nodes within 0.81 of the local radius of the generator's skeleton,
        // all within 0.005 D; 99 % of the generator's nodes within 0.34 radii of the extracted one,
        // all within 0.0022 D; 1638 nodes for 1582. The lines baked from it do as well.
        TEST(EllipsoidLineBake, extractedSkeletonFollowsTheGenerator)
        {
            const TreeModel& oak = generatedOak(256);
            TreeModel bare = oak;
            bare.skeleton.clear();
            const std::vector<SkeletonNode> s = extractSkeleton(bare);
            EXPECT_EQ(barkSkeleton(oak).size(), oak.skeleton.size());
            EXPECT_EQ(barkSkeleton(bare).size(), s.size());
            const float D = glm::length(oak.boundsMax - oak.boundsMin);
            ASSERT_NEAR(float(s.size()) / float(oak.skeleton.size()), 1.0f, 0.1f);
            std::vector<float> forward, backward;
            float forwardMax = 0.0f, backwardMax = 0.0f;
            std::size_t roots = 0;
            for (std::size_t i = 0; i < s.size(); ++i)
            {
                roots += s[i].parent < 0;
                EXPECT_LT(s[i].parent, std::int32_t(i));
                EXPECT_TRUE(finite(s[i].position) && std::isfinite(s[i].radius) && s[i].radius >= 0.0f);
                float radius = 0.0f;
                const float d = skeletonDistance(s[i].position, oak.skeleton, &radius);
                forward.push_back(d / std::max({radius, s[i].radius, 1e-3f * D}));
                forwardMax = std::max(forwardMax, d / D);
            }
            for (const SkeletonNode& n : oak.skeleton)
            {
                float radius = 0.0f;
                const float d = skeletonDistance(n.position, s, &radius);
                backward.push_back(d / std::max({radius, n.radius, 1e-3f * D}));
                backwardMax = std::max(backwardMax, d / D);
            }
            EXPECT_EQ(roots, 1u);
            EXPECT_LT(quantile(forward, 0.99f), 1.0f);
            EXPECT_LT(forwardMax, 0.01f);
            EXPECT_LT(quantile(backward, 0.99f), 0.6f);
            EXPECT_LT(backwardMax, 0.005f);

            const EllipsoidLineData own = oakLines(), extracted = bakeOrFail(bare);
            ASSERT_EQ(extracted.levels.size(), own.levels.size());
            for (std::size_t k = 0; k < own.levels.size(); ++k)
                EXPECT_NEAR(extracted.levels[k].imageError / own.levels[k].imageError, 1.0f, 0.25f) << "level " << k;
        }

        // ---- The hierarchy ------------------------------------------------------------------

        // 1581 segments, divisor 4: 1581, 395, 98, 24, 6, 1; divisor 8: 1581, 197, 24, 3, 1. Every
        // level's weights sum to the same total, level 0's are the capsules' volumes; targets never
        // grow towards coarser levels; coarser levels err more, and more still without the image
        // error's choice.
        TEST(EllipsoidLineBake, levelCountsWeightsAndTargets)
        {
            const TreeModel& oak = generatedOak(256);
            ASSERT_EQ(oak.skeleton.size(), 1582u);
            std::vector<double> weights;
            const EllipsoidLineData d = bakeOrFail(oak, {}, &weights);
            ASSERT_EQ(weights.size(), d.lines.size());
            const std::uint32_t counts[] = {1581, 395, 98, 24, 6, 1};
            ASSERT_EQ(d.levels.size(), 6u);
            double total = 0.0;
            for (std::uint32_t i = 0; i < d.levels[0].count; ++i)
            {
                const EllipsoidLine& l = d.lines[i];
                const double volume =
                    double(PI) * l.radius * l.radius * (glm::distance(l.start, l.end) + 4.0 * l.radius / 3.0);
                EXPECT_NEAR(weights[i] / volume, 1.0, 2e-3) << "line " << i;
                total += weights[i];
            }
            for (std::size_t k = 0; k < d.levels.size(); ++k)
            {
                EXPECT_EQ(d.levels[k].count, counts[k]) << "level " << k;
                double sum = 0.0;
                for (std::uint32_t i = d.levels[k].first; i < d.levels[k].first + d.levels[k].count; ++i)
                    sum += weights[i];
                EXPECT_NEAR(sum / total, 1.0, 1e-9) << "level " << k;
                if (k > 0)
                {
                    EXPECT_LE(d.levels[k].targetHeightPx, d.levels[k - 1].targetHeightPx) << "level " << k;
                }
            }
            EXPECT_LT(d.levels[0].imageError, 0.5f * d.levels.back().imageError);
            EXPECT_LT(d.levels[0].imageError, d.levels[2].imageError);

            // The image error steers the merges: one draw a merge (a random merge order) errs much
            // more at the first merged levels (measured 0.058 and 0.094 against 0.024 and 0.046).
            EllipsoidLineOptions random;
            random.candidates = 1;
            const EllipsoidLineData r = bakeOrFail(oak, random);
            ASSERT_EQ(r.levels.size(), d.levels.size());
            EXPECT_LT(d.levels[1].imageError, 0.6f * r.levels[1].imageError);
            EXPECT_LT(d.levels[2].imageError, 0.7f * r.levels[2].imageError);

            EllipsoidLineOptions eight;
            eight.linesDivisor = 8;
            const EllipsoidLineData e = bakeOrFail(oak, eight);
            ASSERT_EQ(e.levels.size(), 5u);
            const std::uint32_t eightCounts[] = {1581, 197, 24, 3, 1};
            for (std::size_t k = 0; k < e.levels.size(); ++k)
                EXPECT_EQ(e.levels[k].count, eightCounts[k]) << "level " << k;
        }

        // The same seed gives the same bytes with 1 and 2 TBB threads; another seed draws other pairs.
        TEST(EllipsoidLineBake, deterministicForSeedAndThreads)
        {
            const TreeModel& oak = generatedOak(256);
            const std::vector<std::uint8_t> reference = encodeEllipsoidLineChunk(oakLines());
            std::vector<std::uint8_t> one, two;
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
                one = encodeEllipsoidLineChunk(bakeOrFail(oak));
            }
            {
                tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
                two = encodeEllipsoidLineChunk(bakeOrFail(oak));
            }
            EXPECT_EQ(one, reference);
            EXPECT_EQ(two, reference);
            EllipsoidLineOptions other;
            other.seed = 99;
            EXPECT_NE(encodeEllipsoidLineChunk(bakeOrFail(oak, other)), reference);
        }

        // A 0.5 m tree and the same tree 1024 times larger (exact in floating point) give the same
        // lines times 1024, also through skeleton extraction. At 1000 times (the input rounds
        // differently) the level counts and level 0 are the same, and every level's error and target
        // stay close: rounding may change which of two nearly equal candidates wins a merge.
        TEST(EllipsoidLineBake, scaleFree)
        {
            for (bool extract : {false, true})
            {
                TreeModel base = generatedOak(128);
                if (extract)
                    base.skeleton.clear();
                const TreeModel small = scaled(base, 0.5f / base.boundsMax.y);
                const EllipsoidLineData a = bakeOrFail(small);
                const EllipsoidLineData b = bakeOrFail(scaled(small, 1024.0f));
                ASSERT_EQ(a.lines.size(), b.lines.size());
                ASSERT_EQ(a.levels.size(), b.levels.size());
                EXPECT_EQ(b.radiusUnit, 1024.0f * a.radiusUnit);
                for (std::size_t k = 0; k < a.levels.size(); ++k)
                {
                    EXPECT_EQ(a.levels[k].count, b.levels[k].count);
                    EXPECT_EQ(a.levels[k].imageError, b.levels[k].imageError);
                    EXPECT_EQ(a.levels[k].targetHeightPx, b.levels[k].targetHeightPx);
                }
                for (std::size_t i = 0; i < a.lines.size(); ++i)
                {
                    EXPECT_EQ(1024.0f * a.lines[i].start, b.lines[i].start) << i;
                    EXPECT_EQ(1024.0f * a.lines[i].end, b.lines[i].end) << i;
                    EXPECT_EQ(1024.0f * a.lines[i].radius, b.lines[i].radius) << i;
                }
                if (extract)
                    continue;
                const EllipsoidLineData c = bakeOrFail(scaled(small, 1000.0f));
                ASSERT_EQ(c.levels.size(), a.levels.size());
                for (std::size_t k = 0; k < a.levels.size(); ++k)
                {
                    EXPECT_EQ(c.levels[k].count, a.levels[k].count);
                    EXPECT_NEAR(c.levels[k].imageError / a.levels[k].imageError, 1.0f, 0.1f) << "level " << k;
                    EXPECT_NEAR(c.levels[k].targetHeightPx / a.levels[k].targetHeightPx, 1.0f, 0.25f) << "level " << k;
                }
                for (std::uint32_t i = 0; i < a.levels[0].count; ++i)
                    EXPECT_LT(glm::distance(1000.0f * a.lines[i].end, c.lines[i].end), 1e-4f * c.radiusUnit) << i;
            }
        }

        // Each level's rendered coverage from two side views the baker did not use, against the
        // bark's: within 15 % for the skeleton's lines and the first merged level, then falling as
        // averaged lines lose the spread of what they replace (measured at azimuths 45 and 200: 1.07
        // and 1.06, 0.99 and 0.98, 0.88 and 0.87, 0.59 and 0.56, 0.30 and 0.23, 0.13 and 0.12).
        TEST(EllipsoidLineBake, everyLevelCoversWhatTheBarkCovers)
        {
            const TreeModel& oak = generatedOak(256);
            const EllipsoidLineData& d = oakLines();
            ASSERT_EQ(d.levels.size(), 6u);
            const TreeModel bark = flatColourBark(oak);
            for (float azimuth : {45.0f, 200.0f})
            {
                const double reference = coverage(bark, bark.boundsMin, bark.boundsMax, azimuth);
                ASSERT_GT(reference, 0.02);
                for (std::size_t k = 0; k < d.levels.size(); ++k)
                {
                    const double c = coverage(ellipsoidLineLevelMesh(d, k), bark.boundsMin, bark.boundsMax, azimuth);
                    const double lowest[] = {0.85, 0.85, 0.7, 0.4, 0.15, 0.08};
                    EXPECT_GT(c / reference, lowest[k]) << "level " << k << ", azimuth " << azimuth;
                    EXPECT_LT(c / reference, 1.15) << "level " << k << ", azimuth " << azimuth;
                }
            }
            for (const EllipsoidLineLevel& l : d.levels)
            {
                EXPECT_GT(l.imageError, 0.0f);
                EXPECT_LT(l.imageError, 0.2f);
            }
            EXPECT_TRUE(ellipsoidLineLevelMesh(d, d.levels.size()).barkIndices.empty());
        }

        // ---- Registration -------------------------------------------------------------------

        // `treelod bake` knows "ellipsoid-lines" and its options, and "ellipsoids" writes the lines
        // too; `treelod info` describes the chunk; bad options and a broken skeleton are errors that
        // name them.
        TEST(EllipsoidLineBake, registeredAndErrorsNamed)
        {
            const BakeTechnique* baker = findBakeTechnique(ELLIPSOID_LINES_CHUNK);
            ASSERT_NE(baker, nullptr);
            std::vector<std::string> names;
            for (const BakeOptionInfo& o : baker->options)
                names.push_back(o.name);
            for (const char* name : {"candidates", "seed", "linesDivisor", "viewResolution"})
                EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
            const TechniqueDescriptor* descriptor = findTechniqueDescriptor(ELLIPSOID_LINES_CHUNK);
            ASSERT_NE(descriptor, nullptr);
            EXPECT_EQ(descriptor->formatVersion, ELLIPSOID_LINES_CHUNK_FORMAT_VERSION);
            Result<ChunkSummary> summary = descriptor->inspect(encodeEllipsoidLineChunk(oakLines()), "oak");
            ASSERT_TRUE(summary.ok()) << summary.error().message();
            EXPECT_NE(summary->text.find("1581 ("), std::string::npos) << summary->text;
            EXPECT_NE(summary->text.find("16 per line"), std::string::npos) << summary->text;

            const TreeModel& oak = generatedOak(256);
            PackageWriter writer;
            ASSERT_TRUE(findBakeTechnique("ellipsoids")
                            ->bake(writer, oak, {{"tries", "1"}, {"viewResolution", "32"}}, "oak", {})
                            .ok());
            EXPECT_TRUE(writer.hasChunk("ellipsoids", 0));
            ASSERT_NE(writer.chunkBytes(ELLIPSOID_LINES_CHUNK, 0), nullptr);
            EXPECT_EQ(*writer.chunkBytes(ELLIPSOID_LINES_CHUNK, 0), encodeEllipsoidLineChunk(oakLines()));

            Result<void> bad = baker->bake(writer, oak, {{"candidates", "0"}}, "oak.treelod", {});
            ASSERT_FALSE(bad.ok());
            EXPECT_NE(bad.error().element.find("ellipsoid-lines.candidates"), std::string::npos)
                << bad.error().message();
            bad = baker->bake(writer, oak, {{"viewResolution", "100"}}, "oak.treelod", {});
            ASSERT_FALSE(bad.ok());
            EXPECT_NE(bad.error().reason.find("power of two"), std::string::npos) << bad.error().message();

            TreeModel broken = oak;
            broken.skeleton[7].position.x = std::numeric_limits<float>::quiet_NaN();
            Result<EllipsoidLineData> r = bakeEllipsoidLines(broken, {}, "broken.glb");
            ASSERT_FALSE(r.ok());
            EXPECT_EQ(r.error().file, "broken.glb");
            EXPECT_NE(r.error().element.find("skeleton node 7"), std::string::npos) << r.error().message();
        }
    }
}
