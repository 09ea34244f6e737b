#include "TreeLod/TreeAsset.h"

#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TechniqueDescriptor.h"
#include "TreeLod/TreeMeshBuilder.h"

#include <OgreException.h>
#include <OgreGpuProgramParams.h>
#include <OgreHardwareBufferManager.h>
#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgrePass.h>
#include <OgreResourceGroupManager.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

namespace TreeLod
{
    TreeAsset::TreeAsset(Ogre::ResourceManager* creator, const Ogre::String& name, Ogre::ResourceHandle handle,
                         const Ogre::String& group, bool isManual, Ogre::ManualResourceLoader* loader)
        : Ogre::Resource(creator, name, handle, group, isManual, loader)
    {
    }

    TreeAsset::~TreeAsset() { unload(); }

    void TreeAsset::setPackageBytes(std::vector<std::uint8_t> bytes) { mManualBytes = std::move(bytes); }

    void TreeAsset::raise(const Error& error) const
    {
        OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, error.message(), "TreeAsset '" + mName + "'");
    }

    void TreeAsset::loadImpl()
    {
        std::vector<std::uint8_t> bytes = mManualBytes;
        if (bytes.empty())
        {
            Ogre::DataStreamPtr stream = Ogre::ResourceGroupManager::getSingleton().openResource(mName, mGroup, this);
            bytes.resize(stream->size());
            if (!bytes.empty() && stream->read(bytes.data(), bytes.size()) != bytes.size())
                raise(fail(mName, "", "short read from resource stream"));
        }
        Result<PackageReader> package = PackageReader::fromMemory(std::move(bytes), mName);
        if (!package)
            raise(package.error());
        mPackage = std::make_unique<PackageReader>(std::move(package.value()));
    }

    void TreeAsset::unloadImpl()
    {
        // Techniques first, newest first: their meshes and materials may use the reference's.
        while (!mResources.empty())
            mResources.pop_back();
        for (Ogre::MeshPtr* mesh : {&mReferenceMesh, &mBarkMesh})
        {
            if (*mesh)
                Ogre::MeshManager::getSingleton().remove(*mesh);
            mesh->reset();
        }
        for (const auto& [suffix, names] : mModelMaterials)
            for (const Ogre::String& m : names)
                if (!m.empty() && (suffix.empty() || Ogre::StringUtil::endsWith(m, suffix, false)))
                {
                    Ogre::MaterialManager::getSingleton().remove(m, mGroup);
                    Ogre::MaterialManager::getSingleton().remove(m + "/Caster", mGroup);
                }
        mModelMaterials.clear();
        for (const Ogre::String& t : mTextureNames)
            if (!t.empty())
                Ogre::TextureManager::getSingleton().remove(t, mGroup);
        mTextureNames.clear();
        mReference.reset();
        mPackage.reset();
    }

    TechniqueResources& TreeAsset::getResources(const Ogre::String& key,
                                                const std::function<std::unique_ptr<TechniqueResources>()>& create)
    {
        for (const auto& entry : mResources)
            if (entry.first == key)
                return *entry.second;
        getPackage(); // loaded
        std::unique_ptr<TechniqueResources> resources = create();
        OgreAssert(resources, "a technique's create function returned nothing");
        mResources.emplace_back(key, std::move(resources));
        return *mResources.back().second;
    }

    std::uint64_t TreeAsset::getTechniqueGpuBytes() const
    {
        std::uint64_t bytes = 0;
        for (const auto& entry : mResources)
            bytes += entry.second->getGpuBytes();
        return bytes;
    }

    size_t TreeAsset::calculateSize() const { return mPackage ? size_t(mPackage->fileSize()) : 0; }

    const PackageReader& TreeAsset::getPackage() const
    {
        if (!mPackage)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE, "TreeAsset '" + mName + "' is not loaded",
                        "TreeAsset::getPackage");
        return *mPackage;
    }

    bool TreeAsset::hasChunk(const Ogre::String& technique, std::uint32_t level) const
    {
        return getPackage().findChunk(technique, level) >= 0;
    }

    std::uint32_t TreeAsset::getChunkFormatVersion(const Ogre::String& technique, std::uint32_t level) const
    {
        const PackageReader& package = getPackage();
        const int index = package.findChunk(technique, level);
        if (index < 0)
            raise(fail(mName, chunkElement(technique, level), "missing: bake the package with --technique " + technique));
        return package.chunks()[std::size_t(index)].formatVersion;
    }

    std::vector<std::uint8_t> TreeAsset::readChunk(const Ogre::String& technique, std::uint32_t level) const
    {
        const PackageReader& package = getPackage();
        const std::uint32_t version = getChunkFormatVersion(technique, level);
        const int index = package.findChunk(technique, level);
        const TechniqueDescriptor* descriptor = findTechniqueDescriptor(technique);
        if (descriptor && !readsFormatVersion(*descriptor, version))
            raise(fail(mName, chunkElement(technique, level),
                       "format version " + std::to_string(version) + ", this build reads " +
                           readFormatVersions(*descriptor) + ": bake the package again"));
        Result<std::vector<std::uint8_t>> bytes = package.readChunk(std::size_t(index));
        if (!bytes)
            raise(bytes.error());
        return std::move(bytes.value());
    }

    const ReferenceChunk& TreeAsset::getReference()
    {
        if (mReference)
            return *mReference;
        Result<ReferenceChunk> chunk = decodeReferenceChunk(readChunk(REFERENCE_CHUNK), mName);
        if (!chunk)
            raise(chunk.error());
        mReference = std::make_unique<ReferenceChunk>(std::move(chunk.value()));
        return *mReference;
    }

    Ogre::AxisAlignedBox TreeAsset::getBounds()
    {
        const TreeModel& m = getReference().model;
        return Ogre::AxisAlignedBox(m.boundsMin.x, m.boundsMin.y, m.boundsMin.z, m.boundsMax.x, m.boundsMax.y,
                                    m.boundsMax.z);
    }

    const std::vector<Ogre::String>& TreeAsset::getMaterialNames()
    {
        return getModelMaterials("TreeLod/Bark", "TreeLod/Leaf", "");
    }

    const std::vector<Ogre::String>& TreeAsset::getShadowedMaterialNames()
    {
        return getModelMaterials("TreeLod/BarkShadowed", "TreeLod/LeafShadowed", "/Shadowed");
    }

    const Ogre::String& TreeAsset::textureName(std::size_t t)
    {
        // GPU-ready textures: RGBA8 with their baked mip chain, uploaded as they are, on first use
        // (a technique drawing the bark alone loads no leaf texture).
        const ReferenceChunk& ref = getReference();
        mTextureNames.resize(ref.textures.size());
        if (mTextureNames[t].empty())
        {
            const GpuTexture& gpu = ref.textures[t];
            const Ogre::String name = "TreeLod/" + mName + "/texture" + std::to_string(t);
            uploadTexture(name, mGroup, gpu.data.data(), gpu.width, gpu.height, Ogre::PF_BYTE_RGBA, gpu.mipCount);
            mTextureNames[t] = name;
        }
        return mTextureNames[t];
    }

    const std::vector<Ogre::String>& TreeAsset::getModelMaterials(const Ogre::String& barkBase,
                                                                  const Ogre::String& leafBase,
                                                                  const Ogre::String& suffix)
    {
        for (const auto& entry : mModelMaterials)
            if (entry.first == suffix)
                return entry.second;
        const ReferenceChunk& ref = getReference();
        const Ogre::String prefix = "TreeLod/" + mName + "/";
        std::vector<Ogre::String> names;
        for (std::size_t i = 0; i < ref.model.materials.size(); ++i)
        {
            const Material& src = ref.model.materials[i];
            if (src.isLeaf && leafBase.empty())
            {
                names.emplace_back(); // bark materials only
                continue;
            }
            const Ogre::String name = prefix + std::to_string(i) + suffix;
            Ogre::MaterialPtr mat = cloneBaseMaterial(src.isLeaf ? leafBase : barkBase, name, mGroup, mName);
            const Ogre::String texture = src.texture >= 0 ? textureName(std::size_t(src.texture)) : "TreeLodWhite.png";
            glm::vec3 back = src.backColour == glm::vec3(0.0f) ? glm::vec3(src.baseColour) : src.backColour;

            auto configure = [&](const Ogre::MaterialPtr& m) {
                configureModelMaterial(m, texture,
                                       Ogre::ColourValue(src.baseColour.r, src.baseColour.g, src.baseColour.b,
                                                         src.baseColour.a),
                                       Ogre::ColourValue(back.r, back.g, back.b, 1.0f), src.alphaCutoff);
            };
            configure(mat);
            // The shadow caster alpha-tests the same texture.
            Ogre::Technique* tech = mat->getTechnique(0);
            if (Ogre::MaterialPtr caster = tech->getShadowCasterMaterial())
            {
                Ogre::MaterialPtr own = caster->clone(name + "/Caster", true, mGroup);
                configure(own);
                tech->setShadowCasterMaterial(own);
            }
            names.push_back(name);
        }
        mModelMaterials.emplace_back(suffix, std::move(names));
        return mModelMaterials.back().second;
    }

    Ogre::MeshPtr TreeAsset::buildBarkMesh(const Ogre::String& name, const std::vector<Ogre::String>& materials,
                                           const std::vector<std::uint8_t>& barkAo)
    {
        TreeModel bark = getReference().model;
        bark.leafVertices.clear();
        bark.leafIndices.clear();
        bark.leaves.clear();
        MeshBuildOptions options;
        options.barkVertexAo = barkAo;
        return buildTreeMesh(name, mGroup, bark, materials, options);
    }

    Ogre::MeshPtr TreeAsset::getBarkMesh()
    {
        if (!mBarkMesh)
            mBarkMesh = buildBarkMesh(mName + "/bark", getMaterialNames(), {});
        return mBarkMesh;
    }

    Ogre::MeshPtr TreeAsset::getReferenceMesh()
    {
        if (!mReferenceMesh)
        {
            if (Result<void> polygons = requirePolygons(getReference().model, mName, "technique 'mesh'"); !polygons)
                raise(polygons.error());
            const std::vector<Ogre::String>& materials = getMaterialNames();
            mReferenceMesh = buildTreeMesh(mName + "/reference", mGroup, getReference().model, materials);
        }
        return mReferenceMesh;
    }
}
