// GltfExporter: write a TreeModel as a binary glTF 2.0 file (.glb).
//
// Layout (what the glTF importer reads back):
//   one scene; node "Bark" with mesh "Bark" (one primitive per bark material) and node
//   "Leaves" with mesh "Leaves" (one primitive per leaf material); a node is left out when
//   its part is empty. Vertices carry POSITION, NORMAL and TEXCOORD_0; indices are 16-bit
//   when every index of the mesh fits (< 65535), else 32-bit.
//   Materials: leaf materials alphaMode MASK with their alphaCutoff, doubleSided as in the
//   model; bark materials OPAQUE. baseColorFactor = Material::baseColour; the texture is an
//   embedded PNG (RGBA, or RGB when fully opaque), sampler repeat + trilinear.
//   Extras: leaf material {"treelodBackColour": [r, g, b]} (linear) when backColour != 0;
//   Bark mesh {"treelodSkeleton": {"positions": [x,y,z,...], "radii": [...],
//   "parents": [...]}} when the model has a skeleton (and bark).
// The model is validated first (TreeModel::validate); the file is written atomically.
#pragma once

#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    /// The .glb bytes of `model`. Error when the model is invalid or a PNG can't be encoded.
    Result<std::vector<std::uint8_t>> encodeGlb(const TreeModel& model);

    /// encodeGlb + writeFileAtomic: `path` is written whole or left untouched.
    Result<void> writeGlb(const TreeModel& model, const std::string& path);
}
