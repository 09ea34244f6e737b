#include "TreeLod/TreeLodPlugin.h"

#include "TreeLod/Forest.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/Wind.h"

#include <MeshLodGenerator/OgreMeshLodGenerator.h>
#include <OgreLodStrategyManager.h>
#include <OgreGpuProgramManager.h>
#include <OgreLogManager.h>
#include <OgreResourceGroupManager.h>
#include <OgreRoot.h>

#include <algorithm>

namespace TreeLod
{
    /// Creates the shared parameters (the casters', the wind's) before the first script that may
    /// reference them is parsed (the render system, which owns the GpuProgramManager, exists by then).
    class TreeLodPlugin::ShadowParamsListener : public Ogre::ResourceGroupListener
    {
    public:
        void scriptParseStarted(const Ogre::String&, bool&) override
        {
            if (Ogre::GpuProgramManager::getSingletonPtr())
            {
                createShadowParams();
                Wind::updateSharedParameters();
            }
        }
    };

    TreeLodPlugin::TreeLodPlugin() = default;
    TreeLodPlugin::~TreeLodPlugin() = default;

    const Ogre::String& TreeLodPlugin::getName() const
    {
        static const Ogre::String name = "TreeLod";
        return name;
    }

    void TreeLodPlugin::install()
    {
        mAssetManager = std::make_unique<TreeAssetManager>();
        // Before any script is parsed: materials and meshes may name it.
        mScreenSizeStrategy = std::make_unique<ScreenSizeLodStrategy>();
        Ogre::LodStrategyManager::getSingleton().addStrategy(mScreenSizeStrategy.get());
        mShadowParamsListener = std::make_unique<ShadowParamsListener>();
        Ogre::ResourceGroupManager::getSingleton().addResourceGroupListener(mShadowParamsListener.get());
        // One MovableObject factory per technique (docs/architecture.md, "Factories"), some shared.
        for (const TechniqueInfo& technique : TechniqueRegistry::getSingleton().getTechniques())
        {
            Ogre::MovableObjectFactory* factory = technique.factory.get();
            if (factory && std::find(mFactories.begin(), mFactories.end(), factory) == mFactories.end())
            {
                Ogre::Root::getSingleton().addMovableObjectFactory(factory);
                mFactories.push_back(factory);
            }
        }
        mForestFactory = std::make_unique<ForestFactory>();
        Ogre::Root::getSingleton().addMovableObjectFactory(mForestFactory.get());
        Ogre::LogManager::getSingleton().logMessage("TreeLod: installed (techniques: " +
                                                    TechniqueRegistry::getSingleton().describe() + ")");
    }

    void TreeLodPlugin::initialise()
    {
        if (!Ogre::MeshLodGenerator::getSingletonPtr())
            mLodGenerator = new Ogre::MeshLodGenerator();
    }

    void TreeLodPlugin::shutdown()
    {
        if (mAssetManager)
            mAssetManager->removeAll();
    }

    void TreeLodPlugin::uninstall()
    {
        for (Ogre::MovableObjectFactory* factory : mFactories)
            Ogre::Root::getSingleton().removeMovableObjectFactory(factory);
        mFactories.clear();
        if (mForestFactory)
            Ogre::Root::getSingleton().removeMovableObjectFactory(mForestFactory.get());
        mForestFactory.reset();
        delete mLodGenerator;
        mLodGenerator = nullptr;
        mAssetManager.reset();
        if (mScreenSizeStrategy)
            Ogre::LodStrategyManager::getSingleton().removeStrategy(ScreenSizeLodStrategy::NAME);
        mScreenSizeStrategy.reset();
        if (mShadowParamsListener)
            Ogre::ResourceGroupManager::getSingleton().removeResourceGroupListener(mShadowParamsListener.get());
        mShadowParamsListener.reset();
    }
}
