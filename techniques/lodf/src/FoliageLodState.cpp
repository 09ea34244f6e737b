#include "TreeLod/FoliageLodState.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        /// Index slots the active leaves of cluster `c` take.
        std::uint32_t usedSlots(const FoliageLodState& state, std::uint32_t c)
        {
            std::uint32_t used = 0;
            state.forEachActive(c, [&](const FoliageLodEntry& e) { used += e.indexCount; });
            return used;
        }
    }

    FoliageLodState::FoliageLodState(const FoliageLodData& data) : mData(&data), mClusters(data.clusters.size())
    {
        for (std::size_t c = 0; c < mClusters.size(); ++c)
        {
            mClusters[c].activeLeaves = data.clusters[c].originalLeaves;
            mClusters[c].usedSlots = data.clusters[c].slotCount;
        }
        mChanged.reserve(mClusters.size());
    }

    std::uint32_t FoliageLodState::setLeafCount(std::uint32_t target)
    {
        mChanged.clear();
        const std::uint32_t lo = mData->minLeafCount(), hi = mData->maxLeafCount();
        target = std::clamp(target, lo, hi);
        const std::uint32_t position = mData->originalLeafCount - target; // collapses to apply
        const std::vector<std::uint32_t>& changedGroup = mData->changedGroup;

        // §3.3: walk Changed_group from init_position, counting changes per cluster.
        auto note = [&](std::uint32_t c, std::int32_t change) {
            if (mClusters[c].changesNumber == 0)
                mChanged.push_back(c);
            mClusters[c].changesNumber += change;
        };
        if (position > mPosition)
            for (std::uint32_t i = mPosition; i < position; ++i)
                note(changedGroup[i], +1); // leaf collapse
        else
            for (std::uint32_t i = position; i < mPosition; ++i)
                note(changedGroup[i], -1); // leaf split
        mPosition = position;

        // eqs. 10-13 on the clusters that changed; then Changes_number back to 0.
        for (std::uint32_t c : mChanged)
        {
            ClusterState& s = mClusters[c];
            s.initGroup = std::uint32_t(std::int64_t(s.initGroup) + 2 * std::int64_t(s.changesNumber));
            s.activeLeaves = std::uint32_t(std::int64_t(s.activeLeaves) - s.changesNumber);
            s.changesNumber = 0;
            s.usedSlots = usedSlots(*this, c);
        }
        return std::uint32_t(mChanged.size());
    }

    template <typename Index> std::uint32_t FoliageLodState::writeCluster(std::uint32_t c, Index* out) const
    {
        const FoliageLodCluster& k = mData->clusters[c];
        std::uint32_t n = 0;
        forEachActive(c, [&](const FoliageLodEntry& e) {
            const std::uint32_t* src = mData->indices.data() + e.firstIndex;
            for (std::uint32_t i = 0; i < e.indexCount; ++i)
                out[n + i] = Index(src[i]);
            n += e.indexCount;
        });
        // Degenerate triangles (one repeated vertex) fill the rest of the region.
        const Index pad = n > 0 ? out[n - 1] : Index(0);
        std::fill(out + n, out + k.slotCount, pad);
        return n;
    }

    template std::uint32_t FoliageLodState::writeCluster<std::uint16_t>(std::uint32_t, std::uint16_t*) const;
    template std::uint32_t FoliageLodState::writeCluster<std::uint32_t>(std::uint32_t, std::uint32_t*) const;

    void FoliageLodState::activeLeaves(std::uint32_t c, std::vector<std::uint32_t>& out) const
    {
        forEachActive(c, [&](const FoliageLodEntry& e) { out.push_back(e.leaf); });
    }

    std::vector<std::uint32_t> FoliageLodState::activeLeaves() const
    {
        std::vector<std::uint32_t> out;
        out.reserve(leafCount());
        for (std::uint32_t c = 0; c < mClusters.size(); ++c)
            activeLeaves(c, out);
        return out;
    }

    std::uint32_t FoliageLodState::quantise(const FoliageLodData& data, std::uint32_t count, std::uint32_t levels)
    {
        const std::uint32_t lo = data.minLeafCount(), hi = data.maxLeafCount();
        count = std::clamp(count, lo, hi);
        if (levels <= 1 || lo == hi)
            return count;
        const double ratio = std::pow(double(hi) / double(std::max(lo, 1u)), 1.0 / double(levels - 1));
        double level = double(std::max(lo, 1u));
        for (std::uint32_t i = 0; i + 1 < levels; ++i, level *= ratio)
            if (double(count) <= std::ceil(level))
                return std::min(hi, std::uint32_t(std::ceil(level)));
        return hi;
    }

    FoliageLodState FoliageLodState::fromScratch(const FoliageLodData& data, std::uint32_t leafCount)
    {
        FoliageLodState state(data);
        leafCount = std::clamp(leafCount, data.minLeafCount(), data.maxLeafCount());
        const std::uint32_t position = data.originalLeafCount - leafCount;
        std::vector<std::uint32_t> applied(data.clusters.size(), 0);
        for (std::uint32_t i = 0; i < position; ++i)
            ++applied[data.changedGroup[i]];
        for (std::size_t c = 0; c < applied.size(); ++c)
        {
            ClusterState& s = state.mClusters[c];
            s.initGroup = 2 * applied[c];
            s.activeLeaves = data.clusters[c].originalLeaves - applied[c];
            s.usedSlots = usedSlots(state, std::uint32_t(c));
        }
        state.mPosition = position;
        return state;
    }
}
