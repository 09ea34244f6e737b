// TreeAssetManager: the ResourceManager for TreeAsset ("TreeAsset", *.treelod).
// Packages are found through resource groups like meshes:
//   TreeAssetManager::getSingleton().load("oak.treelod", "General")
#pragma once

#include "TreeLod/TreeAsset.h"
#include "TreeLod/TreeBaker.h"

#include <OgreResourceManager.h>
#include <OgreSingleton.h>

namespace TreeLod
{
    class TreeAssetManager : public Ogre::ResourceManager, public Ogre::Singleton<TreeAssetManager>
    {
    public:
        TreeAssetManager();
        ~TreeAssetManager() override;

        TreeAssetPtr create(const Ogre::String& name, const Ogre::String& group);
        TreeAssetPtr load(const Ogre::String& name, const Ogre::String& group);
        TreeAssetPtr getByName(const Ogre::String& name,
                               const Ogre::String& group = Ogre::ResourceGroupManager::AUTODETECT_RESOURCE_GROUP_NAME);

        /// Create and load an asset from package bytes held in memory.
        TreeAssetPtr loadFromBytes(const Ogre::String& name, const Ogre::String& group,
                                   std::vector<std::uint8_t> packageBytes);

        /// The baker require() asks (not owned; nullptr = none). See TreeBaker.h.
        void setBaker(TreeBaker* baker) { mBaker = baker; }
        TreeBaker* getBaker() const { return mBaker; }

        /// Lazy baking: the asset for `source` holding the chunks of `techniques`, baked by the
        /// registered baker if missing, loaded into `group` under the package's file name (a
        /// second call for more techniques reloads it). Throws Ogre::InvalidStateException when
        /// no baker is registered, else what the baker or the loader throws.
        TreeAssetPtr require(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                             const Ogre::String& group);

        static TreeAssetManager& getSingleton();
        static TreeAssetManager* getSingletonPtr();

    protected:
        Ogre::Resource* createImpl(const Ogre::String& name, Ogre::ResourceHandle handle, const Ogre::String& group,
                                   bool isManual, Ogre::ManualResourceLoader* loader,
                                   const Ogre::NameValuePairList* params) override;

    private:
        TreeBaker* mBaker = nullptr;
    };
}
