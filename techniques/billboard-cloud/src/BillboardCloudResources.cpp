#include "TreeLod/BillboardCloudResources.h"

#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreeAsset.h"

#include <OgreGpuProgramParams.h>
#include <OgreHardwareBufferManager.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgrePass.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

namespace TreeLod
{
    BillboardCloudResources& BillboardCloudResources::of(TreeAsset& asset, bool classic)
    {
        return asset.getResources<BillboardCloudResources>(
            classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK,
            [&asset, classic] { return std::make_unique<BillboardCloudResources>(asset, classic); });
    }

    BillboardCloudResources::BillboardCloudResources(TreeAsset& asset, bool classic)
        : mAsset(asset), mClassic(classic)
    {
    }

    BillboardCloudResources::~BillboardCloudResources()
    {
        if (mBarkAoMesh)
            Ogre::MeshManager::getSingleton().remove(mBarkAoMesh);
        if (mGpu)
        {
            for (const Ogre::String& m : mGpu->materials)
                Ogre::MaterialManager::getSingleton().remove(m, mAsset.getGroup());
            for (const Ogre::String& t : mGpu->textures)
                Ogre::TextureManager::getSingleton().remove(t, mAsset.getGroup());
        }
    }

    const char* BillboardCloudResources::chunk() const
    {
        return mClassic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK;
    }

    const std::vector<Ogre::String>& BillboardCloudResources::getBarkAoMaterialNames(bool shadowed)
    {
        return shadowed ? mAsset.getModelMaterials("TreeLod/BarkAoShadowed", "", "/BarkAoShadowed")
                        : mAsset.getModelMaterials("TreeLod/BarkAo", "", "/BarkAo");
    }

    Ogre::MeshPtr BillboardCloudResources::getBarkAoMesh()
    {
        if (!mBarkAoMesh)
            mBarkAoMesh = mAsset.buildBarkMesh(mAsset.getName() + "/bark-ao/" + chunk(),
                                               getBarkAoMaterialNames(false), getData().barkAo);
        return mBarkAoMesh;
    }

    std::uint64_t BillboardCloudResources::getGpuBytes() const
    {
        if (!mGpu)
            return 0;
        std::uint64_t bytes = 0;
        if (mGpu->vertexData)
            for (const auto& binding : mGpu->vertexData->vertexBufferBinding->getBindings())
                bytes += binding.second->getSizeInBytes();
        if (mGpu->indexBuffer)
            bytes += mGpu->indexBuffer->getSizeInBytes();
        for (const Ogre::String& name : mGpu->textures)
            if (Ogre::TexturePtr t = Ogre::TextureManager::getSingleton().getByName(name, mAsset.getGroup()))
                bytes += t->getSize();
        return bytes;
    }

    Ogre::Real billboardCloudPixelCount(float entries, float cellSize, float radius, float listFactor)
    {
        // entries = listFactor * sqrt(2) * cellSize * r_px / radius  =>  r_px; value = 4 pi r_px^2.
        if (!(cellSize > 0.0f) || !(listFactor > 0.0f))
            return std::numeric_limits<Ogre::Real>::max();
        const double rPx = double(entries) * double(radius) / (std::sqrt(2.0) * double(listFactor) * double(cellSize));
        return Ogre::Real(4.0 * Ogre::Math::PI * rPx * rPx);
    }

    const BillboardCloudData& BillboardCloudResources::getData()
    {
        std::unique_ptr<BillboardCloudData>& slot = mData;
        if (slot)
            return *slot;
        const bool classic = mClassic;
        const char* chunk = this->chunk();
        Result<BillboardCloudData> data = decodeBillboardCloudChunk(mAsset.readChunk(chunk), mAsset.getName());
        if (!data)
            mAsset.raise(data.error());
        const TreeModel& model = mAsset.getReference().model;
        if (data->barkAo.size() != model.barkVertices.size())
            mAsset.raise(fail(mAsset.getName(), chunkElement(chunk, 0),
                       "bark AO for " + std::to_string(data->barkAo.size()) + " vertices, the reference bark has " +
                           std::to_string(model.barkVertices.size())));
        if (data->classic != classic)
            mAsset.raise(fail(mAsset.getName(), chunkElement(chunk, 0), classic ? "not a classic cloud" : "a classic cloud"));
        for (const BillboardLeafImage& m : data->leafImages)
            if (m.material >= model.materials.size())
                mAsset.raise(fail(mAsset.getName(), chunkElement(chunk, 0),
                           "leaf material " + std::to_string(m.material) + " is not a material of the reference"));
        slot = std::make_unique<BillboardCloudData>(std::move(data.value()));
        return *slot;
    }

    const BillboardCloudGpu& BillboardCloudResources::getLayout()
    {
        std::unique_ptr<BillboardCloudGpu>& slot = mLayout;
        if (slot)
            return *slot;
        const BillboardCloudData& data = getData();
        auto layout = std::make_unique<BillboardCloudGpu>();
        layout->listFactor = data.listFactor;
        layout->bounds = mAsset.getBounds();
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

    const BillboardCloudGpu& BillboardCloudResources::getGpu()
    {
        std::unique_ptr<BillboardCloudGpu>& slot = mGpu;
        if (slot)
            return *slot;
        const BillboardCloudData& data = getData();
        const Ogre::String prefix =
            "TreeLod/" + mAsset.getName() + "/" + chunk() + "/";
        const BillboardCloudGpu& layout = getLayout();
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
            if (byteCount > 0) // an empty cloud's lists: no bytes, maybe no pointer
                std::memcpy(padded.data(), bytes, std::min(byteCount, padded.size()));
            const Ogre::String name = prefix + suffix;
            uploadTexture(name, mAsset.getGroup(), padded.data(), width, height, format, 1);
            gpu->textures.push_back(name);
        };
        atlas("hash", data.hashAtlas.data(), data.hashAtlas.size(), data.hashAtlasWidth, data.hashAtlasHeight,
              Ogre::PF_BYTE_RGBA);
        // Four u16 words a texel: normalised where the render system has 16-bit normalised
        // textures, unsigned integers under GLSL ES (TreeLodBillboardCloud.frag reads either).
        static_assert(sizeof(BillboardListEntry) == 8, "a list entry is four u16 words");
        atlas("lists", reinterpret_cast<const std::uint8_t*>(data.entries.data()), data.entries.size() * 8,
              data.listsAtlasWidth, data.listsAtlasHeight,
              programsAreGlslEs() ? Ogre::PF_R16G16B16A16_UINT : Ogre::PF_SHORT_RGBA);
        atlas("ao", data.entryAo.data(), data.entryAo.size(), data.listsAtlasWidth, data.listsAtlasHeight,
              Ogre::PF_BYTE_RGBA);
        // Leaves Texture and low-res texture: every mip level as baked (DXT or RGBA8).
        for (const std::pair<const char*, const GpuTexture*>& t :
             {std::make_pair("leaves-colour", &data.leavesColour), std::make_pair("leaves-normal", &data.leavesNormal),
              std::make_pair("low-res", &data.lowRes)})
        {
            const Ogre::String name = prefix + t.first;
            uploadTexture(name, mAsset.getGroup(), *t.second);
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
        createMaterials(*gpu, data, prefix);
        slot = std::move(gpu);
        return *slot;
    }

    void BillboardCloudResources::createMaterials(BillboardCloudGpu& gpu, const BillboardCloudData& data,
                                                  const Ogre::String& prefix)
    {
        const std::vector<std::pair<Ogre::String, Ogre::String>> units = {
            {"HashAtlas", prefix + "hash"},           {"ListsAtlas", prefix + "lists"},
            {"AoAtlas", prefix + "ao"},               {"LeavesColour", prefix + "leaves-colour"},
            {"LeavesNormal", prefix + "leaves-normal"}, {"LowRes", prefix + "low-res"}};
        const int tileSize = int(std::max<std::uint32_t>(data.tileSize, 1));
        const int columns = int(std::max<std::uint32_t>(data.tileColumns, 1));
        const int rows = std::max(1, int(data.leavesColour.height) / tileSize);

        auto configure = [&](const Ogre::MaterialPtr& material) {
            configurePasses(material, units, [&](Ogre::Pass& pass) {
                if (!pass.hasFragmentProgram())
                    return;
                Ogre::GpuProgramParametersSharedPtr p = pass.getFragmentProgramParameters();
                p->setIgnoreMissingParams(true);
                p->setNamedConstant("listsAtlasWidth", int(std::max<std::uint32_t>(data.listsAtlasWidth, 1)));
                p->setNamedConstant("tileSize", float(tileSize));
                p->setNamedConstant("tileColumns", columns);
                p->setNamedConstant("tileRows", rows);
                p->setNamedConstant("orientationCount", int(std::max<std::uint32_t>(data.orientationCount(), 1)));
                p->setNamedConstant("leavesMaxLod", float(data.leavesMaxLod));
            });
        };
        auto clone = [&](const Ogre::String& base, const Ogre::String& name) {
            Ogre::MaterialPtr material = cloneBaseMaterial(base, name, mAsset.getGroup(), mAsset.getName());
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
}
