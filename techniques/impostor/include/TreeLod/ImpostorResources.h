// ImpostorResources: the one-quad impostor (chunk "impostor", ImpostorData.h) of one TreeAsset on
// the GPU, shared by every ImpostorTree and Forest level drawing it.
#pragma once

#include "TreeLod/ImpostorData.h"
#include "TreeLod/ImpostorTree.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace Ogre
{
    class Pass;
}

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

        /// What an ImpostorTree draws; bounds: the box swept by the quad turning about +Y.
        ImpostorQuad quad() const
        {
            return {vertexData.get(), indexBuffer, material, shadowedMaterial,
                    Ogre::AxisAlignedBox(-halfWidth, bottom, -halfWidth, halfWidth, top, halfWidth)};
        }
    };

    /// The impostor techniques' shared GPU pieces. makeImpostorQuad: one quad of `vertices`
    /// (position x, y, z, uv0 u, v each; counter-clockwise seen from +Z) into `vertexData` and
    /// `indexBuffer` (two triangles); returns the bytes uploaded.
    std::size_t makeImpostorQuad(const float (&vertices)[4][5], std::unique_ptr<Ogre::VertexData>& vertexData,
                                 Ogre::HardwareIndexBufferSharedPtr& indexBuffer);
    /// Clones of `base` as `material` and of `shadowedBase` as `shadowedMaterial`, their shadow
    /// caster cloned once as `<material>/Caster`, for asset `asset`; each loaded clone's passes
    /// get `textures` (unit name -> texture) and `configure(pass)`. removeImpostorMaterials
    /// removes what this made (whatever of it was made).
    void cloneImpostorMaterials(TreeAsset& asset, const Ogre::String& base, const Ogre::String& shadowedBase,
                                const Ogre::String& material, const Ogre::String& shadowedMaterial,
                                const std::vector<std::pair<Ogre::String, Ogre::String>>& textures,
                                const std::function<void(Ogre::Pass&)>& configure);
    void removeImpostorMaterials(const Ogre::String& material, const Ogre::String& shadowedMaterial,
                                 const Ogre::String& group);

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
