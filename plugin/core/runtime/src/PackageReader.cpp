#include "TreeLod/Package.h"

#include "TreeLod/ByteReader.h"
#include "TreeLod/Crc32.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <tuple>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        std::string hex32(std::uint32_t v)
        {
            char buf[16];
            std::snprintf(buf, sizeof(buf), "0x%08x", v);
            return buf;
        }

        std::string truncated(std::uint64_t needs, std::uint64_t offset, std::uint64_t fileSize)
        {
            return "truncated: needs " + std::to_string(needs) + " bytes at offset " + std::to_string(offset) +
                   ", file has " + std::to_string(fileSize);
        }

        std::string checksumMismatch(std::uint32_t stored, std::uint32_t computed)
        {
            return "checksum mismatch (stored " + hex32(stored) + ", computed " + hex32(computed) + ")";
        }

        /// "54 52 4c 44" and, when printable, the characters.
        std::string describeMagic(const std::uint8_t* p, std::size_t n)
        {
            std::string hex, text;
            bool printable = true;
            for (std::size_t i = 0; i < n; ++i)
            {
                char buf[4];
                std::snprintf(buf, sizeof(buf), "%s%02x", i ? " " : "", p[i]);
                hex += buf;
                printable = printable && p[i] >= 0x20 && p[i] < 0x7f;
                text += char(p[i]);
            }
            return printable ? hex + " \"" + text + "\"" : hex;
        }

        /// Read `size` bytes at `offset` of the open file `fd`; error if fewer are there.
        Result<std::vector<std::uint8_t>> readFileRange(const std::string& path, int fd, std::uint64_t offset,
                                                        std::uint64_t size, const std::string& element)
        {
            struct stat status;
            if (::fstat(fd, &status) != 0)
                return fail(path, element, std::string("cannot read the file size: ") + std::strerror(errno));
            const std::uint64_t fileSize = std::uint64_t(status.st_size);
            if (offset > fileSize || size > fileSize - offset)
                return fail(path, element, truncated(size, offset, fileSize) + " (file changed since it was opened?)");
            std::vector<std::uint8_t> bytes(size);
            std::uint64_t done = 0;
            while (done < size)
            {
                const ssize_t n = ::pread(fd, bytes.data() + done, size - done, off_t(offset + done));
                if (n < 0 && errno == EINTR)
                    continue;
                if (n < 0)
                    return fail(path, element, "read error at offset " + std::to_string(offset + done) + ": " +
                                                   std::strerror(errno));
                if (n == 0)
                    return fail(path, element, truncated(size, offset, offset + done) +
                                                   " (file changed since it was opened?)");
                done += std::uint64_t(n);
            }
            return bytes;
        }
    }

    struct PackageReader::OpenFile
    {
        int fd = -1;
        ~OpenFile()
        {
            if (fd >= 0)
                ::close(fd);
        }
    };

    std::string chunkElement(const std::string& technique, std::uint32_t level)
    {
        return "chunk '" + technique + "' level " + std::to_string(level);
    }

    std::string ChunkInfo::element() const { return chunkElement(technique, level); }

    Result<PackageReader> PackageReader::open(const std::string& path)
    {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec))
            return fail(path, "", "file does not exist");
        if (std::filesystem::is_directory(path, ec))
            return fail(path, "", "is a directory, not a file");
        auto file = std::make_shared<OpenFile>();
        file->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (file->fd < 0)
            return fail(path, "", std::string("cannot open: ") + std::strerror(errno));
        struct stat status;
        if (::fstat(file->fd, &status) != 0)
            return fail(path, "", std::string("cannot determine the file size: ") + std::strerror(errno));

        PackageReader reader;
        reader.mLabel = path;
        reader.mFile = file;
        reader.mFileSize = std::uint64_t(status.st_size);
        Result<void> r = reader.parse([&](std::uint64_t offset, std::uint64_t size, const std::string& element) {
            return readFileRange(path, file->fd, offset, size, element);
        });
        if (!r)
            return r.error();
        return reader;
    }

    Result<PackageReader> PackageReader::fromMemory(std::vector<std::uint8_t> bytes, const std::string& label)
    {
        PackageReader reader;
        reader.mLabel = label;
        reader.mFileSize = bytes.size();
        auto shared = std::make_shared<const std::vector<std::uint8_t>>(std::move(bytes));
        reader.mBytes = shared;
        Result<void> r = reader.parse([&](std::uint64_t offset, std::uint64_t size, const std::string&) {
            // parse() checked the range against mFileSize already.
            return std::vector<std::uint8_t>(shared->begin() + std::ptrdiff_t(offset),
                                             shared->begin() + std::ptrdiff_t(offset + size));
        });
        if (!r)
            return r.error();
        return reader;
    }

    Result<void> PackageReader::parse(const RangeReader& readRange)
    {
        const std::string& file = mLabel;
        const std::uint64_t fileSize = mFileSize;
        if (fileSize == 0)
            return fail(file, "", "empty file, not a TreeLod package");

        // ---- header ----
        Result<std::vector<std::uint8_t>> head = readRange(0, std::min<std::uint64_t>(fileSize, PACKAGE_HEADER_SIZE), "header");
        if (!head)
            return head.error();
        const std::vector<std::uint8_t>& h = head.value();
        if (h.size() < 4 || std::memcmp(h.data(), PACKAGE_MAGIC, 4) != 0)
            return fail(file, "header",
                        "not a TreeLod package (magic " + describeMagic(h.data(), std::min<std::size_t>(h.size(), 4)) +
                            ", expected 54 52 4c 44 \"TRLD\")");
        if (fileSize < PACKAGE_HEADER_SIZE)
            return fail(file, "header", truncated(PACKAGE_HEADER_SIZE, 0, fileSize));

        ByteReader in(h.data(), h.size(), file, "header", "file");
        in.take(4);
        mVersion = in.u32();
        const std::uint32_t chunkCount = in.u32();
        in.u32(); // flags: none defined in version 1, ignored
        const std::uint64_t tableOffset = in.u64();
        const std::uint32_t tableCrc = in.u32();
        const std::uint32_t headerCrc = in.u32();
        if (mVersion != PACKAGE_VERSION)
            return fail(file, "header",
                        "unsupported version " + std::to_string(mVersion) + ", this build reads " +
                            std::to_string(PACKAGE_VERSION));
        const std::uint32_t headerComputed = crc32(h.data(), 28);
        if (headerComputed != headerCrc)
            return fail(file, "header", checksumMismatch(headerCrc, headerComputed));

        // ---- chunk table ----
        if (tableOffset < PACKAGE_HEADER_SIZE)
            return fail(file, "chunk table", "offset " + std::to_string(tableOffset) + " overlaps the header");
        if (tableOffset > fileSize || chunkCount > (fileSize - tableOffset) / PACKAGE_TABLE_ENTRY_SIZE)
            return fail(file, "chunk table",
                        truncated(std::uint64_t(chunkCount) * PACKAGE_TABLE_ENTRY_SIZE, tableOffset, fileSize));
        const std::uint64_t tableSize = std::uint64_t(chunkCount) * PACKAGE_TABLE_ENTRY_SIZE;
        const std::uint64_t tableEnd = tableOffset + tableSize;
        Result<std::vector<std::uint8_t>> table = readRange(tableOffset, tableSize, "chunk table");
        if (!table)
            return table.error();
        const std::vector<std::uint8_t>& t = table.value();
        const std::uint32_t tableComputed = crc32(t.data(), t.size());
        if (tableComputed != tableCrc)
            return fail(file, "chunk table", checksumMismatch(tableCrc, tableComputed));

        mChunks.clear();
        mChunks.reserve(chunkCount);
        ByteReader entries(t.data(), t.size(), file, "chunk table", "file");
        for (std::uint32_t i = 0; i < chunkCount; ++i)
        {
            const std::string element = "chunk table entry " + std::to_string(i);
            const std::uint8_t* name = entries.take(PACKAGE_MAX_TECHNIQUE_NAME);
            ChunkInfo c;
            c.level = entries.u32();
            c.formatVersion = entries.u32();
            c.offset = entries.u64();
            c.size = entries.u64();
            c.crc32 = entries.u32();
            entries.u32(); // reserved
            if (!entries.ok())
                return entries.error(); // cannot happen: the table size was checked

            std::size_t length = 0;
            while (length < PACKAGE_MAX_TECHNIQUE_NAME && name[length] != 0)
                ++length;
            if (length == 0)
                return fail(file, element, "empty technique name");
            for (std::size_t k = 0; k < length; ++k)
                if (name[k] < 0x20 || name[k] >= 0x7f)
                    return fail(file, element, "technique name has a non-printable byte at " + std::to_string(k));
            for (std::size_t k = length; k < PACKAGE_MAX_TECHNIQUE_NAME; ++k)
                if (name[k] != 0)
                    return fail(file, element, "technique name is not zero-padded");
            c.technique.assign(reinterpret_cast<const char*>(name), length);

            const std::string what = element + " (" + c.element() + ")";
            if (c.offset % PACKAGE_ALIGNMENT != 0)
                return fail(file, what,
                            "offset " + std::to_string(c.offset) + " is not a multiple of " +
                                std::to_string(PACKAGE_ALIGNMENT));
            if (c.offset > fileSize || c.size > fileSize - c.offset)
                return fail(file, what, truncated(c.size, c.offset, fileSize));
            if (c.offset < PACKAGE_HEADER_SIZE || (c.size > 0 && c.offset < tableEnd && c.offset + c.size > tableOffset))
                return fail(file, what, "payload overlaps the header or the chunk table");
            mChunks.push_back(std::move(c));
        }

        // A (technique, level) pair may appear once, or findChunk would be ambiguous.
        std::vector<std::size_t> order(mChunks.size());
        std::iota(order.begin(), order.end(), std::size_t(0));
        auto key = [&](std::size_t i) { return std::tie(mChunks[i].technique, mChunks[i].level); };
        std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
        for (std::size_t k = 1; k < order.size(); ++k)
            if (key(order[k - 1]) == key(order[k]))
                return fail(file, "chunk table entry " + std::to_string(order[k]),
                            "duplicate of entry " + std::to_string(order[k - 1]) + " (" +
                                mChunks[order[k]].element() + ")");
        return {};
    }

    int PackageReader::findChunk(const std::string& technique, std::uint32_t level) const
    {
        for (std::size_t i = 0; i < mChunks.size(); ++i)
            if (mChunks[i].level == level && mChunks[i].technique == technique)
                return int(i);
        return -1;
    }

    Result<std::vector<std::uint8_t>> PackageReader::readChunk(std::size_t index) const
    {
        if (index >= mChunks.size())
            return fail(mLabel, "chunk index " + std::to_string(index),
                        "out of range (" + std::to_string(mChunks.size()) + " chunks)");
        const ChunkInfo& c = mChunks[index];
        std::vector<std::uint8_t> bytes;
        if (mBytes)
        {
            auto begin = mBytes->begin() + std::ptrdiff_t(c.offset);
            bytes.assign(begin, begin + std::ptrdiff_t(c.size));
        }
        else
        {
            Result<std::vector<std::uint8_t>> r = readFileRange(mLabel, mFile->fd, c.offset, c.size, c.element());
            if (!r)
                return r.error();
            bytes = std::move(r.value());
        }
        const std::uint32_t computed = crc32(bytes.data(), bytes.size());
        if (computed != c.crc32)
            return fail(mLabel, c.element(), checksumMismatch(c.crc32, computed));
        return bytes;
    }

    Result<std::vector<std::uint8_t>> PackageReader::readChunk(const std::string& technique, std::uint32_t level) const
    {
        int index = findChunk(technique, level);
        if (index < 0)
            return fail(mLabel, chunkElement(technique, level), "no such chunk in the package");
        return readChunk(std::size_t(index));
    }
}
