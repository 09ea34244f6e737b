// TechniqueSupport: what a technique's Ogre half (its TechniqueResources) uses to put its chunk's
// textures and materials on the GPU: the Ogre format of a baked texture, its upload with every
// baked mip (decoded at load where TreeAssetManager says so), a clone of one of TreeLod's base
// materials and its passes' textures, and a single tree as one instance.
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreHighLevelGpuProgramManager.h>
#include <OgreImage.h>
#include <OgreMaterial.h>
#include <OgreMaterialManager.h>
#include <OgrePass.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>
#include <OgreVertexIndexData.h>

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace TreeLod
{
    /// The Ogre pixel format of a baked texture: DXT1, DXT5, BC4, BC5 (unsigned normalised), else RGBA8.
    inline Ogre::PixelFormat ogreFormat(GpuTextureFormat format)
    {
        switch (format)
        {
        case GpuTextureFormat::DXT1:
            return Ogre::PF_DXT1;
        case GpuTextureFormat::DXT5:
            return Ogre::PF_DXT5;
        case GpuTextureFormat::BC4:
            return Ogre::PF_BC4_UNORM;
        case GpuTextureFormat::BC5:
            return Ogre::PF_BC5_UNORM;
        default:
            return Ogre::PF_BYTE_RGBA;
        }
    }

    /// Whether TreeLod's programs run as GLSL ES (materials/TreeLod.program: the render system
    /// compiles GLSL ES and no GLSL, as RenderSystem_GLES2): textures that the shaders read must
    /// then have formats ES 3.00 samples (no 16-bit normalised ones).
    inline bool programsAreGlslEs()
    {
        const Ogre::HighLevelGpuProgramManager& programs = Ogre::HighLevelGpuProgramManager::getSingleton();
        return programs.isLanguageSupported("glsles") && !programs.isLanguageSupported("glsl");
    }

    /// Upload `bytes` (level 0 then its mips, tightly packed; `mips` levels, 0 read as 1) as
    /// texture `name` in `group`.
    inline void uploadTexture(const Ogre::String& name, const Ogre::String& group, const std::uint8_t* bytes,
                              std::uint32_t width, std::uint32_t height, Ogre::PixelFormat format, std::uint32_t mips)
    {
        Ogre::Image image;
        image.loadDynamicImage(const_cast<Ogre::uchar*>(bytes), width, height, 1, format, false, 1,
                               mips > 0 ? mips - 1 : 0);
        Ogre::TextureManager::getSingleton().loadImage(name, group, image, Ogre::TEX_TYPE_2D,
                                                       int(mips > 0 ? mips - 1 : 0));
    }

    /// Upload `texture` with every baked mip level as texture `name` in `group`: in its own format,
    /// or decoded to RGBA8 where TreeAssetManager::decodesAtLoad says so. Returns the bytes uploaded.
    inline std::uint64_t uploadTexture(const Ogre::String& name, const Ogre::String& group, const GpuTexture& texture)
    {
        const TreeAssetManager* assets = TreeAssetManager::getSingletonPtr();
        if (assets && assets->decodesAtLoad(texture))
        {
            const GpuTexture decoded = decodeGpuTexture(texture);
            uploadTexture(name, group, decoded.data.data(), decoded.width, decoded.height, Ogre::PF_BYTE_RGBA,
                          decoded.mipCount);
            return decoded.data.size();
        }
        uploadTexture(name, group, texture.data.data(), texture.width, texture.height, ogreFormat(texture.format),
                      texture.mipCount);
        return texture.data.size();
    }

    /// A clone of TreeLod's material `base` named `name` in `group`; throws naming `base` (and the
    /// asset `assetName`) when TreeLod's materials are not in a resource group.
    inline Ogre::MaterialPtr cloneBaseMaterial(const Ogre::String& base, const Ogre::String& name,
                                               const Ogre::String& group, const Ogre::String& assetName)
    {
        Ogre::MaterialPtr parent = Ogre::MaterialManager::getSingleton().getByName(base, Ogre::RGN_DEFAULT);
        if (!parent)
            parent = Ogre::MaterialManager::getSingleton().getByName(base);
        if (!parent)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                        "material '" + base + "' not found: add TreeLod's materials/ to a resource group",
                        "TreeAsset '" + assetName + "'");
        return parent->clone(name, true, group);
    }

    /// Load `material` and set up every pass: each texture unit named in `textures` (unit name,
    /// texture) shows that texture, then `configure` (if any) runs on the pass.
    inline void configurePasses(const Ogre::MaterialPtr& material,
                                const std::vector<std::pair<Ogre::String, Ogre::String>>& textures,
                                const std::function<void(Ogre::Pass&)>& configure = {})
    {
        material->load();
        for (Ogre::Technique* tech : material->getTechniques())
            for (Ogre::Pass* pass : tech->getPasses())
            {
                for (const auto& [unitName, texture] : textures)
                    if (Ogre::TextureUnitState* unit = pass->getTextureUnitState(unitName))
                        unit->setTextureName(texture);
                if (configure)
                    configure(*pass);
            }
    }

    /// Set every pass of `material` (loaded first) as TreeLod's Bark/Leaf programs read it: texture
    /// unit 0 shows `texture`, fragment constants baseColour, backColour (the back face of a
    /// leaf) and alphaCutoff.
    inline void configureModelMaterial(const Ogre::MaterialPtr& material, const Ogre::String& texture,
                                       const Ogre::ColourValue& baseColour, const Ogre::ColourValue& backColour,
                                       float alphaCutoff)
    {
        material->load();
        for (Ogre::Technique* tech : material->getTechniques())
            for (Ogre::Pass* pass : tech->getPasses())
            {
                if (pass->getNumTextureUnitStates() > 0)
                    pass->getTextureUnitState(0)->setTextureName(texture);
                if (!pass->hasFragmentProgram())
                    continue;
                Ogre::GpuProgramParametersSharedPtr p = pass->getFragmentProgramParameters();
                p->setIgnoreMissingParams(true);
                p->setNamedConstant("baseColour", baseColour);
                p->setNamedConstant("backColour", backColour);
                p->setNamedConstant("alphaCutoff", alphaCutoff);
            }
    }

    /// A single tree drawn by a Forest level's instanced programs (TreeLodInstance.glsl): adds to
    /// `vertexData` the instance attributes uv4 = (0, 0, 0, 1) and uv5 = (1, 0) (position 0, scale 1,
    /// no rotation) as constant per-vertex attributes in a buffer of their own.
    inline void addOriginInstance(Ogre::VertexData& vertexData)
    {
        const unsigned short source = static_cast<unsigned short>(vertexData.vertexDeclaration->getMaxSource() + 1);
        vertexData.vertexDeclaration->addElement(source, 0, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 4);
        vertexData.vertexDeclaration->addElement(source, 4 * sizeof(float), Ogre::VET_FLOAT2,
                                                 Ogre::VES_TEXTURE_COORDINATES, 5);
        const float origin[6] = {0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 0.0f};
        std::vector<float> values(6 * vertexData.vertexCount);
        for (std::size_t i = 0; i < vertexData.vertexCount; ++i)
            std::copy(origin, origin + 6, &values[6 * i]);
        Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            6 * sizeof(float), vertexData.vertexCount, Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        buffer->writeData(0, buffer->getSizeInBytes(), values.data(), true);
        vertexData.vertexBufferBinding->setBinding(source, buffer);
    }
}
