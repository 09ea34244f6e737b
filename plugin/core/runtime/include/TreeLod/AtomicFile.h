// Whole-or-nothing output files (docs/architecture.md, "Errors"): write to a temporary file
// beside the target, then rename over it. A failure leaves the target untouched.
#pragma once

#include "TreeLod/Result.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    /// Write `bytes` to `path` atomically (temp file in the same directory + rename).
    Result<void> writeFileAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

    /// Let `writer` produce a file at a temporary path (e.g. an image library that only
    /// writes to paths), then rename it to `path`. If `writer` fails, the temp file is removed.
    Result<void> writeFileAtomicVia(const std::string& path,
                                    const std::function<Result<void>(const std::string& tempPath)>& writer);

    /// Read a whole file. Error names the file and the reason (missing, unreadable).
    Result<std::vector<std::uint8_t>> readFile(const std::string& path);
}
