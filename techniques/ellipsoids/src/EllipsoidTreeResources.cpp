// EllipsoidTreeResources: the ellipsoids (chunk "ellipsoids", EllipsoidTreeData.h) on the GPU, and
// the noise cube maps every tree shares (EllipsoidNoise.h).
#include "TreeLod/EllipsoidTreeResources.h"

#include "TreeLod/EllipsoidNoise.h"
#include "TreeLod/TreeAsset.h"

#include <OgreHardwareBufferManager.h>
#include <OgreHardwarePixelBuffer.h>
#include <OgreMaterialManager.h>
#include <OgrePass.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cstring>
#include <limits>

namespace TreeLod
{
    EllipsoidTreeResources& EllipsoidTreeResources::of(TreeAsset& asset)
    {
        return asset.getResources<EllipsoidTreeResources>(
            ELLIPSOID_TREE_CHUNK, [&asset] { return std::make_unique<EllipsoidTreeResources>(asset); });
    }

    EllipsoidTreeResources::~EllipsoidTreeResources() = default;

    const EllipsoidTreeData& EllipsoidTreeResources::getData()
    {
        if (mData)
            return *mData;
        Result<EllipsoidTreeData> decoded =
            decodeEllipsoidTreeChunk(mAsset.readChunk(ELLIPSOID_TREE_CHUNK), mAsset.getName());
        if (!decoded)
            mAsset.raise(decoded.error());
        mData = std::make_unique<EllipsoidTreeData>(std::move(decoded.value()));
        return *mData;
    }

    Ogre::AxisAlignedBox ellipsoidBounds(const EllipsoidTreeData& data)
    {
        Ogre::AxisAlignedBox bounds;
        for (const EllipsoidLevel& level : data.levels)
            for (std::uint32_t e = level.first; e < level.first + level.count; ++e)
            {
                const Ellipsoid& ellipsoid = data.ellipsoids[e];
                // The ellipsoid's own box: per axis, the length of that row of R * diag(scale * radii).
                const glm::mat3 rotation = glm::mat3_cast(ellipsoid.rotation);
                glm::vec3 reach(0.0f);
                for (int a = 0; a < 3; ++a)
                {
                    const glm::vec3 axis = rotation[a] * (ellipsoid.radii[a] * level.scale);
                    reach += axis * axis;
                }
                reach = glm::sqrt(reach);
                const Ogre::Vector3 centre(ellipsoid.centre.x, ellipsoid.centre.y, ellipsoid.centre.z);
                const Ogre::Vector3 half(reach.x, reach.y, reach.z);
                bounds.merge(Ogre::AxisAlignedBox(centre - half, centre + half));
            }
        return bounds;
    }

    std::size_t levelForHeight(const std::vector<EllipsoidGpuLevel>& levels, float heightPx)
    {
        std::size_t level = 0;
        for (std::size_t l = 0; l < levels.size(); ++l)
            if (levels[l].targetHeightPx >= heightPx)
                level = l;
        return level;
    }

    namespace
    {
        /// Fills the noise cube maps (EllipsoidNoise.h) every mip level as the core defines it, on
        /// creation and whenever Ogre reloads them.
        class NoiseLoader : public Ogre::ManualResourceLoader
        {
        public:
            void loadResource(Ogre::Resource* resource) override
            {
                auto* texture = static_cast<Ogre::Texture*>(resource);
                const bool alpha = texture->getName() == ELLIPSOID_NOISE_ALPHA_TEXTURE;
                const Ogre::PixelFormat format = alpha ? Ogre::PF_L8 : Ogre::PF_BYTE_RGBA;
                texture->setTextureType(Ogre::TEX_TYPE_CUBE_MAP);
                texture->setWidth(ELLIPSOID_NOISE_SIZE);
                texture->setHeight(ELLIPSOID_NOISE_SIZE);
                texture->setNumMipmaps(ELLIPSOID_NOISE_LEVELS - 1);
                texture->setFormat(format);
                texture->createInternalResources();
                const EllipsoidNoiseMaps& maps = ellipsoidNoiseMaps();
                for (std::size_t level = 0; level < std::size_t(ELLIPSOID_NOISE_LEVELS); ++level)
                    for (std::size_t face = 0; face < 6; ++face)
                    {
                        const std::vector<std::uint8_t>& texels = alpha ? maps.alpha[level][face] : maps.normal[level][face];
                        const Ogre::uint32 side = Ogre::uint32(ELLIPSOID_NOISE_SIZE >> level);
                        const Ogre::PixelBox box(side, side, 1, format, const_cast<std::uint8_t*>(texels.data()));
                        texture->getBuffer(face, level)->blitFromMemory(box);
                    }
            }
        };

        NoiseLoader& noiseLoader()
        {
            static NoiseLoader loader;
            return loader;
        }

        /// Two triangles per quad of 4 vertices, `quads` quads; 16-bit indices while the vertices allow.
        Ogre::HardwareIndexBufferSharedPtr quadIndices(std::size_t quads)
        {
            const bool narrow = 4 * quads <= std::numeric_limits<std::uint16_t>::max();
            std::vector<std::uint32_t> indices;
            indices.reserve(6 * quads);
            for (std::uint32_t q = 0; q < quads; ++q)
                for (const std::uint32_t corner : {0u, 1u, 2u, 0u, 2u, 3u})
                    indices.push_back(4 * q + corner);
            Ogre::HardwareIndexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                narrow ? Ogre::HardwareIndexBuffer::IT_16BIT : Ogre::HardwareIndexBuffer::IT_32BIT, indices.size(),
                Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            if (narrow)
            {
                const std::vector<std::uint16_t> small(indices.begin(), indices.end());
                buffer->writeData(0, small.size() * 2, small.data(), true);
            }
            else
                buffer->writeData(0, indices.size() * 4, indices.data(), true);
            return buffer;
        }

        /// One vertex of TreeLodEllipsoid.vert: centre; corner, noise lod and threshold; the first
        /// semi-axis and the normal blend; the other two semi-axes; RGBA8.
        struct EllipsoidVertex
        {
            float centre[3];
            float corner[4];
            float axis0[4];
            float axes[2][3];
            std::uint8_t colour[4];
        };
        static_assert(sizeof(EllipsoidVertex) == 17 * sizeof(float) + 4, "tightly packed");
    }

    void bindEllipsoidNoise()
    {
        Ogre::TextureManager& textures = Ogre::TextureManager::getSingleton();
        Ogre::TexturePtr maps[2];
        const char* names[2] = {ELLIPSOID_NOISE_ALPHA_TEXTURE, ELLIPSOID_NOISE_NORMAL_TEXTURE};
        for (int i = 0; i < 2; ++i)
        {
            maps[i] = textures.getByName(names[i], Ogre::RGN_INTERNAL);
            if (!maps[i])
                maps[i] = textures.createManual(names[i], Ogre::RGN_INTERNAL, Ogre::TEX_TYPE_CUBE_MAP, ELLIPSOID_NOISE_SIZE,
                                                ELLIPSOID_NOISE_SIZE, ELLIPSOID_NOISE_LEVELS - 1,
                                                i == 0 ? Ogre::PF_L8 : Ogre::PF_BYTE_RGBA, Ogre::TU_DEFAULT, &noiseLoader());
            maps[i]->load();
        }
        for (const char* name : {ELLIPSOID_MATERIAL, ELLIPSOID_SHADOWED_MATERIAL, ELLIPSOID_CASTER_MATERIAL})
        {
            const Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(name, Ogre::RGN_AUTODETECT);
            if (!material)
                continue; // EllipsoidTree names the missing material
            for (Ogre::Technique* technique : material->getTechniques())
                for (Ogre::Pass* pass : technique->getPasses())
                    for (Ogre::TextureUnitState* unit : pass->getTextureUnitStates())
                        if (unit->getName() == "NoiseAlpha" && unit->_getTexturePtr() != maps[0])
                            unit->setTexture(maps[0]);
                        else if (unit->getName() == "NoiseNormal" && unit->_getTexturePtr() != maps[1])
                            unit->setTexture(maps[1]);
        }
    }

    const EllipsoidTreeGpu& EllipsoidTreeResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
        bindEllipsoidNoise();
        const EllipsoidTreeData& data = getData();
        auto gpu = std::make_unique<EllipsoidTreeGpu>();
        const std::size_t count = data.ellipsoids.size();
        std::vector<EllipsoidVertex> vertices(4 * count);
        const float corners[4][2] = {{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}};
        for (const EllipsoidLevel& level : data.levels)
            for (std::uint32_t e = level.first; e < level.first + level.count; ++e)
            {
                const Ellipsoid& ellipsoid = data.ellipsoids[e];
                const glm::mat3 rotation = glm::mat3_cast(ellipsoid.rotation);
                EllipsoidVertex v{};
                std::memcpy(v.centre, &ellipsoid.centre[0], sizeof v.centre);
                for (int a = 0; a < 3; ++a)
                {
                    const glm::vec3 axis = rotation[a] * (ellipsoid.radii[a] * level.scale);
                    std::memcpy(a == 0 ? v.axis0 : v.axes[a - 1], &axis[0], 3 * sizeof(float));
                }
                v.corner[2] = ellipsoidNoiseBaseLod(ellipsoid.leafWeight);
                v.corner[3] = level.noiseThreshold;
                v.axis0[3] = level.normalBlend;
                std::copy(ellipsoid.colour.begin(), ellipsoid.colour.end(), v.colour);
                for (int c = 0; c < 4; ++c)
                {
                    EllipsoidVertex& out = vertices[4 * e + std::size_t(c)];
                    out = v;
                    out.corner[0] = corners[c][0];
                    out.corner[1] = corners[c][1];
                }
            }
        gpu->bounds = ellipsoidBounds(data);
        for (const EllipsoidLevel& level : data.levels)
            gpu->levels.push_back({6 * std::size_t(level.first), 6 * std::size_t(level.count), level.targetHeightPx});

        Ogre::HardwareBufferManager& buffers = Ogre::HardwareBufferManager::getSingleton();
        gpu->vertexData = std::make_unique<Ogre::VertexData>();
        Ogre::VertexDeclaration* declaration = gpu->vertexData->vertexDeclaration;
        std::size_t offset = 0;
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 0).getSize();
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 1).getSize();
        for (unsigned short a = 2; a <= 3; ++a)
            offset += declaration->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_TEXTURE_COORDINATES, a).getSize();
        declaration->addElement(0, offset, Ogre::VET_UBYTE4_NORM, Ogre::VES_DIFFUSE);
        Ogre::HardwareVertexBufferSharedPtr vertexBuffer =
            buffers.createVertexBuffer(sizeof(EllipsoidVertex), vertices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        vertexBuffer->writeData(0, vertexBuffer->getSizeInBytes(), vertices.data(), true);
        gpu->vertexData->vertexBufferBinding->setBinding(0, vertexBuffer);
        gpu->vertexData->vertexStart = 0;
        gpu->vertexData->vertexCount = vertices.size();

        gpu->indexBuffer = quadIndices(count);
        gpu->gpuBytes = vertexBuffer->getSizeInBytes() + gpu->indexBuffer->getSizeInBytes();
        mGpu = std::move(gpu);
        return *mGpu;
    }

    const EllipsoidLineData* EllipsoidTreeResources::getLineData()
    {
        if (mLinesRead)
            return mLineData.get();
        if (mAsset.hasChunk(ELLIPSOID_LINES_CHUNK))
        {
            Result<EllipsoidLineData> decoded =
                decodeEllipsoidLineChunk(mAsset.readChunk(ELLIPSOID_LINES_CHUNK), mAsset.getName());
            if (!decoded)
                mAsset.raise(decoded.error());
            mLineData = std::make_unique<EllipsoidLineData>(std::move(decoded.value()));
        }
        mLinesRead = true;
        return mLineData.get();
    }

    namespace
    {
        /// One vertex of TreeLodEllipsoidLine.vert: start, corner, end and radius, RGBA8.
        struct LineVertex
        {
            float start[3];
            float corner[2];
            float endRadius[4];
            std::uint8_t colour[4];
        };
        static_assert(sizeof(LineVertex) == 9 * sizeof(float) + 4, "tightly packed");
    }

    const EllipsoidLineGpu* EllipsoidTreeResources::getLineGpu()
    {
        if (mLineGpu || !getLineData())
            return mLineGpu.get();
        const EllipsoidLineData& data = *mLineData;
        auto gpu = std::make_unique<EllipsoidLineGpu>();
        std::vector<LineVertex> vertices;
        vertices.reserve(4 * data.lines.size());
        const float corners[4][2] = {{0.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
        for (const EllipsoidLine& line : data.lines)
        {
            LineVertex v{};
            std::memcpy(v.start, &line.start[0], sizeof v.start);
            std::memcpy(v.endRadius, &line.end[0], 3 * sizeof(float));
            v.endRadius[3] = line.radius;
            const std::array<std::uint8_t, 4>& colour = data.palette[line.colour];
            std::copy(colour.begin(), colour.begin() + 3, v.colour);
            v.colour[3] = line.ambientOcclusion;
            for (const auto& corner : corners)
            {
                v.corner[0] = corner[0];
                v.corner[1] = corner[1];
                vertices.push_back(v);
            }
        }
        for (const EllipsoidLineLevel& level : data.levels)
            gpu->levels.push_back({6 * std::size_t(level.first), 6 * std::size_t(level.count), level.targetHeightPx});

        gpu->vertexData = std::make_unique<Ogre::VertexData>();
        Ogre::VertexDeclaration* declaration = gpu->vertexData->vertexDeclaration;
        std::size_t offset = 0;
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0).getSize();
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 1).getSize();
        declaration->addElement(0, offset, Ogre::VET_UBYTE4_NORM, Ogre::VES_DIFFUSE);
        Ogre::HardwareVertexBufferSharedPtr vertexBuffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            sizeof(LineVertex), vertices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        vertexBuffer->writeData(0, vertexBuffer->getSizeInBytes(), vertices.data(), true);
        gpu->vertexData->vertexBufferBinding->setBinding(0, vertexBuffer);
        gpu->vertexData->vertexStart = 0;
        gpu->vertexData->vertexCount = vertices.size();
        gpu->indexBuffer = quadIndices(data.lines.size());
        gpu->gpuBytes = vertexBuffer->getSizeInBytes() + gpu->indexBuffer->getSizeInBytes();
        mLineGpu = std::move(gpu);
        return mLineGpu.get();
    }
}
