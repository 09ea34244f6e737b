// OctahedralImpostorResources: the octahedral impostor (chunk "octahedral-impostor",
// OctahedralImpostorData.h) on the GPU.
#include "TreeLod/OctahedralImpostorResources.h"

#include "TreeLod/ImpostorResources.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreeAsset.h"

#include <OgreGpuProgramParams.h>
#include <OgrePass.h>
#include <OgreTextureManager.h>

namespace TreeLod
{
    OctahedralImpostorResources& OctahedralImpostorResources::of(TreeAsset& asset)
    {
        return asset.getResources<OctahedralImpostorResources>(
            OCTAHEDRAL_IMPOSTOR_CHUNK, [&asset] { return std::make_unique<OctahedralImpostorResources>(asset); });
    }

    namespace
    {
        void removeGpu(const OctahedralImpostorGpu& gpu, const Ogre::String& group)
        {
            removeImpostorMaterials(gpu.material, gpu.shadowedMaterial, group);
            for (const Ogre::String& t : {gpu.texture, gpu.normalTexture})
                Ogre::TextureManager::getSingleton().remove(t, group);
        }
    }

    OctahedralImpostorResources::~OctahedralImpostorResources()
    {
        if (mGpu)
            removeGpu(*mGpu, mAsset.getGroup());
    }

    const OctahedralImpostorData& OctahedralImpostorResources::getData()
    {
        if (mData)
            return *mData;
        Result<OctahedralImpostorData> decoded =
            decodeOctahedralImpostorChunk(mAsset.readChunk(OCTAHEDRAL_IMPOSTOR_CHUNK), mAsset.getName());
        if (!decoded)
            mAsset.raise(decoded.error());
        mData = std::make_unique<OctahedralImpostorData>(std::move(decoded.value()));
        return *mData;
    }

    Ogre::AxisAlignedBox OctahedralImpostorResources::getDrawnBounds()
    {
        // The quad's corners lie within the cylinder's circumscribed sphere grown by the margins.
        const OctahedralImpostorData& d = getData();
        const float f = float(d.frameTexels());
        const float r = octahedralDepthRadius(d.radius, d.bottom, d.top) * f / (f - 2.0f * OCTAHEDRAL_MARGIN_TEXELS);
        const float y = 0.5f * (d.bottom + d.top);
        return Ogre::AxisAlignedBox(-r, y - r, -r, r, y + r, r);
    }

    const OctahedralImpostorGpu& OctahedralImpostorResources::getGpu()
    {
        if (mGpu)
            return *mGpu;
        const OctahedralImpostorData& data = getData();
        auto gpu = std::make_unique<OctahedralImpostorGpu>();
        const Ogre::String prefix = "TreeLod/" + mAsset.getName() + "/octahedral-impostor";
        gpu->texture = prefix + "-colour";
        gpu->normalTexture = prefix + "-normal";
        gpu->material = prefix;
        gpu->shadowedMaterial = prefix + "/Shadowed";
        gpu->bounds = getDrawnBounds();
        try
        {
            const std::uint64_t textureBytes = uploadTexture(gpu->texture, mAsset.getGroup(), data.colour) +
                                               uploadTexture(gpu->normalTexture, mAsset.getGroup(), data.normal);
            const float vertices[4][5] = {{-1.0f, -1.0f, 0.0f, 0.0f, 1.0f},
                                          {1.0f, -1.0f, 0.0f, 1.0f, 1.0f},
                                          {1.0f, 1.0f, 0.0f, 1.0f, 0.0f},
                                          {-1.0f, 1.0f, 0.0f, 0.0f, 0.0f}};
            gpu->gpuBytes = textureBytes + makeImpostorQuad(vertices, gpu->vertexData, gpu->indexBuffer);

            // The programs' constants (TreeLodOctahedralImpostor.vert/.frag).
            const Ogre::Vector4 cylinder(data.radius, data.bottom, data.top,
                                         octahedralDepthRadius(data.radius, data.bottom, data.top));
            const Ogre::Vector4 atlas(float(data.framesPerSide), float(data.frameTexels()),
                                      float(OCTAHEDRAL_MARGIN_TEXELS), 0.0f);
            cloneImpostorMaterials(mAsset, "TreeLod/OctahedralImpostor", "TreeLod/OctahedralImpostorShadowed",
                                   gpu->material, gpu->shadowedMaterial,
                                   {{"Colour", gpu->texture}, {"Normal", gpu->normalTexture}}, [&](Ogre::Pass& pass) {
                                       for (bool vertex : {true, false})
                                       {
                                           if (vertex ? !pass.hasVertexProgram() : !pass.hasFragmentProgram())
                                               continue;
                                           Ogre::GpuProgramParametersSharedPtr p =
                                               vertex ? pass.getVertexProgramParameters()
                                                      : pass.getFragmentProgramParameters();
                                           p->setIgnoreMissingParams(true);
                                           p->setNamedConstant("cylinder", cylinder);
                                           p->setNamedConstant("atlas", atlas);
                                           p->setNamedConstant("alphaCutoff", data.alphaCutoff);
                                       }
                                   });
        }
        catch (...)
        {
            removeGpu(*gpu, mAsset.getGroup());
            throw;
        }
        mGpu = std::move(gpu);
        return *mGpu;
    }
}
