#include "TreeLod/TreeAssetManager.h"

#include <OgreResourceGroupManager.h>

template <> TreeLod::TreeAssetManager* Ogre::Singleton<TreeLod::TreeAssetManager>::msSingleton = nullptr;

namespace TreeLod
{
    TreeAssetManager& TreeAssetManager::getSingleton() { return *msSingleton; }
    TreeAssetManager* TreeAssetManager::getSingletonPtr() { return msSingleton; }

    TreeAssetManager::TreeAssetManager()
    {
        mResourceType = "TreeAsset";
        mLoadOrder = 250.0f; // after materials (100) and meshes (200)
        Ogre::ResourceGroupManager::getSingleton()._registerResourceManager(mResourceType, this);
    }

    TreeAssetManager::~TreeAssetManager()
    {
        Ogre::ResourceGroupManager::getSingleton()._unregisterResourceManager(mResourceType);
    }

    TreeAssetPtr TreeAssetManager::create(const Ogre::String& name, const Ogre::String& group)
    {
        return Ogre::static_pointer_cast<TreeAsset>(createResource(name, group));
    }

    TreeAssetPtr TreeAssetManager::load(const Ogre::String& name, const Ogre::String& group)
    {
        TreeAssetPtr asset = Ogre::static_pointer_cast<TreeAsset>(createOrRetrieve(name, group).first);
        asset->load();
        return asset;
    }

    TreeAssetPtr TreeAssetManager::getByName(const Ogre::String& name, const Ogre::String& group)
    {
        return Ogre::static_pointer_cast<TreeAsset>(getResourceByName(name, group));
    }

    TreeAssetPtr TreeAssetManager::loadFromBytes(const Ogre::String& name, const Ogre::String& group,
                                                 std::vector<std::uint8_t> packageBytes)
    {
        TreeAssetPtr asset = create(name, group);
        asset->setPackageBytes(std::move(packageBytes));
        asset->load();
        return asset;
    }

    Ogre::Resource* TreeAssetManager::createImpl(const Ogre::String& name, Ogre::ResourceHandle handle,
                                                 const Ogre::String& group, bool isManual,
                                                 Ogre::ManualResourceLoader* loader, const Ogre::NameValuePairList*)
    {
        return new TreeAsset(this, name, handle, group, isManual, loader);
    }
}
