// BakeCache under failure and contention (BakeCache.h, "Failures" and "Concurrency"): a disk that
// fills while a package is written, and two processes baking one key at once. A child process is
// this test binary run again on BakeCacheChild.Run alone, which does nothing unless CHILD_ENV
// holds its request (JSON); it prints its result as one JSON line.
#include "TestOutput.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeCache.h"
#include "TreeLod/Crc32.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/GltfExporter.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/Package.h"
#include "TreeLod/TreeGenerator.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

using namespace TreeLod;
using nlohmann::json;

namespace
{
    using Strings = std::vector<std::string>;
    using Bytes = std::vector<std::uint8_t>;

    /// The child's request; BakeCacheChild.Run is skipped without it.
    constexpr const char* CHILD_ENV = "TREELOD_BAKECACHE_CHILD";
    /// Starts the line of a child's output that holds its result.
    constexpr const char* RESULT_PREFIX = "bakecache-child-result ";
    /// A child at its barrier writes one byte to READY_FD, then reads GO_FD until the parent
    /// closes the other end.
    constexpr int READY_FD = 3;
    constexpr int GO_FD = 4;

    /// A fresh (emptied) directory for one test.
    std::string testDir(const std::string& name) { return TreeLod::test::freshTestDir("bakecache-process", name); }

    /// dir/oak.glb, a tiny generated tree (100 leaves, 16-texel textures).
    std::string writeTinyGlb(const std::string& dir)
    {
        GeneratorOptions options;
        options.preset = TreePreset::Oak;
        options.seed = 1;
        options.leafCount = 100;
        options.textureSize = 16;
        Result<TreeModel> model = generateTree(options);
        EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
        const std::string path = dir + "/oak.glb";
        if (model)
        {
            Result<void> written = writeGlb(model.value(), path);
            EXPECT_TRUE(written.ok()) << (written.ok() ? "" : written.error().message());
        }
        return path;
    }

    Bytes fileBytes(const std::string& path)
    {
        Result<Bytes> bytes = readFile(path);
        return bytes ? bytes.value() : Bytes();
    }

    BakeCacheEntry requireOk(const BakeCache& cache, const std::string& source, const Strings& techniques)
    {
        Result<BakeCacheEntry> entry = cache.require(source, techniques, "{}");
        EXPECT_TRUE(entry.ok()) << (entry.ok() ? "" : entry.error().message());
        return entry ? entry.value() : BakeCacheEntry();
    }

    /// "" when the package at `path` opens, has a meta chunk and every chunk passes its checksum,
    /// else why not.
    std::string verifyPackage(const std::string& path)
    {
        Result<PackageReader> reader = PackageReader::open(path);
        if (!reader)
            return reader.error().message();
        if (reader->findChunk(META_CHUNK, 0) < 0)
            return path + ": no meta chunk";
        for (std::size_t i = 0; i < reader->chunks().size(); ++i)
            if (Result<Bytes> bytes = reader->readChunk(i); !bytes)
                return bytes.error().message();
        return "";
    }

    /// The names of the entries of `dir`, sorted: a temporary file left behind shows up here.
    Strings filesIn(const std::string& dir)
    {
        Strings names;
        std::error_code ec;
        for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
            names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    /// Size and CRC-32 of every file in `dir`, by name.
    json fileDigests(const std::string& dir)
    {
        json digests = json::object();
        for (const std::string& name : filesIn(dir))
        {
            const Bytes bytes = fileBytes(dir + "/" + name);
            digests[name] = std::to_string(bytes.size()) + " " + std::to_string(crc32(bytes.data(), bytes.size()));
        }
        return digests;
    }

    std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

    // ---- the child's side ------------------------------------------------------------------

    /// Says that this child is at its barrier, then waits until the parent lets every child go.
    void waitAtBarrier()
    {
        const char ready = 'r';
        while (write(READY_FD, &ready, 1) < 0 && errno == EINTR)
            ;
        char go;
        while (read(GO_FD, &go, 1) < 0 && errno == EINTR)
            ;
    }

    /// Mounts a tmpfs of `bytes` bytes on `dir` holding copies of the files `dir` held, in this
    /// process's own mount namespace (the parent starts it under unshare(1): a library this binary
    /// loads starts threads, and a threaded process cannot enter a user namespace). `parentMounts`
    /// is the parent's namespace: nothing is mounted there. "" when done, else why not.
    std::string mountSmallTmpfs(const std::string& dir, std::uint64_t bytes, const std::string& parentMounts)
    {
        std::error_code ec;
        if (std::filesystem::read_symlink("/proc/self/ns/mnt", ec).string() == parentMounts)
            return "not in a mount namespace of its own";
        std::map<std::string, Bytes> files;
        for (const std::string& name : filesIn(dir))
            files[name] = fileBytes(dir + "/" + name);
        if (mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
            return std::string("making the mounts private: ") + std::strerror(errno);
        const std::string options = "size=" + std::to_string(bytes);
        if (mount("tmpfs", dir.c_str(), "tmpfs", 0, options.c_str()) != 0)
            return std::string("mounting a tmpfs: ") + std::strerror(errno);
        for (const auto& [name, content] : files)
        {
            std::ofstream out(dir + "/" + name, std::ios::binary);
            out.write(reinterpret_cast<const char*>(content.data()), std::streamsize(content.size()));
            out.close();
            if (!out)
                return "cannot copy " + name + " onto the tmpfs";
        }
        return "";
    }

    /// What a require() in the child returned, and whether its package verifies.
    json requireInChild(const BakeCache& cache, const json& request, const ProgressCallback& progress)
    {
        Result<BakeCacheEntry> entry =
            cache.require(request["source"], request["techniques"].get<Strings>(), "{}", progress);
        if (!entry)
            return {{"ok", false},
                    {"file", entry.error().file},
                    {"element", entry.error().element},
                    {"reason", entry.error().reason}};
        return {{"ok", true},
                {"path", entry->path},
                {"built", entry->builtTechniques},
                {"reused", entry->reusedTechniques},
                {"discarded", entry->discardedReason},
                {"verify", verifyPackage(entry->path)}};
    }
}

// The child process of the tests below. Its request: "source", "cache", "techniques"; "barrier"
// ("start": before require(), "write": when require() starts writing the package); "fileLimit"
// (RLIMIT_FSIZE, so that a write past it fails with EFBIG); "tmpfsBytes" (the cache directory
// becomes a tmpfs that small, so that a write fails with ENOSPC; with "parentMounts") and
// "retryTmpfsBytes" (then grown to this and require() run again).
TEST(BakeCacheChild, Run)
{
    const char* text = std::getenv(CHILD_ENV);
    if (!text)
        GTEST_SKIP() << "runs only as the child process of the BakeCacheProcesses tests";
    const json request = json::parse(text);
    const std::string cacheDir = request["cache"];
    json result;
    if (request.contains("tmpfsBytes"))
    {
        const std::string why = mountSmallTmpfs(cacheDir, request["tmpfsBytes"], request["parentMounts"]);
        ASSERT_EQ(why, "");
    }
    result["before"] = fileDigests(cacheDir);
    if (request.contains("fileLimit"))
    {
        std::signal(SIGXFSZ, SIG_IGN); // a write past the limit fails with EFBIG instead
        rlimit limit{};
        ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &limit), 0);
        limit.rlim_cur = request["fileLimit"].get<rlim_t>();
        ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limit), 0) << std::strerror(errno);
    }

    const std::string barrier = request.value("barrier", "");
    const std::string writeStep = fileName(request["source"]) + ": write";
    bool reached = false;
    const ProgressCallback progress = [&](const std::string& step, float fraction) {
        if (barrier == "write" && !reached && step == writeStep && fraction == 0.0f)
        {
            reached = true;
            waitAtBarrier();
        }
    };
    if (barrier == "start")
        waitAtBarrier();
    const BakeCache cache(cacheDir);
    result["first"] = requireInChild(cache, request, progress);
    result["files"] = filesIn(cacheDir);
    result["after"] = fileDigests(cacheDir);
    json verified = json::object();
    for (const std::string& name : filesIn(cacheDir))
        verified[name] = verifyPackage(cacheDir + "/" + name);
    result["verified"] = verified;
    if (request.contains("retryTmpfsBytes"))
    {
        const std::string options = "size=" + std::to_string(request["retryTmpfsBytes"].get<std::uint64_t>());
        ASSERT_EQ(mount("tmpfs", cacheDir.c_str(), "tmpfs", MS_REMOUNT, options.c_str()), 0) << std::strerror(errno);
        result["retry"] = requireInChild(cache, request, {});
        result["retryFiles"] = filesIn(cacheDir);
    }
    std::cout << RESULT_PREFIX << result.dump() << std::endl;
}

namespace
{
    // ---- the parent's side -----------------------------------------------------------------

    /// A pipe, both ends closed on exec and numbered above READY_FD and GO_FD.
    struct Pipe
    {
        int read = -1;
        int write = -1;
    };

    Pipe makePipe()
    {
        int fds[2];
        if (pipe2(fds, O_CLOEXEC) != 0)
            return {};
        Pipe p{fcntl(fds[0], F_DUPFD_CLOEXEC, 10), fcntl(fds[1], F_DUPFD_CLOEXEC, 10)};
        close(fds[0]);
        close(fds[1]);
        return p;
    }

    void closeFd(int& fd)
    {
        if (fd >= 0)
            close(fd);
        fd = -1;
    }

    struct ChildRun
    {
        pid_t pid = -1;
        Pipe output;         ///< the child's stdout and stderr
        Pipe ready;          ///< one byte when the child is at its barrier; end of file when it exits
        int status = -1;     ///< from waitpid
        std::string printed; ///< everything the child wrote
        bool atBarrier = false;
        json result; ///< its result line, null if it printed none

        bool exitedCleanly() const { return WIFEXITED(status) && WEXITSTATUS(status) == 0 && !result.is_null(); }
    };

    /// Runs the child in a user and mount namespace of its own, where it may mount a tmpfs.
    const Strings UNSHARE = {"unshare", "--user", "--map-root-user", "--mount"};

    /// Starts `argv` (its program found on PATH) with this process's environment less gtest's
    /// settings (an output file, sharding) plus `extraEnv`; its stdout and stderr go to `output`,
    /// and each pair of `fds` is dup'ed to the second number in the child. The pid, or -1 and why
    /// in `error`.
    pid_t spawn(Strings argv, const std::string& extraEnv, int output, const std::vector<std::pair<int, int>>& fds,
                std::string& error)
    {
        Strings env;
        for (char** e = environ; *e; ++e)
        {
            const std::string entry = *e;
            if (entry.rfind("GTEST_", 0) != 0 && entry.rfind(std::string(CHILD_ENV) + "=", 0) != 0)
                env.push_back(entry);
        }
        if (!extraEnv.empty())
            env.push_back(extraEnv);
        std::vector<char*> argvp, envp;
        for (std::string& arg : argv)
            argvp.push_back(arg.data());
        argvp.push_back(nullptr);
        for (std::string& entry : env)
            envp.push_back(entry.data());
        envp.push_back(nullptr);

        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_adddup2(&actions, output, STDOUT_FILENO);
        posix_spawn_file_actions_adddup2(&actions, output, STDERR_FILENO);
        for (const auto& [from, to] : fds)
            posix_spawn_file_actions_adddup2(&actions, from, to);
        pid_t pid = -1;
        const int spawned = posix_spawnp(&pid, argvp[0], &actions, nullptr, argvp.data(), envp.data());
        posix_spawn_file_actions_destroy(&actions);
        if (spawned == 0)
            return pid;
        error = argv[0] + ": posix_spawn: " + std::strerror(spawned);
        return -1;
    }

    std::string readAll(int fd)
    {
        std::string text;
        char buffer[4096];
        ssize_t n;
        while ((n = read(fd, buffer, sizeof(buffer))) != 0)
            if (n > 0)
                text.append(buffer, std::size_t(n));
            else if (errno != EINTR)
                break;
        return text;
    }

    int waitFor(pid_t pid)
    {
        int status = -1;
        if (pid > 0)
            while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
                ;
        return status;
    }

    /// "" when unshare(1) can give a child the namespaces of UNSHARE, else what it said.
    std::string unshareUnavailable()
    {
        Strings argv = UNSHARE;
        argv.push_back("true");
        Pipe output = makePipe();
        std::string error;
        const pid_t pid = spawn(argv, "", output.write, {}, error);
        closeFd(output.write);
        const std::string printed = readAll(output.read);
        closeFd(output.read);
        const int status = waitFor(pid);
        if (pid < 0)
            return error;
        return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? "" : printed;
    }

    /// Runs BakeCacheChild.Run once per request, all at once. A child with a barrier waits there
    /// until every child has reached its own or exited, then all go on together.
    std::vector<ChildRun> runChildren(const std::vector<json>& requests)
    {
        std::error_code ec;
        const std::string exe = std::filesystem::read_symlink("/proc/self/exe", ec).string();
        std::vector<ChildRun> runs(requests.size());
        Pipe go = makePipe();
        for (std::size_t i = 0; i < requests.size(); ++i)
        {
            ChildRun& run = runs[i];
            run.output = makePipe();
            run.ready = makePipe();
            Strings argv = requests[i].contains("tmpfsBytes") ? UNSHARE : Strings();
            argv.push_back(exe);
            argv.push_back("--gtest_filter=BakeCacheChild.Run");
            run.pid = spawn(argv, std::string(CHILD_ENV) + "=" + requests[i].dump(), run.output.write,
                            {{run.ready.write, READY_FD}, {go.read, GO_FD}}, run.printed);
            closeFd(run.output.write);
            closeFd(run.ready.write);
        }
        closeFd(go.read);

        for (ChildRun& run : runs)
        {
            char byte;
            ssize_t n;
            while ((n = read(run.ready.read, &byte, 1)) < 0 && errno == EINTR)
                ;
            run.atBarrier = n == 1;
        }
        closeFd(go.write);

        for (ChildRun& run : runs)
        {
            run.printed += readAll(run.output.read);
            closeFd(run.output.read);
            closeFd(run.ready.read);
            run.status = waitFor(run.pid);
            const std::size_t line = run.printed.find(RESULT_PREFIX);
            if (line != std::string::npos)
            {
                const std::size_t start = line + std::strlen(RESULT_PREFIX);
                run.result = json::parse(run.printed.substr(start, run.printed.find('\n', start) - start), nullptr,
                                         false);
            }
        }
        return runs;
    }

    ChildRun runChild(const json& request) { return std::move(runChildren({request}).front()); }
}

// A disk that fills while the cache rewrites a package (RLIMIT_FSIZE in the child: write() fails
// with EFBIG part way): require() fails naming the cache file and the OS's reason, the package
// cached before is untouched and still verifies, no temporary file is left, and the next request
// rewrites the package reusing what was cached.
TEST(BakeCacheProcesses, DiskFullDuringRewriteKeepsTheCachedPackage)
{
    const std::string dir = testDir("file-limit");
    const std::string glb = writeTinyGlb(dir);
    const Strings both = {"reference", FOLIAGE_LOD_CHUNK};
    const BakeCache whole(dir + "/whole");
    const BakeCacheEntry complete = requireOk(whole, glb, both);
    const std::uint64_t size = std::filesystem::file_size(complete.path);
    const std::string cacheDir = dir + "/cache";
    const std::string efbig = std::strerror(EFBIG);

    // A first bake that cannot be written leaves nothing behind.
    {
        const ChildRun child = runChild({{"source", glb}, {"cache", cacheDir}, {"techniques", both}, {"fileLimit", 1}});
        ASSERT_TRUE(child.exitedCleanly()) << child.printed;
        const json& first = child.result["first"];
        EXPECT_FALSE(first["ok"].get<bool>()) << first.dump();
        EXPECT_EQ(first.value("file", ""), cacheDir + "/" + fileName(complete.path));
        EXPECT_NE(first.value("reason", "").find(efbig), std::string::npos) << first.dump();
        EXPECT_EQ(filesIn(cacheDir), Strings{});
    }

    for (const std::uint64_t limit : {std::uint64_t(1), size / 2, size - 1})
    {
        SCOPED_TRACE("file size limit " + std::to_string(limit) + " bytes, package " + std::to_string(size));
        std::filesystem::remove_all(cacheDir);
        const BakeCache cache(cacheDir);
        const BakeCacheEntry cached = requireOk(cache, glb, {"reference"});
        const Bytes before = fileBytes(cached.path);
        ASSERT_FALSE(before.empty());

        const ChildRun child =
            runChild({{"source", glb}, {"cache", cacheDir}, {"techniques", both}, {"fileLimit", limit}});
        ASSERT_TRUE(child.exitedCleanly()) << child.printed;
        const json& first = child.result["first"];
        EXPECT_FALSE(first["ok"].get<bool>()) << first.dump();
        EXPECT_EQ(first.value("file", ""), cached.path);
        EXPECT_NE(first.value("reason", "").find(efbig), std::string::npos) << first.dump();
        EXPECT_EQ(filesIn(cacheDir), Strings{fileName(cached.path)}) << "no temporary file is left";
        EXPECT_EQ(fileBytes(cached.path), before);
        EXPECT_EQ(verifyPackage(cached.path), "");

        const BakeCacheEntry next = requireOk(cache, glb, both);
        EXPECT_EQ(next.builtTechniques, Strings{FOLIAGE_LOD_CHUNK});
        EXPECT_EQ(next.reusedTechniques, Strings{"reference"});
        EXPECT_TRUE(next.discardedReason.empty()) << next.discardedReason;
        EXPECT_EQ(fileBytes(next.path), fileBytes(complete.path));
        EXPECT_EQ(filesIn(cacheDir), Strings{fileName(cached.path)});
    }
}

// The same with a real ENOSPC: the child puts the cache directory on a tmpfs with room for the
// cached package and half the new one (in namespaces of its own; skipped where unshare(1) cannot
// make them), then grows it and asks again.
TEST(BakeCacheProcesses, NoSpaceDuringRewriteKeepsTheCachedPackage)
{
    const std::string dir = testDir("no-space");
    const std::string glb = writeTinyGlb(dir);
    const Strings both = {"reference", FOLIAGE_LOD_CHUNK};
    const BakeCache whole(dir + "/whole");
    const BakeCacheEntry complete = requireOk(whole, glb, both);
    const std::uint64_t size = std::filesystem::file_size(complete.path);
    const std::string cacheDir = dir + "/cache";
    const BakeCache cache(cacheDir);
    const BakeCacheEntry cached = requireOk(cache, glb, {"reference"});
    const std::string name = fileName(cached.path);
    const Bytes before = fileBytes(cached.path);

    if (const std::string why = unshareUnavailable(); !why.empty())
        GTEST_SKIP() << "no namespaces of its own for the child: " << why;
    std::error_code ec;
    const std::string parentMounts = std::filesystem::read_symlink("/proc/self/ns/mnt", ec).string();
    const auto pages = [](std::uint64_t bytes) { return (bytes + 4095) / 4096 * 4096; };
    ASSERT_LT(pages(size / 2), pages(size)) << "the package fits in half its size";
    const ChildRun child = runChild({{"source", glb},
                                     {"cache", cacheDir},
                                     {"techniques", both},
                                     {"tmpfsBytes", pages(before.size()) + pages(size / 2)},
                                     {"retryTmpfsBytes", 4 * (pages(before.size()) + pages(size))},
                                     {"parentMounts", parentMounts}});
    ASSERT_TRUE(child.exitedCleanly()) << child.printed;

    const json& first = child.result["first"];
    EXPECT_FALSE(first["ok"].get<bool>()) << first.dump();
    EXPECT_EQ(first.value("file", ""), cached.path);
    EXPECT_NE(first.value("reason", "").find(std::strerror(ENOSPC)), std::string::npos) << first.dump();
    EXPECT_EQ(child.result["files"], json(Strings{name})) << "no temporary file is left";
    EXPECT_EQ(child.result["after"], child.result["before"]) << "the cached package is untouched";
    EXPECT_EQ(child.result["verified"][name], "");

    const json& retry = child.result["retry"];
    EXPECT_TRUE(retry["ok"].get<bool>()) << retry.dump();
    EXPECT_EQ(retry["built"], json(Strings{FOLIAGE_LOD_CHUNK}));
    EXPECT_EQ(retry["reused"], json(Strings{"reference"}));
    EXPECT_EQ(retry["discarded"], "");
    EXPECT_EQ(retry["verify"], "");
    EXPECT_EQ(child.result["retryFiles"], json(Strings{name}));

    // The tmpfs was the child's alone: the parent's cache never changed.
    EXPECT_EQ(fileBytes(cached.path), before);
}

namespace
{
    /// Checks one child of a concurrent bake: it ran, require() succeeded with a package that
    /// verifies at `path`, building `built` and reusing `reused`, nothing discarded.
    void expectBaked(const ChildRun& child, const std::string& path, const Strings& built, const Strings& reused)
    {
        ASSERT_TRUE(child.exitedCleanly()) << child.printed;
        const json& first = child.result["first"];
        ASSERT_TRUE(first["ok"].get<bool>()) << first.dump();
        EXPECT_EQ(first["path"], path);
        EXPECT_EQ(first["verify"], "") << "the package it returned verifies";
        EXPECT_EQ(first["built"], json(built));
        EXPECT_EQ(first["reused"], json(reused));
        EXPECT_EQ(first["discarded"], "") << "a package replaced while it was read is not taken for a damaged one";
    }

    /// "start": the children call require() together; "write": they write the package together.
    const char* barrierOfRound(int round) { return round % 2 ? "start" : "write"; }
}

// Two processes bake the same techniques of one source into one cache at once, over several
// rounds: both succeed with a package that verifies, and the cache ends with that package, byte
// for byte the package one process bakes, and no temporary file.
TEST(BakeCacheProcesses, TwoProcessesBakeTheSameTechniquesAtOnce)
{
    const std::string dir = testDir("same-techniques");
    const std::string glb = writeTinyGlb(dir);
    const Strings both = {"reference", FOLIAGE_LOD_CHUNK};
    const BakeCache alone(dir + "/alone");
    const Bytes expected = fileBytes(requireOk(alone, glb, both).path);
    ASSERT_FALSE(expected.empty());
    const std::string cacheDir = dir + "/cache";
    const BakeCache cache(cacheDir);
    Result<std::string> path = cache.packagePath(glb, "{}");
    ASSERT_TRUE(path.ok()) << path.error().message();

    for (int round = 0; round < 5; ++round)
    {
        const std::string barrier = barrierOfRound(round);
        SCOPED_TRACE("round " + std::to_string(round) + ", barrier at " + barrier);
        std::filesystem::remove_all(cacheDir);
        const json request = {{"source", glb}, {"cache", cacheDir}, {"techniques", both}, {"barrier", barrier}};
        const std::vector<ChildRun> children = runChildren({request, request});
        for (const ChildRun& child : children)
        {
            EXPECT_TRUE(child.atBarrier) << child.printed;
            if (barrier == "write") // both had looked at the cache before either wrote
                expectBaked(child, path.value(), both, {});
            else // one may find the package the other wrote
            {
                ASSERT_TRUE(child.exitedCleanly()) << child.printed;
                const json& first = child.result["first"];
                ASSERT_TRUE(first["ok"].get<bool>()) << first.dump();
                EXPECT_EQ(first["verify"], "") << first.dump();
                EXPECT_EQ(first["discarded"], "") << first.dump();
                EXPECT_TRUE(first["built"] == json(both) || first["reused"] == json(both)) << first.dump();
            }
        }
        EXPECT_EQ(filesIn(cacheDir), Strings{fileName(path.value())}) << "no temporary file is left";
        EXPECT_EQ(verifyPackage(path.value()), "");
        EXPECT_EQ(fileBytes(path.value()), expected);
        const BakeCacheEntry after = requireOk(cache, glb, both);
        EXPECT_EQ(after.reusedTechniques, both);
        EXPECT_TRUE(after.discardedReason.empty()) << after.discardedReason;
    }
}

// Two processes add different techniques to one cached package at once: both succeed with a
// package that verifies; the cache ends with one of the packages they could have written (the
// last rename wins, the other technique may be lost) and no temporary file; the next request
// bakes only what was lost.
TEST(BakeCacheProcesses, TwoProcessesAddDifferentTechniquesAtOnce)
{
    const std::string dir = testDir("different-techniques");
    const std::string glb = writeTinyGlb(dir);
    const Strings withLodf = {"reference", FOLIAGE_LOD_CHUNK};
    const Strings withImpostor = {"reference", IMPOSTOR_CHUNK};
    const Strings all = {"reference", FOLIAGE_LOD_CHUNK, IMPOSTOR_CHUNK};
    // What either child, or one after the other, can leave (an incremental bake gives the bytes
    // of a bake in one request).
    const Bytes seed = fileBytes(requireOk(BakeCache(dir + "/seed"), glb, {"reference"}).path);
    const Bytes lodfPackage = fileBytes(requireOk(BakeCache(dir + "/lodf"), glb, withLodf).path);
    const Bytes impostorPackage = fileBytes(requireOk(BakeCache(dir + "/impostor"), glb, withImpostor).path);
    const Bytes allPackage = fileBytes(requireOk(BakeCache(dir + "/all"), glb, all).path);
    ASSERT_FALSE(seed.empty() || lodfPackage.empty() || impostorPackage.empty() || allPackage.empty());
    const std::string cacheDir = dir + "/cache";
    const BakeCache cache(cacheDir);
    Result<std::string> path = cache.packagePath(glb, "{}");
    ASSERT_TRUE(path.ok()) << path.error().message();

    for (int round = 0; round < 5; ++round)
    {
        const std::string barrier = barrierOfRound(round);
        SCOPED_TRACE("round " + std::to_string(round) + ", barrier at " + barrier);
        std::filesystem::remove_all(cacheDir);
        std::filesystem::create_directories(cacheDir);
        ASSERT_TRUE(writeFileAtomic(path.value(), seed).ok());
        const std::vector<ChildRun> children = runChildren(
            {{{"source", glb}, {"cache", cacheDir}, {"techniques", withLodf}, {"barrier", barrier}},
             {{"source", glb}, {"cache", cacheDir}, {"techniques", withImpostor}, {"barrier", barrier}}});
        EXPECT_TRUE(children[0].atBarrier && children[1].atBarrier) << children[0].printed << children[1].printed;
        expectBaked(children[0], path.value(), {FOLIAGE_LOD_CHUNK}, {"reference"});
        expectBaked(children[1], path.value(), {IMPOSTOR_CHUNK}, {"reference"});

        EXPECT_EQ(filesIn(cacheDir), Strings{fileName(path.value())}) << "no temporary file is left";
        EXPECT_EQ(verifyPackage(path.value()), "");
        const Bytes final = fileBytes(path.value());
        const bool lodfWon = final == lodfPackage;
        const bool impostorWon = final == impostorPackage;
        // Written together, each had read the seed; one after the other, the second adds to the first.
        EXPECT_TRUE(lodfWon || impostorWon || (barrier == "start" && final == allPackage))
            << "the cache holds a package neither child wrote (" << final.size() << " bytes)";

        const BakeCacheEntry after = requireOk(cache, glb, all);
        EXPECT_TRUE(after.discardedReason.empty()) << after.discardedReason;
        EXPECT_EQ(after.builtTechniques, lodfWon ? Strings{IMPOSTOR_CHUNK}
                                         : impostorWon ? Strings{FOLIAGE_LOD_CHUNK}
                                                       : Strings{});
        EXPECT_EQ(fileBytes(path.value()), allPackage);
    }
}

// A cache hit while other bakes replace the package (a thread renaming two valid packages of the
// key over it, over and over): every request finds the chunk it asks for, and none takes a
// package replaced while it was read for a damaged one.
TEST(BakeCacheProcesses, HitsWhilePackagesAreReplacedAreNotDiscarded)
{
    const std::string dir = testDir("replaced");
    const std::string glb = writeTinyGlb(dir);
    const std::string lodfPackage = requireOk(BakeCache(dir + "/lodf"), glb, {"reference", FOLIAGE_LOD_CHUNK}).path;
    const std::string impostorPackage =
        requireOk(BakeCache(dir + "/impostor"), glb, {"reference", IMPOSTOR_CHUNK}).path;
    ASSERT_EQ(verifyPackage(lodfPackage), "");
    ASSERT_EQ(verifyPackage(impostorPackage), "");
    const std::string cacheDir = dir + "/cache";
    std::filesystem::create_directories(cacheDir);
    const BakeCache cache(cacheDir);
    Result<std::string> path = cache.packagePath(glb, "{}");
    ASSERT_TRUE(path.ok()) << path.error().message();
    std::filesystem::copy_file(lodfPackage, path.value());

    // A hard link renamed into place: a replacement as a bake makes it, many times faster.
    std::atomic<bool> done{false};
    std::atomic<int> writeErrors{0};
    std::thread writer([&] {
        const std::string linkPath = dir + "/link";
        for (int i = 0; !done; ++i)
            if (::link(i % 2 ? lodfPackage.c_str() : impostorPackage.c_str(), linkPath.c_str()) != 0 ||
                ::rename(linkPath.c_str(), path->c_str()) != 0)
                ++writeErrors;
    });
    const int requests = 500;
    Strings failures;
    for (int i = 0; i < requests; ++i)
    {
        Result<BakeCacheEntry> entry = cache.require(glb, {"reference"}, "{}");
        if (!entry)
            failures.push_back(entry.error().message());
        else if (!entry->builtTechniques.empty() || !entry->discardedReason.empty())
            failures.push_back(entry->describe());
    }
    done = true;
    writer.join();
    EXPECT_EQ(writeErrors.load(), 0);
    EXPECT_TRUE(failures.empty()) << failures.size() << " of " << requests << " requests, first: " << failures[0];
    EXPECT_EQ(filesIn(cacheDir), Strings{fileName(path.value())});
}

// Threads of one process writing one path at once each use a temporary file of their own: all
// succeed, and the file ends whole, as one of them wrote it.
TEST(BakeCacheProcesses, WritersOfOnePathNeverShareATemporaryFile)
{
    const std::string dir = testDir("writers");
    const std::string path = dir + "/file.bin";
    std::vector<Bytes> contents;
    for (int t = 0; t < 8; ++t)
        contents.push_back(Bytes(std::size_t(100000 + 1000 * t), std::uint8_t(t + 1)));
    std::atomic<int> errors{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&, t] {
            for (int i = 0; i < 20; ++i)
                if (Result<void> written = writeFileAtomic(path, contents[std::size_t(t)]); !written)
                {
                    ++errors;
                    std::cerr << written.error().message() << "\n";
                }
        });
    for (std::thread& t : threads)
        t.join();
    EXPECT_EQ(errors.load(), 0);
    EXPECT_NE(std::find(contents.begin(), contents.end(), fileBytes(path)), contents.end());
    EXPECT_EQ(filesIn(dir), Strings{"file.bin"});
}
