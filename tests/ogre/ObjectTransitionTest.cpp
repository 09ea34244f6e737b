// Level transitions of the tree objects (ObjectTransition.h: BillboardCloudTree, EllipsoidTree,
// VolumeOctreeTree), on everyTechniqueOak: mid-transition each object covers what its two levels
// cover alone (no hole, no double density); a sweep through a band changes a small share of the
// pixels a frame where a hard switch changes them at once; a cloud mid-transition casts one shadow;
// bad lengths are refused by name.
#include "ForestTestSupport.h"

#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/EllipsoidTree.h"
#include "TreeLod/EllipsoidTreeResources.h"
#include "TreeLod/VolumeOctreeTree.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>

namespace TreeLod::ObjectTransitionTests
{
    namespace
    {
        constexpr int SIZE = 128;

        Image renderOak() { return toImage(OgreEnvironment::renderer().render(everyTechniqueOakView(), SIZE, SIZE, 1)); }

        template <typename T>
        T* placeOak(const std::string& technique, const Ogre::NameValuePairList& params)
        {
            return static_cast<T*>(placeTechnique(technique, *everyTechniqueOak().asset, params));
        }

        /// A billboard cloud whose screen size is `ratio` times its switch from level 0 to 1 (by its
        /// mesh LoD factor), with transition `length`.
        BillboardCloudTree* cloudAt(float ratio, float length)
        {
            auto* cloud = placeOak<BillboardCloudTree>("billboard-cloud", {{"lodTransition", std::to_string(length)}});
            renderOak(); // the value at factor 1
            const Ogre::Real factor = cloud->getSwitchPixelCount(0) * ratio * ratio / cloud->getPixelCountValue();
            cloud->setMeshLodBias(factor);
            return cloud;
        }
    }

    // For each object, the oak mid-transition (coarse share about 0.5): every pixel both levels
    // cover stays covered, a pixel one level alone covers is covered about its share of the time,
    // and the pictures match their golden.
    TEST(ObjectTransition, midTransitionCoversWhatBothLevelsCover)
    {
        std::vector<Image> strip, goldenStrip;
        auto check = [&](const std::string& name, const Image& fine, const Image& mid, const Image& coarse,
                         double low, double high) {
            SCOPED_TRACE(name);
            const TransitionCoverage c = transitionCoverage(fine, mid, coarse);
            std::printf("%s: covered by both %zu px, %.3f kept; fine alone %zu px, %.3f kept; coarse alone %zu px, "
                        "%.3f kept\n",
                        name.c_str(), c.both, c.bothKept, c.fineOnly, c.fineKept, c.coarseOnly, c.coarseKept);
            ASSERT_GT(c.both, 500u) << "the levels overlap";
            EXPECT_GT(c.bothKept, 0.97) << "no hole where both levels cover";
            ASSERT_GE(c.fineOnly + c.coarseOnly, 100u) << "the two levels differ";
            for (const auto& [alone, share] : {std::make_pair(c.fineOnly, c.fineKept), std::make_pair(c.coarseOnly, c.coarseKept)})
                if (alone >= 100)
                {
                    EXPECT_GT(share, low) << "each level draws its share";
                    EXPECT_LT(share, high) << "not both levels whole";
                }
            strip.insert(strip.end(), {fine, mid, coarse});
            goldenStrip.push_back(mid);
        };

        {
            // Screen size 1.1 times the switch's, t = 0.2: coarse share 0.5.
            BillboardCloudTree* cloud = cloudAt(1.1f, 0.2f);
            ASSERT_GE(cloud->getLevelCount(), 2u);
            const Image mid = renderOak();
            EXPECT_EQ(cloud->getLevel(), 0u);
            EXPECT_NEAR(cloud->getTransitionShare(), 0.5, 1e-3);
            cloud->setForcedLevel(0);
            const Image fine = renderOak();
            EXPECT_EQ(cloud->getTransitionShare(), 0.0f) << "a forced level draws alone";
            cloud->setForcedLevel(1);
            const Image coarse = renderOak();
            check("billboard cloud 0 to 1", fine, mid, coarse, 0.3, 0.7);
        }
        {
            // lines=false: the bark mesh, which no level changes.
            auto* tree = placeOak<EllipsoidTree>("ellipsoids", {{"lodTransition", "0.2"}, {"lines", "false"}});
            const EllipsoidTreeGpu& gpu = EllipsoidTreeResources::of(*everyTechniqueOak().asset).getGpu();
            ASSERT_GE(gpu.levels.size(), 2u);
            renderOak();
            const float height = tree->getHeightOnScreen(); // at factor 1
            const float target = 1.1f * gpu.levels[1].targetHeightPx;
            tree->setMeshLodBias((target / height) * (target / height)); // heights grow as the value's root
            const Image mid = renderOak();
            EXPECT_NEAR(tree->getHeightOnScreen(), target, 1e-3 * target);
            EXPECT_EQ(tree->getLevel(), 0u);
            EXPECT_NEAR(tree->getTransitionShare(), 0.5, 1e-3);
            // Alone: forced levels (a clamp by setMeshLodBias would clamp the bark's LoD too).
            auto forced = [&](const char* level) {
                auto* alone = placeOak<EllipsoidTree>("ellipsoids", {{"level", level}, {"lines", "false"}});
                alone->setMeshLodBias((target / height) * (target / height));
                return renderOak();
            };
            const Image fine = forced("0"), coarse = forced("1");
            check("ellipsoids 0 to 1", fine, mid, coarse, 0.3, 0.7);
        }
        {
            // Per cell: the cells of the level above within 1.4 of the plane (in screen size) and
            // their children share their pixels. Alone: the plane at P (fine) and at P / 1.4
            // (coarse: those cells behind it), the active level held by the clamp.
            auto* octree = placeOak<VolumeOctreeTree>("volume-octree", {{"lodTransition", "0.4"}});
            renderOak();
            const std::uint32_t active = octree->getActiveLevel();
            ASSERT_GE(active, 1u);
            const auto index = Ogre::ushort(octree->getLevelCount() - 1 - active);
            // The plane through the crown's middle (the view looks at the box's centre): its depth
            // grows as the root of the LoD value, with the active level held by the clamp.
            const CameraSpec view = everyTechniqueOakView();
            const TreeModel& model = everyTechniqueOak().model;
            const float middle = glm::dot(0.5f * (model.boundsMin + model.boundsMax) - view.position,
                                          glm::normalize(view.target - view.position));
            const float factor = (middle / octree->getPlaneDepth()) * (middle / octree->getPlaneDepth());
            octree->setMeshLodBias(factor, index, index);
            const Image mid = renderOak();
            EXPECT_NEAR(octree->getPlaneDepth(), middle, 1e-3f * middle);
            octree->setLodTransition(0.0f);
            const Image fine = renderOak();
            octree->setMeshLodBias(factor / (1.4f * 1.4f), index, index);
            const Image coarse = renderOak();
            EXPECT_EQ(octree->getActiveLevel(), active);
            EXPECT_GT(flipMean(fine, mid, FlipOver::Tree), 1e-3) << "cells are in the band";
            // Shares run from 0 to 1 across the band's cells.
            check("volume octree, cells in the band", fine, mid, coarse, 0.1, 0.9);
        }
        writePng(OgreEnvironment::outDir() + "/object-transitions-all.png", sideBySide(strip));
        compareWithGolden(sideBySide(goldenStrip), "object-transitions", 0.02);
    }

    // A billboard cloud swept through its band by its mesh LoD factor: with a transition each
    // frame changes a small share of the pixels; a hard switch changes most at once.
    TEST(ObjectTransition, aSweepThroughTheBandChangesFewPixelsAFrame)
    {
        auto worstFrame = [](float length) {
            BillboardCloudTree* cloud = cloudAt(1.0f, length); // the switch at factor 1
            const Ogre::Real atSwitch = cloud->getLodBias().meshFactor;
            std::vector<Image> frames;
            int inBand = 0;
            // Screen size 1.26 to 0.89 times the switch's in 20 frames.
            for (int f = 0; f <= 20; ++f)
            {
                cloud->setMeshLodBias(atSwitch * (1.6f - 0.04f * float(f)));
                frames.push_back(renderOak());
                inBand += cloud->getTransitionShare() > 0.0f;
            }
            const double worst = worstFrameChange(frames);
            std::printf("transition %.2f: %d frames in the band, worst frame changes %.3f of the tree's pixels\n",
                        double(length), inBand, worst);
            return std::make_pair(worst, inBand);
        };
        const auto [smooth, framesInBand] = worstFrame(0.2f);
        const auto [hard, none] = worstFrame(0.0f);
        EXPECT_GE(framesInBand, 8);
        EXPECT_EQ(none, 0);
        EXPECT_LT(smooth, 0.5 * hard) << "a transition spreads the change over its frames";
    }

    // A billboard cloud mid-transition casts one shadow: the ground darkens about as much as under
    // either cloud alone, well below both clouds drawn whole at once.
    TEST(ObjectTransition, aCloudMidTransitionCastsOneShadow)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const TreeModel& model = everyTechniqueOak().model;
        const float h = model.boundsMax.y - model.boundsMin.y;
        // The sun's default direction shades the ground beside the tree: seen from above.
        const CameraSpec view = look(glm::vec3(0.3f * h, 2.6f * h, 1.6f * h), glm::vec3(0.0f, 0.0f, 0.0f), 60.0f);
        // Clouds at the origin over a ground: `levels` (-1: the strategy's, mid-transition), shadows
        // on or off; returns the picture and the transition share of the last cloud.
        Ogre::Real factor = 1.0f;
        BillboardCloudTree* lastCloud = nullptr;
        auto render = [&](const std::vector<int>& levels, bool shadows) {
            r.clearContent();
            r.setShadows(false);
            r.setLodBias(1.0f);
            placeGround(3.0f * h, shadows);
            static int serial = 0;
            BillboardCloudTree* cloud = nullptr;
            for (int level : levels)
            {
                cloud = static_cast<BillboardCloudTree*>(TechniqueRegistry::getSingleton().createInstance(
                    "billboard-cloud", r.getSceneManager(), "transitionShadow" + std::to_string(serial++),
                    *everyTechniqueOak().asset, {{"lodTransition", "0.2"}}));
                cloud->setMeshLodBias(factor);
                cloud->setForcedLevel(level);
                r.getContentNode().createChildSceneNode()->attachObject(cloud);
            }
            r.setShadows(shadows, 1024);
            Image image = toImage(r.render(view, 160, 160, 1));
            r.setShadows(false);
            lastCloud = cloud;
            return std::make_pair(image, cloud ? cloud->getTransitionShare() : 0.0f);
        };
        // The factor that puts the cloud's screen size at 1.1 times its switch from this view.
        render({-1}, false);
        factor = lastCloud->getSwitchPixelCount(0) * 1.21f / lastCloud->getPixelCountValue();
        const std::vector<std::vector<int>> cases = {{0}, {1}, {-1}, {0, 1}};
        const char* names[] = {"cloud 0", "cloud 1", "mid-transition", "clouds 0 and 1 whole"};
        std::vector<Image> lit, shadowed;
        for (const std::vector<int>& levels : cases)
        {
            lit.push_back(render(levels, false).first);
            const auto [image, share] = render(levels, true);
            shadowed.push_back(image);
            if (&levels == &cases[2])
                EXPECT_NEAR(share, 0.5f, 1e-3f) << "mid-transition";
        }
        const Image groundOnly = render({}, false).first;
        std::vector<double> darkening;
        for (std::size_t c = 0; c < cases.size(); ++c)
        {
            double sum = 0.0;
            for (std::size_t i = 0; i < groundOnly.pixels.size(); ++i)
            {
                bool ground = true;
                for (const Image& image : lit)
                    ground = ground && glm::length(glm::vec3(image.pixels[i]) - glm::vec3(groundOnly.pixels[i])) < 0.02f;
                if (ground)
                    sum += pixelLuminance(lit[c].pixels[i]) - pixelLuminance(shadowed[c].pixels[i]);
            }
            darkening.push_back(sum);
            std::printf("%s: ground darkened by %.2f (luminance summed over the ground's pixels)\n", names[c], sum);
        }
        writePng(OgreEnvironment::outDir() + "/object-transition-shadows.png", sideBySide(shadowed));
        // The clouds' shadows overlap much more than a mesh's and a quad's (measured: 1.26 times
        // either for both whole), so the bounds are tighter than the Forest's test.
        const double mean = 0.5 * (darkening[0] + darkening[1]);
        ASSERT_GT(darkening[0], 20.0) << "the cloud casts a shadow on the ground in view";
        ASSERT_GT(darkening[3], 1.15 * mean) << "two casters whole cast more than either";
        EXPECT_NEAR(darkening[2], mean, 0.08 * mean) << "mid-transition: one shadow, between the levels'";
    }

    // Lengths outside [0, 1] and NaN are refused naming the parameter, as parameters and setters.
    TEST(ObjectTransition, badLengthsAreRefusedByName)
    {
        for (const char* technique : {"billboard-cloud", "ellipsoids", "volume-octree"})
            for (const char* bad : {"-0.1", "nan", "1.5", "inf"})
            {
                SCOPED_TRACE(std::string(technique) + " " + bad);
                try
                {
                    placeOak<Ogre::MovableObject>(technique, {{"lodTransition", bad}});
                    ADD_FAILURE() << "accepted";
                }
                catch (const Ogre::InvalidParametersException& e)
                {
                    EXPECT_NE(e.getFullDescription().find("lodTransition"), std::string::npos) << e.getFullDescription();
                }
            }
        using Setter = std::function<void(Ogre::MovableObject*, float)>;
        const std::vector<std::pair<const char*, Setter>> setters = {
            {"billboard-cloud", [](Ogre::MovableObject* o, float t) { static_cast<BillboardCloudTree*>(o)->setLodTransition(t); }},
            {"ellipsoids", [](Ogre::MovableObject* o, float t) { static_cast<EllipsoidTree*>(o)->setLodTransition(t); }},
            {"volume-octree", [](Ogre::MovableObject* o, float t) { static_cast<VolumeOctreeTree*>(o)->setLodTransition(t); }}};
        for (const auto& [technique, set] : setters)
        {
            Ogre::MovableObject* object = placeOak<Ogre::MovableObject>(technique, {});
            for (float bad : {-0.1f, std::nanf(""), 1.5f})
                EXPECT_THROW(set(object, bad), Ogre::InvalidParametersException) << technique << " " << bad;
        }
        auto* cloud = placeOak<BillboardCloudTree>("billboard-cloud", {});
        EXPECT_THROW(cloud->setLodTransition(-1.0f), Ogre::InvalidParametersException);
        EXPECT_EQ(cloud->getLodTransition(), 0.0f) << "hard by default, unchanged by a refused value";
    }
}
