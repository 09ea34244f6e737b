// BillboardCloudResources: a billboard cloud (García et al. 2007) of one TreeAsset on the GPU,
// shared by every BillboardCloudTree and Forest level drawing it: the decoded chunk
// "billboard-cloud" or "classic-billboard-cloud" (checked against the reference), its layout,
// its buffers, textures and materials, and the bark mesh with the cloud's bark AO.
#pragma once

#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreMesh.h>
#include <OgreVertexIndexData.h>

#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// A billboard cloud chunk on the GPU, built once per asset and shared by every
    /// BillboardCloudTree drawing it (García et al. 2007 §6: all levels' quads in one vertex buffer).
    /// Vertex: position, normal (billboard normal), tangent (unit axisU), uv0 = billboard (u, v)
    /// in [0, 1]^2, uv1 = (hashX, hashY, hashWidth, hashHeight) (§4.2: the vertices carry the
    /// hash resolution), uv2 = the billboard's low-res rectangle in the atlas, normalised
    /// (x0, y0, x1, y1). Materials per level: clones of TreeLod/BillboardCloud for layered levels
    /// (material LoD: layers, then the low-res texture only), of TreeLod/BillboardCloudLowRes
    /// for the others, with the chunk's textures bound and constants set.
    struct BillboardCloudGpu
    {
        struct Level
        {
            std::size_t indexStart = 0;
            std::size_t indexCount = 0;
            bool layered = false;
            float cellSize = 0.0f;        ///< metres (layered levels)
            Ogre::String material;
            Ogre::String shadowedMaterial; ///< receives texture shadows
            /// Layered levels: the material LoD value (pixel_count, Ogre's perspective convention)
            /// below which the low-res technique is used: where listFactor * projected cell
            /// diagonal < 1 (billboardCloudPixelCount with entries = 1). 0 otherwise.
            Ogre::Real lowResPixelCount = 0.0f;
        };
        std::unique_ptr<Ogre::VertexData> vertexData; ///< null when the cloud has no billboards
        Ogre::HardwareIndexBufferSharedPtr indexBuffer;
        std::vector<Level> levels;
        Ogre::AxisAlignedBox bounds; ///< reference and billboards, local metres
        Ogre::Real radius = 0.0f;    ///< Ogre's bounding radius of `bounds` (about the origin)
        float listFactor = 1.0f;     ///< the chunk's
        std::vector<Ogre::String> textures;
        std::vector<Ogre::String> materials; ///< every material made for the cloud (casters too)
    };

    /// Pixel-count LoD value (AbsolutePixelCountLodStrategy's units for a perspective camera:
    /// pi * r^2 * viewport area * P00 * P11 / d^2 = 4 pi r_px^2) at which a billboard cloud
    /// whose hash cells are `cellSize` metres, in a tree of bounding radius `radius` metres,
    /// walks `entries` list entries with shader LoD factor `listFactor` (García et al. 2007 §5.1:
    /// entries = listFactor * projected cell diagonal, the diagonal sqrt(2) * cellSize * r_px / radius).
    Ogre::Real billboardCloudPixelCount(float entries, float cellSize, float radius, float listFactor);

    class BillboardCloudResources : public TechniqueResources
    {
    public:
        /// The asset's cloud of chunk "billboard-cloud", or "classic-billboard-cloud" when `classic`
        /// (made on first call).
        static BillboardCloudResources& of(TreeAsset& asset, bool classic);

        BillboardCloudResources(TreeAsset& asset, bool classic);
        ~BillboardCloudResources() override;

        bool isClassic() const { return mClassic; }
        /// The decoded chunk (on first call; its bark AO, kind and leaf materials checked against
        /// the reference).
        const BillboardCloudData& getData();
        /// Its levels (index ranges, layered, cell sizes, low-res switch), bounds, radius and list
        /// factor, from the decoded chunk alone: nothing is uploaded (buffers, textures and
        /// materials empty). What the Forest plans levels and culls with before it draws them.
        const BillboardCloudGpu& getLayout();
        /// Its GPU resources (built on first call; the layout's fields as getLayout).
        const BillboardCloudGpu& getGpu();
        /// The bark mesh with the cloud's bark AO as a vertex colour, "<asset>/bark-ao/<chunk>",
        /// with MeshLodGenerator levels and TreeLod/BarkAo materials (§5.2, §6).
        Ogre::MeshPtr getBarkAoMesh();
        /// Materials for getBarkAoMesh's submeshes ("TreeLod/<asset>/<i>/BarkAo"), and their
        /// shadow-receiving clones ("/BarkAoShadowed"); leaf materials keep their plain names.
        const std::vector<Ogre::String>& getBarkAoMaterialNames(bool shadowed);

        std::uint64_t getGpuBytes() const override;

    private:
        void createMaterials(BillboardCloudGpu& gpu, const BillboardCloudData& data, const Ogre::String& prefix);
        const char* chunk() const;

        TreeAsset& mAsset;
        const bool mClassic;
        std::unique_ptr<BillboardCloudData> mData;
        std::unique_ptr<BillboardCloudGpu> mLayout;
        std::unique_ptr<BillboardCloudGpu> mGpu;
        Ogre::MeshPtr mBarkAoMesh;
    };
}
