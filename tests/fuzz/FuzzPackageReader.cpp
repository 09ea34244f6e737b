// libFuzzer target: PackageReader::fromMemory on arbitrary bytes, then every chunk read and,
// for every registered technique (TechniqueDescriptor.h), decoded and validated (inspect) and
// walked as a renderer reads it (the descriptor's fuzz hook: LoDF levels written cluster by
// cluster, billboard-cloud list walks, texture mips). Must never crash, read out of bounds or
// allocate more than a small multiple of the input (Package.h, "Hostile input").
//
// Seeds: tests/fuzz/corpus/package/ (small valid packages). The chunk CRCs stop most
// mutations at readChunk; the input's last byte may ask the fuzzer to skip those checks by
// resealing the checksums, so the decoders behind them are fuzzed too.
#include "TreeLod/Crc32.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace
{
    std::uint32_t getU32(const std::vector<std::uint8_t>& b, std::size_t at)
    {
        return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
               std::uint32_t(b[at + 3]) << 24;
    }

    std::uint64_t getU64(const std::vector<std::uint8_t>& b, std::size_t at)
    {
        return std::uint64_t(getU32(b, at)) | std::uint64_t(getU32(b, at + 4)) << 32;
    }

    void putU32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v)
    {
        for (int i = 0; i < 4; ++i)
            b[at + i] = std::uint8_t(v >> (8 * i));
    }

    /// Recompute every checksum that fits in the data, so mutations reach the parsers
    /// behind them. Leaves anything out of range alone (the reader must reject it).
    void reseal(std::vector<std::uint8_t>& b)
    {
        if (b.size() < TreeLod::PACKAGE_HEADER_SIZE)
            return;
        const std::uint64_t count = getU32(b, 8), tableOffset = getU64(b, 16);
        const std::uint64_t entry = TreeLod::PACKAGE_TABLE_ENTRY_SIZE;
        if (tableOffset <= b.size() && count <= (b.size() - tableOffset) / entry)
        {
            for (std::uint64_t i = 0; i < count; ++i)
            {
                const std::size_t at = std::size_t(tableOffset + i * entry);
                const std::uint64_t offset = getU64(b, at + 40), size = getU64(b, at + 48);
                if (offset <= b.size() && size <= b.size() - offset)
                    putU32(b, at + 56, TreeLod::crc32(b.data() + offset, std::size_t(size)));
            }
            putU32(b, 24, TreeLod::crc32(b.data() + tableOffset, std::size_t(count * entry)));
        }
        putU32(b, 28, TreeLod::crc32(b.data(), 28));
    }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    std::vector<std::uint8_t> bytes(data, data + size);
    if (!bytes.empty() && (bytes.back() & 1u))
        reseal(bytes);

    TreeLod::Result<TreeLod::PackageReader> reader = TreeLod::PackageReader::fromMemory(std::move(bytes), "fuzz");
    if (!reader)
        return 0;
    for (std::size_t i = 0; i < reader->chunks().size(); ++i)
    {
        TreeLod::Result<std::vector<std::uint8_t>> chunk = reader->readChunk(i);
        if (!chunk)
            continue;
        // Every registered technique: what `treelod info` and a loader do (decode, validate), then
        // what a renderer reads from the result (the descriptor's fuzz hook).
        const TreeLod::TechniqueDescriptor* technique =
            TreeLod::findTechniqueDescriptor(reader->chunks()[i].technique);
        if (!technique)
            continue;
        TreeLod::inspectChunk(*technique, chunk.value(), "fuzz", reader->chunks()[i].formatVersion);
        if (technique->fuzz)
            technique->fuzz(chunk.value());
    }
    reader->findChunk(TreeLod::REFERENCE_CHUNK, 0);
    return 0;
}
