#include "TreeLod/AtomicFile.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        std::string tempPathFor(const std::string& path)
        {
            static thread_local std::mt19937_64 rng{std::random_device{}()};
            char suffix[32];
            std::snprintf(suffix, sizeof(suffix), ".tmp%d.%08llx", int(getpid()),
                          (unsigned long long)(rng() & 0xffffffffull));
            std::filesystem::path p(path);
            // Keep the extension last: image writers pick the format from it.
            return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
        }
    }

    Result<void> writeFileAtomicVia(const std::string& path,
                                    const std::function<Result<void>(const std::string& tempPath)>& writer)
    {
        std::filesystem::path parent = std::filesystem::path(path).parent_path();
        std::error_code ec;
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
            return fail(path, "", "directory '" + parent.string() + "' does not exist");
        const std::string temp = tempPathFor(path);
        Result<void> r = writer(temp);
        if (!r)
        {
            std::filesystem::remove(temp, ec);
            return r;
        }
        std::filesystem::rename(temp, path, ec);
        if (ec)
        {
            std::filesystem::remove(temp, ec);
            return fail(path, "", "cannot rename temporary file into place: " + ec.message());
        }
        return {};
    }

    Result<void> writeFileAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes)
    {
        return writeFileAtomicVia(path, [&](const std::string& temp) -> Result<void> {
            std::ofstream out(temp, std::ios::binary | std::ios::trunc);
            if (!out)
                return fail(path, "", std::string("cannot open for writing: ") + std::strerror(errno));
            out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            out.flush();
            if (!out)
                return fail(path, "", "write failed (disk full?)");
            return {};
        });
    }

    Result<std::vector<std::uint8_t>> readFile(const std::string& path)
    {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec))
            return fail(path, "", "file does not exist");
        if (std::filesystem::is_directory(path, ec))
            return fail(path, "", "is a directory, not a file");
        std::ifstream in(path, std::ios::binary);
        if (!in)
            return fail(path, "", std::string("cannot open: ") + std::strerror(errno));
        std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (in.bad())
            return fail(path, "", "read error");
        return bytes;
    }
}
