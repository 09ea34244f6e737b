// FoliageLodState: the retrieval algorithms of LoDF (Rebollo et al. 2006 §3.3) on one instance's
// current level of detail.
//
// Per cluster it keeps Init_group, Active_leaves and Changes_number; init_position is the
// number of collapses of Changed_group applied. setLeafCount() walks Changed_group forward
// (collapse) or backward (split), counts the changes per cluster, applies eqs. 10-13 to the
// clusters that changed and lists them, so that only their index regions are rewritten and
// sent to the GPU (§4). writeCluster() fills one cluster's region: its active leaves'
// triangles, then degenerate triangles up to the region's end so that one draw over all
// regions needs no compaction.
#pragma once

#include "TreeLod/FoliageLodData.h"

#include <cstdint>
#include <vector>

namespace TreeLod
{
    class FoliageLodState
    {
    public:
        struct ClusterState
        {
            std::uint32_t initGroup = 0;     ///< position of the first active leaf (2 x collapses applied)
            std::uint32_t activeLeaves = 0;  ///< leaves drawn now
            std::int32_t changesNumber = 0;  ///< pending collapses (+) or splits (-) while updating
            std::uint32_t usedSlots = 0;     ///< indices of its active leaves in its region
            bool operator==(const ClusterState& o) const
            {
                return initGroup == o.initGroup && activeLeaves == o.activeLeaves &&
                       changesNumber == o.changesNumber && usedSlots == o.usedSlots;
            }
        };

        /// F_0: every original leaf active. `data` must outlive the state.
        explicit FoliageLodState(const FoliageLodData& data);

        /// Move to `target` leaves, clamped to [minLeafCount, maxLeafCount]. Returns the number
        /// of clusters that changed; they are listed by changedClusters() until the next call.
        std::uint32_t setLeafCount(std::uint32_t target);
        const std::vector<std::uint32_t>& changedClusters() const { return mChanged; }

        std::uint32_t leafCount() const { return mData->originalLeafCount - mPosition; }
        std::uint32_t initPosition() const { return mPosition; } ///< collapses applied
        const ClusterState& cluster(std::uint32_t c) const { return mClusters[c]; }
        const FoliageLodData& data() const { return *mData; }

        /// Write the region of cluster `c` (slotCount indices) into `out`, as `Index`
        /// (std::uint16_t or std::uint32_t; the caller checks that the vertex count fits).
        /// Returns the indices of active leaves written before the degenerate padding.
        template <typename Index> std::uint32_t writeCluster(std::uint32_t c, Index* out) const;

        /// Call visit(const FoliageLodEntry&) for each active leaf of cluster `c`, in array order:
        /// the entries at positions >= Init_group created by a step the cluster has applied
        /// (FoliageLodData.h, the deviation from Fig. 7).
        template <typename Visit> void forEachActive(std::uint32_t c, Visit&& visit) const
        {
            const FoliageLodCluster& k = mData->clusters[c];
            const ClusterState& s = mClusters[c];
            const std::uint32_t applied = s.initGroup / 2;
            std::uint32_t left = s.activeLeaves;
            for (std::uint32_t p = s.initGroup; p < k.entryCount && left > 0; ++p)
            {
                const FoliageLodEntry& e = mData->entries[k.firstEntry + p];
                if (e.created <= applied)
                {
                    visit(e);
                    --left;
                }
            }
        }

        /// Numbers of the active leaves of cluster `c` (or of all clusters), in array order.
        void activeLeaves(std::uint32_t c, std::vector<std::uint32_t>& out) const;
        std::vector<std::uint32_t> activeLeaves() const;

        /// Snap `count` to one of `levels` leaf counts spaced geometrically from minLeafCount to
        /// maxLeafCount (the next one up, never fewer leaves than asked). For instances that
        /// share index buffers (a Forest's distant trees); levels <= 1 only clamps `count`.
        static std::uint32_t quantise(const FoliageLodData& data, std::uint32_t count, std::uint32_t levels);

        /// The state reached from F_0 by applying the first `collapses` of Changed_group in
        /// one go: what setLeafCount must agree with after any sequence of moves.
        static FoliageLodState fromScratch(const FoliageLodData& data, std::uint32_t leafCount);

    private:
        const FoliageLodData* mData;
        std::vector<ClusterState> mClusters;
        std::vector<std::uint32_t> mChanged;
        std::uint32_t mPosition = 0; ///< init_position
    };

    extern template std::uint32_t FoliageLodState::writeCluster<std::uint16_t>(std::uint32_t, std::uint16_t*) const;
    extern template std::uint32_t FoliageLodState::writeCluster<std::uint32_t>(std::uint32_t, std::uint32_t*) const;
}
