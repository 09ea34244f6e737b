// TreeInput: one tree file loaded for a command: the model and, for the Ogre path, the
// package bytes the plugin loads (a .treelod as it is; other inputs baked in memory
// with the reference chunk only).
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
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

    /// .glb / .gltf (glTF importer) or .treelod (package reader). .mesh files need Ogre and
    /// are read by the Ogre .mesh importer when the build has the plugin.
    Result<TreeInput> loadTreeInput(const std::string& path, const std::vector<std::string>& leafMaterials,
                                    const ProgressCallback& progress);
}
