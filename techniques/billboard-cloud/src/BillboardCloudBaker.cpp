// BillboardCloudBaker: TreeModel -> BillboardCloudData, García et al. 2007 (García, Patow,
// Szirmay-Kalos, Sbert, "Multi-layered indirect texturing for tree rendering", 2007) §4, §5.1,
// §5.2, §6, and the classic billboard cloud it is compared with (Fig. 13). Contract:
// BillboardCloudBaker.h and BillboardCloudData.h. Choices the paper leaves open
// (techniques/billboard-cloud/README.md):
//   - leaf length (cell and texel sizes are multiples of the median): the leaf's diameter,
//     2 x the largest distance of its vertices from its centre (the diagonal of a quad leaf);
//   - hash cells grow past cellLeafRatio median leaf lengths when the largest leaf's tile would
//     not fit the entry's scale code, instead of drawing that leaf smaller (chooseCellSize);
//   - clustering: BillboardClustering.h (plane error + spatial and orientation terms, error
//     bound); a quad is padded to whole square cells, so every billboard's cells are square;
//   - hash lists (§4.2): computed exactly instead of point sprites + depth peeling: a cell lists a
//     leaf when its tile's bilinear coverage (either view side, level 0) is > 0 somewhere in the
//     cell, i.e. the cell meets the open 2-texel square around a texel with coverage > 0 (the
//     one-texel dilation), mapped through the entry's own quantised centre, rotation, scale and
//     mirror;
//   - low-res texture (§5.1): every billboard of every level is evaluated from the layered
//     representation (4 x 4 sub-samples per texel, lists walked front to back as the shader
//     does); a texel is covered when its sub-sample hits reach the count that keeps the
//     billboard's leaf area (a fixed 1/2 loses the leaves smaller than two texels); level 1 and 2
//     texels are 2x and 4x the level 0 texel (seen from about 3x and 9x farther: no detail lost
//     on screen, about a quarter of level 0's texels for both);
//   - the classic cloud's textures are made by the same evaluation, at the texel size that fits
//     the memory budget.
#include "TreeLod/BillboardCloudBaker.h"

#include "BillboardClustering.h"
#include "BillboardLeafTiles.h"

#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/Image.h"
#include "TreeLod/Package.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t MAX_HASH_EDGE = 4096;    ///< hash cells per billboard edge
        constexpr std::uint32_t MAX_LOW_RES_EDGE = 1024; ///< low-res texels per billboard edge
        constexpr std::uint32_t MAX_ATLAS_WIDTH = 4096;
        constexpr std::uint32_t LOW_RES_GUTTER = 2; ///< texels between two low-res rects
        constexpr int SUB = 4;                      ///< low-res sub-samples per texel axis
        constexpr float LEVEL_TEXEL_FACTOR[3] = {1.0f, 2.0f, 4.0f};
        constexpr std::uint8_t LOW_RES_ALPHA_BYTE = 64; ///< A >= 64 <=> A / 255 >= LOW_RES_ALPHA_CUTOFF

        std::uint32_t nextPowerOfTwo(std::uint64_t v)
        {
            std::uint64_t p = 1;
            while (p < v)
                p *= 2;
            return std::uint32_t(std::min<std::uint64_t>(p, std::numeric_limits<std::uint32_t>::max()));
        }

        bool isPowerOfTwo(std::uint32_t v) { return v != 0 && (v & (v - 1)) == 0; }

        GpuTexture placeholderTexture(const std::string& name)
        {
            GpuTexture tex;
            tex.name = name;
            tex.format = GpuTextureFormat::RGBA8;
            tex.width = tex.height = tex.mipCount = 1;
            tex.data = {0, 0, 0, 0};
            return tex;
        }

        /// One billboard while baking (a cluster of leaves and its plane).
        struct BillboardBuild
        {
            std::vector<std::uint32_t> leaves;                          ///< model leaf indices, increasing
            glm::vec3 origin{0.0f}, U{1, 0, 0}, V{0, 1, 0}, N{0, 0, 1}; ///< unit axes, N = cross(U, V)
            float width = 0.0f, height = 0.0f;                          ///< metres: hashWidth * cell, hashHeight * cell
            float cell = 0.0f;                                          ///< metres per hash cell of this billboard
            std::uint32_t hashWidth = 0, hashHeight = 0;
            std::vector<LeafPlacement> placements; ///< per leaf, against `origin`
            // §4.2 lists, per cell row-major; kept for layered levels, dropped after the low-res pass
            std::vector<std::uint32_t> cellStart; ///< hashWidth * hashHeight + 1 offsets
            std::vector<BillboardListEntry> entries;
            std::vector<std::array<std::uint8_t, 4>> entryAo;
            std::uint32_t longest = 0, truncated = 0;
            // §5.1 low-res image (RGBA8, straight, sRGB colour)
            std::uint32_t lowResWidth = 0, lowResHeight = 0;
            std::vector<std::uint8_t> lowRes;
            std::vector<float> lowResCoverage, lowResAo; ///< per texel: fraction of sub-samples hit, their mean AO
        };

        /// What every level and both clouds share.
        struct BakeContext
        {
            const TreeModel& model;
            const BillboardCloudOptions& options;
            std::string label;
            ProgressCallback progress;
            AmbientOcclusion ao;
            std::unique_ptr<BillboardLeafTiles> tiles;
            float leafLength = 0.0f; ///< median leaf diameter, metres
            float diagonal = 0.0f;   ///< of the tree's bounding box
            glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};
            glm::vec2 trunkAxis{0.0f}; ///< x, z of the vertical trunk axis
            glm::vec3 crownCentre{0.0f};
            std::uint32_t orientationCount = 0;
            /// Per side-0 tile (index = orientation field): tile-local texel centres - 0.5 of the
            /// texels with coverage > 0 on either view side.
            std::vector<std::vector<glm::vec2>> coverage;
            float cellSize = 0.0f;  ///< metres per hash cell of the layered levels
            std::unique_ptr<ClusteringJudge> judge; ///< when clusteringTries > 1

            BakeContext(const TreeModel& m, const BillboardCloudOptions& o, const std::string& l,
                        const ProgressCallback& p)
                : model(m), options(o), label(l), progress(p)
            {
            }
        };

        Result<void> checkOptions(const BillboardCloudOptions& o, const std::string& label)
        {
            auto bad = [&](const std::string& what, const std::string& why) {
                return fail(label, "billboard-cloud option " + what, why);
            };
            if (!(o.maxPlaneError >= 0.0f) || !std::isfinite(o.maxPlaneError))
                return bad("maxPlaneError", std::to_string(o.maxPlaneError) + " is not a finite number >= 0");
            if (!(o.cellLeafRatio > 0.0f) || !std::isfinite(o.cellLeafRatio))
                return bad("cellLeafRatio", std::to_string(o.cellLeafRatio) + " is not a finite number > 0");
            if (!(o.lowResLeafRatio > 0.0f) || !std::isfinite(o.lowResLeafRatio))
                return bad("lowResLeafRatio", std::to_string(o.lowResLeafRatio) + " is not a finite number > 0");
            if (o.tileSize < 8 || o.tileSize > 1024 || !isPowerOfTwo(o.tileSize))
                return bad("tileSize", std::to_string(o.tileSize) + " is not a power of two in 8..1024");
            if (o.orientationGrid < 1 || o.orientationGrid > 16)
                return bad("orientationGrid", std::to_string(o.orientationGrid) + " is not in 1..16");
            if (!isPowerOfTwo(o.listsAtlasWidth) || o.listsAtlasWidth > MAX_ATLAS_WIDTH)
                return bad("listsAtlasWidth", std::to_string(o.listsAtlasWidth) + " is not a power of two in 1..4096");
            if (!(o.listFactor > 0.0f) || !std::isfinite(o.listFactor))
                return bad("listFactor", std::to_string(o.listFactor) + " is not a finite number > 0");
            if (o.clusteringTries < 1 || o.clusteringTries > CLUSTERING_TRIES_MAX)
                return bad("clusteringTries",
                           std::to_string(o.clusteringTries) + " is not in 1.." + std::to_string(CLUSTERING_TRIES_MAX));
            if (!(o.clusteringAreaGrowth >= 0.0f) || !std::isfinite(o.clusteringAreaGrowth))
                return bad("clusteringAreaGrowth",
                           std::to_string(o.clusteringAreaGrowth) + " is not a finite number >= 0");
            if (o.aoRays < 1)
                return bad("aoRays", std::to_string(o.aoRays) + " is not >= 1");
            return {};
        }

        // ---- context: AO (§5.2), Leaves Texture (§3, §5), leaf sizes ----------------------------

        /// Hash cell edge: cellLeafRatio median leaf lengths, grown until the largest tile fits the
        /// entry's scale code (BillboardCloudData.h: at most 2^(127/32) cells), so no leaf is
        /// drawn smaller than it is. Tiles below the code's smallest side (2^-4 cells) are drawn
        /// at that side: a warning names how many and the first.
        void chooseCellSize(BakeContext& ctx)
        {
            const BillboardLeafTiles& tiles = *ctx.tiles;
            const float largestCode = BillboardListEntry::encode(0, 0, 0, false, 0, 1e30f).side();
            const float smallestCode = BillboardListEntry::encode(0, 0, 0, false, 0, 1e-30f).side();
            ctx.cellSize = ctx.options.cellLeafRatio * ctx.leafLength;
            std::uint32_t largest = 0;
            float largestSide = 0.0f;
            for (std::uint32_t l = 0; l < ctx.model.leaves.size(); ++l)
                if (const float side = tiles.sideRange(l).y; side > largestSide)
                {
                    largestSide = side;
                    largest = l;
                }
            // 0.99: the code rounds to the nearest step, which must not round above the range.
            if (largestSide > 0.99f * largestCode * ctx.cellSize)
            {
                const float grown = largestSide / (0.99f * largestCode);
                report(ctx.progress,
                       "warning: " + ctx.label + ": leaf " + std::to_string(largest) + " (material '" +
                           ctx.model.materials[ctx.model.leaves[largest].material].name + "') is " +
                           std::to_string(int(std::lround(largestSide / ctx.leafLength))) +
                           " median leaf lengths across; hash cells grow " +
                           std::to_string(grown / ctx.cellSize) + "x to hold its tile, so lists are longer",
                       1.0f);
                ctx.cellSize = grown;
            }
            std::uint32_t enlarged = 0, first = 0;
            for (std::uint32_t l = 0; l < ctx.model.leaves.size(); ++l)
            {
                const float side = tiles.sideRange(l).x;
                if (tiles.imageOf(l) >= 0 && side < smallestCode * ctx.cellSize)
                    if (enlarged++ == 0)
                        first = l;
            }
            if (enlarged > 0)
                report(ctx.progress,
                       "warning: " + ctx.label + ": " + std::to_string(enlarged) + " leaves (the first is leaf " +
                           std::to_string(first) + ", material '" +
                           ctx.model.materials[ctx.model.leaves[first].material].name + "') are under " +
                           std::to_string(smallestCode * ctx.cellSize / ctx.leafLength) +
                           " median leaf lengths and are drawn at that size",
                       1.0f);
        }

        Result<void> prepare(BakeContext& ctx)
        {
            Result<void> ok = checkOptions(ctx.options, ctx.label);
            if (!ok)
                return ok;
            const TreeModel& model = ctx.model;
            Result<void> valid = model.validate(ctx.label);
            if (!valid)
                return fail(ctx.label, "model '" + model.name + "', " + valid.error().element, valid.error().reason);

            // Bounds of everything (the chunk's culling box) and of the leaves.
            glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            glm::vec3 leafLo = lo, leafHi = hi, barkLo = lo, barkHi = hi;
            for (const Vertex& v : model.barkVertices)
            {
                barkLo = glm::min(barkLo, v.position);
                barkHi = glm::max(barkHi, v.position);
            }
            for (const Vertex& v : model.leafVertices)
            {
                leafLo = glm::min(leafLo, v.position);
                leafHi = glm::max(leafHi, v.position);
            }
            lo = glm::min(barkLo, leafLo);
            hi = glm::max(barkHi, leafHi);
            if (lo.x > hi.x)
                lo = hi = glm::vec3(0.0f);
            ctx.boundsMin = lo;
            ctx.boundsMax = hi;
            ctx.diagonal = glm::length(hi - lo);
            if (!std::isfinite(ctx.diagonal))
                return fail(ctx.label, "model '" + model.name + "'", "bounding box too large for single precision");
            if (ctx.options.clusteringTries > 1 && !model.leaves.empty())
            {
                report(ctx.progress, "billboard clustering views", 0.0f);
                ctx.judge = std::make_unique<ClusteringJudge>(model, lo, hi, ClusteringJudge::Options{});
            }
            const bool hasBark = barkLo.x <= barkHi.x, hasLeaves = leafLo.x <= leafHi.x;
            // Trunk axis: the vertical through the mean of the lowest tenth of the bark (its base),
            // else through the centre of the bounds.
            const glm::vec3 mid = 0.5f * (lo + hi);
            ctx.trunkAxis = glm::vec2(mid.x, mid.z);
            if (hasBark)
            {
                const float top = barkLo.y + 0.1f * (barkHi.y - barkLo.y);
                glm::dvec2 sum(0.0);
                std::size_t n = 0;
                for (const Vertex& v : model.barkVertices)
                    if (v.position.y <= top)
                    {
                        sum += glm::dvec2(v.position.x, v.position.z);
                        ++n;
                    }
                if (n)
                    ctx.trunkAxis = glm::vec2(sum / double(n));
            }
            ctx.crownCentre = hasLeaves ? 0.5f * (leafLo + leafHi) : 0.5f * (lo + hi);

            // §5.2: AO of the polygonal tree, per vertex.
            AoOptions aoOptions;
            aoOptions.raysPerPoint = ctx.options.aoRays;
            ctx.ao = computeAmbientOcclusion(model, aoOptions, ctx.progress);

            if (model.leaves.empty())
                return {};

            // Median leaf diameter.
            std::vector<float> sizes(model.leaves.size());
            tbb::parallel_for(std::size_t(0), model.leaves.size(), [&](std::size_t l) {
                const Leaf& leaf = model.leaves[l];
                float r = 0.0f;
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                    r = std::max(r, glm::length(model.leafVertices[v].position - leaf.centre));
                sizes[l] = 2.0f * r;
            });
            std::nth_element(sizes.begin(), sizes.begin() + std::ptrdiff_t(sizes.size() / 2), sizes.end());
            ctx.leafLength = sizes[sizes.size() / 2];
            if (!(ctx.leafLength > 0.0f))
                ctx.leafLength = std::max(ctx.diagonal * 1e-3f, 1e-6f);

            // §3, §5: the Leaves Texture.
            report(ctx.progress, "billboard leaf tiles", 0.0f);
            ctx.tiles = std::make_unique<BillboardLeafTiles>(model, ctx.options.tileSize, ctx.options.orientationGrid,
                                                             ctx.options.maxLeavesTexels);
            report(ctx.progress, "billboard leaf tiles", 1.0f);
            const BillboardLeafTiles& tiles = *ctx.tiles;
            if (tiles.tileSize() < ctx.options.tileSize)
                report(ctx.progress,
                       "warning: " + ctx.label + ": " + std::to_string(tiles.images().size()) +
                           " leaf images: tiles of " +
                           std::to_string(tiles.tileSize()) + " texels keep the Leaves Texture within " +
                           std::to_string(ctx.options.maxLeavesTexels) + " texels (tileSize " +
                           std::to_string(ctx.options.tileSize) + " asked)",
                       1.0f);
            const std::uint32_t oc = tiles.grid() * tiles.grid();
            ctx.orientationCount = oc;
            const std::uint32_t T = tiles.tileSize(), columns = tiles.tileColumns();
            const TextureImage& colour = tiles.colour();
            ctx.coverage.assign(tiles.tileCount(), {});
            for (const std::string& warning : tiles.warnings())
                report(ctx.progress, "warning: " + ctx.label + ": " + warning, 1.0f);
            chooseCellSize(ctx);
            tbb::parallel_for(std::uint32_t(0), tiles.tileCount(), [&](std::uint32_t t) {
                if (t % (2 * oc) >= oc)
                    return; // side 1: merged into its side-0 tile
                std::vector<char> covered(std::size_t(T) * T, 0);
                for (std::uint32_t side = 0; side < 2; ++side)
                {
                    const std::uint32_t tile = t + side * oc;
                    const std::uint32_t ox = (tile % columns) * T, oy = (tile / columns) * T;
                    for (std::uint32_t y = 0; y < T; ++y)
                        for (std::uint32_t x = 0; x < T; ++x)
                            if (colour.rgba[(std::size_t(oy + y) * std::size_t(colour.width) + ox + x) * 4 + 3] > 0)
                                covered[std::size_t(y) * T + x] = 1;
                }
                std::vector<glm::vec2>& points = ctx.coverage[t];
                for (std::uint32_t y = 0; y < T; ++y)
                    for (std::uint32_t x = 0; x < T; ++x)
                        if (covered[std::size_t(y) * T + x])
                            points.push_back(glm::vec2((float(x) + 0.5f) / float(T) - 0.5f,
                                                       (float(y) + 0.5f) / float(T) - 0.5f));
            });
            return {};
        }

        // ---- billboards (§4.1) -------------------------------------------------------------------

        /// The quad of cluster k: plane oriented outwards, axes by 2D PCA, the rectangle holding
        /// every leaf's projection and tile square, padded to whole cells of `cellSize`.
        void buildBillboard(const BakeContext& ctx, const LeafClustering& clustering, std::uint32_t k, float cellSize,
                            BillboardBuild& bb)
        {
            const TreeModel& model = ctx.model;
            const BillboardLeafTiles& tiles = *ctx.tiles;
            bb.leaves = clustering.members[k];
            glm::vec3 N = clustering.normal[k];
            const glm::vec3 g = clustering.centroid[k];
            // Outward: away from the trunk axis; for a plane near the axis or nearly containing the
            // horizontal direction from it (e.g. a horizontal one), away from the crown centre.
            glm::vec3 out(g.x - ctx.trunkAxis.x, 0.0f, g.z - ctx.trunkAxis.y);
            if (glm::length(out) < 0.05f * ctx.diagonal || std::abs(glm::dot(N, glm::normalize(out))) < 0.1f)
                out = g - ctx.crownCentre;
            if (glm::length(out) < 1e-6f * ctx.diagonal)
                out = glm::vec3(0, 1, 0);
            if (glm::dot(N, out) < 0.0f)
                N = -N;
            // The centroid projected onto the plane.
            const glm::vec3 o0 = g - clustering.normal[k] * (glm::dot(clustering.normal[k], g) - clustering.offset[k]);

            const glm::vec3 U0 =
                glm::normalize(glm::cross(N, std::abs(N.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
            const glm::vec3 V0 = glm::cross(N, U0);
            // 2D PCA of the leaves' vertices in the plane (area-weighted).
            double sw = 0.0, sa = 0.0, sb = 0.0, saa = 0.0, sab = 0.0, sbb = 0.0;
            for (std::uint32_t l : bb.leaves)
            {
                const Leaf& leaf = model.leaves[l];
                const double w =
                    (leaf.area > 0.0f ? double(leaf.area) : 1e-12) / std::max<std::uint32_t>(leaf.vertexCount, 1);
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                {
                    const glm::vec3 q = model.leafVertices[v].position - o0;
                    const double a = glm::dot(q, U0), b = glm::dot(q, V0);
                    sw += w;
                    sa += w * a;
                    sb += w * b;
                    saa += w * a * a;
                    sab += w * a * b;
                    sbb += w * b * b;
                }
            }
            double theta = 0.0;
            if (sw > 0.0)
            {
                const double ma = sa / sw, mb = sb / sw;
                const double caa = saa / sw - ma * ma, cab = sab / sw - ma * mb, cbb = sbb / sw - mb * mb;
                theta = 0.5 * std::atan2(2.0 * cab, caa - cbb);
                if (!std::isfinite(theta))
                    theta = 0.0;
            }
            glm::vec3 U = glm::normalize(float(std::cos(theta)) * U0 + float(std::sin(theta)) * V0);
            glm::vec3 V = glm::cross(N, U);
            // Canonical: v runs down the tree (low-res images upright), else u along +x.
            const float down = -V.y;
            if (down < -1e-4f || (std::abs(down) <= 1e-4f && U.x < 0.0f))
            {
                U = -U;
                V = -V;
            }

            // Rectangle: every leaf's tile square (rotated: half extent side/2 (|cos| + |sin|))
            // and its vertices' projections. The entries' quantised scale (steps of 2^(1/16)) may
            // grow a tile by 2.2 %, inside its empty TILE_MARGIN.
            glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            for (std::uint32_t l : bb.leaves)
            {
                const LeafPlacement p = tiles.place(l, o0, U, V, N);
                const float h = 0.5f * p.side * (std::abs(std::cos(p.rotation)) + std::abs(std::sin(p.rotation)));
                lo = glm::min(lo, p.centre - glm::vec2(h));
                hi = glm::max(hi, p.centre + glm::vec2(h));
                const Leaf& leaf = model.leaves[l];
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                {
                    const glm::vec3 q = model.leafVertices[v].position - o0;
                    const glm::vec2 c(glm::dot(q, U), glm::dot(q, V));
                    lo = glm::min(lo, c);
                    hi = glm::max(hi, c);
                }
            }
            const float minEdge = 1e-4f * ctx.leafLength;
            const float w = std::max(hi.x - lo.x, minEdge), h = std::max(hi.y - lo.y, minEdge);
            // Whole square cells (the entries' scale is one number: cells must be square); a
            // billboard wider than MAX_HASH_EDGE cells gets coarser cells of its own.
            float cell = cellSize;
            if (std::max(w, h) / cell > float(MAX_HASH_EDGE))
                cell = std::max(w, h) / float(MAX_HASH_EDGE) * 1.0001f;
            bb.cell = cell;
            bb.hashWidth = std::clamp<std::uint32_t>(std::uint32_t(std::ceil(w / cell)), 1, MAX_HASH_EDGE);
            bb.hashHeight = std::clamp<std::uint32_t>(std::uint32_t(std::ceil(h / cell)), 1, MAX_HASH_EDGE);
            bb.width = float(bb.hashWidth) * cell;
            bb.height = float(bb.hashHeight) * cell;
            const glm::vec2 corner = lo - 0.5f * (glm::vec2(bb.width, bb.height) - glm::vec2(w, h));
            bb.origin = o0 + corner.x * U + corner.y * V;
            bb.U = U;
            bb.V = V;
            bb.N = N;
            bb.placements.resize(bb.leaves.size());
            for (std::size_t i = 0; i < bb.leaves.size(); ++i)
                bb.placements[i] = tiles.place(bb.leaves[i], bb.origin, U, V, N);
        }

        // ---- hash lists (§4.2, Fig. 6) ------------------------------------------------------------

        void buildLists(const BakeContext& ctx, BillboardBuild& bb)
        {
            const BillboardLeafTiles& tiles = *ctx.tiles;
            const std::uint32_t W = bb.hashWidth, H = bb.hashHeight;
            const float cell = bb.cell;
            struct Fragment
            {
                std::uint32_t cell;
                float depth;
                std::uint32_t member;
                BillboardListEntry entry;
            };
            std::vector<Fragment> fragments;
            fragments.reserve(bb.leaves.size() * 4);
            std::vector<std::array<std::uint8_t, 4>> memberAo(bb.leaves.size());
            std::vector<char> mark;
            for (std::uint32_t m = 0; m < bb.leaves.size(); ++m)
            {
                const std::uint32_t leaf = bb.leaves[m];
                const LeafPlacement& p = bb.placements[m];
                memberAo[m] = tiles.fitAo(leaf, p, bb.origin, bb.U, bb.V, ctx.ao.leafVertex); // §5.2, Fig. 11
                // The fragment as the shader sees it: the quantised entry of the centre's cell.
                const std::uint32_t i0 = billboardGridCell(p.centre.x / cell, W);
                const std::uint32_t j0 = billboardGridCell(p.centre.y / cell, H);
                const BillboardListEntry e0 = tiles.entryFor(p, cell, i0, j0);
                const glm::vec2 centre(float(i0) + e0.centreX(), float(j0) + e0.centreY());
                const float psi = e0.rotation(), side = e0.side();
                const float c = std::cos(psi), s = std::sin(psi);
                const bool mirror = e0.mirrored();
                const float reach = 0.7072f * side * (1.0f + 2.0f / float(tiles.tileSize())) + 1.0f;
                const int ilo = std::max(0, int(std::floor(centre.x - reach))),
                          ihi = std::min(int(W) - 1, int(std::floor(centre.x + reach)));
                const int jlo = std::max(0, int(std::floor(centre.y - reach))),
                          jhi = std::min(int(H) - 1, int(std::floor(centre.y + reach)));
                if (ilo > ihi || jlo > jhi)
                    continue;
                const int bw = ihi - ilo + 1;
                mark.assign(std::size_t(bw) * std::size_t(jhi - jlo + 1), 0);
                // Bilinear coverage is > 0 within one texel of a covered texel's centre: the open
                // square of 2 texels around it, mapped by q = R(psi) F (local - 0.5) side (F mirrors
                // x; BillboardCloudData.h, inverted), a turned square of half edge t = side / T
                // cells. Every cell it meets is listed (separating axes against the cell).
                const float t = side / float(tiles.tileSize());
                const float half = t * (std::abs(c) + std::abs(s));
                const float reachAxis = t + 0.5f * (std::abs(c) + std::abs(s)); // + the cell along the axes
                for (const glm::vec2& dl : ctx.coverage[e0.orientation()])
                {
                    const float dx = mirror ? -dl.x : dl.x;
                    const float px = centre.x + (c * dx - s * dl.y) * side;
                    const float py = centre.y + (s * dx + c * dl.y) * side;
                    const int i0 = std::max(ilo, int(std::floor(px - half)));
                    const int i1 = std::min(ihi, int(std::floor(px + half)));
                    const int j0 = std::max(jlo, int(std::floor(py - half)));
                    const int j1 = std::min(jhi, int(std::floor(py + half)));
                    for (int j = j0; j <= j1; ++j)
                        for (int i = i0; i <= i1; ++i)
                        {
                            const float ox = px - (float(i) + 0.5f), oy = py - (float(j) + 0.5f);
                            if (std::abs(c * ox + s * oy) < reachAxis && std::abs(-s * ox + c * oy) < reachAxis)
                                mark[std::size_t(j - jlo) * std::size_t(bw) + std::size_t(i - ilo)] = 1;
                        }
                }
                for (int j = jlo; j <= jhi; ++j)
                    for (int i = ilo; i <= ihi; ++i)
                        if (mark[std::size_t(j - jlo) * std::size_t(bw) + std::size_t(i - ilo)])
                            fragments.push_back({std::uint32_t(j) * W + std::uint32_t(i), p.depth, m,
                                                 tiles.entryFor(p, cell, std::uint32_t(i), std::uint32_t(j))});
            }
            // Front to back as seen from +N (decreasing depth), ties by leaf index.
            std::sort(fragments.begin(), fragments.end(), [](const Fragment& a, const Fragment& b) {
                if (a.cell != b.cell)
                    return a.cell < b.cell;
                if (a.depth != b.depth)
                    return a.depth > b.depth;
                return a.member < b.member;
            });
            bb.cellStart.assign(std::size_t(W) * H + 1, 0);
            bb.entries.clear();
            bb.entryAo.clear();
            bb.longest = bb.truncated = 0;
            std::size_t f = 0;
            for (std::uint32_t c = 0; c < W * H; ++c)
            {
                bb.cellStart[c] = std::uint32_t(bb.entries.size());
                std::size_t e = f;
                while (e < fragments.size() && fragments[e].cell == c)
                    ++e;
                const std::size_t n = e - f;
                bb.longest = std::max<std::uint32_t>(bb.longest, std::uint32_t(n));
                // Longer than the hash's A channel holds: the 127 frontmost and 128 backmost, so
                // both walk directions (§5) start with their nearest leaves.
                const std::size_t keepFront = n > BILLBOARD_MAX_LIST_LENGTH ? 127 : n;
                const std::size_t keepBack = n > BILLBOARD_MAX_LIST_LENGTH ? 128 : 0;
                if (n > BILLBOARD_MAX_LIST_LENGTH)
                    ++bb.truncated;
                for (std::size_t k = 0; k < n; ++k)
                    if (k < keepFront || k >= n - keepBack)
                    {
                        bb.entries.push_back(fragments[f + k].entry);
                        bb.entryAo.push_back(memberAo[fragments[f + k].member]);
                    }
                f = e;
            }
            bb.cellStart[std::size_t(W) * H] = std::uint32_t(bb.entries.size());
        }

        // ---- low-resolution texture (§5.1, §5.2) ---------------------------------------------------

        std::pair<std::uint32_t, std::uint32_t> lowResSize(const BillboardBuild& bb, float texel)
        {
            std::uint32_t w = std::uint32_t(std::max(1.0f, std::ceil(bb.width / texel)));
            std::uint32_t h = std::uint32_t(std::max(1.0f, std::ceil(bb.height / texel)));
            if (std::max(w, h) > MAX_LOW_RES_EDGE)
            {
                const float t = std::max(bb.width, bb.height) / float(MAX_LOW_RES_EDGE) * 1.0001f;
                w = std::clamp<std::uint32_t>(std::uint32_t(std::ceil(bb.width / t)), 1, MAX_LOW_RES_EDGE);
                h = std::clamp<std::uint32_t>(std::uint32_t(std::ceil(bb.height / t)), 1, MAX_LOW_RES_EDGE);
            }
            return {w, h};
        }

        /// The billboard's image seen from +N through its lists, as the shader walks them.
        void renderLowRes(const BakeContext& ctx, BillboardBuild& bb, std::uint32_t w, std::uint32_t h)
        {
            const BillboardLeafTiles& tiles = *ctx.tiles;
            const std::uint32_t oc = ctx.orientationCount;
            struct Decoded
            {
                float cx, cy, c, s, inverseSide;
                std::uint32_t tile;
                bool mirror;
            };
            std::vector<Decoded> decoded(bb.entries.size());
            for (std::size_t e = 0; e < bb.entries.size(); ++e)
            {
                const BillboardListEntry& entry = bb.entries[e];
                Decoded& d = decoded[e];
                d.cx = entry.centreX();
                d.cy = entry.centreY();
                d.c = std::cos(entry.rotation());
                d.s = std::sin(entry.rotation());
                d.inverseSide = 1.0f / entry.side();
                d.mirror = entry.mirrored();
                d.tile = entry.orientation() + (d.mirror ? oc : 0u); // view side 0 XOR m
            }
            const std::size_t texels = std::size_t(w) * h;
            std::vector<glm::vec3> albedo(texels, glm::vec3(0.0f));
            std::vector<float> ao(texels, 0.0f);
            std::vector<int> hits(texels, 0);
            for (std::uint32_t y = 0; y < h; ++y)
                for (std::uint32_t x = 0; x < w; ++x)
                {
                    const std::size_t t = std::size_t(y) * w + x;
                    for (int sy = 0; sy < SUB; ++sy)
                        for (int sx = 0; sx < SUB; ++sx)
                        {
                            const float u = (float(x) + (float(sx) + 0.5f) / SUB) / float(w);
                            const float v = (float(y) + (float(sy) + 0.5f) / SUB) / float(h);
                            const float gx = u * float(bb.hashWidth), gy = v * float(bb.hashHeight);
                            const std::uint32_t i = billboardGridCell(gx, bb.hashWidth);
                            const std::uint32_t j = billboardGridCell(gy, bb.hashHeight);
                            const float px = gx - float(i), py = gy - float(j);
                            const std::uint32_t c = j * bb.hashWidth + i;
                            for (std::uint32_t e = bb.cellStart[c]; e < bb.cellStart[c + 1]; ++e)
                            {
                                const Decoded& d = decoded[e];
                                const float qx = px - d.cx, qy = py - d.cy;
                                const glm::vec2 local =
                                    billboardTileLocal(glm::vec2(qx, qy), d.c, d.s, d.inverseSide, d.mirror);
                                if (!(local.x >= 0.0f && local.x <= 1.0f && local.y >= 0.0f && local.y <= 1.0f))
                                    continue;
                                const glm::vec4 sample = tiles.sample(d.tile, local);
                                if (sample.a < LEAVES_COVERAGE_CUTOFF)
                                    continue;
                                const std::array<std::uint8_t, 4>& a = bb.entryAo[e];
                                const float top = float(a[0]) + (float(a[1]) - float(a[0])) * local.x;
                                const float bottom = float(a[2]) + (float(a[3]) - float(a[2])) * local.x;
                                ao[t] += (top + (bottom - top) * local.y) / 255.0f;
                                albedo[t] += glm::vec3(sample);
                                ++hits[t];
                                break;
                            }
                        }
                }
            // Bleed colour into the texels nothing covers (rings of hit neighbours, then the mean).
            std::vector<char> known(texels);
            glm::dvec3 mean(0.0);
            std::size_t meanCount = 0;
            for (std::size_t t = 0; t < texels; ++t)
            {
                known[t] = hits[t] > 0;
                if (known[t])
                {
                    albedo[t] /= float(hits[t]);
                    ao[t] /= float(hits[t]);
                    mean += glm::dvec3(albedo[t]);
                    ++meanCount;
                }
            }
            const glm::vec3 fill = meanCount ? glm::vec3(mean / double(meanCount)) : glm::vec3(0.2f);
            std::vector<std::size_t> ring;
            std::vector<glm::vec3> ringColour;
            for (int r = 0; r < 8; ++r)
            {
                ring.clear();
                ringColour.clear();
                for (std::uint32_t y = 0; y < h; ++y)
                    for (std::uint32_t x = 0; x < w; ++x)
                    {
                        const std::size_t t = std::size_t(y) * w + x;
                        if (known[t])
                            continue;
                        glm::vec3 s(0.0f);
                        int n = 0;
                        for (int dy = -1; dy <= 1; ++dy)
                            for (int dx = -1; dx <= 1; ++dx)
                            {
                                const int nx = int(x) + dx, ny = int(y) + dy;
                                if (nx < 0 || ny < 0 || nx >= int(w) || ny >= int(h))
                                    continue;
                                const std::size_t o = std::size_t(ny) * w + std::size_t(nx);
                                if (known[o])
                                {
                                    s += albedo[o];
                                    ++n;
                                }
                            }
                        if (n)
                        {
                            ring.push_back(t);
                            ringColour.push_back(s / float(n));
                        }
                    }
                if (ring.empty())
                    break;
                for (std::size_t k = 0; k < ring.size(); ++k)
                {
                    albedo[ring[k]] = ringColour[k];
                    known[ring[k]] = 1;
                }
            }
            // Covered texels: those with at least `least` hits, the count that keeps the
            // billboard's leaf area (sum of coverage); a fixed 1/2 would drop every texel that
            // a single leaf smaller than two texels only partly covers.
            std::array<std::size_t, SUB * SUB + 1> atLeast{};
            std::size_t hitSum = 0;
            for (std::size_t t = 0; t < texels; ++t)
            {
                ++atLeast[std::size_t(hits[t])];
                hitSum += std::size_t(hits[t]);
            }
            for (int k = SUB * SUB - 1; k >= 0; --k)
                atLeast[std::size_t(k)] += atLeast[std::size_t(k) + 1];
            const double area = double(hitSum) / double(SUB * SUB);
            int least = SUB * SUB / 2;
            for (int k = SUB * SUB; k >= 1; --k)
                if (std::abs(double(atLeast[std::size_t(k)]) - area) <
                    std::abs(double(atLeast[std::size_t(least)]) - area))
                    least = k;
            bb.lowResWidth = w;
            bb.lowResHeight = h;
            bb.lowRes.assign(texels * 4, 0);
            for (std::size_t t = 0; t < texels; ++t)
            {
                const glm::vec3 c = known[t] ? albedo[t] : fill;
                bb.lowRes[4 * t + 0] = linearToSrgbByte(c.r);
                bb.lowRes[4 * t + 1] = linearToSrgbByte(c.g);
                bb.lowRes[4 * t + 2] = linearToSrgbByte(c.b);
                // §5.2: AO in alpha where the texel is covered.
                bb.lowRes[4 * t + 3] = hits[t] >= least ? unitToByte(0.5f + 0.5f * ao[t]) : 0;
            }
            bb.lowResCoverage.resize(texels);
            for (std::size_t t = 0; t < texels; ++t)
                bb.lowResCoverage[t] = float(hits[t]) / float(SUB * SUB);
            bb.lowResAo = std::move(ao);
        }

        // ---- atlases (§6) --------------------------------------------------------------------------

        struct Packing
        {
            std::uint32_t width = 0, height = 0;
            std::vector<glm::uvec2> position; ///< per rect, top-left of its slot
        };

        /// Shelf packing by decreasing height: width = the smallest power of two >= the widest
        /// slot and >= sqrt(total area) (at most MAX_ATLAS_WIDTH), height rounded up to 4.
        Packing shelfPack(const std::vector<glm::uvec2>& slots)
        {
            Packing p;
            p.position.resize(slots.size());
            if (slots.empty())
                return p;
            std::uint64_t area = 0;
            std::uint32_t widest = 0;
            for (const glm::uvec2& s : slots)
            {
                area += std::uint64_t(s.x) * s.y;
                widest = std::max(widest, s.x);
            }
            const std::uint64_t side = std::uint64_t(std::ceil(std::sqrt(double(area))));
            p.width = std::max(nextPowerOfTwo(widest), std::min(nextPowerOfTwo(side), MAX_ATLAS_WIDTH));
            std::vector<std::uint32_t> order(slots.size());
            std::iota(order.begin(), order.end(), 0u);
            std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
                return slots[a].y != slots[b].y ? slots[a].y > slots[b].y : slots[a].x > slots[b].x;
            });
            std::uint64_t x = 0, y = 0, shelf = 0;
            for (std::uint32_t r : order)
            {
                if (x + slots[r].x > p.width)
                {
                    y += shelf;
                    x = 0;
                    shelf = 0;
                }
                p.position[r] = glm::uvec2(std::uint32_t(x), std::uint32_t(y));
                x += slots[r].x;
                shelf = std::max<std::uint64_t>(shelf, slots[r].y);
            }
            const std::uint64_t height = (y + shelf + 3) / 4 * 4;
            p.height = std::uint32_t(std::min<std::uint64_t>(height, std::numeric_limits<std::uint32_t>::max()));
            return p;
        }

        /// Coverage-preserving mip chain of the low-res atlas (as buildMipChain's
        /// preserveAlphaCoverage, for a binary coverage): every level carries the box-filtered
        /// sub-sample coverage, and its covered texels (A >= LOW_RES_ALPHA_CUTOFF) are the ones of
        /// highest coverage, as many as keep level 0's covered fraction (ties by position). Colour
        /// and AO are coverage-weighted means of the children (linear light; the plain mean where
        /// nothing is covered, so edges keep their hue); A = 0.5 + 0.5 x AO where covered.
        GpuTexture lowResMipChain(const std::string& name, std::uint32_t width, std::uint32_t height,
                                  const std::vector<std::uint8_t>& level0, std::vector<float> coverage,
                                  std::vector<float> ao)
        {
            GpuTexture tex;
            tex.name = name;
            tex.format = GpuTextureFormat::RGBA8;
            tex.width = width;
            tex.height = height;
            tex.mipCount = fullMipCount(width, height);
            tex.data.resize(gpuTextureBytes(tex.format, width, height, tex.mipCount));
            std::copy(level0.begin(), level0.end(), tex.data.begin());
            std::size_t covered = 0;
            for (std::size_t t = 0; t < std::size_t(width) * height; ++t)
                covered += level0[4 * t + 3] >= LOW_RES_ALPHA_BYTE ? 1 : 0;
            const double fraction = double(covered) / double(std::size_t(width) * height);
            auto range = [](std::uint32_t d, std::uint32_t dsize, std::uint32_t ssize) {
                if (ssize == 1)
                    return std::make_pair(0u, 1u);
                const std::uint32_t first = 2 * d;
                return std::make_pair(first, d + 1 == dsize ? ssize : first + 2);
            };
            for (std::uint32_t mip = 1; mip < tex.mipCount; ++mip)
            {
                const std::uint32_t sw = tex.mipWidth(mip - 1), sh = tex.mipHeight(mip - 1);
                const std::uint32_t dw = tex.mipWidth(mip), dh = tex.mipHeight(mip);
                const std::uint8_t* src = tex.data.data() + tex.mipOffset(mip - 1);
                std::uint8_t* dst = tex.data.data() + tex.mipOffset(mip);
                std::vector<float> nextCoverage(std::size_t(dw) * dh), nextAo(std::size_t(dw) * dh);
                tbb::parallel_for(std::uint32_t(0), dh, [&](std::uint32_t y) {
                    const auto [y0, y1] = range(y, dh, sh);
                    for (std::uint32_t x = 0; x < dw; ++x)
                    {
                        const auto [x0, x1] = range(x, dw, sw);
                        glm::vec3 all(0.0f), weighted(0.0f);
                        float cov = 0.0f, aoSum = 0.0f;
                        int n = 0;
                        for (std::uint32_t yy = y0; yy < y1; ++yy)
                            for (std::uint32_t xx = x0; xx < x1; ++xx)
                            {
                                const std::size_t i = std::size_t(yy) * sw + xx;
                                const std::uint8_t* p = src + i * 4;
                                const glm::vec3 rgb(srgbByteToLinear(p[0]), srgbByteToLinear(p[1]),
                                                    srgbByteToLinear(p[2]));
                                all += rgb;
                                weighted += coverage[i] * rgb;
                                aoSum += coverage[i] * ao[i];
                                cov += coverage[i];
                                ++n;
                            }
                        const std::size_t o = std::size_t(y) * dw + x;
                        const glm::vec3 rgb = cov > 0.0f ? weighted / cov : all / float(n);
                        nextCoverage[o] = cov / float(n);
                        nextAo[o] = cov > 0.0f ? aoSum / cov : 1.0f;
                        std::uint8_t* q = dst + o * 4;
                        q[0] = linearToSrgbByte(rgb.r);
                        q[1] = linearToSrgbByte(rgb.g);
                        q[2] = linearToSrgbByte(rgb.b);
                        q[3] = 0;
                    }
                });
                // The covered texels: the highest coverage, level 0's fraction of them.
                const std::size_t texels = nextCoverage.size();
                const std::size_t keep =
                    std::min<std::size_t>(texels, std::size_t(std::llround(fraction * double(texels))));
                std::vector<std::uint32_t> order(texels);
                std::iota(order.begin(), order.end(), 0u);
                auto higher = [&](std::uint32_t a, std::uint32_t b) {
                    return nextCoverage[a] != nextCoverage[b] ? nextCoverage[a] > nextCoverage[b] : a < b;
                };
                if (keep > 0 && keep < texels)
                    std::nth_element(order.begin(), order.begin() + std::ptrdiff_t(keep), order.end(), higher);
                for (std::size_t k = 0; k < keep; ++k)
                    if (nextCoverage[order[k]] > 0.0f)
                        dst[4 * std::size_t(order[k]) + 3] = unitToByte(0.5f + 0.5f * nextAo[order[k]]);
                coverage = std::move(nextCoverage);
                ao = std::move(nextAo);
            }
            return tex;
        }

        /// Box-filtered mip chain of a normal map (n * 0.5 + 0.5 in RGB), renormalised.
        GpuTexture normalMipChain(const TextureImage& image)
        {
            GpuTexture tex;
            tex.name = image.name;
            tex.format = GpuTextureFormat::RGBA8;
            tex.width = std::uint32_t(image.width);
            tex.height = std::uint32_t(image.height);
            tex.mipCount = fullMipCount(tex.width, tex.height);
            tex.data.resize(gpuTextureBytes(tex.format, tex.width, tex.height, tex.mipCount));
            std::copy(image.rgba.begin(), image.rgba.end(), tex.data.begin());
            for (std::uint32_t mip = 1; mip < tex.mipCount; ++mip)
            {
                const std::uint32_t sw = tex.mipWidth(mip - 1), sh = tex.mipHeight(mip - 1);
                const std::uint32_t dw = tex.mipWidth(mip), dh = tex.mipHeight(mip);
                const std::uint8_t* src = tex.data.data() + tex.mipOffset(mip - 1);
                std::uint8_t* dst = tex.data.data() + tex.mipOffset(mip);
                tbb::parallel_for(std::uint32_t(0), dh, [&](std::uint32_t y) {
                    const std::uint32_t y0 = sh == 1 ? 0 : 2 * y, y1 = sh == 1 ? 1 : (y + 1 == dh ? sh : 2 * y + 2);
                    for (std::uint32_t x = 0; x < dw; ++x)
                    {
                        const std::uint32_t x0 = sw == 1 ? 0 : 2 * x, x1 = sw == 1 ? 1 : (x + 1 == dw ? sw : 2 * x + 2);
                        glm::vec3 n(0.0f);
                        for (std::uint32_t yy = y0; yy < y1; ++yy)
                            for (std::uint32_t xx = x0; xx < x1; ++xx)
                            {
                                const std::uint8_t* p = src + (std::size_t(yy) * sw + xx) * 4;
                                n += glm::vec3(p[0], p[1], p[2]) / 255.0f * 2.0f - 1.0f;
                            }
                        n = glm::length(n) > 1e-6f ? glm::normalize(n) : glm::vec3(0, 0, 1);
                        std::uint8_t* q = dst + (std::size_t(y) * dw + x) * 4;
                        q[0] = unitToByte(n.x * 0.5f + 0.5f);
                        q[1] = unitToByte(n.y * 0.5f + 0.5f);
                        q[2] = unitToByte(n.z * 0.5f + 0.5f);
                        q[3] = 255;
                    }
                });
            }
            return tex;
        }

        // ---- levels -------------------------------------------------------------------------------

        struct LevelBuild
        {
            std::vector<BillboardBuild> billboards;
            float cellSize = 0.0f, lowResTexel = 0.0f;
            bool layered = false;
            float meanError = 0.0f, maxError = 0.0f;
            JudgedClustering judged;
        };

        /// (spatialWeight, orientationWeight) of each try, LeafClusteringOptions' defaults first.
        constexpr float SPATIAL = LeafClusteringOptions{}.spatialWeight;
        constexpr float ORIENTATION = LeafClusteringOptions{}.orientationWeight;
        constexpr std::array<std::pair<float, float>, CLUSTERING_TRIES_MAX> CLUSTERING_WEIGHTS{
            {{SPATIAL, ORIENTATION},
             {SPATIAL, 3.0f * ORIENTATION},
             {0.5f * SPATIAL, ORIENTATION},
             {2.0f * SPATIAL, ORIENTATION},
             {SPATIAL, 0.25f * ORIENTATION},
             {0.5f * SPATIAL, 3.0f * ORIENTATION}}};

        /// §4.1's clustering into `count` planes, tried with clusteringTries weight pairs and judged
        /// by image error over views around and above (ClusteringJudge): the first of the least
        /// error among those whose billboard area (billboardArea: hash and low-res texels) is
        /// within clusteringAreaGrowth of the default weights' clustering.
        LeafClustering chooseClustering(const BakeContext& ctx, std::uint32_t count, const std::string& step,
                                        JudgedClustering& judged)
        {
            std::uint32_t bestTry = 0;
            LeafClusteringOptions co;
            co.clusterCount = count;
            co.errorBound = ctx.options.maxPlaneError * ctx.diagonal;
            const std::uint32_t tries = std::min<std::uint32_t>(ctx.options.clusteringTries, CLUSTERING_TRIES_MAX);
            judged = {};
            double defaultArea = 0.0;
            LeafClustering best;
            double bestError = std::numeric_limits<double>::infinity();
            for (std::uint32_t t = 0; t < tries; ++t)
            {
                co.spatialWeight = CLUSTERING_WEIGHTS[t].first;
                co.orientationWeight = CLUSTERING_WEIGHTS[t].second;
                LeafClustering clustering = clusterLeaves(ctx.model, co);
                if (tries == 1)
                {
                    judged.spatialWeight = co.spatialWeight;
                    judged.orientationWeight = co.orientationWeight;
                    return clustering;
                }
                const double area = billboardArea(ctx.model, clustering);
                if (t == 0)
                    defaultArea = area;
                else if (ctx.options.clusteringAreaGrowth > 0.0f &&
                         area > (1.0 + double(ctx.options.clusteringAreaGrowth)) * defaultArea)
                    continue;
                const double e = ctx.judge->error(clustering);
                report(ctx.progress, step, 0.5f * float(t + 1) / float(tries));
                if (e < bestError)
                {
                    bestError = e;
                    bestTry = t;
                    best = std::move(clustering);
                }
                if (t == 0)
                    judged.defaultError = e;
            }
            judged.error = bestError;
            judged.spatialWeight = CLUSTERING_WEIGHTS[bestTry].first;
            judged.orientationWeight = CLUSTERING_WEIGHTS[bestTry].second;
            return best;
        }

        /// §4.1: clusters -> billboards with lists (all levels: the low-res pass reads them).
        LevelBuild buildLevel(const BakeContext& ctx, std::uint32_t count, bool layered, const std::string& step)
        {
            LevelBuild level;
            level.layered = layered;
            level.cellSize = ctx.cellSize;
            report(ctx.progress, step, 0.0f);
            const LeafClustering clustering = chooseClustering(ctx, count, step, level.judged);
            double sum = 0.0;
            for (float e : clustering.error)
            {
                sum += e;
                level.maxError = std::max(level.maxError, e);
            }
            level.meanError = clustering.error.empty() ? 0.0f : float(sum / double(clustering.error.size()));
            report(ctx.progress, step, 0.5f);
            const std::uint32_t C = std::uint32_t(clustering.members.size());
            level.billboards.resize(C);
            tbb::parallel_for(std::uint32_t(0), C, [&](std::uint32_t k) {
                BillboardBuild& bb = level.billboards[k];
                buildBillboard(ctx, clustering, k, level.cellSize, bb);
                buildLists(ctx, bb);
            });
            report(ctx.progress, step, 1.0f);
            return level;
        }

        /// Render every billboard's low-res image at `texel` metres.
        void renderLevelLowRes(const BakeContext& ctx, LevelBuild& level, float texel, bool keepLists)
        {
            level.lowResTexel = texel;
            tbb::parallel_for(std::size_t(0), level.billboards.size(), [&](std::size_t b) {
                BillboardBuild& bb = level.billboards[b];
                const auto [w, h] = lowResSize(bb, texel);
                renderLowRes(ctx, bb, w, h);
                if (!keepLists)
                {
                    bb.cellStart = {};
                    bb.entries = {};
                    bb.entryAo = {};
                }
            });
        }

        /// Low-res atlas of all levels' billboards (2-texel gutters, edge colours extended into
        /// them with A = 0), mip chain, optional DXT5. Sets each billboard's rect.
        Result<GpuTexture> lowResAtlas(const BakeContext& ctx, const std::vector<LevelBuild*>& levels,
                                       std::vector<Billboard>& billboards, bool compress)
        {
            std::vector<const BillboardBuild*> all;
            for (const LevelBuild* level : levels)
                for (const BillboardBuild& bb : level->billboards)
                    all.push_back(&bb);
            const std::uint32_t half = LOW_RES_GUTTER / 2;
            std::vector<glm::uvec2> slots(all.size());
            for (std::size_t b = 0; b < all.size(); ++b)
                slots[b] = glm::uvec2(all[b]->lowResWidth + LOW_RES_GUTTER, all[b]->lowResHeight + LOW_RES_GUTTER);
            const Packing packing = shelfPack(slots);
            if (packing.height > GPU_TEXTURE_MAX_SIZE)
                return fail(ctx.label, "billboard-cloud low-res atlas",
                            std::to_string(packing.width) + "x" + std::to_string(packing.height) + " texels exceed " +
                                std::to_string(GPU_TEXTURE_MAX_SIZE) +
                                " (lower lowResLeafRatio's detail or the billboard count)");
            const std::uint32_t W = packing.width, H = packing.height;
            std::vector<std::uint8_t> atlas(std::size_t(W) * H * 4, 0);
            std::vector<float> coverage(std::size_t(W) * H, 0.0f), ao(std::size_t(W) * H, 1.0f);
            for (std::size_t t = 0; t < std::size_t(W) * H; ++t)
                atlas[4 * t + 0] = atlas[4 * t + 1] = atlas[4 * t + 2] = 64; // background, A = 0
            tbb::parallel_for(std::size_t(0), all.size(), [&](std::size_t b) {
                const BillboardBuild& bb = *all[b];
                const glm::uvec2 at = packing.position[b];
                for (std::uint32_t y = 0; y < slots[b].y; ++y)
                    for (std::uint32_t x = 0; x < slots[b].x; ++x)
                    {
                        const int sx = std::clamp(int(x) - int(half), 0, int(bb.lowResWidth) - 1);
                        const int sy = std::clamp(int(y) - int(half), 0, int(bb.lowResHeight) - 1);
                        const bool inside =
                            x >= half && y >= half && x < half + bb.lowResWidth && y < half + bb.lowResHeight;
                        const std::uint8_t* s = &bb.lowRes[(std::size_t(sy) * bb.lowResWidth + std::size_t(sx)) * 4];
                        std::uint8_t* d = &atlas[(std::size_t(at.y + y) * W + at.x + x) * 4];
                        d[0] = s[0];
                        d[1] = s[1];
                        d[2] = s[2];
                        d[3] = inside ? s[3] : 0;
                        if (inside)
                        {
                            const std::size_t from = std::size_t(sy) * bb.lowResWidth + std::size_t(sx);
                            const std::size_t to = std::size_t(at.y + y) * W + at.x + x;
                            coverage[to] = bb.lowResCoverage[from];
                            ao[to] = bb.lowResAo[from];
                        }
                    }
            });
            for (std::size_t b = 0; b < all.size(); ++b)
            {
                billboards[b].lowResX = packing.position[b].x + half;
                billboards[b].lowResY = packing.position[b].y + half;
                billboards[b].lowResWidth = all[b]->lowResWidth;
                billboards[b].lowResHeight = all[b]->lowResHeight;
            }
            GpuTexture tex = lowResMipChain("billboard low-res", W, H, atlas, std::move(coverage), std::move(ao));
            if (compress)
                tex = compressTexture(tex, GpuTextureFormat::DXT5);
            return tex;
        }

        Billboard toBillboard(const BillboardBuild& bb)
        {
            Billboard b;
            b.origin = bb.origin;
            b.axisU = bb.U * bb.width;
            b.axisV = bb.V * bb.height;
            b.normal = bb.N;
            return b;
        }

        std::vector<std::uint8_t> barkAoBytes(const BakeContext& ctx)
        {
            std::vector<std::uint8_t> out(ctx.ao.barkVertex.size());
            for (std::size_t v = 0; v < out.size(); ++v)
                out[v] = unitToByte(ctx.ao.barkVertex[v]);
            return out;
        }

        void fillEmpty(const BakeContext& ctx, BillboardCloudData& data, bool classic)
        {
            data.classic = classic;
            data.listFactor = ctx.options.listFactor;
            data.boundsMin = ctx.boundsMin;
            data.boundsMax = ctx.boundsMax;
            data.levels.assign(classic ? 1 : 3, BillboardCloudLevel{});
            data.leavesColour = placeholderTexture("billboard leaves colour");
            data.leavesNormal = placeholderTexture("billboard leaves normal");
            data.lowRes = placeholderTexture("billboard low-res");
            data.barkAo = barkAoBytes(ctx);
        }

        std::uint32_t finestCount(const BillboardCloudOptions& options, std::uint32_t leaves)
        {
            std::uint32_t c = options.billboardCount;
            if (c == 0)
                c = std::uint32_t(std::clamp(std::lround(3.0 * std::sqrt(double(leaves))), 8l, 260l));
            return std::clamp<std::uint32_t>(c, 1, std::max<std::uint32_t>(leaves, 1));
        }

        /// No leaves: the placeholders of fillEmpty and the bark AO, nothing else.
        BillboardCloudData emptyCloud(BillboardCloudData data, BillboardCloudStats& s, BillboardCloudStats* stats)
        {
            s.gpuBytes = data.gpuBytes();
            if (stats)
                *stats = s;
            return data;
        }

        // ---- the multi-layered cloud --------------------------------------------------------------

        /// Bytes `texture` takes once compressed to `format` (DXT sizes follow from the dimensions).
        std::uint64_t compressedBytes(const GpuTexture& texture, GpuTextureFormat format)
        {
            return gpuTextureBytes(format, texture.width, texture.height, texture.mipCount);
        }

        /// The layered bake. `sizeOnly`: skip the DXT compression and report in stats->gpuBytes
        /// what the compressed textures would take (the data returned keeps them uncompressed).
        /// `finest`: receives level 0's build (for the classic cloud, which clusters the same way).
        Result<BillboardCloudData> bakeLayered(const BakeContext& ctx, BillboardCloudStats* stats,
                                               bool sizeOnly = false, LevelBuild* finest = nullptr)
        {
            BillboardCloudData data;
            fillEmpty(ctx, data, false);
            BillboardCloudStats s;
            const std::uint32_t L = std::uint32_t(ctx.model.leaves.size());
            s.leaves = L;
            if (L == 0)
                return emptyCloud(std::move(data), s, stats);
            const BillboardLeafTiles& tiles = *ctx.tiles;

            // §4.1, §6: three clouds of decreasing count; the coarsest is low-res only.
            const std::uint32_t c0 = finestCount(ctx.options, L);
            const std::uint32_t counts[3] = {c0, std::max(1u, c0 / 3), std::max(1u, c0 / 9)};
            std::array<LevelBuild, 3> levels;
            for (int l = 0; l < 3; ++l)
            {
                levels[std::size_t(l)] =
                    buildLevel(ctx, counts[l], l < 2, "billboard clustering level " + std::to_string(l));
                s.billboards[l] = std::uint32_t(levels[std::size_t(l)].billboards.size());
            }
            s.meanPlaneError = levels[0].meanError;
            s.maxPlaneError = levels[0].maxError;
            for (int l = 0; l < 3; ++l)
                s.clustering[l] = levels[std::size_t(l)].judged;

            // §5.1: low-res images from the layered representation.
            report(ctx.progress, "billboard low-res", 0.0f);
            const float texel0 = ctx.options.lowResLeafRatio * ctx.leafLength;
            for (int l = 0; l < 3; ++l)
            {
                renderLevelLowRes(ctx, levels[std::size_t(l)], texel0 * LEVEL_TEXEL_FACTOR[l], l < 2);
                report(ctx.progress, "billboard low-res", float(l + 1) / 3.0f);
            }

            // Levels and billboards.
            std::uint32_t first = 0;
            for (int l = 0; l < 3; ++l)
            {
                BillboardCloudLevel& level = data.levels[std::size_t(l)];
                level.firstBillboard = first;
                level.billboardCount = s.billboards[l];
                level.layered = levels[std::size_t(l)].layered;
                level.cellSize = level.layered ? levels[std::size_t(l)].cellSize : 0.0f;
                level.lowResTexelSize = levels[std::size_t(l)].lowResTexel;
                first += level.billboardCount;
                for (const BillboardBuild& bb : levels[std::size_t(l)].billboards)
                    data.billboards.push_back(toBillboard(bb));
            }

            // §4.2, §6: the Hash atlas (layered billboards) and the Lists and AO atlases.
            report(ctx.progress, "billboard atlases", 0.0f);
            std::vector<const BillboardBuild*> layered;
            std::vector<std::uint32_t> layeredIndex;
            for (int l = 0; l < 2; ++l)
                for (std::size_t b = 0; b < levels[std::size_t(l)].billboards.size(); ++b)
                {
                    layered.push_back(&levels[std::size_t(l)].billboards[b]);
                    layeredIndex.push_back(data.levels[std::size_t(l)].firstBillboard + std::uint32_t(b));
                }
            std::uint64_t entryCount = 0;
            std::vector<std::uint64_t> entryOffset(layered.size());
            for (std::size_t b = 0; b < layered.size(); ++b)
            {
                entryOffset[b] = entryCount;
                entryCount += layered[b]->entries.size();
                s.longestList = std::max(s.longestList, layered[b]->longest);
                s.truncatedCells += layered[b]->truncated;
            }
            if (entryCount > BILLBOARD_MAX_ENTRIES)
                return fail(ctx.label, "billboard-cloud lists atlas",
                            "atlas overflow: " + std::to_string(entryCount) +
                                " list entries, at most 2^24 (raise cellLeafRatio or lower the billboard count)");
            std::vector<glm::uvec2> hashRects(layered.size());
            for (std::size_t b = 0; b < layered.size(); ++b)
                hashRects[b] = glm::uvec2(layered[b]->hashWidth, layered[b]->hashHeight);
            const Packing hashPacking = shelfPack(hashRects);
            if (hashPacking.height > GPU_TEXTURE_MAX_SIZE)
                return fail(ctx.label, "billboard-cloud hash atlas",
                            std::to_string(hashPacking.width) + "x" + std::to_string(hashPacking.height) +
                                " texels exceed " + std::to_string(GPU_TEXTURE_MAX_SIZE) + " (raise cellLeafRatio)");
            data.hashAtlasWidth = hashPacking.width;
            data.hashAtlasHeight = hashPacking.height;
            data.hashAtlas.assign(std::size_t(data.hashAtlasWidth) * data.hashAtlasHeight * 4, 0);
            data.entries.resize(std::size_t(entryCount));
            data.entryAo.resize(std::size_t(entryCount) * 4);
            tbb::parallel_for(std::size_t(0), layered.size(), [&](std::size_t b) {
                const BillboardBuild& bb = *layered[b];
                Billboard& out = data.billboards[layeredIndex[b]];
                out.hashX = hashPacking.position[b].x;
                out.hashY = hashPacking.position[b].y;
                out.hashWidth = bb.hashWidth;
                out.hashHeight = bb.hashHeight;
                for (std::uint32_t j = 0; j < bb.hashHeight; ++j)
                    for (std::uint32_t i = 0; i < bb.hashWidth; ++i)
                    {
                        const std::uint32_t c = j * bb.hashWidth + i;
                        const std::uint32_t length = bb.cellStart[c + 1] - bb.cellStart[c];
                        if (length == 0)
                            continue;
                        const std::uint64_t start = entryOffset[b] + bb.cellStart[c];
                        std::uint8_t* t =
                            &data.hashAtlas[((std::size_t(out.hashY) + j) * data.hashAtlasWidth + out.hashX + i) * 4];
                        t[0] = std::uint8_t(start & 0xff);
                        t[1] = std::uint8_t((start >> 8) & 0xff);
                        t[2] = std::uint8_t((start >> 16) & 0xff);
                        t[3] = std::uint8_t(length);
                    }
                std::copy(bb.entries.begin(), bb.entries.end(), data.entries.begin() + std::ptrdiff_t(entryOffset[b]));
                for (std::size_t e = 0; e < bb.entryAo.size(); ++e)
                    std::copy(bb.entryAo[e].begin(), bb.entryAo[e].end(),
                              data.entryAo.begin() + std::ptrdiff_t((entryOffset[b] + e) * 4));
            });
            std::uint32_t listsWidth = ctx.options.listsAtlasWidth;
            auto rowsFor = [&](std::uint32_t width) { return std::uint32_t((entryCount + width - 1) / width); };
            while (rowsFor(listsWidth) > listsWidth && listsWidth < MAX_ATLAS_WIDTH)
                listsWidth *= 2;
            data.listsAtlasWidth = entryCount ? listsWidth : 0;
            data.listsAtlasHeight = entryCount ? rowsFor(listsWidth) : 0;
            report(ctx.progress, "billboard atlases", 0.5f);

            const bool compress = ctx.options.compress && !sizeOnly;
            Result<GpuTexture> lowRes =
                lowResAtlas(ctx, {&levels[0], &levels[1], &levels[2]}, data.billboards, compress);
            if (!lowRes)
                return lowRes.error();
            data.lowRes = std::move(lowRes.value());
            report(ctx.progress, "billboard atlases", 1.0f);

            // §3, §5, §5.2: the Leaves Texture, colour and normal map, mip-mapped.
            report(ctx.progress, "billboard leaves texture", 0.0f);
            data.tileSize = tiles.tileSize();
            data.tileColumns = tiles.tileColumns();
            data.orientationGrid = tiles.grid();
            data.leafImages = tiles.images();
            data.leavesMaxLod = tiles.maxLod();
            MipChainOptions mips;
            mips.preserveAlphaCoverage = true;
            mips.alphaCutoff = LEAVES_COVERAGE_CUTOFF;
            data.leavesColour = buildMipChain(tiles.colour(), mips);
            data.leavesNormal = normalMipChain(tiles.normal());
            data.leavesMaxLod = std::min(data.leavesMaxLod, data.leavesColour.mipCount - 1);
            if (compress)
            {
                data.leavesColour = compressTexture(data.leavesColour, GpuTextureFormat::DXT5);
                data.leavesNormal = compressTexture(data.leavesNormal, GpuTextureFormat::DXT1);
            }
            report(ctx.progress, "billboard leaves texture", 1.0f);

            Result<void> valid = data.validate(ctx.label);
            if (!valid)
                return valid.error();
            s.entries = std::uint32_t(data.entries.size());
            s.gpuBytes = data.gpuBytes();
            if (sizeOnly && ctx.options.compress)
                s.gpuBytes = s.gpuBytes - data.lowRes.data.size() - data.leavesColour.data.size() -
                             data.leavesNormal.data.size() + compressedBytes(data.lowRes, GpuTextureFormat::DXT5) +
                             compressedBytes(data.leavesColour, GpuTextureFormat::DXT5) +
                             compressedBytes(data.leavesNormal, GpuTextureFormat::DXT1);
            if (stats)
                *stats = s;
            if (finest)
                *finest = std::move(levels[0]);
            return data;
        }

        // ---- the classic cloud (Fig. 13's baseline) --------------------------------------------------

        /// `built`: level 0 of a layered bake with the same options (the same clustering), or null.
        Result<BillboardCloudData> bakeClassic(const BakeContext& ctx, std::uint64_t memoryBytes,
                                               BillboardCloudStats* stats, LevelBuild* built = nullptr)
        {
            BillboardCloudData data;
            fillEmpty(ctx, data, true);
            BillboardCloudStats s;
            const std::uint32_t L = std::uint32_t(ctx.model.leaves.size());
            s.leaves = L;
            if (L == 0)
                return emptyCloud(std::move(data), s, stats);
            LevelBuild level =
                built ? std::move(*built) : buildLevel(ctx, finestCount(ctx.options, L), false, "billboard clustering");
            level.layered = false;
            s.billboards[0] = std::uint32_t(level.billboards.size());
            s.meanPlaneError = level.meanError;
            s.maxPlaneError = level.maxError;
            s.clustering[0] = level.judged;

            // Texel size for the budget: bytes ~ texels x (1 DXT5, 4 RGBA8) x 4/3 (mips). The
            // atlas size follows from the rect sizes alone, so it is solved before rendering:
            // a first guess from the billboards' area, then up to four corrections by the ratio
            // of the measured to the wanted bytes.
            const std::uint64_t fixedBytes = data.gpuBytes() - data.lowRes.data.size();
            const double budget = double(memoryBytes > fixedBytes ? memoryBytes - fixedBytes : 1);
            const double bytesPerTexel = (ctx.options.compress ? 1.0 : 4.0) * 4.0 / 3.0;
            double area = 0.0;
            for (const BillboardBuild& bb : level.billboards)
                area += double(bb.width) * bb.height;
            auto atlasBytes = [&](float texel) {
                std::vector<glm::uvec2> slots;
                for (const BillboardBuild& bb : level.billboards)
                {
                    const auto [w, h] = lowResSize(bb, texel);
                    slots.push_back(glm::uvec2(w + LOW_RES_GUTTER, h + LOW_RES_GUTTER));
                }
                const Packing p = shelfPack(slots);
                return double(gpuTextureBytes(ctx.options.compress ? GpuTextureFormat::DXT5 : GpuTextureFormat::RGBA8,
                                              p.width, p.height, fullMipCount(p.width, p.height)));
            };
            float texel = float(std::sqrt(area / std::max(budget / bytesPerTexel, 1.0)));
            for (int step = 0; step < 4; ++step)
            {
                const double bytes = atlasBytes(texel);
                if (std::abs(bytes - budget) <= 0.1 * budget)
                    break;
                texel *= float(std::sqrt(bytes / budget));
            }
            report(ctx.progress, "billboard low-res", 0.0f);
            renderLevelLowRes(ctx, level, texel, false);
            report(ctx.progress, "billboard low-res", 1.0f);

            for (const BillboardBuild& bb : level.billboards)
                data.billboards.push_back(toBillboard(bb));
            data.levels[0].firstBillboard = 0;
            data.levels[0].billboardCount = s.billboards[0];
            data.levels[0].layered = false;
            data.levels[0].cellSize = 0.0f;
            data.levels[0].lowResTexelSize = texel;
            Result<GpuTexture> lowRes = lowResAtlas(ctx, {&level}, data.billboards, ctx.options.compress);
            if (!lowRes)
                return lowRes.error();
            data.lowRes = std::move(lowRes.value());

            Result<void> valid = data.validate(ctx.label);
            if (!valid)
                return valid.error();
            s.gpuBytes = data.gpuBytes();
            if (stats)
                *stats = s;
            return data;
        }
    }

    Result<BillboardCloudData> bakeBillboardCloud(const TreeModel& model, const BillboardCloudOptions& options,
                                                  const std::string& label, const ProgressCallback& progress,
                                                  BillboardCloudStats* stats)
    {
        // Deviation (techniques/billboard-cloud/README.md): a leaf in several planes is clustered, tiled and
        // listed plane by plane, each plane a leaf showing its part of the leaf image.
        const std::optional<TreeModel> planes = leafPlanesAsLeaves(model);
        BakeContext ctx(planes ? *planes : model, options, label, progress);
        Result<void> ready = prepare(ctx);
        if (!ready)
            return ready.error();
        return bakeLayered(ctx, stats);
    }

    Result<BillboardCloudData> bakeClassicBillboardCloud(const TreeModel& model,
                                                         const ClassicBillboardCloudOptions& options,
                                                         const std::string& label, const ProgressCallback& progress,
                                                         BillboardCloudStats* stats)
    {
        const std::optional<TreeModel> planes = leafPlanesAsLeaves(model); // as bakeBillboardCloud
        BakeContext ctx(planes ? *planes : model, options.cloud, label, progress);
        Result<void> ready = prepare(ctx);
        if (!ready)
            return ready.error();
        std::uint64_t memory = options.memoryBytes;
        if (memory == 0)
        {
            // Fig. 13: the same memory as the multi-layered cloud. Its size needs no compression,
            // and its finest clustering is the classic cloud's.
            BillboardCloudStats layeredStats;
            LevelBuild finest;
            Result<BillboardCloudData> layered = bakeLayered(ctx, &layeredStats, true, &finest);
            if (!layered)
                return layered.error();
            memory = layeredStats.gpuBytes;
            if (!finest.billboards.empty())
                return bakeClassic(ctx, memory, stats, &finest);
        }
        return bakeClassic(ctx, memory, stats);
    }

    Result<void> addBillboardCloudChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                        const ProgressCallback& progress)
    {
        return addBillboardCloudChunk(writer, model, BillboardCloudOptions{}, label, progress);
    }

    Result<void> addBillboardCloudChunk(PackageWriter& writer, const TreeModel& model,
                                        const BillboardCloudOptions& options, const std::string& label,
                                        const ProgressCallback& progress)
    {
        return addBakedChunk(writer, model, label, progress, BILLBOARD_CLOUD_CHUNK, BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION,
                             encodeBillboardCloudChunk, [&]() {
            BillboardCloudStats stats;
            Result<BillboardCloudData> data = bakeBillboardCloud(model, options, label, progress, &stats);
            // Truncated lists are not an error (the front and back ends are kept) but must not be silent.
            if (data && stats.truncatedCells > 0)
                report(progress,
                       "warning: " + label + ": " + std::to_string(stats.truncatedCells) +
                           " hash cells hold more than " + std::to_string(BILLBOARD_MAX_LIST_LENGTH) +
                           " leaf fragments; their lists keep the 127 frontmost and 128 backmost",
                       1.0f);
            return data;
        });
    }

    Result<void> addClassicBillboardCloudChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                               const ProgressCallback& progress)
    {
        return addClassicBillboardCloudChunk(writer, model, ClassicBillboardCloudOptions{}, label, progress);
    }

    Result<void> addClassicBillboardCloudChunk(PackageWriter& writer, const TreeModel& model,
                                               const ClassicBillboardCloudOptions& classic, const std::string& label,
                                               const ProgressCallback& progress)
    {
        return addBakedChunk(writer, model, label, progress, CLASSIC_BILLBOARD_CLOUD_CHUNK,
                             BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION, encodeBillboardCloudChunk, [&]() {
            ClassicBillboardCloudOptions options = classic;
            // Fig. 13: the layered cloud's memory; a layered chunk already in the package gives it
            // without baking again.
            if (const std::vector<std::uint8_t>* layered =
                    options.memoryBytes == 0 ? writer.chunkBytes(BILLBOARD_CLOUD_CHUNK, 0) : nullptr)
            {
                Result<BillboardCloudData> decoded = decodeBillboardCloudChunk(*layered, label);
                if (decoded && decoded->gpuBytes() > 0)
                    options.memoryBytes = decoded->gpuBytes();
            }
            return bakeClassicBillboardCloud(model, options, label, progress);
        });
    }
}
