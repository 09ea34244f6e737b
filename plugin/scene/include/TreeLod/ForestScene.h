// ForestScene: a scene script (SceneScript.h) built in an Ogre SceneManager: the ground, the
// sun and shadows, and one Forest holding every placed tree. Used by treelod_frames,
// `treelod bench` and the sample browser. In TreeLodScene, which links the runtime side only
// (Plugin_TreeLod, TreeLodOffscreen, TreeLodScript; docs/architecture.md, "Runtime vs bake").
//
// Packages: each species' package comes from TreeAssetManager::require, so the registered
// TreeBaker supplies exactly the chunks the species' techniques draw from: CacheTreeBaker
// (CacheTreeBaker.h, TreeLodSceneBake) bakes them, PackageListBaker (PackageListBaker.h) looks
// them up in the list a bake wrote.
//
// Technique choice: the script's, or one technique for every species and distance (`treelod
// bench --techniques`, the browser). "auto" is budgeted (Forest::levelsForErrorBudget: the
// script's "lod" maxError, or E for the choice "auto@E") where the package has error curves and
// ForestSceneOptions::levelCosts gives this machine's costs; otherwise, and logged, the fixed bands
// of Forest::getAutoBands(). Distance bands become screen-height bands for the script's camera:
// h_px = height * resolutionY / (2 d tan(fovY/2)).
#pragma once

#include "TreeLod/Forest.h"
#include "TreeLod/ForestBaseline.h"
#include "TreeLod/LodPolicy.h"
#include "TreeLod/OgreGreyImage.h"
#include "TreeLod/SceneScript.h"
#include "TreeLod/TreeAsset.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreManualObject.h>
#include <OgreSceneManager.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace TreeLod
{
    /// The source string of a species (its file, or "preset:NAME?seed=S&leaves=N&height=H").
    std::string speciesSource(const SceneSpecies& species);

    /// The bake technique (chunk) a technique or measurement baseline draws from (its registered
    /// chunkTechnique: mesh -> reference). Empty for an unknown technique.
    std::string bakeTechniqueOf(const std::string& technique);

    /// Whether `technique` names a measurement baseline drawn without the Forest (the speed floors:
    /// TechniqueRegistry::getBaselines, ForestBaseline.h).
    bool isBaseline(const std::string& technique);

    /// A run every bench run is compared with: a technique whose roles give a comparison label
    /// (the reference, the floor), or a measurement baseline.
    struct ComparisonRun
    {
        std::string technique;
        std::string label;             ///< what the plots call it
        char marker = 'o';  ///< its point in the trade plot (a matplotlib marker)
    };
    /// The registry's comparison runs: techniques with a comparison label in registry order (the
    /// reference first), then the baselines in the order registered.
    std::vector<ComparisonRun> comparisonRuns();
    bool isComparisonRun(const std::string& technique);
    /// "mesh, impostor, entities, ..." for help texts.
    std::string describeComparisonRuns();
    /// A run of `treelod bench` or treelod_frames: its name as --techniques spells it, and what it
    /// draws. "auto" there is the script's own choice; "auto@E" and "auto~MS" budgeted auto; any
    /// other name one technique or measurement baseline alone (LodPolicy).
    struct BenchRun
    {
        std::string name;
        LodPolicy policy;
    };
    /// The names of --techniques, parsed once: an error naming the option for an unknown technique
    /// or a bad budget.
    Result<std::vector<BenchRun>> parseBenchRuns(const std::vector<std::string>& names);
    /// The comparison runs as BenchRuns (each technique or baseline alone).
    std::vector<BenchRun> comparisonBenchRuns();

    /// What `treelod bench` and treelod_frames draw without --techniques: "auto" and the techniques
    /// whose roles say benchDefault ("auto,<technique>,...").
    std::string defaultBenchTechniques();

    /// The techniques bakeTechniqueOf knows, for messages: "mesh, <technique>, ...".
    std::string knownSceneTechniques();

    /// The packages that drawing `script` needs: per species source, the sorted bake techniques
    /// ("reference" always) of every policy in `policies` (each as ForestSceneOptions::policy).
    /// What a ForestScene of each policy requires through the TreeBaker, so a program can bake it
    /// all first (`treelod bench`). Throws Ogre::Exception naming the script and the species for
    /// an unknown technique.
    std::map<std::string, std::vector<std::string>> scenePackages(const SceneScript& script,
                                                                  const std::vector<LodPolicy>& policies);

    struct ForestSceneOptions
    {
        /// The script's choice by default; budgeted auto for every species; or every species drawn
        /// with one technique alone, or by a measurement baseline (isBaseline) instead of the
        /// Forest, whose getForest() then holds no species.
        LodPolicy policy;
        PlacementOptions placement;
        /// Forest::setUploadBudget: bytes of levels built per frame (0 = no limit: every level the
        /// first frame needs is built in it).
        std::uint64_t uploadBudget = 0;
        Ogre::String group = "TreeLod"; ///< resource group for assets, meshes and materials
        /// This machine's costs of an asset's levels (LevelCalibration.h), for budgeted auto. Null,
        /// or an Ogre::Exception from it (its text logged as the reason): auto draws the fixed bands.
        std::function<std::vector<LevelCost>(TreeAsset& asset)> levelCosts;
        /// false: no ground mesh; the application draws the script's ground itself (the browser's
        /// terrain sample: Ogre's Terrain on the same heightfield, heights from groundHeight()).
        bool ground = true;
    };

    class ForestScene
    {
    public:
        /// Builds under `parent` (ground mesh unless options.ground is false, Forest) and sets the scene manager's ambient light,
        /// the sun (the light "TreeLodSun" when the scene manager has one, as OffscreenRenderer's
        /// does, else created and owned) and texture shadows as the script says. Throws Ogre::Exception with the script's file and the species' name when
        /// a bake or load fails.
        ForestScene(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const SceneScript& script,
                    const ForestSceneOptions& options = {});
        ~ForestScene(); ///< destroys everything it created

        const SceneScript& getScript() const { return mScript; }
        Forest& getForest() { return *mForest; }
        Ogre::Light& getSun() { return *mSun; }
        const std::vector<PlacedTree>& getPlacements() const { return mPlacements; }
        const std::vector<TreeAssetPtr>& getAssets() const { return mAssets; } ///< per species

        /// Re-create the Forest's species for another policy, keeping the instances; bakes what the
        /// new policy needs.
        void setPolicy(const LodPolicy& policy);
        const LodPolicy& getPolicy() const { return mPolicy; }
        /// setPolicy without waiting for bakes: they run on worker threads
        /// (TreeAssetManager::requireAsync) while the current policy keeps drawing, and update()
        /// switches once they have ended. A later request replaces an earlier one.
        void requestPolicy(const LodPolicy& policy);
        /// Once per frame: switches to the requested policy when its bakes have ended; true when
        /// it did. Throws Ogre::Exception naming the script and the source when a bake failed (the
        /// request is dropped, the current policy stays).
        bool update();
        bool isPolicyPending() const { return mPendingRequested; }
        const LodPolicy& getPendingPolicy() const { return mPendingPolicy; }

        /// Texture shadows on or off (the script's size and shadow camera setup), reaching
        /// getShadowFarDistance() metres from the camera; the ground receives them.
        void setShadows(bool enabled);
        static float getShadowFarDistance();

        /// Show or hide the ground mesh (no effect without one): hidden, the trees stand against
        /// the background colour, so an image's tree pixels are those of another colour (the
        /// bench's motion frames).
        void setGroundVisible(bool visible);

        /// The camera at frame `frame` of `frameCount` (0 = the script's frame count).
        CameraSpec cameraAtFrame(std::uint32_t frame, std::uint32_t frameCount = 0) const;

        /// Per auto species, how its levels are chosen now: "oak: budget 0.04: <technique> 0 >= 301 px, ..."
        /// or why the fixed auto bands were used.
        std::vector<std::string> getLevelNotes() const;
        /// Re-plan the budgeted species for `budget` now (Forest::setErrorBudget; throws as it does);
        /// false, and nothing changed, when no species is budgeted.
        bool setErrorBudget(float budget);

        /// GPU bytes of the drawables in use (Forest::getGpuBytes).
        std::uint64_t getGpuBytes() const;

    private:
        void release();
        void destroyForest(); ///< the Forest and any floor
        void buildGround();
        void buildSpecies();

        Ogre::SceneManager& mSceneManager;
        Ogre::SceneNode& mParent;
        SceneScript mScript;
        ForestSceneOptions mOptions;
        LodPolicy mPolicy;
        bool mPendingRequested = false;
        LodPolicy mPendingPolicy;
        std::vector<std::shared_ptr<TreeAssetRequest>> mPendingBakes;
        std::vector<PlacedTree> mPlacements;
        std::vector<TreeAssetPtr> mAssets;
        struct LevelNote
        {
            std::string name; ///< the script's species
            int species = -1; ///< the Forest's budgeted species, or -1: `fixed` says why not
            std::string fixed;
        };
        std::string levelNote(const LevelNote& note) const;
        std::vector<LevelNote> mLevelNotes;
        Forest* mForest = nullptr;
        std::unique_ptr<ForestBaseline> mBaseline; ///< a measurement baseline drawn instead of the Forest
        Ogre::SceneNode* mForestNode = nullptr;
        Ogre::ManualObject* mGround = nullptr;
        Ogre::SceneNode* mGroundNode = nullptr;
        Ogre::Light* mSun = nullptr;
        Ogre::SceneNode* mSunNode = nullptr;
    };
}
