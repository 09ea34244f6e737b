// BillboardLeafTiles (García et al. 2007 §3, §5, §5.2): the Leaves Texture and the leaf -> billboard
// placement. The key check goes through the shader's own addressing: a leaf is placed on a
// one-cell billboard, its entry encoded, and points of the leaf surface projected onto the
// plane are looked up with BillboardCloudSampler (hash -> list entry -> tile-local) and the
// tile; coverage and colour must match the leaf's texture at those points. Textures with
// distinct quadrants and an asymmetric cut-out catch sign, rotation and mirror errors.
#include "BillboardLeafTiles.h"

#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/Image.h"
#include "TreeLod/TreeGenerator.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace
    {
        constexpr float kPi = 3.14159265358979f;
        constexpr int kTexSize = 32;

        /// Quadrant colours (sRGB bytes) of the test texture, u right / v down: 0 top-left,
        /// 1 top-right, 2 bottom-left, 3 bottom-right.
        const glm::vec3 kQuadrant[4] = {{220, 40, 40}, {40, 200, 60}, {50, 70, 220}, {230, 210, 40}};

        int quadrantOf(float s, float v) { return (s < 0.5f ? 0 : 1) + (v < 0.5f ? 0 : 2); }

        glm::vec3 quadrantLinear(int q)
        {
            const glm::vec3 c = kQuadrant[q] / 255.0f;
            return {srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b)};
        }

        /// Opaque inside a one-texel transparent border, except a notch at the top right and a
        /// round hole in the bottom-left quadrant: no symmetry survives a flip or a turn.
        bool opaqueTexel(int x, int y)
        {
            if (x < 1 || y < 1 || x > kTexSize - 2 || y > kTexSize - 2)
                return false;
            const float s = (float(x) + 0.5f) / kTexSize, v = (float(y) + 0.5f) / kTexSize;
            if (s > 0.7f && v < 0.35f)
                return false;
            return glm::length(glm::vec2(s - 0.25f, v - 0.72f)) > 0.1f;
        }

        TextureImage quadrantTexture()
        {
            TextureImage t;
            t.name = "quadrants";
            t.width = t.height = kTexSize;
            t.rgba.resize(std::size_t(kTexSize) * kTexSize * 4);
            for (int y = 0; y < kTexSize; ++y)
                for (int x = 0; x < kTexSize; ++x)
                {
                    const glm::vec3 c =
                        kQuadrant[quadrantOf((float(x) + 0.5f) / kTexSize, (float(y) + 0.5f) / kTexSize)];
                    std::uint8_t* p = &t.rgba[(std::size_t(y) * kTexSize + x) * 4];
                    p[0] = std::uint8_t(c.r);
                    p[1] = std::uint8_t(c.g);
                    p[2] = std::uint8_t(c.b);
                    p[3] = opaqueTexel(x, y) ? 255 : 0;
                }
            return t;
        }

        /// The reference renderer's alpha lookup (bilinear, REPEAT) of quadrantTexture().
        float textureAlpha(float s, float v)
        {
            const float x = s * kTexSize - 0.5f, y = v * kTexSize - 0.5f;
            const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
            const float ax = x - float(x0), ay = y - float(y0);
            auto a = [](int px, int py) {
                px = (px % kTexSize + kTexSize) % kTexSize;
                py = (py % kTexSize + kTexSize) % kTexSize;
                return opaqueTexel(px, py) ? 1.0f : 0.0f;
            };
            return (1 - ay) * ((1 - ax) * a(x0, y0) + ax * a(x0 + 1, y0)) +
                   ay * ((1 - ax) * a(x0, y0 + 1) + ax * a(x0 + 1, y0 + 1));
        }

        const glm::vec3 kBackColour(0.4f, 0.7f, 1.0f);

        /// A quad leaf as TreeGenerator makes them: width along w (texture u), length along t
        /// (tip at v = 0), facing cross(w, t). mirrorTexture runs u against w instead.
        struct QuadLeaf
        {
            glm::vec3 centre{0.0f};
            glm::vec3 w{1, 0, 0}, t{0, 1, 0};
            float width = 0.06f, length = 0.1f;
            std::uint32_t material = 0;
            bool mirrorTexture = false;

            /// The surface point showing texture (s, v).
            glm::vec3 at(float s, float v) const
            {
                const float a = mirrorTexture ? 0.5f - s : s - 0.5f;
                return centre + a * width * w + (0.5f - v) * length * t;
            }
            glm::vec3 normal() const { return glm::normalize(glm::cross(w, t)); }
        };

        /// Leaf materials 0 .. materials - 1 (all on the quadrant texture unless `textured` is
        /// false; material 1 tinted green), white base colour, kBackColour on the back.
        TreeModel quadModel(const std::vector<QuadLeaf>& leaves, std::uint32_t materials = 1, bool textured = true)
        {
            TreeModel m;
            m.name = "quads";
            m.textures.push_back(quadrantTexture());
            for (std::uint32_t k = 0; k < materials; ++k)
            {
                Material mat;
                mat.name = "Leaves " + std::to_string(k);
                mat.isLeaf = true;
                mat.doubleSided = true;
                mat.texture = textured ? 0 : -1;
                mat.backColour = kBackColour;
                if (k == 1)
                    mat.baseColour = glm::vec4(0.5f, 1.0f, 0.5f, 1.0f);
                m.materials.push_back(mat);
            }
            for (const QuadLeaf& q : leaves)
            {
                Leaf l;
                l.firstVertex = std::uint32_t(m.leafVertices.size());
                l.vertexCount = 4;
                l.firstIndex = std::uint32_t(m.leafIndices.size());
                l.indexCount = 6;
                l.material = q.material;
                const glm::vec2 uvs[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
                for (const glm::vec2& uv : uvs)
                    m.leafVertices.push_back({q.at(uv.x, uv.y), q.normal(), uv});
                // Counter-clockwise around the normal.
                if (q.mirrorTexture)
                    for (std::uint32_t k : {0u, 2u, 1u, 0u, 3u, 2u})
                        m.leafIndices.push_back(l.firstVertex + k);
                else
                    for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
                        m.leafIndices.push_back(l.firstVertex + k);
                m.leaves.push_back(l);
                m.updateLeafRecord(m.leaves.size() - 1);
            }
            m.updateBounds();
            return m;
        }

        glm::vec3 randomUnit(std::mt19937& rng)
        {
            std::normal_distribution<float> g;
            glm::vec3 v(g(rng), g(rng), g(rng));
            return glm::length(v) > 1e-3f ? glm::normalize(v) : glm::vec3(0, 0, 1);
        }

        glm::vec3 orthogonalTo(const glm::vec3& n, std::mt19937& rng)
        {
            glm::vec3 r = randomUnit(rng);
            r -= n * glm::dot(r, n);
            return glm::length(r) > 1e-3f ? glm::normalize(r)
                                          : glm::normalize(glm::cross(n, glm::vec3(0.3f, 0.9f, 0.1f)));
        }

        glm::vec3 rotateAbout(const glm::vec3& v, const glm::vec3& axis, float angle)
        {
            return v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) +
                   axis * glm::dot(axis, v) * (1.0f - std::cos(angle));
        }

        /// A plane through `point` with unit normal N and axes U, V (N = cross(U, V)).
        struct Plane
        {
            glm::vec3 origin{0.0f}, U{1, 0, 0}, V{0, 1, 0}, N{0, 0, 1};
        };

        Plane planeWithNormal(const glm::vec3& N, const glm::vec3& near, std::mt19937& rng)
        {
            Plane p;
            p.N = glm::normalize(N);
            p.U = orthogonalTo(p.N, rng);
            p.V = glm::cross(p.N, p.U);
            p.origin = near + 0.3f * p.N; // off the leaf: only the projection along N matters
            return p;
        }

        /// One billboard with a single hash cell holding the one leaf's entry: the shader's
        /// addressing for this leaf, through BillboardCloudSampler.
        struct OneLeafCloud
        {
            BillboardCloudData data;
            Plane plane;
            float cellSize = 1.0f;
            LeafPlacement placement;
        };

        OneLeafCloud oneLeafCloud(const BillboardLeafTiles& tiles, std::uint32_t leaf, const glm::vec3& leafCentre,
                                  Plane plane, float cellSize)
        {
            OneLeafCloud c;
            // Put the cell's corner so the leaf centre is in the middle of the cell.
            const glm::vec3 rel = leafCentre - plane.origin;
            plane.origin += (glm::dot(rel, plane.U) - 0.5f * cellSize) * plane.U +
                            (glm::dot(rel, plane.V) - 0.5f * cellSize) * plane.V;
            c.plane = plane;
            c.cellSize = cellSize;
            c.placement = tiles.place(leaf, plane.origin, plane.U, plane.V, plane.N);
            Billboard b;
            b.origin = plane.origin;
            b.axisU = plane.U * cellSize;
            b.axisV = plane.V * cellSize;
            b.normal = plane.N;
            b.hashWidth = b.hashHeight = 1;
            c.data.billboards.push_back(b);
            c.data.hashAtlasWidth = c.data.hashAtlasHeight = 1;
            c.data.hashAtlas = {0, 0, 0, 1}; // list start 0, length 1
            c.data.entries.push_back(tiles.entryFor(c.placement, cellSize, 0, 0));
            c.data.orientationGrid = tiles.grid();
            c.data.tileSize = tiles.tileSize();
            c.data.tileColumns = tiles.tileColumns();
            c.data.leafImages = tiles.images();
            return c;
        }

        /// What the shader shows at world point p (projected along N) seen from the +N side
        /// (frontSide) or the other: linear albedo + coverage; tile and local when `fragment`.
        glm::vec4 shade(const OneLeafCloud& c, const BillboardLeafTiles& tiles, const glm::vec3& p, bool frontSide,
                        BillboardCloudSampler::Fragment* fragment = nullptr)
        {
            const glm::vec3 rel = p - c.plane.origin;
            const float u = glm::dot(rel, c.plane.U) / c.cellSize, v = glm::dot(rel, c.plane.V) / c.cellSize;
            if (u < 0.0f || u > 1.0f || v < 0.0f || v > 1.0f)
                return glm::vec4(0.0f);
            BillboardCloudSampler sampler(c.data);
            const std::vector<BillboardCloudSampler::Fragment> f = sampler.walk(0, u, v, frontSide);
            if (f.empty())
                return glm::vec4(0.0f);
            if (fragment)
                *fragment = f[0];
            return tiles.sample(f[0].tile, f[0].local);
        }

        /// The same lookup from the unquantised placement (the header's formula, no encoding):
        /// separates the placement's geometry from the entry's precision.
        glm::vec4 shadeExact(const OneLeafCloud& c, const BillboardLeafTiles& tiles, const glm::vec3& p, bool frontSide)
        {
            const LeafPlacement& pl = c.placement;
            const glm::vec3 rel = p - c.plane.origin;
            const glm::vec2 q = glm::vec2(glm::dot(rel, c.plane.U), glm::dot(rel, c.plane.V)) - pl.centre;
            const float cs = std::cos(pl.rotation), sn = std::sin(pl.rotation);
            glm::vec2 local = glm::vec2(cs * q.x + sn * q.y, -sn * q.x + cs * q.y) / pl.side + 0.5f;
            if (pl.mirrored)
                local.x = 1.0f - local.x;
            const std::uint32_t side = (frontSide ? 0u : 1u) ^ (pl.mirrored ? 1u : 0u);
            return tiles.sample(pl.orientation + side * tiles.grid() * tiles.grid(), local);
        }

        /// A plane whose normal is exactly orientation k's direction (or its opposite) in the frame
        /// of `leaf` (w, t, cross(w, t)): no orientation quantisation.
        Plane planeAlongOrientation(const QuadLeaf& leaf, std::uint32_t k, std::uint32_t grid, bool back,
                                    std::mt19937& rng)
        {
            const glm::vec3 d = billboardOrientationDirection(k, grid);
            const glm::vec3 N = d.x * leaf.w + d.y * leaf.t + d.z * leaf.normal();
            return planeWithNormal(back ? -N : N, leaf.centre, rng);
        }

        /// The orientation of `grid` whose direction is closest to `tilt` degrees off the pole,
        /// the n-th such (cycling), so cases spread over azimuths.
        std::uint32_t orientationWithTilt(std::uint32_t grid, float tilt, std::uint32_t n)
        {
            std::vector<std::pair<float, std::uint32_t>> byError;
            for (std::uint32_t k = 0; k < grid * grid; ++k)
            {
                const float a =
                    std::acos(std::clamp(billboardOrientationDirection(k, grid).z, -1.0f, 1.0f)) * 180.0f / kPi;
                byError.push_back({std::abs(a - tilt), k});
            }
            std::sort(byError.begin(), byError.end());
            std::vector<std::uint32_t> best;
            for (const auto& e : byError)
                if (e.first <= byError[0].first + 2.0f)
                    best.push_back(e.second);
            return best[n % best.size()];
        }

        /// Agreement of the shader's view of `leaf` with its texture over a grid of surface points.
        struct Agreement
        {
            int samples = 0, coverageAgree = 0;
            int colourSamples = 0, quadrantAgree = 0;
            float maxColourError = 0.0f;
            float coverage() const { return samples ? float(coverageAgree) / float(samples) : 0.0f; }
            float quadrant() const { return colourSamples ? float(quadrantAgree) / float(colourSamples) : 0.0f; }
        };

        Agreement compare(const OneLeafCloud& c, const BillboardLeafTiles& tiles, const QuadLeaf& leaf, bool frontSide,
                          bool exact = false)
        {
            Agreement a;
            const glm::vec3 viewer = frontSide ? c.plane.N : -c.plane.N;
            // The reference's albedo: base colour (white) from the front, back colour from the back.
            const glm::vec3 tint = glm::dot(viewer, leaf.normal()) > 0.0f ? glm::vec3(1.0f) : kBackColour;
            constexpr int n = 40;
            for (int iy = 0; iy < n; ++iy)
                for (int ix = 0; ix < n; ++ix)
                {
                    const float s = (float(ix) + 0.5f) / n, v = (float(iy) + 0.5f) / n;
                    const glm::vec4 got = exact ? shadeExact(c, tiles, leaf.at(s, v), frontSide)
                                                : shade(c, tiles, leaf.at(s, v), frontSide);
                    const float alpha = textureAlpha(s, v);
                    ++a.samples;
                    a.coverageAgree += (got.a >= 0.5f) == (alpha >= 0.5f) ? 1 : 0;
                    // Colour away from the quadrant boundaries and the cut-out's edges.
                    const bool interior = std::abs(s - 0.5f) > 0.1f && std::abs(v - 0.5f) > 0.1f &&
                                          textureAlpha(s - 0.08f, v) == 1.0f && textureAlpha(s + 0.08f, v) == 1.0f &&
                                          textureAlpha(s, v - 0.08f) == 1.0f && textureAlpha(s, v + 0.08f) == 1.0f;
                    if (!interior || got.a < 0.5f)
                        continue;
                    ++a.colourSamples;
                    const glm::vec3 rgb(got);
                    int best = 0;
                    for (int q = 1; q < 4; ++q)
                        if (glm::length(rgb - tint * quadrantLinear(q)) <
                            glm::length(rgb - tint * quadrantLinear(best)))
                            best = q;
                    a.quadrantAgree += best == quadrantOf(s, v) ? 1 : 0;
                    const glm::vec3 d = glm::abs(rgb - tint * quadrantLinear(quadrantOf(s, v)));
                    a.maxColourError = std::max({a.maxColourError, d.r, d.g, d.b});
                }
            return a;
        }

        /// `count` random leaves (random frames and sizes) spread over a 2 m box.
        std::vector<QuadLeaf> randomLeaves(std::size_t count, std::uint32_t seed)
        {
            std::mt19937 rng(seed);
            std::uniform_real_distribution<float> unit(0.0f, 1.0f);
            std::vector<QuadLeaf> out(count);
            for (QuadLeaf& q : out)
            {
                q.centre = glm::vec3(2.0f * unit(rng), 2.0f * unit(rng), 2.0f * unit(rng));
                q.t = randomUnit(rng);
                q.w = orthogonalTo(q.t, rng);
                q.length = 0.08f + 0.04f * unit(rng);
                q.width = 0.6f * q.length; // one aspect per material (the canonical leaf's)
            }
            return out;
        }

        std::filesystem::path testOut(const std::string& name)
        {
            const char* dir = std::getenv("TREELOD_TEST_OUT");
            std::filesystem::path root = dir ? dir : std::filesystem::temp_directory_path() / "treelod-test-out";
            std::filesystem::create_directories(root);
            return root / name;
        }

        Image toImage(const TextureImage& t)
        {
            Image image(t.width, t.height);
            for (std::size_t i = 0; i < image.pixels.size(); ++i)
                image.pixels[i] =
                    glm::vec4(t.rgba[i * 4], t.rgba[i * 4 + 1], t.rgba[i * 4 + 2], t.rgba[i * 4 + 3]) / 255.0f;
            return image;
        }

        const TreeModel& generatedOak()
        {
            static const TreeModel model = [] {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.seed = 3;
                options.leafCount = 300;
                options.textureSize = 128;
                Result<TreeModel> m = generateTree(options);
                EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message());
                return m.ok() ? std::move(m).value() : TreeModel();
            }();
            return model;
        }
    }

    // Leaves parallel to the plane (d = the pole, a cell centre for an odd grid) from the front
    // and from the back (mirrored): the lookup must reproduce the texture: coverage, the quadrant
    // layout (a mirror or turn error swaps quadrants) and colour, with the back colour when the
    // viewer sees the leaf's back. From the unquantised placement nearly exactly; through the
    // encoded entry (rotation in 1.4 degree steps, side in 2^(1/16) steps: up to ~1% of a leaf
    // length at its rim) and the shader's addressing almost as well.
    TEST(BillboardLeafTiles, parallelLeafRoundTripThroughShaderAddressing)
    {
        const std::vector<QuadLeaf> leaves = randomLeaves(12, 11);
        const TreeModel model = quadModel(leaves);
        const BillboardLeafTiles tiles(model, 64, 5);
        std::mt19937 rng(5);
        for (std::uint32_t i = 0; i < leaves.size(); ++i)
            for (bool back : {false, true})
            {
                const glm::vec3 n = leaves[i].normal();
                const OneLeafCloud c = oneLeafCloud(tiles, i, leaves[i].centre,
                                                    planeWithNormal(back ? -n : n, leaves[i].centre, rng), 0.25f);
                EXPECT_EQ(c.placement.mirrored, back);
                EXPECT_EQ(c.placement.orientation, 12u) << "the pole is the centre cell of a 5 x 5 grid";
                for (bool frontSide : {true, false})
                {
                    SCOPED_TRACE("leaf " + std::to_string(i) + (back ? " back-facing" : " front-facing") +
                                 (frontSide ? ", viewer on +N" : ", viewer on -N"));
                    const Agreement exact = compare(c, tiles, leaves[i], frontSide, true);
                    EXPECT_GT(exact.coverage(), 0.99f);
                    EXPECT_GT(exact.colourSamples, 200);
                    EXPECT_EQ(exact.quadrant(), 1.0f);
                    EXPECT_LT(exact.maxColourError, 0.03f);
                    const Agreement a = compare(c, tiles, leaves[i], frontSide);
                    EXPECT_GT(a.coverage(), 0.93f);
                    EXPECT_EQ(a.quadrant(), 1.0f);
                    EXPECT_LT(a.maxColourError, 0.03f);
                }
            }
    }

    // Tilted leaves (30, 60, 80 degrees off the plane, front and back facing) on planes along an
    // orientation of the grid: the tile is exactly the leaf's projection, so the lookup must
    // reproduce the texture at every tilt: this checks the tile projection, psi and the mirror.
    TEST(BillboardLeafTiles, tiltedLeafRoundTripThroughShaderAddressing)
    {
        const std::vector<QuadLeaf> leaves = randomLeaves(6, 23);
        const TreeModel model = quadModel(leaves);
        const BillboardLeafTiles tiles(model, 64, 8);
        std::mt19937 rng(9);
        std::uint32_t n = 0;
        for (std::uint32_t i = 0; i < leaves.size(); ++i)
            for (float tilt : {30.0f, 60.0f, 80.0f})
                for (bool back : {false, true})
                {
                    const std::uint32_t k = orientationWithTilt(8, tilt, n++);
                    const OneLeafCloud c = oneLeafCloud(tiles, i, leaves[i].centre,
                                                        planeAlongOrientation(leaves[i], k, 8, back, rng), 0.25f);
                    SCOPED_TRACE("leaf " + std::to_string(i) + " tilt " + std::to_string(tilt) + " k " +
                                 std::to_string(k) + (back ? " back" : ""));
                    EXPECT_EQ(c.placement.mirrored, back);
                    EXPECT_EQ(c.placement.orientation, k);
                    for (bool frontSide : {true, false})
                    {
                        // At 80 degrees the leaf is ~10 texels wide in its tile: its one-texel
                        // transparent border and the notch blur, hence the lower bar there.
                        const Agreement exact = compare(c, tiles, leaves[i], frontSide, true);
                        EXPECT_GT(exact.coverage(), tilt < 70.0f ? 0.98f : 0.9f);
                        EXPECT_EQ(exact.quadrant(), 1.0f);
                        // Through the encoded entry: its rotation and side steps shift the rim by
                        // up to ~1% of the leaf, magnified by the foreshortening in (s, v).
                        const Agreement a = compare(c, tiles, leaves[i], frontSide);
                        EXPECT_GT(a.coverage(), tilt < 70.0f ? 0.9f : 0.85f);
                        EXPECT_GT(a.quadrant(), 0.97f);
                    }
                }
    }

    // Random planes: the leaf's direction is quantised to the nearest orientation (up to ~8.7
    // degrees on a 16 x 16 grid, ~34 on 4 x 4), the paper's design. Agreement then degrades
    // with the tilt (a grazing leaf's foreshortening is sensitive to the direction), but the
    // leaf is still mostly where it should be.
    TEST(BillboardLeafTiles, quantisedOrientationStaysClose)
    {
        const std::vector<QuadLeaf> leaves = randomLeaves(6, 29);
        const TreeModel model = quadModel(leaves);
        const BillboardLeafTiles fine(model, 64, 16);
        const BillboardLeafTiles coarse(model, 64, 4);
        std::mt19937 rng(13);
        for (std::uint32_t i = 0; i < leaves.size(); ++i)
            for (float tilt : {10.0f, 30.0f, 60.0f})
                for (bool back : {false, true})
                {
                    const glm::vec3 n = leaves[i].normal();
                    glm::vec3 N = rotateAbout(n, orthogonalTo(n, rng), tilt * kPi / 180.0f);
                    const Plane plane = planeWithNormal(back ? -N : N, leaves[i].centre, rng);
                    SCOPED_TRACE("leaf " + std::to_string(i) + " tilt " + std::to_string(tilt) + (back ? " back" : ""));
                    const OneLeafCloud f = oneLeafCloud(fine, i, leaves[i].centre, plane, 0.25f);
                    EXPECT_EQ(f.placement.mirrored, back);
                    const Agreement a = compare(f, fine, leaves[i], true);
                    EXPECT_GT(a.coverage(), tilt < 45.0f ? 0.9f : 0.8f);
                    const OneLeafCloud c4 = oneLeafCloud(coarse, i, leaves[i].centre, plane, 0.25f);
                    EXPECT_GT(compare(c4, coarse, leaves[i], true).coverage(), tilt < 45.0f ? 0.75f : 0.6f);
                }
    }

    // Rotation and mirror by hand: a leaf in the plane z = 0 whose tip points along +U must get
    // psi = 3 pi / 2 (the tile's +y lands on R(psi) (0, 1) = +U); seen from -z it is mirrored.
    // Then the notch (top right of the texture, near the tip on the +w side) must be found by
    // the shader where the leaf has it.
    TEST(BillboardLeafTiles, rotationAndMirrorOfAKnownLeaf)
    {
        QuadLeaf q;
        q.centre = glm::vec3(0.0f);
        q.t = glm::vec3(1, 0, 0); // tip along +x
        q.w = glm::vec3(0, -1, 0); // normal cross(w, t) = +z
        const TreeModel model = quadModel({q});
        const BillboardLeafTiles tiles(model, 64, 3);
        std::mt19937 rng(1);
        Plane plane;
        plane.origin = glm::vec3(-0.5f, -0.5f, 0.2f);
        const LeafPlacement front = tiles.place(0, plane.origin, plane.U, plane.V, plane.N);
        EXPECT_FALSE(front.mirrored);
        EXPECT_NEAR(front.rotation, 1.5f * kPi, 1e-4f);
        EXPECT_NEAR(front.centre.x, 0.5f, 1e-5f);
        EXPECT_NEAR(front.centre.y, 0.5f, 1e-5f);
        EXPECT_NEAR(front.depth, -0.2f, 1e-5f);
        // Seen along -z: U = +x, V = -y, N = -z. The tip still points along +U.
        Plane under;
        under.U = glm::vec3(1, 0, 0);
        under.V = glm::vec3(0, -1, 0);
        under.N = glm::vec3(0, 0, -1);
        const LeafPlacement back = tiles.place(0, under.origin, under.U, under.V, under.N);
        EXPECT_TRUE(back.mirrored);
        EXPECT_EQ(back.orientation, front.orientation);
        EXPECT_NEAR(back.rotation, 1.5f * kPi, 1e-4f);
        EXPECT_NEAR(back.side, front.side, 1e-6f);
        for (const Plane& p : {plane, under})
        {
            const OneLeafCloud c = oneLeafCloud(tiles, 0, q.centre, p, 0.25f);
            EXPECT_LT(shade(c, tiles, q.at(0.85f, 0.15f), true).a, 0.1f) << "notch";
            EXPECT_GT(shade(c, tiles, q.at(0.15f, 0.15f), true).a, 0.9f) << "opposite corner";
            EXPECT_LT(shade(c, tiles, q.at(0.25f, 0.72f), true).a, 0.1f) << "hole";
            EXPECT_GT(shade(c, tiles, q.at(0.75f, 0.72f), true).a, 0.9f) << "mirror image of the hole";
        }
    }

    // A leaf whose texture runs mirrored on it (u against cross(t, n)): its image must still
    // land right (the frame flips n; only the front/back tint swaps, documented).
    TEST(BillboardLeafTiles, mirroredTextureLeafKeepsItsImage)
    {
        const std::vector<QuadLeaf> base = randomLeaves(4, 31);
        std::vector<QuadLeaf> leaves = base;
        for (QuadLeaf& q : leaves)
            q.mirrorTexture = true;
        const TreeModel model = quadModel(leaves);
        const BillboardLeafTiles tiles(model, 64, 5);
        std::mt19937 rng(2);
        for (std::uint32_t i = 0; i < leaves.size(); ++i)
        {
            const OneLeafCloud c = oneLeafCloud(tiles, i, leaves[i].centre,
                                                planeWithNormal(leaves[i].normal(), leaves[i].centre, rng), 0.25f);
            int agree = 0, total = 0;
            for (int iy = 0; iy < 30; ++iy)
                for (int ix = 0; ix < 30; ++ix)
                {
                    const float s = (ix + 0.5f) / 30.0f, v = (iy + 0.5f) / 30.0f;
                    agree += (shade(c, tiles, leaves[i].at(s, v), true).a >= 0.5f) == (textureAlpha(s, v) >= 0.5f);
                    ++total;
                }
            EXPECT_GT(float(agree) / float(total), 0.97f) << "leaf " << i;
        }
    }

    // The normal map: the stored normal, taken from the tile frame to the plane frame with the
    // entry's rotation and mirror, is the leaf's normal facing the viewer: exactly +-z for a
    // parallel leaf, within the orientation quantisation for tilted ones.
    TEST(BillboardLeafTiles, normalMapFacesTheViewer)
    {
        const std::vector<QuadLeaf> leaves = randomLeaves(8, 41);
        const TreeModel model = quadModel(leaves);
        const BillboardLeafTiles parallel(model, 64, 5);
        const BillboardLeafTiles tiles(model, 64, 12);
        // Parallel: the pole tile, both sides.
        const glm::vec3 n0 = parallel.sampleNormal(12, glm::vec2(0.3f, 0.3f));
        const glm::vec3 n1 = parallel.sampleNormal(25 + 12, glm::vec2(0.3f, 0.3f));
        EXPECT_GT(n0.z, 0.995f);
        EXPECT_LT(n1.z, -0.995f);
        std::mt19937 rng(4);
        std::uint32_t count = 0;
        for (std::uint32_t i = 0; i < leaves.size(); ++i)
            for (float tilt : {0.0f, 40.0f, 75.0f})
                for (bool back : {false, true})
                    for (bool quantised : {false, true})
                    {
                        const glm::vec3 n = leaves[i].normal();
                        Plane plane;
                        if (quantised)
                        {
                            const glm::vec3 N = rotateAbout(n, orthogonalTo(n, rng), tilt * kPi / 180.0f);
                            plane = planeWithNormal(back ? -N : N, leaves[i].centre, rng);
                        }
                        else
                            plane =
                                planeAlongOrientation(leaves[i], orientationWithTilt(12, tilt, count++), 12, back, rng);
                        const OneLeafCloud c = oneLeafCloud(tiles, i, leaves[i].centre, plane, 0.25f);
                        const LeafPlacement& p = c.placement;
                        for (bool frontSide : {true, false})
                        {
                            // The tile texel showing leaf point (0.2, 0.3), a quadrant interior where
                            // the bump is zero (the unquantised lookup; clamped into the tile).
                            const glm::vec3 rel = leaves[i].at(0.2f, 0.3f) - c.plane.origin;
                            const glm::vec2 q =
                                glm::vec2(glm::dot(rel, c.plane.U), glm::dot(rel, c.plane.V)) - p.centre;
                            const float cs = std::cos(p.rotation), sn = std::sin(p.rotation),
                                        f = p.mirrored ? -1.0f : 1.0f;
                            glm::vec2 local = glm::vec2(cs * q.x + sn * q.y, -sn * q.x + cs * q.y) / p.side + 0.5f;
                            if (p.mirrored)
                                local.x = 1.0f - local.x;
                            local = glm::clamp(local, glm::vec2(0.0f), glm::vec2(1.0f));
                            const std::uint32_t side = (frontSide ? 0u : 1u) ^ (p.mirrored ? 1u : 0u);
                            const glm::vec3 t = tiles.sampleNormal(p.orientation + side * 144u, local);
                            // Tile frame -> world: x = R(psi) F (1, 0), y = R(psi) (0, 1) in (U, V);
                            // z = +N, or -N when mirrored.
                            const glm::vec3 X = f * (cs * c.plane.U + sn * c.plane.V);
                            const glm::vec3 Y = -sn * c.plane.U + cs * c.plane.V;
                            const glm::vec3 Z = p.mirrored ? -c.plane.N : c.plane.N;
                            const glm::vec3 world = glm::normalize(t.x * X + t.y * Y + t.z * Z);
                            const glm::vec3 viewer = frontSide ? c.plane.N : -c.plane.N;
                            const glm::vec3 expected = glm::dot(n, viewer) > 0.0f ? n : -n;
                            const float angle =
                                std::acos(std::clamp(glm::dot(world, expected), -1.0f, 1.0f)) * 180.0f / kPi;
                            // Exact orientations: 8-bit encoding only; quantised: within the
                            // 12 x 12 grid's worst direction error (~11.5 degrees).
                            EXPECT_LT(angle, quantised ? 12.0f : 2.0f)
                                << "leaf " << i << " tilt " << tilt << (back ? " back" : "")
                                << (frontSide ? " +N" : " -N") << (quantised ? " quantised" : "");
                        }
                    }
    }

    // The luminance bump (§5.2) shows: across a quadrant boundary of different brightness the
    // stored normal of a parallel leaf tilts away from +z, in the flat interior it does not.
    TEST(BillboardLeafTiles, normalMapCarriesTheLuminanceBump)
    {
        QuadLeaf q;
        const TreeModel model = quadModel({q});
        const BillboardLeafTiles tiles(model, 64, 1);
        // Tile 0 with grid 1 is the pole: local x = s across the canonical rectangle scaled.
        float maxTilt = 0.0f;
        for (int x = 0; x < 64; ++x)
        {
            const glm::vec3 n = tiles.sampleNormal(0, glm::vec2((x + 0.5f) / 64.0f, 0.3f));
            maxTilt = std::max(maxTilt, std::sqrt(n.x * n.x + n.y * n.y));
        }
        EXPECT_GT(maxTilt, 0.05f);
        EXPECT_LT(maxTilt, 0.6f);
        const glm::vec3 flat = tiles.sampleNormal(0, glm::vec2(0.3f, 0.3f));
        EXPECT_GT(flat.z, 0.995f);
    }

    // §5.2, Fig. 11: the bilinear AO at the tile corners.
    TEST(BillboardLeafTiles, fitAoExactAtCornersAndLeastSquaresOtherwise)
    {
        // A square leaf aligned with U and V, with a hand-made placement whose tile is the leaf:
        // its 4 vertices sit on the tile corners and the fit returns their values.
        QuadLeaf q;
        q.width = q.length = 0.1f;
        const TreeModel model = quadModel({q});
        const BillboardLeafTiles tiles(model, 64, 3);
        LeafPlacement p;
        p.centre = glm::vec2(0.0f);
        p.side = 0.1f;
        const glm::vec3 origin(0.0f), U(1, 0, 0), V(0, 1, 0);
        // Vertices: (0,1) uv -> (-x, -y) = local (0, 0); (1,1) -> (1, 0); (1,0) -> (1, 1); (0,0) -> (0, 1).
        const std::vector<float> ao = {0.1f, 0.4f, 0.9f, 0.6f};
        std::array<std::uint8_t, 4> a = tiles.fitAo(0, p, origin, U, V, ao);
        EXPECT_NEAR(a[0], 0.1f * 255, 1.0f);
        EXPECT_NEAR(a[1], 0.4f * 255, 1.0f);
        EXPECT_NEAR(a[2], 0.6f * 255, 1.0f);
        EXPECT_NEAR(a[3], 0.9f * 255, 1.0f);
        // Mirrored: local x flips, so corners (0,0) <-> (1,0) and (0,1) <-> (1,1).
        p.mirrored = true;
        a = tiles.fitAo(0, p, origin, U, V, ao);
        EXPECT_NEAR(a[0], 0.4f * 255, 1.0f);
        EXPECT_NEAR(a[1], 0.1f * 255, 1.0f);
        EXPECT_NEAR(a[2], 0.9f * 255, 1.0f);
        EXPECT_NEAR(a[3], 0.6f * 255, 1.0f);
        // Rotated a quarter turn: local = R(-psi) q, the corner at local (0,0) is q = R(psi) (-1,-1) h.
        p.mirrored = false;
        p.rotation = 0.5f * kPi; // q = (-y, x) of local -> local (0,0) is vertex at (+h, -h): uv (1,1)
        a = tiles.fitAo(0, p, origin, U, V, ao);
        EXPECT_NEAR(a[0], 0.4f * 255, 1.0f);
        EXPECT_NEAR(a[1], 0.9f * 255, 1.0f);
        EXPECT_NEAR(a[2], 0.1f * 255, 1.0f);
        EXPECT_NEAR(a[3], 0.6f * 255, 1.0f);
    }

    TEST(BillboardLeafTiles, fitAoIsTheLeastSquaresBilinear)
    {
        // A 3 x 3 vertex leaf (flat) with AO = 0.3 + 0.4 x^2 + 0.2 y, not bilinear:
        // the fit must be a local minimum of the squared error over the u8 codes.
        TreeModel model = quadModel({QuadLeaf{}});
        Leaf& leaf = model.leaves[0];
        model.leafVertices.clear();
        model.leafIndices.clear();
        std::vector<float> ao;
        std::vector<glm::vec2> locals;
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 3; ++x)
            {
                const glm::vec2 l(0.15f + 0.35f * x, 0.1f + 0.4f * y);
                locals.push_back(l);
                model.leafVertices.push_back(
                    {glm::vec3(l.x - 0.5f, l.y - 0.5f, 0.0f), {0, 0, 1}, glm::vec2(l.x, 1.0f - l.y)});
                ao.push_back(0.3f + 0.4f * l.x * l.x + 0.2f * l.y); // its bilinear fit stays inside [0, 1]
            }
        for (std::uint32_t k : {0u, 2u, 8u, 0u, 8u, 6u})
            model.leafIndices.push_back(k);
        leaf.vertexCount = 9;
        leaf.indexCount = 6;
        model.updateLeafRecord(0);
        const BillboardLeafTiles tiles(model, 64, 3);
        LeafPlacement p;
        p.side = 1.0f;
        const std::array<std::uint8_t, 4> a = tiles.fitAo(0, p, glm::vec3(0.0f), {1, 0, 0}, {0, 1, 0}, ao);
        auto error = [&](const std::array<float, 4>& c) {
            double e = 0.0;
            for (std::size_t i = 0; i < ao.size(); ++i)
            {
                const glm::vec2 l = locals[i];
                const double f =
                    c[0] * (1 - l.x) * (1 - l.y) + c[1] * l.x * (1 - l.y) + c[2] * (1 - l.x) * l.y + c[3] * l.x * l.y;
                e += (f - ao[i]) * (f - ao[i]);
            }
            return e;
        };
        std::array<float, 4> best;
        for (int i = 0; i < 4; ++i)
            best[std::size_t(i)] = a[std::size_t(i)] / 255.0f;
        const double e0 = error(best);
        for (int i = 0; i < 4; ++i)
            for (float step : {-2.0f / 255.0f, 2.0f / 255.0f})
            {
                std::array<float, 4> other = best;
                other[std::size_t(i)] += step;
                EXPECT_GE(error(other), e0) << "coefficient " << i;
            }
        // And an exactly bilinear AO is recovered from 9 vertices.
        for (std::size_t i = 0; i < ao.size(); ++i)
            ao[i] = 0.2f * (1 - locals[i].x) * (1 - locals[i].y) + 0.7f * locals[i].x * (1 - locals[i].y) +
                    0.5f * (1 - locals[i].x) * locals[i].y + 1.0f * locals[i].x * locals[i].y;
        const std::array<std::uint8_t, 4> b = tiles.fitAo(0, p, glm::vec3(0.0f), {1, 0, 0}, {0, 1, 0}, ao);
        EXPECT_NEAR(b[0], 0.2f * 255, 1.0f);
        EXPECT_NEAR(b[1], 0.7f * 255, 1.0f);
        EXPECT_NEAR(b[2], 0.5f * 255, 1.0f);
        EXPECT_NEAR(b[3], 1.0f * 255, 1.0f);
    }

    // Degenerate AO inputs: one position (all vertices coincide) gives the mean everywhere,
    // collinear vertices stay bounded, NaN AO values are ignored.
    TEST(BillboardLeafTiles, fitAoDegenerateInputs)
    {
        TreeModel model = quadModel({QuadLeaf{}});
        const BillboardLeafTiles tiles(model, 64, 3);
        LeafPlacement p;
        p.side = 1.0f;
        TreeModel point = model;
        for (int k = 0; k < 4; ++k)
            point.leafVertices[std::size_t(k)].position = glm::vec3(0.1f, 0.2f, 0.0f);
        const BillboardLeafTiles pointTiles(point, 64, 3);
        std::array<std::uint8_t, 4> a =
            pointTiles.fitAo(0, p, glm::vec3(0.0f), {1, 0, 0}, {0, 1, 0}, {0.2f, 0.4f, 0.6f, 0.8f});
        for (std::uint8_t v : a)
            EXPECT_NEAR(v, 0.5f * 255, 1.0f);
        TreeModel line = model;
        for (int k = 0; k < 4; ++k)
            line.leafVertices[std::size_t(k)].position = glm::vec3(0.1f * k, 0.0f, 0.0f);
        const BillboardLeafTiles lineTiles(line, 64, 3);
        a = lineTiles.fitAo(0, p, glm::vec3(0.0f), {1, 0, 0}, {0, 1, 0}, {0.0f, 1.0f, 0.0f, 1.0f});
        // Along the line local y = 1/2 the fit is the regression line 0.5 + 2 (x - 0.65) of the
        // data, clamped: 0 at x = 0, 1 at x = 1; the ridge splits it evenly between y = 0 and 1.
        EXPECT_EQ(a[0], 0);
        EXPECT_EQ(a[2], 0);
        EXPECT_EQ(a[1], 255);
        EXPECT_EQ(a[3], 255);
        a = tiles.fitAo(0, p, glm::vec3(0.0f), {1, 0, 0}, {0, 1, 0}, {NAN, 0.5f, 0.5f, 0.5f});
        for (std::uint8_t v : a)
            EXPECT_NEAR(v, 0.5f * 255, 1.0f);
    }

    // Degenerate leaves: zero area, all UVs equal, no texture; the tiles stay finite and the
    // untextured leaf is a fully covered rectangle of its base colour.
    TEST(BillboardLeafTiles, degenerateLeaves)
    {
        std::vector<QuadLeaf> leaves(3);
        leaves[1].centre = glm::vec3(1, 0, 0);
        leaves[2].centre = glm::vec3(2, 0, 0);
        TreeModel model = quadModel(leaves);
        for (int k = 0; k < 4; ++k)
            model.leafVertices[std::size_t(k)].position = glm::vec3(0.0f); // zero area
        for (int k = 4; k < 8; ++k)
            model.leafVertices[std::size_t(k)].uv = glm::vec2(0.25f, 0.25f); // all UVs equal
        for (std::size_t l = 0; l < model.leaves.size(); ++l)
            model.updateLeafRecord(l);
        const BillboardLeafTiles tiles(model, 32, 3);
        Plane plane;
        plane.origin = glm::vec3(0, 0, 1);
        for (std::uint32_t i = 0; i < 3; ++i)
        {
            const LeafPlacement p = tiles.place(i, plane.origin, plane.U, plane.V, plane.N);
            EXPECT_TRUE(std::isfinite(p.centre.x) && std::isfinite(p.centre.y) && std::isfinite(p.rotation) &&
                        std::isfinite(p.side) && std::isfinite(p.depth));
            EXPECT_LT(p.orientation, tiles.tileCount());
        }
        EXPECT_EQ(tiles.colour().rgba.size(), std::size_t(tiles.colour().width) * tiles.colour().height * 4);
        // The degenerate leaves don't spoil their material's canonical leaf: leaf 2 is still exact.
        {
            std::mt19937 rng(3);
            const OneLeafCloud c = oneLeafCloud(tiles, 2, leaves[2].centre,
                                                planeWithNormal(leaves[2].normal(), leaves[2].centre, rng), 0.25f);
            EXPECT_GT(compare(c, tiles, leaves[2], true, true).coverage(), 0.98f);
        }

        // All UVs equal, on its own material: the leaf is one texel's colour (red quadrant) over
        // its whole quad.
        std::vector<QuadLeaf> one(1);
        TreeModel same = quadModel(one);
        for (Vertex& v : same.leafVertices)
            v.uv = glm::vec2(0.25f, 0.25f);
        same.updateLeafRecord(0);
        const BillboardLeafTiles sameTiles(same, 32, 3);
        const OneLeafCloud c = oneLeafCloud(sameTiles, 0, one[0].centre, plane, 0.25f);
        for (float s : {0.1f, 0.5f, 0.9f})
            for (float v : {0.1f, 0.5f, 0.9f})
            {
                const glm::vec4 got = shade(c, sameTiles, one[0].at(s, v), true);
                EXPECT_GT(got.a, 0.9f);
                EXPECT_NEAR(got.r, quadrantLinear(0).r, 0.02f);
            }

        // No texture: white, coverage 1 over the whole rectangle, none outside.
        const TreeModel plain = quadModel(one, 1, false);
        const BillboardLeafTiles plainTiles(plain, 32, 3);
        const OneLeafCloud pc = oneLeafCloud(plainTiles, 0, one[0].centre, plane, 0.25f);
        for (float s : {0.1f, 0.5f, 0.9f})
            for (float v : {0.1f, 0.5f, 0.9f})
            {
                const glm::vec4 got = shade(pc, plainTiles, one[0].at(s, v), true);
                EXPECT_GT(got.a, 0.99f);
                EXPECT_NEAR(got.g, 1.0f, 0.01f);
            }
        EXPECT_LT(shade(pc, plainTiles, one[0].at(1.3f, 0.5f), true).a, 0.01f);
        EXPECT_LT(shade(pc, plainTiles, one[0].at(0.5f, -0.3f), true).a, 0.01f);

        // No leaves: no tiles, empty images.
        const BillboardLeafTiles none(quadModel({}), 32, 3);
        EXPECT_EQ(none.tileCount(), 0u);
        EXPECT_TRUE(none.colour().rgba.empty());
    }

    // Two leaf materials: two blocks of 2 * grid^2 tiles in material order; a leaf of the second
    // material points into the second block and shows that material's colour.
    TEST(BillboardLeafTiles, twoMaterialsGiveTwoBlocks)
    {
        std::vector<QuadLeaf> leaves(2);
        leaves[1].material = 1;
        leaves[1].centre = glm::vec3(1, 0, 0);
        const TreeModel model = quadModel(leaves, 2);
        const BillboardLeafTiles tiles(model, 32, 3);
        ASSERT_EQ(tiles.images().size(), 2u);
        EXPECT_EQ(tiles.images()[0].material, 0u);
        EXPECT_EQ(tiles.images()[1].material, 1u);
        EXPECT_EQ(tiles.tileCount(), 2u * 2u * 9u);
        EXPECT_EQ(tiles.tileColumns(), 8u);
        EXPECT_EQ(tiles.colour().width, 8 * 32);
        EXPECT_EQ(tiles.colour().height, 5 * 32);
        Plane plane;
        plane.origin = glm::vec3(0, 0, 1);
        const LeafPlacement p0 = tiles.place(0, plane.origin, plane.U, plane.V, plane.N);
        const LeafPlacement p1 = tiles.place(1, plane.origin, plane.U, plane.V, plane.N);
        EXPECT_EQ(p0.orientation, 4u);
        EXPECT_EQ(p1.orientation, 18u + 4u);
        // Red quadrant: material 0 white base, material 1 (0.5, 1, 0.5).
        const OneLeafCloud c = oneLeafCloud(tiles, 1, leaves[1].centre, plane, 0.25f);
        const glm::vec4 got = shade(c, tiles, leaves[1].at(0.25f, 0.25f), true);
        EXPECT_NEAR(got.r, 0.5f * quadrantLinear(0).r, 0.02f);
        EXPECT_NEAR(got.g, 1.0f * quadrantLinear(0).g, 0.02f);
        // Unused tiles (36 .. 39) are transparent.
        const TextureImage& img = tiles.colour();
        for (std::uint32_t t = 36; t < 40; ++t)
        {
            const std::size_t x = (t % 8) * 32 + 16, y = (t / 8) * 32 + 16;
            EXPECT_EQ(img.rgba[(y * std::size_t(img.width) + x) * 4 + 3], 0) << "unused tile " << t;
        }
    }

    TEST(BillboardLeafTiles, deterministic)
    {
        const TreeModel model = quadModel(randomLeaves(20, 3), 2);
        const BillboardLeafTiles a(model, 32, 4);
        // The same bytes on one thread as on all of them.
        const BillboardLeafTiles b = [&]() {
            tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
            return BillboardLeafTiles(model, 32, 4);
        }();
        EXPECT_EQ(a.colour().rgba, b.colour().rgba);
        EXPECT_EQ(a.normal().rgba, b.normal().rgba);
    }

    // maxLod: at that level a tile's outermost texel ring is still transparent (its content
    // keeps away from its neighbours under a 2x2 box chain and a bilinear fetch), one level
    // coarser it no longer need be; and the margin rule 2^L <= TILE_MARGIN * tileSize.
    TEST(BillboardLeafTiles, maxLodKeepsTilesApart)
    {
        const TreeModel& oak = generatedOak();
        ASSERT_FALSE(oak.leaves.empty());
        const BillboardLeafTiles tiles(oak, 64, 4);
        EXPECT_EQ(tiles.maxLod(), 2u);
        EXPECT_EQ(BillboardLeafTiles(quadModel({QuadLeaf{}}), 8, 1).maxLod(), 0u);
        EXPECT_EQ(BillboardLeafTiles(quadModel({QuadLeaf{}}), 128, 1).maxLod(), 3u);
        // Box-filter the coverage down to maxLod and check every tile's border ring.
        const TextureImage& c = tiles.colour();
        int w = c.width, h = c.height;
        std::vector<float> alpha(std::size_t(w) * h);
        for (std::size_t i = 0; i < alpha.size(); ++i)
            alpha[i] = c.rgba[i * 4 + 3] / 255.0f;
        for (std::uint32_t l = 0; l < tiles.maxLod(); ++l)
        {
            std::vector<float> next(std::size_t(w / 2) * (h / 2));
            for (int y = 0; y < h / 2; ++y)
                for (int x = 0; x < w / 2; ++x)
                    next[std::size_t(y) * (w / 2) + x] =
                        0.25f *
                        (alpha[std::size_t(2 * y) * w + 2 * x] + alpha[std::size_t(2 * y) * w + 2 * x + 1] +
                         alpha[std::size_t(2 * y + 1) * w + 2 * x] + alpha[std::size_t(2 * y + 1) * w + 2 * x + 1]);
            alpha.swap(next);
            w /= 2;
            h /= 2;
        }
        const int T = int(tiles.tileSize() >> tiles.maxLod());
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (x % T == 0 || y % T == 0 || x % T == T - 1 || y % T == T - 1)
                {
                    ASSERT_EQ(alpha[std::size_t(y) * w + x], 0.0f) << "texel " << x << ", " << y << " at level "
                                                                    << tiles.maxLod();
                }
    }

    // The generated oak: every leaf, placed on a plane through it parallel to it, is seen by the
    // shader where its quad is (coverage at the quad's centre region), and the Leaves Texture
    // images are written for a look (billboard-leaves-colour.png, -normal.png).
    TEST(BillboardLeafTiles, generatedOakTiles)
    {
        const TreeModel& oak = generatedOak();
        ASSERT_FALSE(oak.leaves.empty());
        const BillboardLeafTiles tiles(oak, 64, 4);
        EXPECT_EQ(tiles.tileCount(), 32u);
        EXPECT_EQ(tiles.tileColumns(), 8u);
        ASSERT_TRUE(writePng(testOut("billboard-leaves-colour.png").string(), toImage(tiles.colour())).ok());
        ASSERT_TRUE(writePng(testOut("billboard-leaves-normal.png").string(), toImage(tiles.normal())).ok());
        // Each tile has content; side 1 (back tint) differs from side 0.
        for (std::uint32_t t = 0; t < 16; ++t)
        {
            float cover0 = 0.0f, cover1 = 0.0f;
            glm::vec3 sum0(0.0f), sum1(0.0f);
            for (int y = 0; y < 64; ++y)
                for (int x = 0; x < 64; ++x)
                {
                    const glm::vec2 l((x + 0.5f) / 64.0f, (y + 0.5f) / 64.0f);
                    const glm::vec4 a = tiles.sample(t, l), b = tiles.sample(t + 16, l);
                    cover0 += a.a;
                    cover1 += b.a;
                    sum0 += glm::vec3(a) * a.a;
                    sum1 += glm::vec3(b) * b.a;
                }
            EXPECT_GT(cover0, 200.0f) << "tile " << t;
            EXPECT_NEAR(cover0, cover1, 1e-3f) << "both sides have the same silhouette";
            EXPECT_GT(glm::length(sum0 / cover0 - sum1 / cover1), 0.005f) << "front and back tints differ";
        }
        // The oak leaves on planes parallel to them: the texture's alpha at the leaf quad's
        // points matches the shader's coverage (oak leaves are TreeGenerator quads, UV 0..1).
        std::mt19937 rng(8);
        int agree = 0, total = 0;
        const TextureImage& tex = oak.textures[std::size_t(oak.materials[oak.leaves[0].material].texture)];
        for (std::uint32_t i = 0; i < oak.leaves.size(); i += 7)
        {
            const Leaf& leaf = oak.leaves[i];
            const Vertex* v = &oak.leafVertices[leaf.firstVertex];
            // TreeGenerator's corners: base - w (0,1), base + w (1,1), tip + w (1,0), tip - w (0,0).
            const glm::vec3 centre = 0.25f * (v[0].position + v[1].position + v[2].position + v[3].position);
            const float cellSize = 3.0f * glm::length(v[3].position - v[0].position);
            const OneLeafCloud c = oneLeafCloud(tiles, i, centre, planeWithNormal(leaf.normal, centre, rng), cellSize);
            for (int iy = 0; iy < 16; ++iy)
                for (int ix = 0; ix < 16; ++ix)
                {
                    const float s = (ix + 0.5f) / 16.0f, t = (iy + 0.5f) / 16.0f;
                    const glm::vec3 p = glm::mix(glm::mix(v[3].position, v[2].position, s),
                                                 glm::mix(v[0].position, v[1].position, s), t);
                    const int tx = std::min(int(s * tex.width), tex.width - 1),
                              ty = std::min(int(t * tex.height), tex.height - 1);
                    const bool opaque = tex.rgba[(std::size_t(ty) * tex.width + tx) * 4 + 3] >= 128;
                    agree += (shade(c, tiles, p, true).a >= 0.5f) == opaque;
                    ++total;
                }
        }
        EXPECT_GT(float(agree) / float(total), 0.9f);
    }

    // A leaf atlas (2 x 2 leaf images) under six leaf materials with cutoffs 0.3 .. 0.7: one
    // leaf image per (material, atlas cell), and every leaf, placed on a plane parallel to it,
    // shows its own cell's silhouette as its material's alpha test cuts it.
    TEST(BillboardLeafTiles, atlasCellsAndMaterialCutoffsGiveEachLeafItsOwnImage)
    {
        GeneratorOptions options;
        options.preset = TreePreset::Oak;
        options.seed = 3;
        options.leafCount = 300;
        options.textureSize = 128;
        options.leafImages = 4;
        options.leafMaterials = 6;
        const Result<TreeModel> built = generateTree(options);
        ASSERT_TRUE(built.ok()) << built.error().message();
        const TreeModel& oak = built.value();
        const BillboardLeafTiles tiles(oak, 64, 4);
        ASSERT_EQ(tiles.images().size(), 24u);
        EXPECT_TRUE(tiles.warnings().empty());
        EXPECT_EQ(tiles.tileCount(), 24u * 32u);
        for (std::size_t i = 0; i < tiles.images().size(); ++i)
        {
            const BillboardLeafImage& image = tiles.images()[i];
            EXPECT_EQ(image.material, 1 + i / 4) << "image " << i;
            EXPECT_EQ(image.alphaCutoff, oak.materials[image.material].alphaCutoff) << "image " << i;
            EXPECT_EQ(image.uvMax - image.uvMin, glm::vec2(0.5f)) << "image " << i;
        }
        ASSERT_TRUE(writePng(testOut("billboard-leaves-atlas-colour.png").string(), toImage(tiles.colour())).ok());
        std::mt19937 rng(8);
        int agree = 0, total = 0;
        const TextureImage& tex = oak.textures[std::size_t(oak.materials[1].texture)];
        for (std::uint32_t i = 0; i < oak.leaves.size(); i += 3)
        {
            const Leaf& leaf = oak.leaves[i];
            const std::int32_t image = tiles.imageOf(i);
            ASSERT_GE(image, 0);
            EXPECT_EQ(tiles.images()[std::size_t(image)].material, leaf.material);
            EXPECT_EQ(tiles.images()[std::size_t(image)].uvMin, leaf.uvMin);
            const Vertex* v = &oak.leafVertices[leaf.firstVertex];
            const glm::vec3 centre = 0.25f * (v[0].position + v[1].position + v[2].position + v[3].position);
            const float cellSize = 3.0f * glm::length(v[3].position - v[0].position);
            const OneLeafCloud c = oneLeafCloud(tiles, i, centre, planeWithNormal(leaf.normal, centre, rng), cellSize);
            const float cutoff = oak.materials[leaf.material].alphaCutoff;
            for (int iy = 0; iy < 16; ++iy)
                for (int ix = 0; ix < 16; ++ix)
                {
                    const float s = (ix + 0.5f) / 16.0f, t = (iy + 0.5f) / 16.0f;
                    const glm::vec3 p = glm::mix(glm::mix(v[3].position, v[2].position, s),
                                                 glm::mix(v[0].position, v[1].position, s), t);
                    const glm::vec2 uv = glm::mix(glm::mix(v[3].uv, v[2].uv, s), glm::mix(v[0].uv, v[1].uv, s), t);
                    const int tx = std::min(int(uv.x * tex.width), tex.width - 1),
                              ty = std::min(int(uv.y * tex.height), tex.height - 1);
                    const bool opaque = tex.rgba[(std::size_t(ty) * tex.width + tx) * 4 + 3] >= cutoff * 255.0f;
                    agree += (shade(c, tiles, p, true).a >= LEAVES_COVERAGE_CUTOFF) == opaque;
                    ++total;
                }
        }
        EXPECT_GT(float(agree) / float(total), 0.9f);
    }

    // A lower cutoff keeps more of the leaf: the same texture under cutoffs 0.3, 0.5, 0.7 gives
    // tiles of strictly decreasing coverage (the alpha test is baked into the coverage).
    TEST(BillboardLeafTiles, eachMaterialsCutoffShapesItsTiles)
    {
        std::vector<QuadLeaf> leaves(3);
        for (std::uint32_t k = 0; k < 3; ++k)
        {
            leaves[k].material = k;
            leaves[k].centre = glm::vec3(float(k), 0, 0);
        }
        TreeModel model = quadModel(leaves, 3);
        // Soft alpha: a ramp from the centre out, so the cutoff moves the edge.
        TextureImage& tex = model.textures[0];
        for (int y = 0; y < kTexSize; ++y)
            for (int x = 0; x < kTexSize; ++x)
            {
                const float r = glm::length(glm::vec2(x + 0.5f, y + 0.5f) / float(kTexSize) - 0.5f) / 0.5f;
                tex.rgba[(std::size_t(y) * kTexSize + x) * 4 + 3] = unitToByte(std::clamp(1.0f - r, 0.0f, 1.0f));
            }
        const float cutoffs[3] = {0.3f, 0.5f, 0.7f};
        for (std::uint32_t k = 0; k < 3; ++k)
            model.materials[k].alphaCutoff = cutoffs[k];
        const BillboardLeafTiles tiles(model, 32, 3);
        ASSERT_EQ(tiles.images().size(), 3u);
        float covered[3] = {0, 0, 0};
        const std::uint32_t straight = 4; // the centre of the 3 x 3 grid: d = n
        for (std::uint32_t k = 0; k < 3; ++k)
        {
            EXPECT_EQ(tiles.images()[k].alphaCutoff, cutoffs[k]);
            for (int y = 0; y < 32; ++y)
                for (int x = 0; x < 32; ++x)
                    covered[k] += tiles.sample(k * 18 + straight, glm::vec2(x + 0.5f, y + 0.5f) / 32.0f).a >=
                                  LEAVES_COVERAGE_CUTOFF;
        }
        // A disc of radius 1 - cutoff (of the half edge): areas in ratio 0.49 : 0.25 : 0.09.
        EXPECT_GT(covered[0], 1.5f * covered[1]);
        EXPECT_GT(covered[1], 2.0f * covered[2]);
        EXPECT_GT(covered[2], 0.0f);
    }

    // Jittered or trimmed UVs of one image stay one image; more than 64 disjoint rectangles
    // in one material are drawn with the nearest of 64 images, and a warning names the
    // material, how many leaves and the first.
    TEST(BillboardLeafTiles, leafImagesGroupOverlappingRectanglesAndWarnPastTheLimit)
    {
        std::mt19937 rng(4);
        std::uniform_real_distribution<float> jitter(-0.03f, 0.03f);
        std::vector<QuadLeaf> leaves(70);
        for (std::size_t k = 0; k < leaves.size(); ++k)
            leaves[k].centre = glm::vec3(0.2f * float(k), 0, 0);
        TreeModel jittered = quadModel(leaves);
        for (std::size_t l = 0; l < jittered.leaves.size(); ++l)
        {
            const glm::vec2 shift(jitter(rng), jitter(rng));
            for (std::uint32_t v = 0; v < 4; ++v)
                jittered.leafVertices[jittered.leaves[l].firstVertex + v].uv += shift;
            jittered.updateLeafRecord(l);
        }
        const BillboardLeafTiles one(jittered, 32, 3);
        EXPECT_EQ(one.images().size(), 1u);
        EXPECT_TRUE(one.warnings().empty());

        TreeModel strips = quadModel(leaves);
        for (std::size_t l = 0; l < strips.leaves.size(); ++l)
        {
            for (std::uint32_t v = 0; v < 4; ++v)
            {
                glm::vec2& uv = strips.leafVertices[strips.leaves[l].firstVertex + v].uv;
                uv.x = (float(l) + uv.x) / 70.0f;
            }
            strips.updateLeafRecord(l);
        }
        const BillboardLeafTiles many(strips, 8, 1);
        EXPECT_EQ(many.images().size(), 64u);
        for (std::uint32_t l = 0; l < 64; ++l)
            EXPECT_EQ(many.imageOf(l), std::int32_t(l));
        EXPECT_EQ(many.imageOf(69), 63); // the nearest centre
        ASSERT_EQ(many.warnings().size(), 1u);
        const std::string& warning = many.warnings()[0];
        EXPECT_NE(warning.find("'Leaves 0'"), std::string::npos) << warning;
        EXPECT_NE(warning.find("6 leaves"), std::string::npos) << warning;
        EXPECT_NE(warning.find("leaf 64"), std::string::npos) << warning;
    }
}
