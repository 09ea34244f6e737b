// ObjectTransition: level transitions of one tree object (BillboardCloudTree, EllipsoidTree,
// VolumeOctreeTree), drawn as the Forest draws its own (LevelTransition.h): within 1 + t of a
// switch the object draws both levels, each Renderable with its screen-door code, so the pair
// covers what one level covers; shadow cameras read the viewer's LoD, so casters get the same
// codes and cast one shadow. Length 0 (the default, as the Forest's) switches hard.
// The clouds' and ellipsoids' codes reach their vertex programs as each Renderable's custom
// parameter TRANSITION_CUSTOM_PARAMETER (uniform `objectTransition`, TreeLodTransition.glsl); the
// volume octree's vertex program computes a code per cell from the band's end it is given.
#pragma once

#include "TreeLod/ForestInstances.h"
#include "TreeLod/LevelTransition.h"
#include "TreeLod/ObjectParams.h"

#include <OgreException.h>
#include <OgreRenderable.h>
#include <OgreVector.h>

#include <string>

namespace TreeLod
{
    /// The Renderable custom parameter (x: transition code, y: pattern shift) read as
    /// `objectTransition` by the programs of the objects above. Ogre keeps a program's last value
    /// for a Renderable without it, so every Renderable those programs draw sets it: TreePart and
    /// the Forest's batches start at (0, 0), the whole tree.
    constexpr std::size_t TRANSITION_CUSTOM_PARAMETER = 7;

    struct ObjectTransition
    {
        /// t in [0, ForestInstances::MAX_TRANSITION]; 0: hard switches.
        float length = ForestInstances::DEFAULT_TRANSITION;

        /// Throws Ogre::InvalidParametersException naming `owner` and the parameter unless
        /// `length` is in [0, MAX_TRANSITION] (NaN refused).
        void set(float value, const Ogre::String& owner)
        {
            if (!(value >= 0.0f && value <= ForestInstances::MAX_TRANSITION))
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                            "lodTransition must be in [0, " + std::to_string(ForestInstances::MAX_TRANSITION) +
                                "], got " + std::to_string(value),
                            owner);
            length = value;
        }

        /// The object parameter `lodTransition`, when present (a number in [0, MAX_TRANSITION]).
        static bool param(const ObjectParams& params, float& out)
        {
            double v = 0.0;
            if (!params.number("lodTransition", 0.0, ForestInstances::MAX_TRANSITION, v))
                return false;
            out = float(v);
            return true;
        }

        /// The coarse level's share at `sizeRatio` (screen size over the switch's) for a fine level
        /// whose own range of screen sizes is `levelRange` (LevelTransition.h); 0 outside the band.
        float coarseShare(float sizeRatio, float levelRange) const
        {
            return transitionCoarseShare(sizeRatio, transitionBandEnd(length, levelRange));
        }

        /// Set `renderable`'s code (0 whole, f > 0 the coarse share, -f the fine rest) and the pattern
        /// shift of an object at world `position`.
        static void apply(Ogre::Renderable& renderable, float code, const Ogre::Vector3& position)
        {
            const float shift = code == 0.0f ? 0.0f : transitionPatternShift({position.x, position.y, position.z});
            renderable.setCustomParameter(TRANSITION_CUSTOM_PARAMETER, Ogre::Vector4(code, shift, 0.0f, 0.0f));
        }
    };
}
