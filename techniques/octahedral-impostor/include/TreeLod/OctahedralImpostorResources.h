// OctahedralImpostorResources: the octahedral impostor (chunk "octahedral-impostor",
// OctahedralImpostorData.h) of one TreeAsset on the GPU, shared by every OctahedralImpostorTree
// and Forest level drawing it.
#pragma once

#include "TreeLod/ImpostorTree.h"
#include "TreeLod/OctahedralImpostorData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <memory>

namespace TreeLod
{
    class TreeAsset;

    /// The octahedral impostor on the GPU: one quad whose corners are (+-1, +-1) (position x, y;
    /// uv0 0..1), made camera-facing and sized by the vertex program
    /// (techniques/octahedral-impostor/media/GLSL/TreeLodOctahedralImpostor.vert) from the cylinder and atlas constants the
    /// materials carry. Instanced only, like the one-quad impostor (ImpostorResources.h).
    struct OctahedralImpostorGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer; ///< two triangles
        Ogre::String material;         ///< clone of TreeLod/OctahedralImpostor with textures and constants
        Ogre::String shadowedMaterial; ///< receives texture shadows
        Ogre::String texture;          ///< colour and coverage atlas (unit Colour)
        Ogre::String normalTexture;    ///< normal, ambient occlusion and depth atlas (unit Normal)
        Ogre::AxisAlignedBox bounds;   ///< local: what the quad may cover, turned any way
        std::uint64_t gpuBytes = 0;    ///< textures + vertices + indices

        ImpostorQuad quad() const { return {vertexData.get(), indexBuffer, material, shadowedMaterial, bounds}; }
    };

    class OctahedralImpostorResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static OctahedralImpostorResources& of(TreeAsset& asset);

        explicit OctahedralImpostorResources(TreeAsset& asset) : mAsset(asset) {}
        ~OctahedralImpostorResources() override;

        /// The decoded chunk (on first call); throws naming the asset when the package lacks the
        /// chunk, has another format version or a broken one.
        const OctahedralImpostorData& getData();
        /// The impostor on the GPU, built on first call (nothing is left behind when it throws).
        const OctahedralImpostorGpu& getGpu();
        /// Local bounds of everything the quad may cover (from the decoded chunk).
        Ogre::AxisAlignedBox getDrawnBounds();

        std::uint64_t getGpuBytes() const override { return mGpu ? mGpu->gpuBytes : 0; }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<OctahedralImpostorData> mData;
        std::unique_ptr<OctahedralImpostorGpu> mGpu;
    };
}
