// TreeAsset: an Ogre resource for one *.treelod package.
//
// Loading reads the package's header and chunk table only (checksummed, see Package.h);
// each technique's chunk is decoded and uploaded on first use, so a scene pays only for
// the techniques and levels it draws ("model only what a scene requires").
// Errors (bad package, missing chunk) throw Ogre::InvalidParametersException whose text
// names the resource, the chunk and the reason.
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"

#include <OgreMesh.h>
#include <OgreResource.h>

#include <memory>
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
        /// and textures (built on first call). See TreeMeshBuilder.
        Ogre::MeshPtr getReferenceMesh();

        /// Local bounds of the tree in metres (from the reference chunk).
        Ogre::AxisAlignedBox getBounds();

        /// Names of the materials made for model material i ("TreeLod/<asset>/<i>").
        const std::vector<Ogre::String>& getMaterialNames();

    protected:
        void loadImpl() override;
        void unloadImpl() override;
        size_t calculateSize() const override;

    private:
        void createMaterials();
        [[noreturn]] void raise(const Error& error) const;

        std::vector<std::uint8_t> mManualBytes;
        std::unique_ptr<PackageReader> mPackage;
        std::unique_ptr<ReferenceChunk> mReference;
        Ogre::MeshPtr mReferenceMesh;
        std::vector<Ogre::String> mMaterialNames;
        std::vector<Ogre::String> mTextureNames;
    };

    typedef Ogre::SharedPtr<TreeAsset> TreeAssetPtr;
}
