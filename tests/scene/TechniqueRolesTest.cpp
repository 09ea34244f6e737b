// What differs between techniques in the trade comes from each one's TechniqueRoles and the
// registered baselines: the Forest's auto candidates and default bands, the bench's defaults and
// comparison runs, the scene's policies and `treelod render`'s options. No Root or render
// system: the registries are made on first use. Its own process: it registers techniques.
#include "TreeLod/Forest.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/TechniqueRegistry.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace TreeLod
{
    namespace
    {
        bool contains(const std::vector<Ogre::String>& names, const Ogre::String& name)
        {
            return std::find(names.begin(), names.end(), name) != names.end();
        }
    }

    TEST(TechniqueRoles, theBuiltInListsAreWhatTheTechniquesDeclare)
    {
        const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        const TechniqueInfo& floor = registry.getFloor();
        ASSERT_TRUE(floor.forestLevels) << "the floor is a Forest level";

        const std::vector<ForestBand> bands = Forest::getAutoBands();
        ASSERT_GE(bands.size(), 2u);
        EXPECT_EQ(bands.back().technique, floor.name);
        EXPECT_EQ(bands.back().minHeightPixels, 0.0f);
        for (std::size_t b = 0; b + 1 < bands.size(); ++b)
        {
            EXPECT_GT(bands[b].minHeightPixels, bands[b + 1].minHeightPixels) << "largest first";
            EXPECT_EQ(registry.get(bands[b].technique).roles.defaultBandMinHeight, bands[b].minHeightPixels);
        }

        std::size_t candidates = 0, benchDefaults = 0;
        for (const TechniqueInfo& t : registry.getTechniques())
        {
            EXPECT_EQ(contains(Forest::getAutoTechniques(), t.name), t.roles.autoCandidate) << t.name;
            candidates += t.roles.autoCandidate;
            benchDefaults += t.roles.benchDefault;
            EXPECT_EQ(isComparisonRun(t.name), !t.roles.comparisonLabel.empty()) << t.name;
            if (t.roles.autoCandidate)
            {
                EXPECT_TRUE(t.forestLevels) << t.name << ": auto chooses among Forest levels";
            }
        }
        EXPECT_EQ(Forest::getAutoTechniques().size(), candidates);
        EXPECT_TRUE(contains(Forest::getAutoTechniques(), REFERENCE_TECHNIQUE));
        const std::string benchList = defaultBenchTechniques();
        EXPECT_EQ(std::size_t(std::count(benchList.begin(), benchList.end(), ',')), benchDefaults);

        // The runs every bench run is compared with: the reference first, then the floor, then the
        // baselines, each drawn from a chunk a bake provides.
        const std::vector<ComparisonRun> runs = comparisonRuns();
        ASSERT_GE(runs.size(), 2u);
        EXPECT_EQ(runs[0].technique, REFERENCE_TECHNIQUE);
        for (const BaselineInfo& b : registry.getBaselines())
        {
            EXPECT_TRUE(isBaseline(b.name));
            EXPECT_TRUE(isComparisonRun(b.name));
            EXPECT_EQ(bakeTechniqueOf(b.name), b.chunkTechnique);
            EXPECT_TRUE(b.create) << b.name;
            EXPECT_NE(knownSceneTechniques().find(b.name), std::string::npos);
        }
    }

    TEST(TechniqueRoles, aTechniqueJoinsEveryListByItsRolesAlone)
    {
        TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        TechniqueInfo info = registry.getFloor(); // a drawable technique to stand in
        info.name = "roles-test";
        info.roles = TechniqueRoles{};
        info.roles.autoCandidate = true;
        info.roles.defaultBandMinHeight = 5000.0f;
        info.roles.benchDefault = true;
        info.roles.comparisonLabel = "a test's comparison";
        info.roles.parameters = {{"testParameter", "test-parameter", "a parameter of the test"}};
        registry.add(info);

        EXPECT_TRUE(contains(Forest::getAutoTechniques(), "roles-test"));
        EXPECT_EQ(Forest::getAutoBands().front().technique, "roles-test") << "5000 px: the first band";
        EXPECT_NE(defaultBenchTechniques().find(",roles-test"), std::string::npos);
        EXPECT_TRUE(isComparisonRun("roles-test"));
        EXPECT_NE(describeComparisonRuns().find("roles-test"), std::string::npos);
        EXPECT_EQ(bakeTechniqueOf("roles-test"), info.chunkTechnique);

        Result<std::vector<BenchRun>> parsed = parseBenchRuns({"auto", "auto@0.05", "roles-test"});
        ASSERT_TRUE(parsed.ok()) << parsed.error().message();
        ASSERT_EQ(parsed->size(), 3u);
        EXPECT_EQ((*parsed)[0].policy, LodPolicy::scriptChoice()) << "the bench's auto is the script's choice";
        EXPECT_EQ((*parsed)[1].policy, LodPolicy::automatic(0.05f));
        EXPECT_EQ((*parsed)[2].policy, LodPolicy::fixed("roles-test"));
        Result<std::vector<BenchRun>> unknown = parseBenchRuns({"no-such-technique"});
        ASSERT_FALSE(unknown.ok());
        EXPECT_NE(unknown.error().message().find("roles-test"), std::string::npos) << "the known list names it";
        EXPECT_FALSE(parseBenchRuns({"auto@2"}).ok());
        // The bench's auto keeps its suffixes.
        Result<std::vector<BenchRun>> suffixed = parseBenchRuns({"auto+mem8+fade0.1"});
        ASSERT_TRUE(suffixed.ok()) << suffixed.error().message();
        EXPECT_EQ((*suffixed)[0].policy.mode, LodPolicy::Mode::Script);
        EXPECT_EQ((*suffixed)[0].policy.memoryBudgetMB, 8.0f);
        EXPECT_EQ((*suffixed)[0].policy.transition, 0.1f);

        // A baseline registered by a technique is a scene technique and a comparison run.
        registry.addBaseline({"roles-test-baseline", "a test's floor", '*', info.chunkTechnique, nullptr});
        EXPECT_TRUE(isBaseline("roles-test-baseline"));
        EXPECT_EQ(comparisonRuns().back().technique, "roles-test-baseline");
        EXPECT_EQ(bakeTechniqueOf("roles-test-baseline"), info.chunkTechnique);
    }

    TEST(TechniqueRoles, withoutAFloorTheDefaultBandsSayWhatIsMissing)
    {
        TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
        TechniqueInfo floor = registry.getFloor();
        floor.roles.floor = false;
        registry.add(floor); // replaces it: no technique is the floor now
        try
        {
            Forest::getAutoBands();
            ADD_FAILURE() << "bands without a floor";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("floor"), std::string::npos) << e.getDescription();
        }
    }
}
