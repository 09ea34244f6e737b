// TreeAsset: an Ogre resource for one *.treelod package.
//
// Loading reads the package's header and chunk table only (checksummed, see Package.h); the
// reference (the polygonal tree, chunk "reference") is decoded on first use, and each technique
// keeps what it builds for the asset (decoded chunks, buffers, textures, materials) in its own
// TechniqueResources, made on first use through getResources and destroyed when the asset
// unloads. A scene pays only for the techniques and levels it draws.
// Errors (bad package, missing chunk) throw Ogre::InvalidParametersException whose text
// names the resource, the chunk and the reason.
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreAxisAlignedBox.h>
#include <OgreMesh.h>
#include <OgreResource.h>

#include <functional>
#include <list>
#include <memory>
#include <utility>
#include <vector>

namespace TreeLod
{
    class TreeAsset : public Ogre::Resource
    {
    public:
        TreeAsset(Ogre::ResourceManager* creator, const Ogre::String& name, Ogre::ResourceHandle handle,
                  const Ogre::String& group, bool isManual = false, Ogre::ManualResourceLoader* loader = nullptr);
        ~TreeAsset() override;

        /// Use these package bytes instead of opening the resource by name (for trees
        /// baked in memory, e.g. by `treelod render tree.glb`). Call before load().
        void setPackageBytes(std::vector<std::uint8_t> bytes);

        /// The package (valid after load()).
        const PackageReader& getPackage() const;
        bool hasChunk(const Ogre::String& technique, std::uint32_t level = 0) const;

        /// The decoded polygonal reference (decoded on first call).
        const ReferenceChunk& getReference();
        /// The polygonal reference as an Ogre mesh "<asset>/reference" with its materials
        /// and textures (built on first call). See TreeMeshBuilder. Throws when the reference has no
        /// polygons (a tree baked from photographs, ModelChunk.h hasPolygons).
        Ogre::MeshPtr getReferenceMesh();

        /// The bark alone as an Ogre mesh "<asset>/bark" with its MeshLodGenerator levels
        /// (techniques that draw their own foliage use it). Built on first call.
        Ogre::MeshPtr getBarkMesh();

        /// The resources of technique `key` for this asset (a technique's chunk name, or its own key):
        /// made by `create` on first call, then the same object until the asset unloads.
        template <typename T> T& getResources(const Ogre::String& key, const std::function<std::unique_ptr<T>()>& create)
        {
            return static_cast<T&>(getResources(key, std::function<std::unique_ptr<TechniqueResources>()>(
                                                         [&create]() -> std::unique_ptr<TechniqueResources> {
                                                             return create();
                                                         })));
        }
        TechniqueResources& getResources(const Ogre::String& key,
                                         const std::function<std::unique_ptr<TechniqueResources>()>& create);
        /// GPU bytes of every technique's resources built so far (TechniqueResources::getGpuBytes).
        std::uint64_t getTechniqueGpuBytes() const;

        /// Local bounds of the tree in metres (from the reference chunk).
        Ogre::AxisAlignedBox getBounds();

        /// Names of the materials made for model material i ("TreeLod/<asset>/<i>").
        const std::vector<Ogre::String>& getMaterialNames();
        /// The same materials receiving texture shadows ("TreeLod/<asset>/<i>/Shadowed", clones
        /// of TreeLod/BarkShadowed and TreeLod/LeafShadowed): for scenes with an integrated
        /// texture shadow technique.
        const std::vector<Ogre::String>& getShadowedMaterialNames();

        // ---- for techniques building their resources ----
        /// Level `level` of chunk `technique`, CRC-checked, its format version one the registered
        /// TechniqueDescriptor reads (readsFormatVersion); throws naming the asset, the chunk and
        /// what to do.
        std::vector<std::uint8_t> readChunk(const Ogre::String& technique, std::uint32_t level = 0) const;
        /// The format version of that chunk (for a technique that reads older versions too); throws
        /// as readChunk when it is missing.
        std::uint32_t getChunkFormatVersion(const Ogre::String& technique, std::uint32_t level = 0) const;
        /// Throw Ogre::InvalidParametersException with `error`'s message, from this asset.
        [[noreturn]] void raise(const Error& error) const;
        /// Clones of `barkBase` and `leafBase`, one per model material, named
        /// "TreeLod/<asset>/<i><suffix>", textures and constants set, shadow casters cloned too; an
        /// empty `leafBase` makes the bark's only (leaf entries empty: for a mesh of the bark alone).
        /// The clones are removed on unload. The model's textures are uploaded as materials use them.
        const std::vector<Ogre::String>& getModelMaterials(const Ogre::String& barkBase, const Ogre::String& leafBase,
                                                           const Ogre::String& suffix);
        /// The bark of the reference alone as mesh `name` in the asset's group, with
        /// MeshLodGenerator levels (bark AO as vertex colour when given). The caller removes it.
        Ogre::MeshPtr buildBarkMesh(const Ogre::String& name, const std::vector<Ogre::String>& materials,
                                    const std::vector<std::uint8_t>& barkAo);

    protected:
        void loadImpl() override;
        void unloadImpl() override;
        size_t calculateSize() const override;

    private:
        /// The Ogre texture of the model's texture `t` (< the reference's textures), uploaded on first use.
        const Ogre::String& textureName(std::size_t t);

        std::vector<std::uint8_t> mManualBytes;
        std::unique_ptr<PackageReader> mPackage;
        std::unique_ptr<ReferenceChunk> mReference;
        Ogre::MeshPtr mReferenceMesh;
        Ogre::MeshPtr mBarkMesh;
        std::vector<Ogre::String> mTextureNames;
        /// Model material clones by suffix ("" plain, "/Shadowed", ...), in creation order.
        std::list<std::pair<Ogre::String, std::vector<Ogre::String>>> mModelMaterials; ///< stable references
        /// Technique resources in creation order (destroyed in reverse).
        std::vector<std::pair<Ogre::String, std::unique_ptr<TechniqueResources>>> mResources;
    };

    typedef Ogre::SharedPtr<TreeAsset> TreeAssetPtr;
}
