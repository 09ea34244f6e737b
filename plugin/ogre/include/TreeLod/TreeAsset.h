// TreeAsset: an Ogre resource for one *.treelod package.
//
// Loading reads the package's header and chunk table only (checksummed, see Package.h);
// each technique's chunk is decoded and uploaded on first use, so a scene pays only for
// the techniques and levels it draws ("model only what a scene requires").
// Errors (bad package, missing chunk) throw Ogre::InvalidParametersException whose text
// names the resource, the chunk and the reason.
#pragma once

#include "TreeLod/FoliageLodData.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreMesh.h>
#include <OgreResource.h>

#include <map>
#include <memory>
#include <vector>

namespace TreeLod
{
    /// One LoDF level shared by every quantised FoliageLodTree of an asset: the active leaves'
    /// indices packed (no padding), one range per run of same-material clusters, in the order
    /// of FoliageLodTree's leaf parts. Built once, never rewritten: instances switch between
    /// levels by pointing at another one, so they upload nothing and can be instanced.
    struct FoliageLodLevel
    {
        Ogre::HardwareIndexBufferSharedPtr buffer;
        std::vector<std::pair<std::size_t, std::size_t>> ranges; ///< (start, count) per leaf part
    };

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
        /// and textures (built on first call). See TreeMeshBuilder.
        Ogre::MeshPtr getReferenceMesh();

        /// The bark alone as an Ogre mesh "<asset>/bark" with its MeshLodGenerator levels
        /// (techniques that draw their own foliage use it). Built on first call.
        Ogre::MeshPtr getBarkMesh();

        /// The LoDF foliage of chunk "lodf" (decoded on first call, checked against the
        /// reference). Its indices are renumbered to address getLeafVertexData().
        const FoliageLodData& getFoliageLod();
        /// The reference chunk's leaf vertices on the GPU, once for every instance, in the
        /// order the LoDF clusters first use them.
        Ogre::VertexData* getLeafVertexData();
        /// The shared LoDF level with `leafCount` leaves (clamped), built on first use.
        const FoliageLodLevel& getFoliageLodLevel(std::uint32_t leafCount);
        /// Shared levels built so far, and the bytes they take on the GPU.
        std::size_t getFoliageLodLevelCount() const { return mFoliageLodLevels.size(); }
        std::uint64_t getFoliageLodLevelBytes() const;

        /// Local bounds of the tree in metres (from the reference chunk).
        Ogre::AxisAlignedBox getBounds();

        /// Names of the materials made for model material i ("TreeLod/<asset>/<i>").
        const std::vector<Ogre::String>& getMaterialNames();
        /// The same materials receiving texture shadows ("TreeLod/<asset>/<i>/Shadowed", clones
        /// of TreeLod/BarkShadowed and TreeLod/LeafShadowed): for scenes with an integrated
        /// texture shadow technique.
        const std::vector<Ogre::String>& getShadowedMaterialNames();

    protected:
        void loadImpl() override;
        void unloadImpl() override;
        size_t calculateSize() const override;

    private:
        void createTextures();
        /// Clones of TreeLod/Bark<variant> and TreeLod/Leaf<variant>, one per model material.
        std::vector<Ogre::String> createMaterials(const Ogre::String& variant);
        [[noreturn]] void raise(const Error& error) const;
        /// Level 0 of chunk `technique`, CRC-checked; throws naming what is missing or broken.
        std::vector<std::uint8_t> readChunk(const char* technique) const;

        std::vector<std::uint8_t> mManualBytes;
        std::unique_ptr<PackageReader> mPackage;
        std::unique_ptr<ReferenceChunk> mReference;
        Ogre::MeshPtr mReferenceMesh;
        Ogre::MeshPtr mBarkMesh;
        std::unique_ptr<FoliageLodData> mFoliageLod;
        std::unique_ptr<Ogre::VertexData> mLeafVertexData;
        std::vector<std::uint32_t> mLeafVertexOrder;
        std::map<std::uint32_t, FoliageLodLevel> mFoliageLodLevels; ///< GPU vertex i = reference leaf vertex mLeafVertexOrder[i]
        std::vector<Ogre::String> mShadowedMaterialNames;
        std::vector<Ogre::String> mMaterialNames;
        std::vector<Ogre::String> mTextureNames;
    };

    typedef Ogre::SharedPtr<TreeAsset> TreeAssetPtr;
}
