// A volume octree baked from a capture folder (`treelod bake CAPTURE_FOLDER`): the package's
// reference holds the capture's volume as bounds and no polygons, consumers that need polygons
// are refused naming the package, the options a capture cannot take are refused, and the source
// hash of a folder covers cameras.json and every image.
#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeCache.h"
#include "TreeLod/CaptureSet.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/VolumeOctreeBaker.h"
#include "TreeLod/VolumeOctreeData.h"
#include "TestOutput.h"
#include "TestTrees.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace TreeLod
{
    namespace
    {
        /// Six 48-pixel photographs of a small generated oak.
        const CaptureSet& smallCapture()
        {
            static const CaptureSet set = [] {
                CaptureSynthesisOptions o;
                o.cameraCount = 6;
                o.resolution = 48;
                o.samplesPerPixel = 1;
                Result<CaptureSet> s = synthesiseCaptureSet(test::generatedOak(200), o, "oak");
                if (!s)
                    throw std::runtime_error(s.error().message());
                return std::move(s).value();
            }();
            return set;
        }

        VolumeOctreeOptions threeLevels()
        {
            VolumeOctreeOptions o;
            o.levelCount = 3;
            o.quantisation.colourCodebookSize = 16;
            o.quantisation.alphaCodebookSize = 16;
            return o;
        }

        void overwrite(const std::string& path, const std::string& text)
        {
            std::ofstream out(path, std::ios::binary | std::ios::trunc);
            out << text;
        }
    }

    TEST(CaptureBake, ReferenceHoldsTheVolumeAndNoPolygons)
    {
        PackageWriter writer;
        ASSERT_TRUE(addVolumeOctreeChunk(writer, smallCapture(), "oak-photos", threeLevels(), "out.treelod"));
        Result<PackageReader> reader = PackageReader::fromMemory(writer.toBytes(), "out.treelod");
        ASSERT_TRUE(reader) << reader.error().message();

        Result<std::vector<std::uint8_t>> bytes = reader->readChunk(REFERENCE_CHUNK, 0);
        ASSERT_TRUE(bytes);
        Result<ReferenceChunk> reference = decodeReferenceChunk(bytes.value(), reader->label());
        ASSERT_TRUE(reference) << reference.error().message();
        const TreeModel& model = reference->model;
        EXPECT_FALSE(hasPolygons(model));
        EXPECT_EQ(model.name, "oak-photos");
        EXPECT_TRUE(model.materials.empty());
        EXPECT_TRUE(reference->textures.empty());
        EXPECT_EQ(model.boundsMin, glm::vec3(smallCapture().volumeMin));
        EXPECT_EQ(model.boundsMax, glm::vec3(smallCapture().volumeMax));

        Result<std::vector<std::uint8_t>> octree = reader->readChunk(VOLUME_OCTREE_CHUNK, 0);
        ASSERT_TRUE(octree);
        Result<VolumeOctreeData> data = decodeVolumeOctreeChunk(octree.value(), reader->label());
        ASSERT_TRUE(data) << data.error().message();
        EXPECT_EQ(data->levelCount, 3u);
        EXPECT_EQ(data->cameraCount(), smallCapture().cameras.size());

        // What needs the polygons says why there are none, naming the package.
        Result<void> refused = requirePolygons(model, "out.treelod", "technique 'mesh'");
        ASSERT_FALSE(refused);
        EXPECT_EQ(refused.error().file, "out.treelod");
        EXPECT_EQ(refused.error().element, "chunk 'reference' level 0");
        EXPECT_NE(refused.error().reason.find("photographs"), std::string::npos) << refused.error().message();
        EXPECT_NE(refused.error().reason.find("technique 'mesh'"), std::string::npos) << refused.error().message();
        EXPECT_TRUE(requirePolygons(test::generatedOak(200), "oak", "technique 'mesh'"));
        EXPECT_TRUE(hasPolygons(test::generatedOak(200)));
    }

    TEST(CaptureBake, RefusesASecondReference)
    {
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, test::generatedOak(200), "out.treelod"));
        Result<void> r = addVolumeOctreeChunk(writer, smallCapture(), "oak", threeLevels(), "out.treelod");
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().element, "chunk 'reference' level 0");
        EXPECT_FALSE(writer.hasChunk(VOLUME_OCTREE_CHUNK, 0));
    }

    TEST(CaptureBake, OptionsOfSynthesisAreRefused)
    {
        VolumeOctreeOptions options;
        Result<void> ok = parseVolumeOctreeBakeOptions({{"levels", "3"}, {"codebookSize", "32"}}, options, nullptr, "o");
        ASSERT_TRUE(ok) << ok.error().message();
        EXPECT_EQ(options.levelCount, 3u);
        EXPECT_EQ(options.quantisation.colourCodebookSize, 32u);
        for (const std::string& name : volumeOctreeSynthesisOptions())
        {
            Result<void> r = parseVolumeOctreeBakeOptions({{name, "16"}}, options, nullptr, "o");
            ASSERT_FALSE(r) << name;
            EXPECT_EQ(r.error().element, "option 'volume-octree." + name + "'");
            EXPECT_NE(r.error().reason.find("capture folder"), std::string::npos) << r.error().message();
        }
        // A synthesised capture takes them.
        CaptureSynthesisOptions synthesis;
        ASSERT_TRUE(parseVolumeOctreeBakeOptions({{"cameras", "8"}, {"resolution", "64"}}, options, &synthesis, "o"));
        EXPECT_EQ(synthesis.cameraCount, 8);
        EXPECT_EQ(synthesis.resolution, 64);
        Result<void> bad = parseVolumeOctreeBakeOptions({{"levels", "2.5"}}, options, nullptr, "o");
        ASSERT_FALSE(bad);
        EXPECT_EQ(bad.error().element, "option 'volume-octree.levels'");
    }

    TEST(CaptureBake, SourceHashOfAFolderCoversCamerasAndImages)
    {
        namespace fs = std::filesystem;
        const std::string dir = test::freshTestDir("capture-bake", "hash") + "/oak";
        ASSERT_TRUE(writeCaptureSet(smallCapture(), dir));
        Result<std::string> first = sourceHashOf(dir);
        ASSERT_TRUE(first) << first.error().message();
        EXPECT_EQ(first->rfind("fnv1a64:", 0), 0u);
        EXPECT_EQ(sourceHashOf(dir + "/").value(), first.value());

        const std::string image = dir + "/" + smallCapture().cameras[1].image;
        Result<std::vector<std::uint8_t>> png = readFile(image);
        ASSERT_TRUE(png);
        std::vector<std::uint8_t> changed = png.value();
        changed.push_back(0);
        ASSERT_TRUE(writeFileAtomic(image, changed));
        Result<std::string> second = sourceHashOf(dir);
        ASSERT_TRUE(second);
        EXPECT_NE(second.value(), first.value());
        ASSERT_TRUE(writeFileAtomic(image, png.value()));
        EXPECT_EQ(sourceHashOf(dir).value(), first.value());

        // A missing image hashes as missing (readCaptureSet names it); cameras.json is needed.
        fs::remove(image);
        Result<std::string> missing = sourceHashOf(dir);
        ASSERT_TRUE(missing);
        EXPECT_NE(missing.value(), first.value());
        const std::string json = dir + "/" + CAPTURE_SET_FILE;
        Result<std::vector<std::uint8_t>> text = readFile(json);
        ASSERT_TRUE(text);
        overwrite(json, std::string(text->begin(), text->end()) + " ");
        EXPECT_NE(sourceHashOf(dir).value(), missing.value());
        fs::remove(json);
        Result<std::string> none = sourceHashOf(dir);
        ASSERT_FALSE(none);
        EXPECT_NE(none.error().message().find("cameras.json"), std::string::npos) << none.error().message();
    }
}
