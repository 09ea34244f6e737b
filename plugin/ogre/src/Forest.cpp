// Forest: many trees in one MovableObject, culled and LoD-selected in one loop
// (ForestInstances::cull) and drawn with hardware instancing (Forest.h). This file: the object,
// its species and instances, and the settings that reach every level.
#include "ForestDetail.h"

namespace TreeLod
{
    // ---- Forest ----------------------------------------------------------------------------------

    const Ogre::String ForestFactory::FACTORY_TYPE_NAME = "Forest";

    Forest::Forest(const Ogre::String& name) : Ogre::MovableObject(name)
    {
        static std::atomic<std::uint32_t> serial{0};
        mMaterialPrefix = "TreeLod/Forest" + std::to_string(serial++) + "/";
        mBounds.setNull();
        mCameraListener = std::make_unique<CameraListener>(*this);
    }

    Forest::~Forest()
    {
        if (mManager && mViewerListener)
            mManager->removeListener(mViewerListener.get());
        for (const auto& camera : mCameras)
            camera.first->removeListener(mCameraListener.get());
        mCameras.clear();
        mSpecies.clear();
        if (Ogre::MaterialManager* materials = Ogre::MaterialManager::getSingletonPtr())
            for (const auto& entry : mInstancedMaterials)
                materials->remove(entry.second);
    }

    const Ogre::String& Forest::getMovableType() const { return ForestFactory::FACTORY_TYPE_NAME; }

    std::uint32_t Forest::addSpecies(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels)
    {
        return addSpeciesImpl(asset, levels, nullptr);
    }

    std::uint32_t Forest::addBudgetedSpecies(const TreeAssetPtr& asset, const std::vector<LevelCost>& costs)
    {
        const char* source = "Forest::addBudgetedSpecies";
        const Ogre::String label = speciesLabel(std::uint32_t(mSpecies.size()), asset.get());
        if (!asset)
            invalid(label + "no asset", source);
        auto plan = std::make_unique<BudgetPlan>();
        plan->curves = autoCurves(*asset, label, source);
        plan->costs = costs;
        // Under a memory budget, every budgeted species is planned again with this one.
        std::optional<MemoryPlan> memory;
        if (mMemoryBudget > 0)
        {
            memory = memoryPlan(plan.get(), asset.get(), mBudget.getUserErrorBudget(), mMemoryBudget, source);
            plan->excluded.assign(plan->curves.levels.size(), true);
            for (const LevelChoice& choice : memory->choices.back())
                plan->excluded[choice.curveLevel] = false;
        }
        for (const float step : frameBudgetLadder())
        {
            Result<std::vector<LevelChoice>> choices =
                chooseLevels(plan->curves, costs, step, MAX_LEVELS, LEVEL_SWITCH_COST_SLACK, plan->excluded);
            if (!choices)
                invalid(label + choices.error().message(), source);
            plan->ladderChoices.push_back(std::move(*choices));
        }
        Result<std::vector<LevelChoice>> choices = chooseLevels(plan->curves, costs, mBudget.getErrorBudget(), MAX_LEVELS,
                                                                LEVEL_SWITCH_COST_SLACK, plan->excluded);
        if (!choices)
            invalid(label + choices.error().message(), source);
        plan->choices = *choices;
        plan->errorBudget = mBudget.getErrorBudget();
        const std::vector<ForestLevel> levels = levelsForChoices(*asset, plan->curves, plan->choices, label, source);
        const std::uint32_t added = addSpeciesImpl(asset, levels, std::move(plan));
        if (memory)
            applyMemoryPlan(*memory);
        else
            updatePlannedGpuBytes();
        return added;
    }

    std::uint32_t Forest::addSpeciesImpl(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels,
                                         std::unique_ptr<BudgetPlan> budget)
    {
        const char* source = "Forest::addSpecies";
        const Ogre::String label = speciesLabel(std::uint32_t(mSpecies.size()), asset.get());
        if (!asset)
            invalid(label + "no asset", source);
        // Planned from decoded chunks only (nothing uploaded but the bark mesh levelsForBands
        // plans with); each level's drawables are built when its trees first need them.
        Ogre::AxisAlignedBox drawn = asset->getBounds();
        checkLevels(*asset, levels, label, source, drawn);
        if (budget)
        {
            // The kind's sphere holds every level a budget may choose: re-plans keep it.
            for (const ErrorCurveLevel& c : budget->curves.levels)
                if (findLevelCost(budget->costs, c.technique, c.techniqueLevel, c.lowRes) >= 0)
                {
                    Ogre::AxisAlignedBox box = asset->getBounds();
                    checkLevels(*asset, {levelOfCurve(c, 0.0f)}, label + "candidate ", source, box);
                    drawn.merge(box);
                }
        }
        auto species = std::make_unique<Species>();
        species->asset = asset;
        species->levels = levels;
        species->parts.resize(levels.size());
        species->residency.assign(levels.size(), Residency::Absent);
        species->budget = std::move(budget);
        try
        {
            // The last level is the fallback of every other: resident from the start.
            species->parts.back() = buildParts(*asset, levels.back(), upperValue(levels, levels.size() - 1));
            species->residency.back() = Residency::Resident;
        }
        catch (const Ogre::Exception& e)
        {
            invalid(label + "level " + std::to_string(levels.size() - 1) + " '" + levels.back().technique +
                        "': " + e.getDescription(),
                    source);
        }

        // The kind: a tight sphere about what is drawn; thresholds in its units (Forest.h).
        const Ogre::Real referenceR = referenceRadius(*asset);
        const Ogre::Vector3 centre = drawn.getCenter();
        const Ogre::Real radius = std::max(0.5f * drawn.getSize().length(), 1e-6f);
        if (!(referenceR > 0.0f))
            invalid(label + "the tree has no extent", source);
        const double unit = double(radius) * double(radius) / (double(referenceR) * double(referenceR));
        const Ogre::AxisAlignedBox bounds = asset->getBounds();
        const double height = double(bounds.getMaximum().y - bounds.getMinimum().y);
        // valueForHeight inverted: value = 4 pi (h_px R / height)^2 in reference units, x unit here.
        species->kindUnit = unit;
        species->heightPerRootValue = height / (double(referenceR) * std::sqrt(4.0 * Ogre::Math::PI * unit));
        ForestKind kind;
        kind.name = asset->getName() + " species " + std::to_string(mSpecies.size());
        kind.boundsCentre = glm::vec3(centre.x, centre.y, centre.z);
        kind.boundsRadius = radius;
        kind.thresholds = kindThresholds(*species, levels);
        kind.hardSwitches = kindHardSwitches(*species, levels);
        Result<std::uint32_t> added = mInstances.addKind(kind);
        if (!added)
            invalid(label + added.error().message(), source);
        OgreAssert(added.value() == mSpecies.size(), "kinds and species share indices");
        mSpecies.push_back(std::move(species));
        mStats.levelCounts.emplace_back(levels.size(), 0u);
        updateShadowLevels(added.value());
        updateOcclusionScales(added.value());
        return added.value();
    }

    std::uint32_t Forest::getSpeciesCount() const { return std::uint32_t(mSpecies.size()); }
    const std::vector<ForestLevel>& Forest::getLevels(std::uint32_t species) const
    {
        return mSpecies.at(species)->levels;
    }
    const TreeAssetPtr& Forest::getAsset(std::uint32_t species) const { return mSpecies.at(species)->asset; }

    std::vector<ForestHandle> Forest::addInstances(const std::vector<ForestInstance>& instances)
    {
        // Added along a Z-order curve so that culling skips whole blocks (ForestInstances.h); the
        // handles come back in the caller's order, and errors name the caller's index.
        if (Result<void> valid = mInstances.validate(instances); !valid)
            invalid("Forest '" + mName + "': " + valid.error().message(), "Forest::addInstances");
        const std::vector<std::uint32_t> order = ForestInstances::spatialOrder(instances);
        std::vector<ForestInstance> sorted(instances.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            sorted[i] = instances[order[i]];
        Result<std::vector<ForestHandle>> handles = mInstances.add(sorted);
        if (!handles)
            invalid("Forest '" + mName + "': " + handles.error().message(), "Forest::addInstances");
        std::vector<ForestHandle> out(instances.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            out[order[i]] = (*handles)[i];
        updateBounds();
        return out;
    }

    void Forest::updateBounds()
    {
        glm::vec3 lo(FLT_MAX), hi(-FLT_MAX);
        for (std::size_t i = 0; i < mInstances.size(); ++i)
        {
            const glm::vec4 sphere = mInstances.getWorldSphere(i);
            lo = glm::min(lo, glm::vec3(sphere) - sphere.w);
            hi = glm::max(hi, glm::vec3(sphere) + sphere.w);
        }
        if (mInstances.size() == 0)
            mBounds.setNull();
        else
            mBounds.setExtents(lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        mRadius = mBounds.isNull() ? 0.0f : Ogre::Math::boundingRadiusFromAABB(mBounds);
        if (mParentNode)
            mParentNode->needUpdate();
    }

    std::vector<float> Forest::kindThresholds(const Species& species, const std::vector<ForestLevel>& levels) const
    {
        // Level l is drawn while the value is at least thresholds[l]: setMeshLodBias's limits make
        // the levels finer than maxDetailIndex unreachable and stop at minDetailIndex.
        std::vector<float> thresholds;
        for (std::size_t l = 0; l + 1 < levels.size(); ++l)
            thresholds.push_back(l < mLodBias.maxMeshIndex    ? FLT_MAX
                                 : l >= mLodBias.minMeshIndex ? 0.0f
                                                              : species.kindValue(levels[l].minPixelCount));
        return thresholds;
    }

    std::uint16_t Forest::kindHardSwitches(const Species& species, const std::vector<ForestLevel>& levels) const
    {
        // A switch's height on screen: valueForHeight inverted (heightPerRootValue, Species).
        std::uint16_t hard = 0;
        for (std::size_t l = 0; l + 1 < levels.size(); ++l)
            if (species.heightPerRootValue * std::sqrt(double(species.kindValue(levels[l].minPixelCount))) <
                    double(mLodTransitionMinHeight) ||
                levelProvider(levels[l + 1].technique, "", "Forest").isContinuousStep(levels[l], levels[l + 1]))
                hard = std::uint16_t(hard | 1u << l);
        return hard;
    }

    void Forest::writeKindTables(const char* source)
    {
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            if (Result<void> set = mInstances.setKindThresholds(s, kindThresholds(*mSpecies[s], mSpecies[s]->levels),
                                                                kindHardSwitches(*mSpecies[s], mSpecies[s]->levels));
                !set)
                invalid("Forest '" + mName + "': " + set.error().message(), source);
    }

    void Forest::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)
    {
        const bool limits = maxDetailIndex != mLodBias.maxMeshIndex || minDetailIndex != mLodBias.minMeshIndex;
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "Forest '" + mName + "'");
        if (limits)
            writeKindTables("Forest::setMeshLodBias");
    }

    void Forest::setLodBias(Ogre::Real bias)
    {
        setMeshLodBias(bias, mLodBias.maxMeshIndex, mLodBias.minMeshIndex);
    }

    void Forest::setLodHysteresis(Ogre::Real hysteresis)
    {
        if (!(hysteresis >= 0.0f && hysteresis <= 1.0f))
            invalid("Forest '" + mName + "': LoD hysteresis " + std::to_string(hysteresis) + " is not in [0, 1]",
                    "Forest::setLodHysteresis");
        mLodHysteresis = hysteresis;
    }

    void Forest::setLodTransition(Ogre::Real transition, Ogre::Real minHeightPx)
    {
        if (!(transition >= 0.0f && transition <= ForestInstances::MAX_TRANSITION))
            invalid("Forest '" + mName + "': LoD transition " + std::to_string(transition) + " is not in [0, " +
                        std::to_string(ForestInstances::MAX_TRANSITION) +
                        "] (0: hard switches; at most a doubling of screen size)",
                    "Forest::setLodTransition");
        if (!(minHeightPx >= 0.0f && std::isfinite(minHeightPx)))
            invalid("Forest '" + mName + "': LoD transition minimum height " + std::to_string(minHeightPx) +
                        " px is not finite and >= 0",
                    "Forest::setLodTransition");
        mLodTransition = transition;
        if (minHeightPx == mLodTransitionMinHeight)
            return;
        mLodTransitionMinHeight = minHeightPx;
        writeKindTables("Forest::setLodTransition");
    }

    void Forest::setShadowLodBias(Ogre::Real bias)
    {
        if (!std::isfinite(bias) || !(bias > 0.0f))
            invalid("Forest '" + mName + "': shadow LoD bias " + std::to_string(bias) + " is not finite and > 0",
                    "Forest::setShadowLodBias");
        mShadowLodBias = bias;
    }

    void Forest::setLodFrozen(bool frozen) { mLodFrozen = frozen; }

    void Forest::setOcclusion(bool occlusion) { mOcclusion = occlusion; }

    void Forest::makeOcclusionMasks()
    {
        // Made when a viewer first culls with occlusion (a Forest that never does, such as the
        // one-tree Forests that measure levels, decodes nothing for it), from the reference's
        // polygons (a tree baked from photographs has none: it hides nothing).
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
        {
            Species& species = *mSpecies[s];
            if (species.occlusionMaskMade)
                continue;
            species.occlusionMaskMade = true;
            const ForestKind& kind = mInstances.getKind(s);
            std::shared_ptr<const OcclusionMask> mask;
            try
            {
                const ReferenceChunk& reference = species.asset->getReference();
                if (hasPolygons(reference.model))
                    mask = std::make_shared<const OcclusionMask>(
                        makeOcclusionMask(reference, kind.boundsCentre, kind.boundsRadius));
            }
            catch (const Ogre::Exception& e)
            {
                Ogre::LogManager::getSingleton().logWarning(speciesLabel(s, species.asset.get()) +
                                                            "no silhouette for occlusion (it hides nothing): " +
                                                            e.getDescription());
            }
            if (Result<void> set = mInstances.setKindOcclusion(s, mask, kind.occlusionHeightScales); !set)
                invalid(speciesLabel(s, species.asset.get()) + set.error().message(), "Forest::makeOcclusionMasks");
        }
    }

    void Forest::updateOcclusionScales(std::uint32_t s)
    {
        const Species& species = *mSpecies[s];
        std::array<float, OCCLUSION_CLASSES> scales;
        scales.fill(1.0f);
        if (const BudgetPlan* plan = species.budget.get())
            for (std::size_t c = 1; c < OCCLUSION_CLASSES; ++c)
                scales[c] = occlusionHeightScale(plan->curves, plan->choices, plan->errorBudget, std::exp2(-float(c)));
        if (Result<void> set = mInstances.setKindOcclusion(s, mInstances.getKind(s).occlusionMask, scales); !set)
            invalid(speciesLabel(s, species.asset.get()) + set.error().message(), "Forest::updateOcclusionScales");
    }

    bool Forest::useShadowedMaterials() const
    {
        return receivesDepthShadows(mManager);
    }
}
