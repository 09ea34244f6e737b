// Instance files: a placement's "file", CSV with one tree a line (docs/scene-format.md,
// "Instance files"). Private to TreeLodScript; the parser calls it for each "file" placement.
#pragma once

#include "TreeLod/Result.h"
#include "TreeLod/SceneScript.h"

#include <string>

namespace TreeLod::SceneScriptDetail
{
    /// An instance file's error, already naming the CSV file, line and column.
    struct InstanceFileError
    {
        Error error;
    };

    /// Reads the CSV at `path` into the placement's explicit trees (docs/scene-format.md,
    /// "Instance files"). Throws InstanceFileError naming the file, line and column.
    void readInstanceFile(const std::string& path, ScenePlacement& p, const SceneScript& script);
}
