// CrossedQuadsResources: the crossed quads (CrossedQuadsData.h) on the GPU.
#include "TreeLod/CrossedQuadsResources.h"

#include "TreeLod/CrossedQuadsData.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreeAsset.h"

#include <OgreException.h>
#include <OgreGpuProgramParams.h>
#include <OgreHardwareBufferManager.h>
#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgrePass.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

namespace TreeLod
{
    CrossedQuadsResources& CrossedQuadsResources::of(TreeAsset& asset)
    {
        return asset.getResources<CrossedQuadsResources>(
            CROSSED_QUADS_CHUNK, [&asset] { return std::make_unique<CrossedQuadsResources>(asset); });
    }

    namespace
    {
        /// Remove what `parts` name from Ogre's managers (names not created are skipped).
        void removeParts(const std::vector<CrossedQuadsPart>& parts, const Ogre::String& group)
        {
            for (const CrossedQuadsPart& part : parts)
            {
                for (const Ogre::String& m : {part.material, part.shadowedMaterial, part.casterMaterial})
                    if (Ogre::MaterialManager::getSingleton().resourceExists(m, group))
                        Ogre::MaterialManager::getSingleton().remove(m, group);
                if (Ogre::TextureManager::getSingleton().resourceExists(part.texture, group))
                    Ogre::TextureManager::getSingleton().remove(part.texture, group);
            }
        }
    }

    CrossedQuadsResources::~CrossedQuadsResources()
    {
        if (mGpu)
            removeParts(mGpu->parts, mAsset.getGroup());
    }

    const CrossedQuadsData& CrossedQuadsResources::getData()
    {
        if (mData)
            return *mData;
        // readChunk checks the format version against the registered TechniqueDescriptor.
        Result<CrossedQuadsData> decoded =
            decodeCrossedQuadsChunk(mAsset.readChunk(CROSSED_QUADS_CHUNK), mAsset.getName());
        if (!decoded)
            mAsset.raise(decoded.error());
        mData = std::make_unique<CrossedQuadsData>(std::move(decoded.value()));
        return *mData;
    }

    Ogre::AxisAlignedBox CrossedQuadsResources::getBounds()
    {
        Ogre::AxisAlignedBox box;
        for (const CrossedQuad& q : getData().quads)
            for (const glm::vec3& p : {q.point(q.left, q.bottom), q.point(q.right, q.top)})
                box.merge(Ogre::Vector3(p.x, p.y, p.z));
        return box;
    }

    const CrossedQuadsGpu& CrossedQuadsResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
        const CrossedQuadsData& data = getData();

        auto gpu = std::make_unique<CrossedQuadsGpu>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/crossed-quads/";
        std::vector<float> vertices; // x y z, nx ny nz, u v
        std::uint64_t textureBytes = 0; // as uploaded (decoded at load or not)
        std::vector<std::uint16_t> indices;
        // A failure half-way (e.g. TreeLod's materials missing) removes what was made so far, so a
        // later call can try again.
        try
        {
            for (std::size_t i = 0; i < data.quads.size(); ++i)
            {
                const CrossedQuad& q = data.quads[i];
                const glm::vec3 n = q.facing(); // the normal: the leaf shader turns it to the viewer
                const std::uint16_t first = std::uint16_t(vertices.size() / 8);
                const float corners[4][4] = {{q.left, q.bottom, 0.0f, 1.0f},
                                             {q.right, q.bottom, 1.0f, 1.0f},
                                             {q.right, q.top, 1.0f, 0.0f},
                                             {q.left, q.top, 0.0f, 0.0f}};
                for (const auto& c : corners)
                {
                    const glm::vec3 p = q.point(c[0], c[1]);
                    vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z, c[2], c[3]});
                }
                CrossedQuadsPart part;
                part.indexStart = indices.size();
                for (std::uint16_t k : {0, 1, 2, 0, 2, 3})
                    indices.push_back(std::uint16_t(first + k));

                const Ogre::String name = prefix + std::to_string(i);
                part.texture = name + "-colour";
                part.material = name;
                part.shadowedMaterial = name + "/Shadowed";
                part.casterMaterial = name + "/Caster";
                gpu->parts.push_back(part); // named before anything is made, for removeParts
                textureBytes += uploadTexture(part.texture, mAsset.getGroup(), q.colour);
                Ogre::MaterialPtr plain = cloneBaseMaterial("TreeLod/Leaf", part.material, mAsset.getGroup(), mAsset.getName());
                Ogre::MaterialPtr shadowed =
                    cloneBaseMaterial("TreeLod/LeafShadowed", part.shadowedMaterial, mAsset.getGroup(), mAsset.getName());
                Ogre::MaterialPtr caster =
                    cloneBaseMaterial("TreeLod/LeafCaster", part.casterMaterial, mAsset.getGroup(), mAsset.getName());
                // Albedo = the texture (white base and back colour), alpha-tested at the chunk's cutoff.
                for (const Ogre::MaterialPtr& m : {plain, shadowed, caster})
                    configureModelMaterial(m, part.texture, Ogre::ColourValue::White, Ogre::ColourValue::White,
                                           data.alphaCutoff);
                // The caster alpha-tests the same texture, so shadows have the quads' leaf shapes.
                plain->getTechnique(0)->setShadowCasterMaterial(caster);
                shadowed->getTechnique(0)->setShadowCasterMaterial(caster);
            }
        }
        catch (...)
        {
            removeParts(gpu->parts, mAsset.getGroup());
            throw;
        }

        gpu->bounds = getBounds();
        gpu->vertexData = std::make_unique<Ogre::VertexData>();
        Ogre::VertexData& vd = *gpu->vertexData;
        vd.vertexCount = vertices.size() / 8;
        Ogre::VertexDeclaration* decl = vd.vertexDeclaration;
        std::size_t offset = decl->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_NORMAL).getSize();
        decl->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0);
        Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            8 * sizeof(float), vd.vertexCount, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        buffer->writeData(0, vertices.size() * sizeof(float), vertices.data(), true);
        vd.vertexBufferBinding->setBinding(0, buffer);
        gpu->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
            Ogre::HardwareIndexBuffer::IT_16BIT, indices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        gpu->indexBuffer->writeData(0, indices.size() * sizeof(std::uint16_t), indices.data(), true);
        gpu->gpuBytes =
            textureBytes + vertices.size() * sizeof(float) + indices.size() * sizeof(std::uint16_t);
        mGpu = std::move(gpu);
        return *mGpu;
    }
}
