// The sample browser end to end: treelod_browser --headless writes its screenshots, and they show
// what they should (needs an X server, like test_ogre). Layout facts used below are the ones
// `treelod_browser --help` states: a 270-pixel column on the left, the split view's three equal
// panels in the rest.
#include "../ogre/OgreTestSupport.h"

#include "TreeLod/Camera.h"
#include "TreeLod/TechniqueRegistry.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        constexpr int WIDTH = 1024, HEIGHT = 640, COLUMN = 270;
        constexpr int CAPTION = 44; ///< the panels' caption labels (top) are left out of pixel counts

        std::string outDir()
        {
            const std::string dir = std::string(TREELOD_BINARY_DIR) + "/test-out/browser";
            std::filesystem::create_directories(dir);
            return dir;
        }

        /// Where the running test's browser writes stdout: one file per test, since ctest runs the
        /// tests of this binary as concurrent processes.
        std::string outputFile(const char* stream)
        {
            return outDir() + "/" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "-" + stream +
                   ".txt";
        }

        /// Run the browser with `args`; returns its exit code, stderr in `errors`.
        int runBrowser(const std::string& args, std::string& errors)
        {
            const std::string errorFile = outputFile("stderr");
            const std::string command =
                std::string(TREELOD_BROWSER_PATH) + " " + args + " > " + outputFile("stdout") + " 2> " + errorFile;
            const int status = std::system(command.c_str());
            std::ifstream in(errorFile);
            std::stringstream text;
            text << in.rdbuf();
            errors = text.str();
            return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        }

        Image crop(const Image& image, int left, int top, int width, int height)
        {
            Image out(width, height);
            for (int y = 0; y < height; ++y)
                for (int x = 0; x < width; ++x)
                    out.at(x, y) = image.at(left + x, top + y);
            return out;
        }

        /// Largest difference of any pixel's RGB from the first pixel's.
        float spread(const Image& image)
        {
            float most = 0.0f;
            for (const glm::vec4& p : image.pixels)
                most = std::max(most, glm::length(glm::vec3(p) - glm::vec3(image.pixels.front())));
            return most;
        }

        Image load(const std::string& dir, const std::string& name)
        {
            const std::string path = dir + "/" + name;
            EXPECT_GT(std::filesystem::exists(path) ? std::filesystem::file_size(path) : 0u, 1000u) << path;
            Result<Image> image = readImage(path);
            EXPECT_TRUE(image.ok()) << (image.ok() ? "" : image.error().message());
            if (!image.ok())
                return Image(WIDTH, HEIGHT);
            EXPECT_EQ(image->width, WIDTH) << path;
            EXPECT_EQ(image->height, HEIGHT) << path;
            return image->width == WIDTH && image->height == HEIGHT ? *image : Image(WIDTH, HEIGHT);
        }

        // The split view: the tree in the reference and technique panels on the sky; the
        // difference panel black where they agree. The "mesh" technique is the reference itself,
        // drawn by a second Entity through its own camera: its FLIP must be 0 everywhere.
        void checkSplitView(const std::string& dir, const std::string& technique)
        {
            SCOPED_TRACE("split view of " + technique);
            const Image image = load(dir, "split-" + technique + ".png");
            const glm::vec3 sky = LightingSpec().background;
            const int third = (WIDTH - COLUMN) / 3;
            for (int panel = 0; panel < 2; ++panel)
            {
                const double coverage = treeCoverage(crop(image, COLUMN + panel * third, CAPTION, third, HEIGHT - CAPTION), sky);
                EXPECT_GT(coverage, 0.05) << "panel " << panel << ": no tree";
                EXPECT_LT(coverage, 0.8) << "panel " << panel << ": no sky around the tree";
            }
            const int left = COLUMN + 2 * third;
            const double lit = treeCoverage(crop(image, left, CAPTION, WIDTH - left, HEIGHT - CAPTION), glm::vec3(0.0f));
            if (technique == REFERENCE_TECHNIQUE)
                EXPECT_EQ(lit, 0.0) << "the reference differs from itself";
            else
                EXPECT_GT(lit, 0.01) << "no difference shown";
            // The column holds the trays: not one flat colour.
            EXPECT_GT(spread(crop(image, 0, 0, COLUMN, HEIGHT)), 0.3f) << "no trays";
        }
    }

    TEST(BrowserHeadless, ScreenshotsShowTheScenes)
    {
        const std::string dir = outDir() + "/screenshots";
        std::filesystem::remove_all(dir);
        std::string errors;
        ASSERT_EQ(runBrowser("--headless --scene " + std::string(TREELOD_SOURCE_DIR) +
                                 "/samples/scenes/single-tree.json --screenshots " + dir + " --frames 2 --size " +
                                 std::to_string(WIDTH) + "x" + std::to_string(HEIGHT),
                             errors),
                  0)
            << errors;

        // A split view per registered technique (the browser makes one sample each).
        ASSERT_GE(TechniqueRegistry::getSingleton().getTechniques().size(), 5u);
        for (const TechniqueInfo& technique : TechniqueRegistry::getSingleton().getTechniques())
            checkSplitView(dir, technique.name);
        // The panels (not the column: it shows measured frame times) against a golden image.
        compareWithGolden(crop(load(dir, "split-billboard-cloud.png"), COLUMN, 0, WIDTH - COLUMN, HEIGHT),
                          "browser-split-billboard-cloud", 0.02);

        // The forest frames follow the scene's camera path: 1 m from the crown, then 2 km away.
        const Image near = crop(load(dir, "forest-000.png"), COLUMN, 0, WIDTH - COLUMN, HEIGHT);
        const Image far = crop(load(dir, "forest-001.png"), COLUMN, 0, WIDTH - COLUMN, HEIGHT);
        EXPECT_GT(spread(near), 0.2f) << "forest frame 0 is flat";
        EXPECT_GT(spread(far), 0.2f) << "forest frame 1 is flat";
        EXPECT_GT(treeCoverage(near, LightingSpec().background), 0.5) << "forest frame 0: no leaves up close";
        Result<FlipResult> change = flip(near, far);
        ASSERT_TRUE(change.ok());
        EXPECT_GT(change->mean, 0.1) << "the camera did not move along the path";

        // The terrain sample (samples/scenes/terrain-pssm.json on Ogre's Terrain): hills and trees.
        const Image terrain = crop(load(dir, "terrain-000.png"), COLUMN, 0, WIDTH - COLUMN, HEIGHT);
        EXPECT_GT(spread(terrain), 0.2f) << "terrain frame 0 is flat";

        // The menu: five thumbnails (trees and the forest) beside the trays.
        const Image menu = crop(load(dir, "menu.png"), COLUMN, 0, WIDTH - COLUMN, HEIGHT);
        EXPECT_GT(treeCoverage(menu, LightingSpec().background), 0.3);
        EXPECT_GT(spread(menu), 0.3f);
    }

    // Memory over a long session: after the warm-up passes over every sample and technique (bakes
    // loaded, levels built, shaders and driver variants compiled), a few hundred more switches
    // leave the heap in use and resident memory (both measured after malloc_trim) within
    // SOAK_GROWTH_MIB of where they were. Every frame is 0.2 s of sample time, so the same frames
    // are drawn however loaded the machine is. Measured at 320x240 with 256-texel shadow maps (2048 costs 1 s a frame on llvmpipe):
    // docs/browser.md, "Memory". Without the terrain sample, as measured there.
    TEST(BrowserHeadless, SoakKeepsMemory)
    {
        constexpr unsigned SWITCHES = 880; // at least four times the warm-up (202 switches with nine techniques)
        constexpr double SOAK_GROWTH_MIB = 48.0;
        std::string errors;
        ASSERT_EQ(runBrowser("--headless --soak " + std::to_string(SWITCHES) + " --scene " +
                                 std::string(TREELOD_SOURCE_DIR) +
                                 "/samples/scenes/single-tree.json --size 320x240 --shadow-size 256 --no-terrain",
                             errors),
                  0)
            << errors;
        std::ifstream in(outputFile("stdout"));
        std::string line, report;
        while (std::getline(in, line))
            if (line.rfind("soak: ", 0) == 0)
                report = line;
        unsigned switches = 0, warmUp = 0;
        double resident0 = 0.0, heap0 = 0.0, resident1 = 0.0, residentGrowth = 0.0, heap1 = 0.0, heapGrowth = 0.0,
               peak = 0.0;
        ASSERT_EQ(std::sscanf(report.c_str(),
                              "soak: %u switches; after the warm-up (%u switches) %lf MiB resident, %lf MiB heap "
                              "in use; at the end %lf MiB resident (%lf), %lf MiB heap in use (%lf); peak %lf MiB "
                              "resident",
                              &switches, &warmUp, &resident0, &heap0, &resident1, &residentGrowth, &heap1,
                              &heapGrowth, &peak),
                  9)
            << "no soak report in stdout: '" << report << "'";
        std::printf("%s\n", report.c_str());
        EXPECT_EQ(switches, SWITCHES);
        EXPECT_GT(warmUp, 10u) << "a pass visits every sample and technique";
        EXPECT_LE(warmUp * 4, SWITCHES) << "too few switches after the warm-up to see a leak";
        EXPECT_GT(heap0, 10.0);
        EXPECT_LE(heap1 - heap0, SOAK_GROWTH_MIB) << report;
        EXPECT_LE(resident1 - resident0, SOAK_GROWTH_MIB) << report;
        EXPECT_GE(peak, resident1);
    }

    // Bad arguments: a message naming the argument, exit 2, nothing written.
    TEST(BrowserArguments, BadArgumentsExitTwo)
    {
        const std::string scene = std::string(TREELOD_SOURCE_DIR) + "/samples/scenes/single-tree.json";
        const std::string shots = outDir() + "/bad";
        std::filesystem::remove_all(shots);
        const std::string badScript = outDir() + "/bad-scene.json";
        {
            std::ofstream out(badScript);
            out << "{\n  \"name\": \"bad\",\n  \"frames\": \"many\"\n}\n";
        }
        const std::pair<std::string, std::string> cases[] = {
            {"--headless --screenshots " + shots + " --size 10x10", "--size"},
            {"--headless --screenshots " + shots + " --frames 0", "--frames"},
            {"--headless", "--screenshots"},
            {"--soak 5", "--soak"},
            {"--headless --soak 5 --shadow-size 1000", "--shadow-size"},
            {"--nosuch", "--nosuch"},
            {"--headless --screenshots " + shots + " --scene /nonexistent/scene.json", "/nonexistent/scene.json"},
            {"--headless --screenshots " + shots + " --tree /nonexistent/tree.glb --scene " + scene, "/nonexistent/tree.glb"},
            {"--headless --screenshots " + shots + " --scene " + badScript, "bad-scene.json"},
        };
        for (const auto& [args, named] : cases)
        {
            std::string errors;
            EXPECT_EQ(runBrowser(args, errors), 2) << args;
            EXPECT_NE(errors.find(named), std::string::npos) << args << ": message does not name " << named << ":\n"
                                                             << errors;
        }
        EXPECT_FALSE(std::filesystem::exists(shots)) << "a refused run wrote screenshots";
        std::string errors;
        EXPECT_EQ(runBrowser("--help", errors), 0);
    }
}
