#include "TreeLod/TreeLodPlugin.h"

#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/Forest.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

#include <MeshLodGenerator/OgreMeshLodGenerator.h>
#include <OgreLogManager.h>
#include <OgreRoot.h>

namespace TreeLod
{
    TreeLodPlugin::TreeLodPlugin() = default;
    TreeLodPlugin::~TreeLodPlugin() = default;

    const Ogre::String& TreeLodPlugin::getName() const
    {
        static const Ogre::String name = "TreeLod";
        return name;
    }

    void TreeLodPlugin::install()
    {
        mTechniques = std::make_unique<TechniqueRegistry>();
        mAssetManager = std::make_unique<TreeAssetManager>();
        // One MovableObject factory per technique (DESIGN.md, "Factories").
        mFoliageLodFactory = std::make_unique<FoliageLodTreeFactory>();
        Ogre::Root::getSingleton().addMovableObjectFactory(mFoliageLodFactory.get());
        mBillboardCloudFactory = std::make_unique<BillboardCloudTreeFactory>();
        Ogre::Root::getSingleton().addMovableObjectFactory(mBillboardCloudFactory.get());
        mForestFactory = std::make_unique<ForestFactory>();
        Ogre::Root::getSingleton().addMovableObjectFactory(mForestFactory.get());
        Ogre::LogManager::getSingleton().logMessage("TreeLod: installed (techniques: " +
                                                    mTechniques->describe() + ")");
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
        if (mFoliageLodFactory)
            Ogre::Root::getSingleton().removeMovableObjectFactory(mFoliageLodFactory.get());
        mFoliageLodFactory.reset();
        if (mBillboardCloudFactory)
            Ogre::Root::getSingleton().removeMovableObjectFactory(mBillboardCloudFactory.get());
        mBillboardCloudFactory.reset();
        if (mForestFactory)
            Ogre::Root::getSingleton().removeMovableObjectFactory(mForestFactory.get());
        mForestFactory.reset();
        delete mLodGenerator;
        mLodGenerator = nullptr;
        mAssetManager.reset();
        mTechniques.reset();
    }
}
