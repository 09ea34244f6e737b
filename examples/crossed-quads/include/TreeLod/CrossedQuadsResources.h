// CrossedQuadsResources: the crossed quads (chunk "crossed-quads", CrossedQuadsData.h) of one
// TreeAsset on the GPU, shared by every CrossedQuadsTree and Forest level drawing it; made on
// first use through TreeAsset::getResources (TechniqueResources.h), removed when the asset unloads.
#pragma once

#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// One quad's draw: 6 indices from indexStart in CrossedQuadsGpu::indexBuffer, its texture and
    /// its materials (clones of TreeLod/Leaf and TreeLod/LeafShadowed, both with a clone of
    /// TreeLod/LeafCaster as shadow caster). The materials are plain (not instanced): the Forest
    /// makes their instanced variants.
    struct CrossedQuadsPart
    {
        std::size_t indexStart = 0;
        Ogre::String material;
        Ogre::String shadowedMaterial;
        Ogre::String casterMaterial;
        Ogre::String texture;
    };

    /// Every quad in one vertex buffer: 4 vertices per quad (position, normal = the quad's facing
    /// direction n, uv0; local metres), two triangles each in a 16-bit index buffer.
    struct CrossedQuadsGpu
    {
        std::unique_ptr<Ogre::VertexData> vertexData;
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        std::vector<CrossedQuadsPart> parts;
        Ogre::AxisAlignedBox bounds; ///< of every quad, local metres
        std::uint64_t gpuBytes = 0;  ///< textures + vertices + indices
    };

    class CrossedQuadsResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static CrossedQuadsResources& of(TreeAsset& asset);

        explicit CrossedQuadsResources(TreeAsset& asset) : mAsset(asset) {}
        ~CrossedQuadsResources() override;

        /// The decoded chunk (decoded on first call, nothing uploaded); throws naming the asset when
        /// the package lacks the chunk, has another format version, or the chunk does not decode.
        const CrossedQuadsData& getData();
        /// The box of every quad, local metres, from the decoded chunk.
        Ogre::AxisAlignedBox getBounds();

        /// Built on first call; throws naming the asset when the package lacks the chunk, has
        /// another format version, or the chunk does not decode. Needs TreeLod's materials.
        const CrossedQuadsGpu& getGpu();

        std::uint64_t getGpuBytes() const override { return mGpu ? mGpu->gpuBytes : 0; }

    private:
        TreeAsset& mAsset;
        std::unique_ptr<CrossedQuadsData> mData;
        std::unique_ptr<CrossedQuadsGpu> mGpu;
    };
}
