// Shared fixture of the Ogre tests: one headless Root per test binary (Ogre allows one
// Root per process), with Plugin_TreeLod loaded from its .so like an application would.
#pragma once

#include "TreeLod/OffscreenRenderer.h"

#include <gtest/gtest.h>

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
}
