// GltfImporter: glTF 2.0 (.gltf with external or embedded data, .glb) -> TreeModel.
//
// What is read:
// - The default scene (or scene 0, or every root node if the file has no scene), its node
//   hierarchy with matrix or TRS transforms applied to positions and normals (normal matrix).
//   A mesh instanced by several nodes gives several copies.
// - Primitives in mode TRIANGLES; TRIANGLE_STRIP and TRIANGLE_FAN are converted to triangles;
//   POINTS and LINE* primitives are skipped with a warning. Indexed (8/16/32-bit) or not;
//   any byteStride/byteOffset; UVs may be normalized 8/16-bit ints. Missing normals are
//   computed (area-weighted, smooth over shared indices); missing UVs are (0, 0).
// - Materials: name, baseColorFactor, baseColorTexture (its image decoded to RGBA8 once per
//   glTF image), alphaMode, alphaCutoff, doubleSided, and the back colour of leaves from the
//   material's extras {"treelodBackColour": [r, g, b]} (linear).
// - Images: .glb bufferViews, data URIs, and files relative to the .gltf; PNG (palette + tRNS
//   alpha kept) and JPEG, decoded with libpng and libjpeg-turbo. A missing external image that a material
//   uses is an Error naming the image and the path.
// - The bark skeleton from a mesh's extras {"treelodSkeleton": {"positions": [x,y,z,...],
//   "radii": [...], "parents": [...]}} (parents before children; -1 = root), transformed by
//   the node that instances the mesh. Several instances append with offset parents.
//
// Leaves (TreeModel header): triangles whose material is a leaf material. A leaf is one
// connected component of leaf triangles, two triangles being connected when they share a
// vertex index or a vertex position (bitwise-equal floats after the node transform; -0 = +0),
// so single quads, multi-triangle leaves and crossed quads whose halves share their middle
// edge's positions are one leaf each; quads that only intersect are two. Leaves are ordered
// by their first triangle in file order (scene traversal, depth first, children in order;
// then primitive; then triangle). Triangles that repeat a vertex index are dropped (they
// have no area and would only glue neighbours). Every other triangle is bark.
// - Zero-area leaves (area <= 1e-6 x the square of their bounding box's longest side: a
//   point or a line, up to float rounding) are dropped and counted.
// - A leaf written twice (an index-connected piece whose corner positions repeat an earlier
//   piece exactly) stays a leaf of its own, not welded to the original, and is counted.
//
// Not supported (an Error names the element): sparse accessors, accessors without a
// bufferView, required extensions other than KHR_mesh_quantization, images that are not
// PNG or JPEG or larger than 16384 per side / 64 Mpixel, JSON nested deeper than 128.
// Ignored: skins, morph targets, cameras, lights, KHR_texture_transform, samplers.
//
// Hostile input: counts and sizes are checked before anything is allocated for them. An
// accessor's count must fit its buffer view and the view its buffer (10 million claimed
// vertices over a few bytes are refused at the accessor); an image's size is read from its
// PNG IHDR or JPEG start-of-frame header and checked against the limit above before a decoder
// sees it, so what an image costs is bounded by the limit, whatever its header claims.
//
// Errors name the file, the element ("mesh 1 'Leaves' primitive 0 accessor 3 (indices)",
// "image 2 'bark'", "node 4", "glb header") and the reason. Nothing is partially returned.
// Bad geometry is an Error (index out of range, NaN/Inf position, accessor overrunning its
// buffer view), as is a file without any triangle; a bare trunk or leaves without bark are
// valid trees. A model more than 1 km across imports with a warning (units are metres).
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    struct ImportOptions
    {
        /// User rule (`--leaf-material NAME`, repeatable): materials with these exact names
        /// are leaves and all others bark. If empty, leaves are materials with alphaMode MASK
        /// or BLEND.
        std::vector<std::string> leafMaterials;
        /// Called with steps "read", "meshes", "leaves", "images"; may be empty.
        ProgressCallback progress;
    };

    /// What the importer fixed or noticed without failing.
    struct ImportReport
    {
        std::size_t droppedDegenerateLeaves = 0; ///< leaves of zero area, not in the model
        std::size_t duplicateLeaves = 0;         ///< leaves equal to an earlier one (kept)
        std::size_t skippedPrimitives = 0;       ///< POINTS / LINES primitives
        std::vector<std::string> warnings;       ///< one sentence each, e.g. size > 1 km
    };

    /// Import a .gltf or .glb file (chosen by content, not by extension). The model is named
    /// after the file stem, has its bounds updated and passes TreeModel::validate().
    Result<TreeModel> importGltf(const std::string& path, const ImportOptions& options = {},
                                 ImportReport* report = nullptr);

    /// Import from memory: .glb bytes or .gltf JSON text. `label` names the data in errors and
    /// gives the model its name (stem). External files (buffers, images) are looked up in
    /// `baseDir`; if `baseDir` is empty, no file is read and external references are errors.
    Result<TreeModel> importGltfFromMemory(const std::uint8_t* data, std::size_t size,
                                           const std::string& label, const std::string& baseDir,
                                           const ImportOptions& options = {},
                                           ImportReport* report = nullptr);
}
