// TreeLodPlugin: the Ogre::Plugin of TreeLod (Plugin_TreeLod.so).
//
// install: creates the TreeAsset resource manager (resource type "TreeAsset", files
// *.treelod found through resource groups like meshes) and the technique registry.
// initialise: creates the MeshLodGenerator singleton if the application has none.
// shutdown/uninstall undo the same in reverse order.
#pragma once

#include <OgrePlugin.h>

#include <memory>

namespace Ogre
{
    class MeshLodGenerator;
}

namespace TreeLod
{
    class BillboardCloudTreeFactory;
    class FoliageLodTreeFactory;
    class ForestFactory;
    class TreeAssetManager;
    class TechniqueRegistry;

    class TreeLodPlugin : public Ogre::Plugin
    {
    public:
        TreeLodPlugin();
        ~TreeLodPlugin() override;

        const Ogre::String& getName() const override;
        void install() override;
        void initialise() override;
        void shutdown() override;
        void uninstall() override;

    private:
        std::unique_ptr<TreeAssetManager> mAssetManager;
        std::unique_ptr<TechniqueRegistry> mTechniques;
        std::unique_ptr<FoliageLodTreeFactory> mFoliageLodFactory;
        std::unique_ptr<BillboardCloudTreeFactory> mBillboardCloudFactory;
        std::unique_ptr<ForestFactory> mForestFactory;
        Ogre::MeshLodGenerator* mLodGenerator = nullptr; ///< owned only when we created it
    };
}
