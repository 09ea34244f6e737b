#include "TreeLod/ObjectLodBias.h"

#include "TreeLod/ScreenSizeLodStrategy.h"

#include <OgreCamera.h>
#include <OgreDistanceLodStrategy.h>
#include <OgreException.h>
#include <OgreLodStrategyManager.h>
#include <OgrePixelCountLodStrategy.h>
#include <OgreViewport.h>

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

    Ogre::Real ObjectLodBias::value(const Ogre::MovableObject& object, const Ogre::Camera* camera) const
    {
        return meshValue(strategy ? *strategy : ScreenSizeLodStrategy::getSingleton(), object, camera);
    }

    Ogre::Real ObjectLodBias::screenSize(const Ogre::MovableObject& object, const Ogre::Camera* camera) const
    {
        return screenSizeOf(value(object, camera), object, camera);
    }

    Ogre::Real ObjectLodBias::screenSizeOf(Ogre::Real value, const Ogre::MovableObject& object,
                                           const Ogre::Camera* camera) const
    {
        const Ogre::Real maxValue = std::numeric_limits<Ogre::Real>::max();
        if (!strategy || strategy == ScreenSizeLodStrategy::getSingletonPtr())
            return value;
        const Ogre::Camera& lod = *camera->getLodCamera();
        if (dynamic_cast<const Ogre::DistanceLodStrategyBase*>(strategy))
        {
            const Ogre::Real toPixels = ScreenSizeLodStrategy::depthFactor(object.getBoundingRadiusScaled(), lod);
            if (toPixels <= 0.0f) // orthographic: distance says nothing of the size
                return meshValue(ScreenSizeLodStrategy::getSingleton(), object, camera);
            return value > 0.0f ? toPixels / value : maxValue;
        }
        if (value >= maxValue)
            return value;
        Ogre::Real scale = 4.0f; // Ogre's pixel counts are pi r_px^2
        if (strategy == Ogre::ScreenRatioPixelCountLodStrategy::getSingletonPtr() && lod.getViewport())
            scale *= Ogre::Real(lod.getViewport()->getActualWidth()) * Ogre::Real(lod.getViewport()->getActualHeight());
        return value * scale;
    }

    const Ogre::LodStrategy* ObjectLodBias::strategyParam(const ObjectParams& params)
    {
        const Ogre::String* name = params.find("lodStrategy");
        if (!name)
            return nullptr;
        const Ogre::String& known = *name == "distance" ? Ogre::String("distance_box") : *name;
        for (const char* supported : {ScreenSizeLodStrategy::NAME.c_str(), "distance_box", "distance_sphere",
                                      "pixel_count", "screen_ratio_pixel_count"})
            if (known == supported)
                return Ogre::LodStrategyManager::getSingleton().getStrategy(known);
        params.bad("lodStrategy", *name,
                   "treelod_screen_size, distance_box (or distance), distance_sphere, pixel_count or "
                   "screen_ratio_pixel_count");
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
