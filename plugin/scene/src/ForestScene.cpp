#include "TreeLod/ForestScene.h"

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/Wind.h"

#include <OgreLogManager.h>
#include <OgreManualObject.h>
#include <OgreMaterialManager.h>
#include <OgreSceneNode.h>
#include <OgreStringConverter.h>
#include <OgreTechnique.h>

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>

namespace TreeLod
{
    namespace
    {
        const Ogre::String SUN_NAME = "TreeLodSun"; // OffscreenRenderer's sun, reused when present
        constexpr float SHADOW_FAR_DISTANCE = 150.0f; // metres: shadows of the trees near the viewer

        /// A linear-space grass colour for the ground (what the Lit bark shader multiplies its white texture by).
        const Ogre::ColourValue GROUND_COLOUR(0.10f, 0.16f, 0.05f, 1.0f);

        /// Whether `species` draws by budgeted auto under `policy`.
        bool budgeted(const LodPolicy& policy, const SceneSpecies& species)
        {
            return policy.isAuto() || (policy.mode == LodPolicy::Mode::Script && species.autoTechnique);
        }

        /// A species' bands under `policy`, distance bands still open (minHeightPixels 0:
        /// ForestScene converts them with the asset's height), and the bake techniques they draw
        /// from, "reference" included. Throws on an unknown technique.
        std::vector<ForestBand> speciesBands(const SceneScript& script, const SceneSpecies& species,
                                             const LodPolicy& policy, std::set<std::string>& bake)
        {
            std::vector<ForestBand> bands;
            if (budgeted(policy, species))
            {
                // Budgeted auto chooses among these; the fixed bands draw from a subset of them.
                bake.insert(REFERENCE_CHUNK);
                for (const Ogre::String& name : Forest::getAutoTechniques())
                    bake.insert(bakeTechniqueOf(name));
                return Forest::getAutoBands();
            }
            if (policy.mode == LodPolicy::Mode::Fixed)
                bands = {ForestBand{policy.technique, 0.0f}};
            else
                for (const TechniqueBand& band : species.bands)
                    bands.push_back(ForestBand{band.technique, band.minPixels});
            bake.insert(REFERENCE_CHUNK);
            for (const ForestBand& band : bands)
            {
                const std::string name = bakeTechniqueOf(band.technique);
                if (name.empty())
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                script.file + ": species '" + species.name + "': unknown technique '" +
                                    band.technique + "' (known: " + knownSceneTechniques() + ")",
                                "ForestScene");
                bake.insert(name);
            }
            return bands;
        }
    }

    std::string speciesSource(const SceneSpecies& species)
    {
        if (!species.source.empty())
            return species.source;
        std::string out = "preset:" + species.preset + "?seed=" + std::to_string(species.seed);
        if (species.leaves)
            out += "&leaves=" + std::to_string(species.leaves);
        if (species.height > 0.0f)
        {
            char text[32];
            std::snprintf(text, sizeof text, "%g", double(species.height));
            out += std::string("&height=") + text;
        }
        return out;
    }

    std::string bakeTechniqueOf(const std::string& technique)
    {
        const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        if (const BaselineInfo* baseline = registry.findBaseline(technique))
            return baseline->chunkTechnique;
        const TechniqueInfo* info = registry.find(technique);
        return info && info->forestLevels ? info->chunkTechnique : "";
    }

    std::vector<ComparisonRun> comparisonRuns()
    {
        const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        std::vector<ComparisonRun> runs;
        for (const TechniqueInfo& t : registry.getTechniques())
            if (!t.roles.comparisonLabel.empty())
                runs.push_back({t.name, t.roles.comparisonLabel, t.roles.plotMarker});
        for (const BaselineInfo& b : registry.getBaselines())
            runs.push_back({b.name, b.comparisonLabel, b.plotMarker});
        return runs;
    }

    bool isComparisonRun(const std::string& technique)
    {
        const std::vector<ComparisonRun> runs = comparisonRuns();
        return std::any_of(runs.begin(), runs.end(), [&](const ComparisonRun& r) { return r.technique == technique; });
    }

    Result<std::vector<BenchRun>> parseBenchRuns(const std::vector<std::string>& names)
    {
        std::vector<BenchRun> runs;
        for (const std::string& name : names)
        {
            Result<LodPolicy> policy = LodPolicy::parse(name, "--techniques");
            if (!policy)
                return policy.error();
            if (policy->isAuto() && std::isnan(policy->errorBudget) && std::isnan(policy->frameBudgetMs))
            {
                // The bench's "auto": each species as its script says (with the run's own suffixes).
                const float transition = policy->transition, memory = policy->memoryBudgetMB,
                            occlusion = policy->occlusion;
                policy = LodPolicy::scriptChoice();
                policy->transition = transition;
                policy->memoryBudgetMB = memory;
                policy->occlusion = occlusion;
            }
            if (policy->mode == LodPolicy::Mode::Fixed && bakeTechniqueOf(policy->technique).empty())
                return fail("", "--techniques",
                            "unknown technique '" + policy->technique + "' (known: auto, auto@E, auto~MS, " +
                                knownSceneTechniques() + "; any with +fadeT or +occB, auto with +memMB)");
            runs.push_back({name, *policy});
        }
        return runs;
    }

    std::vector<BenchRun> comparisonBenchRuns()
    {
        std::vector<BenchRun> runs;
        for (const ComparisonRun& c : comparisonRuns())
            runs.push_back({c.technique, LodPolicy::fixed(c.technique)});
        return runs;
    }

    std::string describeComparisonRuns()
    {
        std::string out;
        for (const ComparisonRun& r : comparisonRuns())
            out += (out.empty() ? "" : ", ") + r.technique;
        return out;
    }

    std::string defaultBenchTechniques()
    {
        std::string list = "auto";
        for (const TechniqueInfo& t : TechniqueRegistry::getSingleton().getTechniques())
            if (t.roles.benchDefault)
                list += "," + t.name;
        return list;
    }

    bool isBaseline(const std::string& technique)
    {
        return TechniqueRegistry::getSingleton().findBaseline(technique) != nullptr;
    }

    std::string knownSceneTechniques()
    {
        std::string known;
        for (const TechniqueInfo& t : TechniqueRegistry::getSingleton().getTechniques())
            if (t.forestLevels)
                known += (known.empty() ? "" : ", ") + t.name;
        for (const BaselineInfo& b : TechniqueRegistry::getSingleton().getBaselines())
            known += (known.empty() ? "" : ", ") + b.name;
        return known;
    }

    std::map<std::string, std::vector<std::string>> scenePackages(const SceneScript& script,
                                                                  const std::vector<LodPolicy>& policies)
    {
        std::map<std::string, std::set<std::string>> wanted;
        for (const LodPolicy& policy : policies)
            for (const SceneSpecies& species : script.species)
                speciesBands(script, species, policy, wanted[speciesSource(species)]);
        std::map<std::string, std::vector<std::string>> packages;
        for (const auto& [source, bake] : wanted)
            packages[source] = std::vector<std::string>(bake.begin(), bake.end());
        return packages;
    }

    ForestScene::ForestScene(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const SceneScript& script,
                             const ForestSceneOptions& options)
        : mSceneManager(sceneManager), mParent(parent), mScript(script), mOptions(options),
          mPolicy(options.policy)
    {
        mPlacements = generatePlacements(mScript, mOptions.placement);
        if (mSceneManager.hasLight(SUN_NAME))
            mSun = mSceneManager.getLight(SUN_NAME);
        else
        {
            mSun = mSceneManager.createLight(SUN_NAME);
            mSunNode = mSceneManager.getRootSceneNode()->createChildSceneNode();
            mSunNode->attachObject(mSun);
        }
        applyLighting(mSceneManager, *mSun, sceneLighting(mScript));
        Wind::setParameters(mScript.wind); // the scene's (calm by default); its clock is the caller's
        Wind::setTime(frameTime(mScript, 0));
        try
        {
            if (mOptions.ground)
                buildGround();
            buildSpecies();
            setShadows(mScript.shadows.enabled);
        }
        catch (...)
        {
            release();
            throw;
        }
    }

    ForestScene::~ForestScene() { release(); }

    void ForestScene::release()
    {
        destroyForest();
        if (mGround)
        {
            mGroundNode->detachAllObjects();
            mSceneManager.destroyMovableObject(mGround);
            mSceneManager.destroySceneNode(mGroundNode);
            mGround = nullptr;
        }
        if (mSunNode)
        {
            mSunNode->detachAllObjects();
            mSceneManager.destroyLight(mSun);
            mSceneManager.destroySceneNode(mSunNode);
            mSunNode = nullptr;
            mSun = nullptr;
        }
    }

    void ForestScene::buildGround()
    {
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const char* suffix : {"", "Shadowed"})
        {
            const Ogre::String name = Ogre::String("TreeLod/Ground") + suffix;
            if (materials.resourceExists(name, mOptions.group))
                continue;
            Ogre::MaterialPtr base = materials.getByName(Ogre::String("TreeLod/Bark") + suffix, mOptions.group);
            if (!base)
                OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND,
                            Ogre::String("material TreeLod/Bark") + suffix + " not found in group " + mOptions.group,
                            "ForestScene");
            Ogre::MaterialPtr ground = base->clone(name, true, mOptions.group);
            ground->getTechnique(0)->getPass(0)->getFragmentProgramParameters()->setNamedConstant("baseColour",
                                                                                                 GROUND_COLOUR);
            ground->load();
        }

        // A grid over the square (65 x 65 vertices; heights and normals from the heightfield).
        const SceneGround& g = mScript.ground;
        const int cells = g.kind == SceneGround::Kind::Heightfield ? 128 : 16;
        const float half = 0.5f * g.size, step = g.size / float(cells);
        static int counter = 0;
        mGround = mSceneManager.createManualObject("TreeLod/Ground/" + std::to_string(counter++));
        mGround->setCastShadows(false);
        mGround->begin("TreeLod/Ground", Ogre::RenderOperation::OT_TRIANGLE_LIST, mOptions.group);
        for (int j = 0; j <= cells; ++j)
            for (int i = 0; i <= cells; ++i)
            {
                const float x = -half + step * float(i), z = -half + step * float(j);
                const float e = 0.5f * step;
                const float dx = groundHeight(g, x + e, z) - groundHeight(g, x - e, z);
                const float dz = groundHeight(g, x, z + e) - groundHeight(g, x, z - e);
                const Ogre::Vector3 n = Ogre::Vector3(-dx, 2.0f * e, -dz).normalisedCopy();
                mGround->position(x, groundHeight(g, x, z), z);
                mGround->normal(n);
                mGround->textureCoord(x / 4.0f, z / 4.0f);
            }
        for (int j = 0; j < cells; ++j)
            for (int i = 0; i < cells; ++i)
            {
                const Ogre::uint32 a = Ogre::uint32(j * (cells + 1) + i), b = a + 1, c = a + Ogre::uint32(cells + 1),
                                   d = c + 1;
                mGround->triangle(a, c, b); // counter-clockwise seen from above (+Y)
                mGround->triangle(b, c, d);
            }
        mGround->end();
        mGroundNode = mParent.createChildSceneNode();
        mGroundNode->attachObject(mGround);
    }

    std::string ForestScene::levelNote(const LevelNote& note) const
    {
        if (note.species < 0)
            return note.fixed;
        const std::uint32_t species = std::uint32_t(note.species);
        const std::vector<ForestLevel>& levels = mForest->getLevels(species);
        std::string text = "budget " + Ogre::StringConverter::toString(mForest->getErrorBudget()) + ":";
        for (std::size_t l = 0; l < levels.size(); ++l)
        {
            const float px = Forest::heightForPixelCount(*mForest->getAsset(species), levels[l].minPixelCount);
            text += (l ? ", " : " ") + Forest::describeLevel(levels[l]) + " >= " +
                    Ogre::StringConverter::toString(int(std::round(px))) + " px";
        }
        return text;
    }

    std::vector<std::string> ForestScene::getLevelNotes() const
    {
        std::vector<std::string> notes;
        for (const LevelNote& note : mLevelNotes)
            notes.push_back(note.name + ": " + levelNote(note));
        return notes;
    }

    bool ForestScene::setErrorBudget(float budget)
    {
        for (std::uint32_t s = 0; mForest && s < mForest->getSpeciesCount(); ++s)
            if (mForest->isBudgeted(s))
            {
                mForest->setErrorBudget(budget);
                return true;
            }
        return false;
    }

    void ForestScene::buildSpecies()
    {
        static int counter = 0;
        mForest = static_cast<Forest*>(
            mSceneManager.createMovableObject("TreeLod/Forest/" + std::to_string(counter++), ForestFactory::FACTORY_TYPE_NAME));
        mForestNode = mParent.createChildSceneNode();
        mForestNode->attachObject(mForest);
        mForest->setUploadBudget(mOptions.uploadBudget);
        mForest->setShadowLodBias(mScript.shadows.lodBias);
        mForest->setFrameBudgetMs(std::isnan(mPolicy.frameBudgetMs) ? mScript.lod.frameBudgetMs : mPolicy.frameBudgetMs);
        mForest->setLodTransition(std::isnan(mPolicy.transition) ? mScript.lod.transition : mPolicy.transition);
        const float memoryMB = std::isnan(mPolicy.memoryBudgetMB) ? mScript.lod.memoryBudgetMB : mPolicy.memoryBudgetMB;
        mForest->setMemoryBudget(std::uint64_t(double(memoryMB) * 1e6));
        mForest->setOcclusion(std::isnan(mPolicy.occlusion) ? mScript.lod.occlusion : mPolicy.occlusion != 0.0f);

        // Bands per species; then one bake request per distinct source with every technique its
        // species draw (two species sharing a file share one package and one asset).
        const float tanHalfFov = std::tan(glm::radians(mScript.camera.fovYDegrees) * 0.5f);
        std::vector<std::vector<ForestBand>> bands(mScript.species.size());
        std::map<std::string, std::set<std::string>> techniques; // source -> bake techniques
        for (std::size_t s = 0; s < mScript.species.size(); ++s)
            bands[s] = speciesBands(mScript, mScript.species[s], mPolicy, techniques[speciesSource(mScript.species[s])]);
        std::map<std::string, TreeAssetPtr> assets;
        for (const auto& [source, wanted] : techniques)
        {
            try
            {
                assets[source] = TreeAssetManager::getSingleton().require(
                    source, std::vector<Ogre::String>(wanted.begin(), wanted.end()), mOptions.group);
            }
            catch (const Ogre::Exception& e)
            {
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, mScript.file + ": " + e.getDescription(), "ForestScene");
            }
        }

        mAssets.clear();
        mLevelNotes.clear();
        for (std::size_t s = 0; s < mScript.species.size(); ++s)
        {
            const SceneSpecies& species = mScript.species[s];
            TreeAssetPtr asset = assets[speciesSource(species)];
            mAssets.push_back(asset);
            // Distance bands: the screen height a tree of this asset has at that distance from the
            // script's camera (the bench and the browser render at the script's resolution).
            if (mPolicy.mode == LodPolicy::Mode::Script && !species.autoTechnique)
            {
                const Ogre::AxisAlignedBox bounds = asset->getBounds();
                const float height = float(bounds.getMaximum().y - bounds.getMinimum().y) *
                                     0.5f * (species.scaleMin + species.scaleMax);
                for (std::size_t b = 0; b < species.bands.size(); ++b)
                    if (species.bands[b].maxDistance > 0.0f)
                        bands[s][b].minHeightPixels =
                            height * float(mScript.height) / (2.0f * species.bands[b].maxDistance * tanHalfFov);
            }
            if (mPolicy.mode == LodPolicy::Mode::Fixed && isBaseline(mPolicy.technique))
                continue; // drawn by the floor below, not the Forest
            try
            {
                const bool isBudgeted = budgeted(mPolicy, species);
                const float budget = std::isnan(mPolicy.errorBudget) ? mScript.lod.maxError : mPolicy.errorBudget;
                const std::size_t notesBefore = mLevelNotes.size();
                std::vector<LevelCost> costs;
                std::string noCosts = "no level costs given";
                if (isBudgeted && mOptions.levelCosts && asset->hasChunk(ERROR_CURVES_CHUNK))
                    try
                    {
                        costs = mOptions.levelCosts(*asset);
                    }
                    catch (const Ogre::Exception& e)
                    {
                        noCosts = e.getDescription();
                    }
                if (!costs.empty())
                {
                    // The Forest's budgets are the scene's: species of one scene share them.
                    mForest->setErrorBudget(budget);
                    mForest->setShadowErrorBudget(mScript.lod.shadowMaxError);
                    const std::uint32_t added = mForest->addBudgetedSpecies(asset, costs);
                    mLevelNotes.push_back(LevelNote{species.name, int(added), ""});
                }
                else
                {
                    const std::vector<ForestLevel> levels = Forest::levelsForBands(*asset, bands[s]);
                    if (isBudgeted)
                        mLevelNotes.push_back(
                            LevelNote{species.name, -1,
                                      std::string("fixed auto bands: ") +
                                          (asset->hasChunk(ERROR_CURVES_CHUNK) ? noCosts
                                                                               : "the package has no error curves")});
                    mForest->addSpecies(asset, levels);
                }
                if (mLevelNotes.size() > notesBefore)
                    Ogre::LogManager::getSingleton().logMessage("TreeLod: species '" + species.name +
                                                                "': " + levelNote(mLevelNotes.back()));
            }
            catch (const Ogre::Exception& e)
            {
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                            mScript.file + ": species '" + species.name + "': " + e.getDescription(), "ForestScene");
            }
        }

        std::vector<ForestInstance> instances;
        instances.reserve(mPlacements.size());
        for (const PlacedTree& tree : mPlacements)
            instances.push_back(ForestInstance{tree.position, tree.rotation, tree.scale, tree.species});
        const BaselineInfo* baseline = mPolicy.mode == LodPolicy::Mode::Fixed
                                           ? TechniqueRegistry::getSingleton().findBaseline(mPolicy.technique)
                                           : nullptr;
        if (baseline)
            mBaseline = baseline->create(mSceneManager, *mForestNode, mAssets, instances);
        else
            mForest->addInstances(instances);
    }

    void ForestScene::destroyForest()
    {
        mBaseline.reset();
        if (mForest)
        {
            mForestNode->detachAllObjects();
            mSceneManager.destroyMovableObject(mForest);
            mSceneManager.destroySceneNode(mForestNode);
            mForest = nullptr;
        }
    }

    void ForestScene::setPolicy(const LodPolicy& policy)
    {
        destroyForest();
        mPolicy = policy;
        buildSpecies();
    }

    void ForestScene::requestPolicy(const LodPolicy& policy)
    {
        std::vector<std::shared_ptr<TreeAssetRequest>> bakes;
        for (const auto& [source, techniques] : scenePackages(mScript, {policy}))
            bakes.push_back(TreeAssetManager::getSingleton().requireAsync(
                source, std::vector<Ogre::String>(techniques.begin(), techniques.end()), mOptions.group));
        mPendingBakes = std::move(bakes);
        mPendingPolicy = policy;
        mPendingRequested = true;
    }

    bool ForestScene::update()
    {
        if (!mPendingRequested)
            return false;
        for (const std::shared_ptr<TreeAssetRequest>& bake : mPendingBakes)
            if (!bake->isReady())
                return false;
        mPendingRequested = false;
        const std::vector<std::shared_ptr<TreeAssetRequest>> bakes = std::move(mPendingBakes);
        mPendingBakes.clear();
        for (const std::shared_ptr<TreeAssetRequest>& bake : bakes)
        {
            try
            {
                bake->get(); // the baker's error, if any; the package is loaded
            }
            catch (const Ogre::Exception& e)
            {
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                            mScript.file + ": technique '" + mPendingPolicy.toString() + "': " + e.getDescription(),
                            "ForestScene::update");
            }
        }
        setPolicy(mPendingPolicy); // its require() calls find the packages baked
        return true;
    }

    void ForestScene::setGroundVisible(bool visible)
    {
        if (mGround)
            mGround->setVisible(visible);
    }

    void ForestScene::setShadows(bool enabled)
    {
        SunShadowSettings settings;
        settings.technique = enabled ? Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED : Ogre::SHADOWTYPE_NONE;
        settings.camera = parseShadowCamera(mScript.shadows.camera, mScript.file + ": /shadows/camera");
        settings.textureSize = unsigned(mScript.shadows.textureSize);
        settings.farDistance = SHADOW_FAR_DISTANCE;
        // PSSM splits the view of the scene manager's first camera (OffscreenRenderer's, the browser's).
        const Ogre::SceneManager::CameraList& cameras = mSceneManager.getCameras();
        setupSunShadows(mSceneManager, *mSun, settings, cameras.empty() ? nullptr : cameras.begin()->second);
        if (enabled)
            mSceneManager.setShadowDirectionalLightExtrusionDistance(2.0f * SHADOW_FAR_DISTANCE + 50.0f);
        if (mGround)
            mGround->setMaterialName(0, enabled ? "TreeLod/GroundShadowed" : "TreeLod/Ground", mOptions.group);
    }

    float ForestScene::getShadowFarDistance() { return SHADOW_FAR_DISTANCE; }

    CameraSpec ForestScene::cameraAtFrame(std::uint32_t frame, std::uint32_t frameCount) const
    {
        return cameraAt(mScript, frameTime(mScript, frame, frameCount));
    }

    std::uint64_t ForestScene::getGpuBytes() const
    {
        if (mBaseline)
            return mBaseline->getGpuBytes();
        return mForest ? mForest->getGpuBytes() : 0;
    }
}
