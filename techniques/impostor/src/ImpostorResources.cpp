// ImpostorResources: the one-quad impostor (chunk "impostor", ImpostorData.h) on the GPU.
#include "TreeLod/ImpostorResources.h"

#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/ImpostorData.h"
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
    ImpostorResources& ImpostorResources::of(TreeAsset& asset)
    {
        return asset.getResources<ImpostorResources>(IMPOSTOR_CHUNK,
                                                     [&asset] { return std::make_unique<ImpostorResources>(asset); });
    }

    std::size_t makeImpostorQuad(const float (&vertices)[4][5], std::unique_ptr<Ogre::VertexData>& vertexData,
                                 Ogre::HardwareIndexBufferSharedPtr& indexBuffer)
    {
        vertexData = std::make_unique<Ogre::VertexData>();
        Ogre::VertexData& vd = *vertexData;
        vd.vertexCount = 4;
        const std::size_t offset = vd.vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        vd.vertexDeclaration->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0);
        Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            sizeof(vertices[0]), 4, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        buffer->writeData(0, sizeof(vertices), vertices, true);
        vd.vertexBufferBinding->setBinding(0, buffer);
        const std::uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
        indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
            Ogre::HardwareIndexBuffer::IT_16BIT, 6, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        indexBuffer->writeData(0, sizeof(indices), indices, true);
        return sizeof(vertices) + sizeof(indices);
    }

    void cloneImpostorMaterials(TreeAsset& asset, const Ogre::String& base, const Ogre::String& shadowedBase,
                                const Ogre::String& material, const Ogre::String& shadowedMaterial,
                                const std::vector<std::pair<Ogre::String, Ogre::String>>& textures,
                                const std::function<void(Ogre::Pass&)>& configure)
    {
        auto clone = [&](const Ogre::String& from, const Ogre::String& name) {
            Ogre::MaterialPtr m = cloneBaseMaterial(from, name, asset.getGroup(), asset.getName());
            configurePasses(m, textures, configure);
            return m;
        };
        Ogre::MaterialPtr caster;
        for (const Ogre::String& name : {material, shadowedMaterial})
        {
            Ogre::MaterialPtr m = clone(name == material ? base : shadowedBase, name);
            Ogre::Technique* tech = m->getTechnique(0);
            if (Ogre::MaterialPtr casterBase = tech->getShadowCasterMaterial())
            {
                if (!caster)
                    caster = clone(casterBase->getName(), material + "/Caster");
                tech->setShadowCasterMaterial(caster);
            }
        }
    }

    void removeImpostorMaterials(const Ogre::String& material, const Ogre::String& shadowedMaterial,
                                 const Ogre::String& group)
    {
        for (const Ogre::String& m : {material, shadowedMaterial, material + "/Caster"})
            Ogre::MaterialManager::getSingleton().remove(m, group);
    }

    namespace
    {
        /// Remove what `gpu` names from Ogre's managers (whatever of it was made).
        void removeGpu(const ImpostorGpu& gpu, const Ogre::String& group)
        {
            removeImpostorMaterials(gpu.material, gpu.shadowedMaterial, group);
            for (const Ogre::String& t : {gpu.texture, gpu.normalTexture})
                Ogre::TextureManager::getSingleton().remove(t, group);
        }
    }

    ImpostorResources::~ImpostorResources()
    {
        if (mGpu)
            removeGpu(*mGpu, mAsset.getGroup());
    }

    const ImpostorData& ImpostorResources::getData()
    {
        if (mData)
            return *mData;
        // TreeAsset::readChunk checks the format version against the registered descriptor.
        Result<ImpostorData> decoded = decodeImpostorChunk(mAsset.readChunk(IMPOSTOR_CHUNK), mAsset.getName());
        if (!decoded)
            mAsset.raise(decoded.error());
        mData = std::make_unique<ImpostorData>(std::move(decoded.value()));
        return *mData;
    }

    const ImpostorGpu& ImpostorResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
        const ImpostorData& data = getData();
        auto gpu = std::make_unique<ImpostorGpu>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/impostor";
        gpu->texture = prefix + "-colour";
        gpu->normalTexture = prefix + "-normal";
        gpu->material = prefix;
        gpu->shadowedMaterial = prefix + "/Shadowed";
        try
        {
            const std::uint64_t textureBytes = uploadTexture(gpu->texture, mAsset.getGroup(), data.colour) +
                                               uploadTexture(gpu->normalTexture, mAsset.getGroup(), data.normal);

            // The quad (ImpostorData.h): x in [-halfWidth, halfWidth], y in [bottom, top], facing +Z.
            const float w = data.halfWidth;
            gpu->halfWidth = w;
            gpu->bottom = data.bottom;
            gpu->top = data.top;
            const float vertices[4][5] = {{-w, data.bottom, 0.0f, 0.0f, 1.0f},
                                          {w, data.bottom, 0.0f, 1.0f, 1.0f},
                                          {w, data.top, 0.0f, 1.0f, 0.0f},
                                          {-w, data.top, 0.0f, 0.0f, 0.0f}};
            gpu->gpuBytes = textureBytes + makeImpostorQuad(vertices, gpu->vertexData, gpu->indexBuffer);

            // Materials: clones of TreeLod/Impostor(Shadowed) and of their shadow caster, the textures
            // bound to units Colour and Normal, the alpha cutoff set.
            cloneImpostorMaterials(mAsset, "TreeLod/Impostor", "TreeLod/ImpostorShadowed", gpu->material,
                                   gpu->shadowedMaterial, {{"Colour", gpu->texture}, {"Normal", gpu->normalTexture}},
                                   [&](Ogre::Pass& pass) {
                                       if (!pass.hasFragmentProgram())
                                           return;
                                       Ogre::GpuProgramParametersSharedPtr p = pass.getFragmentProgramParameters();
                                       p->setIgnoreMissingParams(true);
                                       p->setNamedConstant("alphaCutoff", data.alphaCutoff);
                                   });
        }
        catch (...)
        {
            removeGpu(*gpu, mAsset.getGroup()); // a later call starts again from nothing
            throw;
        }
        mGpu = std::move(gpu);
        return *mGpu;
    }
}
