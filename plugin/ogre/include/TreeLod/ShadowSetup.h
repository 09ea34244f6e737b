// ShadowSetup: the sun's shadows in an application's scene manager, as TreeLod's trees draw them.
//
// Trees cast and receive under Ogre's integrated texture shadows with depth textures
// (SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED or _MODULATIVE_INTEGRATED, PF_FLOAT32_R): each tree
// material has a shadow caster writing the shadow camera's window depth and a receiving variant
// (TreeAsset::getShadowedMaterialNames) that the objects pick while such a technique is active. Up
// to three shadow textures per light are read, so focused, LiSPSM and PSSM (3 splits) cameras all
// work; the depth encoding is the one OGRE's RTSS integrated PSSM reads, so an application's RTSS
// materials receive the trees' shadows and the trees receive theirs.
//
// Under Ogre's colour texture shadows (SHADOWTYPE_TEXTURE_MODULATIVE, SHADOWTYPE_TEXTURE_ADDITIVE)
// trees cast what Ogre's own caster pass writes (the shadow colour, or black) and, as casters with
// self shadowing off (Ogre's default), receive none: such a texture holds no depth, so a crown would
// shadow itself all over. With self shadowing on, Ogre would split the trees' one-pass programs into
// its illumination stages, which they do not support: the objects log that once per scene manager.
// Stencil shadows are not supported either (the objects have no edge lists); logged the same way.
//
// setupSunShadows configures all of this on a scene manager in one call; an application may
// equally configure Ogre itself, and the objects follow whatever technique is set.
#pragma once

#include <OgreCommon.h>
#include <OgrePrerequisites.h>

namespace TreeLod
{
    /// How the sun's shadow camera frames the view.
    enum class ShadowCamera
    {
        Focused, ///< Ogre::FocusedShadowCameraSetup: orthographic, fitted to the visible receivers
        LiSPSM,  ///< Ogre::LiSPSMShadowCameraSetup: light space perspective shadow maps [WSP04] (García et al. 2007 §5.2)
        PSSM     ///< Ogre::PSSMShadowCameraSetup: parallel-split shadow maps, 3 splits (as OGRE's Terrain sample)
    };

    /// "focused", "lispsm" or "pssm" (scene scripts, the CLI); throws Ogre::Exception naming `where` otherwise.
    ShadowCamera parseShadowCamera(const Ogre::String& name, const Ogre::String& where);

    struct SunShadowSettings
    {
        /// SHADOWTYPE_NONE turns shadows off. Stencil techniques are refused (Ogre::Exception).
        Ogre::ShadowTechnique technique = Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED;
        ShadowCamera camera = ShadowCamera::Focused; ///< PSSM only with the integrated techniques
        unsigned textureSize = 2048;                 ///< each shadow texture is textureSize^2
        Ogre::Real farDistance = 0;                  ///< > 0: SceneManager::setShadowFarDistance
    };

    /// The number of splits PSSM uses.
    constexpr int PSSM_SPLITS = 3;

    /// Texture shadows from the directional light `sun` as `settings` say: technique, texture
    /// count and format (float depth when integrated, Ogre's colour default otherwise), self
    /// shadowing, camera setup, the sun casting. PSSM needs `viewCamera` (its near clip bounds
    /// the first split; see updateShadowSplits). Throws Ogre::Exception for a stencil technique, a
    /// light that is not directional, and PSSM without an integrated technique or a camera.
    void setupSunShadows(Ogre::SceneManager& sceneManager, Ogre::Light& sun, const SunShadowSettings& settings,
                         const Ogre::Camera* viewCamera = nullptr);

    /// Under a PSSM camera setup: split points from the camera's near clip to the scene manager's
    /// shadow far distance (Zhang et al. 2006's practical split scheme, lambda 0.95, as
    /// PSSMShadowCameraSetup::calculateSplitPoints). Call it again when either changes; does
    /// nothing under other setups.
    void updateShadowSplits(Ogre::SceneManager& sceneManager, const Ogre::Camera& viewCamera);

    /// Whether trees draw their shadow-receiving materials: under integrated texture shadows.
    bool receivesDepthShadows(const Ogre::SceneManager* sceneManager);

    /// What the tree objects call before they queue themselves (a camera, a shadow camera): the
    /// casters' mode follows the scene manager's shadow technique; a stencil technique is logged
    /// once per scene manager as unsupported.
    void notifyShadowTechnique(const Ogre::SceneManager& sceneManager);

    /// The GPU shared parameters the casters read ("TreeLodShadowParams": float4 shadowMode),
    /// created if missing; needs the render system's GpuProgramManager. The plugin creates them
    /// before any script is parsed.
    void createShadowParams();
    constexpr const char* SHADOW_PARAMS_NAME = "TreeLodShadowParams";
}
