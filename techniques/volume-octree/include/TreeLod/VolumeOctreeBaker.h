// VolumeOctreeBaker: CaptureSet (CaptureSet.h) -> VolumeOctreeData (VolumeOctreeData.h), after
// Linz, Reche-Martinez, Drettakis and Magnor 2006 (paper 002) and the reconstruction of
// Reche-Martinez et al. 2004 it builds on (§2.1).
//
//   1. Octree, level by level from the root (§3.1). A level's candidate cells are the children of
//      the previous level's cells. Visual hull: a candidate is dropped when some camera that has
//      it in front sees only zero alpha over the cell's footprint (a max-alpha pyramid per image).
//   2. Opacity (§2.1: "opacity estimation ... similar to tomography"): each hull cell gets an
//      optical depth tau (opacity 1 - exp(-tau)). Along the ray from camera c through a cell's
//      centre, the hull cells' depths should add up to T = -log(1 - a), a the image's mean alpha
//      over the cell's footprint. Start: each cell's mean over the cameras of T / n (n hull cells
//      on the ray: an even share); then options.tomographyIterations multiplicative updates (MART,
//      Gordon, Bender and Herman 1970): tau *= the geometric mean over the cameras of T / (the sum
//      along the ray), every cell at once. Cells left below 1e-5 are empty. No cell is dropped for
//      a low density otherwise: a coarse cell's depth is a mean over a large footprint.
//   3. Billboards (§2.1, §3.1, §4: 4x4 texels at every level, intermediate levels included): for
//      camera c, a square of the cell's edge through its centre, on camera c's image axes; each
//      texel samples the image over its footprint (a mean pyramid of premultiplied linear
//      colour, trilinear): colour = the image's, alpha = 1 - (1 - a)^s with a the texel's alpha
//      and s the cell's share of the optical depth along c's ray through its centre, so the
//      billboards along camera c's rays give its image back. Deviation: Reche-Martinez et al.'s
//      heuristic also weighs the colour by the cell's depth in the tree; this one keeps the
//      photograph's colour.
//   4. Pruning (§3.2): a billboard is pruned for camera c when the alpha the cells in front of it
//      accumulate along the ray from c to its centre (1 - exp(-their summed depths)) exceeds
//      options.pruneAlpha, or when all its texels are transparent. Applied recursively (§3.2): a
//      cell pruned for every camera is dropped, and its children are never made.
//   5. Vector quantisation (§4.1, VectorQuantiser.h): the modified GLA in CIELab, colour and alpha
//      apart, the black-pixel heuristic, trained on at most 200,000 of the kept billboards
//      (deviation: BillboardQuantisationOptions::maxTrainingVectors), every billboard then given
//      its nearest codewords; then the codebook atlas and optionally DXT5 (§5).
// Deterministic for the inputs and options, whatever the thread count.
#pragma once

#include "TreeLod/BakeTechniques.h"
#include "TreeLod/CaptureSet.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/VectorQuantiser.h"
#include "TreeLod/VolumeOctreeData.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    struct VolumeOctreeOptions
    {
        std::uint32_t levelCount = 7;   ///< [1, VOLUME_OCTREE_MAX_LEVELS]: finest 2^(levelCount-1) cells a side
        std::uint32_t tomographyIterations = 4; ///< MART updates of the opacities, 0 to 32
        bool prune = true;              ///< §3.2
        float pruneAlpha = 0.95f;       ///< accumulated alpha that hides a billboard, in (0, 1]
        BillboardQuantisationOptions quantisation; ///< §4.1: codebook sizes, space, modified GLA
        bool compress = true;           ///< DXT5 atlas (§5), else RGBA8
        std::size_t maxCells = 4'000'000; ///< cells of all levels: more is an error (memory bound)
    };

    /// Steps 1 to 4: the octree and its uncompressed billboards.
    struct VolumeOctreeReconstruction
    {
        VolumeOctreeData octree;               ///< levels, cameras and cells; no slots, codebooks, atlas
        std::vector<std::uint32_t> billboardOf; ///< per slot: index into billboards or UINT32_MAX
        std::vector<BillboardTexture> billboards;
        /// Per level: candidate cells (children of the level above), cells stored, cells dropped for
        /// having no billboard; over the slots of the cells that passed the hull (stored and
        /// dropped): slots, billboards kept, pruned because hidden, pruned because empty.
        struct LevelStats
        {
            std::uint64_t candidates = 0, cells = 0, dropped = 0, slots = 0, billboards = 0, hidden = 0, empty = 0;
        };
        std::vector<LevelStats> levels;
    };

    /// Steps 1 to 4. Errors name `label`: invalid options or capture set, every cell carved
    /// away, more than options.maxCells cells. Progress steps "volume octree: level L".
    Result<VolumeOctreeReconstruction> reconstructVolumeOctree(const CaptureSet& capture,
                                                               const VolumeOctreeOptions& options,
                                                               const std::string& label,
                                                               const ProgressCallback& progress = {});

    /// Step 5 over a reconstruction: the chunk's data (codebooks, slots, atlas).
    Result<VolumeOctreeData> compressVolumeOctree(const VolumeOctreeReconstruction& reconstruction,
                                                  const VolumeOctreeOptions& options, const std::string& label,
                                                  const ProgressCallback& progress = {});

    /// Every step.
    Result<VolumeOctreeData> bakeVolumeOctree(const CaptureSet& capture, const VolumeOctreeOptions& options,
                                              const std::string& label, const ProgressCallback& progress = {});

    /// Package glue for `treelod bake` (BakeTechniques): the reference chunk when missing, a capture
    /// set synthesised from `model`, and the volume-octree chunk.
    Result<void> addVolumeOctreeChunk(PackageWriter& writer, const TreeModel& model,
                                      const CaptureSynthesisOptions& capture, const VolumeOctreeOptions& options,
                                      const std::string& label, const ProgressCallback& progress = {});

    /// Package glue for `treelod bake CAPTURE_FOLDER`: the volume-octree chunk baked from `capture`,
    /// and a reference chunk holding no geometry (hasPolygons, ModelChunk.h), only a model named
    /// `name` whose bounds are the capture's volume box. Errors name `label`; an error when `writer`
    /// holds a reference already.
    Result<void> addVolumeOctreeChunk(PackageWriter& writer, const CaptureSet& capture, const std::string& name,
                                      const VolumeOctreeOptions& options, const std::string& label,
                                      const ProgressCallback& progress = {});

    /// The names of the volume-octree bake options that only a synthesised capture reads
    /// (cameras, resolution, samplesPerPixel): a capture folder's photographs fix them.
    const std::vector<std::string>& volumeOctreeSynthesisOptions();

    /// `--option volume-octree.NAME=VALUE` values (the names its BakeTechnique declares) into
    /// `options` and, when not null, `synthesis`; absent names keep their value. With `synthesis`
    /// null (a bake from photographs) a volumeOctreeSynthesisOptions() name is an error. Errors
    /// name `label` and "option 'volume-octree.NAME'".
    Result<void> parseVolumeOctreeBakeOptions(const BakeOptions& given,
                                              VolumeOctreeOptions& options, CaptureSynthesisOptions* synthesis,
                                              const std::string& label);

    // ---- the CPU twin of the renderer (VolumeOctreeRaster.cpp) -----------------------------

    /// What VolumeOctreeTree draws, on the CPU: for a camera, the pair of input cameras
    /// (volumeOctreeCameraPair, towards = from the root cube's centre to the camera), each cell's
    /// level by the distance planes (volumeOctreeDrawsCell), billboards facing the camera (the
    /// camera's right and up axes), texels bilinear within their block (sRGB colour and alpha
    /// apart, as the GPU filters the atlas; raw billboards get the black-pixel fill first), the
    /// two cameras' premultiplied texels weighted, blended back to front (the level above first,
    /// each level in volumeOctreeOctantOrder for the view's octant, as VolumeOctreeTree draws) with
    /// the over operator on sRGB values, as the GPU's framebuffer does, over
    /// `background` (sRGB, alpha 1) or over transparency. One sample per pixel centre.
    struct VolumeOctreeRenderOptions
    {
        int width = 256, height = 256;
        /// The finest level drawn ("active LOD", §3.1); -1 = chosen from the screen size
        /// (volumeOctreeActiveLevel).
        int activeLevel = -1;
        float lodPixels = 4.0f; ///< screen pixels a cell's edge may cover before its children draw
        glm::vec3 background{0.62f, 0.74f, 0.88f};
        bool transparentBackground = false;
    };
    /// Writes the billboard of (cell index, camera) to `out`; false when it is pruned.
    using VolumeBillboardSource = std::function<bool(std::size_t cell, std::uint32_t camera, BillboardTexture& out)>;
    Image renderVolumeOctree(const VolumeOctreeData& octree, const VolumeBillboardSource& billboards,
                             const CameraSpec& camera, const VolumeOctreeRenderOptions& options);
    /// The billboards of a compressed octree, decoded from its atlas (DXT5 decompressed); the
    /// source keeps what it needs.
    VolumeBillboardSource volumeOctreeAtlasSource(const VolumeOctreeData& data);
    /// The raw billboards of a reconstruction (the source refers to `reconstruction`).
    VolumeBillboardSource volumeOctreeRawSource(const VolumeOctreeReconstruction& reconstruction);
}
