// ObjectLodBias: the LoD bias of one tree object, as Ogre::Entity::setMeshLodBias and
// setMaterialLodBias have it: a factor on the object's LoD value, applied the way the value's
// strategy transforms it (LodStrategy::transformBias: pixel counts multiplied, squared distances
// divided), and limits on the level index chosen (0 = finest; a larger index is coarser).
// "Mesh" is the object's geometric level, "material" its material LoD; each object's header says
// what the indices mean for its technique. The LoD camera's own bias (Camera::setLodBias) is in
// the strategy's value where the strategy puts it (treelod_screen_size and Ogre's distance
// strategies; Ogre's pixel_count leaves it out, for meshes as for an Entity).
//
// The strategy an object reads its own levels through is treelod_screen_size unless its
// `lodStrategy` parameter names another registered with Ogre's LodStrategyManager: distance_box,
// distance_sphere ("distance" = distance_box), pixel_count or screen_ratio_pixel_count. Its value
// is turned into treelod_screen_size's units, what the levels are written in (screenSize).
#pragma once

#include "TreeLod/ObjectParams.h"

#include <OgreLodStrategy.h>
#include <OgreMaterial.h>
#include <OgreMesh.h>

namespace TreeLod
{
    struct ObjectLodBias
    {
        /// What the object's own levels are read through; null: treelod_screen_size.
        const Ogre::LodStrategy* strategy = nullptr;
        Ogre::Real meshFactor = 1.0f;         ///< > 0; > 1 keeps more detail
        unsigned short maxMeshIndex = 0;      ///< the finest mesh level allowed
        unsigned short minMeshIndex = 99;     ///< the coarsest mesh level allowed
        Ogre::Real materialFactor = 1.0f;     ///< > 0; > 1 keeps more detail
        unsigned short maxMaterialIndex = 0;  ///< the finest material LoD allowed
        unsigned short minMaterialIndex = 99; ///< the coarsest material LoD allowed

        /// Entity::setMeshLodBias / setMaterialLodBias; throws InvalidParametersException unless
        /// `factor` is finite and > 0 (`owner` names the object in the message).
        void setMesh(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex,
                     const Ogre::String& owner);
        void setMaterial(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex,
                         const Ogre::String& owner);

        /// `strategy`'s value for `object` seen by `camera` (LodStrategy::getValue: through its LoD
        /// camera), biased by `factor`; a value at the strategy's limit (a camera at the node)
        /// stays there.
        static Ogre::Real biasedValue(const Ogre::LodStrategy& strategy, const Ogre::MovableObject& object,
                                      const Ogre::Camera* camera, Ogre::Real factor);
        Ogre::Real meshValue(const Ogre::LodStrategy& strategy, const Ogre::MovableObject& object,
                             const Ogre::Camera* camera) const
        {
            return biasedValue(strategy, object, camera, meshFactor);
        }
        /// The strategy's value (LodStrategy::getValue) with the mesh factor.
        Ogre::Real value(const Ogre::MovableObject& object, const Ogre::Camera* camera) const;
        /// That value in treelod_screen_size's units (ScreenSizeLodStrategy), what the objects'
        /// own levels compare: a squared distance through the LoD camera's projection (under an
        /// orthographic camera, treelod_screen_size's own value), Ogre's pixel counts times 4 (and
        /// the viewport's area for the screen ratio).
        Ogre::Real screenSize(const Ogre::MovableObject& object, const Ogre::Camera* camera) const;
        Ogre::Real screenSizeOf(Ogre::Real value, const Ogre::MovableObject& object, const Ogre::Camera* camera) const;

        /// The object parameter `lodStrategy` (see above), null when absent; ObjectParams::bad for
        /// a name that is not one of them.
        static const Ogre::LodStrategy* strategyParam(const ObjectParams& params);

        unsigned short clampMesh(unsigned short index) const;
        unsigned short clampMaterial(unsigned short index) const;

        /// The LoD index of `mesh` by its own strategy and values, biased and clamped
        /// (Entity::_notifyCurrentCamera).
        unsigned short meshLodIndex(const Ogre::Mesh& mesh, const Ogre::MovableObject& object,
                                    const Ogre::Camera* camera) const;
        /// The material LoD index of `material` by its own strategy and values, biased by the
        /// material factor and clamped.
        unsigned short materialLodIndex(const Ogre::Material& material, const Ogre::MovableObject& object,
                                        const Ogre::Camera* camera) const;
    };
}
