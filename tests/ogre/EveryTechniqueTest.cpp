// Every registered technique against the same extremes, through the registries (no technique is
// named here): everyTechniqueOak (ForestTestSupport.h), each technique's object created from it by
// TechniqueRegistry.
#include "ForestTestSupport.h"

#include "TreeLod/TechniqueRegistry.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace TreeLod::EveryTechniqueTests
{
    namespace
    {
        /// `technique`'s object of the oak at `at`, seen from `camera` moved by `at`, without shadows.
        Image renderTechniqueAt(const std::string& technique, const glm::vec3& at, CameraSpec camera)
        {
            OffscreenRenderer& r = OgreEnvironment::renderer();
            placeTechnique(technique, *everyTechniqueOak().asset, {}, Ogre::Vector3(at.x, at.y, at.z));
            camera.position += at;
            camera.target += at;
            Image image = toImage(r.render(camera, 128, 128, 1));
            r.clearContent();
            return image;
        }
    }

    // Every technique's object and the camera 10 km from the origin (floats step by 1 mm there, a
    // hundredth of a pixel at this view): the picture at the origin, over the tree's pixels.
    TEST(EveryTechnique, tenKilometresFromTheOriginLooksAsAtTheOrigin)
    {
        const EveryTechniqueTree& t = everyTechniqueOak();
        const CameraSpec view = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 30.0f, 10.0f);
        const glm::vec3 offset(1.0e4f, 0.0f, -1.0e4f);
        std::vector<Image> row;
        for (const TechniqueInfo& technique : TechniqueRegistry::getSingleton().getTechniques())
        {
            SCOPED_TRACE(technique.name);
            const Image atOrigin = renderTechniqueAt(technique.name, glm::vec3(0.0f), view);
            const Image away = renderTechniqueAt(technique.name, offset, view);
            const double error = flipMean(atOrigin, away, FlipOver::Tree), overlap = coveredOverlap(atOrigin, away, LightingSpec().background);
            std::printf("%s: coverage %.4f, 10 km away FLIP %.4f over the tree, overlap %.4f\n", technique.name.c_str(),
                        treeCoverage(atOrigin, LightingSpec().background), error, overlap);
            EXPECT_GT(treeCoverage(atOrigin, LightingSpec().background), 0.05);
            EXPECT_LT(error, 0.05);
            EXPECT_GT(overlap, 0.95);
            row.insert(row.end(), {atOrigin, away});
        }
        writePng(OgreEnvironment::outDir() + "/every-technique-10km.png", sideBySide(row));
    }

    // A telephoto view from 200 times as far (about 6 km, a field of view of 0.225 degrees): the tree
    // is as large on screen, so each technique draws the level it draws near. The view is nearly
    // orthographic, so the pictures differ from the near ones; each technique's error against the
    // polygonal tree in the same view stays what it is near (depth and the ray casts' precision at
    // kilometres), over the tree's pixels.
    TEST(EveryTechnique, aTelephotoViewFromKilometresLooksAsFromNear)
    {
        const EveryTechniqueTree& t = everyTechniqueOak();
        const CameraSpec nearView = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 30.0f, 10.0f);
        const CameraSpec farView = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 30.0f, 10.0f, 1.0f, 45.0f / 200.0f);
        const Image meshNear = renderTechniqueAt(REFERENCE_TECHNIQUE, glm::vec3(0.0f), nearView);
        const Image meshFar = renderTechniqueAt(REFERENCE_TECHNIQUE, glm::vec3(0.0f), farView);
        std::printf("telephoto camera %.0f m from the tree; the mesh covers %.4f near, %.4f telephoto\n",
                    double(glm::distance(farView.position, farView.target)), treeCoverage(meshNear, LightingSpec().background),
                    treeCoverage(meshFar, LightingSpec().background));
        EXPECT_NEAR(treeCoverage(meshFar, LightingSpec().background) / treeCoverage(meshNear, LightingSpec().background), 1.0, 0.1);
        std::vector<Image> row;
        for (const TechniqueInfo& technique : TechniqueRegistry::getSingleton().getTechniques())
        {
            SCOPED_TRACE(technique.name);
            const Image near = renderTechniqueAt(technique.name, glm::vec3(0.0f), nearView);
            const Image far = renderTechniqueAt(technique.name, glm::vec3(0.0f), farView);
            const double nearError = flipMean(meshNear, near, FlipOver::Tree), farError = flipMean(meshFar, far, FlipOver::Tree);
            std::printf("%s: FLIP against the mesh over the tree %.4f near, %.4f telephoto\n", technique.name.c_str(),
                        nearError, farError);
            EXPECT_GT(treeCoverage(far, LightingSpec().background), 0.05); // not a tree drawn nowhere in both views
            EXPECT_LT(farError, nearError + 0.03);
            row.insert(row.end(), {near, far});
        }
        writePng(OgreEnvironment::outDir() + "/every-technique-telephoto.png", sideBySide(row));
    }
}
