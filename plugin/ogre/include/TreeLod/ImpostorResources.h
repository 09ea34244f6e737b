// ImpostorResources: the one-quad impostor (chunk "impostor", ImpostorData.h) of one TreeAsset on
// the GPU, shared by every ImpostorTree and Forest level drawing it.
#pragma once

#include "TreeLod/ImpostorData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <memory>

namespace TreeLod
{
    class TreeAsset;

    /// The impostor of chunk "impostor" on the GPU (ImpostorData.h): one quad, rotated about +Y
    /// towards the camera in the vertex program. Instanced only: its materials' vertex programs read
    /// the Forest's instance data (uv4, uv5; Forest.h); an ImpostorTree draws one instance.
    /// Vertex: position (local, the quad in the x-y plane: x in [-halfWidth, halfWidth], y in
    /// [bottom, top]), uv0. Built on first use by ImpostorResources::getGpu.
    struct ImpostorGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer; ///< two triangles
        Ogre::String material;         ///< clone of TreeLod/Impostor with the textures bound
        Ogre::String shadowedMaterial; ///< receives texture shadows
        Ogre::String texture;          ///< colour and coverage (unit 0)
        Ogre::String normalTexture;    ///< normal and ambient occlusion (unit 1)
        float halfWidth = 0.0f;        ///< the quad: x in [-halfWidth, halfWidth] (metres)
        float bottom = 0.0f, top = 0.0f; ///< y in [bottom, top] (metres)
        std::uint64_t gpuBytes = 0;    ///< textures + vertices + indices
    };

    class ImpostorResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static ImpostorResources& of(TreeAsset& asset);

        explicit ImpostorResources(TreeAsset& asset) : mAsset(asset) {}
        ~ImpostorResources() override;

        /// The decoded chunk (on first call); throws naming the asset when the package lacks the
        /// chunk, has another format version or a broken one.
        const ImpostorData& getData();
        /// The impostor on the GPU, built on first call (nothing is left behind when it throws).
        const ImpostorGpu& getGpu();

        std::uint64_t getGpuBytes() const override { return mGpu ? mGpu->gpuBytes : 0; }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<ImpostorData> mData;
        std::unique_ptr<ImpostorGpu> mGpu;
    };
}
