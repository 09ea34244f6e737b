// Forest: thousands of trees of several TreeAssets in one MovableObject (type "Forest"), no
// SceneNode per tree: culling, level choice and one instanced draw per (species, level, part).
// Manual: docs/forest.md.
//
// A species is one TreeAsset drawn by levels, near to far, each one technique's drawable at one of
// its own levels (ForestLevelProvider). Levels come from fixed screen-height bands (levelsForBands,
// getAutoBands) or are budgeted (addBudgetedSpecies): the cheapest within an error budget, from the
// asset's error curves and this machine's costs (LevelSelection.h), optionally held to a frame
// budget (docs/forest.md, "Budgeted levels"). Each camera that renders the Forest (the viewer's,
// the shadow cameras) culls and picks levels from its LoD camera in one loop (ForestInstances::cull).
//
// Units: metres in the Forest's local space (a uniform node scale keeps LoD exact); switch values
// (ForestLevel::minPixelCount) are treelod_screen_size's 4 pi r_px^2 of the asset's reference
// sphere, the one an Entity of the asset sees, times the camera's LoD bias and setMeshLodBias's
// factor ("lodBias"). A species' tighter culling sphere scales its thresholds to the same switches.
// Bark: a level draws the bark mesh LoD of the largest value it covers; levels split where it switches.
// Materials: instanced clones, vertex programs swapped for "<program>/Instanced" (INSTANCED=1);
// ForestPartOptions::instancedMaterial parts are used as they are.
// Per-camera state: instance buffers (28 bytes a draw of a tree) and Renderables, dropped with the
// camera; a warmed-up frame allocates nothing.
// Transitions (setLodTransition): a tree near a level switch is drawn at both levels with
// complementary screen-door masks (ForestInstances.h, TreeLodTransition.glsl), in the view and in
// the shadow textures alike.
// Residency: driven from the render thread, which uploads. addSpecies builds the last level only;
// others are built when a camera first needs them, within setUploadBudget's bytes a frame, their
// trees drawn at the nearest resident level meanwhile; nothing is evicted. Bakes run elsewhere.
// Budgeted species: re-planned in place when the error budget changes (setErrorBudget, the frame
// budget's controller); the last level is built first, so a failure keeps the old plan.
#pragma once

#include "TreeLod/ForestInstances.h"
#include "TreeLod/FrameBudgetController.h"
#include "TreeLod/ForestLevelProvider.h"
#include "TreeLod/LevelCosts.h"
#include "TreeLod/LevelSelection.h"
#include "TreeLod/ObjectLodBias.h"
#include "TreeLod/TreeAsset.h"

#include <OgreCamera.h>
#include <OgreMaterial.h>
#include <OgreMovableObject.h>

#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <memory>
#include <vector>

namespace TreeLod
{
    /// What the last frame of the viewer's camera drew.
    /// Which budget decided the budgeted species' plans (Forest::getBindingBudget).
    enum class ForestBinding : std::uint8_t
    {
        Error,  ///< the error budget: the cheapest levels within it
        Frame,  ///< the frame budget: the error budget in use is coarser than the one set
        Memory  ///< the memory budget: levels were taken out to fit it
    };
    /// "error", "frame", "memory".
    const char* toString(ForestBinding binding);

    /// One GPU resource a level draws from (Forest::getGpuResources): a vertex or index buffer or a
    /// texture (all mips).
    struct ForestGpuResource
    {
        std::shared_ptr<const void> handle; ///< keeps the resource alive while held; its identity
        std::uint64_t bytes = 0;
    };

    struct ForestStats
    {
        std::uint32_t instances = 0;          ///< in the Forest
        std::uint32_t visibleInstances = 0;   ///< after frustum culling
        /// Visible instances at another level than this camera's previous frame gave them
        /// (ForestVisibility::getSwitchCount): the pops a user may see.
        std::uint32_t levelSwitches = 0;
        /// Visible instances drawn at two levels, in a transition (setLodTransition).
        std::uint32_t transitionInstances = 0;
        /// Instances in the frustum not drawn: hidden behind the trees in front (setOcclusion).
        /// Not counted in visibleInstances.
        std::uint32_t occludedInstances = 0;
        std::uint32_t batches = 0;            ///< instanced draws queued (all parts)
        std::uint64_t triangles = 0;          ///< submitted, summed over instances
        /// Instances drawn per species and level: levelCounts[species][level] (a tree in a
        /// transition counts at both of its levels).
        std::vector<std::vector<std::uint32_t>> levelCounts;
        double cullMilliseconds = 0.0;        ///< ForestInstances::cull of the viewer's camera
        std::uint64_t instanceBufferBytes = 0; ///< instance vertex buffers, all cameras
        /// Residency, this Root frame (all cameras): GPU bytes the Forest started drawing from
        /// (buffers and textures of the levels built, each counted once; see "Residency").
        std::uint64_t uploadedBytes = 0;
        std::uint32_t uploadedLevels = 0;     ///< levels built this frame
        std::uint32_t pendingLevels = 0;      ///< levels asked for and waiting for a later frame
        /// Visible instances of the viewer drawn at a fallback level (theirs not resident yet).
        std::uint32_t fallbackInstances = 0;
        /// The frame budget's prediction at its last re-plan (ms, the viewer's trees of budgeted
        /// species at the levels in use, times Forest::getFrameTimeRatio); 0 without a frame budget.
        double predictedMilliseconds = 0.0;
        /// GPU bytes of the budgeted species' planned levels, from their error curves
        /// (ErrorCurves::gpuBytes; 0 where the curves hold none).
        std::uint64_t plannedGpuBytes = 0;
    };

    class Forest : public Ogre::MovableObject
    {
    public:
        explicit Forest(const Ogre::String& name);
        ~Forest() override;

        /// The default technique choice ("techniques": "auto"): a band per technique whose roles
        /// give a default band (TechniqueRoles::defaultBandMinHeight), largest first, the floor's
        /// last (`treelod info --techniques` lists them). Ogre::ItemIdentityException when no
        /// technique is the floor.
        static std::vector<ForestBand> getAutoBands();

        /// The levels `bands` give for `asset`: each band's technique contributes its own levels
        /// (ForestLevelProvider::getSpans, each technique's own spans on its pixel curve; split
        /// where the bark mesh's LoD switches) clipped to the band's screen-size range. At most ForestInstances::MAX_THRESHOLDS + 1. Throws
        /// Ogre::InvalidParametersException naming the band and technique when a technique is
        /// unknown or the asset lacks its chunk.
        static std::vector<ForestLevel> levelsForBands(TreeAsset& asset, const std::vector<ForestBand>& bands);

        /// Every level `asset` can be drawn at, for measuring (error curves, calibration): each
        /// registered technique that can be a Forest level and whose chunk the asset holds (of
        /// `techniques` only, when not empty), with all its levels (ForestLevelProvider::getSpans) in
        /// its own order, each once, minPixelCount 0.
        static std::vector<ForestLevel> getCandidateLevels(TreeAsset& asset,
                                                           const std::vector<Ogre::String>& techniques = {});

        /// A few words naming `level` (its technique's ForestLevelProvider::describeLevel).
        static Ogre::String describeLevel(const ForestLevel& level);
        /// The height on screen (pixels) of `asset` at LoD value `pixelCount` (reference-sphere
        /// units, as ForestLevel::minPixelCount): the inverse of the bands' conversion.
        static Ogre::Real heightForPixelCount(TreeAsset& asset, Ogre::Real pixelCount);
        /// The LoD value (reference-sphere units) of `asset` drawn `heightPixels` tall: the bands'
        /// conversion. Throws Ogre::InvalidParametersException for a tree without height.
        static Ogre::Real pixelCountForHeight(TreeAsset& asset, Ogre::Real heightPixels);

        /// The techniques budgeted auto chooses among: those whose roles say autoCandidate, in the
        /// registry's order (`treelod info --techniques` lists them).
        static std::vector<Ogre::String> getAutoTechniques();

        /// Budgeted auto (docs/forest.md, "Budgeted levels"): the levels chooseLevels
        /// (LevelSelection.h) gives for `asset` from its error-curves chunk and `costs` (this
        /// machine's, LevelCalibration.h) within `errorBudget`, among getAutoTechniques' levels.
        /// Throws Ogre::InvalidParametersException naming the asset when it has no error curves,
        /// the budget is not in [0, 1] or no level has a cost.
        static std::vector<ForestLevel> levelsForErrorBudget(TreeAsset& asset, const std::vector<LevelCost>& costs,
                                                             float errorBudget);

        /// Add a budgeted species: its levels are levelsForErrorBudget's for getErrorBudget(), chosen
        /// again whenever the budget changes (see "Budgeted species"). `costs`: this machine's
        /// (LevelCalibration.h). Throws as levelsForErrorBudget and addSpecies; nothing is added then.
        std::uint32_t addBudgetedSpecies(const TreeAssetPtr& asset, const std::vector<LevelCost>& costs);
        bool isBudgeted(std::uint32_t species) const;

        /// Error budget of the budgeted species (default DEFAULT_ERROR_BUDGET: FLIP over the
        /// tree's box above the polygonal reference's own), in [0, 1]; re-plans them now. Throws
        /// Ogre::InvalidParametersException for NaN or a budget outside [0, 1]. Under a frame
        /// budget, the start of its controller, which then sets the budget itself.
        void setErrorBudget(float budget);
        /// The error budget the budgeted species are planned for now.
        float getErrorBudget() const { return mBudget.getErrorBudget(); }
        /// Shadow casters' own error budget, in [0, 1] (default DEFAULT_SHADOW_ERROR_BUDGET); see
        /// "Budgeted species". Throws as setErrorBudget.
        void setShadowErrorBudget(float budget);
        float getShadowErrorBudget() const { return mShadowErrorBudget; }
        /// The level the shadow casters of `species` draw for each of its levels (itself for a
        /// species with fixed levels).
        const std::vector<std::uint32_t>& getShadowLevels(std::uint32_t species) const;
        /// Frame budget in milliseconds for the viewer's trees of budgeted species (0, the default:
        /// none, the error budget holds); finite and >= 0, else Ogre::InvalidParametersException.
        /// Turning it off plans for the last setErrorBudget again.
        void setFrameBudgetMs(float milliseconds);
        float getFrameBudgetMs() const { return mBudget.getFrameBudgetMs(); }
        /// GPU memory budget of the budgeted species' levels in bytes (0, the default: none): their
        /// plans hold at most this many bytes of level resources (ErrorCurves' GPU bytes: buffers
        /// and textures with mips; the instance buffers are not counted), levels taken out as
        /// chooseLevelsWithinMemory says, in the plan for the error budget set (setErrorBudget);
        /// the frame budget's steps choose among the levels left. Re-plans now. Throws
        /// Ogre::InvalidParametersException, changing nothing, when a budgeted species' curves hold
        /// no GPU bytes or the budget is below the smallest plan (naming both).
        void setMemoryBudget(std::uint64_t bytes);
        std::uint64_t getMemoryBudget() const { return mMemoryBudget; }
        /// Which budget decides the plans now (ForestBinding); Error without budgeted species.
        ForestBinding getBindingBudget() const;
        /// The application's measured time of the frame just drawn (ms, finite and > 0; others are
        /// ignored): under a frame budget the controller scales its predictions by the running ratio
        /// of measured to predicted time, closing the loop on what the calibration cannot see
        /// (occlusion between trees, the rest of the frame). Optional: without reports the
        /// prediction stands alone.
        void notifyFrameTime(float milliseconds);
        /// Measured over predicted time, as the controller applies it (1 until frames are reported).
        double getFrameTimeRatio() const { return mBudget.getFrameTimeRatio(); }
        /// Viewer frames between two re-plans of the frame budget.
        static constexpr unsigned FRAME_BUDGET_INTERVAL = 8;

        /// Add a species; returns its index (= ForestInstances kind). Levels near to far (at most
        /// ForestInstances::MAX_THRESHOLDS + 1), strictly decreasing minPixelCount, the last 0;
        /// each level as its technique's ForestLevelProvider::checkLevel accepts. Throws as levelsForBands, naming the
        /// species and level; nothing is added then.
        std::uint32_t addSpecies(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels);
        std::uint32_t getSpeciesCount() const;
        const std::vector<ForestLevel>& getLevels(std::uint32_t species) const;
        const TreeAssetPtr& getAsset(std::uint32_t species) const;

        /// The instance store (add, update, remove instances; kind = species index).
        ForestInstances& getInstances() { return mInstances; }
        const ForestInstances& getInstances() const { return mInstances; }
        /// Add instances all or nothing; throws Ogre::InvalidParametersException with
        /// ForestInstances' message (instance index and reason). Updates the bounds. Stored along
        /// ForestInstances::spatialOrder (dense indices differ from the input's; handles are in
        /// the input's order), so that culling skips whole blocks.
        std::vector<ForestHandle> addInstances(const std::vector<ForestInstance>& instances);
        /// Recompute the local bounds after changing instances through getInstances().
        void updateBounds();

        /// As Entity::setMeshLodBias: `factor` (> 0) multiplies every instance's LoD value (with
        /// the camera's LoD bias), and each instance's level (its species' level index, 0 = the
        /// nearest) is kept within [maxDetailIndex, minDetailIndex]. The levels fix their
        /// materials (ForestLevel), so there is no material LoD bias.
        void setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex = 0, unsigned short minDetailIndex = 99);
        const ObjectLodBias& getMeshLodBias() const { return mLodBias; }
        /// setMeshLodBias's factor alone (the "lodBias" parameter).
        void setLodBias(Ogre::Real bias);
        Ogre::Real getLodBias() const { return mLodBias.meshFactor; }
        /// Multiplies the LoD value of shadow casters (> 0; default 1: the viewer's levels). Below
        /// 1 the shadow textures draw coarser levels than the view: their fill, not the view's,
        /// bounds the worst frames when a shadow camera magnifies the trees near the viewer (LiSPSM).
        void setShadowLodBias(Ogre::Real bias);
        Ogre::Real getShadowLodBias() const { return mShadowLodBias; }
        /// LoD hysteresis h in [0, 1] (default 0.15): a tree keeps its level while its LoD value
        /// is within a factor 1 + h of what would switch it (ForestInstances::cull), per camera, so
        /// that trees at a switch do not flicker under camera jitter.
        void setLodHysteresis(Ogre::Real hysteresis);
        Ogre::Real getLodHysteresis() const { return mLodHysteresis; }
        /// Transition length t in [0, 1] (ForestInstances::MAX_TRANSITION; default
        /// DEFAULT_LOD_TRANSITION): a tree whose screen size is within 1 + t times its level's switch
        /// to the next is drawn at both, cross-faded by complementary screen-door masks, so that no
        /// level pops. 0: hard switches. Each band takes at most the lower half of its level's range
        /// of screen sizes (in ratio). Some switches stay hard, held by hysteresis: those below
        /// `minHeightPx` on screen (at LoD bias 1; default DEFAULT_LOD_TRANSITION_MIN_HEIGHT: a small
        /// tree's pop is small, where its masks are noise that a dense forest's many small trees add
        /// up) and the steps of a continuous simplification (ForestLevelProvider::isContinuousStep).
        void setLodTransition(Ogre::Real transition, Ogre::Real minHeightPx = DEFAULT_LOD_TRANSITION_MIN_HEIGHT);
        Ogre::Real getLodTransition() const { return mLodTransition; }
        Ogre::Real getLodTransitionMinHeight() const { return mLodTransitionMinHeight; }
        static constexpr Ogre::Real DEFAULT_LOD_TRANSITION = ForestInstances::DEFAULT_TRANSITION;
        static constexpr Ogre::Real DEFAULT_LOD_TRANSITION_MIN_HEIGHT = 64.0f;
        /// Keep the LoD camera of the last frame (levels stop changing; culling goes on).
        void setLodFrozen(bool frozen);
        bool isLodFrozen() const { return mLodFrozen; }
        /// Occlusion between the trees (default on; docs/forest.md, "Occlusion"): the viewer's cull
        /// estimates the share of each tree the trees in front leave visible (ForestOcclusion.h,
        /// each species' silhouette from its reference), does not draw a tree of which less than
        /// OCCLUSION_HIDDEN is visible, and draws a partly hidden tree of a budgeted species at the
        /// level its plan gives for its error budget over that share (occlusionHeightScale,
        /// LevelSelection.h). Shadow cameras draw every tree: what the viewer does not see still
        /// casts shadows it sees.
        void setOcclusion(bool occlusion);
        bool getOcclusion() const { return mOcclusion; }

        const ForestStats& getStats() const { return mStats; }
        /// GPU bytes of the assets' drawables in use (vertex and index buffers and textures, all
        /// mips, of every resident level's parts, with every LoD level of the meshes they draw,
        /// each counted once) plus the instance buffers.
        std::uint64_t getGpuBytes() const;
        /// The resources level `level` of `species` draws from, each once (empty while it is not
        /// resident): what getGpuBytes counts for it.
        std::vector<ForestGpuResource> getGpuResources(std::uint32_t species, std::uint32_t level) const;
        /// Levels resident now, all species.
        std::uint32_t getResidentLevelCount() const;

        /// Bytes the levels built in one Root frame may upload (0, the default: no limit, every
        /// level is built in the frame that first needs it). See "Residency".
        void setUploadBudget(std::uint64_t bytesPerFrame);
        std::uint64_t getUploadBudget() const { return mUploadBudget; }
        /// Build every level of every species now (preloading, outside the frame loop).
        void makeAllResident();
        bool isResident(std::uint32_t species, std::uint32_t level) const;
        /// The level drawn for trees at `level`: itself when resident, else the nearest resident
        /// level, coarser first (the last level always is).
        std::uint32_t getDrawnLevel(std::uint32_t species, std::uint32_t level) const;

        // MovableObject
        const Ogre::String& getMovableType() const override;
        const Ogre::AxisAlignedBox& getBoundingBox() const override { return mBounds; }
        Ogre::Real getBoundingRadius() const override { return mRadius; }
        void _notifyCurrentCamera(Ogre::Camera* camera) override;
        void _notifyManager(Ogre::SceneManager* manager) override;
        void _updateRenderQueue(Ogre::RenderQueue* queue) override;
        void visitRenderables(Ogre::Renderable::Visitor* visitor, bool debugRenderables = false) override;

    private:
        struct Part;
        class PartBuilder;
        enum class Residency : std::uint8_t;
        struct Species;
        class Batch;
        struct BucketState;
        struct CameraState;
        class ViewerListener;
        class CameraListener;

        struct BudgetPlan;
        /// "Forest 'NAME' species N ('ASSET'): ", the start of errors about a species.
        Ogre::String speciesLabel(std::uint32_t species, const TreeAsset* asset) const;
        /// addSpecies and addBudgetedSpecies: `budget` is null for fixed levels.
        std::uint32_t addSpeciesImpl(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels,
                                     std::unique_ptr<BudgetPlan> budget);
        /// Replace the levels of budgeted species `species` by those of `choices` (see "Budgeted
        /// species"); throws naming the species when its last level cannot be built (nothing changed).
        void replan(std::uint32_t species, const std::vector<LevelChoice>& choices);
        /// Plan every budgeted species for `budget` (replan where its levels change).
        void applyErrorBudget(float budget);
        /// The memory plan of the budgeted species (and of `extra` for `extraAsset`, a species being
        /// added, last) at `errorBudget` within `memoryBudget`; throws naming the Forest.
        MemoryPlan memoryPlan(const BudgetPlan* extra, const TreeAsset* extraAsset, float errorBudget,
                              std::uint64_t memoryBudget, const char* source) const;
        /// Each budgeted species' excluded levels and frame-budget steps from `plan`, then re-plan at
        /// the error budget in use.
        void applyMemoryPlan(const MemoryPlan& plan);
        void updatePlannedGpuBytes(); ///< ForestStats::plannedGpuBytes of the plans in use
        void updateShadowLevels(std::uint32_t species);
        /// The kind's occlusion height scales from its plan (1 for fixed levels).
        void updateOcclusionScales(std::uint32_t species);
        /// Each species' silhouette for occlusion (ForestKind::occlusionMask), where not made yet.
        void makeOcclusionMasks();
        /// The kind's table of `levels` of `species`, within setMeshLodBias's limits.
        std::vector<float> kindThresholds(const Species& species, const std::vector<ForestLevel>& levels) const;
        /// ForestKind::hardSwitches of `levels`: the switches below the transitions' smallest height.
        std::uint16_t kindHardSwitches(const Species& species, const std::vector<ForestLevel>& levels) const;
        void writeKindTables(const char* source); ///< every species' thresholds and hard switches again
        /// The frame budget's measurement on the viewer's cull: prediction and the step it wants.
        void measureFrameBudget(const CameraState& state);

        /// The parts `level` of `asset` draws (instanced materials made on the way).
        std::vector<std::unique_ptr<Part>> buildParts(TreeAsset& asset, const ForestLevel& level,
                                                      Ogre::Real upperPixelCount);
        /// Build level `level` of species `species` (no-op when resident or failed); returns the
        /// GPU bytes the Forest draws from that it did not before.
        std::uint64_t makeResident(std::uint32_t species, std::uint32_t level);
        /// Build queued levels within this frame's budget.
        void serviceUploads();
        static unsigned long currentFrame();
        std::uint64_t drawableBytes() const; ///< getGpuBytes without the instance buffers
        using ResourceVisitor = std::function<void(const std::shared_ptr<const void>& handle, std::uint64_t bytes)>;
        /// Each buffer and named texture `part` draws from, and the other LoD levels' index buffers of
        /// its mesh (a resource may come twice).
        static void visitPartResources(const Part& part, const ResourceVisitor& visit);
        /// This Forest's instanced clone of material `name` (and of its shadow casters).
        Ogre::MaterialPtr instancedMaterial(const Ogre::String& name, const Ogre::String& group);
        bool useShadowedMaterials() const;
        /// Write the instances of `state`'s bucket `bucket` into its instance buffer (grown if needed),
        /// drawn with the parts of level `level` of its species (or its fallback).
        void fillBucket(CameraState& state, std::uint32_t bucket, std::uint32_t level);
        /// Zero the per-frame counts of mStats (a viewer's visibility pass begins).
        void clearFrameStats();
        /// Free the state of `camera` (being destroyed): its instance buffers and Renderables.
        void dropCamera(Ogre::Camera* camera);

        ForestInstances mInstances;
        std::vector<std::unique_ptr<Species>> mSpecies;
        std::map<Ogre::Camera*, std::unique_ptr<CameraState>> mCameras; ///< each listened to
        std::unique_ptr<CameraListener> mCameraListener;
        std::map<Ogre::String, Ogre::MaterialPtr> mInstancedMaterials; ///< by source material name
        Ogre::String mMaterialPrefix;
        Ogre::Camera* mCurrentCamera = nullptr;
        Ogre::AxisAlignedBox mBounds;
        Ogre::Real mRadius = 0.0f;
        ObjectLodBias mLodBias;
        Ogre::Real mShadowLodBias = 1.0f;
        Ogre::Real mLodHysteresis = 0.15f;
        Ogre::Real mLodTransition = DEFAULT_LOD_TRANSITION;
        Ogre::Real mLodTransitionMinHeight = DEFAULT_LOD_TRANSITION_MIN_HEIGHT;
        FrameBudgetController mBudget{DEFAULT_ERROR_BUDGET}; ///< the error budget, set or under a frame budget
        float mShadowErrorBudget = DEFAULT_SHADOW_ERROR_BUDGET;
        std::uint64_t mMemoryBudget = 0;
        bool mMemoryBinds = false; ///< the memory plan took levels out
        bool mLodFrozen = false;
        bool mOcclusion = true;
        ForestStats mStats;
        std::uint64_t mInstanceBufferBytes = 0;
        std::uint64_t mUploadBudget = 0;
        std::deque<std::pair<std::uint32_t, std::uint32_t>> mUploadQueue; ///< (species, level), FIFO
        unsigned long mUploadFrame = std::numeric_limits<unsigned long>::max(); ///< of mStats' upload counts
        std::unique_ptr<ViewerListener> mViewerListener; ///< registered with mManager
    };

    class ForestFactory : public Ogre::MovableObjectFactory
    {
    public:
        static const Ogre::String FACTORY_TYPE_NAME;
        const Ogre::String& getType() const override { return FACTORY_TYPE_NAME; }

    protected:
        Ogre::MovableObject* createInstanceImpl(const Ogre::String& name,
                                                const Ogre::NameValuePairList* params) override;
    };
}
