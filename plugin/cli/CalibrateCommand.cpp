// treelod calibrate TREE... [--calibration DIR] [--force] [--json] [-q]
// What each level of each tree costs on this machine (LevelCalibration.h): instanced draws of every
// level budgeted auto chooses among, at a few screen heights, timed by read-back; cached per
// renderer string in DIR (default: the user's cache), where treelod_frames, the bench and the
// browser read it. A .glb/.gltf is baked in memory first. First, whether this renderer samples
// block-compressed textures slower than RGBA8 (then they are decoded at load).
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/LevelCosts.h"

#ifdef TREELOD_WITH_OGRE
#include "TreeInput.h"
#include "TreeLod/Forest.h"
#include "TreeLod/ForestScene.h" // bakeTechniqueOf
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/TreeAssetManager.h"
#endif

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace TreeLod
{
    namespace
    {
        struct CalibrateArgs
        {
            std::vector<std::string> inputs;
            std::string directory;
            bool force = false;
            bool json = false;
            bool quiet = false;
        };

        int runCalibrate(const CalibrateArgs& args)
        {
#ifdef TREELOD_WITH_OGRE
            const ProgressCallback progress = makeProgress(args.quiet);
            const std::string directory = args.directory.empty() ? userCacheDirectory() : args.directory;
            nlohmann::json out = nlohmann::json::array();
            try
            {
                OffscreenRenderer renderer;
                const std::string rendererName = rendererString(renderer.getRoot());
                if (args.force)
                {
                    // Measure the texture sampling again too.
                    const std::string path = costCalibrationPath(directory, rendererName);
                    Result<CostCalibration> held = readCostCalibration(path, rendererName);
                    if (held && held->hasTextureSampling)
                    {
                        held->hasTextureSampling = false;
                        if (Result<void> w = writeCostCalibration(path, *held); !w)
                            return printError(w.error());
                    }
                }
                Result<TextureSamplingCost> sampling = requireTextureUpload(renderer, directory, {}, progress);
                if (!sampling)
                    return printError(sampling.error());
                const bool decoded = TreeAssetManager::getSingleton().getCompressedTextureUpload() ==
                                     CompressedTextureUpload::Decoded;
                if (!args.json)
                    std::printf("texture sampling on %s: block-compressed %.2f ms, RGBA8 %.2f ms: %s%s\n",
                                rendererName.c_str(), sampling->compressedMs, sampling->decodedMs,
                                decoded ? "decoded to RGBA8 at load" : "uploaded as stored",
                                TreeAssetManager::getSingleton().isCompressedTextureUploadChosen()
                                    ? " (TREELOD_COMPRESSED_TEXTURES)"
                                    : "");
                std::vector<std::string> chunks = {REFERENCE_CHUNK};
                for (const Ogre::String& t : Forest::getAutoTechniques())
                    if (const std::string chunk = bakeTechniqueOf(t); !chunk.empty() && chunk != REFERENCE_CHUNK)
                        chunks.push_back(chunk);
                for (const std::string& input : args.inputs)
                {
                    Result<TreeInput> tree = loadTreeInput(input, {}, progress, {}, chunks);
                    if (!tree)
                        return printError(tree.error());
                    TreeAssetPtr asset = TreeAssetManager::getSingleton().loadFromBytes(tree->name, Ogre::RGN_DEFAULT,
                                                                                        tree->packageBytes);
                    if (args.force)
                    {
                        // Drop this tree's entry so that it is measured again.
                        const std::string path = costCalibrationPath(directory, rendererName);
                        Result<CostCalibration> held = readCostCalibration(path, rendererName);
                        if (held && held->assets.erase(levelCostKey(*asset)))
                            if (Result<void> w = writeCostCalibration(path, *held); !w)
                                return printError(w.error());
                    }
                    bool calibrated = false;
                    Result<std::vector<LevelCost>> costs =
                        requireLevelCosts(renderer, *asset, directory, {}, progress, &calibrated);
                    if (!costs)
                        return printError(costs.error());
                    nlohmann::json levels = nlohmann::json::array();
                    if (!args.json)
                        std::printf("%s on %s (%s):\n", input.c_str(), rendererName.c_str(),
                                    calibrated ? "calibrated now" : "from the cache");
                    for (const LevelCost& c : *costs)
                    {
                        ForestLevel level;
                        level.technique = c.technique;
                        level.techniqueLevel = c.techniqueLevel;
                        level.lowRes = c.lowRes;
                        std::string row;
                        for (std::size_t h = 0; h < c.heightsPx.size(); ++h)
                        {
                            char cell[64];
                            std::snprintf(cell, sizeof cell, "  %g px %.4f ms", double(c.heightsPx[h]),
                                          double(c.msPerTree[h]));
                            row += cell;
                        }
                        if (!args.json)
                            std::printf("  %-28s%s\n", Forest::describeLevel(level).c_str(), row.c_str());
                        levels.push_back({{"level", Forest::describeLevel(level)},
                                          {"technique", c.technique},
                                          {"techniqueLevel", c.techniqueLevel},
                                          {"lowRes", c.lowRes},
                                          {"heightsPx", c.heightsPx},
                                          {"msPerTree", c.msPerTree}});
                    }
                    out.push_back({{"input", input},
                                   {"renderer", rendererName},
                                   {"textureSampling",
                                    {{"compressedMs", sampling->compressedMs},
                                     {"decodedMs", sampling->decodedMs},
                                     {"decodedAtLoad", decoded}}},
                                   {"calibrated", calibrated},
                                   {"file", costCalibrationPath(directory, rendererName)},
                                   {"levels", levels}});
                    TreeAssetManager::getSingleton().remove(asset);
                }
            }
            catch (const Ogre::Exception& e)
            {
                return printError(fail("", "ogre", e.getDescription()));
            }
            if (args.json)
                std::printf("%s\n", out.dump(2).c_str());
            return EXIT_OK;
#else
            (void)args;
            return printError(fail("", "calibrate", "this build has no Ogre plugin to draw with"));
#endif
        }
    }

    void addCalibrateCommand(CLI::App& app)
    {
        auto args = std::make_shared<CalibrateArgs>();
        CLI::App* cmd = app.add_subcommand(
            "calibrate", "measure what each level of a tree costs on this machine (cached per renderer; budgeted auto "
                         "chooses levels by it)");
        cmd->add_option("trees", args->inputs, ".treelod, .glb or .gltf files")->required();
        cmd->add_option("--calibration", args->directory, "folder of the calibration files (default: the user's cache)");
        cmd->add_flag("--force", args->force, "measure again even when the cache holds the tree's costs");
        cmd->add_flag("--json", args->json, "print the costs as JSON");
        cmd->add_flag("-q,--quiet", args->quiet, "no progress display");
        cmd->callback([args]() { setExitCode(runCalibrate(*args)); });
    }
}
