#include "TreeLod/ShadowSetup.h"

#include <OgreGpuProgramManager.h>
#include <OgreLight.h>
#include <OgreLogManager.h>
#include <OgreSceneManager.h>
#include <OgreShadowCameraSetupFocused.h>
#include <OgreShadowCameraSetupLiSPSM.h>
#include <OgreShadowCameraSetupPSSM.h>

#include <algorithm>
#include <mutex>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// shadowMode.x as TreeLodShadowCaster.glsl reads it.
        float casterMode(Ogre::ShadowTechnique technique)
        {
            if (!(technique & Ogre::SHADOWDETAILTYPE_TEXTURE) || (technique & Ogre::SHADOWDETAILTYPE_INTEGRATED))
                return 0.0f;
            return (technique & Ogre::SHADOWDETAILTYPE_MODULATIVE) ? 1.0f : 2.0f;
        }

        /// The caster mode last written to the shared parameters, and the program manager (the
        /// render system's) that holds them; reset when they are created.
        const Ogre::GpuProgramManager* gLastManager = nullptr;
        float gLastMode = -1.0f;

        enum class Unsupported
        {
            Stencil,         ///< stencil shadows
            ColourSelfShadow ///< colour texture shadows with self shadowing on
        };

        const char* techniqueName(Ogre::ShadowTechnique technique)
        {
            switch (technique)
            {
            case Ogre::SHADOWTYPE_STENCIL_MODULATIVE: return "SHADOWTYPE_STENCIL_MODULATIVE";
            case Ogre::SHADOWTYPE_STENCIL_ADDITIVE: return "SHADOWTYPE_STENCIL_ADDITIVE";
            default: return "a stencil shadow technique";
            }
        }

        /// Logs why `sceneManager`'s shadows are not what the trees support, once per scene
        /// manager and reason (the objects call it every frame: the message is built once).
        void warnOnce(const Ogre::SceneManager& sceneManager, Unsupported what)
        {
            static std::mutex mutex;
            static std::set<std::pair<Ogre::String, Unsupported>> told;
            {
                std::lock_guard<std::mutex> lock(mutex);
                if (!told.insert({sceneManager.getName(), what}).second)
                    return;
            }
            const Ogre::String message =
                what == Unsupported::Stencil
                    ? Ogre::String("uses ") + techniqueName(sceneManager.getShadowTechnique()) +
                          "; TreeLod's trees do not support stencil shadows (no edge lists): they neither cast nor "
                          "receive them. Use texture shadows (TreeLod/ShadowSetup.h)"
                    : Ogre::String("uses colour texture shadows with self shadowing on; TreeLod's trees draw "
                                   "correctly there only as casters that do not receive: "
                                   "setShadowTextureSelfShadow(false) (TreeLod/ShadowSetup.h)");
            Ogre::LogManager::getSingleton().logWarning("TreeLod: scene manager '" + sceneManager.getName() + "' " +
                                                        message);
        }

    }

    ShadowCamera parseShadowCamera(const Ogre::String& name, const Ogre::String& where)
    {
        if (name == "focused")
            return ShadowCamera::Focused;
        if (name == "lispsm")
            return ShadowCamera::LiSPSM;
        if (name == "pssm")
            return ShadowCamera::PSSM;
        OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                    where + ": shadow camera '" + name + "' is not one of focused, lispsm, pssm", "parseShadowCamera");
    }

    void createShadowParams()
    {
        Ogre::GpuProgramManager& programs = Ogre::GpuProgramManager::getSingleton();
        if (programs.getAvailableSharedParameters().count(SHADOW_PARAMS_NAME))
            return;
        Ogre::GpuSharedParametersPtr params = programs.createSharedParameters(SHADOW_PARAMS_NAME);
        params->addConstantDefinition("shadowMode", Ogre::GCT_FLOAT4);
        gLastManager = nullptr;
    }

    bool receivesDepthShadows(const Ogre::SceneManager* sceneManager)
    {
        return sceneManager && sceneManager->isShadowTechniqueTextureBased() &&
               sceneManager->isShadowTechniqueIntegrated();
    }

    void notifyShadowTechnique(const Ogre::SceneManager& sceneManager)
    {
        if (sceneManager.isShadowTechniqueStencilBased())
        {
            warnOnce(sceneManager, Unsupported::Stencil);
            return;
        }
        const float mode = casterMode(sceneManager.getShadowTechnique());
        if (mode != 0.0f && sceneManager.getShadowTextureSelfShadow())
            warnOnce(sceneManager, Unsupported::ColourSelfShadow);
        // Every object calls this for every camera: the parameters are written only when the
        // mode or the program manager changes.
        Ogre::GpuProgramManager* programs = Ogre::GpuProgramManager::getSingletonPtr();
        if (!programs || (programs == gLastManager && mode == gLastMode))
            return;
        createShadowParams();
        programs->getSharedParameters(SHADOW_PARAMS_NAME)->setNamedConstant("shadowMode",
                                                                            Ogre::Vector4(mode, 0.0f, 0.0f, 0.0f));
        gLastManager = programs;
        gLastMode = mode;
    }

    void setupSunShadows(Ogre::SceneManager& sceneManager, Ogre::Light& sun, const SunShadowSettings& settings,
                         const Ogre::Camera* viewCamera)
    {
        const Ogre::ShadowTechnique technique = settings.technique;
        if (technique == Ogre::SHADOWTYPE_NONE)
        {
            sceneManager.setShadowTechnique(Ogre::SHADOWTYPE_NONE);
            return;
        }
        if (technique & Ogre::SHADOWDETAILTYPE_STENCIL)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        Ogre::String("scene manager '") + sceneManager.getName() + "': stencil shadows (" +
                            techniqueName(technique) +
                            ") are not supported by TreeLod's trees (no edge lists); use a texture shadow technique",
                        "setupSunShadows");
        if (sun.getType() != Ogre::Light::LT_DIRECTIONAL)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "light '" + sun.getName() + "' is not directional: TreeLod's shadows are the sun's",
                        "setupSunShadows");
        const bool integrated = technique & Ogre::SHADOWDETAILTYPE_INTEGRATED;
        if (settings.camera == ShadowCamera::PSSM && (!integrated || !viewCamera))
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        !integrated ? "PSSM shadows need an integrated texture shadow technique (the receivers pick "
                                      "the split; Ogre's colour shadows would darken each split's area once more)"
                                    : "PSSM shadows need the view camera (its near clip bounds the first split)",
                        "setupSunShadows");
        const int textures = settings.camera == ShadowCamera::PSSM ? PSSM_SPLITS : 1;
        sceneManager.setShadowTechnique(technique);
        sceneManager.setShadowTextureCountPerLightType(Ogre::Light::LT_DIRECTIONAL, textures);
        // Depth in a float texture for integrated shadows (the casters write it); Ogre's default
        // colour texture otherwise.
        sceneManager.setShadowTextureSettings(settings.textureSize, textures,
                                              integrated ? Ogre::PF_FLOAT32_R : Ogre::PF_X8R8G8B8);
        sceneManager.setShadowTextureSelfShadow(integrated);
        if (settings.farDistance > 0)
            sceneManager.setShadowFarDistance(settings.farDistance);
        switch (settings.camera)
        {
        case ShadowCamera::Focused:
            sceneManager.setShadowCameraSetup(std::make_shared<Ogre::FocusedShadowCameraSetup>());
            break;
        case ShadowCamera::LiSPSM:
            sceneManager.setShadowCameraSetup(std::make_shared<Ogre::LiSPSMShadowCameraSetup>());
            break;
        case ShadowCamera::PSSM:
        {
            auto pssm = std::make_shared<Ogre::PSSMShadowCameraSetup>();
            // As OGRE's Terrain sample: LiSPSM's adjustment strongest in the nearest split.
            pssm->setOptimalAdjustFactor(0, 2.0f);
            pssm->setOptimalAdjustFactor(1, 1.0f);
            pssm->setOptimalAdjustFactor(2, 0.5f);
            sceneManager.setShadowCameraSetup(pssm);
            updateShadowSplits(sceneManager, *viewCamera);
            break;
        }
        }
        sun.setCastShadows(true);
        notifyShadowTechnique(sceneManager);
    }

    void updateShadowSplits(Ogre::SceneManager& sceneManager, const Ogre::Camera& viewCamera)
    {
        auto* pssm = dynamic_cast<Ogre::PSSMShadowCameraSetup*>(sceneManager.getShadowCameraSetup().get());
        if (!pssm)
            return;
        const Ogre::Real nearClip = viewCamera.getNearClipDistance();
        Ogre::Real farDistance = sceneManager.getShadowFarDistance();
        if (!(farDistance > nearClip))
            farDistance = viewCamera.getFarClipDistance() > nearClip ? viewCamera.getFarClipDistance() : 1000 * nearClip;
        pssm->calculateSplitPoints(PSSM_SPLITS, nearClip, farDistance);
        // Each split's shadow camera starts this much before the split (OGRE's Terrain sample: twice
        // the near clip); at most half the first split, so that it starts in front of the eye.
        pssm->setSplitPadding(std::min(2.0f * nearClip, 0.5f * pssm->getSplitPoints()[1]));
    }
}
