// Test output folders: under $TREELOD_TEST_OUT (ctest sets it), else <build>/test-out.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace TreeLod::test
{
    /// <test-out>/<group>/<name>, emptied and created.
    inline std::string freshTestDir(const std::string& group, const std::string& name)
    {
        const char* out = std::getenv("TREELOD_TEST_OUT");
        const std::filesystem::path dir =
            std::filesystem::path(out && *out ? out : TREELOD_BINARY_DIR "/test-out") / group / name;
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
        std::filesystem::create_directories(dir, ec);
        return dir.string();
    }
}
