// TreeAssetManager: the ResourceManager for TreeAsset ("TreeAsset", *.treelod).
// Packages are found through resource groups like meshes:
//   TreeAssetManager::getSingleton().load("oak.treelod", "General")
//
// Baking off the frame path: requireAsync runs the registered TreeBaker on a worker
// thread and returns at once; the render thread polls TreeAssetRequest::isReady() and then get()s
// the asset (loading the package: header and chunk table only, TreeAsset.h). Bakes run one at a
// time (require() waits for a running one); the baker must not call Ogre's render-thread APIs
// (CacheTreeBaker does not) and must outlive them: setBaker and the destructor wait for them.
#pragma once

#include "TreeLod/TreeAsset.h"
#include "TreeLod/TreeBaker.h"

#include <OgreResourceManager.h>
#include <OgreSingleton.h>

#include <future>
#include <memory>
#include <mutex>
#include <optional>

namespace TreeLod
{
    /// A bake TreeAssetManager::requireAsync started. Dropping it does not wait for the bake.
    class TreeAssetRequest
    {
    public:
        const Ogre::String& getSource() const { return mSource; }
        /// The bake has ended (the package is there, or the bake failed).
        bool isReady() const;
        /// On the render thread: the asset, loaded from the baked package (waits for the bake
        /// when it has not ended). Throws what the baker threw, naming the source, or the loader's
        /// error; every call returns the same asset or throws the same error.
        TreeAssetPtr get();

    private:
        friend class TreeAssetManager;
        Ogre::String mSource, mGroup;
        std::vector<Ogre::String> mTechniques;
        std::shared_future<Ogre::String> mPath; ///< the baker's answer
        TreeAssetPtr mAsset;
    };

    /// How block-compressed textures (GpuTextureFormat DXT1, DXT5, BC4, BC5) of a package reach the GPU.
    enum class CompressedTextureUpload
    {
        AsStored, ///< as baked: the texture unit decodes them (every GPU)
        Decoded   ///< decoded to RGBA8 at load (decodeGpuTexture): for renderers that sample RGBA8 faster
    };

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

        /// The baker require() asks (not owned; nullptr = none). See TreeBaker.h. Waits for the
        /// bakes requireAsync started, so the previous baker may be destroyed once this returns.
        void setBaker(TreeBaker* baker);
        TreeBaker* getBaker() const { return mBaker; }

        /// Lazy baking: the asset for `source` holding the chunks of `techniques`, baked by the
        /// registered baker if missing, loaded into `group` under the package's file name (a
        /// second call for more techniques reloads it). Throws Ogre::InvalidStateException when
        /// no baker is registered, else what the baker or the loader throws.
        TreeAssetPtr require(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                             const Ogre::String& group);
        /// require() with the bake on a worker thread (see the file comment). Throws
        /// Ogre::InvalidStateException at once when no baker is registered.
        std::shared_ptr<TreeAssetRequest> requireAsync(const Ogre::String& source,
                                                       const std::vector<Ogre::String>& techniques,
                                                       const Ogre::String& group);

        /// The user's choice for textures uploaded from now on (already uploaded ones stay as they
        /// are), which a calibration's measured choice (adoptMeasuredTextureUpload) does not change;
        /// nullopt forgets it. The environment variable TREELOD_COMPRESSED_TEXTURES ("as-stored" or
        /// "decoded") makes the same choice when the manager is created.
        void setCompressedTextureUpload(std::optional<CompressedTextureUpload> upload);
        /// The choice measured on this renderer (LevelCalibration.h: sampling a compressed texture
        /// against the same texture decoded); the user's choice wins. AsStored until either.
        void adoptMeasuredTextureUpload(CompressedTextureUpload upload) { mMeasuredTextureUpload = upload; }
        /// The user's choice, else the measured one, else AsStored.
        CompressedTextureUpload getCompressedTextureUpload() const
        {
            return mChosenTextureUpload ? *mChosenTextureUpload : mMeasuredTextureUpload;
        }
        /// Whether the user chose (setCompressedTextureUpload or the environment variable).
        bool isCompressedTextureUploadChosen() const { return mChosenTextureUpload.has_value(); }
        /// Whether `texture` is decoded to RGBA8 before upload: a block format under
        /// CompressedTextureUpload::Decoded, or one the render system cannot sample (no
        /// RSC_TEXTURE_COMPRESSION_DXT for DXT1/DXT5, no RSC_TEXTURE_COMPRESSION_BC4_BC5 for
        /// BC4/BC5), or, under OpenGL ES, a block format with more than one mip level but fewer
        /// than the full chain (OGRE 1.12's GLES2 render system drew those black; one level and
        /// full chains draw: test rendersystem.GLES2).
        bool decodesAtLoad(const GpuTexture& texture) const;

        static TreeAssetManager& getSingleton();
        static TreeAssetManager* getSingletonPtr();

    protected:
        Ogre::Resource* createImpl(const Ogre::String& name, Ogre::ResourceHandle handle, const Ogre::String& group,
                                   bool isManual, Ogre::ManualResourceLoader* loader,
                                   const Ogre::NameValuePairList* params) override;

    private:
        friend class TreeAssetRequest;
        TreeBaker& baker(const Ogre::String& source) const; ///< throws when none is registered
        /// The asset of package `path` baked for `source` (reused when it holds `techniques`).
        TreeAssetPtr loadBaked(const Ogre::String& source, const std::vector<Ogre::String>& techniques,
                               const Ogre::String& path, const Ogre::String& group);

        TreeBaker* mBaker = nullptr;
        std::optional<CompressedTextureUpload> mChosenTextureUpload;
        CompressedTextureUpload mMeasuredTextureUpload = CompressedTextureUpload::AsStored;
        std::mutex mBakeMutex; ///< one bake at a time
        std::vector<std::shared_future<Ogre::String>> mBakes; ///< running or ended; waited for at destruction
    };
}
