// EllipsoidTreeResources: the ellipsoids (chunk "ellipsoids", EllipsoidTreeData.h) on the GPU.
#include "TreeLod/EllipsoidTreeResources.h"

#include "TreeLod/TreeAsset.h"

#include <OgreHardwareBufferManager.h>

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

    namespace
    {
        /// One vertex of TreeLodEllipsoid.vert: centre, corner, three semi-axes, RGBA8.
        struct EllipsoidVertex
        {
            float centre[3];
            float corner[2];
            float axes[3][3];
            std::uint8_t colour[4];
        };
        static_assert(sizeof(EllipsoidVertex) == 14 * sizeof(float) + 4, "tightly packed");
    }

    const EllipsoidTreeGpu& EllipsoidTreeResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
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
                float reach = 0.0f;
                for (int a = 0; a < 3; ++a)
                {
                    const glm::vec3 axis = rotation[a] * (ellipsoid.radii[a] * level.scale);
                    std::memcpy(v.axes[a], &axis[0], sizeof v.axes[a]);
                    reach = std::max(reach, glm::length(axis));
                }
                std::copy(ellipsoid.colour.begin(), ellipsoid.colour.end(), v.colour);
                for (int c = 0; c < 4; ++c)
                {
                    EllipsoidVertex& out = vertices[4 * e + std::size_t(c)];
                    out = v;
                    out.corner[0] = corners[c][0];
                    out.corner[1] = corners[c][1];
                }
                const Ogre::Vector3 centre(ellipsoid.centre.x, ellipsoid.centre.y, ellipsoid.centre.z);
                gpu->bounds.merge(Ogre::AxisAlignedBox(centre - reach, centre + reach));
            }
        std::size_t index = 0;
        for (const EllipsoidLevel& level : data.levels)
        {
            gpu->levels.push_back({6 * std::size_t(level.first), 6 * std::size_t(level.count), level.targetHeightPx});
            index += 6 * std::size_t(level.count);
        }

        Ogre::HardwareBufferManager& buffers = Ogre::HardwareBufferManager::getSingleton();
        gpu->vertexData = std::make_unique<Ogre::VertexData>();
        Ogre::VertexDeclaration* declaration = gpu->vertexData->vertexDeclaration;
        std::size_t offset = 0;
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        offset += declaration->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0).getSize();
        for (unsigned short a = 1; a <= 3; ++a)
            offset += declaration->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_TEXTURE_COORDINATES, a).getSize();
        declaration->addElement(0, offset, Ogre::VET_UBYTE4_NORM, Ogre::VES_DIFFUSE);
        Ogre::HardwareVertexBufferSharedPtr vertexBuffer =
            buffers.createVertexBuffer(sizeof(EllipsoidVertex), vertices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        vertexBuffer->writeData(0, vertexBuffer->getSizeInBytes(), vertices.data(), true);
        gpu->vertexData->vertexBufferBinding->setBinding(0, vertexBuffer);
        gpu->vertexData->vertexStart = 0;
        gpu->vertexData->vertexCount = vertices.size();

        // Two triangles per quad, 16-bit indices while the vertices allow.
        const bool narrow = vertices.size() <= std::numeric_limits<std::uint16_t>::max();
        std::vector<std::uint32_t> indices;
        indices.reserve(index);
        for (std::uint32_t e = 0; e < count; ++e)
            for (const std::uint32_t corner : {0u, 1u, 2u, 0u, 2u, 3u})
                indices.push_back(4 * e + corner);
        gpu->indexBuffer = buffers.createIndexBuffer(narrow ? Ogre::HardwareIndexBuffer::IT_16BIT
                                                            : Ogre::HardwareIndexBuffer::IT_32BIT,
                                                     indices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        if (narrow)
        {
            const std::vector<std::uint16_t> small(indices.begin(), indices.end());
            gpu->indexBuffer->writeData(0, small.size() * 2, small.data(), true);
        }
        else
            gpu->indexBuffer->writeData(0, indices.size() * 4, indices.data(), true);
        gpu->gpuBytes = vertexBuffer->getSizeInBytes() + gpu->indexBuffer->getSizeInBytes();
        mGpu = std::move(gpu);
        return *mGpu;
    }
}
