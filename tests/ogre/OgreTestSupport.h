// Shared fixture of the Ogre tests: one headless Root per test binary (Ogre allows one
// Root per process), with Plugin_TreeLod loaded from its .so like an application would.
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/OffscreenRenderer.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

namespace TreeLod
{
    class OgreEnvironment
    {
    public:
        static OffscreenRenderer& renderer()
        {
            static std::unique_ptr<OffscreenRenderer> instance = [] {
                OffscreenOptions options;
                options.pluginPath = TREELOD_PLUGIN_PATH;
                options.logFile = outDir() + "/ogre-test.log";
                return std::make_unique<OffscreenRenderer>(options);
            }();
            return *instance;
        }

        static std::string outDir()
        {
            std::string dir = std::string(TREELOD_BINARY_DIR) + "/test-out/ogre";
            std::filesystem::create_directories(dir);
            return dir;
        }

        static std::string sourcePath(const std::string& relative)
        {
            return std::string(TREELOD_SOURCE_DIR) + "/" + relative;
        }
    };

    // Golden images: each render is compared with tests/golden/NAME.png by FLIP (mean below
    // the bound stated per test); with TREELOD_GOLDEN=update the goldens are rewritten
    // instead (then open them and look before committing). On a failure the render and the
    // FLIP heat map are left in build/test-out/ogre/ for inspection.
    inline Image toImage(const RgbaImage& rgba)
    {
        Image image(rgba.width, rgba.height);
        for (std::size_t i = 0; i < image.pixels.size(); ++i)
            image.pixels[i] = glm::vec4(rgba.pixels[4 * i], rgba.pixels[4 * i + 1], rgba.pixels[4 * i + 2],
                                        rgba.pixels[4 * i + 3]) / 255.0f;
        return image;
    }

    /// Fraction of pixels that differ from the background colour: a black, empty or
    /// background-only picture cannot pass a golden test.
    inline double treeCoverage(const Image& image, const glm::vec3& background)
    {
        std::size_t covered = 0;
        for (const glm::vec4& p : image.pixels)
            covered += glm::length(glm::vec3(p) - background) > 0.02f;
        return double(covered) / double(image.pixels.size());
    }

    inline void compareWithGolden(const Image& actual, const std::string& name, double bound)
    {
        const std::string golden = OgreEnvironment::sourcePath("tests/golden/" + name + ".png");
        const std::string actualPath = OgreEnvironment::outDir() + "/" + name + ".png";
        ASSERT_TRUE(writePng(actualPath, actual).ok());
        const char* mode = std::getenv("TREELOD_GOLDEN");
        if (mode && std::string(mode) == "update")
        {
            ASSERT_TRUE(writePng(golden, actual).ok());
            GTEST_SKIP() << "golden updated: " << golden << " (open it and look before committing)";
        }
        Result<Image> expected = readImage(golden);
        ASSERT_TRUE(expected.ok()) << expected.error().message()
                                   << " (run with TREELOD_GOLDEN=update to create it)";
        FlipOptions options;
        options.keepErrorMap = true;
        Result<FlipResult> flipped = flip(expected.value(), actual, options);
        ASSERT_TRUE(flipped.ok()) << flipped.error().message();
        if (flipped->mean >= bound)
            writePng(OgreEnvironment::outDir() + "/" + name + ".flip.png", flipHeatmap(flipped.value()));
        EXPECT_LT(flipped->mean, bound) << name << ": see " << actualPath;
    }
}
