// FoliageLodData: the multiresolution foliage F^r of LoDF (Rebollo et al. 2006 §3.1-3.2) and its
// package chunk "lodf".
//
// The leaves of the tree (originals and the ones created by leaf collapses, 2L - 1 at most,
// eq. 5) are stored in an array of independent clusters. Each cluster holds the binary tree
// of one group (Figs. 4-7): its entries are ordered as the paper's Fig. 7 orders them, the
// two leaves of the cluster's first collapse, then the two of its second, ..., the cluster's
// root (its coarsest leaf) last. A collapse never adds vertices (eq. 3): a created leaf is a
// quad over four vertices of the leaves it replaces, so all vertices are the reference
// chunk's leaf vertices and live on the GPU once.
//
// Deviation from Fig. 7 (documented in techniques/lodf/README.md): the paper gives each entry a fixed `next`
// position; a fixed chain cannot represent every state in general (in the paper's own
// group 1, after two collapses the chain from position 4 yields {l3, l10} instead of
// {l3, l12}). Each entry stores instead the cluster-local collapse step that creates it:
// after j collapses the active leaves are the entries at positions >= Init_group = 2j whose
// step is <= j, read in array order (FoliageLodState). Same word count per leaf.
//
// Chunk "lodf" level 0, formatVersion 1 (FOLIAGE_LOD_CHUNK_FORMAT_VERSION), little-endian,
// "align16" as in ModelChunk.h:
//   u32 originalLeafCount L, u32 leafVertexCount (of the reference chunk it indexes)
//   u32 clusterCount, align16, clusters of 24 bytes:
//       u32 material, firstEntry, entryCount, originalLeaves, firstSlot, slotCount
//   u32 entryCount, align16, entries of 16 bytes: u32 leaf, created, firstIndex, indexCount
//   u32 indexCount, align16, u32 indices (absolute into the reference's leafVertices)
//   u32 collapseCount, align16, u32 cluster per collapse (Changed_group, Fig. 8)
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/Result.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* FOLIAGE_LOD_CHUNK = "lodf";
    constexpr std::uint32_t FOLIAGE_LOD_CHUNK_FORMAT_VERSION = 1;

    /// One leaf of a cluster's array (Fig. 7).
    struct FoliageLodEntry
    {
        std::uint32_t leaf = 0;       ///< leaf number: < L an original, L + k created by collapse k
        std::uint32_t created = 0;    ///< cluster-local collapse step that creates it, 0 for originals
        std::uint32_t firstIndex = 0; ///< its triangles in FoliageLodData::indices
        std::uint32_t indexCount = 0; ///< multiple of 3 (6 for a created quad)
    };

    /// One independent group (§3.1): the leaves of one binary tree.
    struct FoliageLodCluster
    {
        std::uint32_t material = 0;       ///< all its leaves share one leaf material
        std::uint32_t firstEntry = 0;     ///< into FoliageLodData::entries
        std::uint32_t entryCount = 0;     ///< 2 * originalLeaves - 1
        std::uint32_t originalLeaves = 0; ///< n >= 1: its leaves in F_0
        /// Its index region on the GPU: [firstSlot, firstSlot + slotCount) of the index
        /// buffer, slotCount = indices of its original leaves (a collapse never adds indices).
        std::uint32_t firstSlot = 0;
        std::uint32_t slotCount = 0;
    };

    struct FoliageLodData
    {
        /// L: the model's leaves, a leaf that is one mesh in several planes counted once per
        /// plane (FoliageLodBaker.h), so at least TreeModel::leaves.size()
        std::uint32_t originalLeafCount = 0;
        std::uint32_t leafVertexCount = 0;   ///< vertices the indices address (reference chunk)
        std::vector<FoliageLodCluster> clusters; ///< sorted by material; regions consecutive
        std::vector<FoliageLodEntry> entries;
        std::vector<std::uint32_t> indices;
        std::vector<std::uint32_t> changedGroup; ///< Fig. 8: cluster of each collapse, in LoD order

        /// Leaves at the coarsest level F_{n-1}: one per cluster.
        std::uint32_t minLeafCount() const { return std::uint32_t(clusters.size()); }
        std::uint32_t maxLeafCount() const { return originalLeafCount; }
        /// Total index slots of all regions (the GPU index buffer's length).
        std::uint32_t slotCount() const
        {
            return clusters.empty() ? 0 : clusters.back().firstSlot + clusters.back().slotCount;
        }

        /// Words of the structure as Rebollo et al. 2006 eq. 7-8 count them (3 per vertex position,
        /// per leaf its number + vertex indices + next, 3 per cluster, 1 per collapse), and
        /// eq. 9's estimate 6.25 V for comparison.
        std::uint64_t paperWords() const;
        std::uint64_t paperEq9Words() const { return std::uint64_t(6.25 * double(leafVertexCount) + 0.5); }
        /// Bytes this structure takes in memory (arrays only, vertices excluded).
        std::uint64_t byteSize() const;

        /// Every invariant FoliageLodState relies on: entry ranges, per-cluster steps, slot
        /// regions, Changed_group counts, indices < leafVertexCount. `label` names the source.
        Result<void> validate(const std::string& label) const;
    };

    std::vector<std::uint8_t> encodeFoliageLodChunk(const FoliageLodData& data);
    /// Parse and validate(); errors name `label` and the element ("chunk 'lodf' level 0" for
    /// layout errors, "lodf cluster 3", "lodf index 17", ... for content).
    Result<FoliageLodData> decodeFoliageLodChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
