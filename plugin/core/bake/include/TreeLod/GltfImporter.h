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
//   alpha kept) and JPEG.
// - The bark skeleton from a mesh's extras {"treelodSkeleton": {"positions": [x,y,z,...],
//   "radii": [...], "parents": [...]}} (parents before children; -1 = root), transformed by
//   the node that instances the mesh. Several instances append with offset parents.
//
// Leaves (TreeModel header): triangles whose material is a leaf material. A leaf is one
// connected component of leaf triangles, two triangles being connected when they share a
// vertex index or a vertex position (after the node transform, welded when equal within
// 1e-6 of the model's size, so crossed quads that share their middle edge are one leaf).
// Leaves are ordered by their first triangle in file order (scene traversal order, then
// primitive, then triangle). Every other triangle is bark.
//
// Errors name the file, the element ("mesh 1 'Leaves' primitive 0 accessor 3", "image 2
// 'bark.png'", "node 4", "glb header") and the reason. Nothing is partially returned.
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
