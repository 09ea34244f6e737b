#include "TreeLod/Wind.h"

#include <OgreException.h>
#include <OgreGpuProgramManager.h>
#include <OgreVector.h>

#include <cmath>
#include <mutex>

namespace TreeLod
{
    namespace
    {
        std::mutex gMutex;
        WindParameters gWind;
        double gSeconds = 0.0;

        void writeShared(const WindParameters& wind, double seconds)
        {
            Ogre::GpuProgramManager* programs = Ogre::GpuProgramManager::getSingletonPtr();
            if (!programs)
                return;
            Ogre::GpuSharedParametersPtr shared;
            if (programs->getAvailableSharedParameters().count(WIND_PARAMS_NAME))
                shared = programs->getSharedParameters(WIND_PARAMS_NAME);
            else
            {
                shared = programs->createSharedParameters(WIND_PARAMS_NAME);
                for (const char* name : {"windDirection", "windPhase", "windShape"})
                    shared->addConstantDefinition(name, Ogre::GCT_FLOAT4);
            }
            const glm::vec2 along = glm::normalize(wind.direction);
            const WindPhases phases = WindPhases::at(seconds);
            shared->setNamedConstant("windDirection", Ogre::Vector4(along.x, 0.0f, along.y, wind.strength));
            shared->setNamedConstant("windPhase", Ogre::Vector4(phases.gust, phases.sway, phases.branch, phases.leaf));
            shared->setNamedConstant("windShape",
                                     Ogre::Vector4(wind.gustiness, 6.2831853f / wind.gustWavelength, 0.0f, 0.0f));
        }
    }

    void Wind::setParameters(const WindParameters& wind)
    {
        if (Result<void> valid = wind.validate(); !valid)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, valid.error().message(), "Wind::setParameters");
        std::lock_guard<std::mutex> lock(gMutex);
        gWind = wind;
        writeShared(gWind, gSeconds);
    }

    WindParameters Wind::getParameters()
    {
        std::lock_guard<std::mutex> lock(gMutex);
        return gWind;
    }

    void Wind::setTime(double seconds)
    {
        if (!std::isfinite(seconds))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "wind time must be finite, got " + std::to_string(seconds),
                        "Wind::setTime");
        std::lock_guard<std::mutex> lock(gMutex);
        gSeconds = seconds;
        writeShared(gWind, gSeconds);
    }

    double Wind::getTime()
    {
        std::lock_guard<std::mutex> lock(gMutex);
        return gSeconds;
    }

    void Wind::updateSharedParameters()
    {
        std::lock_guard<std::mutex> lock(gMutex);
        writeShared(gWind, gSeconds);
    }

    Ogre::Real Wind::treeHeight(const Ogre::AxisAlignedBox& bounds)
    {
        return bounds.isFinite() ? std::max(bounds.getMaximum().y, 0.0f) : 0.0f;
    }

    void Wind::setTreeHeight(Ogre::Renderable& renderable, Ogre::Real height)
    {
        renderable.setCustomParameter(WIND_CUSTOM_PARAMETER, Ogre::Vector4(std::isfinite(height) ? height : 0.0f, 0.0f, 0.0f, 0.0f));
    }
}
