// EllipsoidTreeResources: the ellipsoids of one TreeAsset (chunk "ellipsoids", EllipsoidTreeData.h)
// on the GPU, shared by every EllipsoidTree drawing it: one quad per ellipsoid, every level in one
// vertex buffer, a level one index range (the paper's sequential array, §5).
#pragma once

#include "TreeLod/EllipsoidTreeData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// Vertices: 4 per ellipsoid, POSITION = centre, uv0 = corner (+-1, +-1), uv1..uv3 = the
    /// semi-axes with the level's scale applied, DIFFUSE = sRGB colour and AO (TreeLodEllipsoid.vert).
    struct EllipsoidTreeGpu
    {
        struct Level
        {
            std::size_t indexStart = 0, indexCount = 0;
            float targetHeightPx = 0.0f;
        };
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        std::vector<Level> levels;   ///< finest first
        Ogre::AxisAlignedBox bounds; ///< local: every level's ellipsoids
        std::uint64_t gpuBytes = 0;  ///< vertices + indices
    };

    class EllipsoidTreeResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static EllipsoidTreeResources& of(TreeAsset& asset);

        explicit EllipsoidTreeResources(TreeAsset& asset) : mAsset(asset) {}
        ~EllipsoidTreeResources() override;

        /// The decoded chunk (on first call); throws naming the asset when the package lacks the
        /// chunk or has a broken one.
        const EllipsoidTreeData& getData();
        /// The ellipsoids on the GPU, built on first call.
        const EllipsoidTreeGpu& getGpu();

        std::uint64_t getGpuBytes() const override { return mGpu ? mGpu->gpuBytes : 0; }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<EllipsoidTreeData> mData;
        std::unique_ptr<EllipsoidTreeGpu> mGpu;
    };
}
