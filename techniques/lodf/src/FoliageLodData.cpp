#include "TreeLod/FoliageLodData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t ALIGN = 16;
        constexpr ArrayLayout CLUSTERS{24, ALIGN};
        constexpr ArrayLayout ENTRIES{16, ALIGN};
        constexpr ArrayLayout WORDS{4, ALIGN};

        constexpr auto clusterFields = [](auto& s, auto& c) {
            s.fields(c.material, c.firstEntry, c.entryCount, c.originalLeaves, c.firstSlot, c.slotCount);
        };
        constexpr auto entryFields = [](auto& s, auto& e) { s.fields(e.leaf, e.created, e.firstIndex, e.indexCount); };
        constexpr auto wordField = [](auto& s, auto& v) { s.fields(v); };

        std::string clusterElement(std::size_t c) { return "lodf cluster " + std::to_string(c); }
    }

    std::uint64_t FoliageLodData::paperWords() const
    {
        // eq. 7-8: 3 |V^r| + 6 |L^r| + 3 G + |Changed_group|; a leaf's vertex indices are
        // counted as the paper counts a quad leaf (4), plus its number and its next/step word.
        return 3ull * leafVertexCount + 6ull * entries.size() + 3ull * clusters.size() + changedGroup.size();
    }

    std::uint64_t FoliageLodData::byteSize() const
    {
        return clusters.size() * sizeof(FoliageLodCluster) + entries.size() * sizeof(FoliageLodEntry) +
               indices.size() * 4 + changedGroup.size() * 4;
    }

    Result<void> FoliageLodData::validate(const std::string& label) const
    {
        std::uint64_t leaves = 0, slot = 0, entry = 0;
        std::vector<std::uint32_t> collapses(clusters.size(), 0);
        for (std::size_t c = 0; c < clusters.size(); ++c)
        {
            const FoliageLodCluster& k = clusters[c];
            const std::string element = clusterElement(c);
            if (k.originalLeaves == 0 || k.entryCount != 2 * std::uint64_t(k.originalLeaves) - 1)
                return fail(label, element, std::to_string(k.entryCount) + " entries for " +
                                                std::to_string(k.originalLeaves) + " leaves (needs 2n - 1)");
            if (k.firstEntry != entry || std::uint64_t(k.firstEntry) + k.entryCount > entries.size())
                return fail(label, element, "entries not consecutive or out of range");
            if (k.firstSlot != slot)
                return fail(label, element, "index region does not follow the previous one");
            if (c > 0 && k.material < clusters[c - 1].material)
                return fail(label, element, "clusters not sorted by material");
            std::uint64_t originalSlots = 0;
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
            {
                const FoliageLodEntry& e = entries[k.firstEntry + p];
                const std::string at = element + " entry " + std::to_string(p);
                // Position p dies at collapse p / 2 + 1; the root (last) never dies. A leaf
                // must be created before it is removed.
                const std::uint32_t removedAt = p + 1 == k.entryCount ? k.originalLeaves : p / 2 + 1;
                if (e.created >= removedAt || e.created >= k.originalLeaves)
                    return fail(label, at, "created at step " + std::to_string(e.created) + ", removed at step " +
                                               std::to_string(removedAt));
                if (e.indexCount == 0 || e.indexCount % 3 != 0 ||
                    std::uint64_t(e.firstIndex) + e.indexCount > indices.size())
                    return fail(label, at, "index range out of bounds or not whole triangles");
                if (e.created == 0)
                    originalSlots += e.indexCount;
            }
            // Exactly n originals, and one created leaf per step 1..n-1.
            std::vector<std::uint8_t> seen(k.originalLeaves, 0);
            std::uint32_t originals = 0;
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
            {
                std::uint32_t s = entries[k.firstEntry + p].created;
                if (s == 0)
                    ++originals;
                else if (seen[s]++)
                    return fail(label, element, "two leaves created at step " + std::to_string(s));
            }
            if (originals != k.originalLeaves)
                return fail(label, element, std::to_string(originals) + " original leaves, header says " +
                                                std::to_string(k.originalLeaves));
            // Replay the steps: no state may need more index slots than the region has.
            std::vector<std::uint32_t> createdAt(k.originalLeaves, 0);
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
                createdAt[entries[k.firstEntry + p].created] = p;
            std::uint64_t used = 0;
            for (std::uint32_t p = 0; p < k.entryCount; ++p)
                if (entries[k.firstEntry + p].created == 0)
                    used += entries[k.firstEntry + p].indexCount;
            for (std::uint32_t step = 1; step < k.originalLeaves; ++step)
            {
                used -= entries[k.firstEntry + 2 * step - 2].indexCount + entries[k.firstEntry + 2 * step - 1].indexCount;
                used += entries[k.firstEntry + createdAt[step]].indexCount;
                if (used > originalSlots)
                    return fail(label, element, "after step " + std::to_string(step) + " its leaves need " +
                                                    std::to_string(used) + " index slots, the region has " +
                                                    std::to_string(originalSlots));
            }
            if (k.slotCount != originalSlots)
                return fail(label, element, "index region of " + std::to_string(k.slotCount) +
                                                " slots, its original leaves have " + std::to_string(originalSlots));
            leaves += k.originalLeaves;
            slot += k.slotCount;
            entry += k.entryCount;
            if (slot > 0xffffffffull)
                return fail(label, element, "index regions exceed 2^32 slots");
        }
        if (entry != entries.size())
            return fail(label, "lodf entries", std::to_string(entries.size() - entry) + " entries outside clusters");
        if (leaves != originalLeafCount)
            return fail(label, "lodf", "clusters hold " + std::to_string(leaves) + " leaves, header says " +
                                           std::to_string(originalLeafCount));
        for (std::size_t i = 0; i < changedGroup.size(); ++i)
        {
            if (changedGroup[i] >= clusters.size())
                return fail(label, "lodf Changed_group " + std::to_string(i),
                            "cluster " + std::to_string(changedGroup[i]) + " out of range");
            ++collapses[changedGroup[i]];
        }
        for (std::size_t c = 0; c < clusters.size(); ++c)
            if (collapses[c] + 1 != clusters[c].originalLeaves)
                return fail(label, clusterElement(c),
                            std::to_string(collapses[c]) + " collapses in Changed_group for " +
                                std::to_string(clusters[c].originalLeaves) + " leaves (needs n - 1)");
        for (std::size_t i = 0; i < indices.size(); ++i)
            if (indices[i] >= leafVertexCount)
                return fail(label, "lodf index " + std::to_string(i),
                            std::to_string(indices[i]) + " out of range (" + std::to_string(leafVertexCount) +
                                " leaf vertices)");
        return {};
    }

    std::vector<std::uint8_t> encodeFoliageLodChunk(const FoliageLodData& data)
    {
        ByteWriter w;
        w.fields(data.originalLeafCount, data.leafVertexCount);
        writeArray(w, data.clusters, CLUSTERS, clusterFields);
        writeArray(w, data.entries, ENTRIES, entryFields);
        writeArray(w, data.indices, WORDS, wordField);
        writeArray(w, data.changedGroup, WORDS, wordField);
        return w.take();
    }

    Result<FoliageLodData> decodeFoliageLodChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(FOLIAGE_LOD_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        FoliageLodData data;
        r.fields(data.originalLeafCount, data.leafVertexCount);
        readArray(r, data.clusters, CLUSTERS, clusterFields);
        readArray(r, data.entries, ENTRIES, entryFields);
        readArray(r, data.indices, WORDS, wordField);
        readArray(r, data.changedGroup, WORDS, wordField);
        return finishDecode(r, label, name, std::move(data));
    }
}
