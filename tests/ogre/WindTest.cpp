// The wind (TreeLod/Wind.h, WindModel.h) as Ogre draws it, on everyTechniqueOak: the programs move
// the mesh where the CPU model moves its vertices (at two times, one near 1e6 s), shadows
// included; a billboard cloud and an ellipsoid level at a gust keep covering what the swaying mesh
// covers; the picture does not depend on the tree's scale; a very strong wind stays bounded; bad
// parameters are refused by name and change nothing. Zero wind draws today's pictures: every
// golden test runs calm.
#include "ForestTestSupport.h"

#include "TreeLod/PackageWriter.h"
#include "TreeLod/Wind.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace TreeLod::WindTests
{
    namespace
    {
        constexpr int SIZE = 160;
        /// Large enough that the mesh draws its full detail (no bark LoD, leaf textures at mip 0), where
        /// the CPU-moved mesh must match exactly: smaller, the two meshes' own LoD levels differ.
        constexpr int FULL_DETAIL_SIZE = 480;

        WindParameters breeze(float strength)
        {
            WindParameters wind;
            wind.direction = {1.0f, 0.4f};
            wind.strength = strength;
            wind.gustiness = 0.5f;
            return wind;
        }

        /// Sets the wind for the scope; calm again after it, whatever the test did.
        struct ScopedWind
        {
            ScopedWind(const WindParameters& wind, double seconds)
            {
                Wind::setParameters(wind);
                Wind::setTime(seconds);
            }
            ~ScopedWind()
            {
                Wind::setParameters(WindParameters{});
                Wind::setTime(0.0);
            }
        };

        CameraSpec view() { return everyTechniqueOakView(); }

        Image render(const CameraSpec& camera = view(), int size = SIZE)
        {
            return toImage(OgreEnvironment::renderer().render(camera, size, size, 1));
        }

        /// The mean position (pixels) of the tree's pixels.
        glm::dvec2 centroid(const Image& image)
        {
            glm::dvec2 sum(0.0);
            std::size_t n = 0;
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                    if (isTreePixel(image.pixels[std::size_t(y) * std::size_t(image.width) + std::size_t(x)], BACKGROUND))
                    {
                        sum += glm::dvec2(x, y);
                        ++n;
                    }
            return n ? sum / double(n) : sum;
        }

        /// everyTechniqueOak's model with every vertex moved by the CPU wind at `seconds` (the tree at
        /// the origin, unturned; the leaves flutter), as a package holding its reference.
        TreeAssetPtr displacedOak(const WindParameters& wind, double seconds, const std::string& name)
        {
            TreeModel model = everyTechniqueOak().model;
            const float height = Wind::treeHeight(everyTechniqueOak().asset->getBounds());
            const glm::vec2 world = glm::normalize(wind.direction);
            const glm::vec3 along(world.x, 0.0f, world.y);
            const WindPhases phases = WindPhases::at(seconds);
            for (auto [vertices, leaf] : {std::pair(&model.barkVertices, false), std::pair(&model.leafVertices, true)})
                for (Vertex& v : *vertices)
                    v.position += WindModel::offset(wind, phases, v.position, height, along, world, glm::vec3(0.0f), leaf);
            PackageWriter writer;
            Result<void> added = addReferenceChunk(writer, model, name);
            EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
            return TreeAssetManager::getSingleton().loadFromBytes(name, Ogre::RGN_DEFAULT, writer.toBytes());
        }

        void save(const std::vector<Image>& images, const std::string& name)
        {
            EXPECT_TRUE(writePng(OgreEnvironment::outDir() + "/" + name + ".png", sideBySide(images)).ok());
        }
    }

    // A vertex the CPU moves and one the programs move land on the same pixel: the mesh drawn in
    // the wind matches the CPU-moved mesh drawn calm, at 1.3 s and near 1e6 s (no phase lost to
    // single precision), and both differ from the calm tree.
    TEST(Wind, programsMoveTheMeshAsTheCpuModelDoes)
    {
        const WindParameters wind = breeze(2.5f);
        std::vector<Image> strip;
        int serial = 0;
        for (double seconds : {1.3, 1.0e6 + 0.7})
        {
            SCOPED_TRACE(seconds);
            TreeAssetPtr moved = displacedOak(wind, seconds, "oak300.wind-" + std::to_string(serial++));
            placeTechnique(REFERENCE_TECHNIQUE, *moved);
            const Image cpu = render(view(), FULL_DETAIL_SIZE);
            placeTechnique(REFERENCE_TECHNIQUE, *everyTechniqueOak().asset);
            const Image still = render(view(), FULL_DETAIL_SIZE);
            Image gpu;
            {
                ScopedWind scoped(wind, seconds);
                gpu = render(view(), FULL_DETAIL_SIZE);
            }
            const double overlap = coveredOverlap(gpu, cpu, BACKGROUND);
            const double moved_ = coveredOverlap(still, cpu, BACKGROUND);
            const double flip = flipMean(gpu, cpu, FlipOver::Tree);
            std::printf("t = %.1f s: programs vs CPU coverage IoU %.4f, FLIP %.4f; calm vs CPU IoU %.4f\n", seconds,
                        overlap, flip, moved_);
            EXPECT_GT(overlap, 0.995);
            EXPECT_LT(flip, 0.002);
            EXPECT_LT(moved_, 0.9) << "the wind moves the tree visibly";
            strip.insert(strip.end(), {still, gpu, cpu});
        }
        save(strip, "wind-programs-vs-cpu");
    }

    // The shadow moves with its caster: what the sun's shadows change in the picture is the same
    // for the mesh moved by the programs and the CPU-moved mesh, and differs from the calm tree's.
    TEST(Wind, shadowsMoveWithTheCasters)
    {
        const WindParameters wind = breeze(2.5f);
        const double seconds = 4.1;
        const TreeModel& model = everyTechniqueOak().model;
        const float height = model.boundsMax.y;
        const CameraSpec camera = look(glm::vec3(0.0f, 2.5f * height, 1.5f * height), glm::vec3(0.0f, 0.0f, 0.0f), 60.0f);
        OffscreenRenderer& r = OgreEnvironment::renderer();
        // The pixels shadows change in a picture of `asset` (in the wind when `windy`).
        auto shadowMask = [&](TreeAsset& asset, bool windy, Image& shadowed) {
            std::unique_ptr<ScopedWind> scoped;
            if (windy)
                scoped = std::make_unique<ScopedWind>(wind, seconds);
            auto picture = [&](bool receiving) {
                placeTechnique(REFERENCE_TECHNIQUE, asset);
                placeGround(3.0f * height, receiving);
                r.setShadows(true, 1024);
                return toImage(r.render(camera, FULL_DETAIL_SIZE, FULL_DETAIL_SIZE, 1));
            };
            shadowed = picture(true);
            const Image lit = picture(false);
            r.setShadows(false);
            Image mask = lit;
            for (std::size_t i = 0; i < mask.pixels.size(); ++i)
            {
                const bool darker = pixelLuminance(shadowed.pixels[i]) < 0.95 * pixelLuminance(lit.pixels[i]);
                mask.pixels[i] = darker ? glm::vec4(0.0f, 0.0f, 0.0f, 1.0f) : glm::vec4(BACKGROUND, 1.0f);
            }
            return mask;
        };
        Image windyPicture, cpuPicture, stillPicture;
        TreeAssetPtr moved = displacedOak(wind, seconds, "oak300.wind-shadow");
        // The process's first shadowed picture draws its shadows coarser (a first-frame state of the
        // shadow texture, with or without wind): one picture first, not compared.
        shadowMask(*everyTechniqueOak().asset, false, stillPicture);
        const Image still = shadowMask(*everyTechniqueOak().asset, false, stillPicture);
        const Image windy = shadowMask(*everyTechniqueOak().asset, true, windyPicture);
        const Image cpu = shadowMask(*moved, false, cpuPicture);
        const double same = coveredOverlap(windy, cpu, BACKGROUND);
        const double moves = coveredOverlap(windy, still, BACKGROUND);
        std::printf("shadowed pixels: programs vs CPU IoU %.4f, programs vs calm IoU %.4f\n", same, moves);
        save({stillPicture, windyPicture, cpuPicture, still, windy, cpu}, "wind-shadows");
        EXPECT_GT(same, 0.95);
        EXPECT_LT(moves, 0.9) << "the shadow moves";
    }

    // A billboard cloud and an ellipsoid level follow the mesh's silhouette at a gust, at two
    // times: their coverage of the swaying mesh's pixels (IoU) is about what it is calm, and their
    // silhouette's centre moves with the mesh's (a level standing still would not move at all).
    TEST(Wind, coarseLevelsFollowTheMeshsSilhouette)
    {
        const WindParameters wind = breeze(3.0f);
        constexpr int SILHOUETTE_SIZE = 320; // the centres move a few pixels
        std::vector<Image> strip;
        for (const auto& [technique, params] :
             {std::make_pair(std::string("billboard-cloud"), Ogre::NameValuePairList{{"level", "1"}}),
              std::make_pair(std::string("ellipsoids"), Ogre::NameValuePairList{{"level", "1"}})})
        {
            placeTechnique(REFERENCE_TECHNIQUE, *everyTechniqueOak().asset);
            const Image meshStill = render(view(), SILHOUETTE_SIZE);
            placeTechnique(technique, *everyTechniqueOak().asset, params);
            const Image levelStill = render(view(), SILHOUETTE_SIZE);
            const double calm = coveredOverlap(levelStill, meshStill, BACKGROUND);
            const glm::dvec2 meshRest = centroid(meshStill), levelRest = centroid(levelStill);
            for (double seconds : {2.0, 5.5})
            {
                SCOPED_TRACE(technique + " at " + std::to_string(seconds) + " s");
                ScopedWind scoped(wind, seconds);
                placeTechnique(REFERENCE_TECHNIQUE, *everyTechniqueOak().asset);
                const Image mesh = render(view(), SILHOUETTE_SIZE);
                placeTechnique(technique, *everyTechniqueOak().asset, params);
                const Image level = render(view(), SILHOUETTE_SIZE);
                const double follows = coveredOverlap(level, mesh, BACKGROUND);
                const glm::dvec2 meshShift = centroid(mesh) - meshRest, levelShift = centroid(level) - levelRest;
                const double apart = glm::length(levelShift - meshShift);
                std::printf("%s at %.1f s: IoU with the swaying mesh %.4f (calm %.4f); the mesh's centre moves "
                            "(%.2f, %.2f) px, the level's (%.2f, %.2f) px\n",
                            technique.c_str(), seconds, follows, calm, meshShift.x, meshShift.y, levelShift.x,
                            levelShift.y);
                EXPECT_GT(follows, calm - 0.03);
                ASSERT_GT(glm::length(meshShift), 2.0) << "the wind moves the mesh visibly";
                EXPECT_LT(apart, 0.25 * glm::length(meshShift) + 0.5) << "the level moves as the mesh does";
                strip.insert(strip.end(), {mesh, level});
            }
        }
        save(strip, "wind-coarse-levels");
    }

    // The same picture at any scale of the tree (a 0.5 m and a 500 m oak: the node scaled and the
    // camera with it), and a gale bends the tree a bounded amount.
    TEST(Wind, extremesOfScaleAndStrength)
    {
        const double seconds = 3.3;
        const TreeModel& model = everyTechniqueOak().model;
        const float height = model.boundsMax.y;
        std::vector<Image> strip;
        Image reference;
        for (float metres : {0.5f, height, 500.0f})
        {
            SCOPED_TRACE(metres);
            const float scale = metres / height;
            ScopedWind scoped(breeze(2.0f), seconds);
            Ogre::MovableObject* tree = placeTechnique(REFERENCE_TECHNIQUE, *everyTechniqueOak().asset);
            tree->getParentSceneNode()->setScale(Ogre::Vector3(scale));
            const CameraSpec framing = CameraSpec::framing(model.boundsMin * scale, model.boundsMax * scale, 30.0f, 10.0f);
            const Image picture = render(framing);
            {
                ScopedWind calm(WindParameters{}, seconds);
                EXPECT_LT(coveredOverlap(picture, render(framing), BACKGROUND), 0.9) << "the wind moves it";
            }
            if (reference.pixels.empty())
                reference = picture;
            else
            {
                const double flip = flipMean(picture, reference, FlipOver::Tree);
                std::printf("%.1f m oak against the 0.5 m one: FLIP %.4f\n", metres, flip);
                EXPECT_LT(flip, 0.02);
            }
            strip.push_back(picture);
        }
        placeTechnique(REFERENCE_TECHNIQUE, *everyTechniqueOak().asset);
        const Image still = render();
        for (float strength : {20.0f, 1.0e4f})
        {
            ScopedWind scoped(breeze(strength), seconds);
            const Image gale = render();
            const double overlap = coveredOverlap(gale, still, BACKGROUND);
            std::printf("strength %.0f: IoU with the calm tree %.4f\n", double(strength), overlap);
            EXPECT_GT(treeCoverage(gale, BACKGROUND), 0.5 * treeCoverage(still, BACKGROUND)) << "still drawn";
            EXPECT_GT(overlap, 0.3) << "bent, not blown away";
            EXPECT_LT(overlap, 0.9) << "bent";
            strip.push_back(gale);
        }
        save(strip, "wind-extremes");
    }

    // NaN, infinities and out-of-range values are refused with the parameter's name, and the wind
    // stays what it was.
    TEST(Wind, badParametersAreRefusedByName)
    {
        ScopedWind scoped(breeze(1.0f), 2.0);
        const std::vector<std::pair<WindParameters, std::string>> bad = [] {
            std::vector<std::pair<WindParameters, std::string>> cases;
            WindParameters w = breeze(1.0f);
            w.strength = std::nanf("");
            cases.emplace_back(w, "wind.strength");
            w = breeze(-1.0f);
            cases.emplace_back(w, "wind.strength");
            w = breeze(1.0f);
            w.direction = {0.0f, 0.0f};
            cases.emplace_back(w, "wind.direction");
            w = breeze(1.0f);
            w.direction = {std::nanf(""), 1.0f};
            cases.emplace_back(w, "wind.direction");
            w = breeze(1.0f);
            w.gustiness = 1.5f;
            cases.emplace_back(w, "wind.gustiness");
            w = breeze(1.0f);
            w.gustWavelength = std::numeric_limits<float>::infinity();
            cases.emplace_back(w, "wind.gustWavelength");
            return cases;
        }();
        for (const auto& [wind, name] : bad)
        {
            try
            {
                Wind::setParameters(wind);
                ADD_FAILURE() << name << " accepted";
            }
            catch (const Ogre::InvalidParametersException& e)
            {
                EXPECT_NE(e.getDescription().find(name), std::string::npos) << e.getDescription();
            }
            EXPECT_EQ(Wind::getParameters().strength, 1.0f) << "the wind it had";
        }
        EXPECT_THROW(Wind::setTime(std::nan("")), Ogre::InvalidParametersException);
        EXPECT_EQ(Wind::getTime(), 2.0);
    }
}
