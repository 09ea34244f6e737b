#include "TreeLod/TreeAssetManager.h"

#include <OgreException.h>
#include <OgreResourceGroupManager.h>

#include <fstream>
#include <iterator>

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

    TreeAssetPtr TreeAssetManager::require(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                                           const Ogre::String& group)
    {
        if (!mBaker)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE,
                        "'" + source + "': no baker registered (TreeAssetManager::setBaker), cannot bake on demand",
                        "TreeAssetManager::require");
        const Ogre::String path = mBaker->requirePackage(source, techniques);
        const Ogre::String name = path.substr(path.find_last_of('/') + 1);
        if (TreeAssetPtr existing = getByName(name, group))
        {
            bool complete = existing->isLoaded();
            for (const Ogre::String& technique : techniques)
                complete = complete && existing->hasChunk(technique);
            if (complete)
                return existing;
            remove(existing); // the cache rewrote the package with more chunks
        }
        std::ifstream in(path, std::ios::binary);
        if (!in)
            OGRE_EXCEPT(Ogre::Exception::ERR_FILE_NOT_FOUND,
                        "'" + source + "': baked package '" + path + "' cannot be opened", "TreeAssetManager::require");
        std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        return loadFromBytes(name, group, std::move(bytes));
    }

    Ogre::Resource* TreeAssetManager::createImpl(const Ogre::String& name, Ogre::ResourceHandle handle,
                                                 const Ogre::String& group, bool isManual,
                                                 Ogre::ManualResourceLoader* loader, const Ogre::NameValuePairList*)
    {
        return new TreeAsset(this, name, handle, group, isManual, loader);
    }
}
