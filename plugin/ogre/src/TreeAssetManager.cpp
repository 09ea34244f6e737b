#include "TreeLod/TreeAssetManager.h"

#include <OgreException.h>
#include <OgreLogManager.h>
#include <OgreRenderSystem.h>
#include <OgreRenderSystemCapabilities.h>
#include <OgreResourceGroupManager.h>
#include <OgreRoot.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
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
        if (const char* env = std::getenv("TREELOD_COMPRESSED_TEXTURES"); env && *env)
        {
            const std::string value = env;
            if (value == "as-stored" || value == "decoded")
                setCompressedTextureUpload(value == "decoded" ? CompressedTextureUpload::Decoded
                                                              : CompressedTextureUpload::AsStored);
            else if (Ogre::LogManager* log = Ogre::LogManager::getSingletonPtr())
                log->logWarning("TreeLod: TREELOD_COMPRESSED_TEXTURES='" + value +
                                "' is neither 'as-stored' nor 'decoded'; ignored");
        }
    }

    void TreeAssetManager::setCompressedTextureUpload(std::optional<CompressedTextureUpload> upload)
    {
        mChosenTextureUpload = upload;
    }

    bool TreeAssetManager::decodesAtLoad(const GpuTexture& texture) const
    {
        const GpuTextureFormat format = texture.format;
        if (!isBlockCompressed(format))
            return false;
        if (getCompressedTextureUpload() == CompressedTextureUpload::Decoded)
            return true;
        const Ogre::RenderSystem* system =
            Ogre::Root::getSingletonPtr() ? Ogre::Root::getSingleton().getRenderSystem() : nullptr;
        const Ogre::RenderSystemCapabilities* caps = system ? system->getCapabilities() : nullptr;
        if (!caps)
            return false;
        const bool rgtc = format == GpuTextureFormat::BC4 || format == GpuTextureFormat::BC5;
        if (!caps->hasCapability(rgtc ? Ogre::RSC_TEXTURE_COMPRESSION_BC4_BC5 : Ogre::RSC_TEXTURE_COMPRESSION_DXT))
            return true;
        const bool es = system->getName().find("OpenGL ES") != Ogre::String::npos;
        return es && texture.mipCount > 1 && texture.mipCount < fullMipCount(texture.width, texture.height);
    }

    TreeAssetManager::~TreeAssetManager()
    {
        for (const std::shared_future<Ogre::String>& bake : mBakes)
            bake.wait();
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

    void TreeAssetManager::setBaker(TreeBaker* baker)
    {
        for (const std::shared_future<Ogre::String>& bake : mBakes)
            bake.wait();
        mBakes.clear();
        mBaker = baker;
    }

    TreeBaker& TreeAssetManager::baker(const Ogre::String& source) const
    {
        if (!mBaker)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE,
                        "'" + source + "': no baker registered (TreeAssetManager::setBaker), cannot bake on demand",
                        "TreeAssetManager::require");
        return *mBaker;
    }

    TreeAssetPtr TreeAssetManager::require(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                                           const Ogre::String& group)
    {
        TreeBaker& registered = baker(source);
        Ogre::String path;
        {
            std::lock_guard<std::mutex> lock(mBakeMutex);
            path = registered.requirePackage(source, techniques);
        }
        return loadBaked(source, techniques, path, group);
    }

    std::shared_ptr<TreeAssetRequest> TreeAssetManager::requireAsync(const Ogre::String& source,
                                                                     const std::vector<Ogre::String>& techniques,
                                                                     const Ogre::String& group)
    {
        TreeBaker* registered = &baker(source);
        auto request = std::make_shared<TreeAssetRequest>();
        request->mSource = source;
        request->mGroup = group;
        request->mTechniques = techniques;
        std::mutex* mutex = &mBakeMutex;
        request->mPath = std::async(std::launch::async, [registered, mutex, source, techniques] {
                             std::lock_guard<std::mutex> lock(*mutex);
                             return registered->requirePackage(source, techniques);
                         }).share();
        // Kept here too: the last copy of an async future waits in its destructor, so a dropped
        // request must not hold it. Ended bakes are forgotten.
        mBakes.erase(std::remove_if(mBakes.begin(), mBakes.end(),
                                    [](const std::shared_future<Ogre::String>& f) {
                                        return f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
                                    }),
                     mBakes.end());
        mBakes.push_back(request->mPath);
        return request;
    }

    bool TreeAssetRequest::isReady() const
    {
        return mPath.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    }

    TreeAssetPtr TreeAssetRequest::get()
    {
        if (!mAsset)
            mAsset = TreeAssetManager::getSingleton().loadBaked(mSource, mTechniques, mPath.get(), mGroup);
        return mAsset;
    }

    TreeAssetPtr TreeAssetManager::loadBaked(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                                             const Ogre::String& path, const Ogre::String& group)
    {
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
