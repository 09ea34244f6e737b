// Whole-or-nothing output files (docs/architecture.md, "Errors"): write to a temporary file
// beside the target, sync it to the disk, rename it over the target and sync the directory. A
// failure before the rename (a full disk: EFBIG, ENOSPC) leaves the target untouched and removes
// the temporary file; the error names the target and the OS's reason. Temporary names hold the
// process id and a per-process counter and are created exclusively, so two writers (processes or
// threads) never share one; a process killed while writing leaves its temporary file behind.
#pragma once

#include "TreeLod/Result.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    /// Write `bytes` to `path` atomically (temp file in the same directory + rename). An error
    /// after the rename ("written, but its directory cannot be synced") leaves the new file in
    /// place, not yet safe from a crash.
    Result<void> writeFileAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

    /// Let `writer` produce a file at a temporary path (e.g. an image library that only
    /// writes to paths; the file exists, empty, and the writer replaces it), then sync and rename
    /// it to `path`. If `writer` fails, the temp file is removed.
    Result<void> writeFileAtomicVia(const std::string& path,
                                    const std::function<Result<void>(const std::string& tempPath)>& writer);

    /// Read a whole file. Error names the file and the reason (missing, unreadable).
    Result<std::vector<std::uint8_t>> readFile(const std::string& path);

    /// TreeLod's folder of the user's cache: $XDG_CACHE_HOME/treelod when that is absolute, else
    /// $HOME/.cache/treelod, else <temp>/treelod-cache (the bake cache, cost calibrations).
    std::string userCacheDirectory();
}
