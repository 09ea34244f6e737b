#include "TreeLod/ScreenSizeLodStrategy.h"

#include <OgreCamera.h>
#include <OgreException.h>
#include <OgreMovableObject.h>
#include <OgreNode.h>
#include <OgreViewport.h>

#include <algorithm>
#include <cmath>
#include <limits>

template <> TreeLod::ScreenSizeLodStrategy* Ogre::Singleton<TreeLod::ScreenSizeLodStrategy>::msSingleton = nullptr;

namespace TreeLod
{
    const Ogre::String ScreenSizeLodStrategy::NAME = "treelod_screen_size";

    ScreenSizeLodStrategy::ScreenSizeLodStrategy() : Ogre::PixelCountLodStrategyBase(NAME) {}

    ScreenSizeLodStrategy& ScreenSizeLodStrategy::getSingleton()
    {
        if (!msSingleton)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE, "the TreeLod plugin is not installed", "ScreenSizeLodStrategy");
        return *msSingleton;
    }

    ScreenSizeLodStrategy* ScreenSizeLodStrategy::getSingletonPtr() { return msSingleton; }

    namespace
    {
        Ogre::Real viewportArea(const Ogre::Camera& camera)
        {
            const Ogre::Viewport* viewport = camera.getViewport();
            return viewport ? Ogre::Real(viewport->getActualWidth()) * Ogre::Real(viewport->getActualHeight()) : 0.0f;
        }
    }

    Ogre::Real ScreenSizeLodStrategy::pixelScale(const Ogre::Camera& camera)
    {
        const Ogre::Matrix4& projection = camera.getProjectionMatrix();
        return viewportArea(camera) * std::abs(projection[0][0] * projection[1][1]);
    }

    Ogre::Real ScreenSizeLodStrategy::depthFactor(Ogre::Real radius, const Ogre::Camera& camera)
    {
        if (camera.getProjectionType() != Ogre::PT_PERSPECTIVE)
            return 0.0f;
        return Ogre::Math::PI * radius * radius * pixelScale(camera);
    }

    Ogre::Real ScreenSizeLodStrategy::radiusInPixels(Ogre::Real value)
    {
        const Ogre::Real maxValue = std::numeric_limits<Ogre::Real>::max();
        return value >= maxValue ? maxValue : std::sqrt(std::max(value, 0.0f) / (4.0f * Ogre::Math::PI));
    }

    Ogre::Real ScreenSizeLodStrategy::pixelCountOf(Ogre::Real value)
    {
        return value >= std::numeric_limits<Ogre::Real>::max() ? value : 0.25f * value;
    }

    Ogre::Real ScreenSizeLodStrategy::valueOf(Ogre::Real radius, Ogre::Real squaredDepth, const Ogre::Camera& camera)
    {
        const Ogre::Real epsilon = std::numeric_limits<Ogre::Real>::epsilon();
        Ogre::Real value;
        if (camera.getProjectionType() == Ogre::PT_PERSPECTIVE)
        {
            if (squaredDepth <= epsilon)
                return std::numeric_limits<Ogre::Real>::max();
            value = depthFactor(radius, camera) / squaredDepth;
        }
        else
        {
            const Ogre::Real window = camera.getOrthoWindowWidth() * camera.getOrthoWindowHeight();
            if (window <= epsilon)
                return std::numeric_limits<Ogre::Real>::max();
            value = 4.0f * Ogre::Math::PI * radius * radius * viewportArea(camera) / window;
        }
        return value * camera.getLodBias();
    }

    Ogre::Real ScreenSizeLodStrategy::getValueImpl(const Ogre::MovableObject* movableObject,
                                                   const Ogre::Camera* camera) const
    {
        const Ogre::Node* node = movableObject->getParentNode();
        if (!node)
            return 0.0f;
        return valueOf(movableObject->getBoundingRadiusScaled(), node->getSquaredViewDepth(camera), *camera);
    }
}
