// TreeInput: one tree file loaded for a command: the model and, for the Ogre path, the
// package bytes the plugin loads (a .treelod as it is; other inputs baked in memory
// with the chunks asked for, the reference by default).
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    struct TreeInput
    {
        std::string name; ///< resource name: the file name
        TreeModel model;
        std::vector<std::uint8_t> packageBytes;
    };

    /// Reads an Ogre .mesh (needs a running Root, so the caller supplies it).
    using MeshImporter = std::function<Result<TreeModel>(const std::string& path)>;

    /// .glb / .gltf (glTF importer), .treelod (package reader), or .mesh through `meshImporter`
    /// (an error naming the file when it is empty). Non-package inputs are baked in memory
    /// with `chunks` (names of TreeLod/BakeTechniques.h); a package must already hold them.
    Result<TreeInput> loadTreeInput(const std::string& path, const std::vector<std::string>& leafMaterials,
                                    const ProgressCallback& progress, const MeshImporter& meshImporter = {},
                                    const std::vector<std::string>& chunks = {"reference"});
}
