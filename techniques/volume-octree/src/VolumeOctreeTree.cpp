// VolumeOctreeTree: the volumetric octree tree (Linz et al. 2006); the rules are in
// VolumeOctreeTree.h, the per-cell decisions in techniques/volume-octree/media/GLSL/TreeLodVolumeOctree.vert.
#include "TreeLod/VolumeOctreeTree.h"

#include "TreeLod/ObjectParams.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TreePart.h"
#include "TreeLod/Wind.h"

#include <OgreCamera.h>
#include <OgreHardwareBufferManager.h>
#include <OgreNode.h>
#include <OgreRenderQueue.h>
#include <OgreSceneManager.h>
#include <OgreViewport.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    class VolumeOctreeTree::Part : public TreePart
    {
    public:
        Part(VolumeOctreeTree& parent, const Ogre::String& group, Ogre::VertexData* vertexData,
             const Ogre::String& material)
            : TreePart(parent, group, vertexData, material, "", "VolumeOctreeTree")
        {
            Wind::setTreeHeight(*this, Wind::treeHeight(parent.mAsset->getBounds()));
        }

    protected:
        bool useShadowedMaterials() const override { return false; }
        unsigned short barkLodIndex() const override { return 0; }
    };

    const Ogre::String VolumeOctreeTreeFactory::FACTORY_TYPE_NAME = "VolumeOctreeTree";

    VolumeOctreeTree::VolumeOctreeTree(const Ogre::String& name, const TreeAssetPtr& asset, const Options& options)
        : Ogre::MovableObject(name), mAsset(asset), mData(&VolumeOctreeResources::of(*asset).getData()),
          mGpu(&VolumeOctreeResources::of(*asset).getGpu()),
          mCellOrders(&VolumeOctreeResources::of(*asset).getCellOrders()), mOptions(options)
    {
        mLodBias.setMesh(mOptions.lodBias, 0, 99, "VolumeOctreeTree '" + name + "'");
        mLodBias.strategy = mOptions.lodStrategy;
        mTransition.set(mOptions.lodTransition, "VolumeOctreeTree '" + name + "'");
        if (mOptions.level >= 0 && std::uint32_t(mOptions.level) >= mData->levelCount)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "parameter 'level': " + std::to_string(mOptions.level) + " is not a level of the octree (" +
                            std::to_string(mData->levelCount) + " levels)",
                        "VolumeOctreeTree '" + name + "'");
        mPart = std::make_unique<Part>(*this, mAsset->getGroup(), mGpu->vertexData.get(), mGpu->material);
        std::size_t most = 0;
        for (std::uint32_t l = 0; l < mData->levelCount; ++l)
            most = std::max<std::size_t>(most, mData->levelCellCounts[l] + (l ? mData->levelCellCounts[l - 1] : 0));
        mIndexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
            Ogre::HardwareIndexBuffer::IT_32BIT, std::max<std::size_t>(6 * most, 6),
            Ogre::HardwareBuffer::HBU_DYNAMIC_WRITE_ONLY_DISCARDABLE);
        mPart->mIndexData.indexBuffer = mIndexBuffer;
        mRadius = Ogre::Math::boundingRadiusFromAABB(mGpu->bounds);
        order(0, mOptions.level >= 0 ? std::uint32_t(mOptions.level) : mData->levelCount - 1);
        mActive = mOrderedActive;
    }

    VolumeOctreeTree::~VolumeOctreeTree() = default;

    const Ogre::String& VolumeOctreeTree::getMovableType() const { return VolumeOctreeTreeFactory::FACTORY_TYPE_NAME; }

    std::size_t VolumeOctreeTree::getDrawnCellCount() const { return mPart->mIndexData.indexCount / 6; }

    void VolumeOctreeTree::order(std::uint32_t octant, std::uint32_t active)
    {
        if (octant == mOctant && active == mOrderedActive)
            return;
        mOctant = octant;
        mOrderedActive = active;
        std::vector<std::uint32_t> indices;
        for (std::uint32_t level = active == 0 ? 0 : active - 1; level <= active; ++level)
        {
            const std::uint32_t first = mData->firstCell(level);
            for (std::uint32_t i : (*mCellOrders)[level][octant])
            {
                const std::uint32_t v = 4 * (first + i);
                indices.insert(indices.end(), {v, v + 1, v + 2, v, v + 2, v + 3});
            }
        }
        if (!indices.empty())
            mIndexBuffer->writeData(0, indices.size() * sizeof(std::uint32_t), indices.data(), true);
        mPart->mIndexData.indexStart = 0;
        mPart->mIndexData.indexCount = indices.size();
    }

    void VolumeOctreeTree::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        if (!mParentNode)
            return;
        const Ogre::Affine3& toWorld = _getParentNodeFullTransform();
        const Ogre::Affine3 toModel = toWorld.inverse();
        const glm::vec3 centre = mData->origin + 0.5f * mData->size;
        Ogre::Vector3 towards;
        if (camera->getProjectionType() == Ogre::PT_PERSPECTIVE)
            towards = toModel * camera->getDerivedPosition() - Ogre::Vector3(centre.x, centre.y, centre.z);
        else
            towards = -(toModel.linear() * camera->getDerivedDirection());
        towards.normalise();
        mPair = volumeOctreeCameraPair(mData->cameraDirections, glm::vec3(towards.x, towards.y, towards.z));
        // Transitions per cell (the vertex program): a cell is drawn from the plane to half its depth,
        // where its children take over, a range of 2 in screen size.
        const float bandEnd = mOptions.level < 0 ? transitionBandEnd(mTransition.length, 2.0f) : 1.0f;
        const Ogre::Vector3 position = mParentNode->_getDerivedPosition();
        const float shift = transitionPatternShift({position.x, position.y, position.z});
        if (mManager && mManager->_getCurrentRenderStage() == Ogre::SceneManager::IRS_RENDER_TO_TEXTURE)
        {
            // A shadow camera: the cameras nearest the light; the viewer's levels and order stay (a
            // depth caster needs no order), the active level everywhere (no plane).
            mPart->setCustomParameter(0, Ogre::Vector4(float(mOrderedActive), std::numeric_limits<float>::max(),
                                                       mPair.firstWeight, 1.0f - mPair.firstWeight));
            mPart->setCustomParameter(1, Ogre::Vector4(float(mPair.first), float(mPair.second), bandEnd, shift));
            return;
        }
        const std::uint32_t octant = volumeOctreeOctant(glm::vec3(-towards.x, -towards.y, -towards.z));

        // The active level, per cell as §3.1 has it, at the pixel scale read through
        // treelod_screen_size (the LoD camera's, the viewer's for shadow cameras, with its bias and
        // the mesh factor): r_px / radius pixels per metre at the node's depth.
        const Ogre::Camera* lod = camera->getLodCamera();
        const Ogre::Real radiusPx = ScreenSizeLodStrategy::radiusInPixels(mLodBias.screenSize(*this, camera));
        const Ogre::Real radius = getBoundingRadiusScaled();
        const Ogre::Vector3 scale = mParentNode->_getDerivedScale();
        const float s = std::max({std::abs(scale.x), std::abs(scale.y), std::abs(scale.z)});
        const Ogre::Affine3 view = lod->getViewMatrix();
        float nearest = std::numeric_limits<float>::max();
        for (int k = 0; k < 8; ++k)
        {
            const glm::vec3 corner = mData->origin + mData->size * glm::vec3(k & 1, (k >> 1) & 1, k >> 2);
            nearest = std::min(nearest, -(view * (toWorld * Ogre::Vector3(corner.x, corner.y, corner.z))).z);
        }
        nearest = std::max(nearest, 1e-6f);
        const bool perspective = lod->getProjectionType() == Ogre::PT_PERSPECTIVE;
        // What volumeOctreeActiveLevel takes: the focal length in pixels (perspective), or pixels
        // per metre times `nearest` (orthographic).
        float focal = std::numeric_limits<float>::max();
        if (radiusPx < std::numeric_limits<Ogre::Real>::max() && radius > 0.0f)
            focal = float(radiusPx / radius) *
                    (perspective ? std::sqrt(float(mParentNode->getSquaredViewDepth(lod))) : nearest);
        std::uint32_t active = mOptions.level >= 0 ? std::uint32_t(mOptions.level)
                                                   : volumeOctreeActiveLevel(*mData, nearest, focal * s, mOptions.lodPixels);
        if (mOptions.level < 0)
        {
            // Detail index 0 is the finest level (levelCount - 1).
            const std::uint32_t last = mData->levelCount - 1;
            active = last - std::min<std::uint32_t>(mLodBias.clampMesh(Ogre::ushort(last - active)), last);
        }
        mActive = active;
        const float plane = perspective && focal < std::numeric_limits<float>::max()
                                ? volumeOctreePlaneDepth(mData->cellEdge(mActive) * s, focal, mOptions.lodPixels)
                                : std::numeric_limits<float>::max();
        mPlaneDepth = plane;
        mPart->updateMaterialLod(mLodBias, camera);
        order(octant, mActive);
        mPart->setCustomParameter(0, Ogre::Vector4(float(mActive), plane, mPair.firstWeight, 1.0f - mPair.firstWeight));
        mPart->setCustomParameter(1, Ogre::Vector4(float(mPair.first), float(mPair.second), bandEnd, shift));
    }

    void VolumeOctreeTree::setLodTransition(Ogre::Real length)
    {
        mTransition.set(length, "VolumeOctreeTree '" + mName + "'");
    }

    void VolumeOctreeTree::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                          unsigned short minDetailIndex)
    {
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "VolumeOctreeTree '" + mName + "'");
    }

    void VolumeOctreeTree::setMaterialLodBias(Ogre::Real factor, unsigned short maxDetailIndex,
                                              unsigned short minDetailIndex)
    {
        mLodBias.setMaterial(factor, maxDetailIndex, minDetailIndex, "VolumeOctreeTree '" + mName + "'");
    }

    void VolumeOctreeTree::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        if (mPart->mIndexData.indexCount > 0)
            queue->addRenderable(mPart.get(), mRenderQueueID, mRenderQueuePriority);
    }

    void VolumeOctreeTree::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        visitor->visit(mPart.get(), 0, false);
    }

    Ogre::MovableObject* VolumeOctreeTreeFactory::createInstanceImpl(const Ogre::String& name,
                                                                     const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "VolumeOctreeTreeFactory::createInstanceImpl");
        VolumeOctreeTree::Options options;
        double value = 0.0;
        if (p.number("level", 0.0, double(VOLUME_OCTREE_MAX_LEVELS - 1), value))
        {
            if (value != std::floor(value))
                p.bad("level", *p.find("level"), "a whole number");
            options.level = int(value);
        }
        if (p.number("lodBias", 1e-6, 1e6, value))
            options.lodBias = float(value);
        options.lodStrategy = ObjectLodBias::strategyParam(p);
        if (p.number("lodPixels", 1e-3, 1e6, value))
            options.lodPixels = float(value);
        ObjectTransition::param(p, options.lodTransition);
        return new VolumeOctreeTree(name, p.loadAsset(name, "VolumeOctreeTree"), options);
    }
}
