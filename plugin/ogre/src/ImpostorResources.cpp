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

    namespace
    {
        /// Remove what `gpu` names from Ogre's managers (whatever of it was made).
        void removeGpu(const ImpostorGpu& gpu, const Ogre::String& group)
        {
            for (const Ogre::String& m : {gpu.material, gpu.shadowedMaterial, gpu.material + "/Caster"})
                Ogre::MaterialManager::getSingleton().remove(m, group);
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
            uploadTexture(gpu->texture, mAsset.getGroup(), data.colour);
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
            gpu->vertexData = std::make_unique<Ogre::VertexData>();
            Ogre::VertexData& vd = *gpu->vertexData;
            vd.vertexCount = 4;
            const std::size_t offset =
                vd.vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
            vd.vertexDeclaration->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0);
            Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                sizeof(vertices[0]), 4, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            buffer->writeData(0, sizeof(vertices), vertices, true);
            vd.vertexBufferBinding->setBinding(0, buffer);
            const std::uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
            gpu->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                Ogre::HardwareIndexBuffer::IT_16BIT, 6, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            gpu->indexBuffer->writeData(0, sizeof(indices), indices, true);
            gpu->gpuBytes = data.gpuBytes() + sizeof(vertices) + sizeof(indices);

            // Materials: clones of TreeLod/Impostor(Shadowed) and of their shadow caster, the textures
            // bound to units Colour and Normal, the alpha cutoff set.
            auto configure = [&](const Ogre::MaterialPtr& material) {
                material->load();
                for (Ogre::Technique* tech : material->getTechniques())
                    for (Ogre::Pass* pass : tech->getPasses())
                    {
                        if (Ogre::TextureUnitState* unit = pass->getTextureUnitState("Colour"))
                            unit->setTextureName(gpu->texture);
                        if (Ogre::TextureUnitState* unit = pass->getTextureUnitState("Normal"))
                            unit->setTextureName(gpu->normalTexture);
                        if (pass->hasFragmentProgram())
                        {
                            Ogre::GpuProgramParametersSharedPtr p = pass->getFragmentProgramParameters();
                            p->setIgnoreMissingParams(true);
                            p->setNamedConstant("alphaCutoff", data.alphaCutoff);
                        }
                    }
            };
            auto clone = [&](const Ogre::String& base, const Ogre::String& name) {
                Ogre::MaterialPtr material = cloneBaseMaterial(base, name, mAsset.getGroup(), mAsset.getName());
                configure(material);
                return material;
            };
            Ogre::MaterialPtr caster;
            for (const Ogre::String& name : {gpu->material, gpu->shadowedMaterial})
            {
                Ogre::MaterialPtr material =
                    clone(name == gpu->material ? "TreeLod/Impostor" : "TreeLod/ImpostorShadowed", name);
                Ogre::Technique* tech = material->getTechnique(0);
                if (Ogre::MaterialPtr base = tech->getShadowCasterMaterial())
                {
                    if (!caster)
                        caster = clone(base->getName(), prefix + "/Caster");
                    tech->setShadowCasterMaterial(caster);
                }
            }
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
