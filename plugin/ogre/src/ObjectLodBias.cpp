#include "TreeLod/ObjectLodBias.h"

#include "TreeLod/ScreenSizeLodStrategy.h"

#include <OgreException.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        void checkFactor(Ogre::Real factor, const char* function, const Ogre::String& owner)
        {
            if (!(factor > 0.0f) || !std::isfinite(factor))
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                            Ogre::String(function) + ": the factor must be finite and > 0, got " +
                                std::to_string(factor),
                            owner);
        }
    }

    void ObjectLodBias::setMesh(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex,
                                const Ogre::String& owner)
    {
        checkFactor(factor, "setMeshLodBias", owner);
        meshFactor = factor;
        maxMeshIndex = maxDetailIndex;
        minMeshIndex = minDetailIndex;
    }

    void ObjectLodBias::setMaterial(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex,
                                    const Ogre::String& owner)
    {
        checkFactor(factor, "setMaterialLodBias", owner);
        materialFactor = factor;
        maxMaterialIndex = maxDetailIndex;
        minMaterialIndex = minDetailIndex;
    }

    Ogre::Real ObjectLodBias::biasedValue(const Ogre::LodStrategy& strategy, const Ogre::MovableObject& object,
                                          const Ogre::Camera* camera, Ogre::Real factor)
    {
        const Ogre::Real value = strategy.getValue(&object, camera);
        if (value == strategy.getBaseValue())
            return value;
        const Ogre::Real biased = value * strategy.transformBias(factor);
        return std::isfinite(biased) ? biased : std::numeric_limits<Ogre::Real>::max();
    }

    Ogre::Real ObjectLodBias::screenSize(const Ogre::MovableObject& object, const Ogre::Camera* camera) const
    {
        return meshValue(ScreenSizeLodStrategy::getSingleton(), object, camera);
    }

    unsigned short ObjectLodBias::clampMesh(unsigned short index) const
    {
        return Ogre::Math::Clamp(index, maxMeshIndex, minMeshIndex);
    }

    unsigned short ObjectLodBias::clampMaterial(unsigned short index) const
    {
        return Ogre::Math::Clamp(index, maxMaterialIndex, minMaterialIndex);
    }

    unsigned short ObjectLodBias::meshLodIndex(const Ogre::Mesh& mesh, const Ogre::MovableObject& object,
                                               const Ogre::Camera* camera) const
    {
        const unsigned short index = mesh.getLodIndex(meshValue(*mesh.getLodStrategy(), object, camera));
        return std::min(clampMesh(index), Ogre::ushort(mesh.getNumLodLevels() - 1));
    }

    unsigned short ObjectLodBias::materialLodIndex(const Ogre::Material& material, const Ogre::MovableObject& object,
                                                   const Ogre::Camera* camera) const
    {
        const Ogre::Real value = biasedValue(*material.getLodStrategy(), object, camera, materialFactor);
        return clampMaterial(material.getLodIndex(value)); // Material::getBestTechnique takes any index
    }
}
