// Level transitions in the Forest (Forest::setLodTransition, ForestInstances.h "Transitions",
// TreeLodTransition.glsl), on everyTechniqueOak: a pair of levels of every technique drawn
// mid-transition covers what the two cover alone (no hole, no double density); a tree whose LoD
// value sweeps through a transition changes a small share of its pixels a frame, where a hard
// switch changes them at once; a caster mid-transition casts one shadow, not two.
#include "ForestTestSupport.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace TreeLod::ForestTransitionTests
{
    namespace
    {
        constexpr int SIZE = 128;
        constexpr float TRANSITION = 0.2f;

        /// The view of the oak (at the origin) every test here renders.
        CameraSpec oakView() { return everyTechniqueOakView(); }

        /// The Forest's LoD value (Forest.h units: 4 pi r_px^2 of the asset's reference sphere) of a
        /// tree at the origin seen from `view` in a SIZE x SIZE viewport.
        Ogre::Real lodValueAtOrigin(const CameraSpec& view)
        {
            const Ogre::Real radius = Ogre::Math::boundingRadiusFromAABB(everyTechniqueOak().asset->getBounds());
            const float d2 = glm::dot(view.position, view.position);
            return Ogre::Math::PI * radius * radius * CullCamera::fromSpec(view, float(SIZE), float(SIZE)).lodPixelScale / d2;
        }

        /// One oak at the origin drawn by `levels` with transition `transition`, rendered from oakView.
        Image renderOak(const std::vector<ForestLevel>& levels, float transition, Forest** placed = nullptr)
        {
            Forest* forest = placeForest();
            forest->setLodTransition(transition, 0.0f); // every switch fades, however small
            forest->addSpecies(everyTechniqueOak().asset, levels);
            forest->addInstances({instance(0.0f, 0.0f, 0.0f)});
            Image image = toImage(OgreEnvironment::renderer().render(oakView(), SIZE, SIZE, 1));
            if (placed)
                *placed = forest;
            return image;
        }

        /// `fine` drawn down to a switch the oak's screen size is `ratio` times (ratio in [1, 1.2):
        /// in the band), `coarse` beyond it.
        std::vector<ForestLevel> pairAt(const ForestLevel& fine, const ForestLevel& coarse, float ratio)
        {
            ForestLevel near = fine;
            near.minPixelCount = lodValueAtOrigin(oakView()) / (ratio * ratio);
            ForestLevel far = coarse;
            far.minPixelCount = 0.0f;
            return {near, far};
        }
    }

    // For a pair of levels of each technique, the oak mid-transition (coarse share 0.5): every pixel
    // both levels cover stays covered (no hole), a pixel one level alone covers is covered about
    // half the time (no double density), and the pictures match their golden.
    TEST(ForestTransition, midTransitionCoversWhatBothLevelsCover)
    {
        struct Pair
        {
            ForestLevel fine, coarse;
        };
        // Each technique's finest Forest level.
        auto finest = [](const char* technique) {
            ForestLevel level = Forest::levelsForBands(*everyTechniqueOak().asset, {{technique, 0.0f}}).front();
            level.minPixelCount = 0.0f;
            return level;
        };
        const std::vector<Pair> pairs = {
            {finest("mesh"), finest("billboard-cloud")},
            {finest("lodf"), finest("ellipsoids")},
            {finest("billboard-cloud"), finest("octahedral-impostor")},
            {finest("ellipsoids"), finest("volume-octree")},
            {finest("volume-octree"), finest("impostor")},
            {finest("octahedral-impostor"), finest("impostor")},
        };
        std::vector<Image> strip, goldenStrip;
        for (const Pair& pair : pairs)
        {
            const std::string name = pair.fine.technique + " to " + pair.coarse.technique;
            SCOPED_TRACE(name);
            const Image fine = renderOak({pair.fine}, TRANSITION);
            const Image coarse = renderOak({pair.coarse}, TRANSITION);
            Forest* forest = nullptr;
            // Screen size 1.1 times the switch's: coarse share (1.2 - 1.1) / 0.2 = 0.5.
            const Image mid = renderOak(pairAt(pair.fine, pair.coarse, 1.1f), TRANSITION, &forest);
            EXPECT_EQ(forest->getStats().visibleInstances, 1u);
            ASSERT_EQ(forest->getStats().transitionInstances, 1u) << "the oak is in the band";
            EXPECT_EQ(forest->getStats().levelCounts.at(0), (std::vector<std::uint32_t>{1u, 1u}));
            const Image hard = renderOak(pairAt(pair.fine, pair.coarse, 1.1f), 0.0f);

            const TransitionCoverage c = transitionCoverage(fine, mid, coarse);
            std::printf("%s: covered by both %zu px, %.3f kept; fine alone %zu px, %.3f kept; coarse alone %zu px, "
                        "%.3f kept; hard switch vs fine FLIP %.4f\n",
                        name.c_str(), c.both, c.bothKept, c.fineOnly, c.fineKept, c.coarseOnly, c.coarseKept,
                        flipMean(fine, hard, FlipOver::Tree));
            ASSERT_GT(c.both, 500u) << "the levels overlap";
            EXPECT_GT(c.bothKept, 0.97) << "no hole where both levels cover";
            for (const auto& [alone, share] : {std::make_pair(c.fineOnly, c.fineKept), std::make_pair(c.coarseOnly, c.coarseKept)})
                if (alone >= 100)
                {
                    EXPECT_GT(share, 0.3) << "each level draws its share";
                    EXPECT_LT(share, 0.7) << "not both levels whole";
                }
            EXPECT_LT(flipMean(fine, hard, FlipOver::Tree), 1e-4) << "transition 0: the fine level alone";
            strip.insert(strip.end(), {fine, mid, coarse});
            goldenStrip.push_back(mid);
        }
        writePng(OgreEnvironment::outDir() + "/forest-transitions.png", sideBySide(strip));
        compareWithGolden(sideBySide(goldenStrip), "forest-transitions", 0.02);
    }

    // The oak's LoD value swept through the band by the Forest's LoD bias (the picture's geometry
    // stays): with a transition each frame changes a small share of the tree's pixels; a hard
    // switch changes most of them in one frame.
    TEST(ForestTransition, aSweepThroughTheBandChangesFewPixelsAFrame)
    {
        const std::vector<ForestLevel> levels =
            pairAt({"mesh", 0, false, 0.0f}, {"impostor", 0, false, 0.0f}, 1.0f); // the switch at bias 1
        auto worstFrame = [&](float transition) {
            Forest* forest = placeForest();
            forest->setLodTransition(transition, 0.0f); // every switch fades, however small
            forest->addSpecies(everyTechniqueOak().asset, levels);
            forest->addInstances({instance(0.0f, 0.0f, 0.0f)});
            OffscreenRenderer& r = OgreEnvironment::renderer();
            std::vector<Image> frames;
            std::uint32_t inBand = 0;
            // Bias 1.6 to 0.8 (screen size 1.26 to 0.89 times the switch's) in 20 frames.
            for (int f = 0; f <= 20; ++f)
            {
                forest->setLodBias(1.6f - 0.04f * float(f));
                frames.push_back(toImage(r.render(oakView(), SIZE, SIZE, 1)));
                inBand += forest->getStats().transitionInstances;
            }
            const double worst = worstFrameChange(frames);
            std::printf("transition %.2f: %u frames in the band, worst frame changes %.3f of the tree's pixels\n",
                        double(transition), inBand, worst);
            return std::make_pair(worst, inBand);
        };
        const auto [smooth, framesInBand] = worstFrame(TRANSITION);
        const auto [hard, none] = worstFrame(0.0f);
        EXPECT_GE(framesInBand, 8u);
        EXPECT_EQ(none, 0u);
        // A switch below the transitions' smallest height on screen stays hard.
        Forest* forest = placeForest();
        forest->setLodTransition(TRANSITION, 1e4f);
        forest->addSpecies(everyTechniqueOak().asset, levels);
        forest->addInstances({instance(0.0f, 0.0f, 0.0f)});
        forest->setLodBias(1.2f);
        OgreEnvironment::renderer().render(oakView(), SIZE, SIZE, 1);
        EXPECT_EQ(forest->getStats().transitionInstances, 0u);
        forest->setLodTransition(TRANSITION, 0.0f);
        OgreEnvironment::renderer().render(oakView(), SIZE, SIZE, 1);
        EXPECT_EQ(forest->getStats().transitionInstances, 1u);
        // Two levels of the same drawable (a bark LoD split) are a continuous step: hard.
        Forest* collapse = placeForest();
        collapse->setLodTransition(TRANSITION, 0.0f);
        collapse->addSpecies(everyTechniqueOak().asset,
                             pairAt({"mesh", 0, false, 0.0f}, {"mesh", 0, false, 0.0f}, 1.1f));
        collapse->addInstances({instance(0.0f, 0.0f, 0.0f)});
        OgreEnvironment::renderer().render(oakView(), SIZE, SIZE, 1);
        EXPECT_EQ(collapse->getStats().transitionInstances, 0u);
        EXPECT_EQ(collapse->getStats().levelCounts.at(0), (std::vector<std::uint32_t>{1u, 0u}));
        forest = collapse;
        EXPECT_THROW(forest->setLodTransition(TRANSITION, -1.0f), Ogre::InvalidParametersException);
        EXPECT_THROW(forest->setLodTransition(std::nanf(""), 0.0f), Ogre::InvalidParametersException);
        EXPECT_THROW(forest->setLodTransition(1.5f), Ogre::InvalidParametersException);
        EXPECT_LT(smooth, 0.2) << "a transition spreads the change over its frames";
        EXPECT_GT(hard, 0.4) << "a hard switch changes the tree at once";
    }

    // A caster mid-transition casts one shadow: the darkening of the ground is about the mean of
    // the two levels' own shadows, well below that of both levels drawn whole at once.
    TEST(ForestTransition, aCasterMidTransitionCastsOneShadow)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const TreeModel& model = everyTechniqueOak().model;
        const float h = model.boundsMax.y - model.boundsMin.y;
        // The sun's default direction shades the ground beside the tree: seen from above.
        const CameraSpec view = look(glm::vec3(0.3f * h, 2.6f * h, 1.6f * h), glm::vec3(0.0f, 0.0f, 0.0f), 60.0f);
        const ForestLevel mesh{"mesh", 0, false, 0.0f}, quad{"impostor", 0, false, 0.0f};
        // LoD value from the shadow scene's view: the switch where the oak's screen size is 1.1 times it.
        const Ogre::Real radius = Ogre::Math::boundingRadiusFromAABB(everyTechniqueOak().asset->getBounds());
        const float value = Ogre::Math::PI * radius * radius * CullCamera::fromSpec(view, 160.0f, 160.0f).lodPixelScale /
                            glm::dot(view.position, view.position);
        ForestLevel fineLevel = mesh;
        fineLevel.minPixelCount = value / 1.21f;

        // `forests` at the origin over a ground, shadows on or off.
        auto render = [&](const std::vector<std::vector<ForestLevel>>& forests, bool shadows) {
            r.clearContent();
            r.setShadows(false);
            r.setLodBias(1.0f);
            placeGround(3.0f * h, shadows);
            static int serial = 0;
            std::vector<Forest*> placed;
            for (const std::vector<ForestLevel>& levels : forests)
            {
                auto* forest = static_cast<Forest*>(
                    sm.createMovableObject("transitionShadow" + std::to_string(serial++), "Forest"));
                forest->setLodTransition(TRANSITION, 0.0f);
                forest->addSpecies(everyTechniqueOak().asset, levels);
                forest->addInstances({instance(0.0f, 0.0f, 0.0f)});
                r.getContentNode().createChildSceneNode()->attachObject(forest);
                placed.push_back(forest);
            }
            r.setShadows(shadows, 1024);
            Image image = toImage(r.render(view, 160, 160, 1));
            r.setShadows(false);
            std::uint32_t transitions = 0;
            for (const Forest* forest : placed)
                transitions += forest->getStats().transitionInstances;
            return std::make_pair(image, transitions);
        };
        const std::vector<std::vector<std::vector<ForestLevel>>> cases = {
            {{mesh}}, {{quad}}, {{fineLevel, quad}}, {{mesh}, {quad}}};
        const char* names[] = {"mesh", "quad", "mid-transition", "mesh and quad whole"};
        // Ground pixels: not covered by a tree in any case's unshadowed picture.
        std::vector<Image> lit, shadowed;
        for (const auto& forests : cases)
        {
            lit.push_back(render(forests, false).first);
            const auto [image, transitions] = render(forests, true);
            shadowed.push_back(image);
            EXPECT_EQ(transitions, &forests == &cases[2] ? 1u : 0u);
        }
        const Image groundOnly = render({}, false).first;
        std::vector<bool> ground(groundOnly.pixels.size(), true);
        for (const Image& image : lit)
            for (std::size_t i = 0; i < ground.size(); ++i)
                ground[i] = ground[i] && glm::length(glm::vec3(image.pixels[i]) - glm::vec3(groundOnly.pixels[i])) < 0.02f;
        std::vector<double> darkening;
        for (std::size_t c = 0; c < cases.size(); ++c)
        {
            double sum = 0.0;
            for (std::size_t i = 0; i < ground.size(); ++i)
                if (ground[i])
                    sum += pixelLuminance(lit[c].pixels[i]) - pixelLuminance(shadowed[c].pixels[i]);
            darkening.push_back(sum);
            std::printf("%s: ground darkened by %.1f (luminance summed over the ground's pixels)\n", names[c], sum);
        }
        const double mean = 0.5 * (darkening[0] + darkening[1]);
        ASSERT_GT(darkening[0], 20.0) << "the mesh casts a shadow on the ground in view";
        ASSERT_GT(darkening[3], 1.3 * mean) << "two casters whole cast more than either";
        EXPECT_NEAR(darkening[2], mean, 0.2 * mean) << "mid-transition: one shadow, between the levels'";
        writePng(OgreEnvironment::outDir() + "/forest-transition-shadows.png", sideBySide(shadowed));
    }
}
