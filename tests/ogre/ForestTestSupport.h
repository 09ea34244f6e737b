// Helpers of the Forest tests (ForestTest.cpp, ForestShadowTest.cpp, ForestLevelPlanTest.cpp,
// ForestFloorTest.cpp, ForestTransitionTest.cpp, EveryTechniqueTest.cpp): the oak package every
// Forest test draws (reference, lodf, billboard-cloud, impostor of media/oak.glb, baked with the
// core bakers (few AO rays) and cached in $TREELOD_TEST_OUT/forest, keyed by the test binary's
// modification time), the oak of every technique (everyTechniqueOak), a ground, grids of
// instances, views and counts.
#pragma once

#include "OgreTestSupport.h"
#include "TestTrees.h"
#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeTechniques.h"

#include "TreeLod/BillboardCloudResources.h"
#include "TreeLod/FoliageLodResources.h"
#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/ErrorCurveMeasurer.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/Forest.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/OgreBootstrap.h"
#include "TreeLod/QuadFloors.h"
#include "TreeLod/ShadowSetup.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreEntity.h>
#include <OgreLogManager.h>
#include <OgreManualObject.h>
#include <OgreMaterialManager.h>
#include <OgreRTShaderSystem.h>
#include <OgreRenderQueue.h>
#include <OgreRenderQueueSortingGrouping.h>
#include <OgreSceneManager.h>
#include <OgreSceneQuery.h>
#include <OgreShadowCameraSetupPSSM.h>
#include <OgreSubEntity.h>
#include <OgreTechnique.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>

namespace TreeLod
{
    namespace
    {
        struct ForestTree
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// `baked`, encoded by `encode`, added as chunk `chunk` level 0; when baking failed, a
        /// test failure naming the error.
        template <typename T, typename Encode>
        void addBakedChunk(PackageWriter& writer, const char* chunk, std::uint32_t version, const Result<T>& baked,
                           Encode encode)
        {
            EXPECT_TRUE(baked.ok()) << (baked.ok() ? "" : baked.error().message());
            if (baked.ok())
            {
                EXPECT_TRUE(writer.addChunk(chunk, 0, version, encode(baked.value())).ok()) << chunk;
            }
        }

        inline std::vector<std::uint8_t> bakePackage(const TreeModel& model, const std::string& name)
        {
            PackageWriter writer;
            Result<void> added = addFoliageLodChunk(writer, model, name); // and the reference
            EXPECT_TRUE(added.ok()) << (added.ok() ? "" : added.error().message());
            BillboardCloudOptions cloudOptions;
            cloudOptions.aoRays = 4;
            addBakedChunk(writer, BILLBOARD_CLOUD_CHUNK, BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION,
                          bakeBillboardCloud(model, cloudOptions, name), encodeBillboardCloudChunk);
            ImpostorOptions impostorOptions;
            impostorOptions.aoRays = 4;
            impostorOptions.resolution = 128;
            addBakedChunk(writer, IMPOSTOR_CHUNK, IMPOSTOR_CHUNK_FORMAT_VERSION,
                          bakeImpostor(model, impostorOptions, name), encodeImpostorChunk);
            return writer.toBytes();
        }

        /// media/oak.glb with every chunk the Forest draws, loaded as "oak.forest-test".
        inline const ForestTree& oak()
        {
            return OgreEnvironment::keep<ForestTree>("forest.oak", [] {
                ForestTree t;
                Result<TreeModel> model = importGltf(OgreEnvironment::sourcePath("media/oak.glb"));
                EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
                t.model = std::move(model.value());
                const std::vector<std::uint8_t> bytes =
                    cachedPackage("forest", "oak", [&] { return bakePackage(t.model, "oak"); });
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak.forest-test", Ogre::RGN_DEFAULT, bytes);
                return t;
            });
        }

        struct EveryTechniqueTree
        {
            TreeModel model;
            TreeAssetPtr asset;
        };

        /// A generated oak of 300 leaves baked by every baker (quick options, TestTrees.h) into one
        /// package, loaded as "oak300.every-technique".
        inline const EveryTechniqueTree& everyTechniqueOak()
        {
            return OgreEnvironment::keep<EveryTechniqueTree>("every-technique.oak", [] {
                EveryTechniqueTree t;
                t.model = test::generatedOak(300);
                const std::vector<std::uint8_t> bytes = cachedPackage("every-technique", "oak300", [&] {
                    PackageWriter writer;
                    for (const BakeTechnique& baker : bakeTechniques())
                    {
                        Result<void> baked = baker.bake(writer, t.model, test::quickBakeOptions(baker.name), "oak300", {});
                        EXPECT_TRUE(baked.ok()) << baker.name << ": " << baked.error().message();
                        if (!baked.ok())
                            return std::vector<std::uint8_t>{};
                    }
                    return writer.toBytes();
                });
                OgreEnvironment::renderer();
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak300.every-technique", Ogre::RGN_DEFAULT, bytes);
                return t;
            });
        }

        const glm::vec3 BACKGROUND = LightingSpec().background;

        /// everyTechniqueOak (at the origin) framed from 30 degrees around, 10 up.
        inline CameraSpec everyTechniqueOakView()
        {
            const TreeModel& model = everyTechniqueOak().model;
            return CameraSpec::framing(model.boundsMin, model.boundsMax, 30.0f, 10.0f);
        }

        /// Per pixel, whether `image` differs from the background there (isTreePixel).
        inline std::vector<bool> treePixelMask(const Image& image)
        {
            std::vector<bool> covered(image.pixels.size());
            for (std::size_t i = 0; i < covered.size(); ++i)
                covered[i] = isTreePixel(image.pixels[i], BACKGROUND);
            return covered;
        }

        /// What a picture mid-transition keeps of its two levels' pictures: the share of the pixels
        /// both cover (1: no hole), and of those each covers alone (about the level's share: no
        /// double density).
        struct TransitionCoverage
        {
            std::size_t both = 0, fineOnly = 0, coarseOnly = 0;
            double bothKept = 0.0, fineKept = 0.0, coarseKept = 0.0;
        };
        /// The largest share of the tree's pixels (tree in either frame) that a frame of `frames`
        /// changes from the one before.
        inline double worstFrameChange(const std::vector<Image>& frames)
        {
            double worst = 0.0;
            for (std::size_t f = 1; f < frames.size(); ++f)
            {
                std::size_t changed = 0, tree = 0;
                for (std::size_t i = 0; i < frames[f].pixels.size(); ++i)
                {
                    const glm::vec4 &a = frames[f - 1].pixels[i], &b = frames[f].pixels[i];
                    tree += isTreePixel(a, BACKGROUND) || isTreePixel(b, BACKGROUND);
                    changed += glm::length(glm::vec3(a) - glm::vec3(b)) > 0.02f;
                }
                worst = std::max(worst, double(changed) / double(std::max<std::size_t>(tree, 1)));
            }
            return worst;
        }

        inline TransitionCoverage transitionCoverage(const Image& fine, const Image& mid, const Image& coarse)
        {
            const std::vector<bool> inFine = treePixelMask(fine), inCoarse = treePixelMask(coarse), inMid = treePixelMask(mid);
            TransitionCoverage c;
            std::size_t bothKept = 0, fineKept = 0, coarseKept = 0;
            for (std::size_t i = 0; i < inMid.size(); ++i)
            {
                if (inFine[i] && inCoarse[i])
                    ++c.both, bothKept += inMid[i];
                else if (inFine[i])
                    ++c.fineOnly, fineKept += inMid[i];
                else if (inCoarse[i])
                    ++c.coarseOnly, coarseKept += inMid[i];
            }
            c.bothKept = double(bothKept) / double(std::max<std::size_t>(c.both, 1));
            c.fineKept = double(fineKept) / double(std::max<std::size_t>(c.fineOnly, 1));
            c.coarseKept = double(coarseKept) / double(std::max<std::size_t>(c.coarseOnly, 1));
            return c;
        }

        /// A ground square of half-size `size` at y = 0 under the content node, casting no shadow: a
        /// clone of TreeLod/Bark in a plain green, or of TreeLod/BarkShadowed where `receiving` (the
        /// sun's depth shadow).
        inline void placeGround(float size, bool receiving)
        {
            Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
            for (const char* suffix : {"", "Shadowed"})
            {
                const Ogre::String name = Ogre::String("ForestTest/ShadowSceneGround") + suffix;
                if (materials.resourceExists(name, "TreeLod"))
                    continue;
                Ogre::MaterialPtr material =
                    materials.getByName(Ogre::String("TreeLod/Bark") + suffix, "TreeLod")->clone(name);
                material->getTechnique(0)->getPass(0)->getFragmentProgramParameters()->setNamedConstant(
                    "baseColour", Ogre::ColourValue(0.45f, 0.5f, 0.3f, 1.0f));
                material->load();
            }
            OffscreenRenderer& r = OgreEnvironment::renderer();
            Ogre::ManualObject* quad = r.getSceneManager().createManualObject();
            quad->setCastShadows(false);
            quad->begin(receiving ? "ForestTest/ShadowSceneGroundShadowed" : "ForestTest/ShadowSceneGround",
                        Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            for (const glm::vec2 c : {glm::vec2(-size, -size), glm::vec2(size, -size), glm::vec2(size, size),
                                      glm::vec2(-size, size)})
            {
                quad->position(c.x, 0.0f, c.y);
                quad->normal(0.0f, 1.0f, 0.0f);
                quad->textureCoord(0.0f, 0.0f);
            }
            quad->quad(0, 3, 2, 1); // counter-clockwise seen from above
            quad->end();
            r.getContentNode().createChildSceneNode()->attachObject(quad);
        }

        /// A fresh Forest (through its factory) under a child of the content node, content cleared.
        inline Forest* placeForest(const Ogre::NameValuePairList& params = {}, Ogre::SceneNode** node = nullptr)
        {
            static int serial = 0;
            OffscreenRenderer& r = OgreEnvironment::renderer();
            r.clearContent();
            r.setShadows(false);
            r.setLodBias(1.0f);
            Ogre::MovableObject* object =
                r.getSceneManager().createMovableObject("forest-" + std::to_string(serial++), "Forest", &params);
            Ogre::SceneNode* parent = r.getContentNode().createChildSceneNode();
            parent->attachObject(object);
            if (node)
                *node = parent;
            return static_cast<Forest*>(object);
        }

        inline Ogre::Camera& ogreCamera()
        {
            return *OgreEnvironment::renderer().getSceneManager().getCamera("TreeLodOffscreenCamera");
        }

        ForestInstance instance(float x, float y, float z, float rotation = 0.0f, float scale = 1.0f,
                                std::uint32_t species = 0)
        {
            return ForestInstance{glm::vec3(x, y, z), rotation, scale, species};
        }

        /// n x n trees `spacing` metres apart centred on the origin, rotations varied.
        inline std::vector<ForestInstance> grid(int n, float spacing, std::uint32_t species = 0)
        {
            std::vector<ForestInstance> out;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    out.push_back(instance((float(i) - 0.5f * float(n - 1)) * spacing, 0.0f,
                                           (float(j) - 0.5f * float(n - 1)) * spacing, 0.7f * float(i * n + j),
                                           0.8f + 0.05f * float((i + 2 * j) % 8), species));
            return out;
        }

        /// A child of `parent` placed, turned and scaled as `t` (a Forest instance as a separate object).
        inline Ogre::SceneNode* instanceNode(Ogre::SceneNode& parent, const ForestInstance& t)
        {
            Ogre::SceneNode* node = parent.createChildSceneNode(
                Ogre::Vector3(t.position.x, t.position.y, t.position.z),
                Ogre::Quaternion(Ogre::Radian(t.rotationY), Ogre::Vector3::UNIT_Y));
            node->setScale(Ogre::Vector3(t.scale));
            return node;
        }

        /// Every `factor` x `factor` block averaged (goldens of pictures rendered large).
        inline Image shrink(const Image& image, int factor)
        {
            Image out(image.width / factor, image.height / factor);
            for (int y = 0; y < out.height; ++y)
                for (int x = 0; x < out.width; ++x)
                {
                    glm::vec4 sum(0.0f);
                    for (int j = 0; j < factor; ++j)
                        for (int i = 0; i < factor; ++i)
                            sum += image.at(x * factor + i, y * factor + j);
                    out.at(x, y) = sum / float(factor * factor);
                }
            return out;
        }

        /// Renderables the object queues into each (group, priority).
        inline std::map<std::pair<int, int>, std::size_t> queued(Ogre::MovableObject& object)
        {
            Ogre::RenderQueue queue;
            object._notifyCurrentCamera(&ogreCamera());
            object._updateRenderQueue(&queue);
            struct Counter : Ogre::QueuedRenderableVisitor
            {
                std::size_t count = 0;
                void visit(Ogre::RenderablePass*) override { ++count; }
                void visit(const Ogre::Pass*, Ogre::RenderableList& list) override { count += list.size(); }
            };
            std::map<std::pair<int, int>, std::size_t> out;
            for (std::size_t id = 0; id < Ogre::RENDER_QUEUE_COUNT; ++id)
                if (const auto& group = queue._getQueueGroups()[id])
                    for (const auto& priority : group->getIterator())
                    {
                        Counter counter;
                        priority.second->getSolidsBasic().acceptVisitor(
                            &counter, Ogre::QueuedRenderableCollection::OM_PASS_GROUP);
                        if (counter.count > 0)
                            out[{int(id), int(priority.first)}] += counter.count;
                    }
            return out;
        }

        float treeHeight(const TreeModel& model) { return model.boundsMax.y - model.boundsMin.y; }

        /// A Forest of `tree` over a 5 x 5 grid 1.4 tree heights apart, its levels (`levels`) the
        /// automatic bands'.
        inline Forest* autoBandsGrid(const ForestTree& tree, std::vector<ForestLevel>& levels)
        {
            Forest* forest = placeForest();
            levels = Forest::levelsForBands(*tree.asset, Forest::getAutoBands());
            forest->addSpecies(tree.asset, levels);
            forest->addInstances(grid(5, 1.4f * treeHeight(tree.model)));
            return forest;
        }

        /// Perspective camera at `eye` looking at `target`.
        inline CameraSpec look(const glm::vec3& eye, const glm::vec3& target, float fov = 40.0f)
        {
            CameraSpec spec;
            spec.position = eye;
            spec.target = target;
            spec.fovYDegrees = fov;
            spec.nearClip = 0.1f;
            spec.farClip = 20000.0f;
            return spec;
        }

        /// The Forest's level of every instance per species (levelCounts) as one list.
        inline std::vector<std::uint32_t> flatCounts(const Forest& forest)
        {
            std::vector<std::uint32_t> out;
            for (const auto& species : forest.getStats().levelCounts)
                out.insert(out.end(), species.begin(), species.end());
            return out;
        }

        /// Mean level index of the visible instances of species 0.
        inline double meanLevel(const Forest& forest)
        {
            const std::vector<std::uint32_t>& counts = forest.getStats().levelCounts.at(0);
            double sum = 0.0, n = 0.0;
            for (std::size_t l = 0; l < counts.size(); ++l)
            {
                sum += double(l) * counts[l];
                n += counts[l];
            }
            return n > 0.0 ? sum / n : -1.0;
        }
    }
}
