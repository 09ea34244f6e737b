#include "TreeLod/TreeAsset.h"

#include "TreeLod/FoliageLodState.h"
#include "TreeLod/TreeMeshBuilder.h"

#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgrePass.h>
#include <OgreResourceGroupManager.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <algorithm>

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
        for (Ogre::MeshPtr* mesh : {&mReferenceMesh, &mBarkMesh})
        {
            if (*mesh)
                Ogre::MeshManager::getSingleton().remove(*mesh);
            mesh->reset();
        }
        mFoliageLodLevels.clear();
        mLeafVertexData.reset();
        mFoliageLod.reset();
        mLeafVertexOrder.clear();
        for (const std::vector<Ogre::String>* names : {&mMaterialNames, &mShadowedMaterialNames})
            for (const Ogre::String& m : *names)
            {
                Ogre::MaterialManager::getSingleton().remove(m, mGroup);
                Ogre::MaterialManager::getSingleton().remove(m + "/Caster", mGroup);
            }
        mShadowedMaterialNames.clear();
        for (const Ogre::String& t : mTextureNames)
            Ogre::TextureManager::getSingleton().remove(t, mGroup);
        mMaterialNames.clear();
        mTextureNames.clear();
        mReference.reset();
        mPackage.reset();
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

    std::vector<std::uint8_t> TreeAsset::readChunk(const char* technique) const
    {
        const PackageReader& package = getPackage();
        int index = package.findChunk(technique, 0);
        if (index < 0)
            raise(fail(mName, chunkElement(technique, 0),
                       std::string("missing: bake the package with --technique ") + technique));
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
        if (mMaterialNames.empty())
            mMaterialNames = createMaterials("");
        return mMaterialNames;
    }

    const std::vector<Ogre::String>& TreeAsset::getShadowedMaterialNames()
    {
        if (mShadowedMaterialNames.empty())
            mShadowedMaterialNames = createMaterials("Shadowed");
        return mShadowedMaterialNames;
    }

    void TreeAsset::createTextures()
    {
        const ReferenceChunk& ref = getReference();
        const Ogre::String prefix = "TreeLod/" + mName + "/";

        // GPU-ready textures: RGBA8 with their baked mip chain, uploaded as they are.
        for (std::size_t t = 0; t < ref.textures.size(); ++t)
        {
            const GpuTexture& gpu = ref.textures[t];
            Ogre::Image image;
            image.loadDynamicImage(const_cast<Ogre::uchar*>(gpu.data.data()), gpu.width, gpu.height, 1,
                                   Ogre::PF_BYTE_RGBA, false, 1, gpu.mipCount > 0 ? gpu.mipCount - 1 : 0);
            const Ogre::String name = prefix + "texture" + std::to_string(t);
            Ogre::TextureManager::getSingleton().loadImage(name, mGroup, image, Ogre::TEX_TYPE_2D,
                                                           int(gpu.mipCount > 0 ? gpu.mipCount - 1 : 0));
            mTextureNames.push_back(name);
        }
    }

    std::vector<Ogre::String> TreeAsset::createMaterials(const Ogre::String& variant)
    {
        const ReferenceChunk& ref = getReference();
        if (mTextureNames.size() != ref.textures.size())
            createTextures();
        const Ogre::String prefix = "TreeLod/" + mName + "/";
        std::vector<Ogre::String> names;
        for (std::size_t i = 0; i < ref.model.materials.size(); ++i)
        {
            const Material& src = ref.model.materials[i];
            const Ogre::String base = (src.isLeaf ? "TreeLod/Leaf" : "TreeLod/Bark") + variant;
            Ogre::MaterialPtr parent = Ogre::MaterialManager::getSingleton().getByName(base, Ogre::RGN_DEFAULT);
            if (!parent)
                parent = Ogre::MaterialManager::getSingleton().getByName(base);
            if (!parent)
                OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                            "material '" + base + "' not found: add TreeLod's materials/ to a resource group",
                            "TreeAsset::createMaterials");
            const Ogre::String name = prefix + std::to_string(i) + (variant.empty() ? "" : "/" + variant);
            Ogre::MaterialPtr mat = parent->clone(name, true, mGroup);
            const Ogre::String texture = src.texture >= 0 ? mTextureNames[std::size_t(src.texture)] : "TreeLodWhite.png";
            glm::vec3 back = src.backColour == glm::vec3(0.0f) ? glm::vec3(src.baseColour) : src.backColour;

            auto configure = [&](const Ogre::MaterialPtr& m) {
                m->load();
                for (Ogre::Technique* tech : m->getTechniques())
                    for (Ogre::Pass* pass : tech->getPasses())
                    {
                        if (pass->getNumTextureUnitStates() > 0)
                            pass->getTextureUnitState(0)->setTextureName(texture);
                        if (!pass->hasFragmentProgram())
                            continue;
                        Ogre::GpuProgramParametersSharedPtr p = pass->getFragmentProgramParameters();
                        p->setIgnoreMissingParams(true);
                        p->setNamedConstant("baseColour", Ogre::ColourValue(src.baseColour.r, src.baseColour.g,
                                                                          src.baseColour.b, src.baseColour.a));
                        p->setNamedConstant("backColour", Ogre::ColourValue(back.r, back.g, back.b, 1.0f));
                        p->setNamedConstant("alphaCutoff", src.alphaCutoff);
                    }
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
        return names;
    }

    Ogre::MeshPtr TreeAsset::getBarkMesh()
    {
        if (!mBarkMesh)
        {
            TreeModel bark = getReference().model;
            bark.leafVertices.clear();
            bark.leafIndices.clear();
            bark.leaves.clear();
            mBarkMesh = buildTreeMesh(mName + "/bark", mGroup, bark, getMaterialNames());
        }
        return mBarkMesh;
    }

    const FoliageLodData& TreeAsset::getFoliageLod()
    {
        if (mFoliageLod)
            return *mFoliageLod;
        Result<FoliageLodData> data = decodeFoliageLodChunk(readChunk(FOLIAGE_LOD_CHUNK), mName);
        if (!data)
            raise(data.error());
        const TreeModel& model = getReference().model;
        if (data->leafVertexCount != model.leafVertices.size() || data->originalLeafCount != model.leaves.size())
            raise(fail(mName, chunkElement(FOLIAGE_LOD_CHUNK, 0),
                       "made for " + std::to_string(data->originalLeafCount) + " leaves / " +
                           std::to_string(data->leafVertexCount) + " vertices, the reference has " +
                           std::to_string(model.leaves.size()) + " / " + std::to_string(model.leafVertices.size())));
        for (const FoliageLodCluster& c : data->clusters)
            if (c.material >= model.materials.size() || !model.materials[c.material].isLeaf)
                raise(fail(mName, chunkElement(FOLIAGE_LOD_CHUNK, 0),
                           "cluster material " + std::to_string(c.material) + " is not a leaf material"));
        // Vertices in the order the clusters first use them, so that a draw's indices address
        // nearby vertices (GPU vertex caches; llvmpipe ran 20 % slower in the reference's order).
        std::vector<std::uint32_t> order(model.leafVertices.size(), ~0u);
        std::uint32_t next = 0;
        for (std::uint32_t& index : data->indices)
        {
            if (order[index] == ~0u)
                order[index] = next++;
            index = order[index];
        }
        mLeafVertexOrder.assign(model.leafVertices.size(), 0);
        for (std::uint32_t v = 0; v < order.size(); ++v)
            mLeafVertexOrder[order[v] == ~0u ? next++ : order[v]] = v;
        mFoliageLod = std::make_unique<FoliageLodData>(std::move(data.value()));
        return *mFoliageLod;
    }

    Ogre::VertexData* TreeAsset::getLeafVertexData()
    {
        if (!mLeafVertexData)
        {
            const std::vector<Vertex>& vertices = getReference().model.leafVertices;
            getFoliageLod(); // the order its indices were renumbered to
            std::vector<Vertex> ordered(vertices.size());
            for (std::size_t i = 0; i < ordered.size(); ++i)
                ordered[i] = vertices[mLeafVertexOrder[i]];
            mLeafVertexData.reset(makeTreeVertexData(ordered));
        }
        return mLeafVertexData.get();
    }

    const FoliageLodLevel& TreeAsset::getFoliageLodLevel(std::uint32_t leafCount)
    {
        const FoliageLodData& data = getFoliageLod();
        leafCount = std::clamp(leafCount, data.minLeafCount(), data.maxLeafCount());
        auto found = mFoliageLodLevels.find(leafCount);
        if (found != mFoliageLodLevels.end())
            return found->second;
        const FoliageLodState state = FoliageLodState::fromScratch(data, leafCount);
        FoliageLodLevel level;
        std::vector<std::uint32_t> indices;
        for (std::uint32_t c = 0; c < data.clusters.size(); ++c)
        {
            if (c == 0 || data.clusters[c].material != data.clusters[c - 1].material)
                level.ranges.emplace_back(indices.size(), 0);
            state.forEachActive(c, [&](const FoliageLodEntry& e) {
                indices.insert(indices.end(), data.indices.begin() + e.firstIndex,
                               data.indices.begin() + e.firstIndex + e.indexCount);
            });
            level.ranges.back().second = indices.size() - level.ranges.back().first;
        }
        const bool wide = data.leafVertexCount > 65535;
        level.buffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
            wide ? Ogre::HardwareIndexBuffer::IT_32BIT : Ogre::HardwareIndexBuffer::IT_16BIT,
            std::max<std::size_t>(indices.size(), 1), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        if (wide)
            level.buffer->writeData(0, indices.size() * 4, indices.data(), true);
        else
        {
            std::vector<std::uint16_t> narrow(indices.begin(), indices.end());
            level.buffer->writeData(0, narrow.size() * 2, narrow.data(), true);
        }
        return mFoliageLodLevels.emplace(leafCount, std::move(level)).first->second;
    }

    std::uint64_t TreeAsset::getFoliageLodLevelBytes() const
    {
        std::uint64_t bytes = 0;
        for (const auto& level : mFoliageLodLevels)
            bytes += level.second.buffer->getSizeInBytes();
        return bytes;
    }

    Ogre::MeshPtr TreeAsset::getReferenceMesh()
    {
        if (!mReferenceMesh)
        {
            const std::vector<Ogre::String>& materials = getMaterialNames();
            mReferenceMesh = buildTreeMesh(mName + "/reference", mGroup, getReference().model, materials);
        }
        return mReferenceMesh;
    }
}
