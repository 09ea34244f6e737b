// TreeLodPlugin: the Ogre::Plugin of TreeLod (Plugin_TreeLod.so).
//
// install: creates the TreeAsset resource manager (resource type "TreeAsset", files
// *.treelod found through resource groups like meshes), registers ScreenSizeLodStrategy
// ("treelod_screen_size") with Ogre::LodStrategyManager, and adds the MovableObject factory of
// every technique in the TechniqueRegistry and the Forest's to Ogre::Root, and has the shadow
// casters' shared parameters created before scripts are parsed (ShadowSetup.h).
// initialise: creates the MeshLodGenerator singleton if the application has none.
// shutdown/uninstall undo the same in reverse order.
#pragma once

#include <OgrePlugin.h>

#include <memory>
#include <vector>

namespace Ogre
{
    class MeshLodGenerator;
    class MovableObjectFactory;
}

namespace TreeLod
{
    class ForestFactory;
    class ScreenSizeLodStrategy;
    class TreeAssetManager;

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
        class ShadowParamsListener;
        std::unique_ptr<TreeAssetManager> mAssetManager;
        std::unique_ptr<ScreenSizeLodStrategy> mScreenSizeStrategy; ///< registered by install()
        std::vector<Ogre::MovableObjectFactory*> mFactories; ///< added to Root by install(), owned by the registry
        std::unique_ptr<ForestFactory> mForestFactory;
        std::unique_ptr<ShadowParamsListener> mShadowParamsListener; ///< a ResourceGroupListener
        Ogre::MeshLodGenerator* mLodGenerator = nullptr; ///< owned only when we created it
    };
}
