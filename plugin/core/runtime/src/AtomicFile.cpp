#include "TreeLod/AtomicFile.h"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        std::string osError(const std::string& what, int error) { return what + ": " + std::strerror(error); }

        /// Creates a new, empty temporary file beside `path` and returns its name: the process id
        /// and a per-process counter make it unique between processes and threads, and O_EXCL
        /// makes sure (a name left by a dead process with the same id is skipped).
        Result<std::string> createTempFile(const std::string& path)
        {
            static std::atomic<unsigned long long> counter{0};
            const std::filesystem::path p(path);
            for (int attempt = 0; attempt < 100; ++attempt)
            {
                char suffix[48];
                std::snprintf(suffix, sizeof(suffix), ".tmp%ld-%llu", long(getpid()), counter++);
                // Keep the extension last: image writers pick the format from it.
                const std::string temp =
                    (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
                const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
                if (fd >= 0)
                {
                    ::close(fd);
                    return temp;
                }
                if (errno != EEXIST)
                    return fail(path, "", osError("cannot create a temporary file beside it", errno));
            }
            return fail(path, "", "cannot create a temporary file beside it: every name tried exists");
        }

        /// Flushes the file at `temp` to the disk (its data and size).
        Result<void> syncFile(const std::string& path, const std::string& temp)
        {
            const int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
            if (fd < 0)
                return fail(path, "", osError("cannot reopen the temporary file to sync it", errno));
            const bool synced = ::fsync(fd) == 0;
            const int error = errno;
            ::close(fd);
            if (!synced)
                return fail(path, "", osError("cannot sync to the disk", error));
            return {};
        }

        /// Flushes the directory `dir`, so that a rename in it survives a crash. File systems that
        /// cannot sync a directory (EINVAL) are taken at their word.
        Result<void> syncDirectory(const std::string& path, const std::filesystem::path& dir)
        {
            const std::string name = dir.empty() ? "." : dir.string();
            const int fd = ::open(name.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            if (fd < 0)
                return fail(path, "", osError("written, but its directory cannot be opened to sync it", errno));
            const bool synced = ::fsync(fd) == 0 || errno == EINVAL;
            const int error = errno;
            ::close(fd);
            if (!synced)
                return fail(path, "", osError("written, but its directory cannot be synced", error));
            return {};
        }
    }

    Result<void> writeFileAtomicVia(const std::string& path,
                                    const std::function<Result<void>(const std::string& tempPath)>& writer)
    {
        const std::filesystem::path parent = std::filesystem::path(path).parent_path();
        std::error_code ec;
        if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
            return fail(path, "", "directory '" + parent.string() + "' does not exist");
        Result<std::string> temp = createTempFile(path);
        if (!temp)
            return temp.error();
        Result<void> r = writer(temp.value());
        if (r)
            r = syncFile(path, temp.value());
        if (r && ::rename(temp->c_str(), path.c_str()) != 0)
            r = fail(path, "", osError("cannot rename the temporary file into place", errno));
        if (!r)
        {
            std::filesystem::remove(temp.value(), ec);
            return r;
        }
        return syncDirectory(path, parent);
    }

    Result<void> writeFileAtomic(const std::string& path, const std::vector<std::uint8_t>& bytes)
    {
        return writeFileAtomicVia(path, [&](const std::string& temp) -> Result<void> {
            const int fd = ::open(temp.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
            if (fd < 0)
                return fail(path, "", osError("cannot open for writing", errno));
            // write() may write less than asked (a file size limit, a signal): go on from there.
            std::size_t done = 0;
            while (done < bytes.size())
            {
                const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
                if (n < 0 && errno == EINTR)
                    continue;
                if (n <= 0)
                {
                    const int error = n < 0 ? errno : EIO;
                    ::close(fd);
                    return fail(path, "", osError("cannot write " + std::to_string(bytes.size()) + " bytes", error));
                }
                done += std::size_t(n);
            }
            // Some file systems (NFS) report a failed write only here.
            if (::close(fd) != 0)
                return fail(path, "", osError("cannot write " + std::to_string(bytes.size()) + " bytes", errno));
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

    std::string userCacheDirectory()
    {
        const char* xdg = std::getenv("XDG_CACHE_HOME");
        if (xdg && std::filesystem::path(xdg).is_absolute())
            return (std::filesystem::path(xdg) / "treelod").string();
        const char* home = std::getenv("HOME");
        if (home && *home)
            return (std::filesystem::path(home) / ".cache" / "treelod").string();
        std::error_code ec;
        const std::filesystem::path temp = std::filesystem::temp_directory_path(ec);
        return ((ec ? std::filesystem::path("/tmp") : temp) / "treelod-cache").string();
    }
}
