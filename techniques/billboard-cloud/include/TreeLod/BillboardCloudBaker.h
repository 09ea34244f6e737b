// BillboardCloudBaker: TreeModel -> BillboardCloudData (BillboardCloudData.h), García et al. 2007.
//
//   0. Leaves: a leaf that is one mesh in several planes (a folded leaf, a sprig in one piece)
//      is a leaf per plane, each showing its part of the leaf image (leafPlanesAsLeaves).
//      Deviation (techniques/billboard-cloud/README.md): as one flat leaf it lost to the classic cloud.
//   1. Clustering (§4.1): leaves grouped into planes, k-means-like on leaf planes with an
//      error bound ([BCF*05], [GSSK05]); each billboard's quad bounds its leaves' projection.
//      Deviation (techniques/billboard-cloud/README.md): each cloud is clustered with several weight pairs
//      and the clustering kept is judged by image error over views around and above the tree
//      (ClusteringJudge), not by plane fit alone.
//      Three clouds of decreasing count (§6): counts C, C/3, C/9 (at least 1 each); the
//      coarsest one is low-res only.
//   2. Leaves Texture (§3, §5, §5.2): per leaf material, tiles for a hemi-octahedral set of
//      orientations, both view sides, colour + normal map, mip-mapped.
//   3. Hash and Lists (§4.2): per billboard a grid of cells; per cell the leaf fragments
//      overlapping it, front to back (computed exactly on the CPU, instead of the paper's
//      point sprites + depth peeling); AO per entry fitted to the tile corners (§5.2, Fig. 11).
//   4. Low-resolution texture (§5.1) made by evaluating the layered representation, AO in alpha.
//   5. Atlases (§6) and DXT compression (libsquish) of the colour textures.
// The classic billboard cloud (the baseline of Fig. 13) is the finest cloud's billboards
// with one plain RGBA texture each, its texel size chosen to fit a memory budget.
//
// Deterministic: the same model and options give byte-identical chunks for any thread count.
#pragma once

#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>

namespace TreeLod
{
    constexpr std::uint32_t CLUSTERING_TRIES_MAX = 6;

    struct BillboardCloudOptions
    {
        /// Billboards of the finest cloud; 0 = derived from the leaf count
        /// (clamp(3 * sqrt(leaves), 8, 260), the paper's 60-260 for trees; 164 for 3000 leaves,
        /// about its Table 1's counts). Never more than the leaves.
        std::uint32_t billboardCount = 0;
        /// Clusterings tried per cloud level, with different spatial and orientation weights
        /// (BillboardClustering.h); the one kept has the least image error of its leaves
        /// flattened onto their billboards, seen from around and above the tree
        /// (ClusteringJudge). 1: the default weights, unjudged. At most CLUSTERING_TRIES_MAX.
        std::uint32_t clusteringTries = CLUSTERING_TRIES_MAX;
        /// Memory bound on the judged tries: a try whose billboard area (hash and low-res texels)
        /// exceeds the default weights' by more than this fraction is not kept. 0: no bound (the
        /// least image error wins: larger billboards, 2.00 MB on the GPU for a 20k-leaf oak
        /// against 1.59 MB with 0.05, and more fill; docs/measurements.md).
        float clusteringAreaGrowth = 0.05f;
        /// Plane-fitting error bound: the largest distance of a leaf vertex from its billboard,
        /// as a fraction of the tree's bounding-box diagonal. 0.02, with the judged clustering:
        /// tree-box FLIP at mid distance lower on 8 of the 9 trees of the corpus than 0.04 with
        /// plane fit alone (docs/measurements.md, "Clustering judged by image error").
        float maxPlaneError = 0.02f;
        /// Hash cell edge in median leaf lengths (cell size of a layered level). A leaf's length
        /// here is its diameter (twice its largest vertex distance from its centre). 2: about 1.6
        /// entries per leaf per layered level, 1.5 MB for a 20k-leaf tree (docs/measurements.md).
        float cellLeafRatio = 2.0f;
        /// Low-res texel edge of level 0 in median leaf lengths (levels 1 and 2: 2x and 4x).
        float lowResLeafRatio = 0.75f;
        std::uint32_t tileSize = 64;      ///< Leaves Texture tile edge, power of two >= 8
        /// Leaves Texture budget: while the leaf images' tiles would take more texels, the tile
        /// edge halves (not below 16; reported). 2^21 texels (about 4 MB with DXT and mips) keep
        /// 64-texel tiles up to 8 leaf images; a 2x2 atlas under six materials (24 images) gets
        /// 32 (techniques/billboard-cloud/README.md). 0: no budget.
        std::uint64_t maxLeavesTexels = std::uint64_t(1) << 21;
        /// Orientations per leaf image = grid^2; odd, so that one cell is centred on the leaf
        /// normal (the most common direction: billboards are fitted to leaf planes).
        std::uint32_t orientationGrid = 5;
        std::uint32_t listsAtlasWidth = 1024; ///< grows (power of two up to 4096) when needed
        /// Shader LoD factor stored in the chunk: list entries walked per pixel of projected cell
        /// diagonal. 8: on the corpus, far views (30 px) at or below the classic cloud at equal
        /// memory on every tree, where 4 lost on the ez-tree pine (0.043 against 0.037), at no
        /// frame time measurable on llvmpipe; 4 measured better than 1 and 2 on the 20k-leaf oak
        /// (docs/measurements.md, treelod_corpus_study and treelod_bc_study).
        float listFactor = 8.0f;
        bool compress = true;              ///< DXT5 leaves colour and low-res, DXT1 normals (libsquish)
        int aoRays = 32;                   ///< per leaf vertex (AmbientOcclusion.h)
    };

    struct ClassicBillboardCloudOptions
    {
        BillboardCloudOptions cloud;  ///< clustering and compression settings (finest cloud)
        /// GPU bytes for all billboard textures; 0 = the layered cloud's gpuBytes() with the
        /// same options (the equal-memory comparison of García et al. 2007 Fig. 13).
        std::uint64_t memoryBytes = 0;
    };

    /// How a cloud level's clustering was chosen (BillboardCloudOptions::clusteringTries).
    struct JudgedClustering
    {
        double error = 0.0;        ///< its image error (ClusteringJudge: mean FLIP), 0 when unjudged
        double defaultError = 0.0; ///< that of the default weights' clustering
        float spatialWeight = 0.5f, orientationWeight = 4.0f; ///< the weights kept
    };

    struct BillboardCloudStats
    {
        std::uint32_t leaves = 0;
        std::uint32_t billboards[3] = {0, 0, 0};
        std::uint32_t entries = 0;
        std::uint32_t longestList = 0;    ///< before truncation (> 255: some lists were cut)
        std::uint32_t truncatedCells = 0; ///< lists cut at 255 entries (reported, never silent)
        float meanPlaneError = 0.0f;      ///< metres, finest cloud
        float maxPlaneError = 0.0f;
        JudgedClustering clustering[3]; ///< per level (the classic cloud: level 0)
        std::uint64_t gpuBytes = 0;
    };

    /// Bake the multi-layered cloud. Errors (invalid model, an atlas beyond 2^24 entries or
    /// GPU_TEXTURE_MAX_SIZE) name `label`. A model without leaves gives a valid cloud with no
    /// billboards (the trunk is drawn by its mesh).
    Result<BillboardCloudData> bakeBillboardCloud(const TreeModel& model, const BillboardCloudOptions& options,
                                                  const std::string& label, const ProgressCallback& progress = {},
                                                  BillboardCloudStats* stats = nullptr);

    /// Bake the classic cloud (one level, `classic` set, no hash or lists).
    Result<BillboardCloudData> bakeClassicBillboardCloud(const TreeModel& model,
                                                         const ClassicBillboardCloudOptions& options,
                                                         const std::string& label,
                                                         const ProgressCallback& progress = {},
                                                         BillboardCloudStats* stats = nullptr);

    /// Package glue for `treelod bake` (BakeTechniques): adds the reference chunk (the trunk
    /// mesh and materials come from it) and the cloud's chunk, default options.
    Result<void> addBillboardCloudChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                        const ProgressCallback& progress = {});
    Result<void> addClassicBillboardCloudChunk(PackageWriter& writer, const TreeModel& model,
                                               const std::string& label, const ProgressCallback& progress = {});
    /// The same with `options` (the classic cloud's memory: options.memoryBytes, else the layered
    /// chunk's in the writer, else the layered cloud's with the same options).
    Result<void> addBillboardCloudChunk(PackageWriter& writer, const TreeModel& model,
                                        const BillboardCloudOptions& options, const std::string& label,
                                        const ProgressCallback& progress = {});
    Result<void> addClassicBillboardCloudChunk(PackageWriter& writer, const TreeModel& model,
                                               const ClassicBillboardCloudOptions& options, const std::string& label,
                                               const ProgressCallback& progress = {});
}
