// TreeAsset::getImpostorGpu: the one-quad impostor (chunk "impostor", ImpostorData.h) on the GPU.
#include "TreeAssetSupport.h"
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
    const ImpostorGpu& TreeAsset::getImpostorGpu()
    {
        if (mImpostorGpu)
            return *mImpostorGpu;
        const PackageReader& package = getPackage();
        const int index = package.findChunk(IMPOSTOR_CHUNK, 0);
        if (index >= 0 && package.chunks()[std::size_t(index)].formatVersion != IMPOSTOR_CHUNK_FORMAT_VERSION)
            raise(fail(mName, chunkElement(IMPOSTOR_CHUNK, 0),
                       "format version " + std::to_string(package.chunks()[std::size_t(index)].formatVersion) +
                           ", this build reads " + std::to_string(IMPOSTOR_CHUNK_FORMAT_VERSION) +
                           ": bake the package again"));
        Result<ImpostorData> decoded = decodeImpostorChunk(readChunk(IMPOSTOR_CHUNK), mName);
        if (!decoded)
            raise(decoded.error());
        const ImpostorData& data = decoded.value();

        auto gpu = std::make_unique<ImpostorGpu>();
        const Ogre::String prefix = "TreeLod/" + mName + "/impostor";
        gpu->texture = prefix + "-colour";
        gpu->normalTexture = prefix + "-normal";
        uploadTexture(gpu->texture, mGroup, data.colour);
        uploadTexture(gpu->normalTexture, mGroup, data.normal);

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
            Ogre::MaterialPtr material = cloneBaseMaterial(base, name, mGroup, mName);
            configure(material);
            return material;
        };
        gpu->material = prefix;
        gpu->shadowedMaterial = prefix + "/Shadowed";
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
        mImpostorGpu = std::move(gpu);
        return *mImpostorGpu;
    }
}
