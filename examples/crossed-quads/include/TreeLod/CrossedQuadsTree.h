// CrossedQuadsTree: a tree drawn as its crossed quads (chunk "crossed-quads", CrossedQuadsData.h).
// MovableObject type "CrossedQuadsTree", made by CrossedQuadsTreeFactory.
//
// One Renderable per quad (each quad has its own texture and so its own material), drawn
// non-instanced with the plain leaf material clones of CrossedQuadsResources; under an
// integrated texture shadow technique the shadow-receiving clones. Bounds: the quads' box.
//
// Parameters (createMovableObject params, or the registry): asset (required), group (default:
// autodetect).
#pragma once

#include "TreeLod/TreeAsset.h"

#include <OgreMovableObject.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    struct CrossedQuadsGpu;

    class CrossedQuadsTree : public Ogre::MovableObject
    {
    public:
        /// Builds the asset's quads on first use; throws naming the asset when it has none.
        CrossedQuadsTree(const Ogre::String& name, const TreeAssetPtr& asset);
        ~CrossedQuadsTree() override;

        const TreeAssetPtr& getAsset() const { return mAsset; }
        std::size_t getQuadCount() const { return mParts.size(); }

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

    private:
        class Part;

        TreeAssetPtr mAsset;
        std::vector<std::unique_ptr<Part>> mParts;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
    };

    class CrossedQuadsTreeFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name, const Ogre::NameValuePairList* params) override;
    };
}
