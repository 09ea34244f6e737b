#include "TreeLod/FoliageLodResources.h"

#include "TreeLod/FoliageLodState.h"
#include "TreeLod/TreeAsset.h"
#include "TreeLod/TreeMeshBuilder.h"

#include <OgreHardwareBufferManager.h>

#include <algorithm>

namespace TreeLod
{
    FoliageLodResources& FoliageLodResources::of(TreeAsset& asset)
    {
        return asset.getResources<FoliageLodResources>(
            FOLIAGE_LOD_CHUNK, [&asset] { return std::make_unique<FoliageLodResources>(asset); });
    }

    FoliageLodResources::FoliageLodResources(TreeAsset& asset) : mAsset(asset) {}

    FoliageLodResources::~FoliageLodResources() = default; // buffers are shared pointers

    const FoliageLodData& FoliageLodResources::getFoliageLod()
    {
        if (mData)
            return *mData;
        Result<FoliageLodData> data = decodeFoliageLodChunk(mAsset.readChunk(FOLIAGE_LOD_CHUNK), mAsset.getName());
        if (!data)
            mAsset.raise(data.error());
        const TreeModel& model = mAsset.getReference().model;
        // Originals are leaves or planes of leaves (FoliageLodData::originalLeafCount).
        if (data->leafVertexCount != model.leafVertices.size() || data->originalLeafCount < model.leaves.size())
            mAsset.raise(fail(mAsset.getName(), chunkElement(FOLIAGE_LOD_CHUNK, 0),
                       "made for " + std::to_string(data->originalLeafCount) + " leaves / " +
                           std::to_string(data->leafVertexCount) + " vertices, the reference has " +
                           std::to_string(model.leaves.size()) + " / " + std::to_string(model.leafVertices.size())));
        for (const FoliageLodCluster& c : data->clusters)
            if (c.material >= model.materials.size() || !model.materials[c.material].isLeaf)
                mAsset.raise(fail(mAsset.getName(), chunkElement(FOLIAGE_LOD_CHUNK, 0),
                           "cluster material " + std::to_string(c.material) + " is not a leaf material"));
        // Vertices in the order the clusters first use them, so that a draw's indices address
        // nearby vertices (GPU vertex caches; llvmpipe ran 20 % slower in the reference's order).
        std::vector<std::uint32_t> order(model.leafVertices.size(), ~0u);
        std::uint32_t next = 0;
        for (std::uint32_t& index : data->indices)
        {
            if (order[index] == ~0u)
                order[index] = next++;
            index = order[index];
        }
        mLeafVertexOrder.assign(model.leafVertices.size(), 0);
        for (std::uint32_t v = 0; v < order.size(); ++v)
            mLeafVertexOrder[order[v] == ~0u ? next++ : order[v]] = v;
        mData = std::make_unique<FoliageLodData>(std::move(data.value()));
        return *mData;
    }

    Ogre::VertexData* FoliageLodResources::getLeafVertexData()
    {
        if (!mLeafVertexData)
        {
            const std::vector<Vertex>& vertices = mAsset.getReference().model.leafVertices;
            getFoliageLod(); // the order its indices were renumbered to
            std::vector<Vertex> ordered(vertices.size());
            for (std::size_t i = 0; i < ordered.size(); ++i)
                ordered[i] = vertices[mLeafVertexOrder[i]];
            mLeafVertexData.reset(makeTreeVertexData(ordered));
        }
        return mLeafVertexData.get();
    }

    const FoliageLodLevel& FoliageLodResources::getFoliageLodLevel(std::uint32_t leafCount)
    {
        const FoliageLodData& data = getFoliageLod();
        leafCount = std::clamp(leafCount, data.minLeafCount(), data.maxLeafCount());
        auto found = mLevels.find(leafCount);
        if (found != mLevels.end())
            return found->second;
        const FoliageLodState state = FoliageLodState::fromScratch(data, leafCount);
        FoliageLodLevel level;
        std::vector<std::uint32_t> indices;
        for (std::uint32_t c = 0; c < data.clusters.size(); ++c)
        {
            if (c == 0 || data.clusters[c].material != data.clusters[c - 1].material)
                level.ranges.emplace_back(indices.size(), 0);
            state.forEachActive(c, [&](const FoliageLodEntry& e) {
                indices.insert(indices.end(), data.indices.begin() + e.firstIndex,
                               data.indices.begin() + e.firstIndex + e.indexCount);
            });
            level.ranges.back().second = indices.size() - level.ranges.back().first;
        }
        const bool wide = data.leafVertexCount > 65535;
        level.buffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
            wide ? Ogre::HardwareIndexBuffer::IT_32BIT : Ogre::HardwareIndexBuffer::IT_16BIT,
            std::max<std::size_t>(indices.size(), 1), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        if (wide)
            level.buffer->writeData(0, indices.size() * 4, indices.data(), true);
        else
        {
            std::vector<std::uint16_t> narrow(indices.begin(), indices.end());
            level.buffer->writeData(0, narrow.size() * 2, narrow.data(), true);
        }
        return mLevels.emplace(leafCount, std::move(level)).first->second;
    }

    std::uint64_t FoliageLodResources::getFoliageLodLevelBytes() const
    {
        std::uint64_t bytes = 0;
        for (const auto& level : mLevels)
            bytes += level.second.buffer->getSizeInBytes();
        return bytes;
    }

    std::uint64_t FoliageLodResources::getGpuBytes() const
    {
        std::uint64_t bytes = getFoliageLodLevelBytes();
        if (mLeafVertexData)
            for (const auto& binding : mLeafVertexData->vertexBufferBinding->getBindings())
                bytes += binding.second->getSizeInBytes();
        return bytes;
    }
}
