// The *.treelod package: one file per tree holding every baked technique and level.
//
// File format, version 1 (the contract between TreeLodBake's PackageWriter and this reader).
// All integers are little-endian; offsets and sizes are in bytes from the start of the file.
//
//   header, 32 bytes at offset 0
//     0  char[4]  magic "TRLD"
//     4  u32      version               PACKAGE_VERSION (1)
//     8  u32      chunkCount            entries in the chunk table (0 is a valid, empty package)
//    12  u32      flags                 none defined in version 1: writers write 0, readers
//                                       ignore them (a change readers must not ignore bumps
//                                       the version)
//    16  u64      tableOffset           writers put the table right after the header (32)
//    24  u32      tableCrc32            CRC-32 (Crc32.h) of the chunkCount * 64 table bytes
//    28  u32      headerCrc32           CRC-32 of header bytes 0..27
//
//   chunk table, chunkCount entries of 64 bytes at tableOffset
//     0  char[32] technique             UTF-8 name, 1..32 bytes, zero-padded; printable ASCII
//                                       only ("reference", "meta", a technique's name)
//    32  u32      level                 level of detail within the technique (0 = finest)
//    36  u32      formatVersion         version of that technique's chunk layout
//    40  u64      offset                multiple of PACKAGE_ALIGNMENT, past header and table
//    48  u64      size                  payload bytes (may be 0)
//    56  u32      crc32                 CRC-32 of the payload
//    60  u32      reserved              0
//
//   chunk payloads, each at its offset; writers pad the gaps with zero bytes, sort the
//   entries by (technique, level) and lay the payloads out in table order, so the same
//   chunks always give byte-identical files (no timestamps anywhere).
//   A (technique, level) pair appears at most once.
//
// Well-known chunks:
//   "meta" level 0       UTF-8 text (JSON written by the baker: source file, content hash of
//                        the source, options); the runtime only hands the bytes out.
//   "reference" level 0  the polygonal tree with GPU-ready textures (ModelChunk.h).
//
// Hostile input: the reader checks every count, offset and size against the file size
// before it allocates or reads, so a corrupt file costs at most its own size in memory.
// Errors name the file (or the label of in-memory data), the element ("header",
// "chunk table entry 3", "chunk 'reference' level 0") and the reason
// ("truncated: needs 64 bytes at offset 32, file has 40", "checksum mismatch", ...).
#pragma once

#include "TreeLod/Result.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr char PACKAGE_MAGIC[4] = {'T', 'R', 'L', 'D'};
    constexpr std::uint32_t PACKAGE_VERSION = 1;
    constexpr std::uint64_t PACKAGE_HEADER_SIZE = 32;
    constexpr std::uint64_t PACKAGE_TABLE_ENTRY_SIZE = 64;
    constexpr std::uint64_t PACKAGE_ALIGNMENT = 16;
    constexpr std::size_t PACKAGE_MAX_TECHNIQUE_NAME = 32;

    /// Technique names of the chunks this build knows (the Ogre registry adds its own).
    constexpr const char* META_CHUNK = "meta";
    constexpr const char* REFERENCE_CHUNK = "reference";

    /// One chunk table entry.
    struct ChunkInfo
    {
        std::string technique;          ///< "reference", "meta" or a technique's registered name
        std::uint32_t level = 0;
        std::uint32_t formatVersion = 1;
        std::uint64_t offset = 0;       ///< from the start of the file
        std::uint64_t size = 0;         ///< payload bytes
        std::uint32_t crc32 = 0;        ///< of the payload

        /// "chunk 'reference' level 0": the element name used in errors.
        std::string element() const;
    };

    /// "chunk 'TECHNIQUE' level N".
    std::string chunkElement(const std::string& technique, std::uint32_t level);

    /// Reads a package's header and chunk table up front and chunk payloads on demand.
    /// Copies are cheap and share the data (in-memory packages share one byte buffer; file
    /// packages the open file, which stays open while a copy lives: every read comes from the
    /// file open() found, even once another is renamed over its path, as BakeCache does).
    /// Thread safety: const member functions may be called from several threads.
    class PackageReader
    {
    public:
        /// An empty reader: no chunks, no label (a placeholder until open() / fromMemory()).
        PackageReader() = default;

        /// Read the header and chunk table of the file at `path`; payloads stay on disk
        /// until readChunk(). Checks magic, version, header and table checksums, and that
        /// every chunk lies inside the file. Errors name `path`.
        static Result<PackageReader> open(const std::string& path);

        /// Same checks on a package already in memory (an Ogre DataStream, a fuzzer input).
        /// `label` names the source in errors (e.g. the Ogre resource name).
        static Result<PackageReader> fromMemory(std::vector<std::uint8_t> bytes, const std::string& label);

        /// The chunk table in file order (sorted by technique, then level, when written by
        /// PackageWriter).
        const std::vector<ChunkInfo>& chunks() const { return mChunks; }

        /// The path or label given to open() / fromMemory().
        const std::string& label() const { return mLabel; }

        /// Index into chunks() of the chunk (technique, level), or -1 if absent.
        int findChunk(const std::string& technique, std::uint32_t level) const;

        /// Payload of chunks()[index], its CRC-32 verified. Errors: index out of range,
        /// read failure or file truncated since open() ("truncated: ..."), "checksum mismatch";
        /// the element is "chunk 'reference' level 0".
        Result<std::vector<std::uint8_t>> readChunk(std::size_t index) const;

        /// Payload of the chunk (technique, level); error "no such chunk" if absent.
        Result<std::vector<std::uint8_t>> readChunk(const std::string& technique, std::uint32_t level) const;

        /// Size of the whole package in bytes (as seen by open() / fromMemory()).
        std::uint64_t fileSize() const { return mFileSize; }

        /// Header version (PACKAGE_VERSION for every package this build accepts).
        std::uint32_t version() const { return mVersion; }

    private:
        /// Reads `size` bytes at `offset` of the package; the element names the part in errors.
        using RangeReader = std::function<Result<std::vector<std::uint8_t>>(
            std::uint64_t offset, std::uint64_t size, const std::string& element)>;
        Result<void> parse(const RangeReader& readRange);

        struct OpenFile;

        std::string mLabel;
        std::shared_ptr<const OpenFile> mFile;                 ///< null for in-memory packages
        std::shared_ptr<const std::vector<std::uint8_t>> mBytes; ///< null for file packages
        std::uint64_t mFileSize = 0;
        std::uint32_t mVersion = 0;
        std::vector<ChunkInfo> mChunks;
    };
}
