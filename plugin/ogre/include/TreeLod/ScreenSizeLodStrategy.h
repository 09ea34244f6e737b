// ScreenSizeLodStrategy: TreeLod's LoD strategy, registered with Ogre::LodStrategyManager by
// TreeLodPlugin::install as "treelod_screen_size", so that material scripts (`lod_strategy
// treelod_screen_size`) and meshes (Mesh::setLodStrategy) can name it.
//
// Value: the screen size of the object's bounding sphere (the radius scaled by its node) in
// TreeLod's LoD units, 4 pi r_px^2 with r_px the projected radius in pixels (a tree drawn h_px
// tall with bounding radius R and height h has r_px = h_px R / h: Forest.h), times the LoD
// camera's bias. A perspective camera gives pi r^2 * viewport area * P00 * P11 / d^2 (d the
// view depth of the node), an orthographic one 4 pi r^2 * viewport area / (ortho window area),
// the same units. Larger is nearer: values descend from the finest level, as Ogre's pixel-count
// strategies (which count pi r_px^2, a quarter of this, and leave the camera's LoD bias out).
#pragma once

#include <OgrePixelCountLodStrategy.h>
#include <OgreSingleton.h>

namespace TreeLod
{
    class ScreenSizeLodStrategy : public Ogre::PixelCountLodStrategyBase,
                                  public Ogre::Singleton<ScreenSizeLodStrategy>
    {
    public:
        /// "treelod_screen_size": the name material scripts and meshes use.
        static const Ogre::String NAME;

        ScreenSizeLodStrategy();

        /// The value of a sphere of radius `radius` seen by `camera` (its LoD camera: the
        /// viewer's for shadow cameras) at squared view depth `squaredDepth`, bias included;
        /// getBaseValue() at depth 0, 0 for a camera without a viewport.
        static Ogre::Real valueOf(Ogre::Real radius, Ogre::Real squaredDepth, const Ogre::Camera& camera);

        /// W * H * |P00 * P11| of `camera`'s viewport and projection: a sphere of radius r has the
        /// value pi r^2 * this / d^2 under a perspective camera, pi r^2 * this under an orthographic
        /// one, times the bias (the Forest values its instances so, ForestInstances.h).
        static Ogre::Real pixelScale(const Ogre::Camera& camera);

        /// value * d^2 for a perspective `camera` without its bias (the factor that turns a
        /// squared view depth into a value); 0 for an orthographic camera or one without a viewport.
        static Ogre::Real depthFactor(Ogre::Real radius, const Ogre::Camera& camera);

        /// The projected radius in pixels r_px of a value, sqrt(value / (4 pi)); the largest
        /// value (a camera at the node) stays the largest.
        static Ogre::Real radiusInPixels(Ogre::Real value);
        /// The value in the units of Ogre's pixel_count (pi r_px^2): a quarter; the largest stays.
        static Ogre::Real pixelCountOf(Ogre::Real value);

        static ScreenSizeLodStrategy& getSingleton();
        static ScreenSizeLodStrategy* getSingletonPtr();

    protected:
        Ogre::Real getValueImpl(const Ogre::MovableObject* movableObject, const Ogre::Camera* camera) const override;
    };
}
