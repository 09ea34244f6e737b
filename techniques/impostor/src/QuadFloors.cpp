#include "TreeLod/QuadFloors.h"

#include "TreeLod/ImpostorResources.h"
#include "TreeLod/TechniqueSupport.h"

#include <OgreBillboard.h>
#include <OgreEntity.h>
#include <OgreHardwareBufferManager.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgrePass.h>
#include <OgreSceneNode.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        /// Floats per vertex: position xyz (the quad's corner), uv0, uv4 (tree position + scale), uv5 (cos, sin).
        constexpr std::size_t VERTEX_FLOATS = 3 + 2 + 4 + 2;

        bool useShadowedMaterials(const Ogre::SceneManager& sceneManager)
        {
            return sceneManager.isShadowTechniqueTextureBased() && sceneManager.isShadowTechniqueIntegrated();
        }

        /// The impostor chunk of every species, decoded (throws naming an asset without it or a
        /// missing asset), checking each instance's kind.
        std::vector<const ImpostorData*> impostorData(const std::vector<TreeAssetPtr>& assets,
                                                      const std::vector<ForestInstance>& instances, const char* who)
        {
            std::vector<const ImpostorData*> out;
            for (const TreeAssetPtr& asset : assets)
            {
                if (!asset)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "species " + std::to_string(out.size()) +
                                                                        " has no asset", who);
                out.push_back(&ImpostorResources::of(*asset).getData());
            }
            for (std::size_t i = 0; i < instances.size(); ++i)
                if (instances[i].kind >= assets.size())
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "instance " + std::to_string(i) + ": species " + std::to_string(instances[i].kind) +
                                    " of " + std::to_string(assets.size()),
                                who);
            return out;
        }

        /// The impostor of every species on the GPU (built on first use), checked as impostorData.
        std::vector<const ImpostorGpu*> impostors(const std::vector<TreeAssetPtr>& assets,
                                                  const std::vector<ForestInstance>& instances, const char* who)
        {
            impostorData(assets, instances, who);
            std::vector<const ImpostorGpu*> out;
            for (const TreeAssetPtr& asset : assets)
                out.push_back(&ImpostorResources::of(*asset).getGpu());
            return out;
        }

        /// A mesh of one quad per tree in `trees` (the impostor's corners; uv4, uv5 per tree).
        Ogre::MeshPtr buildQuadMesh(const Ogre::String& name, const Ogre::String& group, const ImpostorGpu& gpu,
                                    const std::vector<const ForestInstance*>& trees, const Ogre::String& material)
        {
            const float corners[4][4] = {{-gpu.halfWidth, gpu.bottom, 0.0f, 1.0f},
                                         {gpu.halfWidth, gpu.bottom, 1.0f, 1.0f},
                                         {gpu.halfWidth, gpu.top, 1.0f, 0.0f},
                                         {-gpu.halfWidth, gpu.top, 0.0f, 0.0f}};
            std::vector<float> vertices;
            vertices.reserve(trees.size() * 4 * VERTEX_FLOATS);
            std::vector<std::uint16_t> indices;
            indices.reserve(trees.size() * 6);
            Ogre::AxisAlignedBox bounds;
            for (const ForestInstance* tree : trees)
            {
                const std::uint16_t base = std::uint16_t(vertices.size() / VERTEX_FLOATS);
                for (const float* c : corners)
                    vertices.insert(vertices.end(), {c[0], c[1], 0.0f, c[2], c[3], tree->position.x, tree->position.y,
                                                     tree->position.z, tree->scale, std::cos(tree->rotationY),
                                                     std::sin(tree->rotationY)});
                for (std::uint16_t i : {0, 1, 2, 0, 2, 3})
                    indices.push_back(std::uint16_t(base + i));
                // The quad turns about +Y: it sweeps a box of half width halfWidth.
                const Ogre::Vector3 p(tree->position.x, tree->position.y, tree->position.z);
                const float s = tree->scale, w = gpu.halfWidth;
                bounds.merge(Ogre::AxisAlignedBox(p + s * Ogre::Vector3(-w, gpu.bottom, -w),
                                                  p + s * Ogre::Vector3(w, gpu.top, w)));
            }

            Ogre::MeshPtr mesh = Ogre::MeshManager::getSingleton().createManual(name, group);
            Ogre::SubMesh* sub = mesh->createSubMesh();
            sub->useSharedVertices = false;
            sub->vertexData = new Ogre::VertexData();
            Ogre::VertexDeclaration& decl = *sub->vertexData->vertexDeclaration;
            std::size_t offset = 0;
            offset += decl.addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
            offset += decl.addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0).getSize();
            offset += decl.addElement(0, offset, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 4).getSize();
            decl.addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 5);
            sub->vertexData->vertexCount = vertices.size() / VERTEX_FLOATS;
            Ogre::HardwareVertexBufferSharedPtr vb = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                VERTEX_FLOATS * sizeof(float), sub->vertexData->vertexCount, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            vb->writeData(0, vertices.size() * sizeof(float), vertices.data(), true);
            sub->vertexData->vertexBufferBinding->setBinding(0, vb);
            sub->indexData->indexCount = indices.size();
            sub->indexData->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                Ogre::HardwareIndexBuffer::IT_16BIT, indices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            sub->indexData->indexBuffer->writeData(0, indices.size() * sizeof(std::uint16_t), indices.data(), true);
            sub->setMaterialName(material, group);
            mesh->_setBounds(bounds);
            mesh->_setBoundingSphereRadius(std::max(bounds.getMaximum().length(), bounds.getMinimum().length()));
            mesh->load();
            return mesh;
        }

        /// The trees of species `kind` in batches of at most `maxTrees`, each a compact patch: sorted
        /// into square cells holding about maxTrees trees each (row by row), then cut in order, so
        /// that culling skips whole batches.
        std::vector<std::vector<const ForestInstance*>> spatialBatches(const std::vector<ForestInstance>& instances,
                                                                       std::size_t kind, std::size_t maxTrees)
        {
            std::vector<const ForestInstance*> trees;
            glm::vec2 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            for (const ForestInstance& tree : instances)
                if (tree.kind == kind)
                {
                    trees.push_back(&tree);
                    lo = glm::min(lo, glm::vec2(tree.position.x, tree.position.z));
                    hi = glm::max(hi, glm::vec2(tree.position.x, tree.position.z));
                }
            const float cells = std::max(1.0f, std::sqrt(float(trees.size()) / float(maxTrees)));
            const glm::vec2 cell = glm::max((hi - lo) / cells, glm::vec2(1e-3f));
            auto key = [&](const ForestInstance* t) {
                const int x = std::min(int(cells) - 1, int((t->position.x - lo.x) / cell.x));
                const int z = std::min(int(cells) - 1, int((t->position.z - lo.y) / cell.y));
                return z * int(cells) + x;
            };
            std::stable_sort(trees.begin(), trees.end(),
                             [&](const ForestInstance* a, const ForestInstance* b) { return key(a) < key(b); });
            std::vector<std::vector<const ForestInstance*>> batches;
            for (std::size_t i = 0; i < trees.size(); i += maxTrees)
                batches.emplace_back(trees.begin() + std::ptrdiff_t(i),
                                     trees.begin() + std::ptrdiff_t(std::min(trees.size(), i + maxTrees)));
            return batches;
        }

        std::uint64_t meshBytes(const Ogre::MeshPtr& mesh)
        {
            const Ogre::SubMesh* sub = mesh->getSubMesh(0);
            return std::uint64_t(sub->vertexData->vertexCount) * VERTEX_FLOATS * sizeof(float) +
                   std::uint64_t(sub->indexData->indexCount) * sizeof(std::uint16_t);
        }

        /// The impostors' textures (gpuBytes less their own quad: 4 vertices of 5 floats + 6 indices).
        std::uint64_t textureBytes(const std::vector<const ImpostorGpu*>& gpus)
        {
            std::uint64_t bytes = 0;
            for (std::size_t s = 0; s < gpus.size(); ++s)
            {
                bool seen = false;
                for (std::size_t t = 0; t < s; ++t)
                    seen = seen || gpus[t] == gpus[s];
                if (!seen)
                    bytes += gpus[s]->gpuBytes - (4 * 5 * sizeof(float) + 6 * sizeof(std::uint16_t));
            }
            return bytes;
        }

        Ogre::String uniqueName(const char* kind)
        {
            static unsigned counter = 0;
            return Ogre::String("TreeLod/") + kind + "/" + std::to_string(counter++);
        }
    }

    EntityFloor::EntityFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                             const std::vector<TreeAssetPtr>& assets, const std::vector<ForestInstance>& instances)
        : mSceneManager(sceneManager)
    {
        const std::vector<const ImpostorGpu*> gpus = impostors(assets, instances, "EntityFloor");
        const bool shadowed = useShadowedMaterials(sceneManager);
        const ForestInstance origin{glm::vec3(0.0f), 0.0f, 1.0f, 0};
        for (std::size_t s = 0; s < assets.size(); ++s)
        {
            mMeshes.push_back(buildQuadMesh(uniqueName("EntityFloorQuad"), assets[s]->getGroup(), *gpus[s], {&origin},
                                            shadowed ? gpus[s]->shadowedMaterial : gpus[s]->material));
            mGpuBytes += meshBytes(mMeshes.back());
        }
        mGpuBytes += textureBytes(gpus);
        mEntities.reserve(instances.size());
        mNodes.reserve(instances.size());
        for (const ForestInstance& tree : instances)
        {
            Ogre::Entity* entity = sceneManager.createEntity(mMeshes[tree.kind]);
            Ogre::SceneNode* node = parent.createChildSceneNode(
                Ogre::Vector3(tree.position.x, tree.position.y, tree.position.z),
                Ogre::Quaternion(Ogre::Radian(tree.rotationY), Ogre::Vector3::UNIT_Y));
            node->setScale(Ogre::Vector3(tree.scale));
            node->attachObject(entity);
            mEntities.push_back(entity);
            mNodes.push_back(node);
        }
    }

    EntityFloor::~EntityFloor()
    {
        for (std::size_t i = 0; i < mEntities.size(); ++i)
        {
            mNodes[i]->detachAllObjects();
            mSceneManager.destroyEntity(mEntities[i]);
            mSceneManager.destroySceneNode(mNodes[i]);
        }
        for (const Ogre::MeshPtr& mesh : mMeshes)
            Ogre::MeshManager::getSingleton().remove(mesh);
    }

    MergedQuadFloor::MergedQuadFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                                     const std::vector<TreeAssetPtr>& assets,
                                     const std::vector<ForestInstance>& instances)
        : mSceneManager(sceneManager)
    {
        const std::vector<const ImpostorGpu*> gpus = impostors(assets, instances, "MergedQuadFloor");
        const bool shadowed = useShadowedMaterials(sceneManager);
        mGpuBytes = textureBytes(gpus);
        mNode = parent.createChildSceneNode();
        for (std::size_t s = 0; s < assets.size(); ++s)
            for (const std::vector<const ForestInstance*>& batch : spatialBatches(instances, s, BATCH_TREES))
            {
                mMeshes.push_back(buildQuadMesh(uniqueName("MergedQuads"), assets[s]->getGroup(), *gpus[s], batch,
                                                shadowed ? gpus[s]->shadowedMaterial : gpus[s]->material));
                mGpuBytes += meshBytes(mMeshes.back());
                mEntities.push_back(sceneManager.createEntity(mMeshes.back()));
                mNode->attachObject(mEntities.back());
            }
    }

    MergedQuadFloor::~MergedQuadFloor()
    {
        mNode->detachAllObjects();
        for (Ogre::Entity* entity : mEntities)
            mSceneManager.destroyEntity(entity);
        mSceneManager.destroySceneNode(mNode);
        for (const Ogre::MeshPtr& mesh : mMeshes)
            Ogre::MeshManager::getSingleton().remove(mesh);
    }

    BillboardSetFloor::BillboardSetFloor(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent,
                                         const std::vector<TreeAssetPtr>& assets,
                                         const std::vector<ForestInstance>& instances)
        : mSceneManager(sceneManager)
    {
        // The chunk's data only: the floor draws none of the impostor's GPU resources.
        const std::vector<const ImpostorData*> impostors = impostorData(assets, instances, "BillboardSetFloor");
        mNode = parent.createChildSceneNode();
        try
        {
            for (std::size_t s = 0; s < assets.size(); ++s)
            {
                // The impostor's colour texture, written as it is read (sRGB), unlit.
                const ImpostorData& data = *impostors[s];
                const Ogre::String texture = uniqueName("BillboardSetFloorColour");
                mGpuBytes += uploadTexture(texture, assets[s]->getGroup(), data.colour);
                mTextures.push_back(Ogre::TextureManager::getSingleton().getByName(texture, assets[s]->getGroup()));
                mMaterials.push_back(cloneBaseMaterial("TreeLod/BillboardSetFloor", uniqueName("BillboardSetFloor"),
                                                       assets[s]->getGroup(), assets[s]->getName()));
                Ogre::Pass* pass = mMaterials.back()->getTechnique(0)->getPass(0);
                pass->getTextureUnitState("Colour")->setTexture(mTextures.back());
                pass->setAlphaRejectSettings(Ogre::CMPF_GREATER_EQUAL,
                                             std::uint8_t(std::lround(255.0f * data.alphaCutoff)));
                pass->getFragmentProgramParameters()->setNamedConstant("alphaCutoff", data.alphaCutoff);
                mMaterials.back()->load();

                const float width = 2.0f * data.halfWidth, height = data.top - data.bottom;
                const float centre = 0.5f * (data.top + data.bottom);
                for (const std::vector<const ForestInstance*>& trees : spatialBatches(instances, s, MAX_SET_TREES))
                {
                    Ogre::BillboardSet* set = sceneManager.createBillboardSet(unsigned(trees.size()));
                    mSets.push_back(set);
                    set->setAutoextend(false);
                    set->setBillboardType(Ogre::BBT_ORIENTED_COMMON); // upright, turned towards the camera
                    set->setCommonDirection(Ogre::Vector3::UNIT_Y);
                    set->setUseAccurateFacing(true); // towards the camera's position, as the quad level
                    set->setBillboardOrigin(Ogre::BBO_CENTER);
                    set->setCastShadows(false);
                    set->setMaterial(mMaterials.back());
                    float largest = 0.0f;
                    for (const ForestInstance* tree : trees)
                        largest = std::max(largest, tree->scale);
                    set->setDefaultDimensions(largest * width, largest * height); // bounds of the set
                    for (const ForestInstance* tree : trees)
                        set->createBillboard(tree->position.x, tree->position.y + tree->scale * centre, tree->position.z)
                            ->setDimensions(tree->scale * width, tree->scale * height);
                    mNode->attachObject(set);
                    // Position, colour, uv per vertex; four vertices and six 16-bit indices per billboard.
                    mGpuBytes += trees.size() * (4 * (3 * sizeof(float) + 4 + 2 * sizeof(float)) + 6 * 2);
                }
            }
        }
        catch (...)
        {
            release();
            throw;
        }
    }

    BillboardSetFloor::~BillboardSetFloor() { release(); }

    void BillboardSetFloor::release()
    {
        if (!mNode)
            return;
        mNode->detachAllObjects();
        for (Ogre::BillboardSet* set : mSets)
            mSceneManager.destroyBillboardSet(set);
        mSets.clear();
        mSceneManager.destroySceneNode(mNode);
        mNode = nullptr;
        for (const Ogre::MaterialPtr& material : mMaterials)
            Ogre::MaterialManager::getSingleton().remove(material);
        mMaterials.clear();
        for (const Ogre::TexturePtr& texture : mTextures)
            Ogre::TextureManager::getSingleton().remove(texture);
        mTextures.clear();
    }
}
