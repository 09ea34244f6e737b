// EllipsoidTreeResources: the ellipsoids of one TreeAsset (chunk "ellipsoids", EllipsoidTreeData.h)
// and its lines when it has them (chunk "ellipsoid-lines", EllipsoidLineData.h) on the GPU, shared by
// every EllipsoidTree and Forest drawing it: one quad per primitive, every level in one vertex
// buffer, a level one index range (the paper's sequential array, §5).
#pragma once

#include "TreeLod/EllipsoidLineData.h"
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

    /// The ellipsoids' materials (techniques/ellipsoids/media/TreeLodEllipsoid.material), shared by every asset: the
    /// programs read everything per vertex and per instance.
    constexpr const char* ELLIPSOID_MATERIAL = "TreeLod/Ellipsoid";
    /// The same receiving the sun's integrated texture shadow.
    constexpr const char* ELLIPSOID_SHADOWED_MATERIAL = "TreeLod/EllipsoidShadowed";
    /// Their shadow caster (ray-cast depth, the noise's holes).
    constexpr const char* ELLIPSOID_CASTER_MATERIAL = "TreeLod/EllipsoidCaster";
    /// The noise cube maps (EllipsoidNoise.h), group RGN_INTERNAL, one pair for every tree: the
    /// materials' texture units "NoiseAlpha" and "NoiseNormal".
    constexpr const char* ELLIPSOID_NOISE_ALPHA_TEXTURE = "TreeLod/EllipsoidNoiseAlpha";
    constexpr const char* ELLIPSOID_NOISE_NORMAL_TEXTURE = "TreeLod/EllipsoidNoiseNormal";

    /// Creates the noise cube maps when missing (filled from the core's bytes, reloadable) and
    /// binds them to the ellipsoid materials' noise units. getGpu() calls it.
    void bindEllipsoidNoise();
    /// The lines' (techniques/ellipsoids/media/TreeLodEllipsoid.material), plain and receiving.
    constexpr const char* ELLIPSOID_LINE_MATERIAL = "TreeLod/EllipsoidLine";
    constexpr const char* ELLIPSOID_LINE_SHADOWED_MATERIAL = "TreeLod/EllipsoidLineShadowed";

    /// One level of primitives on the GPU: an index range and the tree height on screen it is for.
    struct EllipsoidGpuLevel
    {
        std::size_t indexStart = 0, indexCount = 0;
        float targetHeightPx = 0.0f;
    };

    /// The level for a tree `heightPx` tall on screen (§6): the coarsest whose target height is at
    /// least `heightPx`, the finest when the tree is taller than every target. `levels` finest first.
    std::size_t levelForHeight(const std::vector<EllipsoidGpuLevel>& levels, float heightPx);

    /// The box (tree space, metres) every level of `data` draws: centres +- the scaled semi-axes' reach.
    Ogre::AxisAlignedBox ellipsoidBounds(const EllipsoidTreeData& data);

    /// Vertices: 4 per ellipsoid, POSITION = centre, uv0 = corner (+-1, +-1), the cluster's noise lod
    /// (ellipsoidNoiseBaseLod) and the level's noise threshold, uv1..uv3 = the semi-axes with the
    /// level's scale applied (uv1.w = the level's normal blend), DIFFUSE = sRGB colour and AO
    /// (TreeLodEllipsoid.vert).
    struct EllipsoidTreeGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        std::vector<EllipsoidGpuLevel> levels; ///< finest first
        Ogre::AxisAlignedBox bounds; ///< local: every level's ellipsoids
        std::uint64_t gpuBytes = 0;  ///< vertices + indices
    };

    /// Vertices: 4 per line, POSITION = start, uv0 = the corner (x: 0 start, 1 end; y: -1, +1
    /// across), uv1 = end xyz and radius, DIFFUSE = sRGB colour and AO (TreeLodEllipsoidLine.vert).
    struct EllipsoidLineGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        std::vector<EllipsoidGpuLevel> levels; ///< finest first
        std::uint64_t gpuBytes = 0;            ///< vertices + indices
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
        /// The decoded lines, or null when the package has no "ellipsoid-lines" chunk (the branches
        /// are then the reference bark mesh); throws naming the asset for a broken chunk.
        const EllipsoidLineData* getLineData();
        /// The lines on the GPU (built on first call), or null as getLineData.
        const EllipsoidLineGpu* getLineGpu();

        std::uint64_t getGpuBytes() const override
        {
            return (mGpu ? mGpu->gpuBytes : 0) + (mLineGpu ? mLineGpu->gpuBytes : 0);
        }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<EllipsoidTreeData> mData;
        std::unique_ptr<EllipsoidTreeGpu> mGpu;
        bool mLinesRead = false;
        std::unique_ptr<EllipsoidLineData> mLineData;
        std::unique_ptr<EllipsoidLineGpu> mLineGpu;
    };
}
