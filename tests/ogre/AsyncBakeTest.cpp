// Baking off the frame path: TreeAssetManager::requireAsync runs the registered
// TreeBaker on a worker thread while the render thread goes on drawing; ForestScene's
// requestPolicy/update switch a scene's policy once its bakes have ended. A gated baker
// (it waits until the test opens its gate) makes "not ready yet" deterministic.
#include "OgreTestSupport.h"

#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreException.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

namespace TreeLod
{
    namespace
    {
        /// Bakes a 100-leaf shrub (reference, lodf, impostor) for any source, after its gate opens.
        class GatedBaker : public TreeBaker
        {
        public:
            explicit GatedBaker(std::string name) : mDir(OgreEnvironment::outDir() + "/async-bake/" + name)
            {
                std::filesystem::remove_all(mDir);
                std::filesystem::create_directories(mDir);
                open();
            }
            /// Later bakes wait until open().
            void close()
            {
                mGate = std::promise<void>();
                mOpened = mGate.get_future().share();
            }
            void open() { mGate.set_value(); }

            std::atomic<bool> fail{false};
            std::atomic<int> finished{0};
            std::atomic<std::thread::id> lastThread{};

            Ogre::String requirePackage(const Ogre::String& source, const std::vector<Ogre::String>&) override
            {
                lastThread = std::this_thread::get_id();
                std::shared_future<void> opened = mOpened;
                opened.wait();
                if (fail)
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, "'" + source + "': the gated baker fails",
                                "GatedBaker");
                const std::string path = mDir + "/shrub.treelod";
                if (!std::filesystem::exists(path))
                {
                    GeneratorOptions options;
                    options.preset = TreePreset::Shrub;
                    options.leafCount = 100;
                    Result<TreeModel> model = generateTree(options);
                    EXPECT_TRUE(model.ok());
                    PackageWriter writer;
                    EXPECT_TRUE(addFoliageLodChunk(writer, *model, "shrub").ok());
                    ImpostorOptions impostor;
                    impostor.resolution = 32;
                    impostor.aoRays = 2;
                    Result<ImpostorData> baked = bakeImpostor(*model, impostor, "shrub");
                    EXPECT_TRUE(baked.ok());
                    EXPECT_TRUE(writer.addChunk(IMPOSTOR_CHUNK, 0, IMPOSTOR_CHUNK_FORMAT_VERSION,
                                                encodeImpostorChunk(*baked)).ok());
                    const std::vector<std::uint8_t> bytes = writer.toBytes();
                    std::ofstream(path, std::ios::binary)
                        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
                }
                ++finished;
                return path;
            }

        private:
            std::string mDir;
            std::promise<void> mGate;
            std::shared_future<void> mOpened = mGate.get_future().share();
        };

        /// Registers `baker` for the scope.
        struct BakerScope
        {
            explicit BakerScope(TreeBaker* baker) { TreeAssetManager::getSingleton().setBaker(baker); }
            ~BakerScope() { TreeAssetManager::getSingleton().setBaker(nullptr); }
        };

        /// Polls `ready` (rendering a frame between polls) for up to a minute.
        template <typename F> bool waitFor(F&& ready)
        {
            const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
            while (!ready())
            {
                if (std::chrono::steady_clock::now() > end)
                    return false;
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
            return true;
        }

        template <typename F> std::string thrownBy(F&& f)
        {
            try
            {
                f();
            }
            catch (const Ogre::Exception& e)
            {
                return e.getDescription();
            }
            return "(nothing thrown)";
        }
    }

    TEST(TreeAssetManager, requireAsyncBakesOnAWorkerThread)
    {
        OgreEnvironment::renderer();
        TreeAssetManager& manager = TreeAssetManager::getSingleton();
        EXPECT_NE(thrownBy([&] { manager.requireAsync("async:none", {"reference"}, Ogre::RGN_DEFAULT); })
                      .find("'async:none': no baker registered"),
                  std::string::npos);

        GatedBaker baker("manager");
        BakerScope scope(&baker);
        baker.close();
        std::shared_ptr<TreeAssetRequest> request = manager.requireAsync("async:one", {"reference"}, Ogre::RGN_DEFAULT);
        EXPECT_EQ(request->getSource(), "async:one");
        // The render thread is free while the bake waits.
        const Image frame = toImage(OgreEnvironment::renderer().render(CameraSpec(), 32, 32, 1));
        EXPECT_EQ(frame.width, 32);
        EXPECT_FALSE(request->isReady());
        EXPECT_EQ(baker.finished, 0);
        baker.open();
        ASSERT_TRUE(waitFor([&] { return request->isReady(); }));
        EXPECT_NE(baker.lastThread.load(), std::this_thread::get_id()) << "the bake ran on the calling thread";
        TreeAssetPtr asset = request->get();
        ASSERT_TRUE(asset);
        EXPECT_TRUE(asset->isLoaded());
        EXPECT_TRUE(asset->hasChunk("reference"));
        EXPECT_EQ(request->get(), asset);

        // A dropped request does not wait for its bake: the gate opens only after the drop
        // returned (or after 20 s, when the drop would otherwise wait forever).
        baker.close();
        std::atomic<bool> dropped{false};
        auto opener = std::async(std::launch::async, [&] {
            const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
            while (!dropped && std::chrono::steady_clock::now() < end)
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            baker.open();
        });
        const int before = baker.finished;
        manager.requireAsync("async:dropped", {"reference"}, Ogre::RGN_DEFAULT).reset();
        EXPECT_EQ(baker.finished, before) << "dropping the request waited for its bake";
        dropped = true;
        opener.wait();

        // A failed bake: get() throws the baker's error, naming the source, every time.
        baker.fail = true;
        std::shared_ptr<TreeAssetRequest> failing =
            manager.requireAsync("async:failing", {"reference"}, Ogre::RGN_DEFAULT);
        ASSERT_TRUE(waitFor([&] { return failing->isReady(); }));
        EXPECT_NE(thrownBy([&] { failing->get(); }).find("'async:failing': the gated baker fails"), std::string::npos);
        EXPECT_NE(thrownBy([&] { failing->get(); }).find("async:failing"), std::string::npos);
    }

    TEST(ForestScene, techniqueSwitchBakesWhileTheCurrentOneDraws)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.clearContent();
        r.setShadows(false);
        GatedBaker baker("scene");
        BakerScope scope(&baker);
        Result<SceneScript> script = parseSceneScript(R"({
            "name": "async", "ground": {"kind": "plane", "size": 40},
            "species": [{"name": "shrub", "source": "preset:shrub", "leaves": 100, "techniques": "auto"}],
            "placements": [{"species": "shrub", "positions": [[0, 0, 0], [2, 0, 1], [-2, 0, -1]]}],
            "camera": {"fovY": 45, "near": 0.05, "far": 500,
                       "keyframes": [{"time": 0, "position": [0, 1.5, 6], "target": [0, 0.6, 0]}]},
            "resolution": [96, 64], "frames": 1})",
                                                      "async.json", "");
        ASSERT_TRUE(script.ok()) << script.error().message();
        ForestSceneOptions options;
        options.policy = LodPolicy::fixed("impostor");
        ForestScene scene(r.getSceneManager(), r.getContentNode(), *script, options);
        const CameraSpec camera = scene.cameraAtFrame(0, 1);
        const Image quads = toImage(r.render(camera, 96, 64, 1));
        const glm::vec3 background = sceneLighting(*script).background;
        EXPECT_GT(treeCoverage(quads, background), 0.01);

        // Asked for lodf with the gate closed: quads go on drawing, frame after frame.
        baker.close();
        scene.requestPolicy(LodPolicy::fixed(FOLIAGE_LOD_CHUNK));
        EXPECT_TRUE(scene.isPolicyPending());
        EXPECT_EQ(scene.getPendingPolicy(), LodPolicy::fixed(FOLIAGE_LOD_CHUNK));
        for (int f = 0; f < 3; ++f)
        {
            EXPECT_FALSE(scene.update());
            const Image frame = toImage(r.render(camera, 96, 64, 1));
            EXPECT_EQ(scene.getPolicy(), LodPolicy::fixed("impostor"));
            EXPECT_EQ(scene.getForest().getLevels(0).front().technique, "impostor");
            EXPECT_LT(flipMean(quads, frame), 0.001) << "the current technique keeps drawing";
        }
        baker.open();
        ASSERT_TRUE(waitFor([&] { return scene.update(); }));
        EXPECT_FALSE(scene.isPolicyPending());
        EXPECT_EQ(scene.getPolicy(), LodPolicy::fixed(FOLIAGE_LOD_CHUNK));
        EXPECT_EQ(scene.getForest().getLevels(0).front().technique, FOLIAGE_LOD_CHUNK);
        const Image leaves = toImage(r.render(camera, 96, 64, 1));
        EXPECT_GT(treeCoverage(leaves, background), 0.01);
        EXPECT_GT(flipMean(quads, leaves), 0.001) << "the switch changed nothing on screen";

        // A failed bake: update() throws naming the script and the source; lodf stays.
        baker.fail = true;
        scene.requestPolicy(LodPolicy::fixed("impostor"));
        std::string error;
        ASSERT_TRUE(waitFor([&] {
            try
            {
                return scene.update();
            }
            catch (const Ogre::Exception& e)
            {
                error = e.getDescription();
                return true;
            }
        }));
        EXPECT_NE(error.find("async.json"), std::string::npos) << error;
        EXPECT_NE(error.find("preset:shrub"), std::string::npos) << error;
        EXPECT_FALSE(scene.isPolicyPending());
        EXPECT_EQ(scene.getPolicy(), LodPolicy::fixed(FOLIAGE_LOD_CHUNK));
        baker.fail = false;
    }
}
