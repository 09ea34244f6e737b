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

        void removeGpu(const VolumeOctreeGpu& gpu, const Ogre::String& group)
        {
            for (const Ogre::String& m : {gpu.material, gpu.casterMaterial})
                if (!m.empty())
                    Ogre::MaterialManager::getSingleton().remove(m, group);
            for (const Ogre::String& t : {gpu.codebookTexture, gpu.slotsTexture})
                if (!t.empty())
                    Ogre::TextureManager::getSingleton().remove(t, group);
        }
    }

    VolumeOctreeResources::~VolumeOctreeResources()
    {
        if (mGpu)
            removeGpu(*mGpu, mAsset.getGroup());
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

            // The slot texture.
            gpu->slotsWidth = std::min<std::uint32_t>(SLOTS_WIDTH, std::uint32_t(std::max<std::size_t>(d.slots.size(), 1)));
            const std::uint32_t rows = std::uint32_t((d.slots.size() + gpu->slotsWidth - 1) / gpu->slotsWidth);
            std::vector<std::uint8_t> slots(std::size_t(gpu->slotsWidth) * std::max(rows, 1u) * 4, 0xFF);
            for (std::size_t i = 0; i < d.slots.size(); ++i)
            {
                const VolumeOctreeSlot& s = d.slots[i];
                slots[4 * i + 0] = std::uint8_t(s.colour & 0xFF);
                slots[4 * i + 1] = std::uint8_t(s.colour >> 8);
                slots[4 * i + 2] = std::uint8_t(s.alpha & 0xFF);
                slots[4 * i + 3] = std::uint8_t(s.alpha >> 8);
            }
            gpu->slotsTexture = prefix + "-slots";
            uploadTexture(gpu->slotsTexture, group, slots.data(), gpu->slotsWidth, std::max(rows, 1u),
                          Ogre::PF_BYTE_RGBA, 1);
            gpu->codebookTexture = prefix + "-codebook";
            uploadTexture(gpu->codebookTexture, group, d.atlas);

            for (std::uint32_t level = 0; level < d.levelCount; ++level)
            {
                gpu->cellOrders.emplace_back();
                for (std::uint32_t octant = 0; octant < 8; ++octant)
                    gpu->cellOrders.back()[octant] = volumeOctreeOctantOrder(d, level, octant);
            }

            const float grow = 0.5f * d.cellEdge(d.levelCount - 1) * 0.75f; // a turned square sticks out
            gpu->bounds = Ogre::AxisAlignedBox(d.origin.x - grow, d.origin.y - grow, d.origin.z - grow,
                                               d.origin.x + d.size + grow, d.origin.y + d.size + grow,
                                               d.origin.z + d.size + grow);
            gpu->gpuBytes = d.atlas.data.size() + slots.size() + buffer->getSizeInBytes();

            // The materials and their constants (TreeLodVolumeOctree.vert/.frag): the caster's clone
            // is the main clone's shadow caster.
            gpu->material = prefix;
            gpu->casterMaterial = prefix + "/Caster";
            const Ogre::MaterialPtr material =
                cloneBaseMaterial(VOLUME_OCTREE_MATERIAL, gpu->material, group, mAsset.getName());
            const Ogre::MaterialPtr caster =
                cloneBaseMaterial(VOLUME_OCTREE_CASTER_MATERIAL, gpu->casterMaterial, group, mAsset.getName());
            for (const Ogre::MaterialPtr& m : {material, caster})
            {
                m->load();
                for (Ogre::Technique* tech : m->getTechniques())
                    for (Ogre::Pass* pass : tech->getPasses())
                    {
                        if (Ogre::TextureUnitState* unit = pass->getTextureUnitState("Codebook"))
                            unit->setTextureName(gpu->codebookTexture);
                        if (Ogre::TextureUnitState* unit = pass->getTextureUnitState("Slots"))
                            unit->setTextureName(gpu->slotsTexture);
                        for (bool vertex : {true, false})
                        {
                            if (vertex ? !pass->hasVertexProgram() : !pass->hasFragmentProgram())
                                continue;
                            Ogre::GpuProgramParametersSharedPtr p =
                                vertex ? pass->getVertexProgramParameters() : pass->getFragmentProgramParameters();
                            p->setIgnoreMissingParams(true);
                            // x: cameras, y: slot texture width, z: atlas blocks a row, w: atlas width
                            p->setNamedConstant("octree",
                                                Ogre::Vector4(float(d.cameraCount()), float(gpu->slotsWidth),
                                                              float(d.atlas.width / VOLUME_BILLBOARD_TEXELS),
                                                              float(d.atlas.width)));
                            p->setNamedConstant("atlasHeight", float(d.atlas.height));
                        }
                    }
            }
            for (Ogre::Technique* tech : material->getTechniques())
                tech->setShadowCasterMaterial(caster);
        }
        catch (...)
        {
            removeGpu(*gpu, group);
            throw;
        }
        mGpu = std::move(gpu);
        return *mGpu;
    }
}
