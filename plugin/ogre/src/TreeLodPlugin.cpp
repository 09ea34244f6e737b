#include "TreeLod/TreeLodPlugin.h"

#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

#include <MeshLodGenerator/OgreMeshLodGenerator.h>
#include <OgreLogManager.h>

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
        delete mLodGenerator;
        mLodGenerator = nullptr;
        mAssetManager.reset();
        mTechniques.reset();
    }
}
