// TreeAsset: an Ogre resource for one *.treelod package.
//
// Loading reads the package's header and chunk table only (checksummed, see Package.h);
// each technique's chunk is decoded and uploaded on first use, so a scene pays only for
// the techniques and levels it draws ("model only what a scene requires").
// Errors (bad package, missing chunk) throw Ogre::InvalidParametersException whose text
// names the resource, the chunk and the reason.
#pragma once

#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreMesh.h>
#include <OgreResource.h>

#include <map>
#include <memory>
#include <vector>

namespace TreeLod
{
    /// One LoDF level shared by every quantised FoliageLodTree of an asset: the active leaves'
    /// indices packed (no padding), one range per run of same-material clusters, in the order
    /// of FoliageLodTree's leaf parts. Built once, never rewritten: instances switch between
    /// levels by pointing at another one, so they upload nothing and can be instanced.
    struct FoliageLodLevel
    {
        Ogre::HardwareIndexBufferSharedPtr buffer;
        std::vector<std::pair<std::size_t, std::size_t>> ranges; ///< (start, count) per leaf part
    };

    /// A billboard cloud chunk on the GPU, built once per asset and shared by every
    /// BillboardCloudTree drawing it (paper 000 §6: all levels' quads in one vertex buffer).
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

    /// The impostor of chunk "impostor" on the GPU (ImpostorData.h): one quad, rotated about +Y
    /// towards the camera in the vertex program, for the Forest's "quad" level. Instanced only:
    /// its materials' vertex programs read the Forest's instance data (uv4, uv5; Forest.h).
    /// Vertex: position (local, the quad in the x-y plane: x in [-halfWidth, halfWidth], y in
    /// [bottom, top]), uv0. Built on first use by TreeAsset::getImpostorGpu.
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

    /// Pixel-count LoD value (AbsolutePixelCountLodStrategy's units for a perspective camera:
    /// pi * r^2 * viewport area * P00 * P11 / d^2 = 4 pi r_px^2) at which a billboard cloud
    /// whose hash cells are `cellSize` metres, in a tree of bounding radius `radius` metres,
    /// walks `entries` list entries with shader LoD factor `listFactor` (paper 000 §5.1:
    /// entries = listFactor * projected cell diagonal, the diagonal sqrt(2) * cellSize * r_px / radius).
    Ogre::Real billboardCloudPixelCount(float entries, float cellSize, float radius, float listFactor);

    class TreeAsset : public Ogre::Resource
    {
    public:
        TreeAsset(Ogre::ResourceManager* creator, const Ogre::String& name, Ogre::ResourceHandle handle,
                  const Ogre::String& group, bool isManual = false, Ogre::ManualResourceLoader* loader = nullptr);
        ~TreeAsset() override;

        /// Use these package bytes instead of opening the resource by name (for trees
        /// baked in memory, e.g. by `treelod render tree.glb`). Call before load().
        void setPackageBytes(std::vector<std::uint8_t> bytes);

        /// The package (valid after load()).
        const PackageReader& getPackage() const;
        bool hasChunk(const Ogre::String& technique, std::uint32_t level = 0) const;

        /// The decoded polygonal reference (decoded on first call).
        const ReferenceChunk& getReference();
        /// The polygonal reference as an Ogre mesh "<asset>/reference" with its materials
        /// and textures (built on first call). See TreeMeshBuilder.
        Ogre::MeshPtr getReferenceMesh();

        /// The bark alone as an Ogre mesh "<asset>/bark" with its MeshLodGenerator levels
        /// (techniques that draw their own foliage use it). Built on first call.
        Ogre::MeshPtr getBarkMesh();

        /// The LoDF foliage of chunk "lodf" (decoded on first call, checked against the
        /// reference). Its indices are renumbered to address getLeafVertexData().
        const FoliageLodData& getFoliageLod();
        /// The reference chunk's leaf vertices on the GPU, once for every instance, in the
        /// order the LoDF clusters first use them.
        Ogre::VertexData* getLeafVertexData();
        /// The shared LoDF level with `leafCount` leaves (clamped), built on first use.
        const FoliageLodLevel& getFoliageLodLevel(std::uint32_t leafCount);
        /// Shared levels built so far, and the bytes they take on the GPU.
        std::size_t getFoliageLodLevelCount() const { return mFoliageLodLevels.size(); }
        std::uint64_t getFoliageLodLevelBytes() const;

        /// The billboard cloud of chunk "billboard-cloud", or "classic-billboard-cloud" when
        /// `classic` (decoded on first call, its bark AO checked against the reference).
        const BillboardCloudData& getBillboardCloud(bool classic);
        /// Its levels (index ranges, layered, cell sizes, low-res switch), bounds, radius and list
        /// factor, from the decoded chunk alone: nothing is uploaded (buffers, textures and
        /// materials empty). What the Forest plans levels and culls with before it draws them.
        const BillboardCloudGpu& getBillboardCloudLayout(bool classic);
        /// Its GPU resources (built on first call; the layout's fields as getBillboardCloudLayout).
        const BillboardCloudGpu& getBillboardCloudGpu(bool classic);
        /// The bark mesh with the cloud's bark AO as a vertex colour, "<asset>/bark-ao/<chunk>",
        /// with MeshLodGenerator levels and TreeLod/BarkAo materials (paper 000 §5.2, §6).
        Ogre::MeshPtr getBarkAoMesh(bool classic);
        /// Materials for getBarkAoMesh's submeshes ("TreeLod/<asset>/<i>/BarkAo"), and their
        /// shadow-receiving clones ("/BarkAoShadowed"); leaf materials keep their plain names.
        const std::vector<Ogre::String>& getBarkAoMaterialNames(bool shadowed);

        /// The impostor (chunk "impostor"), built on first call; throws naming the asset when the
        /// package lacks the chunk.
        const ImpostorGpu& getImpostorGpu();

        /// Local bounds of the tree in metres (from the reference chunk).
        Ogre::AxisAlignedBox getBounds();

        /// Names of the materials made for model material i ("TreeLod/<asset>/<i>").
        const std::vector<Ogre::String>& getMaterialNames();
        /// The same materials receiving texture shadows ("TreeLod/<asset>/<i>/Shadowed", clones
        /// of TreeLod/BarkShadowed and TreeLod/LeafShadowed): for scenes with an integrated
        /// texture shadow technique.
        const std::vector<Ogre::String>& getShadowedMaterialNames();

    protected:
        void loadImpl() override;
        void unloadImpl() override;
        size_t calculateSize() const override;

    private:
        void createTextures();
        /// Clones of `barkBase` and `leafBase`, one per model material, named
        /// "TreeLod/<asset>/<i><suffix>"; an empty `leafBase` keeps the plain leaf materials.
        std::vector<Ogre::String> createMaterials(const Ogre::String& barkBase, const Ogre::String& leafBase,
                                                  const Ogre::String& suffix);
        /// The bark of the reference alone as mesh `name` (bark AO as vertex colour when given).
        Ogre::MeshPtr buildBarkMesh(const Ogre::String& name, const std::vector<Ogre::String>& materials,
                                    const std::vector<std::uint8_t>& barkAo);
        void createBillboardCloudMaterials(BillboardCloudGpu& gpu, const BillboardCloudData& data,
                                           const Ogre::String& prefix);
        [[noreturn]] void raise(const Error& error) const;
        /// Level 0 of chunk `technique`, CRC-checked; throws naming what is missing or broken.
        std::vector<std::uint8_t> readChunk(const char* technique) const;

        std::vector<std::uint8_t> mManualBytes;
        std::unique_ptr<PackageReader> mPackage;
        std::unique_ptr<ReferenceChunk> mReference;
        Ogre::MeshPtr mReferenceMesh;
        Ogre::MeshPtr mBarkMesh;
        std::unique_ptr<FoliageLodData> mFoliageLod;
        std::unique_ptr<Ogre::VertexData> mLeafVertexData;
        std::vector<std::uint32_t> mLeafVertexOrder;
        std::map<std::uint32_t, FoliageLodLevel> mFoliageLodLevels; ///< GPU vertex i = reference leaf vertex mLeafVertexOrder[i]
        std::vector<Ogre::String> mShadowedMaterialNames;
        std::vector<Ogre::String> mMaterialNames;
        std::vector<Ogre::String> mTextureNames;
        std::unique_ptr<BillboardCloudData> mBillboardClouds[2];  ///< [classic]
        std::unique_ptr<BillboardCloudGpu> mBillboardCloudLayouts[2]; ///< [classic]
        std::unique_ptr<BillboardCloudGpu> mBillboardCloudGpus[2]; ///< [classic]
        std::unique_ptr<ImpostorGpu> mImpostorGpu;
        Ogre::MeshPtr mBarkAoMeshes[2];                            ///< [classic]
        std::vector<Ogre::String> mBarkAoMaterialNames[2];         ///< [shadowed]
    };

    typedef Ogre::SharedPtr<TreeAsset> TreeAssetPtr;
}
