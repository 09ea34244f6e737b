// Wind: the scene's wind for every TreeLod object (WindModel.h: the model). One per process, as
// Ogre's shared GPU parameters are: the parameters and the clock go to the shared parameter set
// WIND_PARAMS_NAME that every TreeLod vertex program references (materials/GLSL/TreeLodWind.glsl);
// each Renderable those programs draw gives its tree's height as custom parameter
// WIND_CUSTOM_PARAMETER (0: the Renderable does not sway).
//
// The clock is the application's: call Wind::setTime each frame (or advance it by the frame's
// time). It is kept in double precision; the programs get phases reduced modulo 2 pi.
#pragma once

#include "TreeLod/WindModel.h"

#include <OgreAxisAlignedBox.h>
#include <OgreRenderable.h>

namespace TreeLod
{
    constexpr const char* WIND_PARAMS_NAME = "TreeLod/Wind";
    /// x: the tree's height in its own units (TreeLodWind.glsl's windTree).
    constexpr std::size_t WIND_CUSTOM_PARAMETER = 12;

    class Wind
    {
    public:
        /// Throws Ogre::InvalidParametersException with WindParameters::validate's message (NaN,
        /// negative strength, ...) and keeps the wind it had.
        static void setParameters(const WindParameters& wind);
        static WindParameters getParameters();
        /// Seconds on the wind's clock (finite; throws otherwise).
        static void setTime(double seconds);
        static double getTime();

        /// The shared parameter set, made if missing and written with the current wind (the
        /// plugin calls this before scripts are parsed; programs reference it by name).
        static void updateSharedParameters();

        /// The tree height programs read for a tree with local `bounds` (its top, metres above
        /// its base at the origin; 0 for an empty box).
        static Ogre::Real treeHeight(const Ogre::AxisAlignedBox& bounds);
        /// Give `renderable`'s programs the tree's height (0: no wind on it).
        static void setTreeHeight(Ogre::Renderable& renderable, Ogre::Real height);
    };
}
