#include "TreeLod/FoliageLodTree.h"

#include "TreeLod/ObjectParams.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TreePart.h"

#include "TreeLod/FoliageLodResources.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/Wind.h"

#include <OgreCamera.h>
#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreMaterialManager.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreSceneManager.h>
#include <OgreStringConverter.h>
#include <OgreSubMesh.h>

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    /// One draw of a FoliageLodTree: a leaf material's regions, or a bark submesh.
    class FoliageLodTree::Part : public TreePart
    {
    public:
        Part(FoliageLodTree& parent, Ogre::VertexData* vertexData, const Ogre::String& material,
             const Ogre::String& shadowedMaterial)
            : TreePart(parent, parent.mAsset->getGroup(), vertexData, material, shadowedMaterial, "FoliageLodTree"),
              mParent(parent)
        {
            Wind::setTreeHeight(*this, Wind::treeHeight(parent.mAsset->getBounds()));
        }

    protected:
        bool useShadowedMaterials() const override { return mParent.useShadowedMaterials(); }
        unsigned short barkLodIndex() const override { return mParent.mBarkLodIndex; }

    private:
        FoliageLodTree& mParent;
    };

    const Ogre::String FoliageLodTreeFactory::FACTORY_TYPE_NAME = "FoliageLodTree";

    FoliageLodTree::FoliageLodTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options)
        : Ogre::MovableObject(name), mAsset(asset), mData(&FoliageLodResources::of(*asset).getFoliageLod()), mState(*mData), mOptions(options)
    {
        mBounds = mAsset->getBounds();
        // Ogre's convention (Mesh::_setBounds): a sphere about the object's origin holding the
        // box, so culling and pixel-count LoD see the same radius as an Entity of this tree.
        mRadius = Ogre::Math::boundingRadiusFromAABB(mBounds);
        mLodBias.strategy = mOptions.lodStrategy;
        const std::vector<Ogre::String>& materials = mAsset->getMaterialNames();
        const std::vector<Ogre::String>& shadowed = mAsset->getShadowedMaterialNames();

        if (!mData->clusters.empty())
        {
            Ogre::VertexData* vertices = FoliageLodResources::of(*mAsset).getLeafVertexData();
            const bool wide = vertices->vertexCount > 65535;
            if (!isQuantised())
                mIndexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                    wide ? Ogre::HardwareIndexBuffer::IT_32BIT : Ogre::HardwareIndexBuffer::IT_16BIT,
                    mData->slotCount(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            // One part per run of clusters with the same material (clusters are sorted by it).
            for (std::size_t c = 0; c < mData->clusters.size();)
            {
                const std::uint32_t material = mData->clusters[c].material;
                std::size_t end = c;
                while (end < mData->clusters.size() && mData->clusters[end].material == material)
                    ++end;
                auto part = std::make_unique<Part>(*this, vertices, materials[material], shadowed[material]);
                part->mIndexData.indexBuffer = mIndexBuffer;
                part->mIndexData.indexStart = mData->clusters[c].firstSlot;
                part->mIndexData.indexCount =
                    mData->clusters[end - 1].firstSlot + mData->clusters[end - 1].slotCount - mData->clusters[c].firstSlot;
                mLeafParts.push_back(std::move(part));
                c = end;
            }
            if (mOptions.fixedLeafCount > 0)
                mState.setLeafCount(mOptions.fixedLeafCount);
            if (isQuantised())
            {
                mState.setLeafCount(FoliageLodState::quantise(*mData, mState.leafCount(), mOptions.quantiseLevels));
                useSharedLevel();
            }
            else
                writeAllClusters();
        }

        if (!mAsset->getReference().model.barkIndices.empty())
        {
            mBarkMesh = mAsset->getBarkMesh();
            for (Ogre::SubMesh* sub : mBarkMesh->getSubMeshes())
            {
                const auto it = std::find(materials.begin(), materials.end(), sub->getMaterialName());
                const Ogre::String receiver = it == materials.end() ? "" : shadowed[std::size_t(it - materials.begin())];
                auto part = std::make_unique<Part>(*this, sub->vertexData, sub->getMaterialName(), receiver);
                part->mLevels.push_back(sub->indexData);
                for (Ogre::IndexData* level : sub->mLodFaceList)
                    part->mLevels.push_back(level);
                mBarkParts.push_back(std::move(part));
            }
        }
        mStats.leafCount = mState.leafCount();
    }

    FoliageLodTree::~FoliageLodTree() = default;

    const Ogre::String& FoliageLodTree::getMovableType() const { return FoliageLodTreeFactory::FACTORY_TYPE_NAME; }

    void FoliageLodTree::writeAllClusters()
    {
        const std::size_t indexSize = mIndexBuffer->getIndexSize();
        std::vector<std::uint8_t> all(std::size_t(mData->slotCount()) * indexSize);
        for (std::uint32_t c = 0; c < mData->clusters.size(); ++c)
            writeRegion(c, all.data() + std::size_t(mData->clusters[c].firstSlot) * indexSize);
        mIndexBuffer->writeData(0, all.size(), all.data(), true);
    }

    void FoliageLodTree::writeRegion(std::uint32_t cluster, std::uint8_t* at) const
    {
        if (mIndexBuffer->getType() == Ogre::HardwareIndexBuffer::IT_32BIT)
            mState.writeCluster(cluster, reinterpret_cast<std::uint32_t*>(at));
        else
            mState.writeCluster(cluster, reinterpret_cast<std::uint16_t*>(at));
    }

    void FoliageLodTree::useSharedLevel()
    {
        const FoliageLodLevel& level = FoliageLodResources::of(*mAsset).getFoliageLodLevel(mState.leafCount());
        for (std::size_t i = 0; i < mLeafParts.size(); ++i)
        {
            mLeafParts[i]->mIndexData.indexBuffer = level.buffer;
            mLeafParts[i]->mIndexData.indexStart = level.ranges[i].first;
            mLeafParts[i]->mIndexData.indexCount = level.ranges[i].second;
        }
    }

    std::uint32_t FoliageLodTree::updateLeafCount(std::uint32_t count)
    {
        if (isQuantised())
            count = FoliageLodState::quantise(*mData, count, mOptions.quantiseLevels);
        const std::uint32_t target = std::clamp(count, mData->minLeafCount(), mData->maxLeafCount());
        if (mLeafParts.empty() || target == mState.leafCount())
            return 0;
        if (isQuantised())
        {
            // A shared level: point the parts at it, upload nothing.
            mState.setLeafCount(target);
            useSharedLevel();
            mStats.clustersWritten = 0;
            mStats.bytesUploaded = 0;
            mStats.writeCalls = 0;
            mStats.leafCount = target;
            ++mStats.changes;
            return 0;
        }
        // §3.3: update the state; §4: send only the changed clusters' regions.
        mState.setLeafCount(target);
        std::vector<std::uint32_t>& changed = mChanged; // reused: no allocation per change
        changed.assign(mState.changedClusters().begin(), mState.changedClusters().end());
        std::sort(changed.begin(), changed.end());
        const std::size_t indexSize = mIndexBuffer->getIndexSize();
        mStats.clustersWritten = std::uint32_t(changed.size());
        mStats.bytesUploaded = 0;
        mStats.writeCalls = 0;
        for (std::size_t i = 0; i < changed.size();)
        {
            // Merge runs of adjacent regions into one write.
            std::size_t end = i + 1;
            while (end < changed.size() && changed[end] == changed[end - 1] + 1)
                ++end;
            const FoliageLodCluster& first = mData->clusters[changed[i]];
            const FoliageLodCluster& last = mData->clusters[changed[end - 1]];
            const std::size_t slots = last.firstSlot + last.slotCount - first.firstSlot;
            mScratch.resize(slots * indexSize);
            for (std::size_t k = i; k < end; ++k)
                writeRegion(changed[k],
                            mScratch.data() + (mData->clusters[changed[k]].firstSlot - first.firstSlot) * indexSize);
            mIndexBuffer->writeData(first.firstSlot * indexSize, mScratch.size(), mScratch.data(), false);
            mStats.bytesUploaded += mScratch.size();
            ++mStats.writeCalls;
            i = end;
        }
        mStats.totalBytesUploaded += mStats.bytesUploaded;
        mStats.leafCount = mState.leafCount();
        ++mStats.changes;
        return mStats.clustersWritten;
    }

    std::uint32_t FoliageLodTree::leafCountForPixels(Ogre::Real pixels, Ogre::Real bias) const
    {
        return leafCountOnCurve(*mData, Ogre::Real(double(pixels) * double(bias)), mOptions.pixelsPerLeaf);
    }

    std::uint32_t FoliageLodTree::leafCountOnCurve(const FoliageLodData& data, Ogre::Real pixels, float pixelsPerLeaf)
    {
        const double leaves = std::max(0.0, double(pixels) / double(pixelsPerLeaf));
        return std::uint32_t(std::clamp(std::ceil(leaves), double(data.minLeafCount()), double(data.maxLeafCount())));
    }

    Ogre::Real FoliageLodTree::pixelCountForLeaves(std::uint32_t leaves, float pixelsPerLeaf)
    {
        // ceil(pixels / pixelsPerLeaf) <= leaves  <=>  pixels <= leaves * pixelsPerLeaf.
        return Ogre::Real(double(leaves) * double(pixelsPerLeaf));
    }

    void FoliageLodTree::setFixedLeafCount(std::uint32_t count)
    {
        mOptions.fixedLeafCount = count;
        if (count > 0)
            updateLeafCount(count);
    }

    void FoliageLodTree::setPixelsPerLeaf(float pixelsPerLeaf)
    {
        if (!(pixelsPerLeaf > 0.0f) || !std::isfinite(pixelsPerLeaf))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "pixelsPerLeaf must be a positive number, got " + std::to_string(pixelsPerLeaf),
                        "FoliageLodTree '" + mName + "'");
        mOptions.pixelsPerLeaf = pixelsPerLeaf;
    }


    void FoliageLodTree::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        if (!mParentNode)
            return;
        // Through the strategies, as an Entity: the LoD camera (the viewer's for shadow cameras)
        // and its bias are in the values.
        if (mBarkMesh)
            mBarkLodIndex = mLodBias.meshLodIndex(*mBarkMesh, *this, camera);
        for (auto* parts : {&mBarkParts, &mLeafParts})
            for (const std::unique_ptr<Part>& part : *parts)
                part->updateMaterialLod(mLodBias, camera);
        if (mOptions.fixedLeafCount > 0)
            updateLeafCount(mOptions.fixedLeafCount);
        else
            updateLeafCount(leafCountForPixels(ScreenSizeLodStrategy::pixelCountOf(mLodBias.screenSize(*this, camera))));
    }

    void FoliageLodTree::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)
    {
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "FoliageLodTree '" + mName + "'");
    }

    void FoliageLodTree::setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                            unsigned short minDetailIndex)
    {
        mLodBias.setMaterial(factor, maxDetailIndex, minDetailIndex, "FoliageLodTree '" + mName + "'");
    }

    bool FoliageLodTree::useShadowedMaterials()
    {
        return receivesDepthShadows(mManager);
    }

    void FoliageLodTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        for (auto* parts : {&mBarkParts, &mLeafParts})
            for (const std::unique_ptr<Part>& part : *parts)
                queue->addRenderable(part.get(), mRenderQueueID, mRenderQueuePriority);
    }

    void FoliageLodTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (auto* parts : {&mBarkParts, &mLeafParts})
            for (const std::unique_ptr<Part>& part : *parts)
                visitor->visit(part.get(), 0, false);
    }

    FoliageLodTree::Options FoliageLodTreeFactory::parseOptions(const Ogre::NameValuePairList* params)
    {
        FoliageLodTree::Options options;
        const ObjectParams p(params, "FoliageLodTreeFactory");
        double v = 0.0;
        if (p.number("leaves", 0.0, 4294967295.0, v))
            options.fixedLeafCount = std::uint32_t(v);
        if (p.number("pixelsPerLeaf", 1e-6, 1e9, v))
            options.pixelsPerLeaf = float(v);
        if (p.number("quantise", 0.0, 1024.0, v))
            options.quantiseLevels = std::uint32_t(v);
        options.lodStrategy = ObjectLodBias::strategyParam(p);
        return options;
    }

    Ogre::MovableObject* FoliageLodTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                  const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "FoliageLodTreeFactory::createInstanceImpl");
        TreeAssetPtr tree = p.loadAsset(name, "FoliageLodTree");
        return new FoliageLodTree(name, tree, parseOptions(params));
    }
}
