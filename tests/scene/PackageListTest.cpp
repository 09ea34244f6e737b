// The scene side's bakers and reader: CacheTreeBaker writes a package list, PackageListBaker (the
// runtime side's TreeBaker, no baking) answers from it; readGreyImageOgre reads heightfields
// through Ogre. Headless: one Root with Codec_STBI, no render system.
#include "TreeLod/CacheTreeBaker.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/Image.h"
#include "TreeLod/OgreGreyImage.h"
#include "TreeLod/PackageListBaker.h"

#include <OgreException.h>
#include <OgreLogManager.h>
#include <OgreRoot.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>

namespace TreeLod
{
    namespace
    {
        std::string outDir(const std::string& name)
        {
            const char* env = std::getenv("TREELOD_TEST_OUT");
            std::filesystem::path dir =
                std::filesystem::path(env && *env ? env : TREELOD_BINARY_DIR "/test-out") / "scene-packages" / name;
            std::filesystem::remove_all(dir);
            std::filesystem::create_directories(dir);
            return dir.string();
        }

        /// The message of the Ogre::Exception `f` throws ("" and a failure when it throws none).
        template <typename F> std::string thrown(F&& f)
        {
            try
            {
                f();
            }
            catch (const Ogre::Exception& e)
            {
                return e.getDescription();
            }
            ADD_FAILURE() << "no exception";
            return "";
        }

        void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

        const std::string SHRUB_1 = "preset:shrub?seed=1&leaves=100";
        const std::string SHRUB_2 = "preset:shrub?seed=2&leaves=100";
    }

    TEST(PackageList, listFromARealCacheAnswersTheSameRequests)
    {
        const std::string dir = outDir("roundtrip");
        CacheTreeBaker baker(dir + "/cache");
        const std::string first = baker.requirePackage(SHRUB_1, {"reference"});
        const std::string second = baker.requirePackage(SHRUB_2, {"reference"});
        ASSERT_TRUE(std::filesystem::is_regular_file(first));
        ASSERT_NE(first, second);
        const std::string listPath = dir + "/packages.json";
        Result<void> written = baker.writePackageList(listPath);
        ASSERT_TRUE(written.ok()) << written.error().message();

        PackageListBaker list(listPath);
        ASSERT_EQ(list.getEntries().size(), 2u);
        for (const PackageListBaker::Entry& e : list.getEntries())
        {
            EXPECT_TRUE(std::filesystem::path(e.path).is_absolute()) << e.path;
            EXPECT_EQ(e.techniques, std::vector<std::string>{"reference"});
        }
        // The paths the cache returned, whatever directory the reader runs in.
        EXPECT_EQ(std::filesystem::path(list.requirePackage(SHRUB_1, {"reference"})),
                  std::filesystem::absolute(first).lexically_normal());
        EXPECT_EQ(std::filesystem::path(list.requirePackage(SHRUB_2, {"reference"})),
                  std::filesystem::absolute(second).lexically_normal());
        EXPECT_EQ(list.requirePackage(SHRUB_2, {}), list.requirePackage(SHRUB_2, {"reference"}));
    }

    TEST(PackageList, aSourceRequiredTwiceListsEveryChunkItsPackageHolds)
    {
        const std::string dir = outDir("union");
        CacheTreeBaker baker(dir + "/cache");
        baker.requirePackage(SHRUB_1, {"reference"});
        const std::string path = baker.requirePackage(SHRUB_1, {"impostor"}); // rewrites the package with both
        ASSERT_TRUE(baker.writePackageList(dir + "/packages.json").ok());
        PackageListBaker list(dir + "/packages.json");
        ASSERT_EQ(list.getEntries().size(), 1u);
        EXPECT_EQ(list.getEntries()[0].techniques, (std::vector<std::string>{"impostor", "reference"}));
        EXPECT_EQ(std::filesystem::path(list.requirePackage(SHRUB_1, {"reference", "impostor"})),
                  std::filesystem::absolute(path).lexically_normal());
    }

    TEST(PackageList, missingSourceOrTechniqueNamesTheListTheSourceAndWhatIsMissing)
    {
        const std::string dir = outDir("missing");
        const std::string listPath = dir + "/packages.json";
        writeText(listPath, R"({"format": "treelod-package-list", "version": 1, "packages": [
            {"source": "/trees/oak.glb", "techniques": ["reference", "lodf"], "path": "/cache/oak.treelod"}]})");
        PackageListBaker list(listPath);
        EXPECT_EQ(list.requirePackage("/trees/oak.glb", {"lodf", "reference"}), "/cache/oak.treelod");

        std::string message = thrown([&] { list.requirePackage("/trees/oak.glb", {"reference", "billboard-cloud", "impostor"}); });
        EXPECT_NE(message.find(listPath), std::string::npos) << message;
        EXPECT_NE(message.find("/trees/oak.glb lacks billboard-cloud, impostor"), std::string::npos) << message;
        EXPECT_NE(message.find("run `treelod bench`, which bakes them"), std::string::npos) << message;

        message = thrown([&] { list.requirePackage("/trees/pine.glb", {"reference"}); });
        EXPECT_NE(message.find(listPath), std::string::npos) << message;
        EXPECT_NE(message.find("no package for /trees/pine.glb (techniques reference)"), std::string::npos) << message;
    }

    TEST(PackageList, badListsAreRefusedNamingTheFile)
    {
        const std::string dir = outDir("bad");
        struct Case
        {
            std::string text, reason;
        };
        const std::vector<Case> cases = {
            {"{", "not JSON"},
            {R"({"format": "something-else", "version": 1, "packages": []})", "not a package list"},
            {R"({"format": "treelod-package-list", "version": 2, "packages": []})", "version 2"},
            {R"({"format": "treelod-package-list", "version": 1, "packages": [{"source": "a", "techniques": []}]})",
             "packages[0]: expected a non-empty string 'path'"},
            {R"({"format": "treelod-package-list", "version": 1, "packages": [{"source": "a", "path": "p", "techniques": [1]}]})",
             "'techniques' holds a number"},
        };
        for (const Case& c : cases)
        {
            writeText(dir + "/list.json", c.text);
            const std::string message = thrown([&] { PackageListBaker list(dir + "/list.json"); });
            EXPECT_NE(message.find(dir + "/list.json"), std::string::npos) << message;
            EXPECT_NE(message.find(c.reason), std::string::npos) << c.text << "\n" << message;
        }
        const std::string message = thrown([&] { PackageListBaker list(dir + "/absent.json"); });
        EXPECT_NE(message.find(dir + "/absent.json"), std::string::npos) << message;
    }

    TEST(ForestScene, budgetedAutoNamesItsBudgetAndBakesEveryTechniqueItChoosesAmong)
    {
        // The policy's grammar is LodPolicyTest's; here what a scene bakes for each policy.

        Result<SceneScript> script = parseSceneScript(R"({"name": "t", "ground": {"kind": "plane", "size": 100},
            "species": [{"name": "s", "source": "preset:shrub", "leaves": 100, "techniques": "auto"}],
            "placements": [{"species": "s", "positions": [[0, 0]]}],
            "camera": {"keyframes": [{"time": 0, "position": [0, 1, 10], "target": [0, 1, 0]}]},
            "resolution": [64, 64], "frames": 1})",
                                                      "t.json", "");
        ASSERT_TRUE(script.ok()) << script.error().message();
        for (const std::string& choice : {std::string(""), std::string("auto@0.05"), std::string("auto~40")})
        {
            Result<LodPolicy> policy = LodPolicy::parse(choice);
            ASSERT_TRUE(policy.ok()) << choice;
            const auto packages = scenePackages(*script, {*policy});
            ASSERT_EQ(packages.size(), 1u);
            EXPECT_EQ(packages.begin()->second,
                      (std::vector<std::string>{"billboard-cloud", "classic-billboard-cloud", "ellipsoids", "impostor",
                                                "lodf", "octahedral-impostor", "reference"}))
                << "choice '" << choice << "'";
        }
    }

    TEST(OgreGreyImage, readsWhatTheBakeSideReads)
    {
        const std::string dir = outDir("grey");
        Image ramp(5, 3);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 5; ++x)
                ramp.at(x, y) = glm::vec4((x + 5.0f * y) / 14.0f, 1.0f - x / 4.0f, 0.5f, 1.0f);
        ASSERT_TRUE(writePng(dir + "/ramp.png", ramp).ok());

        // Without a codec: a clear error, no exception.
        Result<GreyImage> early = readGreyImageOgre(dir + "/ramp.png");
        ASSERT_FALSE(early.ok());
        EXPECT_NE(early.error().message().find("no Ogre image codec for 'png'"), std::string::npos)
            << early.error().message();

        Ogre::LogManager logs; // quiet: the log goes to the file only
        logs.createLog(dir + "/ogre.log", true, false, false);
        auto root = std::make_unique<Ogre::Root>("", "", "");
        root->loadPlugin(std::string(TREELOD_OGRE_PLUGIN_DIR) + "/Codec_STBI");
        Result<GreyImage> ogre = readGreyImageOgre(dir + "/ramp.png");
        Result<GreyImage> bake = readGreyImage(dir + "/ramp.png");
        ASSERT_TRUE(ogre.ok()) << ogre.error().message();
        ASSERT_TRUE(bake.ok()) << bake.error().message();
        ASSERT_EQ(ogre->width, 5);
        ASSERT_EQ(ogre->height, 3);
        ASSERT_EQ(bake->values.size(), 15u);
        for (std::size_t i = 0; i < 15; ++i)
        {
            // Red channel, top row first, 8 bits: within half a step of the written value.
            EXPECT_NEAR(ogre->values[i], bake->values[i], 1e-6f) << i;
            EXPECT_NEAR(ogre->values[i], float(i) / 14.0f, 0.5f / 255.0f + 1e-6f) << i;
        }
        EXPECT_FALSE(readGreyImageOgre(dir + "/absent.png").ok());
        writeText(dir + "/broken.png", "not a png");
        Result<GreyImage> broken = readGreyImageOgre(dir + "/broken.png");
        ASSERT_FALSE(broken.ok());
        EXPECT_NE(broken.error().message().find(dir + "/broken.png"), std::string::npos);
    }
}
