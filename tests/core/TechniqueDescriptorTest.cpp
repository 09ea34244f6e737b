// The core half of the technique seam: every registered baker has a descriptor, every descriptor
// reads what its baker wrote (inspect: text and JSON for `treelod info`), refuses broken chunks
// with a message naming the package, and registration replaces by name with a stable order.
#include "TestTrees.h"

#include "TreeLod/BakeTechniques.h"
#include "TreeLod/ErrorCurves.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <map>
#include <set>

namespace TreeLod
{
    TEST(TechniqueDescriptor, everyBakerHasADescriptorAndTheListIsStable)
    {
        ASSERT_GE(bakeTechniques().size(), 2u) << "the technique libraries were not linked whole";
        EXPECT_EQ(techniqueDescriptors().front().name, REFERENCE_CHUNK);
        EXPECT_EQ(bakeTechniques().front().name, std::string(REFERENCE_CHUNK));
        std::set<std::string> names;
        for (const BakeTechnique& baker : bakeTechniques())
        {
            const TechniqueDescriptor* descriptor = findTechniqueDescriptor(baker.name);
            ASSERT_NE(descriptor, nullptr) << baker.name << " bakes chunks nothing can read";
            EXPECT_NE(descriptor->inspect, nullptr) << baker.name;
            names.insert(baker.name);
        }
        // The error curves are measured by the Ogre side (ErrorCurveMeasurer.h), not by a core baker.
        EXPECT_NE(findTechniqueDescriptor(ERROR_CURVES_CHUNK), nullptr);
        for (const TechniqueDescriptor& d : techniqueDescriptors())
            EXPECT_TRUE(names.count(d.name) || d.name == ERROR_CURVES_CHUNK) << d.name << " has no baker";
        // After "reference", by name: listings do not depend on static initialisation order.
        for (std::size_t i = 2; i < techniqueDescriptors().size(); ++i)
            EXPECT_LT(techniqueDescriptors()[i - 1].name, techniqueDescriptors()[i].name);
    }

    TEST(TechniqueDescriptor, inspectReadsWhatEachBakerWrote)
    {
        const TreeModel& tree = test::generatedOak(300);
        for (const BakeTechnique& baker : bakeTechniques())
        {
            PackageWriter writer;
            Result<void> baked = baker.bake(writer, tree, test::quickBakeOptions(baker.name), "oak", {});
            ASSERT_TRUE(baked.ok()) << baker.name << ": " << baked.error().message();
            Result<PackageReader> reader = PackageReader::fromMemory(writer.toBytes(), "oak.treelod");
            ASSERT_TRUE(reader.ok()) << reader.error().message();
            const int index = reader->findChunk(baker.name, 0);
            ASSERT_GE(index, 0) << baker.name << " wrote no chunk of its own name";
            const TechniqueDescriptor& descriptor = *findTechniqueDescriptor(baker.name);
            EXPECT_EQ(reader->chunks()[std::size_t(index)].formatVersion, descriptor.formatVersion) << baker.name;
            Result<std::vector<std::uint8_t>> bytes = reader->readChunk(std::size_t(index));
            ASSERT_TRUE(bytes.ok());
            Result<ChunkSummary> summary = descriptor.inspect(bytes.value(), "oak.treelod");
            ASSERT_TRUE(summary.ok()) << baker.name << ": " << summary.error().message();
            EXPECT_FALSE(summary->text.empty()) << baker.name;
            const nlohmann::json json = nlohmann::json::parse(summary->json, nullptr, false);
            EXPECT_TRUE(json.is_object()) << baker.name << ": " << summary->json;
            EXPECT_FALSE(json.empty()) << baker.name;
            if (descriptor.fuzz)
                descriptor.fuzz(bytes.value()); // valid data: no trap

            // Broken: empty, cut short, and a flipped byte in the first 64 are refused, naming the
            // package, or decoded whole; never a crash.
            std::vector<std::vector<std::uint8_t>> broken = {{}, {bytes->begin(), bytes->begin() + bytes->size() / 2}};
            for (std::size_t i = 0; i < 64 && i < bytes->size(); i += 7)
            {
                broken.push_back(bytes.value());
                broken.back()[i] ^= 0xA5;
            }
            for (std::size_t b = 0; b < broken.size(); ++b)
            {
                Result<ChunkSummary> refused = descriptor.inspect(broken[b], "broken.treelod");
                if (b < 2)
                {
                    ASSERT_FALSE(refused.ok()) << baker.name << " accepted broken chunk " << b;
                    EXPECT_NE(refused.error().message().find("broken.treelod"), std::string::npos)
                        << refused.error().message();
                }
                if (descriptor.fuzz)
                    descriptor.fuzz(broken[b]);
            }
        }
    }

    TEST(TechniqueDescriptor, registrationReplacesByName)
    {
        const std::size_t before = techniqueDescriptors().size();
        registerTechniqueDescriptor({"zz-test", "a test technique", 3, nullptr, nullptr});
        ASSERT_NE(findTechniqueDescriptor("zz-test"), nullptr);
        EXPECT_EQ(findTechniqueDescriptor("zz-test")->formatVersion, 3u);
        registerTechniqueDescriptor({"zz-test", "a test technique", 4, nullptr, nullptr});
        EXPECT_EQ(findTechniqueDescriptor("zz-test")->formatVersion, 4u);
        EXPECT_EQ(techniqueDescriptors().size(), before + 1);
        EXPECT_EQ(techniqueDescriptors().back().name, "zz-test");
        EXPECT_EQ(findTechniqueDescriptor("no-such-technique"), nullptr);
    }
}
