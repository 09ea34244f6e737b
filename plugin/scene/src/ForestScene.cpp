#include "TreeLod/ForestScene.h"

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

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

        /// A species' bands for a technique choice ("" = the script's), distance bands still
        /// open (minHeightPixels 0: ForestScene converts them with the asset's height), and the
        /// bake techniques they draw from, "reference" included. Throws on an unknown technique.
        std::vector<ForestBand> speciesBands(const SceneScript& script, const SceneSpecies& species,
                                             const std::string& technique, std::set<std::string>& bake)
        {
            std::vector<ForestBand> bands;
            float budget = 0.0f;
            if (parseAutoTechnique(technique, budget) || (technique.empty() && species.autoTechnique))
            {
                // Budgeted auto chooses among these; the fixed bands draw from a subset of them.
                bake.insert(REFERENCE_CHUNK);
                for (const Ogre::String& name : Forest::getAutoTechniques())
                    bake.insert(bakeTechniqueOf(name));
                return Forest::getAutoBands();
            }
            if (!technique.empty())
                bands = {ForestBand{technique, 0.0f}};
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
        if (isQuadFloor(technique))
            return IMPOSTOR_CHUNK;
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(technique);
        return info && info->forestLevels ? info->chunkTechnique : "";
    }

    bool parseAutoTechnique(const std::string& technique, float& budget, float* frameBudgetMs)
    {
        budget = std::numeric_limits<float>::quiet_NaN();
        if (frameBudgetMs)
            *frameBudgetMs = std::numeric_limits<float>::quiet_NaN();
        if (technique == "auto")
            return true;
        const bool frame = technique.rfind("auto~", 0) == 0;
        if (!frame && technique.rfind("auto@", 0) != 0)
            return false;
        const std::string number = technique.substr(5);
        char* end = nullptr;
        const double value = std::strtod(number.c_str(), &end);
        if (number.empty() || *end != '\0' || (frame ? !(value > 0.0 && value <= 1e6) : !(value >= 0.0 && value <= 1.0)))
            return false;
        if (!frame)
            budget = float(value);
        else if (frameBudgetMs)
            *frameBudgetMs = float(value);
        return true;
    }

    bool isQuadFloor(const std::string& technique)
    {
        return technique == "entities" || technique == "merged-quads" || technique == "billboard-set";
    }

    std::string knownSceneTechniques()
    {
        std::string known;
        for (const TechniqueInfo& t : TechniqueRegistry::getSingleton().getTechniques())
            if (t.forestLevels)
                known += t.name + ", ";
        return known + "entities, merged-quads, billboard-set";
    }

    std::map<std::string, std::vector<std::string>> scenePackages(const SceneScript& script,
                                                                  const std::vector<std::string>& techniques)
    {
        std::map<std::string, std::set<std::string>> wanted;
        for (const std::string& technique : techniques)
            for (const SceneSpecies& species : script.species)
                speciesBands(script, species, technique, wanted[speciesSource(species)]);
        std::map<std::string, std::vector<std::string>> packages;
        for (const auto& [source, bake] : wanted)
            packages[source] = std::vector<std::string>(bake.begin(), bake.end());
        return packages;
    }

    ForestScene::ForestScene(Ogre::SceneManager& sceneManager, Ogre::SceneNode& parent, const SceneScript& script,
                             const ForestSceneOptions& options)
        : mSceneManager(sceneManager), mParent(parent), mScript(script), mOptions(options),
          mTechnique(options.technique)
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
        float errorBudget = 0.0f, frameBudget = 0.0f;
        parseAutoTechnique(mTechnique, errorBudget, &frameBudget);
        mForest->setFrameBudgetMs(std::isnan(frameBudget) ? mScript.lod.frameBudgetMs : frameBudget);

        // Bands per species; then one bake request per distinct source with every technique its
        // species draw (two species sharing a file share one package and one asset).
        const float tanHalfFov = std::tan(glm::radians(mScript.camera.fovYDegrees) * 0.5f);
        std::vector<std::vector<ForestBand>> bands(mScript.species.size());
        std::map<std::string, std::set<std::string>> techniques; // source -> bake techniques
        for (std::size_t s = 0; s < mScript.species.size(); ++s)
            bands[s] = speciesBands(mScript, mScript.species[s], mTechnique, techniques[speciesSource(mScript.species[s])]);
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
            if (mTechnique.empty() && !species.autoTechnique)
            {
                const Ogre::AxisAlignedBox bounds = asset->getBounds();
                const float height = float(bounds.getMaximum().y - bounds.getMinimum().y) *
                                     0.5f * (species.scaleMin + species.scaleMax);
                for (std::size_t b = 0; b < species.bands.size(); ++b)
                    if (species.bands[b].maxDistance > 0.0f)
                        bands[s][b].minHeightPixels =
                            height * float(mScript.height) / (2.0f * species.bands[b].maxDistance * tanHalfFov);
            }
            if (isQuadFloor(mTechnique))
                continue; // drawn by the floor below, not the Forest
            try
            {
                float budget = std::numeric_limits<float>::quiet_NaN(); // NaN: the script's
                const bool budgeted =
                    parseAutoTechnique(mTechnique, budget) || (mTechnique.empty() && species.autoTechnique);
                if (std::isnan(budget))
                    budget = mScript.lod.maxError;
                const std::size_t notesBefore = mLevelNotes.size();
                std::vector<LevelCost> costs;
                std::string noCosts = "no level costs given";
                if (budgeted && mOptions.levelCosts && asset->hasChunk(ERROR_CURVES_CHUNK))
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
                    if (budgeted)
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
        if (mTechnique == "entities")
            mEntityFloor = std::make_unique<EntityFloor>(mSceneManager, *mForestNode, mAssets, instances);
        else if (mTechnique == "merged-quads")
            mMergedQuadFloor = std::make_unique<MergedQuadFloor>(mSceneManager, *mForestNode, mAssets, instances);
        else if (mTechnique == "billboard-set")
            mBillboardSetFloor = std::make_unique<BillboardSetFloor>(mSceneManager, *mForestNode, mAssets, instances);
        else
            mForest->addInstances(instances);
    }

    void ForestScene::destroyForest()
    {
        mEntityFloor.reset();
        mMergedQuadFloor.reset();
        mBillboardSetFloor.reset();
        if (mForest)
        {
            mForestNode->detachAllObjects();
            mSceneManager.destroyMovableObject(mForest);
            mSceneManager.destroySceneNode(mForestNode);
            mForest = nullptr;
        }
    }

    void ForestScene::setTechnique(const std::string& technique)
    {
        destroyForest();
        mTechnique = technique;
        buildSpecies();
    }

    void ForestScene::requestTechnique(const std::string& technique)
    {
        std::vector<std::shared_ptr<TreeAssetRequest>> bakes;
        for (const auto& [source, techniques] : scenePackages(mScript, {technique}))
            bakes.push_back(TreeAssetManager::getSingleton().requireAsync(
                source, std::vector<Ogre::String>(techniques.begin(), techniques.end()), mOptions.group));
        mPendingBakes = std::move(bakes);
        mPendingTechnique = technique;
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
                            mScript.file + ": technique '" + mPendingTechnique + "': " + e.getDescription(),
                            "ForestScene::update");
            }
        }
        setTechnique(mPendingTechnique); // its require() calls find the packages baked
        return true;
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
        if (mEntityFloor)
            return mEntityFloor->getGpuBytes();
        if (mMergedQuadFloor)
            return mMergedQuadFloor->getGpuBytes();
        if (mBillboardSetFloor)
            return mBillboardSetFloor->getGpuBytes();
        return mForest ? mForest->getGpuBytes() : 0;
    }
}
