// SceneScript: the shipped scenes, error positions, placements and the camera path.
#include "TreeLod/SceneScript.h"

#include "TreeLod/ForestInstances.h"
#include "TreeLod/Image.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

namespace TreeLod
{
    namespace
    {
        std::string scenePath(const std::string& name)
        {
            return std::string(TREELOD_SOURCE_DIR) + "/samples/scenes/" + name;
        }

        /// A small valid script; tests replace parts of it.
        const std::string MINIMAL = R"({
  "name": "t",
  "ground": {"kind": "plane", "size": 100},
  "species": [{"name": "a", "source": "preset:oak", "techniques": "auto"}],
  "placements": [{"species": "a", "random": {"seed": 1, "count": 10, "area": {"rect": [-10, -10, 10, 10]}}}],
  "camera": {"keyframes": [{"time": 0, "position": [0, 2, 10], "target": [0, 2, 0]},
                           {"time": 1, "position": [0, 2, 20], "target": [0, 2, 0]}]},
  "resolution": [64, 64],
  "frames": 2
})";

        std::string replaced(std::string text, const std::string& from, const std::string& to)
        {
            std::size_t at = text.find(from);
            EXPECT_NE(at, std::string::npos) << from;
            if (at != std::string::npos)
                text.replace(at, from.size(), to);
            return text;
        }

        /// "line L, column C" of the first occurrence of `needle` (1-based, bytes), counted here
        /// independently of the parser.
        std::string positionOf(const std::string& text, const std::string& needle)
        {
            std::size_t at = text.find(needle), line = 1, column = 1;
            for (std::size_t i = 0; i < at; ++i)
            {
                column = text[i] == '\n' ? 1 : column + 1;
                line += text[i] == '\n';
            }
            return "line " + std::to_string(line) + ", column " + std::to_string(column);
        }

        /// Parses `text`, expects failure; returns the message.
        std::string errorOf(const std::string& text)
        {
            Result<SceneScript> r = parseSceneScript(text, "test.json", "");
            EXPECT_FALSE(r.ok());
            return r.ok() ? std::string() : r.error().message();
        }

        SceneScript parsed(const std::string& text)
        {
            Result<SceneScript> r = parseSceneScript(text, "test.json", "");
            EXPECT_TRUE(r.ok()) << r.error().message();
            return r.ok() ? r.value() : SceneScript();
        }

        /// Mean distance from each point to its nearest neighbour (brute force).
        double meanNearestNeighbour(const std::vector<PlacedTree>& trees)
        {
            double sum = 0.0;
            for (std::size_t i = 0; i < trees.size(); ++i)
            {
                double best = 1e30;
                for (std::size_t j = 0; j < trees.size(); ++j)
                    if (j != i)
                    {
                        glm::vec2 d(trees[i].position.x - trees[j].position.x,
                                    trees[i].position.z - trees[j].position.z);
                        best = std::min(best, double(glm::length(d)));
                    }
                sum += best;
            }
            return sum / double(trees.size());
        }
    }

    TEST(SceneScript, shippedScenesParse)
    {
        for (const char* name : {"single-tree.json", "table2.json", "flythrough-10k.json", "plaza-290.json",
                                 "forest-100k.json", "windy-grove.json"})
        {
            Result<SceneScript> s = loadSceneScript(scenePath(name));
            ASSERT_TRUE(s.ok()) << s.error().message();
            EXPECT_FALSE(s->name.empty()) << name;
            EXPECT_FALSE(s->description.empty()) << name;
            EXPECT_GE(s->camera.keyframes.size(), 2u) << name;
            for (const SceneSpecies& sp : s->species)
                EXPECT_TRUE(!sp.preset.empty() || std::filesystem::is_regular_file(sp.source)) << sp.source;
        }
    }

    TEST(SceneScript, shippedScenesHaveTheirTreeCounts)
    {
        // flythrough: the ellipsoids-and-lines paper's 10 000 plants; plaza: Linz et al. 2006's 290,
        // none on the free square.
        std::vector<PlacedTree> fly = generatePlacements(*loadSceneScript(scenePath("flythrough-10k.json")));
        EXPECT_EQ(fly.size(), 10000u);
        Result<SceneScript> plaza = loadSceneScript(scenePath("plaza-290.json"));
        ASSERT_TRUE(plaza.ok());
        std::vector<PlacedTree> trees = generatePlacements(*plaza);
        EXPECT_EQ(trees.size(), 290u);
        std::vector<int> perSpecies(plaza->species.size(), 0);
        for (const PlacedTree& t : trees)
        {
            EXPECT_FALSE(std::abs(t.position.x) < 30.0f && std::abs(t.position.z) < 30.0f);
            ++perSpecies[t.species];
        }
        for (int n : perSpecies)
            EXPECT_GT(n, 50); // three species mixed, about 97 each
        // Walking height all along the path.
        for (std::uint32_t f = 0; f < plaza->frames; f += 7)
            EXPECT_NEAR(cameraAt(*plaza, frameTime(*plaza, f)).position.y, 1.7f, 1e-3f);
    }

    TEST(SceneScript, shippedCamerasStayAboveGroundAndOutOfTrunks)
    {
        // Splines overshoot: a walk at 1.7 m must not dip under the ground, and a low camera must
        // not pass through a trunk (the flythrough's glade and track keep trees off its path).
        for (const char* name : {"single-tree.json", "table2.json", "flythrough-10k.json", "plaza-290.json",
                                 "forest-100k.json", "windy-grove.json"})
        {
            Result<SceneScript> s = loadSceneScript(scenePath(name));
            ASSERT_TRUE(s.ok()) << s.error().message();
            std::vector<PlacedTree> trees = generatePlacements(*s);
            double lowest = 1e30, closest = 1e30;
            for (std::uint32_t f = 0; f < s->frames; ++f)
            {
                CameraSpec cam = cameraAt(*s, frameTime(*s, f));
                double above = cam.position.y - groundHeight(s->ground, cam.position.x, cam.position.z);
                lowest = std::min(lowest, above);
                EXPECT_GT(glm::length(cam.target - cam.position), 1.0f) << name << " frame " << f;
                if (above > 20.0)
                    continue; // above the crowns
                for (const PlacedTree& t : trees)
                    closest = std::min(closest, double(glm::length(glm::vec2(cam.position.x - t.position.x,
                                                                             cam.position.z - t.position.z))));
            }
            EXPECT_GT(lowest, 1.0) << name;
            EXPECT_GT(closest, 0.5) << name; // single-tree starts 1 m from the trunk
        }
    }

    TEST(SceneScript, mixedWalkDriveWalksThenDrivesBesideItsRoad)
    {
        // Its trees are generated (tools/ez-tree/corpus.sh): parsed here beside empty stand-ins.
        const std::filesystem::path root = std::filesystem::path(TREELOD_BINARY_DIR) / "test-out" / "scene" /
                                           "mixed-walk-drive";
        std::filesystem::create_directories(root / "media" / "third-party");
        std::filesystem::create_directories(root / "samples" / "scenes");
        for (const std::string tree : {"aspen", "oak", "ash", "pine"})
            std::ofstream(root / "media" / "third-party" / ("ez-tree-" + tree + ".glb"));
        std::ifstream in(scenePath("mixed-walk-drive.json"), std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        Result<SceneScript> s = parseSceneScript(text, "mixed-walk-drive.json", (root / "samples" / "scenes").string());
        ASSERT_TRUE(s.ok()) << s.error().message();
        const std::vector<PlacedTree> trees = generatePlacements(*s);
        EXPECT_EQ(trees.size(), 2400u);
        std::vector<int> perSpecies(s->species.size(), 0);
        for (const PlacedTree& t : trees)
        {
            ++perSpecies[t.species];
            EXPECT_GE(std::abs(t.position.z), 8.0f) << "a tree in the clearing";
        }
        for (int n : perSpecies)
            EXPECT_GT(n, 400); // four species mixed, about 600 each

        // 30 frames a second, at 1.7 m; within the clearing (the spline overshoots its keyframes by 0.12 m),
        // at least 2.5 m from every trunk.
        EXPECT_NEAR(frameTime(*s, 1) - frameTime(*s, 0), 1.0 / 30.0, 1e-9);
        EXPECT_EQ(s->lod.transition, 0.2f) << "levels cross-fade on the flythrough";
        for (std::uint32_t f = 0; f < s->frames; ++f)
        {
            const CameraSpec cam = cameraAt(*s, frameTime(*s, f));
            EXPECT_NEAR(cam.position.y, 1.7f, 1e-3f) << "frame " << f;
            EXPECT_LT(std::abs(cam.position.z), 5.5f) << "frame " << f;
        }
        // Walking speed, then driving speed: metres per second over windows of the path.
        const auto speed = [&](double from, double to) {
            double metres = 0.0;
            for (double t = from; t < to - 1e-9; t += 0.1)
                metres += glm::length(cameraAt(*s, std::min(t + 0.1, to)).position - cameraAt(*s, t).position);
            return metres / (to - from);
        };
        EXPECT_NEAR(speed(0.0, 10.0), 1.4, 0.1);
        EXPECT_NEAR(speed(12.0, 32.0), 14.0, 0.5);
    }

    TEST(SceneScript, singleTreeOrbitSpans1mTo2km)
    {
        Result<SceneScript> s = loadSceneScript(scenePath("single-tree.json"));
        ASSERT_TRUE(s.ok()) << s.error().message();
        std::vector<PlacedTree> trees = generatePlacements(*s);
        ASSERT_EQ(trees.size(), 1u);
        const glm::vec3 crown = trees[0].position + glm::vec3(0.0f, 6.0f, 0.0f);
        double nearest = 1e30, farthest = 0.0, previous = 0.0;
        int decreases = 0;
        for (std::uint32_t f = 0; f < s->frames; ++f)
        {
            CameraSpec cam = cameraAt(*s, frameTime(*s, f));
            double d = glm::length(cam.position - crown);
            nearest = std::min(nearest, d);
            farthest = std::max(farthest, d);
            decreases += f > 0 && d < previous;
            previous = d;
            EXPECT_LT(glm::length(cam.target - crown), 1e-4f); // always looking at the crown
            EXPECT_GT(cam.farClip, d);
        }
        EXPECT_NEAR(nearest, 1.0, 0.02);
        EXPECT_NEAR(farthest, 2000.0, 2.0);
        EXPECT_LT(decreases, int(s->frames) / 20); // an outward spiral, not back and forth
    }

    TEST(SceneScript, table2CountSweep)
    {
        Result<SceneScript> s = loadSceneScript(scenePath("table2.json"));
        ASSERT_TRUE(s.ok()) << s.error().message();
        ASSERT_EQ(s->counts, (std::vector<std::uint32_t>{1, 50, 100, 1000, 10000}));
        for (std::uint32_t n : s->counts)
        {
            PlacementOptions o;
            o.totalCount = n;
            std::vector<PlacedTree> trees = generatePlacements(*s, o);
            ASSERT_EQ(trees.size(), n);
            EXPECT_EQ(trees[0].position, glm::vec3(0.0f)); // the explicit tree in front of the camera
        }
        // --scale 0.1 thins the forest in the same area and keeps the origin tree.
        PlacementOptions o;
        o.totalCount = 10000;
        o.scale = 0.1;
        std::vector<PlacedTree> scaled = generatePlacements(*s, o);
        EXPECT_EQ(scaled.size(), 1u + 1000u);
        float minZ = 0.0f;
        for (const PlacedTree& t : scaled)
            minZ = std::min(minZ, t.position.z);
        EXPECT_LT(minZ, -500.0f); // still reaching the forest's far edge (-560)
    }

    TEST(SceneScript, syntaxErrorGivesLineAndColumn)
    {
        // The missing comma: the error shows at the last character read, the closing quote of
        // the next key ("frames" spans columns 3 to 10 of line 3).
        std::string text = "{\n  \"name\": \"t\"\n  \"frames\": 2\n}";
        std::string message = errorOf(text);
        EXPECT_EQ(message.rfind("test.json: line 3, column 10: ", 0), 0u) << message;
        EXPECT_NE(message.find("syntax error"), std::string::npos) << message;

        // A number beyond a double and, after it, a line feed inside a string: nlohmann stops at
        // the number, the first error in the text (found by FuzzSceneScript).
        text = replaced(replaced(MINIMAL, "\"size\": 100", "\"size\": 1e999"), "\"frames\": 2",
                        "\"frames\": 2, \"description\": \"a\nb\"");
        message = errorOf(text);
        EXPECT_EQ(message, "test.json: line 3, column 39: 1e999 is not a finite number (beyond the range of a double)");
        // ... and a text that ends inside an object after it (the position scan stays in bounds).
        text = replaced(MINIMAL, "\"size\": 100", "\"size\": 1e999");
        text.resize(text.find("\"frames\"") + 3);
        EXPECT_EQ(errorOf(text), "test.json: line 3, column 39: 1e999 is not a finite number (beyond the range of a double)");
    }

    TEST(SceneScript, semanticErrorsNameLineColumnAndKey)
    {
        struct Case
        {
            std::string from, to;   ///< edit of MINIMAL
            std::string at;         ///< text whose start the error must point at
            std::string key;        ///< JSON pointer in the message
            std::string reason;     ///< part of the reason
        };
        const std::vector<Case> cases = {
            // missing key: reported at the key of the object that lacks it
            {"\"kind\": \"plane\", ", "", "\"ground\"", "/ground/kind", "missing required key"},
            // wrong type
            {"\"size\": 100", "\"size\": \"big\"", "\"size\"", "/ground/size", "expected a number, got string"},
            {"\"frames\": 2", "\"frames\": 2.5", "\"frames\"", "/frames", "expected an integer"},
            // unknown key (a typo)
            {"\"seed\": 1,", "\"sead\": 1,", "\"sead\"", "/placements/0/random/sead", "unknown key 'sead'"},
            // keyframe times must increase
            {"\"time\": 1", "\"time\": 0", "\"time\": 0, \"position\": [0, 2, 20]", "/camera/keyframes/1/time",
             "greater than the previous keyframe's time"},
            // negative density
            {"\"count\": 10", "\"density\": -5", "\"density\"", "/placements/0/random/density", "must be > 0"},
            // a duplicate key (nlohmann alone would keep the last silently)
            {"\"frames\": 2", "\"frames\": 2, \"frames\": 3", "\"frames\": 3", "/frames", "duplicate key"},
            // unknown species, technique name syntax, area outside the ground
            {"\"species\": \"a\"", "\"species\": \"b\"", "\"species\": \"b\"", "/placements/0/species",
             "no species named 'b'"},
            {"\"techniques\": \"auto\"", "\"techniques\": [{\"technique\": \"Bill Board\"}]", "\"technique\":",
             "/species/0/techniques/0/technique", "not a technique name"},
            {"[-10, -10, 10, 10]", "[-10, -10, 10, 60]", "60", "/placements/0/random/area/rect/3", "<= 50"},
            // the shadow casters' LoD bias (Forest::setShadowLodBias)
            {"\"frames\": 2", "\"frames\": 2, \"shadows\": {\"enabled\": true, \"lodBias\": 0}", "\"lodBias\"",
             "/shadows/lodBias", "must be > 0"},
            {"\"frames\": 2", "\"frames\": 2, \"shadows\": {\"enabled\": true, \"lodBias\": \"low\"}", "\"lodBias\"",
             "/shadows/lodBias", "expected a number"},
            // a sun above the horizon only before rounding to floats
            {"\"frames\": 2", "\"frames\": 2, \"sun\": {\"azimuth\": 0, \"elevation\": 1e-300}", "\"elevation\"",
             "/sun/elevation", "rounds to the horizon"},
            {"\"frames\": 2", "\"frames\": 2, \"sun\": {\"direction\": [1e9, 1e-38, 0]}", "\"direction\"",
             "/sun/direction", "above the horizon"},
            {"\"frames\": 2", "\"frames\": 2, \"sun\": {\"direction\": [0, 0, 0]}", "\"direction\"",
             "/sun/direction", "zero vector"},
        };
        for (const Case& c : cases)
        {
            std::string text = replaced(MINIMAL, c.from, c.to);
            std::string message = errorOf(text);
            std::string expected = "test.json: " + positionOf(text, c.at) + ", key " + c.key + ": ";
            EXPECT_EQ(message.rfind(expected, 0), 0u) << "expected '" << expected << "' in\n" << message;
            EXPECT_NE(message.find(c.reason), std::string::npos) << message;
        }
    }

    TEST(SceneScript, keyPositionsFollowTheJsonReader)
    {
        // Comments end where nlohmann ends them (a carriage return, a NUL), and a byte order
        // mark is skipped: the key positions must not lose step with the parsed JSON.
        std::string crOnly = "{ // carriage returns only\r" + MINIMAL.substr(1);
        std::replace(crOnly.begin(), crOnly.end(), '\n', '\r');
        EXPECT_EQ(parsed(crOnly).name, "t");
        EXPECT_EQ(parsed(std::string("{ // ends at a NUL") + '\0' + MINIMAL.substr(1)).name, "t");

        const std::string bom = "\xEF\xBB\xBF" + replaced(MINIMAL, "\"size\": 100", "\"size\": \"big\"");
        const std::string message = errorOf(bom);
        EXPECT_EQ(message.rfind("test.json: " + positionOf(bom, "\"size\"") + ", key /ground/size: ", 0), 0u) << message;
    }

    TEST(SceneScript, shadowsTakeACasterLodBias)
    {
        Result<SceneScript> plain = parseSceneScript(
            replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"shadows\": {\"enabled\": true}"), "test.json", "");
        ASSERT_TRUE(plain.ok()) << plain.error().message();
        EXPECT_EQ(plain->shadows.lodBias, 1.0f);
        Result<SceneScript> coarse = parseSceneScript(
            replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"shadows\": {\"enabled\": true, \"lodBias\": 0.25}"),
            "test.json", "");
        ASSERT_TRUE(coarse.ok()) << coarse.error().message();
        EXPECT_EQ(coarse->shadows.lodBias, 0.25f);
    }

    TEST(SceneScript, windIsCalmByDefaultAndCheckedByKey)
    {
        EXPECT_TRUE(parsed(MINIMAL).wind.calm());
        const SceneScript windy = parsed(replaced(
            MINIMAL, "\"frames\": 2",
            "\"frames\": 2, \"wind\": {\"strength\": 1.5, \"direction\": [3, 4], \"gustiness\": 0.2, \"gustWavelength\": 80}"));
        EXPECT_EQ(windy.wind.strength, 1.5f);
        EXPECT_NEAR(windy.wind.direction.x, 0.6f, 1e-6f);
        EXPECT_NEAR(windy.wind.direction.y, 0.8f, 1e-6f);
        EXPECT_EQ(windy.wind.gustiness, 0.2f);
        EXPECT_EQ(windy.wind.gustWavelength, 80.0f);
        EXPECT_TRUE(windy.wind.validate().ok());
        for (const auto& [wind, key] : {std::pair<std::string, std::string>("{\"direction\": [1, 0]}", "/wind/strength"),
                                        {"{\"strength\": -1}", "/wind/strength"},
                                        {"{\"strength\": 1, \"direction\": [0, 0]}", "/wind/direction"},
                                        {"{\"strength\": 1, \"direction\": [1, 0, 0]}", "/wind/direction"},
                                        {"{\"strength\": 1, \"gustiness\": 2}", "/wind/gustiness"},
                                        {"{\"strength\": 1, \"gustWavelength\": 0}", "/wind/gustWavelength"},
                                        {"{\"strength\": 1, \"speed\": 2}", "/wind/speed"}})
        {
            const std::string message = errorOf(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"wind\": " + wind));
            EXPECT_NE(message.find(key), std::string::npos) << wind << ": " << message;
        }
        const SceneScript grove = *loadSceneScript(scenePath("windy-grove.json"));
        EXPECT_EQ(grove.wind.strength, 1.5f);
    }

    TEST(SceneScript, lodTakesAnErrorBudget)
    {
        EXPECT_EQ(parsed(MINIMAL).lod.maxError, SceneLod::DEFAULT_MAX_ERROR);
        EXPECT_EQ(parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {\"maxError\": 0.05}")).lod.maxError,
                  0.05f);
        EXPECT_EQ(parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {}")).lod.maxError,
                  SceneLod::DEFAULT_MAX_ERROR);
        for (const char* bad : {"{\"maxError\": 1.5}", "{\"maxError\": -0.1}", "{\"maxError\": \"low\"}"})
        {
            const std::string message =
                errorOf(replaced(MINIMAL, "\"frames\": 2", std::string("\"frames\": 2, \"lod\": ") + bad));
            EXPECT_NE(message.find("/lod/maxError"), std::string::npos) << message;
        }
        const std::string unknown =
            errorOf(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {\"maxErr\": 0.1}"));
        EXPECT_NE(unknown.find("maxErr"), std::string::npos) << unknown;

        // The shadow casters' budget and the frame budget.
        const SceneScript both = parsed(replaced(MINIMAL, "\"frames\": 2",
                                                 "\"frames\": 2, \"lod\": {\"shadowMaxError\": 0.2, \"frameBudgetMs\": 16}"));
        EXPECT_EQ(both.lod.shadowMaxError, 0.2f);
        EXPECT_EQ(both.lod.frameBudgetMs, 16.0f);
        EXPECT_EQ(both.lod.maxError, SceneLod::DEFAULT_MAX_ERROR);
        EXPECT_EQ(parsed(MINIMAL).lod.shadowMaxError, SceneLod::DEFAULT_SHADOW_MAX_ERROR);
        EXPECT_EQ(parsed(MINIMAL).lod.frameBudgetMs, 0.0f);
        // The memory budget, megabytes.
        EXPECT_EQ(parsed(MINIMAL).lod.memoryBudgetMB, 0.0f);
        EXPECT_EQ(parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {\"memoryBudgetMB\": 48.5}"))
                      .lod.memoryBudgetMB,
                  48.5f);
        // Occlusion, on unless turned off.
        EXPECT_TRUE(parsed(MINIMAL).lod.occlusion);
        EXPECT_FALSE(parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {\"occlusion\": false}")).lod.occlusion);
        // Level transitions.
        EXPECT_EQ(parsed(MINIMAL).lod.transition, ForestInstances::DEFAULT_TRANSITION);
        EXPECT_EQ(parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"lod\": {\"transition\": 0.3}")).lod.transition,
                  0.3f);
        for (const auto& [bad, key] : {std::pair<const char*, const char*>{"{\"shadowMaxError\": 2}", "/lod/shadowMaxError"},
                                      {"{\"transition\": -0.1}", "/lod/transition"},
                                      {"{\"transition\": 1.5}", "/lod/transition"},
                                      {"{\"transition\": \"smooth\"}", "/lod/transition"},
                                      {"{\"frameBudgetMs\": -1}", "/lod/frameBudgetMs"},
                                      {"{\"frameBudgetMs\": \"fast\"}", "/lod/frameBudgetMs"},
                                      {"{\"memoryBudgetMB\": -5}", "/lod/memoryBudgetMB"},
                                      {"{\"memoryBudgetMB\": 2e9}", "/lod/memoryBudgetMB"},
                                      {"{\"occlusion\": 1}", "/lod/occlusion"}})
        {
            const std::string message =
                errorOf(replaced(MINIMAL, "\"frames\": 2", std::string("\"frames\": 2, \"lod\": ") + bad));
            EXPECT_NE(message.find(key), std::string::npos) << message;
        }
    }

    TEST(SceneScript, techniqueBandsParseAndMustBeOrdered)
    {
        SceneScript s = parsed(replaced(MINIMAL, "\"techniques\": \"auto\"",
                                        "\"techniques\": [{\"technique\": \"mesh\", \"maxDistance\": 20}, "
                                        "{\"technique\": \"lodf\", \"maxDistance\": 200}, "
                                        "{\"technique\": \"billboard-cloud\"}]"));
        ASSERT_EQ(s.species.size(), 1u);
        EXPECT_FALSE(s.species[0].autoTechnique);
        ASSERT_EQ(s.species[0].bands.size(), 3u);
        EXPECT_EQ(s.species[0].bands[1].technique, "lodf");
        EXPECT_EQ(s.species[0].bands[1].maxDistance, 200.0f);
        EXPECT_EQ(s.species[0].bands[2].maxDistance, 0.0f); // open-ended

        std::string message = errorOf(replaced(MINIMAL, "\"techniques\": \"auto\"",
                                               "\"techniques\": [{\"technique\": \"mesh\", \"maxDistance\": 20}, "
                                               "{\"technique\": \"lodf\", \"maxDistance\": 10}]"));
        EXPECT_NE(message.find("key /species/0/techniques/1/maxDistance"), std::string::npos) << message;
        message = errorOf(replaced(MINIMAL, "\"techniques\": \"auto\"",
                                   "\"techniques\": [{\"technique\": \"mesh\", \"maxDistance\": 20}, "
                                   "{\"technique\": \"lodf\", \"minPixels\": 10}]"));
        EXPECT_NE(message.find("same measure"), std::string::npos) << message;
    }

    TEST(SceneScript, sceneBoundsAreErrorsAtThePlacementThatPassesThem)
    {
        // 10,000,000 trees and 64 exclusion areas in all placements together (SceneScript.h).
        const std::string first = "\"count\": 10, \"area\": {\"rect\": [-10, -10, 10, 10]}}}";
        auto twoPlacements = [&](const std::string& count0, const std::string& random1) {
            return replaced(MINIMAL, first,
                            "\"count\": " + count0 + ", \"area\": {\"rect\": [-10, -10, 10, 10]}}}, "
                            "{\"species\": \"a\", \"random\": {\"seed\": 2, " + random1 + "}}");
        };
        const std::string area = "\"area\": {\"rect\": [-10, -10, 10, 10]}";
        EXPECT_EQ(parsed(twoPlacements("9999998", "\"count\": 2, " + area)).placements.size(), 2u);

        std::string text = twoPlacements("9999999", "\"count\": 2, " + area);
        std::string message = errorOf(text);
        EXPECT_EQ(message.rfind("test.json: " + positionOf(text, "\"count\": 2") +
                                    ", key /placements/1/random/count: the placements add up to 10000001 trees "
                                    "(2 here), more than 10000000",
                                0),
                  0u)
            << message;
        // 50 trees per hectare of 400 m²: 2 trees, reported at the density
        text = twoPlacements("9999999", "\"density\": 50, " + area);
        message = errorOf(text);
        EXPECT_NE(message.find(positionOf(text, "\"density\"") + ", key /placements/1/random/density: the "
                                                                   "placements add up to 10000001 trees"),
                  std::string::npos)
            << message;

        auto exclusions = [](int n) {
            std::string list;
            for (int i = 0; i < n; ++i)
                list += std::string(i ? ", " : "") + "{\"disc\": [0, 0, 1]}";
            return "\"exclude\": [" + list + "]";
        };
        EXPECT_EQ(parsed(twoPlacements("10, " + exclusions(40), "\"count\": 2, " + area + ", " + exclusions(24)))
                      .placements[1]
                      .exclude.size(),
                  24u);
        text = twoPlacements("10, " + exclusions(40), "\"count\": 2, " + area + ", " + exclusions(25));
        message = errorOf(text);
        // at the second placement's "exclude" (the first's comes earlier on the same line)
        const std::string firstExclude = positionOf(text, "\"exclude\"");
        const std::size_t column = std::stoul(firstExclude.substr(firstExclude.find("column ") + 7)) +
                                   (text.find("\"exclude\"", text.find("\"seed\": 2")) - text.find("\"exclude\""));
        EXPECT_EQ(message.rfind("test.json: " + firstExclude.substr(0, firstExclude.find("column ")) + "column " +
                                    std::to_string(column) +
                                    ", key /placements/1/random/exclude: the placements exclude 65 areas in all "
                                    "(25 here), more than 64",
                                0),
                  0u)
            << message;
    }

    TEST(SceneScript, missingFileNamesThePath)
    {
        Result<SceneScript> r = loadSceneScript("/nonexistent/scene.json");
        ASSERT_FALSE(r.ok());
        EXPECT_NE(r.error().message().find("/nonexistent/scene.json"), std::string::npos);
        std::string message = errorOf(replaced(MINIMAL, "\"preset:oak\"", "\"no-such-tree.glb\""));
        EXPECT_NE(message.find("key /species/0/source: no such file"), std::string::npos) << message;
    }

    TEST(SceneScript, placementsAreDeterministicInsideTheAreaAndCounted)
    {
        SceneScript s = parsed(replaced(MINIMAL, "\"count\": 10", "\"count\": 500"));
        std::vector<PlacedTree> a = generatePlacements(s), b = generatePlacements(s);
        ASSERT_EQ(a.size(), 500u);
        for (std::size_t i = 0; i < a.size(); ++i)
        {
            EXPECT_EQ(a[i].position, b[i].position);
            EXPECT_EQ(a[i].rotation, b[i].rotation);
            EXPECT_TRUE(std::abs(a[i].position.x) <= 10.0f && std::abs(a[i].position.z) <= 10.0f);
            EXPECT_EQ(a[i].position.y, 0.0f);
            EXPECT_TRUE(a[i].rotation >= 0.0f && a[i].rotation < 6.2832f);
        }
        // Another seed, other trees.
        SceneScript other = parsed(replaced(replaced(MINIMAL, "\"count\": 10", "\"count\": 500"), "\"seed\": 1",
                                            "\"seed\": 2"));
        EXPECT_NE(generatePlacements(other)[0].position, a[0].position);

        // Density: trees per hectare of the free area. A 100 m disc with a 50 m hole: 2.356 ha.
        std::string ringText = replaced(replaced(MINIMAL, "\"count\": 10", "\"density\": 120"),
                                        "\"area\": {\"rect\": [-10, -10, 10, 10]}",
                                        "\"area\": {\"disc\": [0, 0, 100]}, "
                                        "\"exclude\": [{\"disc\": [0, 0, 50]}], \"clumping\": 0.5");
        SceneScript d = parsed(replaced(ringText, "\"size\": 100", "\"size\": 300"));
        std::vector<PlacedTree> ring = generatePlacements(d);
        const double freeHa = 3.14159265 * (100.0 * 100.0 - 50.0 * 50.0) / 10000.0;
        // The free area is estimated on a 512^2 grid: allow 1 %.
        EXPECT_NEAR(double(ring.size()), 120.0 * freeHa, 0.01 * 120.0 * freeHa);
        for (const PlacedTree& t : ring)
        {
            float r = glm::length(glm::vec2(t.position.x, t.position.z));
            EXPECT_TRUE(r >= 50.0f && r <= 100.0f) << r;
        }
    }

    TEST(SceneScript, clumpingShrinksNearestNeighbourDistances)
    {
        // Clark-Evans: for n uniform points on area A the mean nearest-neighbour distance is
        // about 0.5 / sqrt(n / A) (a little more at the edges). Clumping must pull it far below.
        const std::string base = replaced(replaced(MINIMAL, "\"count\": 10", "\"count\": 800"),
                                          "[-10, -10, 10, 10]", "[-40, -40, 40, 40]");
        const double expected = 0.5 / std::sqrt(800.0 / (80.0 * 80.0));
        std::vector<PlacedTree> uniform = generatePlacements(parsed(base));
        double uniformNN = meanNearestNeighbour(uniform);
        EXPECT_NEAR(uniformNN, expected, 0.12 * expected);
        double previous = uniformNN;
        for (const char* c : {"0.3", "0.6", "1"})
        {
            std::string text = replaced(base, "\"count\": 800", std::string("\"count\": 800, \"clumping\": ") + c);
            std::vector<PlacedTree> clumped = generatePlacements(parsed(text));
            ASSERT_EQ(clumped.size(), 800u);
            double nn = meanNearestNeighbour(clumped);
            EXPECT_LT(nn, previous) << "clumping " << c;
            previous = nn;
        }
        EXPECT_LT(previous, 0.5 * uniformNN);
    }

    TEST(SceneScript, explicitPositionsAndSpeciesMix)
    {
        std::string text = replaced(MINIMAL, "{\"species\": \"a\", \"random\"",
                                    "{\"species\": \"a\", \"positions\": [[1, 2], [3, 4, 90, 2]]}, "
                                    "{\"species\": [\"a\", \"b\"], \"random\"");
        text = replaced(text, "\"techniques\": \"auto\"}",
                        "\"techniques\": \"auto\"}, {\"name\": \"b\", \"source\": \"preset:birch\", "
                        "\"techniques\": \"auto\", \"scale\": [2, 3]}");
        SceneScript s = parsed(text);
        std::vector<PlacedTree> trees = generatePlacements(s);
        ASSERT_EQ(trees.size(), 12u);
        EXPECT_EQ(trees[1].position, glm::vec3(3, 0, 4));
        EXPECT_NEAR(trees[1].rotation, 3.14159265f / 2.0f, 1e-6f);
        EXPECT_EQ(trees[1].scale, 2.0f);
        EXPECT_EQ(trees[0].scale, 1.0f);
        int speciesB = 0;
        for (std::size_t i = 2; i < trees.size(); ++i)
        {
            speciesB += trees[i].species == 1;
            const float lo = trees[i].species == 1 ? 2.0f : 1.0f, hi = trees[i].species == 1 ? 3.0f : 1.0f;
            EXPECT_TRUE(trees[i].scale >= lo && trees[i].scale <= hi);
        }
        EXPECT_TRUE(speciesB > 0 && speciesB < 10); // both species drawn (P(all one) = 2 * 2^-10)
        // The sweep keeps explicit trees first: a total of 1 is the first explicit tree.
        PlacementOptions one;
        one.totalCount = 1;
        ASSERT_EQ(generatePlacements(s, one).size(), 1u);
        EXPECT_EQ(generatePlacements(s, one)[0].position, glm::vec3(1, 0, 2));
    }

    TEST(SceneScript, cameraPassesThroughKeyframesAndIsContinuous)
    {
        std::string text = replaced(MINIMAL, "{\"time\": 1, \"position\": [0, 2, 20], \"target\": [0, 2, 0]}",
                                    "{\"time\": 1, \"position\": [0, 2, 20], \"target\": [0, 2, 0]},"
                                    "{\"time\": 3, \"position\": [40, 30, -5], \"target\": [1, 2, 0]},"
                                    "{\"time\": 3.5, \"position\": [41, 30, -5], \"target\": [1, 2, 0]},"
                                    "{\"time\": 10, \"position\": [500, 80, 900], \"target\": [3, 5, 7]}");
        SceneScript s = parsed(text);
        for (const SceneKeyframe& k : s.camera.keyframes)
        {
            CameraSpec c = cameraAt(s, k.time);
            EXPECT_EQ(c.position, k.position) << k.time;
            EXPECT_EQ(c.target, k.target) << k.time;
        }
        // Clamped outside the path.
        EXPECT_EQ(cameraAt(s, -5.0).position, s.camera.keyframes.front().position);
        EXPECT_EQ(cameraAt(s, 50.0).position, s.camera.keyframes.back().position);
        // Continuous: 10^4 steps of 1 ms; no step moves more than a few times the path's
        // fastest average keyframe-to-keyframe speed (about 160 m/s here) would allow.
        double maxStep = 0.0;
        glm::vec3 previous = cameraAt(s, 0.0).position;
        for (int i = 1; i <= 10000; ++i)
        {
            glm::vec3 p = cameraAt(s, i * 1e-3).position;
            maxStep = std::max(maxStep, double(glm::length(p - previous)));
            previous = p;
        }
        EXPECT_LT(maxStep, 3.0 * 160.0 * 1e-3);
        EXPECT_GT(maxStep, 0.0);
        // Not linear: between keyframes the spline leaves the chord.
        glm::vec3 mid = cameraAt(s, 2.0).position;
        glm::vec3 chordMid = 0.5f * (s.camera.keyframes[1].position + s.camera.keyframes[2].position);
        EXPECT_GT(glm::length(mid - chordMid), 0.1f);
        s.camera.linear = true;
        EXPECT_LT(glm::length(cameraAt(s, 2.0).position - chordMid), 1e-4f);
    }

    TEST(SceneScript, framesSpreadOverThePath)
    {
        SceneScript s = parsed(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 5"));
        EXPECT_EQ(frameTime(s, 0), 0.0);
        EXPECT_EQ(frameTime(s, 2), 0.5);
        EXPECT_EQ(frameTime(s, 4), 1.0);
        EXPECT_EQ(frameTime(s, 99), 1.0);
        EXPECT_EQ(frameTime(s, 1, 3), 0.5); // --frames 3
        EXPECT_EQ(frameTime(s, 0, 1), 0.0);
    }

    TEST(SceneScript, heightfieldGivesTreesTheirHeight)
    {
        const char* env = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path dir = std::filesystem::path(env && *env ? env : TREELOD_BINARY_DIR "/test-out") /
                                    "scene";
        std::filesystem::create_directories(dir);
        // A ramp in both directions: grey = (column + 4 row) / 11 over 4 x 3 pixels. Columns span
        // x and rows z over the 100 m square (row 0 at z = -50), so with u = x / 100 + 0.5 and
        // v = z / 100 + 0.5, height = 30 * (3u + 8v) / 11.
        Image ramp(4, 3);
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x)
                ramp.at(x, y) = glm::vec4(glm::vec3((x + 4.0f * y) / 11.0f), 1.0f);
        auto expected = [](float x, float z) {
            return 30.0f * (3.0f * (x / 100.0f + 0.5f) + 8.0f * (z / 100.0f + 0.5f)) / 11.0f;
        };
        ASSERT_TRUE(writePng((dir / "ramp.png").string(), ramp).ok());
        std::string text = replaced(MINIMAL, "{\"kind\": \"plane\", \"size\": 100}",
                                    "{\"kind\": \"heightfield\", \"size\": 100, \"image\": \"ramp.png\", "
                                    "\"heightScale\": 30}");
        Result<SceneScript> r = parseSceneScript(text, "test.json", dir.string(), readGreyImage);
        ASSERT_TRUE(r.ok()) << r.error().message();
        ASSERT_EQ(r->ground.heightsWidth, 4);
        ASSERT_EQ(r->ground.heightsHeight, 3);
        for (const PlacedTree& t : generatePlacements(*r))
            // 8-bit PNG: grey steps of 1/255 of 30 m.
            EXPECT_NEAR(t.position.y, expected(t.position.x, t.position.z), 30.0f / 255.0f);
        // Rows run along z, row 0 at -z: the corners, the middle row, and halfway between rows.
        EXPECT_NEAR(groundHeight(r->ground, -50.0f, -50.0f), 0.0f, 1e-6f);
        EXPECT_NEAR(groundHeight(r->ground, 50.0f, 50.0f), 30.0f, 1e-6f);
        EXPECT_NEAR(groundHeight(r->ground, -50.0f, 50.0f), 30.0f * 8.0f / 11.0f, 30.0f / 255.0f);
        EXPECT_NEAR(groundHeight(r->ground, 50.0f, -50.0f), 30.0f * 3.0f / 11.0f, 30.0f / 255.0f);
        EXPECT_NEAR(groundHeight(r->ground, -50.0f, 0.0f), 30.0f * 4.0f / 11.0f, 30.0f / 255.0f);
        EXPECT_NEAR(groundHeight(r->ground, -50.0f, -25.0f), 30.0f * 2.0f / 11.0f, 30.0f / 255.0f);
        EXPECT_NEAR(groundHeight(r->ground, 10.0f, 30.0f), expected(10.0f, 30.0f), 30.0f / 255.0f);
        // Clamped at the edges.
        EXPECT_NEAR(groundHeight(r->ground, -80.0f, -70.0f), 0.0f, 1e-6f);
        EXPECT_NEAR(groundHeight(r->ground, -80.0f, 0.0f), groundHeight(r->ground, -50.0f, 0.0f), 1e-6f);
        EXPECT_NEAR(groundHeight(r->ground, 0.0f, 90.0f), groundHeight(r->ground, 0.0f, 50.0f), 1e-6f);

        std::string message = errorOf(replaced(text, "ramp.png", "missing.png"));
        EXPECT_NE(message.find("key /ground/image"), std::string::npos) << message;
        // No reader injected (the default): the script says where and why.
        Result<SceneScript> unread = parseSceneScript(text, "test.json", dir.string());
        ASSERT_FALSE(unread.ok());
        message = unread.error().message();
        EXPECT_EQ(message.rfind("test.json: " + positionOf(text, "\"image\"") + ", key /ground/image: ", 0), 0u)
            << message;
        EXPECT_NE(message.find("no image reader given ("), std::string::npos) << message;
        // A reader's values outside [0, 1] are refused, not turned into heights.
        GreyImageReader wild = [](const std::string&) {
            return Result<GreyImage>(GreyImage{2, 2, {0.0f, 0.5f, 2.0f, 1.0f}});
        };
        Result<SceneScript> wrong = parseSceneScript(text, "test.json", dir.string(), wild);
        ASSERT_FALSE(wrong.ok());
        EXPECT_NE(wrong.error().message().find("outside [0, 1]: 2"), std::string::npos) << wrong.error().message();
    }

    // docs/scene-format.md: azimuth 0 is the +Z side, 90 the +X side; elevation above the horizon.
    TEST(SceneScript, sunAzimuthAndElevationGiveTheDocumentedDirection)
    {
        std::string text = replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"sun\": {\"azimuth\": 90, "
                                                          "\"elevation\": 30, \"colour\": [1, 0.5, 0.25]}");
        Result<SceneScript> r = parseSceneScript(text, "test.json", ".");
        ASSERT_TRUE(r.ok()) << r.error().message();
        const LightingSpec lighting = sceneLighting(*r);
        EXPECT_NEAR(lighting.sunDirection.x, std::sqrt(3.0f) / 2.0f, 1e-6f);
        EXPECT_NEAR(lighting.sunDirection.y, 0.5f, 1e-6f);
        EXPECT_NEAR(lighting.sunDirection.z, 0.0f, 1e-6f);
        EXPECT_EQ(lighting.sunColour, glm::vec3(1.0f, 0.5f, 0.25f));
        EXPECT_EQ(lighting.ambientColour, SceneSun().ambient);

        // Azimuth 0 is the +Z side.
        r = parseSceneScript(replaced(text, "\"azimuth\": 90", "\"azimuth\": 0"), "test.json", ".");
        ASSERT_TRUE(r.ok()) << r.error().message();
        EXPECT_NEAR(sceneLighting(*r).sunDirection.x, 0.0f, 1e-6f);
        EXPECT_NEAR(sceneLighting(*r).sunDirection.z, std::sqrt(3.0f) / 2.0f, 1e-6f);

        // A direction too short for floats is normalised in doubles (FuzzSceneScript found NaN here).
        r = parseSceneScript(replaced(MINIMAL, "\"frames\": 2", "\"frames\": 2, \"sun\": {\"direction\": [0, 1e-38, 0]}"),
                             "test.json", ".");
        ASSERT_TRUE(r.ok()) << r.error().message();
        EXPECT_EQ(sceneLighting(*r).sunDirection, glm::vec3(0.0f, 1.0f, 0.0f));
    }

    namespace
    {
        std::filesystem::path testDir(const std::string& name)
        {
            const char* env = std::getenv("TREELOD_TEST_OUT");
            std::filesystem::path dir =
                std::filesystem::path(env && *env ? env : TREELOD_BINARY_DIR "/test-out") / "scene" / name;
            std::filesystem::create_directories(dir);
            return dir;
        }

        /// MINIMAL with species a (oak) and b (birch, scale 2) placed from `file` next to the script.
        std::string withInstanceFile(const std::string& file = "trees.csv")
        {
            std::string text = replaced(MINIMAL, "\"techniques\": \"auto\"}",
                                        "\"techniques\": \"auto\"}, {\"name\": \"b\", \"source\": \"preset:birch\", "
                                        "\"techniques\": \"auto\", \"scale\": 2}");
            return replaced(text, "{\"species\": \"a\", \"random\": {\"seed\": 1, \"count\": 10, \"area\": {\"rect\": [-10, -10, 10, 10]}}}",
                            "{\"species\": [\"a\", \"b\"], \"file\": \"" + file + "\"}");
        }

        /// Writes `csv` as trees.csv beside a script placing it; the parse result.
        Result<SceneScript> parseWithCsv(const std::string& name, const std::string& csv)
        {
            std::filesystem::path dir = testDir(name);
            std::ofstream(dir / "trees.csv", std::ios::binary) << csv;
            return parseSceneScript(withInstanceFile(), "test.json", dir.string());
        }
    }

    TEST(SceneScript, explicitScaleZeroIsRefusedAtItsPosition)
    {
        for (const char* scale : {"0", "-1"})
        {
            std::string text = replaced(MINIMAL, "\"random\": {\"seed\": 1, \"count\": 10, \"area\": {\"rect\": [-10, -10, 10, 10]}}",
                                        std::string("\"positions\": [[1, 2, 0, 1], [3, 4, 90, ") + scale + "]]");
            std::string message = errorOf(text);
            std::string expected = "test.json: " + positionOf(text, std::string(scale) + "]]") +
                                   ", key /placements/0/positions/1/3: must be > 0";
            EXPECT_EQ(message.rfind(expected, 0), 0u) << "expected '" << expected << "' in\n" << message;
        }
    }

    TEST(SceneScript, instanceFileGivesSpeciesRotationScaleAndHeight)
    {
        const std::string csv = "# trees of the test\n"
                                "x, z, species, rotation, scale, y\n"
                                "\n"
                                "1.5,-2,b,90,0.5,3\n"
                                "# a comment between rows\n"
                                "-4,5.25,a,-45,2,-1.5\r\n"
                                "+10,1e1,b,0,1e0,0\n";
        Result<SceneScript> r = parseWithCsv("csv-full", csv);
        ASSERT_TRUE(r.ok()) << r.error().message();
        ASSERT_EQ(r->placements.size(), 1u);
        EXPECT_FALSE(r->placements[0].random);
        EXPECT_NE(r->placements[0].file.find("trees.csv"), std::string::npos);
        std::vector<PlacedTree> trees = generatePlacements(*r);
        ASSERT_EQ(trees.size(), 3u);
        EXPECT_EQ(trees[0].species, 1u);
        EXPECT_EQ(trees[0].position, glm::vec3(1.5f, 3.0f, -2.0f));
        EXPECT_NEAR(trees[0].rotation, 3.14159265f / 2.0f, 1e-6f);
        EXPECT_EQ(trees[0].scale, 0.5f); // the file's scale, not the species' [2, 2]
        EXPECT_EQ(trees[1].species, 0u);
        EXPECT_EQ(trees[1].position, glm::vec3(-4.0f, -1.5f, 5.25f));
        EXPECT_NEAR(trees[1].rotation, -3.14159265f / 4.0f, 1e-6f);
        EXPECT_EQ(trees[2].position, glm::vec3(10.0f, 0.0f, 10.0f));

        // Optional columns left out: the placement's first species, no rotation, scale 1, on the ground.
        r = parseWithCsv("csv-minimal", "z,x\n7,8\n-7,-8\n");
        ASSERT_TRUE(r.ok()) << r.error().message();
        trees = generatePlacements(*r);
        ASSERT_EQ(trees.size(), 2u);
        EXPECT_EQ(trees[0].species, 0u);
        EXPECT_EQ(trees[0].position, glm::vec3(8.0f, 0.0f, 7.0f));
        EXPECT_EQ(trees[0].rotation, 0.0f);
        EXPECT_EQ(trees[0].scale, 1.0f);
    }

    TEST(SceneScript, instanceFileFollowsTheExplicitPlacementRules)
    {
        // A file placement is explicit: kept under --scale, first in a count sweep.
        std::string csv = "x,z\n";
        for (int i = 0; i < 20; ++i)
            csv += std::to_string(i) + ",0\n";
        std::filesystem::path dir = testDir("csv-rules");
        std::ofstream(dir / "trees.csv") << csv;
        std::string text = replaced(withInstanceFile(), "{\"species\": [\"a\", \"b\"], \"file\": \"trees.csv\"}",
                                    "{\"species\": [\"a\", \"b\"], \"file\": \"trees.csv\"}, {\"species\": \"a\", "
                                    "\"random\": {\"seed\": 1, \"count\": 100, \"area\": {\"rect\": [-40, 10, 40, 40]}}}");
        Result<SceneScript> r = parseSceneScript(text, "test.json", dir.string());
        ASSERT_TRUE(r.ok()) << r.error().message();
        EXPECT_EQ(generatePlacements(*r).size(), 120u);
        PlacementOptions thin;
        thin.scale = 0.1;
        std::vector<PlacedTree> thinned = generatePlacements(*r, thin);
        ASSERT_EQ(thinned.size(), 20u + 10u);
        EXPECT_EQ(thinned[19].position, glm::vec3(19.0f, 0.0f, 0.0f));
        PlacementOptions few;
        few.totalCount = 5;
        std::vector<PlacedTree> five = generatePlacements(*r, few);
        ASSERT_EQ(five.size(), 5u);
        EXPECT_EQ(five[4].position, glm::vec3(4.0f, 0.0f, 0.0f));
    }

    TEST(SceneScript, instanceFileErrorsNameFileLineColumnAndReason)
    {
        struct Case
        {
            std::string csv;
            std::string expected; ///< after "trees.csv: "
        };
        const std::string header = "x,z,species,rotation,scale\n# comment\n1,2,a,0,1\n";
        const std::vector<Case> cases = {
            {header + "1,2,a,0,0\n", "line 4, column scale: 0 must be finite and > 0"},
            {header + "1,2,a,0,-2\n", "line 4, column scale: -2 must be finite and > 0"},
            {header + "1,2,a,0,NaN\n", "line 4, column scale: NaN must be finite and > 0"},
            {header + "nan,2,a,0,1\n", "line 4, column x: nan must be finite and on the ground (|x| <= 50)"},
            {header + "1,inf,a,0,1\n", "line 4, column z: inf must be finite"},
            {header + "1,-inf,a,0,1\n", "line 4, column z: -inf must be finite"},
            {header + "1,2,a,1e999,1\n", "line 4, column rotation: 1e999 must be finite degrees in [-360, 360]"},
            {header + "1,2,a,0,1e999\n", "line 4, column scale: 1e999 must be finite and > 0"},
            {header + "1,2,a,0,2000\n", "line 4, column scale: 2000 must be <= 1000"},
            {header + "60,2,a,0,1\n", "line 4, column x: 60 must be finite and on the ground (|x| <= 50)"},
            {header + "1,2,pine,0,1\n", "line 4, column species: unknown species 'pine' (this placement's: a, b)"},
            {header + "1,2,a,0\n", "line 4: expected 5 columns (x, z, species, rotation, scale), got 4"},
            {header + "1,2,a,0,1,5\n", "line 4: expected 5 columns (x, z, species, rotation, scale), got 6"},
            {header + "1,two,a,0,1\n", "line 4, column z: 'two' is not a number"},
            {header + "1,2,a,,1\n", "line 4, column rotation: '' is not a number"},
            {header + "1,2,a,0,1 m\n", "line 4, column scale: '1 m' is not a number"},
            {"# header next\nx,z,height\n1,2,3\n", "line 2: unknown column 'height'"},
            {"x,species\n1,a\n", "line 1: the header lacks the column z"},
            {"x,z,x\n1,2,3\n", "line 1: column 'x' named twice"},
            {"# nothing\n\n", "line 2: no header line"},
            {"x,z\n", "line 1: no trees"},
        };
        for (const Case& c : cases)
        {
            Result<SceneScript> r = parseWithCsv("csv-errors", c.csv);
            ASSERT_FALSE(r.ok()) << c.csv;
            const std::string message = r.error().message();
            const std::size_t at = message.find("trees.csv: ");
            EXPECT_NE(at, std::string::npos) << message;
            EXPECT_EQ(message.substr(at + 11, c.expected.size()), c.expected) << c.csv << "\n" << message;
        }
        // The file itself missing: an error at the script's key.
        std::filesystem::path dir = testDir("csv-missing");
        std::filesystem::remove(dir / "absent.csv");
        const std::string text = withInstanceFile("absent.csv");
        Result<SceneScript> r = parseSceneScript(text, "test.json", dir.string());
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().message().rfind("test.json: " + positionOf(text, "\"file\"") +
                                                ", key /placements/0/file: no such file: ",
                                            0),
                  0u)
            << r.error().message();
        // One of positions, random or file.
        std::string both = replaced(text, "\"file\": \"absent.csv\"", "\"file\": \"absent.csv\", \"positions\": [[0, 0]]");
        EXPECT_NE(errorOf(both).find("key /placements/0/file: a placement has one of positions, random or file"),
                  std::string::npos)
            << errorOf(both);
    }

    TEST(SceneScript, twoSpeciesSharingOneAssetFileLoad)
    {
        std::string text = replaced(MINIMAL, "{\"name\": \"a\", \"source\": \"preset:oak\", \"techniques\": \"auto\"}",
                                    "{\"name\": \"a\", \"source\": \"../../media/oak.glb\", \"techniques\": \"auto\"}, "
                                    "{\"name\": \"big\", \"source\": \"../../media/oak.glb\", \"techniques\": \"auto\", "
                                    "\"scale\": [1.5, 2]}");
        text = replaced(text, "{\"species\": \"a\", \"random\"", "{\"species\": [\"a\", \"big\"], \"random\"");
        Result<SceneScript> r = parseSceneScript(text, "test.json", scenePath(""));
        ASSERT_TRUE(r.ok()) << r.error().message();
        ASSERT_EQ(r->species.size(), 2u);
        EXPECT_EQ(r->species[0].source, r->species[1].source);
        EXPECT_EQ(r->species[1].scaleMin, 1.5f);
        std::vector<PlacedTree> trees = generatePlacements(*r);
        ASSERT_EQ(trees.size(), 10u);
        for (const PlacedTree& t : trees)
            EXPECT_TRUE(t.species == 0 ? t.scale == 1.0f : t.scale >= 1.5f && t.scale <= 2.0f);
    }

    TEST(SceneScript, forest100kPlacesItsTreesAndLandsTheCameraAtWalkingHeight)
    {
        Result<SceneScript> s = loadSceneScript(scenePath("forest-100k.json"));
        ASSERT_TRUE(s.ok()) << s.error().message();
        std::vector<PlacedTree> trees = generatePlacements(*s);
        EXPECT_EQ(trees.size(), 100000u);
        std::vector<std::size_t> perSpecies(s->species.size(), 0);
        glm::vec2 lo(1e9f), hi(-1e9f);
        for (const PlacedTree& t : trees)
        {
            ++perSpecies[t.species];
            lo = glm::min(lo, glm::vec2(t.position.x, t.position.z));
            hi = glm::max(hi, glm::vec2(t.position.x, t.position.z));
        }
        EXPECT_GE(s->species.size(), 2u);
        for (std::size_t n : perSpecies)
            EXPECT_GT(n, 10000u);
        const double km2 = double(hi.x - lo.x) * double(hi.y - lo.y) / 1e6;
        EXPECT_TRUE(km2 > 8.0 && km2 < 12.0) << km2; // about 10 km²
        EXPECT_EQ(s->width, 1920);
        EXPECT_EQ(s->height, 1080);

        PlacementOptions thin;
        thin.scale = 0.01;
        const std::size_t thinned = generatePlacements(*s, thin).size();
        EXPECT_TRUE(thinned >= 900 && thinned <= 1100) << thinned;

        // From the overview (most of the forest in view) down to walking height.
        double highest = 0.0, lowest = 1e9;
        for (std::uint32_t f = 0; f < s->frames; ++f)
        {
            CameraSpec cam = cameraAt(*s, frameTime(*s, f));
            highest = std::max(highest, double(cam.position.y));
            lowest = std::min(lowest, double(cam.position.y));
        }
        EXPECT_GE(highest, 1500.0);
        EXPECT_LT(lowest, 2.0);
        EXPECT_GT(double(s->camera.farClip), highest * 2.0); // the far side of the forest from the overview
    }

    // ---- hostile numbers and a million trees -----------------------------------------------

    namespace
    {
        /// A script that gives every numeric key of the format a value (docs/scene-format.md,
        /// "Keys"): a heightfield ground, preset species with bands by distance and by pixels
        /// and both forms of "scale", positions of 2, 3 and 4 numbers, random placements by
        /// count and by density over rect, disc and ring areas and exclusions, sun, shadows,
        /// camera, resolution, frames and counts. The sun's "direction" excludes its azimuth and
        /// elevation, so the test gives it in a second script.
        const std::string EVERY_NUMBER = R"({
  "name": "every number",
  "ground": {"kind": "heightfield", "size": 400, "image": "ground.png", "heightScale": 12.5},
  "species": [
    {"name": "oak", "source": "preset:oak", "seed": 7, "leaves": 2000, "height": 9.5, "scale": 1.25,
     "techniques": [{"technique": "mesh", "maxDistance": 30}, {"technique": "lodf", "maxDistance": 300},
                    {"technique": "billboard-cloud"}]},
    {"name": "birch", "source": "preset:birch", "scale": [0.8, 1.2],
     "techniques": [{"technique": "mesh", "minPixels": 400}, {"technique": "impostor"}]}
  ],
  "placements": [
    {"species": "oak", "positions": [[0, 0], [12, -5, 90], [20, 10, -45, 1.5]]},
    {"species": ["oak", "birch"], "random": {"seed": 3, "count": 50, "area": {"rect": [-150, -150, -50, -50]},
     "exclude": [{"disc": [-100, -100, 20], "innerRadius": 5}], "clumping": 0.3}},
    {"species": "birch", "random": {"seed": 4, "density": 20, "area": {"disc": [100, 100, 60], "innerRadius": 10},
     "exclude": [{"rect": [90, 90, 110, 110]}]}}
  ],
  "sun": {"azimuth": 30, "elevation": 50, "colour": [1, 0.9, 0.8], "ambient": [0.3, 0.35, 0.4]},
  "shadows": {"enabled": true, "textureSize": 2048, "camera": "focused", "lodBias": 0.5},
  "camera": {"fovY": 50, "near": 0.1, "far": 5000, "interpolation": "catmull-rom",
             "keyframes": [{"time": 0, "position": [-20, 1.7, 20], "target": [0, 4, 0]},
                           {"time": 10, "position": [10, 1.7, 15], "target": [0, 4, -60]}]},
  "resolution": [1280, 720],
  "frames": 200,
  "counts": [10, 100]
})";

        /// The heightfield EVERY_NUMBER's ground reads: 2 x 2 pixels.
        Result<GreyImage> groundGrey(const std::string&) { return GreyImage{2, 2, {0.0f, 0.5f, 0.5f, 1.0f}}; }

        /// JSON pointers of every number in `j` (depth first).
        void numberPointers(const nlohmann::json& j, const std::string& pointer, std::vector<std::string>& out)
        {
            if (j.is_number())
                out.push_back(pointer);
            else if (j.is_object())
                for (auto it = j.begin(); it != j.end(); ++it)
                    numberPointers(it.value(), pointer + "/" + it.key(), out);
            else if (j.is_array())
                for (std::size_t i = 0; i < j.size(); ++i)
                    numberPointers(j[i], pointer + "/" + std::to_string(i), out);
        }

        /// A script's text with one value replaced: keyAt is the offset errors about it point at
        /// (the key's quote for an object member, the value for an array element), valueAt that
        /// of the replacement.
        struct Substitution
        {
            std::string target, replacement, text;
            std::size_t keyAt = 0, valueAt = 0;
        };

        /// Appends `j` (at `pointer`) to s.text, one object member a line, writing the value at
        /// s.target as s.replacement.
        void writeWith(const nlohmann::json& j, const std::string& pointer, int depth, Substitution& s)
        {
            if (pointer == s.target)
            {
                s.valueAt = s.text.size();
                s.text += s.replacement;
                return;
            }
            const std::string indent(std::size_t(2 * depth + 2), ' ');
            if (j.is_object())
            {
                s.text += "{\n";
                for (auto it = j.begin(); it != j.end(); ++it)
                {
                    s.text += indent;
                    const std::string member = pointer + "/" + it.key();
                    if (member == s.target)
                        s.keyAt = s.text.size();
                    s.text += nlohmann::json(it.key()).dump() + ": ";
                    writeWith(it.value(), member, depth + 1, s);
                    s.text += std::next(it) == j.end() ? "\n" : ",\n";
                }
                s.text += std::string(std::size_t(2 * depth), ' ') + "}";
            }
            else if (j.is_array())
            {
                s.text += "[";
                for (std::size_t i = 0; i < j.size(); ++i)
                {
                    const std::string element = pointer + "/" + std::to_string(i);
                    s.text += i ? ", " : "";
                    if (element == s.target)
                        s.keyAt = s.text.size();
                    writeWith(j[i], element, depth + 1, s);
                }
                s.text += "]";
            }
            else
                s.text += j.dump();
        }

        /// The pointer with every array index replaced by '#': "/species/#/scale/#".
        std::string pointerShape(const std::string& pointer)
        {
            std::string out;
            std::size_t at = 0;
            while (at < pointer.size())
            {
                std::size_t next = pointer.find('/', at + 1);
                const std::string token = pointer.substr(at + 1, next == std::string::npos ? next : next - at - 1);
                const bool index = !token.empty() && token.find_first_not_of("0123456789") == std::string::npos;
                out += "/" + (index ? std::string("#") : token);
                at = next == std::string::npos ? pointer.size() : next;
            }
            return out;
        }
    }

    TEST(SceneScript, nonFiniteInputInEveryNumericKeyIsAnErrorAtItsKey)
    {
        // JSON has no NaN: a user may write NaN or Infinity (a syntax error, at the line and
        // column of the word) or 1e999 / -1e999 (overflows to an infinity; an error naming line,
        // column and key). Each number of the scripts in turn, found by walking them.
        nlohmann::json base = nlohmann::json::parse(EVERY_NUMBER);
        nlohmann::json withDirection = base;
        withDirection["sun"] = {{"direction", {0.3, 0.8, 0.2}}, {"colour", {1, 1, 1}}};
        std::vector<std::pair<const nlohmann::json*, std::string>> targets; // the second script: its sun only
        std::set<std::string> seen, shapes;
        for (const nlohmann::json* script : {&base, &withDirection})
        {
            Result<SceneScript> valid = parseSceneScript(script->dump(), "test.json", "", groundGrey);
            ASSERT_TRUE(valid.ok()) << valid.error().message();
            std::vector<std::string> pointers;
            numberPointers(*script, "", pointers);
            for (const std::string& p : pointers)
                if (seen.insert(p).second)
                {
                    targets.emplace_back(script, p);
                    shapes.insert(pointerShape(p));
                }
        }
        // The fixture uses every numeric key of docs/scene-format.md.
        const std::set<std::string> formatKeys = {
            "/ground/size", "/ground/heightScale", "/species/#/seed", "/species/#/leaves", "/species/#/height",
            "/species/#/techniques/#/maxDistance", "/species/#/techniques/#/minPixels", "/species/#/scale",
            "/species/#/scale/#", "/placements/#/positions/#/#", "/placements/#/random/seed",
            "/placements/#/random/count", "/placements/#/random/density", "/placements/#/random/area/rect/#",
            "/placements/#/random/area/disc/#", "/placements/#/random/area/innerRadius",
            "/placements/#/random/exclude/#/rect/#", "/placements/#/random/exclude/#/disc/#",
            "/placements/#/random/exclude/#/innerRadius", "/placements/#/random/clumping", "/sun/azimuth",
            "/sun/elevation", "/sun/direction/#", "/sun/colour/#", "/sun/ambient/#", "/shadows/textureSize",
            "/shadows/lodBias", "/camera/fovY", "/camera/near", "/camera/far", "/camera/keyframes/#/time",
            "/camera/keyframes/#/position/#", "/camera/keyframes/#/target/#", "/resolution/#", "/frames",
            "/counts/#"};
        EXPECT_EQ(shapes, formatKeys);

        auto lineColumn = [](const std::string& text, std::size_t offset) {
            std::size_t line = 1, column = 1;
            for (std::size_t i = 0; i < offset; ++i)
            {
                column = text[i] == '\n' ? 1 : column + 1;
                line += text[i] == '\n';
            }
            return "line " + std::to_string(line) + ", column " + std::to_string(column);
        };
        std::size_t checked = 0;
        for (const auto& [script, pointer] : targets)
            for (const char* replacement : {"NaN", "Infinity", "1e999", "-1e999"})
            {
                Substitution s;
                s.target = pointer;
                s.replacement = replacement;
                writeWith(*script, "", 0, s);
                Result<SceneScript> r = parseSceneScript(s.text, "test.json", "", groundGrey);
                ASSERT_FALSE(r.ok()) << pointer << " = " << replacement << " was accepted";
                const std::string message = r.error().message();
                const bool syntax = replacement[0] != '1' && replacement[0] != '-';
                if (syntax)
                {
                    const std::string expected = "test.json: " + lineColumn(s.text, s.valueAt) + ": ";
                    EXPECT_EQ(message.substr(0, expected.size()), expected) << pointer << " = " << replacement;
                    EXPECT_NE(message.find("syntax error"), std::string::npos) << message;
                }
                else
                {
                    EXPECT_EQ(message, "test.json: " + lineColumn(s.text, s.keyAt) + ", key " + pointer + ": " +
                                           replacement + " is not a finite number (beyond the range of a double)");
                }
                ++checked;
            }
        EXPECT_GE(checked, 4u * 70u);
    }

    TEST(SceneScript, instanceFileRefusesEveryNonFiniteFormInEveryNumericColumn)
    {
        // std::from_chars reads "nan", "inf", "infinity" (any case, signed) as numbers; 1e999
        // overflows. In each numeric column each form is an error naming the file, line and column.
        const std::vector<std::string> columns = {"x", "z", "rotation", "scale", "y"};
        std::string header = "x,z,species,rotation,scale,y\n";
        for (const std::string& column : columns)
            for (const char* bad : {"nan", "NaN", "-nan", "+nan", "nan(123)", "inf", "-inf", "+inf", "INF",
                                    "infinity", "-Infinity", "1e999", "-1e999"})
            {
                std::string row;
                for (const char* c : {"x", "z", "species", "rotation", "scale", "y"})
                {
                    const std::string name = c;
                    row += row.empty() ? "" : ",";
                    row += name == column ? std::string(bad) : name == "species" ? "a" : name == "scale" ? "1" : "2";
                }
                const std::string csv = header + "# one good row, then the bad one\n2,2,b,0,1,0\n" + row + "\n";
                Result<SceneScript> r = parseWithCsv("csv-non-finite", csv);
                ASSERT_FALSE(r.ok()) << row;
                const Error& e = r.error();
                EXPECT_EQ(std::filesystem::path(e.file), (testDir("csv-non-finite") / "trees.csv").lexically_normal())
                    << e.message();
                EXPECT_EQ(e.element, "line 4, column " + column) << row;
                EXPECT_EQ(e.reason.rfind(std::string(bad) + " must be finite", 0), 0u) << e.message();
            }
    }

    TEST(SceneScript, aMillionTreesParsePlaceAndFillAForest)
    {
        // A random placement of 1 000 000 trees and an instance file of 1 000 000 lines: each
        // parses, generatePlacements gives every tree, and ForestInstances holds and culls them
        // at the documented memory per tree: 5 floats, the 16-bit kind and the two 32-bit handle
        // maps (30 bytes) plus a box of 6 floats per block of 256, and per visible tree
        // 12 floats of transform, 4 index arrays and a distance-class byte (65 bytes).
        constexpr std::size_t MILLION = 1000000;
        const std::filesystem::path dir = testDir("million");
        {
            std::ofstream csv(dir / "trees.csv", std::ios::binary);
            csv << "x,z,species,rotation,scale\n";
            for (std::size_t i = 0; i < MILLION; ++i)
                csv << (int(i % 1000) - 500) << "," << (int(i / 1000) - 500) << "," << (i % 3 ? "a" : "b") << ","
                    << (i % 360) << ",1." << (i % 10) << "\n";
        }
        const std::string random = replaced(replaced(replaced(MINIMAL, "\"count\": 10", "\"count\": 1000000"),
                                                     "[-10, -10, 10, 10]", "[-500, -500, 500, 500]"),
                                            "\"size\": 100", "\"size\": 1200");
        const std::string file = replaced(withInstanceFile(), "\"size\": 100", "\"size\": 1200");
        for (const std::string& text : {random, file})
        {
            Result<SceneScript> script = parseSceneScript(text, "test.json", dir.string());
            ASSERT_TRUE(script.ok()) << script.error().message();
            const std::vector<PlacedTree> trees = generatePlacements(*script);
            ASSERT_EQ(trees.size(), MILLION);

            ForestInstances forest;
            for (std::size_t k = 0; k < script->species.size(); ++k)
            {
                ForestKind kind;
                kind.name = script->species[k].name;
                kind.boundsCentre = glm::vec3(0.0f, 8.0f, 0.0f);
                kind.boundsRadius = 9.0f;
                kind.thresholds = {2e5f, 2e4f, 2e3f};
                ASSERT_TRUE(forest.addKind(kind));
            }
            std::vector<ForestInstance> instances(trees.size());
            for (std::size_t i = 0; i < trees.size(); ++i)
                instances[i] = ForestInstance{trees[i].position, trees[i].rotation, trees[i].scale, trees[i].species};
            ASSERT_TRUE(forest.add(instances));
            ASSERT_EQ(forest.size(), MILLION);
            const std::size_t blocks = (MILLION + ForestInstances::BLOCK_SIZE - 1) / ForestInstances::BLOCK_SIZE;
            const std::size_t storeBound = MILLION * (5 * sizeof(float) + sizeof(std::uint16_t) +
                                                      2 * sizeof(ForestHandle)) +
                                           blocks * 6 * sizeof(float);
            std::printf("%s: %.2f bytes per tree in ForestInstances\n", script->placements[0].random ? "random" : "file",
                        double(forest.getMemoryBytes()) / double(MILLION));
            EXPECT_LE(forest.getMemoryBytes(), storeBound);

            // From 3 km up, all in view; a second cull at the same counts allocates nothing.
            CameraSpec overview;
            overview.position = glm::vec3(0.0f, 3000.0f, 1.0f);
            overview.target = glm::vec3(0.0f);
            overview.farClip = 5000.0f;
            const CullCamera camera = CullCamera::fromSpec(overview, 1920.0f, 1080.0f);
            ForestVisibility vis;
            ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
            EXPECT_EQ(vis.getVisibleCount(), MILLION);
            // per visible tree: transform, LoD key, transition code (and its scratch); index, its place
            // near first, the draw's instance, bucket and index; distance class; per tree (all
            // visible here): its last level
            const std::size_t perVisible = (ForestVisibility::TRANSFORM_FLOATS + 3) * sizeof(float) +
                                           5 * sizeof(std::uint32_t) + 2 * sizeof(std::uint8_t);
            const std::size_t visibilityBound = MILLION * perVisible +
                                                forest.getBucketCount() * (sizeof(ForestBucket) + sizeof(std::uint32_t));
            EXPECT_LE(vis.getCapacityBytes(), visibilityBound);
            const std::size_t capacity = vis.getCapacityBytes();
            ASSERT_TRUE(forest.cull(camera, 1.0f, vis));
            EXPECT_EQ(vis.getCapacityBytes(), capacity);
        }
    }
}
