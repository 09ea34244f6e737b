// VolumeOctreeResources: the volumetric octree tree (chunk "volume-octree", VolumeOctreeData.h) on
// the GPU (layout in VolumeOctreeResources.h).
#include "TreeLod/VolumeOctreeResources.h"

#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreeAsset.h"

#include <OgreGpuProgramParams.h>
#include <OgreHardwareBufferManager.h>
#include <OgrePass.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <algorithm>
#include <functional>

namespace TreeLod
{
    VolumeOctreeResources& VolumeOctreeResources::of(TreeAsset& asset)
    {
        return asset.getResources<VolumeOctreeResources>(
            VOLUME_OCTREE_CHUNK, [&asset] { return std::make_unique<VolumeOctreeResources>(asset); });
    }

    namespace
    {
        /// Slots a row of the slot texture.
        constexpr std::uint32_t SLOTS_WIDTH = 4096;

        /// Texels a row of the cell and order textures.
        constexpr std::uint32_t TEXELS_WIDTH = 4096;

        void removeResources(const std::vector<Ogre::String>& materials, const std::vector<Ogre::String>& textures,
                             const Ogre::String& group)
        {
            for (const Ogre::String& m : materials)
                if (!m.empty())
                    Ogre::MaterialManager::getSingleton().remove(m, group);
            for (const Ogre::String& t : textures)
                if (!t.empty())
                    Ogre::TextureManager::getSingleton().remove(t, group);
        }

        void removeGpu(const VolumeOctreeGpu& gpu, const Ogre::String& group)
        {
            removeResources({gpu.material, gpu.casterMaterial}, {}, group);
        }

        void removeForestGpu(const VolumeOctreeForestGpu& gpu, const Ogre::String& group)
        {
            removeResources({gpu.material, gpu.casterMaterial}, {gpu.cellsTexture, gpu.ordersTexture}, group);
        }

        /// The constants of TreeLodVolumeOctree.vert/.frag every clone shares.
        void setOctreeConstants(Ogre::GpuProgramParameters& p, const VolumeOctreeData& d,
                                const VolumeOctreeTextures& textures)
        {
            // x: cameras, y: slot texture width, z: atlas blocks a row, w: atlas width
            p.setNamedConstant("octree", Ogre::Vector4(float(d.cameraCount()), float(textures.slotsWidth),
                                                       float(d.atlas.width / VOLUME_BILLBOARD_TEXELS),
                                                       float(d.atlas.width)));
            p.setNamedConstant("atlasHeight", float(d.atlas.height));
        }

        /// Clone `base` as `name` and `casterBase` as `name`/Caster, the clone's shadow caster; bind
        /// the texture units named in `textures` and set `constants` on every program.
        void cloneMaterials(const Ogre::String& base, const Ogre::String& casterBase, const Ogre::String& name,
                            const Ogre::String& group, const Ogre::String& assetName,
                            const std::vector<std::pair<Ogre::String, Ogre::String>>& textures,
                            const std::function<void(Ogre::GpuProgramParameters&)>& constants)
        {
            const Ogre::MaterialPtr material = cloneBaseMaterial(base, name, group, assetName);
            const Ogre::MaterialPtr caster = cloneBaseMaterial(casterBase, name + "/Caster", group, assetName);
            for (const Ogre::MaterialPtr& m : {material, caster})
                configurePasses(m, textures, [&](Ogre::Pass& pass) {
                    for (bool vertex : {true, false})
                    {
                        if (vertex ? !pass.hasVertexProgram() : !pass.hasFragmentProgram())
                            continue;
                        Ogre::GpuProgramParametersSharedPtr p =
                            vertex ? pass.getVertexProgramParameters() : pass.getFragmentProgramParameters();
                        p->setIgnoreMissingParams(true);
                        constants(*p);
                    }
                });
            for (Ogre::Technique* tech : material->getTechniques())
                tech->setShadowCasterMaterial(caster);
        }
    }

    Ogre::AxisAlignedBox volumeOctreeDrawnBounds(const VolumeOctreeData& d)
    {
        const float grow = 0.5f * d.cellEdge(d.levelCount - 1) * 0.75f; // a turned square sticks out
        return Ogre::AxisAlignedBox(d.origin.x - grow, d.origin.y - grow, d.origin.z - grow, d.origin.x + d.size + grow,
                                    d.origin.y + d.size + grow, d.origin.z + d.size + grow);
    }

    VolumeOctreeResources::~VolumeOctreeResources()
    {
        if (mForestGpu)
            removeForestGpu(*mForestGpu, mAsset.getGroup());
        if (mGpu)
            removeGpu(*mGpu, mAsset.getGroup());
        if (mTextures)
            removeResources({}, {mTextures->codebook, mTextures->slots}, mAsset.getGroup());
    }

    const VolumeOctreeData& VolumeOctreeResources::getData()
    {
        if (mData)
            return *mData;
        Result<VolumeOctreeData> decoded = decodeVolumeOctreeChunk(mAsset.readChunk(VOLUME_OCTREE_CHUNK), mAsset.getName());
        if (!decoded)
            mAsset.raise(decoded.error());
        mData = std::make_unique<VolumeOctreeData>(std::move(decoded.value()));
        return *mData;
    }

    const VolumeOctreeTextures& VolumeOctreeResources::getTextures()
    {
        if (mTextures)
            return *mTextures;
        const VolumeOctreeData& d = getData();
        auto textures = std::make_unique<VolumeOctreeTextures>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/volume-octree";
        try
        {
            textures->slotsWidth =
                std::min<std::uint32_t>(SLOTS_WIDTH, std::uint32_t(std::max<std::size_t>(d.slots.size(), 1)));
            const std::uint32_t rows =
                std::max(std::uint32_t((d.slots.size() + textures->slotsWidth - 1) / textures->slotsWidth), 1u);
            std::vector<std::uint8_t> slots(std::size_t(textures->slotsWidth) * rows * 4, 0xFF);
            for (std::size_t i = 0; i < d.slots.size(); ++i)
            {
                const VolumeOctreeSlot& s = d.slots[i];
                slots[4 * i + 0] = std::uint8_t(s.colour & 0xFF);
                slots[4 * i + 1] = std::uint8_t(s.colour >> 8);
                slots[4 * i + 2] = std::uint8_t(s.alpha & 0xFF);
                slots[4 * i + 3] = std::uint8_t(s.alpha >> 8);
            }
            textures->slots = prefix + "-slots";
            uploadTexture(textures->slots, mAsset.getGroup(), slots.data(), textures->slotsWidth, rows,
                          Ogre::PF_BYTE_RGBA, 1);
            textures->codebook = prefix + "-codebook";
            textures->bytes = uploadTexture(textures->codebook, mAsset.getGroup(), d.atlas) + slots.size();
        }
        catch (...)
        {
            removeResources({}, {textures->codebook, textures->slots}, mAsset.getGroup());
            throw;
        }
        mTextures = std::move(textures);
        return *mTextures;
    }

    const VolumeOctreeCellOrders& VolumeOctreeResources::getCellOrders()
    {
        if (mCellOrders.empty())
        {
            const VolumeOctreeData& d = getData();
            VolumeOctreeCellOrders orders(d.levelCount);
            for (std::uint32_t level = 0; level < d.levelCount; ++level)
                for (std::uint32_t octant = 0; octant < 8; ++octant)
                    orders[level][octant] = volumeOctreeOctantOrder(d, level, octant);
            mCellOrders = std::move(orders);
        }
        return mCellOrders;
    }

    const VolumeOctreeGpu& VolumeOctreeResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
        const VolumeOctreeData& d = getData();
        auto gpu = std::make_unique<VolumeOctreeGpu>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/volume-octree";
        const Ogre::String& group = mAsset.getGroup();
        try
        {
            // Vertices: 4 a cell.
            const std::size_t cells = d.cells.size();
            std::vector<float> vertices;
            vertices.reserve(cells * 4 * 11);
            for (std::uint32_t level = 0; level < d.levelCount; ++level)
            {
                const std::uint32_t first = d.firstCell(level);
                for (std::uint32_t i = 0; i < d.levelCellCounts[level]; ++i)
                {
                    const std::uint32_t code = d.cells[first + i];
                    const glm::vec3 centre = d.cellCentre(code, level);
                    const glm::uvec3 c = volumeCellCoords(code);
                    const glm::vec3 parent =
                        level == 0 ? centre : d.cellCentre(volumeCellCode(c.x / 2, c.y / 2, c.z / 2), level - 1);
                    for (const glm::vec2 corner : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)})
                        vertices.insert(vertices.end(), {centre.x, centre.y, centre.z, corner.x, corner.y, float(level),
                                                         float(first + i), parent.x, parent.y, parent.z,
                                                         0.5f * d.cellEdge(level)});
                }
            }
            gpu->vertexData = std::make_unique<Ogre::VertexData>();
            Ogre::VertexDeclaration* decl = gpu->vertexData->vertexDeclaration;
            decl->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION);
            decl->addElement(0, 3 * sizeof(float), Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 0);
            decl->addElement(0, 7 * sizeof(float), Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 1);
            gpu->vertexData->vertexCount = cells * 4;
            Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                11 * sizeof(float), cells * 4, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            buffer->writeData(0, buffer->getSizeInBytes(), vertices.data(), true);
            gpu->vertexData->vertexBufferBinding->setBinding(0, buffer);

            gpu->bounds = volumeOctreeDrawnBounds(d);
            gpu->gpuBytes = buffer->getSizeInBytes();

            // The materials and their constants (TreeLodVolumeOctree.vert/.frag).
            const VolumeOctreeTextures& textures = getTextures();
            gpu->material = prefix;
            gpu->casterMaterial = prefix + "/Caster";
            cloneMaterials(VOLUME_OCTREE_MATERIAL, VOLUME_OCTREE_CASTER_MATERIAL, gpu->material, group,
                           mAsset.getName(), {{"Codebook", textures.codebook}, {"Slots", textures.slots}},
                           [&](Ogre::GpuProgramParameters& p) { setOctreeConstants(p, d, textures); });
        }
        catch (...)
        {
            removeGpu(*gpu, group);
            throw;
        }
        mGpu = std::move(gpu);
        return *mGpu;
    }

    const VolumeOctreeForestGpu& VolumeOctreeResources::getForestGpu()
    {
        if (mForestGpu)
            return *mForestGpu;
        const VolumeOctreeData& d = getData();
        const VolumeOctreeTextures& textures = getTextures();
        const VolumeOctreeCellOrders& cellOrders = getCellOrders();
        auto gpu = std::make_unique<VolumeOctreeForestGpu>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/volume-octree-forest";
        const Ogre::String& group = mAsset.getGroup();
        try
        {
            // Cells: coordinates and level packed in 32 bits; orders: cell indices, 32 bits; both
            // little-endian RGBA8, exact for any octree (TreeLodVolumeOctree.vert).
            static_assert(VOLUME_OCTREE_MAX_LEVELS <= 10, "9 bits a coordinate");
            std::vector<std::uint32_t> cellWords(d.cells.size());
            for (std::uint32_t level = 0; level < d.levelCount; ++level)
                for (std::uint32_t i = d.firstCell(level); i < d.firstCell(level) + d.levelCellCounts[level]; ++i)
                {
                    const glm::uvec3 c = volumeCellCoords(d.cells[i]);
                    cellWords[i] = c.x | c.y << 9 | c.z << 18 | level << 27;
                }
            std::vector<std::uint32_t> orders;
            std::uint32_t mostQuads = 1;
            for (std::uint32_t active = 0; active < d.levelCount; ++active)
            {
                gpu->orderStart.push_back(std::uint32_t(orders.size()));
                const std::uint32_t first = active == 0 ? 0 : active - 1;
                std::uint32_t quads = 0;
                for (std::uint32_t level = first; level <= active; ++level)
                    quads += d.levelCellCounts[level];
                gpu->quadCount.push_back(quads);
                mostQuads = std::max(mostQuads, quads);
                for (std::uint32_t octant = 0; octant < 8; ++octant)
                    for (std::uint32_t level = first; level <= active; ++level)
                        for (std::uint32_t i : cellOrders[level][octant])
                            orders.push_back(d.firstCell(level) + i);
            }
            const auto upload = [&](std::vector<std::uint32_t>& words, const Ogre::String& name) {
                const std::uint32_t rows =
                    std::uint32_t(std::max<std::size_t>((words.size() + TEXELS_WIDTH - 1) / TEXELS_WIDTH, 1));
                words.resize(std::size_t(TEXELS_WIDTH) * rows, 0);
                std::vector<std::uint8_t> bytes(words.size() * 4);
                for (std::size_t i = 0; i < words.size(); ++i)
                    for (int b = 0; b < 4; ++b)
                        bytes[4 * i + b] = std::uint8_t(words[i] >> (8 * b));
                uploadTexture(name, group, bytes.data(), TEXELS_WIDTH, rows, Ogre::PF_BYTE_RGBA, 1);
                return bytes.size();
            };
            gpu->cellsTexture = prefix + "-cells";
            gpu->gpuBytes += upload(cellWords, gpu->cellsTexture);
            gpu->ordersTexture = prefix + "-orders";
            gpu->gpuBytes += upload(orders, gpu->ordersTexture);

            // Quads: 4 vertices (4 quad + corner) and 6 indices each.
            std::vector<float> vertices;
            std::vector<std::uint32_t> indices;
            vertices.reserve(std::size_t(mostQuads) * 4);
            indices.reserve(std::size_t(mostQuads) * 6);
            for (std::uint32_t q = 0; q < mostQuads; ++q)
            {
                const std::uint32_t v = 4 * q;
                vertices.insert(vertices.end(), {float(v), float(v + 1), float(v + 2), float(v + 3)});
                indices.insert(indices.end(), {v, v + 1, v + 2, v, v + 2, v + 3});
            }
            gpu->vertexData = std::make_unique<Ogre::VertexData>();
            gpu->vertexData->vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT1, Ogre::VES_POSITION);
            gpu->vertexData->vertexCount = std::size_t(mostQuads) * 4;
            Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                sizeof(float), gpu->vertexData->vertexCount, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            buffer->writeData(0, buffer->getSizeInBytes(), vertices.data(), true);
            gpu->vertexData->vertexBufferBinding->setBinding(0, buffer);
            gpu->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                Ogre::HardwareIndexBuffer::IT_32BIT, indices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            gpu->indexBuffer->writeData(0, gpu->indexBuffer->getSizeInBytes(), indices.data(), true);
            gpu->gpuBytes += buffer->getSizeInBytes() + gpu->indexBuffer->getSizeInBytes();

            gpu->material = prefix;
            gpu->casterMaterial = prefix + "/Caster";
            std::vector<float> directions(4 * VOLUME_OCTREE_MAX_CAMERAS, 0.0f);
            for (std::uint32_t c = 0; c < d.cameraCount(); ++c)
                std::copy_n(&d.cameraDirections[c].x, 3, &directions[4 * c]);
            cloneMaterials(VOLUME_OCTREE_FOREST_MATERIAL, VOLUME_OCTREE_FOREST_CASTER_MATERIAL, gpu->material, group,
                           mAsset.getName(),
                           {{"Codebook", textures.codebook},
                            {"Slots", textures.slots},
                            {"Cells", gpu->cellsTexture},
                            {"Orders", gpu->ordersTexture}},
                           [&](Ogre::GpuProgramParameters& p) {
                               setOctreeConstants(p, d, textures);
                               p.setNamedConstant("octreeBox", Ogre::Vector4(d.origin.x, d.origin.y, d.origin.z, d.size));
                               p.setNamedConstant("cameraDirections", directions.data(), VOLUME_OCTREE_MAX_CAMERAS, 4);
                               p.setNamedConstant("texelsWidth", float(TEXELS_WIDTH));
                           });
        }
        catch (...)
        {
            removeForestGpu(*gpu, group);
            throw;
        }
        mForestGpu = std::move(gpu);
        return *mForestGpu;
    }
}
