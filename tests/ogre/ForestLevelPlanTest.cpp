// The Forest's level plans through Plugin_TreeLod: levels from bands along the techniques' curves,
// error curves against the CPU reference (and the switch FLIP between levels; curves of version 1
// read and measured again), calibration per renderer, the cheapest level within an
// error budget, and budgeted species replanned in place for an error, a frame and a shadow budget.
#include "ForestTestSupport.h"

namespace TreeLod
{
    TEST(Forest, levelsForBandsFollowTheTechniquesCurves)
    {
        const ForestTree& tree = oak();
        TreeAsset& asset = *tree.asset;
        const std::vector<ForestLevel> levels = Forest::levelsForBands(asset, Forest::getAutoBands());
        ASSERT_GE(levels.size(), 3u);
        for (std::size_t l = 1; l < levels.size(); ++l)
            EXPECT_LT(levels[l].minPixelCount, levels[l - 1].minPixelCount);
        EXPECT_EQ(levels.back().minPixelCount, 0.0f);
        EXPECT_EQ(levels.back().technique, "impostor");
        EXPECT_EQ(levels.front().technique, "lodf");
        EXPECT_EQ(levels.front().techniqueLevel, FoliageLodResources::of(asset).getFoliageLod().maxLeafCount());

        // Band edges: a tree h_px tall has r_px = h_px * R / h, value 4 pi r_px^2.
        const Ogre::AxisAlignedBox bounds = asset.getBounds();
        const double radius = Ogre::Math::boundingRadiusFromAABB(bounds);
        const double height = bounds.getMaximum().y - bounds.getMinimum().y;
        auto value = [&](double pixels) {
            const double r = pixels * radius / height;
            return 4.0 * Ogre::Math::PI * r * r;
        };
        std::size_t lastLodf = 0, lastCloud = 0;
        for (std::size_t l = 0; l < levels.size(); ++l)
        {
            if (levels[l].technique == "lodf")
                lastLodf = l;
            if (levels[l].technique == "billboard-cloud")
                lastCloud = l;
        }
        EXPECT_NEAR(levels[lastLodf].minPixelCount, value(160.0), 1e-3 * value(160.0));
        EXPECT_NEAR(levels[lastCloud].minPixelCount, value(24.0), 1e-3 * value(24.0));
        // A level repeated with the same drawable: split where its bark mesh's LoD switches.
        auto isBarkSwitch = [](const Ogre::MeshPtr& bark, Ogre::Real value) {
            for (unsigned short i = 1; i < bark->getNumLodLevels(); ++i)
                if (bark->getLodLevel(i).value == value)
                    return true;
            return false;
        };
        auto same = [](const ForestLevel& a, const ForestLevel& b) {
            return a.technique == b.technique && a.techniqueLevel == b.techniqueLevel && a.lowRes == b.lowRes;
        };
        std::size_t barkSplits = 0;
        // lodf: halving counts, each kept while FoliageLodTree's curve asks for more than the next.
        for (std::size_t l = 0; l < lastLodf; ++l)
        {
            if (same(levels[l], levels[l + 1]))
            {
                EXPECT_TRUE(isBarkSwitch(asset.getBarkMesh(), levels[l].minPixelCount)) << "level " << l;
                ++barkSplits;
                continue;
            }
            EXPECT_EQ(levels[l + 1].techniqueLevel, (levels[l].techniqueLevel + 1) / 2);
            EXPECT_FLOAT_EQ(levels[l].minPixelCount,
                            FoliageLodTree::pixelCountForLeaves(levels[l + 1].techniqueLevel,
                                                                FoliageLodTree::DEFAULT_PIXELS_PER_LEAF));
        }
        // Billboard cloud: BillboardCloudTree's switches (in the same units) inside the band.
        const BillboardCloudGpu& gpu = BillboardCloudResources::of(asset, false).getGpu();
        const std::vector<Ogre::Real> switches =
            BillboardCloudTree::switchPixelCounts(gpu, gpu.listFactor, float(radius));
        for (std::size_t l = lastLodf + 1; l < lastCloud; ++l)
        {
            const ForestLevel& level = levels[l];
            const ForestLevel& next = levels[l + 1];
            if (same(level, next))
            {
                EXPECT_TRUE(isBarkSwitch(BillboardCloudResources::of(asset, false).getBarkAoMesh(), level.minPixelCount)) << "level " << l;
                ++barkSplits;
            }
            else if (next.techniqueLevel == level.techniqueLevel)
                EXPECT_TRUE(!level.lowRes && next.lowRes) << "a layered level, then its low-res technique";
            else
                EXPECT_FLOAT_EQ(level.minPixelCount, switches.at(level.techniqueLevel));
        }
        EXPECT_GT(barkSplits, 0u) << "the bark's LoD switches inside the billboard-cloud band";
        std::printf("auto levels of oak:");
        for (const ForestLevel& level : levels)
            std::printf(" %s/%u%s>=%.0f", level.technique.c_str(), level.techniqueLevel, level.lowRes ? "lowres" : "",
                        level.minPixelCount);
        std::printf("\n");

        // A single band: the technique's own levels from the finest to 0.
        const std::vector<ForestLevel> lodf = Forest::levelsForBands(asset, {{"lodf", 0.0f}});
        EXPECT_EQ(lodf.back().techniqueLevel, FoliageLodResources::of(asset).getFoliageLod().minLeafCount());
        const std::vector<ForestLevel> mesh = Forest::levelsForBands(asset, {{"mesh", 0.0f}});
        const Ogre::MeshPtr reference = asset.getReferenceMesh();
        ASSERT_EQ(mesh.size(), std::size_t(reference->getNumLodLevels()));
        for (std::size_t l = 0; l + 1 < mesh.size(); ++l)
        {
            EXPECT_EQ(mesh[l].technique, "mesh");
            EXPECT_EQ(mesh[l].minPixelCount, reference->getLodLevel(std::uint16_t(l + 1)).value);
        }
    }

    namespace
    {
        /// Few heights and views: the curves of the oak's levels in seconds.
        ErrorCurveOptions smallCurveOptions()
        {
            ErrorCurveOptions o;
            o.heightsPx = {16.0f, 64.0f, 192.0f};
            o.views = {{0.0f, 10.0f}, {100.0f, 45.0f}};
            o.referenceSupersample = 2;
            return o;
        }

        /// The oak's package with its error curves (smallCurveOptions), loaded as "oak.budget-test".
        TreeAssetPtr oakWithCurves()
        {
            return OgreEnvironment::keep<TreeAssetPtr>("forest.oak-curves", [] {
                const ForestTree& tree = oak();
                const std::vector<std::uint8_t> bytes = cachedPackage("forest", "oak-curves", [&] {
                    Result<std::vector<std::uint8_t>> with = addErrorCurves(
                        OgreEnvironment::renderer(), cachedPackage("forest", "oak", [&] { return bakePackage(tree.model, "oak"); }),
                        "oak", smallCurveOptions());
                    EXPECT_TRUE(with.ok()) << (with.ok() ? "" : with.error().message());
                    return with.ok() ? with.value() : std::vector<std::uint8_t>{};
                });
                return TreeAssetManager::getSingleton().loadFromBytes("oak.budget-test", Ogre::RGN_DEFAULT, bytes);
            });
        }

        /// Costs fixed here, not calibrated, so that the levels (and the golden) do not follow the
        /// machine's noise: the mesh dearest, lodf by its leaves, clouds cheap, the impostor nearly free.
        std::vector<LevelCost> fixedCosts(TreeAsset& asset)
        {
            std::vector<LevelCost> costs;
            for (const ForestLevel& level : Forest::getCandidateLevels(asset))
            {
                LevelCost c;
                c.technique = level.technique;
                c.techniqueLevel = level.techniqueLevel;
                c.lowRes = level.lowRes;
                c.heightsPx = {16.0f, 256.0f};
                const float base = level.technique == "mesh"              ? 2.0f
                                   : level.technique == "lodf"            ? 0.2f + 1.5e-4f * float(level.techniqueLevel)
                                   : level.technique == "billboard-cloud" ? 0.3f - 0.1f * float(level.techniqueLevel)
                                                                          : 0.005f;
                c.msPerTree = {base, 16.0f * base};
                costs.push_back(c);
            }
            return costs;
        }
    }

    TEST(Forest, errorCurvesRankTheLevelsAgainstTheCpuReference)
    {
        const TreeAssetPtr asset = oakWithCurves();
        ASSERT_TRUE(asset->hasChunk(ERROR_CURVES_CHUNK));
        Result<ErrorCurves> curves = decodeErrorCurves(asset->readChunk(ERROR_CURVES_CHUNK), "oak");
        ASSERT_TRUE(curves) << curves.error().message();
        EXPECT_TRUE(coversCandidateLevels(*curves, *asset, smallCurveOptions()));
        EXPECT_EQ(curves->levels.size(), Forest::getCandidateLevels(*asset).size());
        const int mesh = curves->find("mesh", 0, false), quad = curves->find("impostor", 0, false);
        ASSERT_GE(mesh, 0);
        ASSERT_GE(quad, 0);
        int fullLodf = -1;
        for (std::size_t l = 0; l < curves->levels.size(); ++l)
            if (curves->levels[l].technique == "lodf" &&
                (fullLodf < 0 || curves->levels[l].techniqueLevel > curves->levels[std::size_t(fullLodf)].techniqueLevel))
                fullLodf = int(l);
        ASSERT_GE(fullLodf, 0);
        for (std::size_t h = 0; h < curves->heightsPx.size(); ++h)
        {
            const float m = curves->levels[std::size_t(mesh)].flip[h];
            std::printf("%5.0f px: mesh %.4f, lodf (all leaves) %.4f, impostor %.4f\n", double(curves->heightsPx[h]),
                        double(m), double(curves->levels[std::size_t(fullLodf)].flip[h]),
                        double(curves->levels[std::size_t(quad)].flip[h]));
            // The GPU's mesh against the CPU's: the same tree, one sample a pixel against four, over
            // the tree's own pixels (0.23 at 16 px, where most of them are edges; 0.15 at 192 px).
            EXPECT_GT(m, 0.0f);
            EXPECT_LT(m, 0.3f);
            // LoDF with every leaf draws what the mesh draws.
            EXPECT_NEAR(curves->levels[std::size_t(fullLodf)].flip[h], m, 0.01f);
        }
        // Close up, one quad is far from the tree; every curve's worst view is at least its mean.
        EXPECT_GT(curves->levels[std::size_t(quad)].flip.back(), curves->levels[std::size_t(mesh)].flip.back() + 0.05f);
        for (const ErrorCurveLevel& level : curves->levels)
            for (std::size_t h = 0; h < level.flip.size(); ++h)
                EXPECT_GE(level.flipMax[h], level.flip[h]);

        // What a switch shows: from the mesh to LoDF with every leaf (which draws what the mesh
        // draws) about nothing, from the mesh to one quad much, at every height.
        ASSERT_TRUE(curves->hasSwitchFlip());
        for (const float h : curves->heightsPx)
        {
            const float same = curves->switchFlipAt(std::size_t(mesh), std::size_t(fullLodf), h);
            const float quadSwitch = curves->switchFlipAt(std::size_t(mesh), std::size_t(quad), h);
            std::printf("%5.0f px: switch mesh-lodf (all leaves) %.4f, mesh-impostor %.4f\n", double(h), double(same),
                        double(quadSwitch));
            EXPECT_LT(same, 0.01f) << h;
            EXPECT_GT(quadSwitch, 0.1f) << h;
        }
        // Along LoDF's ladder a halving shows less than going from every leaf to the fewest.
        std::vector<std::size_t> lodf; // finest first
        for (std::size_t l = 0; l < curves->levels.size(); ++l)
            if (curves->levels[l].technique == "lodf")
                lodf.push_back(l);
        std::sort(lodf.begin(), lodf.end(), [&](std::size_t a, std::size_t b) {
            return curves->levels[a].techniqueLevel > curves->levels[b].techniqueLevel;
        });
        ASSERT_GE(lodf.size(), 3u);
        for (const float h : curves->heightsPx)
            EXPECT_LT(curves->switchFlipAt(lodf[lodf.size() - 2], lodf.back(), h),
                      curves->switchFlipAt(lodf.front(), lodf.back(), h))
                << h;

        // The chunk is added once: a package that holds curves covering its levels is not measured again.
        const std::string path = OgreEnvironment::outDir() + "/oak-curves.treelod";
        const std::vector<std::uint8_t> bytes = cachedPackage("forest", "oak-curves", [] {
            ADD_FAILURE() << "oakWithCurves() cached the package";
            return std::vector<std::uint8_t>{};
        });
        ASSERT_TRUE(writeFileAtomic(path, bytes));
        Result<bool> again = ensureErrorCurves(OgreEnvironment::renderer(), path, smallCurveOptions());
        ASSERT_TRUE(again) << again.error().message();
        EXPECT_FALSE(*again);
        EXPECT_EQ(readFile(path).value(), bytes);
        // Other heights: measured again, the other chunks' bytes unchanged.
        ErrorCurveOptions other = smallCurveOptions();
        other.heightsPx = {32.0f};
        again = ensureErrorCurves(OgreEnvironment::renderer(), path, other);
        ASSERT_TRUE(again) << again.error().message();
        EXPECT_TRUE(*again);
        Result<PackageReader> rewritten = PackageReader::open(path);
        ASSERT_TRUE(rewritten);
        for (const ChunkInfo& info : asset->getPackage().chunks())
        {
            if (info.technique == ERROR_CURVES_CHUNK)
                continue;
            EXPECT_EQ(rewritten->readChunk(info.technique, info.level).value(),
                      asset->getPackage().readChunk(info.technique, info.level).value())
                << info.element();
        }
        Result<ErrorCurves> remeasured = decodeErrorCurves(rewritten->readChunk(ERROR_CURVES_CHUNK, 0).value(), path);
        ASSERT_TRUE(remeasured);
        EXPECT_EQ(remeasured->heightsPx, other.heightsPx);
    }

    TEST(Forest, errorCurvesOfVersionOneAreReadAndMeasuredAgain)
    {
        // The oak's package with its curves written as version 1 wrote them: without switch FLIP
        // and GPU bytes (version 3's layout less its last two u32, 0 pairs and 0 resources).
        const TreeAssetPtr asset = oakWithCurves();
        Result<ErrorCurves> curves = decodeErrorCurves(asset->readChunk(ERROR_CURVES_CHUNK), "oak");
        ASSERT_TRUE(curves) << curves.error().message();
        EXPECT_TRUE(curves->hasGpuBytes());
        curves->switchFlip.clear();
        curves->resourceBytes.clear();
        for (ErrorCurveLevel& level : curves->levels)
            level.resources.clear();
        std::vector<std::uint8_t> v1 = encodeErrorCurves(*curves);
        v1.resize(v1.size() - 8);
        PackageWriter writer;
        for (const ChunkInfo& info : asset->getPackage().chunks())
        {
            if (info.technique != ERROR_CURVES_CHUNK)
            {
                ASSERT_TRUE(writer.addChunk(info.technique, info.level, info.formatVersion,
                                            asset->getPackage().readChunk(info.technique, info.level).value()));
            }
        }
        // A version this build does not read: refused, naming both.
        ASSERT_TRUE(writer.addChunk(ERROR_CURVES_CHUNK, 0, 4, v1));
        Result<std::vector<std::uint8_t>> newer = writer.toBytes();
        ASSERT_TRUE(newer) << newer.error().message();
        TreeAssetPtr future =
            TreeAssetManager::getSingleton().loadFromBytes("oak.v4-curves", Ogre::RGN_DEFAULT, *newer);
        try
        {
            future->readChunk(ERROR_CURVES_CHUNK);
            ADD_FAILURE() << "a chunk of version 4 was read";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("format version 4, this build reads 1..3"), std::string::npos)
                << e.getDescription();
        }
        TreeAssetManager::getSingleton().remove(future);

        ASSERT_TRUE(writer.addChunk(ERROR_CURVES_CHUNK, 0, 1, v1));
        Result<std::vector<std::uint8_t>> bytes = writer.toBytes();
        ASSERT_TRUE(bytes) << bytes.error().message();

        // Loaded: the chunk is read, the curves have no switch FLIP, and they do not cover the levels.
        TreeAssetPtr old = TreeAssetManager::getSingleton().loadFromBytes("oak.v1-curves", Ogre::RGN_DEFAULT, *bytes);
        EXPECT_EQ(old->getChunkFormatVersion(ERROR_CURVES_CHUNK), 1u);
        Result<ErrorCurves> read = decodeErrorCurves(old->readChunk(ERROR_CURVES_CHUNK), "oak",
                                                     old->getChunkFormatVersion(ERROR_CURVES_CHUNK));
        ASSERT_TRUE(read) << read.error().message();
        EXPECT_EQ(read->levels.size(), curves->levels.size());
        EXPECT_FALSE(read->hasSwitchFlip());
        EXPECT_FALSE(coversCandidateLevels(*read, *old, smallCurveOptions()));
        // Budgeted auto still plans with them (flip(a) + flip(b) standing in for the switches).
        EXPECT_FALSE(Forest::levelsForErrorBudget(*old, fixedCosts(*old), DEFAULT_ERROR_BUDGET).empty());
        TreeAssetManager::getSingleton().remove(old);

        // The package is measured again, to version 3 with switch FLIP and GPU bytes.
        const std::string path = OgreEnvironment::outDir() + "/oak-v1-curves.treelod";
        ASSERT_TRUE(writeFileAtomic(path, *bytes));
        Result<bool> measured = ensureErrorCurves(OgreEnvironment::renderer(), path, smallCurveOptions());
        ASSERT_TRUE(measured) << measured.error().message();
        EXPECT_TRUE(*measured);
        Result<PackageReader> rewritten = PackageReader::open(path);
        ASSERT_TRUE(rewritten);
        const int chunk = rewritten->findChunk(ERROR_CURVES_CHUNK, 0);
        ASSERT_GE(chunk, 0);
        EXPECT_EQ(rewritten->chunks()[std::size_t(chunk)].formatVersion, ERROR_CURVES_FORMAT_VERSION);
        Result<ErrorCurves> again = decodeErrorCurves(rewritten->readChunk(std::size_t(chunk)).value(), path);
        ASSERT_TRUE(again) << again.error().message();
        EXPECT_TRUE(again->hasSwitchFlip());
        EXPECT_TRUE(again->hasGpuBytes());
    }

    TEST(Forest, calibrationTimesEveryLevelAndIsCachedPerRenderer)
    {
        const TreeAssetPtr asset = oakWithCurves();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        CalibrationOptions options;
        options.heightsPx = {16.0f, 64.0f};
        options.viewport = 128;
        options.frames = 1;
        options.targetFrameMs = 10.0;
        const std::string dir = OgreEnvironment::outDir() + "/calibration";
        std::filesystem::remove_all(dir);
        bool calibrated = false;
        Result<std::vector<LevelCost>> costs = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(costs) << costs.error().message();
        EXPECT_TRUE(calibrated);
        ASSERT_EQ(costs->size(), Forest::getCandidateLevels(*asset, Forest::getAutoTechniques()).size());
        for (const LevelCost& c : *costs)
        {
            ASSERT_EQ(c.msPerTree.size(), 2u) << c.technique;
            for (const float ms : c.msPerTree)
                EXPECT_TRUE(std::isfinite(ms) && ms >= 0.0f) << c.technique;
        }
        // The cache answers the second time, for this renderer only.
        Result<std::vector<LevelCost>> cached = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(cached);
        EXPECT_FALSE(calibrated);
        EXPECT_EQ(cached->front().msPerTree, costs->front().msPerTree);
        const std::string renderer = rendererString(r.getRoot());
        EXPECT_NE(renderer.find("OpenGL"), std::string::npos) << renderer;
        Result<CostCalibration> file = readCostCalibration(costCalibrationPath(dir, renderer), renderer);
        ASSERT_TRUE(file) << file.error().message();
        // The same costs under another renderer's name: not this renderer's, so calibrated again.
        CostCalibration foreign = *file;
        foreign.renderer = "OpenGL 3+ Rendering Subsystem | some GPU | 4.6";
        ASSERT_TRUE(writeCostCalibration(costCalibrationPath(dir, renderer), foreign));
        cached = requireLevelCosts(r, *asset, dir, options, {}, &calibrated);
        ASSERT_TRUE(cached);
        EXPECT_TRUE(calibrated);
    }

    TEST(Forest, anErrorBudgetChoosesTheCheapestLevelWithinIt)
    {
        const TreeAssetPtr asset = oakWithCurves();
        const ForestTree& tree = oak();
        const std::vector<LevelCost> costs = fixedCosts(*asset);

        const std::vector<ForestLevel> reference = Forest::levelsForErrorBudget(*asset, costs, 0.0f);
        ASSERT_EQ(reference.size(), 1u);
        EXPECT_EQ(reference[0].technique, "mesh");
        const std::vector<ForestLevel> cheapest = Forest::levelsForErrorBudget(*asset, costs, 1.0f);
        ASSERT_EQ(cheapest.size(), 1u);
        EXPECT_EQ(cheapest[0].technique, "impostor");
        const std::vector<ForestLevel> budgeted = Forest::levelsForErrorBudget(*asset, costs, 0.03f);
        ASSERT_GE(budgeted.size(), 2u);
        std::string described;
        for (const ForestLevel& level : budgeted)
            described += Forest::describeLevel(level) + " >= " +
                         std::to_string(int(Forest::heightForPixelCount(*asset, level.minPixelCount))) + " px; ";
        std::printf("budget 0.03: %s\n", described.c_str());
        EXPECT_NE(budgeted.front().technique, "impostor") << described;
        EXPECT_EQ(budgeted.back().minPixelCount, 0.0f);

        for (const float bad : {-0.1f, 1.5f, std::nanf("")})
            EXPECT_THROW(Forest::levelsForErrorBudget(*asset, costs, bad), Ogre::InvalidParametersException) << bad;
        try
        {
            Forest::levelsForErrorBudget(*tree.asset, costs, 0.03f);
            ADD_FAILURE() << "an asset without curves was accepted";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("oak.forest-test"), std::string::npos) << e.getDescription();
            EXPECT_NE(e.getDescription().find("no error curves"), std::string::npos) << e.getDescription();
        }

        // Drawn: a grid from near to far, one sample a pixel as the curves measured, against the
        // mesh supersampled 4x4: within the budget of the mesh's own error (and a margin for a
        // whole frame where the curves saw one tree), better than the cheapest, not a black picture.
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.3f * h, 1.4f * h, 7.0f * h), glm::vec3(0.0f, 0.0f, -4.0f * h));
        std::vector<Image> pictures;
        Image supersampled;
        for (const std::vector<ForestLevel>* levels : {&reference, &budgeted, &cheapest})
        {
            Forest* forest = placeForest();
            forest->addSpecies(asset, *levels);
            forest->addInstances(grid(6, 1.6f * h));
            if (levels == &reference)
                supersampled = toImage(r.render(view, 320, 180, 4));
            pictures.push_back(toImage(r.render(view, 320, 180, 1)));
        }
        const double flipMesh = flipMean(supersampled, pictures[0]), flipBudgeted = flipMean(supersampled, pictures[1]),
                     flipCheapest = flipMean(supersampled, pictures[2]);
        std::printf("FLIP against the mesh 4x4: mesh %.4f, budget 0.03 %.4f, budget 1 %.4f\n", flipMesh, flipBudgeted,
                    flipCheapest);
        EXPECT_GT(treeCoverage(pictures[1], BACKGROUND), 0.15);
        EXPECT_LT(flipBudgeted, flipMesh + 0.03 + 0.01);
        EXPECT_LT(flipBudgeted + 0.02, flipCheapest);
        writePng(OgreEnvironment::outDir() + "/forest-budgets.png", sideBySide(pictures));
        compareWithGolden(pictures[1], "forest-budget", 0.03);
    }

    TEST(Forest, budgetedSpeciesReplanInPlaceForAnErrorAFrameAndAShadowBudget)
    {
        const TreeAssetPtr asset = oakWithCurves();
        const ForestTree& tree = oak();
        const std::vector<LevelCost> costs = fixedCosts(*asset);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = treeHeight(tree.model);
        const CameraSpec view = look(glm::vec3(0.3f * h, 1.4f * h, 7.0f * h), glm::vec3(0.0f, 0.0f, -4.0f * h));
        const std::vector<ForestInstance> trees = grid(6, 1.6f * h);
        auto sameLevels = [](const std::vector<ForestLevel>& a, const std::vector<ForestLevel>& b) {
            return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const auto& x, const auto& y) {
                       return x.technique == y.technique && x.techniqueLevel == y.techniqueLevel &&
                              x.lowRes == y.lowRes && x.minPixelCount == y.minPixelCount;
                   });
        };
        const std::vector<ForestLevel> planned = Forest::levelsForErrorBudget(*asset, costs, DEFAULT_ERROR_BUDGET);
        ASSERT_GE(planned.size(), 2u);

        // The same levels added as fixed: the picture a budgeted species must give. A frame budget
        // has nothing to plan there: the error budget stays.
        // Occlusion off in both: it would draw the budgeted species' partly hidden trees coarser
        // than the fixed levels (ForestOcclusion tests that).
        Forest* fixed = placeForest();
        fixed->setOcclusion(false);
        fixed->addSpecies(asset, planned);
        fixed->addInstances(trees);
        EXPECT_FALSE(fixed->isBudgeted(0));
        EXPECT_EQ(fixed->getShadowLevels(0).size(), planned.size());
        const Image expected = toImage(r.render(view, 320, 180, 1));
        fixed->setFrameBudgetMs(1e-6f);
        r.render(view, 320, 180, 1);
        r.render(view, 320, 180, 1);
        EXPECT_EQ(fixed->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(fixed->getLevels(0), planned));

        Forest* forest = placeForest();
        forest->setOcclusion(false);
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_EQ(forest->getShadowErrorBudget(), DEFAULT_SHADOW_ERROR_BUDGET);
        try
        {
            forest->addBudgetedSpecies(tree.asset, costs);
            ADD_FAILURE() << "an asset without curves was accepted";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("no error curves"), std::string::npos) << e.getDescription();
        }
        EXPECT_EQ(forest->getSpeciesCount(), 0u) << "nothing added";
        const std::uint32_t s = forest->addBudgetedSpecies(asset, costs);
        EXPECT_TRUE(forest->isBudgeted(s));
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));
        forest->addInstances(trees);
        const Image first = toImage(r.render(view, 320, 180, 1));
        const std::vector<std::uint32_t> firstCounts = forest->getStats().levelCounts.at(s);
        // Not bit-identical in general: passes of one hash are ordered by address in Ogre's queue, and
        // the order decides ties of equal depth; a level drawn wrong differs by 100 times more.
        EXPECT_LT(flipMean(expected, first), 2e-4);
        EXPECT_GT(treeCoverage(first, BACKGROUND), 0.15);

        // 0: the reference everywhere; 1: the cheapest everywhere; back: the first picture again.
        forest->setErrorBudget(0.0f);
        ASSERT_EQ(forest->getLevels(s).size(), 1u);
        EXPECT_EQ(forest->getLevels(s)[0].technique, "mesh");
        const Image reference = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), (std::vector<std::uint32_t>{forest->getStats().visibleInstances}));
        forest->setErrorBudget(1.0f);
        ASSERT_EQ(forest->getLevels(s).size(), 1u);
        EXPECT_EQ(forest->getLevels(s)[0].technique, "impostor");
        const Image cheapest = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), (std::vector<std::uint32_t>{forest->getStats().visibleInstances}));
        forest->setErrorBudget(DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));
        const Image again = toImage(r.render(view, 320, 180, 1));
        EXPECT_EQ(forest->getStats().levelCounts.at(s), firstCounts);
        EXPECT_LT(flipMean(expected, again), 2e-4) << "levels, buckets and hysteresis as a new Forest's";
        EXPECT_GT(flipMean(reference, cheapest), 0.02);
        writePng(OgreEnvironment::outDir() + "/forest-replanned.png", sideBySide({reference, again, cheapest}));

        for (const float bad : {std::nanf(""), -0.1f, 1.5f})
        {
            EXPECT_THROW(forest->setErrorBudget(bad), Ogre::InvalidParametersException) << bad;
            EXPECT_THROW(forest->setShadowErrorBudget(bad), Ogre::InvalidParametersException) << bad;
        }
        for (const float bad : {std::nanf(""), -1.0f, INFINITY})
            EXPECT_THROW(forest->setFrameBudgetMs(bad), Ogre::InvalidParametersException) << bad;
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET) << "refused budgets change nothing";

        // A frame budget nothing fits: the cheapest step, taken the viewer frame after a measurement.
        forest->setFrameBudgetMs(1e-6f);
        r.render(view, 160, 90, 1);
        EXPECT_GT(forest->getStats().predictedMilliseconds, 0.0);
        r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), frameBudgetLadder().back());
        EXPECT_EQ(forest->getLevels(s).back().technique, "impostor");
        // One everything fits: the reference; its prediction, the mesh's fixed cost (2 ms at 16 px,
        // growing with the height) summed over the 36 trees.
        forest->setFrameBudgetMs(1e6f);
        for (unsigned f = 0; f < Forest::FRAME_BUDGET_INTERVAL + 2; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), 0.0f);
        EXPECT_EQ(forest->getLevels(s).size(), 1u);
        const double meshMs = forest->getStats().predictedMilliseconds;
        EXPECT_GT(meshMs, 36.0 * 2.0);
        EXPECT_LT(meshMs, 36.0 * 64.0);
        // Measured frames reported at 4x the model: the controller scales its predictions by the
        // running ratio and leaves the reference, which the model alone keeps.
        forest->setFrameBudgetMs(float(2.0 * meshMs));
        for (unsigned f = 0; f < Forest::FRAME_BUDGET_INTERVAL + 2; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_EQ(forest->getErrorBudget(), 0.0f) << "the model alone: the reference fits";
        EXPECT_EQ(forest->getFrameTimeRatio(), 1.0);
        for (unsigned f = 0; f < 3 * Forest::FRAME_BUDGET_INTERVAL + 1; ++f)
        {
            r.render(view, 160, 90, 1);
            forest->notifyFrameTime(float(4.0 * meshMs));
            forest->notifyFrameTime(std::nanf("")); // ignored
        }
        EXPECT_GT(forest->getFrameTimeRatio(), 1.5);
        EXPECT_GT(forest->getErrorBudget(), 0.0f) << "measured frames 4x the model: a coarser step";
        // Half of that: a step predicted within it, coarser than the reference.
        forest->setFrameBudgetMs(float(0.5 * meshMs));
        for (unsigned f = 0; f < 2 * Forest::FRAME_BUDGET_INTERVAL + 1; ++f)
            r.render(view, 160, 90, 1);
        EXPECT_GT(forest->getErrorBudget(), 0.0f);
        EXPECT_LE(forest->getStats().predictedMilliseconds, 0.5 * meshMs);
        // Off: the error budget set last.
        forest->setFrameBudgetMs(0.0f);
        EXPECT_EQ(forest->getErrorBudget(), DEFAULT_ERROR_BUDGET);
        EXPECT_TRUE(sameLevels(forest->getLevels(s), planned));

        // Shadow casters: their own budget picks coarser levels for them; the view keeps its own.
        forest->setShadowErrorBudget(1.0f);
        const std::uint32_t last = std::uint32_t(planned.size() - 1);
        EXPECT_EQ(forest->getShadowLevels(s), std::vector<std::uint32_t>(planned.size(), last));
        r.setShadows(true, 1024);
        const Image coarseCasters = toImage(r.render(view, 320, 180, 1));
        const std::vector<std::uint32_t> viewCounts = forest->getStats().levelCounts.at(s);
        forest->setShadowErrorBudget(0.0f);
        for (std::uint32_t l = 0; l < planned.size(); ++l)
            EXPECT_GE(forest->getShadowLevels(s)[l], l) << "never finer than the view";
        const Image viewCasters = toImage(r.render(view, 320, 180, 1));
        const Image viewCastersAgain = toImage(r.render(view, 320, 180, 1));
        // Re-planned while the shadow camera has buckets of its own: they move with the view's.
        forest->setErrorBudget(0.05f);
        const Image coarserView = toImage(r.render(view, 320, 180, 1));
        forest->setErrorBudget(DEFAULT_ERROR_BUDGET);
        const Image replannedCasters = toImage(r.render(view, 320, 180, 1));
        EXPECT_LT(flipMean(viewCasters, replannedCasters), 2e-4);
        EXPECT_GT(treeCoverage(coarserView, BACKGROUND), 0.15);
        r.setShadows(false);
        EXPECT_EQ(forest->getStats().levelCounts.at(s), viewCounts);
        const double noise = flipMean(viewCasters, viewCastersAgain), casters = flipMean(viewCasters, coarseCasters);
        std::printf("shadow error budget 1 vs 0: FLIP %.5f (the same frame twice: %.5f)\n", casters, noise);
        EXPECT_GT(casters, 0.002);
        EXPECT_GT(casters, 5.0 * noise);
        EXPECT_GT(treeCoverage(coarseCasters, BACKGROUND), 0.15);
        writePng(OgreEnvironment::outDir() + "/forest-shadow-budget.png", sideBySide({viewCasters, coarseCasters}));
        // Bound under half the casters' difference: the view's casters in their place fail it.
        compareWithGolden(coarseCasters, "forest-shadow-budget", 0.005);

        // A frame budget on a Forest whose error budget is off the ladder (never set: the default
        // is on it; 0.045 is not): the controller's first choice is taken.
        for (const float start : {-1.0f, 0.045f})
        {
            Forest* other = placeForest();
            if (start >= 0.0f)
                other->setErrorBudget(start);
            other->addBudgetedSpecies(asset, costs);
            other->addInstances(trees);
            other->setFrameBudgetMs(1e6f);
            r.render(view, 160, 90, 1);
            r.render(view, 160, 90, 1);
            EXPECT_EQ(other->getErrorBudget(), 0.0f) << "start " << start;
        }
    }
}

namespace TreeLod
{
    namespace
    {
        /// Bytes Ogre's managers hold, counted from their own objects: every loaded texture's pixel
        /// buffers (all faces and mips) and every hardware vertex and index buffer.
        struct BufferLists : Ogre::HardwareBufferManagerBase
        {
            static std::uint64_t bytes(const Ogre::HardwareBufferManagerBase& manager)
            {
                std::uint64_t total = 0;
                for (const Ogre::HardwareVertexBuffer* buffer : manager.*(&BufferLists::mVertexBuffers))
                    total += buffer->getSizeInBytes();
                for (const Ogre::HardwareIndexBuffer* buffer : manager.*(&BufferLists::mIndexBuffers))
                    total += buffer->getSizeInBytes();
                return total;
            }
        };

        std::uint64_t ogreGpuBytes()
        {
            std::uint64_t total = BufferLists::bytes(Ogre::HardwareBufferManager::getSingleton());
            auto textures = Ogre::TextureManager::getSingleton().getResourceIterator();
            while (textures.hasMoreElements())
            {
                const Ogre::TexturePtr texture = Ogre::static_pointer_cast<Ogre::Texture>(textures.getNext());
                if (!texture->isLoaded())
                    continue;
                for (std::size_t face = 0; face < texture->getNumFaces(); ++face)
                    for (std::uint32_t mip = 0; mip <= texture->getNumMipmaps(); ++mip)
                        total += texture->getBuffer(face, mip)->getSizeInBytes();
            }
            return total;
        }
    }

    TEST(Forest, gpuBytesOfEachTechniqueAreWhatOgresManagersHold)
    {
        // As the curves are measured: no shadows (a shadowed material draws from more textures), and
        // meshes not prepared for stencil shadow volumes (an earlier test's stencil shadows make
        // Ogre double their position buffers).
        OffscreenRenderer& renderer = OgreEnvironment::renderer();
        renderer.clearContent();
        renderer.setShadows(false);
        Ogre::MeshManager& meshes = Ogre::MeshManager::getSingleton();
        const bool shadowVolumes = meshes.getPrepareAllMeshesForShadowVolumes();
        meshes.setPrepareAllMeshesForShadowVolumes(false);
        const ForestTree& tree = oak();
        const std::vector<std::uint8_t> package =
            cachedPackage("forest", "oak", [&] { return bakePackage(tree.model, "oak"); });
        // The curves' bytes, measured here (two heights, one view: the bytes do not depend on the views).
        Result<ErrorCurves> curves = [&] {
            const TreeAssetPtr asset =
                TreeAssetManager::getSingleton().loadFromBytes("oak.gpu-bytes.curves", Ogre::RGN_DEFAULT, package);
            ErrorCurveOptions options;
            options.heightsPx = {16.0f, 192.0f};
            options.views = {{0.0f, 10.0f}};
            options.referenceSupersample = 1;
            Result<ErrorCurves> measured = measureErrorCurves(renderer, *asset, options);
            TreeAssetManager::getSingleton().remove(asset);
            return measured;
        }();
        ASSERT_TRUE(curves) << curves.error().message();
        ASSERT_TRUE(curves->hasGpuBytes());
        std::vector<std::string> techniques;
        for (const ErrorCurveLevel& level : curves->levels)
            if (std::find(techniques.begin(), techniques.end(), level.technique) == techniques.end())
                techniques.push_back(level.technique);
        Ogre::SceneManager& scene = renderer.getSceneManager();
        for (const std::string& technique : techniques)
        {
            // A fresh asset: only this technique's levels build anything.
            const TreeAssetPtr asset =
                TreeAssetManager::getSingleton().loadFromBytes("oak.gpu-bytes." + technique, Ogre::RGN_DEFAULT, package);
            asset->getBounds();
            const std::uint64_t before = ogreGpuBytes();
            std::vector<Forest*> forests;
            std::vector<std::size_t> levels;
            std::set<const void*> seen;
            std::uint64_t drawn = 0;
            for (std::size_t l = 0; l < curves->levels.size(); ++l)
            {
                const ErrorCurveLevel& c = curves->levels[l];
                if (c.technique != technique)
                    continue;
                levels.push_back(l);
                ForestLevel level;
                level.technique = c.technique;
                level.techniqueLevel = c.techniqueLevel;
                level.lowRes = c.lowRes;
                Forest* forest = createLevelForest(scene, renderer.getContentNode(), *asset, level,
                                                   {ForestInstance{}}, "gpu-bytes/" + technique + std::to_string(l), 0.0f);
                forest->makeAllResident();
                forests.push_back(forest);
                for (const ForestGpuResource& resource : forest->getGpuResources(0, 0))
                    if (seen.insert(resource.handle.get()).second)
                        drawn += resource.bytes;
            }
            const std::uint64_t held = ogreGpuBytes() - before;
            const std::uint64_t planned = curves->gpuBytes(levels);
            std::printf("%s: Ogre's managers %llu bytes, the Forests draw from %llu, the curves say %llu\n",
                        technique.c_str(), (unsigned long long)held, (unsigned long long)drawn,
                        (unsigned long long)planned);
            // Byte for byte: a level that draws a mesh holds every LoD level of it.
            EXPECT_GT(drawn, 0u) << technique;
            EXPECT_EQ(drawn, held) << technique;
            EXPECT_EQ(planned, held) << technique;
            for (Forest* forest : forests)
                scene.destroyMovableObject(forest);
            TreeAssetManager::getSingleton().remove(asset);
        }
        meshes.setPrepareAllMeshesForShadowVolumes(shadowVolumes);
    }

    TEST(Forest, aMemoryBudgetBindsThePlanAndOneBelowTheSmallestPlanIsRefused)
    {
        const TreeAssetPtr asset = oakWithCurves();
        const std::vector<LevelCost> costs = fixedCosts(*asset);
        Forest* forest = placeForest();
        EXPECT_EQ(forest->getMemoryBudget(), 0u);
        const std::uint32_t s = forest->addBudgetedSpecies(asset, costs);
        const std::vector<ForestLevel> unbudgeted = forest->getLevels(s);
        const std::uint64_t full = forest->getStats().plannedGpuBytes;
        ASSERT_GT(full, 0u);
        EXPECT_EQ(forest->getBindingBudget(), ForestBinding::Error);
        // A second species of the same asset holds the same levels: no more bytes.
        forest->addBudgetedSpecies(asset, costs);
        EXPECT_EQ(forest->getStats().plannedGpuBytes, full);

        // Half the bytes: levels taken out, the memory budget binds, and what is built fits it.
        forest->setMemoryBudget(full / 2);
        EXPECT_EQ(forest->getMemoryBudget(), full / 2);
        EXPECT_LE(forest->getStats().plannedGpuBytes, full / 2);
        EXPECT_EQ(forest->getBindingBudget(), ForestBinding::Memory);
        std::string levels;
        for (const ForestLevel& level : forest->getLevels(s))
            levels += Forest::describeLevel(level) + "; ";
        std::printf("planned %llu bytes; within %llu: %llu bytes, levels %s\n", (unsigned long long)full,
                    (unsigned long long)(full / 2), (unsigned long long)forest->getStats().plannedGpuBytes,
                    levels.c_str());
        const ForestTree& tree = oak();
        const float h = treeHeight(tree.model);
        forest->addInstances(grid(4, 1.6f * h));
        forest->makeAllResident();
        EXPECT_LE(forest->getGpuBytes() - forest->getStats().instanceBufferBytes, full / 2);
        const Image picture = toImage(OgreEnvironment::renderer().render(
            look(glm::vec3(0.3f * h, 1.4f * h, 6.0f * h), glm::vec3(0.0f, 0.0f, -3.0f * h)), 320, 180, 1));
        EXPECT_GT(treeCoverage(picture, BACKGROUND), 0.1);
        // The error budget changes within the memory budget.
        forest->setErrorBudget(0.0f);
        EXPECT_LE(forest->getStats().plannedGpuBytes, full / 2);
        forest->setErrorBudget(DEFAULT_ERROR_BUDGET);

        // Below the smallest plan: refused, naming the budget and the smallest plan; nothing changes.
        const std::vector<ForestLevel> held = forest->getLevels(s);
        try
        {
            forest->setMemoryBudget(1000);
            ADD_FAILURE() << "a budget of 1000 bytes was accepted";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("memory budget: 0.00 MB is below the smallest plan"), std::string::npos)
                << e.getDescription();
            EXPECT_NE(e.getDescription().find("impostor"), std::string::npos) << e.getDescription();
        }
        EXPECT_EQ(forest->getMemoryBudget(), full / 2);
        EXPECT_EQ(forest->getLevels(s).size(), held.size());

        // No budget: the first plan again.
        forest->setMemoryBudget(0);
        EXPECT_EQ(forest->getStats().plannedGpuBytes, full);
        EXPECT_EQ(forest->getLevels(s).size(), unbudgeted.size());
        EXPECT_EQ(forest->getBindingBudget(), ForestBinding::Error);
    }
}
