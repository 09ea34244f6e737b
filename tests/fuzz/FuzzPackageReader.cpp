// libFuzzer target: PackageReader::fromMemory on arbitrary bytes, then every chunk read,
// every "reference" chunk decoded, every "lodf" chunk decoded and walked through its
// levels as FoliageLodTree does (writeCluster must stay inside each cluster's region), and
// every "billboard-cloud" / "classic-billboard-cloud" chunk decoded and sampled as the
// shader addresses it (BillboardCloudSampler), and every "impostor" chunk decoded and its
// texture mips walked. Must never crash, read out of bounds or
// allocate more than a small multiple of the input (Package.h, "Hostile input").
//
// Seeds: tests/fuzz/corpus/package/ (small valid packages). The chunk CRCs stop most
// mutations at readChunk; the input's last byte may ask the fuzzer to skip those checks by
// resealing the checksums, so the decoders behind them are fuzzed too.
#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/Crc32.h"
#include "TreeLod/FoliageLodState.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"

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
        if (reader->chunks()[i].technique == TreeLod::REFERENCE_CHUNK)
        {
            TreeLod::Result<TreeLod::ReferenceChunk> decoded = TreeLod::decodeReferenceChunk(chunk.value(), "fuzz");
            if (decoded)
            {
                // What a loader does next: walk the mips of each texture.
                for (const TreeLod::GpuTexture& t : decoded->textures)
                    for (std::uint32_t level = 0; level < t.mipCount; ++level)
                        if (t.mipOffset(level) + t.mipBytes(level) > t.data.size())
                            __builtin_trap();
            }
        }
        else if (reader->chunks()[i].technique == TreeLod::BILLBOARD_CLOUD_CHUNK ||
                 reader->chunks()[i].technique == TreeLod::CLASSIC_BILLBOARD_CLOUD_CHUNK)
        {
            TreeLod::Result<TreeLod::BillboardCloudData> decoded =
                TreeLod::decodeBillboardCloudChunk(chunk.value(), "fuzz");
            if (!decoded)
                continue;
            // What the shader does per fragment: hash fetch, list walk from either end; every
            // entry and tile it reads must exist.
            const TreeLod::BillboardCloudSampler sampler(decoded.value());
            const std::uint32_t billboards = std::uint32_t(decoded->billboards.size());
            for (std::uint32_t b = 0; b < billboards && b < 64; ++b)
                for (float uv : {0.0f, 0.37f, 0.5f, 1.0f})
                    for (bool front : {true, false})
                        for (const TreeLod::BillboardCloudSampler::Fragment& f : sampler.walk(b, uv, 1.0f - uv, front))
                            if (f.entry >= decoded->entries.size() || f.tile >= decoded->tileCount())
                                __builtin_trap();
            sampler.walk(billboards, 0.5f, 0.5f, true); // out of range: no fragments, no crash
        }
        else if (reader->chunks()[i].technique == TreeLod::IMPOSTOR_CHUNK)
        {
            TreeLod::Result<TreeLod::ImpostorData> decoded = TreeLod::decodeImpostorChunk(chunk.value(), "fuzz");
            if (!decoded)
                continue;
            // What TreeAsset::getImpostorGpu uploads: every mip of both textures.
            for (const TreeLod::GpuTexture* t : {&decoded->colour, &decoded->normal})
                for (std::uint32_t level = 0; level < t->mipCount; ++level)
                    if (t->mipOffset(level) + t->mipBytes(level) > t->data.size())
                        __builtin_trap();
        }
        else if (reader->chunks()[i].technique == TreeLod::FOLIAGE_LOD_CHUNK)
        {
            TreeLod::Result<TreeLod::FoliageLodData> decoded = TreeLod::decodeFoliageLodChunk(chunk.value(), "fuzz");
            if (!decoded)
                continue;
            TreeLod::FoliageLodState state(decoded.value());
            const std::uint32_t lo = decoded->minLeafCount(), hi = decoded->maxLeafCount();
            for (std::uint32_t target : {lo, (lo + hi) / 2, hi + 1, 0u})
            {
                state.setLeafCount(target);
                for (std::uint32_t c : state.changedClusters())
                {
                    // A region of exactly slotCount: ASan reports any write past it.
                    std::vector<std::uint32_t> region(decoded->clusters[c].slotCount);
                    if (!region.empty() && state.writeCluster(c, region.data()) > region.size())
                        __builtin_trap();
                }
            }
        }
    }
    reader->findChunk(TreeLod::REFERENCE_CHUNK, 0);
    return 0;
}
