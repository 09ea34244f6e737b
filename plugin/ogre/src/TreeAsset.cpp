#include "TreeLod/TreeAsset.h"

#include "TreeAssetSupport.h"
#include "TreeLod/FoliageLodState.h"
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
        for (Ogre::MeshPtr* mesh : {&mReferenceMesh, &mBarkMesh})
        {
            if (*mesh)
                Ogre::MeshManager::getSingleton().remove(*mesh);
            mesh->reset();
        }
        for (Ogre::MeshPtr& mesh : mBarkAoMeshes)
        {
            if (mesh)
                Ogre::MeshManager::getSingleton().remove(mesh);
            mesh.reset();
        }
        for (std::unique_ptr<BillboardCloudGpu>& gpu : mBillboardCloudGpus)
        {
            if (!gpu)
                continue;
            for (const Ogre::String& m : gpu->materials)
                Ogre::MaterialManager::getSingleton().remove(m, mGroup);
            for (const Ogre::String& t : gpu->textures)
                Ogre::TextureManager::getSingleton().remove(t, mGroup);
            gpu.reset();
        }
        for (std::unique_ptr<BillboardCloudData>& data : mBillboardClouds)
            data.reset();
        for (std::unique_ptr<BillboardCloudGpu>& layout : mBillboardCloudLayouts)
            layout.reset();
        if (mImpostorGpu)
        {
            const ImpostorGpu& gpu = *mImpostorGpu;
            for (const Ogre::String& m : {gpu.material, gpu.shadowedMaterial, gpu.material + "/Caster"})
                Ogre::MaterialManager::getSingleton().remove(m, mGroup);
            for (const Ogre::String& t : {gpu.texture, gpu.normalTexture})
                Ogre::TextureManager::getSingleton().remove(t, mGroup);
            mImpostorGpu.reset();
        }
        for (std::vector<Ogre::String>& names : mBarkAoMaterialNames)
        {
            for (const Ogre::String& m : names)
                if (m.find("/BarkAo") != Ogre::String::npos) // leaf entries are the plain materials
                {
                    Ogre::MaterialManager::getSingleton().remove(m, mGroup);
                    Ogre::MaterialManager::getSingleton().remove(m + "/Caster", mGroup);
                }
            names.clear();
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
            mMaterialNames = createMaterials("TreeLod/Bark", "TreeLod/Leaf", "");
        return mMaterialNames;
    }

    const std::vector<Ogre::String>& TreeAsset::getShadowedMaterialNames()
    {
        if (mShadowedMaterialNames.empty())
            mShadowedMaterialNames = createMaterials("TreeLod/BarkShadowed", "TreeLod/LeafShadowed", "/Shadowed");
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
            const Ogre::String name = prefix + "texture" + std::to_string(t);
            uploadTexture(name, mGroup, gpu.data.data(), gpu.width, gpu.height, Ogre::PF_BYTE_RGBA, gpu.mipCount);
            mTextureNames.push_back(name);
        }
    }

    std::vector<Ogre::String> TreeAsset::createMaterials(const Ogre::String& barkBase, const Ogre::String& leafBase,
                                                         const Ogre::String& suffix)
    {
        const ReferenceChunk& ref = getReference();
        if (mTextureNames.size() != ref.textures.size())
            createTextures();
        const Ogre::String prefix = "TreeLod/" + mName + "/";
        std::vector<Ogre::String> names;
        for (std::size_t i = 0; i < ref.model.materials.size(); ++i)
        {
            const Material& src = ref.model.materials[i];
            if (src.isLeaf && leafBase.empty())
            {
                names.push_back(getMaterialNames()[i]);
                continue;
            }
            const Ogre::String name = prefix + std::to_string(i) + suffix;
            Ogre::MaterialPtr mat = cloneBaseMaterial(src.isLeaf ? leafBase : barkBase, name, mGroup, mName);
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

    const std::vector<Ogre::String>& TreeAsset::getBarkAoMaterialNames(bool shadowed)
    {
        std::vector<Ogre::String>& names = mBarkAoMaterialNames[shadowed ? 1 : 0];
        if (names.empty())
            names = shadowed ? createMaterials("TreeLod/BarkAoShadowed", "", "/BarkAoShadowed")
                             : createMaterials("TreeLod/BarkAo", "", "/BarkAo");
        return names;
    }

    Ogre::MeshPtr TreeAsset::getBarkAoMesh(bool classic)
    {
        Ogre::MeshPtr& mesh = mBarkAoMeshes[classic ? 1 : 0];
        if (!mesh)
        {
            const BillboardCloudData& data = getBillboardCloud(classic);
            const char* chunk = classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK;
            mesh = buildBarkMesh(mName + "/bark-ao/" + chunk, getBarkAoMaterialNames(false), data.barkAo);
        }
        return mesh;
    }

    // ---- billboard clouds (paper 000) ----------------------------------------------------------

    Ogre::Real billboardCloudPixelCount(float entries, float cellSize, float radius, float listFactor)
    {
        // entries = listFactor * sqrt(2) * cellSize * r_px / radius  =>  r_px; value = 4 pi r_px^2.
        if (!(cellSize > 0.0f) || !(listFactor > 0.0f))
            return std::numeric_limits<Ogre::Real>::max();
        const double rPx = double(entries) * double(radius) / (std::sqrt(2.0) * double(listFactor) * double(cellSize));
        return Ogre::Real(4.0 * Ogre::Math::PI * rPx * rPx);
    }

    const BillboardCloudData& TreeAsset::getBillboardCloud(bool classic)
    {
        std::unique_ptr<BillboardCloudData>& slot = mBillboardClouds[classic ? 1 : 0];
        if (slot)
            return *slot;
        const char* chunk = classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK;
        Result<BillboardCloudData> data = decodeBillboardCloudChunk(readChunk(chunk), mName);
        if (!data)
            raise(data.error());
        const TreeModel& model = getReference().model;
        if (data->barkAo.size() != model.barkVertices.size())
            raise(fail(mName, chunkElement(chunk, 0),
                       "bark AO for " + std::to_string(data->barkAo.size()) + " vertices, the reference bark has " +
                           std::to_string(model.barkVertices.size())));
        if (data->classic != classic)
            raise(fail(mName, chunkElement(chunk, 0), classic ? "not a classic cloud" : "a classic cloud"));
        for (const BillboardLeafMaterial& m : data->leafMaterials)
            if (m.material >= model.materials.size())
                raise(fail(mName, chunkElement(chunk, 0),
                           "leaf material " + std::to_string(m.material) + " is not a material of the reference"));
        slot = std::make_unique<BillboardCloudData>(std::move(data.value()));
        return *slot;
    }

    const BillboardCloudGpu& TreeAsset::getBillboardCloudLayout(bool classic)
    {
        std::unique_ptr<BillboardCloudGpu>& slot = mBillboardCloudLayouts[classic ? 1 : 0];
        if (slot)
            return *slot;
        const BillboardCloudData& data = getBillboardCloud(classic);
        auto layout = std::make_unique<BillboardCloudGpu>();
        layout->listFactor = data.listFactor;
        layout->bounds = getBounds();
        layout->bounds.merge(Ogre::AxisAlignedBox(data.boundsMin.x, data.boundsMin.y, data.boundsMin.z,
                                                  data.boundsMax.x, data.boundsMax.y, data.boundsMax.z));
        for (const Billboard& b : data.billboards)
            for (const glm::vec3& c : {b.origin, b.origin + b.axisU, b.origin + b.axisV, b.origin + b.axisU + b.axisV})
                layout->bounds.merge(Ogre::Vector3(c.x, c.y, c.z));
        layout->radius = Ogre::Math::boundingRadiusFromAABB(layout->bounds);
        // §6: all levels' quads in one buffer, a range of the index buffer per level.
        for (const BillboardCloudLevel& l : data.levels)
        {
            BillboardCloudGpu::Level level;
            level.indexStart = std::size_t(l.firstBillboard) * 6;
            level.indexCount = std::size_t(l.billboardCount) * 6;
            level.layered = l.layered;
            level.cellSize = l.cellSize;
            if (l.layered)
                level.lowResPixelCount =
                    billboardCloudPixelCount(1.0f, l.cellSize, float(layout->radius), data.listFactor);
            layout->levels.push_back(level);
        }
        slot = std::move(layout);
        return *slot;
    }

    const BillboardCloudGpu& TreeAsset::getBillboardCloudGpu(bool classic)
    {
        std::unique_ptr<BillboardCloudGpu>& slot = mBillboardCloudGpus[classic ? 1 : 0];
        if (slot)
            return *slot;
        const BillboardCloudData& data = getBillboardCloud(classic);
        const Ogre::String prefix =
            "TreeLod/" + mName + "/" + (classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK) + "/";
        const BillboardCloudGpu& layout = getBillboardCloudLayout(classic);
        auto gpu = std::make_unique<BillboardCloudGpu>();
        gpu->listFactor = layout.listFactor;
        gpu->bounds = layout.bounds;
        gpu->radius = layout.radius;
        gpu->levels = layout.levels;

        // §6 atlases: integer texel fetches only (no mips; filtering unused). The Lists and AO
        // atlases are padded with zero texels past the last entry.
        auto atlas = [&](const char* suffix, const std::uint8_t* bytes, std::size_t byteCount, std::uint32_t width,
                         std::uint32_t height, Ogre::PixelFormat format) {
            const std::size_t texel = Ogre::PixelUtil::getNumElemBytes(format);
            if (width == 0 || height == 0)
                width = height = 1;
            std::vector<std::uint8_t> padded(std::size_t(width) * height * texel, 0);
            std::memcpy(padded.data(), bytes, std::min(byteCount, padded.size()));
            const Ogre::String name = prefix + suffix;
            uploadTexture(name, mGroup, padded.data(), width, height, format, 1);
            gpu->textures.push_back(name);
        };
        atlas("hash", data.hashAtlas.data(), data.hashAtlas.size(), data.hashAtlasWidth, data.hashAtlasHeight,
              Ogre::PF_BYTE_RGBA);
        static_assert(sizeof(BillboardListEntry) == 8, "a list entry is four u16 words");
        atlas("lists", reinterpret_cast<const std::uint8_t*>(data.entries.data()), data.entries.size() * 8,
              data.listsAtlasWidth, data.listsAtlasHeight, Ogre::PF_SHORT_RGBA);
        atlas("ao", data.entryAo.data(), data.entryAo.size(), data.listsAtlasWidth, data.listsAtlasHeight,
              Ogre::PF_BYTE_RGBA);
        // Leaves Texture and low-res texture: every mip level as baked (DXT or RGBA8).
        for (const std::pair<const char*, const GpuTexture*>& t :
             {std::make_pair("leaves-colour", &data.leavesColour), std::make_pair("leaves-normal", &data.leavesNormal),
              std::make_pair("low-res", &data.lowRes)})
        {
            const Ogre::String name = prefix + t.first;
            uploadTexture(name, mGroup, *t.second);
            gpu->textures.push_back(name);
        }

        // §6: the quads of every level in one vertex buffer, a range of the index buffer per level.
        if (!data.billboards.empty())
        {
            constexpr std::size_t floatsPerVertex = 3 + 3 + 3 + 2 + 4 + 4;
            const float lowResW = float(data.lowRes.width), lowResH = float(data.lowRes.height);
            std::vector<float> vertices;
            vertices.reserve(data.billboards.size() * 4 * floatsPerVertex);
            for (const Billboard& b : data.billboards)
            {
                const glm::vec3 tangent = glm::normalize(b.axisU);
                for (const glm::vec2 c : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)})
                {
                    const glm::vec3 p = b.origin + c.x * b.axisU + c.y * b.axisV;
                    const float v[floatsPerVertex] = {
                        p.x, p.y, p.z, b.normal.x, b.normal.y, b.normal.z, tangent.x, tangent.y, tangent.z, c.x, c.y,
                        float(b.hashX), float(b.hashY), float(b.hashWidth), float(b.hashHeight),
                        float(b.lowResX) / lowResW, float(b.lowResY) / lowResH,
                        float(b.lowResX + b.lowResWidth) / lowResW, float(b.lowResY + b.lowResHeight) / lowResH};
                    vertices.insert(vertices.end(), v, v + floatsPerVertex);
                }
            }
            gpu->vertexData = std::make_unique<Ogre::VertexData>();
            Ogre::VertexData& vd = *gpu->vertexData;
            vd.vertexCount = data.billboards.size() * 4;
            Ogre::VertexDeclaration* decl = vd.vertexDeclaration;
            std::size_t offset = 0;
            offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
            offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_NORMAL).getSize();
            offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_TANGENT).getSize();
            offset += decl->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0).getSize();
            offset += decl->addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 1).getSize();
            decl->addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 2);
            Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                floatsPerVertex * sizeof(float), vd.vertexCount, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            buffer->writeData(0, buffer->getSizeInBytes(), vertices.data(), true);
            vd.vertexBufferBinding->setBinding(0, buffer);

            std::vector<std::uint32_t> indices;
            indices.reserve(data.billboards.size() * 6);
            for (std::uint32_t b = 0; b < data.billboards.size(); ++b)
                for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
                    indices.push_back(4 * b + k);
            const bool wide = vd.vertexCount > 65535;
            gpu->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                wide ? Ogre::HardwareIndexBuffer::IT_32BIT : Ogre::HardwareIndexBuffer::IT_16BIT, indices.size(),
                Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            if (wide)
                gpu->indexBuffer->writeData(0, indices.size() * 4, indices.data(), true);
            else
            {
                std::vector<std::uint16_t> narrow(indices.begin(), indices.end());
                gpu->indexBuffer->writeData(0, narrow.size() * 2, narrow.data(), true);
            }
        }
        createBillboardCloudMaterials(*gpu, data, prefix);
        slot = std::move(gpu);
        return *slot;
    }

    void TreeAsset::createBillboardCloudMaterials(BillboardCloudGpu& gpu, const BillboardCloudData& data,
                                                  const Ogre::String& prefix)
    {
        const std::pair<const char*, Ogre::String> units[] = {
            {"HashAtlas", prefix + "hash"},           {"ListsAtlas", prefix + "lists"},
            {"AoAtlas", prefix + "ao"},               {"LeavesColour", prefix + "leaves-colour"},
            {"LeavesNormal", prefix + "leaves-normal"}, {"LowRes", prefix + "low-res"}};
        const int tileSize = int(std::max<std::uint32_t>(data.tileSize, 1));
        const int columns = int(std::max<std::uint32_t>(data.tileColumns, 1));
        const int rows = std::max(1, int(data.leavesColour.height) / tileSize);
        float cutoffs[4] = {0.5f, 0.5f, 0.5f, 0.5f};
        for (std::size_t m = 0; m < data.leafMaterials.size() && m < 4; ++m)
            cutoffs[m] = data.leafMaterials[m].alphaCutoff;

        auto configure = [&](const Ogre::MaterialPtr& material) {
            material->load();
            for (Ogre::Technique* tech : material->getTechniques())
                for (Ogre::Pass* pass : tech->getPasses())
                {
                    for (const auto& unit : units)
                        if (Ogre::TextureUnitState* state = pass->getTextureUnitState(unit.first))
                            state->setTextureName(unit.second);
                    if (!pass->hasFragmentProgram())
                        continue;
                    Ogre::GpuProgramParametersSharedPtr p = pass->getFragmentProgramParameters();
                    p->setIgnoreMissingParams(true);
                    p->setNamedConstant("listsAtlasWidth", int(std::max<std::uint32_t>(data.listsAtlasWidth, 1)));
                    p->setNamedConstant("tileSize", float(tileSize));
                    p->setNamedConstant("tileColumns", columns);
                    p->setNamedConstant("tileRows", rows);
                    p->setNamedConstant("orientationCount", int(std::max<std::uint32_t>(data.orientationCount(), 1)));
                    p->setNamedConstant("leavesMaxLod", float(data.leavesMaxLod));
                    p->setNamedConstant("alphaCutoffs", Ogre::Vector4(cutoffs[0], cutoffs[1], cutoffs[2], cutoffs[3]));
                }
        };
        auto clone = [&](const Ogre::String& base, const Ogre::String& name) {
            Ogre::MaterialPtr material = cloneBaseMaterial(base, name, mGroup, mName);
            configure(material);
            gpu.materials.push_back(name);
            return material;
        };
        // The shadow casters of each technique (§5.2: layers close up, low-res far away).
        std::map<Ogre::String, Ogre::MaterialPtr> casters;
        auto withCasters = [&](const Ogre::MaterialPtr& material) {
            for (Ogre::Technique* tech : material->getTechniques())
                if (Ogre::MaterialPtr caster = tech->getShadowCasterMaterial())
                {
                    Ogre::MaterialPtr& own = casters[caster->getName()];
                    if (!own)
                        own = clone(caster->getName(), prefix + caster->getName().substr(8)); // drop "TreeLod/"
                    tech->setShadowCasterMaterial(own);
                }
        };
        for (std::size_t l = 0; l < gpu.levels.size(); ++l)
        {
            BillboardCloudGpu::Level& level = gpu.levels[l];
            const Ogre::String base = level.layered ? "TreeLod/BillboardCloud" : "TreeLod/BillboardCloudLowRes";
            level.material = prefix + std::to_string(l);
            level.shadowedMaterial = level.material + "/Shadowed";
            for (const Ogre::String& name : {level.material, level.shadowedMaterial})
            {
                Ogre::MaterialPtr material = clone(name == level.material ? base : base + "Shadowed", name);
                // §5.1: far away the layered material switches to the low-res technique.
                if (level.layered)
                    material->setLodLevels({level.lowResPixelCount});
                withCasters(material);
            }
        }
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
