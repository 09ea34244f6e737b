// The Forest's level plan: levels from bands or from error curves within an error budget, the
// budgeted species' replanning, shadow levels, and the frame-budget controller that moves the error
// budget along frameBudgetLadder() (LevelSelection.h).
#include "ForestDetail.h"

namespace TreeLod
{
    Ogre::MeshPtr ForestLevelProvider::getBarkMesh(TreeAsset& asset) { return asset.getBarkMesh(); }

    std::vector<ForestBand> Forest::getAutoBands()
    {
        const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        std::vector<ForestBand> bands;
        for (const TechniqueInfo& info : registry.getTechniques())
            if (info.roles.defaultBandMinHeight > 0.0f && !info.roles.floor)
                bands.push_back(ForestBand{info.name, info.roles.defaultBandMinHeight});
        std::stable_sort(bands.begin(), bands.end(), [](const ForestBand& a, const ForestBand& b) {
            return a.minHeightPixels > b.minHeightPixels;
        });
        bands.push_back(ForestBand{registry.getFloor().name, 0.0f});
        return bands;
    }

    std::vector<ForestLevel> Forest::getCandidateLevels(TreeAsset& asset, const std::vector<Ogre::String>& techniques)
    {
        std::vector<ForestLevel> levels;
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
        {
            if (!info.forestLevels || !asset.hasChunk(info.chunkTechnique) ||
                (!techniques.empty() && std::find(techniques.begin(), techniques.end(), info.name) == techniques.end()))
                continue;
            for (const Span& span : info.forestLevels->getSpans(asset, info.name))
            {
                ForestLevel level = span.level;
                level.minPixelCount = 0.0f;
                const bool seen = std::any_of(levels.begin(), levels.end(), [&](const ForestLevel& l) {
                    return l.technique == level.technique && l.techniqueLevel == level.techniqueLevel &&
                           l.lowRes == level.lowRes;
                });
                if (!seen)
                    levels.push_back(level);
            }
        }
        return levels;
    }

    Ogre::String Forest::describeLevel(const ForestLevel& level)
    {
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(level.technique);
        return info && info->forestLevels ? info->forestLevels->describeLevel(level) : level.technique;
    }

    Ogre::Real Forest::pixelCountForHeight(TreeAsset& asset, Ogre::Real heightPixels)
    {
        return valueForHeight(asset, heightPixels, "asset '" + asset.getName() + "': ",
                                            "Forest::pixelCountForHeight");
    }

    Ogre::Real Forest::heightForPixelCount(TreeAsset& asset, Ogre::Real pixelCount)
    {
        const Ogre::Real perPixel = valueForHeight(asset, 1.0f, "asset '" + asset.getName() + "': ",
                                                        "Forest::heightForPixelCount");
        return std::sqrt(std::max(pixelCount, 0.0f) / perPixel);
    }

    std::vector<Ogre::String> Forest::getAutoTechniques()
    {
        std::vector<Ogre::String> names;
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            if (info.roles.autoCandidate)
                names.push_back(info.name);
        return names;
    }

    std::vector<ForestLevel> Forest::levelsForErrorBudget(TreeAsset& asset, const std::vector<LevelCost>& costs,
                                                          float errorBudget)
    {
        const char* source = "Forest::levelsForErrorBudget";
        const Ogre::String label = "asset '" + asset.getName() + "': ";
        const ErrorCurves curves = autoCurves(asset, label, source);
        Result<std::vector<LevelChoice>> choices = chooseLevels(curves, costs, errorBudget, MAX_LEVELS);
        if (!choices)
            invalid(label + choices.error().message(), source);
        return levelsForChoices(asset, curves, *choices, label, source);
    }

    std::vector<ForestLevel> Forest::levelsForBands(TreeAsset& asset, const std::vector<ForestBand>& bands)
    {
        const char* source = "Forest::levelsForBands";
        const Ogre::String label = "asset '" + asset.getName() + "': ";
        if (bands.empty())
            invalid(label + "no technique bands", source);
        valueForHeight(asset, 1.0f, label, source); // a tree without height has no screen size: refused here
        auto pixelCount = [&](Ogre::Real heightPixels) { return valueForHeight(asset, heightPixels, label, source); };

        std::vector<ForestLevel> levels;
        Ogre::Real upper = NO_UPPER;
        Ogre::Real previousHeight = std::numeric_limits<Ogre::Real>::infinity();
        for (std::size_t b = 0; b < bands.size(); ++b)
        {
            const ForestBand& band = bands[b];
            const Ogre::String element = label + "band " + std::to_string(b) + " '" + band.technique + "': ";
            ForestLevelProvider& technique = levelProvider(band.technique, element, source);
            const bool last = b + 1 == bands.size();
            if (last && band.minHeightPixels != 0.0f)
                invalid(element + "the last band must reach 0 pixels, not " + std::to_string(band.minHeightPixels),
                        source);
            if (!last && !(std::isfinite(band.minHeightPixels) && band.minHeightPixels > 0.0f &&
                           band.minHeightPixels < previousHeight))
                invalid(element + "minHeightPixels " + std::to_string(band.minHeightPixels) +
                            " is not finite, > 0 and below the previous band's",
                        source);
            previousHeight = band.minHeightPixels;
            const Ogre::Real lower = last ? 0.0f : pixelCount(band.minHeightPixels);
            std::vector<Span> spans;
            try
            {
                spans = techniqueSpans(asset, technique, band.technique);
            }
            catch (const Ogre::Exception& e)
            {
                invalid(element + e.getDescription(), source);
            }
            if (spans.empty())
                invalid(element + "the asset has nothing this technique draws (its package lacks the technique's "
                                  "chunk: a tree baked from photographs has only the chunks baked from photographs)",
                        source);
            // The technique's levels clipped to the band's values [lower, upper).
            for (const Span& span : spans)
                if (span.level.minPixelCount < upper && span.upper > lower)
                {
                    levels.push_back(span.level);
                    levels.back().minPixelCount = std::max(span.level.minPixelCount, lower);
                }
            upper = lower;
        }
        if (levels.size() > MAX_LEVELS)
            invalid(label + "the bands give " + std::to_string(levels.size()) + " levels (at most " +
                        std::to_string(MAX_LEVELS) + ")",
                    source);
        return levels;
    }

    Ogre::String Forest::speciesLabel(std::uint32_t species, const TreeAsset* asset) const
    {
        return "Forest '" + mName + "' species " + std::to_string(species) + " ('" +
               (asset ? asset->getName() : Ogre::String("null")) + "'): ";
    }

    bool Forest::isBudgeted(std::uint32_t species) const { return mSpecies.at(species)->budget != nullptr; }

    const std::vector<std::uint32_t>& Forest::getShadowLevels(std::uint32_t species) const
    {
        return mSpecies.at(species)->shadowLevels;
    }

    void Forest::updateShadowLevels(std::uint32_t s)
    {
        Species& species = *mSpecies[s];
        species.shadowLevels.resize(species.levels.size());
        for (std::uint32_t l = 0; l < species.shadowLevels.size(); ++l)
            species.shadowLevels[l] = l;
        if (!species.budget)
            return;
        const BudgetPlan& plan = *species.budget;
        Result<std::vector<std::size_t>> shadow =
            chooseShadowLevels(plan.curves, plan.costs, plan.choices, mShadowErrorBudget);
        if (shadow && shadow->size() == species.levels.size())
            for (std::size_t l = 0; l < shadow->size(); ++l)
                species.shadowLevels[l] = std::uint32_t((*shadow)[l]);
    }

    void Forest::replan(std::uint32_t s, const std::vector<LevelChoice>& choices)
    {
        const char* source = "Forest::replan";
        Species& species = *mSpecies[s];
        BudgetPlan& plan = *species.budget;
        TreeAsset& asset = *species.asset;
        const Ogre::String label = speciesLabel(s, &asset);
        const std::vector<ForestLevel> levels = levelsForChoices(asset, plan.curves, choices, label, source);
        const bool same = levels.size() == species.levels.size() &&
                          std::equal(levels.begin(), levels.end(), species.levels.begin(),
                                     [](const ForestLevel& a, const ForestLevel& b) {
                                         return sameDrawable(a, b) && a.minPixelCount == b.minPixelCount;
                                     });
        if (same)
        {
            plan.choices = choices;
            updateShadowLevels(s);
            updateOcclusionScales(s);
            return;
        }
        Ogre::AxisAlignedBox drawn = asset.getBounds();
        checkLevels(asset, levels, label, source, drawn);

        // Parts: the last level first (its failure changes nothing); then kept, rebuilt or absent.
        const std::size_t count = levels.size();
        std::vector<std::vector<std::unique_ptr<Part>>> parts(count);
        std::vector<Residency> residency(count, Residency::Absent);
        std::vector<bool> moved(species.levels.size(), false);
        // An old resident level drawing what level l draws: with the same switch value and parts not
        // taken yet (they are kept), or any (its drawables are uploaded).
        auto findOld = [&](std::size_t l, bool sameUpper) -> int {
            for (std::size_t k = 0; k < species.levels.size(); ++k)
                if (!(sameUpper && moved[k]) && species.residency[k] == Residency::Resident &&
                    sameDrawable(species.levels[k], levels[l]) &&
                    (!sameUpper || upperValue(species.levels, k) == upperValue(levels, l)))
                    return int(k);
            return -1;
        };
        if (findOld(count - 1, true) < 0)
        {
            try
            {
                parts[count - 1] = buildParts(asset, levels[count - 1], upperValue(levels, count - 1));
            }
            catch (const Ogre::Exception& e)
            {
                invalid(label + "level " + std::to_string(count - 1) + " '" + levels[count - 1].technique +
                            "': " + e.getDescription() + " (the levels stay as they were)",
                        source);
            }
            residency[count - 1] = Residency::Resident;
        }
        for (std::size_t l = 0; l < count; ++l)
        {
            if (residency[l] == Residency::Resident)
                continue;
            if (const int k = findOld(l, true); k >= 0)
            {
                parts[l] = std::move(species.parts[std::size_t(k)]);
                moved[std::size_t(k)] = true;
                residency[l] = Residency::Resident;
            }
            else if (findOld(l, false) >= 0)
            {
                // Its drawables are uploaded: the parts at the new switch value cost no upload.
                try
                {
                    parts[l] = buildParts(asset, levels[l], upperValue(levels, l));
                    residency[l] = Residency::Resident;
                }
                catch (const Ogre::Exception&)
                {
                    residency[l] = Residency::Absent; // built on demand, where a failure is logged
                }
            }
        }

        // The kind's table; each camera's buckets of this species reset (their batches draw the
        // old parts), the buckets of later species moved with their indices.
        const std::uint32_t first = mInstances.getBucketIndex(s, 0);
        const std::size_t oldCount = species.levels.size();
        if (Result<void> set = mInstances.setKindThresholds(s, kindThresholds(species, levels), kindHardSwitches(species, levels));
            !set)
            invalid(label + set.error().message(), source);
        for (auto& [camera, state] : mCameras)
        {
            std::vector<std::unique_ptr<BucketState>>& buckets = state->buckets;
            if (buckets.size() <= first)
                continue; // has not seen this species yet
            const std::size_t end = std::min(buckets.size(), first + oldCount);
            std::vector<std::unique_ptr<BucketState>> slots;
            for (std::size_t b = first; b < end; ++b)
                slots.push_back(std::move(buckets[b]));
            for (std::unique_ptr<BucketState>& slot : slots)
            {
                slot->batches.clear();
                slot->drawnLevel = NO_LEVEL;
            }
            while (slots.size() > count)
            {
                mInstanceBufferBytes -= slots.back()->capacity * INSTANCE_BYTES;
                slots.pop_back();
            }
            while (slots.size() < count)
                slots.push_back(std::make_unique<BucketState>());
            buckets.erase(buckets.begin() + std::ptrdiff_t(first), buckets.begin() + std::ptrdiff_t(end));
            buckets.insert(buckets.begin() + std::ptrdiff_t(first), std::make_move_iterator(slots.begin()),
                           std::make_move_iterator(slots.end()));
        }
        mUploadQueue.erase(std::remove_if(mUploadQueue.begin(), mUploadQueue.end(),
                                          [s](const auto& entry) { return entry.first == s; }),
                           mUploadQueue.end());
        species.levels = levels;
        species.parts = std::move(parts);
        species.residency = std::move(residency);
        plan.choices = choices;
        mStats.levelCounts[s].assign(count, 0u);
        mStats.instanceBufferBytes = mInstanceBufferBytes;
        updateShadowLevels(s);
        updateOcclusionScales(s);
    }

    const char* toString(ForestBinding binding)
    {
        switch (binding)
        {
        case ForestBinding::Frame:
            return "frame";
        case ForestBinding::Memory:
            return "memory";
        case ForestBinding::Error:
            break;
        }
        return "error";
    }

    ForestBinding Forest::getBindingBudget() const
    {
        if (mMemoryBinds)
            return ForestBinding::Memory;
        if (mBudget.getFrameBudgetMs() > 0.0f && mBudget.getErrorBudget() != mBudget.getUserErrorBudget())
            return ForestBinding::Frame;
        return ForestBinding::Error;
    }

    MemoryPlan Forest::memoryPlan(const BudgetPlan* extra, const TreeAsset* extraAsset, float errorBudget,
                                  std::uint64_t memoryBudget, const char* source) const
    {
        std::vector<MemoryPlanSpecies> species;
        std::vector<std::uint32_t> indices; // the Forest's species index of each entry
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            if (const BudgetPlan* plan = mSpecies[s]->budget.get())
            {
                species.push_back(MemoryPlanSpecies{&plan->curves, &plan->costs, plan->visible.counts,
                                                    mSpecies[s]->asset.get()});
                indices.push_back(s);
            }
        if (extra)
        {
            species.push_back(MemoryPlanSpecies{&extra->curves, &extra->costs, {}, extraAsset});
            indices.push_back(std::uint32_t(mSpecies.size()));
        }
        Result<MemoryPlan> plan = chooseLevelsWithinMemory(species, errorBudget, memoryBudget, MAX_LEVELS);
        if (!plan)
        {
            // The planner counts its own species; the Forest's are named.
            Error error = plan.error();
            const std::string prefix = "species ";
            if (error.element.rfind(prefix, 0) == 0)
            {
                const std::size_t entry = std::size_t(std::stoul(error.element.substr(prefix.size())));
                if (entry < indices.size())
                {
                    const std::uint32_t s = indices[entry];
                    error.element = speciesLabel(s, s < mSpecies.size() ? mSpecies[s]->asset.get() : extraAsset) +
                                    error.element.substr(error.element.find_first_not_of("0123456789", prefix.size()));
                }
            }
            invalid("Forest '" + mName + "': " + error.message(), source);
        }
        return std::move(*plan);
    }

    void Forest::applyMemoryPlan(const MemoryPlan& plan)
    {
        std::size_t entry = 0;
        for (const std::unique_ptr<Species>& species : mSpecies)
        {
            BudgetPlan* budget = species->budget.get();
            if (!budget)
                continue;
            // Under a memory budget the levels outside the plan stay out at every step of the
            // frame budget, so that its moves never hold more than the plan.
            budget->excluded.assign(budget->curves.levels.size(), mMemoryBudget > 0);
            for (const LevelChoice& choice : plan.choices.at(entry))
                budget->excluded[choice.curveLevel] = false;
            budget->ladderChoices.clear();
            for (const float step : frameBudgetLadder())
            {
                Result<std::vector<LevelChoice>> choices = chooseLevels(
                    budget->curves, budget->costs, step, MAX_LEVELS, LEVEL_SWITCH_COST_SLACK, budget->excluded);
                budget->ladderChoices.push_back(choices ? std::move(*choices) : plan.choices.at(entry));
            }
            ++entry;
        }
        mMemoryBinds = plan.memoryBinds;
        applyErrorBudget(mBudget.getErrorBudget());
    }

    void Forest::setMemoryBudget(std::uint64_t bytes)
    {
        const MemoryPlan plan =
            memoryPlan(nullptr, nullptr, mBudget.getUserErrorBudget(), bytes, "Forest::setMemoryBudget");
        mMemoryBudget = bytes;
        applyMemoryPlan(plan);
    }

    void Forest::updatePlannedGpuBytes()
    {
        std::vector<MemoryPlanSpecies> planned;
        std::vector<std::vector<LevelChoice>> plans;
        for (const std::unique_ptr<Species>& species : mSpecies)
            if (const BudgetPlan* plan = species->budget.get())
            {
                planned.push_back(MemoryPlanSpecies{&plan->curves, &plan->costs, {}, species->asset.get()});
                plans.push_back(plan->choices);
            }
        mStats.plannedGpuBytes = planGpuBytes(planned, plans);
    }

    void Forest::applyErrorBudget(float budget)
    {
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
        {
            Species& species = *mSpecies[s];
            if (!species.budget)
                continue;
            Result<std::vector<LevelChoice>> choices =
                chooseLevels(species.budget->curves, species.budget->costs, budget, MAX_LEVELS,
                             LEVEL_SWITCH_COST_SLACK, species.budget->excluded);
            if (!choices)
                invalid("Forest '" + mName + "' species " + std::to_string(s) + ": " + choices.error().message(),
                        "Forest::setErrorBudget");
            species.budget->errorBudget = budget;
            replan(s, *choices);
        }
        updatePlannedGpuBytes();
        mBudget.setErrorBudgetInUse(budget);
    }

    void Forest::setErrorBudget(float budget)
    {
        if (!(std::isfinite(budget) && budget >= 0.0f && budget <= 1.0f))
            invalid("Forest '" + mName + "': error budget " + std::to_string(budget) + " is not a number in [0, 1]",
                    "Forest::setErrorBudget");
        if (mMemoryBudget > 0)
        {
            // The levels the memory budget leaves depend on the error budget they are planned for.
            const MemoryPlan plan = memoryPlan(nullptr, nullptr, budget, mMemoryBudget, "Forest::setErrorBudget");
            mBudget.setErrorBudget(budget);
            applyMemoryPlan(plan);
            return;
        }
        applyErrorBudget(budget);
        mBudget.setErrorBudget(budget);
    }

    void Forest::setShadowErrorBudget(float budget)
    {
        if (!(std::isfinite(budget) && budget >= 0.0f && budget <= 1.0f))
            invalid("Forest '" + mName + "': shadow error budget " + std::to_string(budget) +
                        " is not a number in [0, 1]",
                    "Forest::setShadowErrorBudget");
        mShadowErrorBudget = budget;
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            updateShadowLevels(s);
    }

    void Forest::setFrameBudgetMs(float milliseconds)
    {
        if (!(std::isfinite(milliseconds) && milliseconds >= 0.0f))
            invalid("Forest '" + mName + "': frame budget " + std::to_string(milliseconds) +
                        " ms is not finite and >= 0 (0: none)",
                    "Forest::setFrameBudgetMs");
        mStats.predictedMilliseconds = 0.0;
        if (mBudget.setFrameBudgetMs(milliseconds))
            setErrorBudget(mBudget.getUserErrorBudget()); // switched off: the user's budget again
    }

    void Forest::measureFrameBudget(const CameraState& state)
    {
        // Every visible tree of a budgeted species, counted at its height on screen.
        bool anyBudgeted = false;
        for (const std::unique_ptr<Species>& species : mSpecies)
            if (species->budget)
            {
                species->budget->visible.clear();
                anyBudgeted = true;
            }
        if (!anyBudgeted)
            return; // nothing to plan: the error budget stays
        const ForestVisibility& visibility = state.visibility;
        for (std::uint32_t b = 0; b < visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = visibility.getBucket(b);
            Species& species = *mSpecies[bucket.kind];
            if (!species.budget || bucket.count == 0)
                continue;
            const std::uint32_t* indices = visibility.getBucketIndices(b);
            for (std::uint32_t i = 0; i < bucket.count; ++i)
            {
                const float value = mInstances.lodValue(indices[i], state.camera, state.lodBias);
                species.budget->visible.add(float(species.heightPerRootValue * std::sqrt(double(value))));
            }
        }
        const std::size_t steps = frameBudgetLadder().size();
        std::vector<double> predicted(steps, 0.0);
        for (const std::unique_ptr<Species>& species : mSpecies)
            if (const BudgetPlan* plan = species->budget.get())
                for (std::size_t step = 0; step < steps; ++step)
                    predicted[step] += plan->visible.milliseconds(
                        planCostPerTree(plan->curves, plan->costs, plan->ladderChoices[step], mLodTransition,
                                        mLodTransitionMinHeight));
        mStats.predictedMilliseconds = mBudget.measure(std::move(predicted)); // scaled by the reported frames
    }

    void Forest::notifyFrameTime(float milliseconds) { mBudget.notifyFrameTime(milliseconds); }
}
