// treelod generate --preset oak|broadleaf|conifer|birch|shrub --seed N --leaves N
//                  [--height M] [--texture-size N] -o OUT.glb
// A procedural tree (TreeGenerator.h) written as .glb (GltfExporter.h). Bad options exit 2
// and write nothing; the .glb is written atomically.
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/GltfExporter.h"
#include "TreeLod/TreeGenerator.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

namespace TreeLod
{
    namespace
    {
        struct GenerateArgs
        {
            std::string preset = "oak";
            std::uint32_t seed = 1;
            long long leaves = 0;
            double height = 0.0;
            int textureSize = 256;
            std::uint32_t leafImages = 1, leafMaterials = 1;
            float leafFold = 0.0f;
            std::string output;
            bool quiet = false;
        };

        int runGenerate(const GenerateArgs& args)
        {
            GeneratorOptions options;
            if (!parsePreset(args.preset, options.preset))
                return printError(fail("", "option --preset",
                                       "'" + args.preset + "' is not oak, broadleaf, conifer, birch or shrub"));
            if (args.leaves != 0 && (args.leaves < 100 || args.leaves > 200000))
                return printError(fail("", "option --leaves",
                                       "leaf count " + std::to_string(args.leaves) + " is outside 100..200000"));
            // Fail before the work when the output can't be written there.
            const std::filesystem::path out(args.output);
            std::error_code ec;
            if (out.has_parent_path() && !std::filesystem::is_directory(out.parent_path(), ec))
                return printError(fail(args.output, "", "directory '" + out.parent_path().string() + "' does not exist"));
            options.seed = args.seed;
            options.leafCount = std::uint32_t(args.leaves);
            options.height = float(args.height);
            options.textureSize = args.textureSize;
            options.leafImages = args.leafImages;
            options.leafMaterials = args.leafMaterials;
            options.leafFold = args.leafFold;

            const auto start = std::chrono::steady_clock::now();
            Result<TreeModel> model = generateTree(options, makeProgress(args.quiet));
            if (!model)
                return printError(model.error());
            Result<std::vector<std::uint8_t>> bytes = encodeGlb(*model);
            if (!bytes)
                return printError(fail(args.output, bytes.error().element, bytes.error().reason));
            Result<void> written = writeFileAtomic(args.output, *bytes);
            if (!written)
                return printError(written.error());
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const glm::vec3 size = model->boundsMax - model->boundsMin;
            std::printf("wrote %s: %s seed %u, %zu leaves, %zu bark triangles, %zu skeleton nodes, "
                        "%.2f x %.2f x %.2f m, %zu bytes (%.2f s)\n",
                        args.output.c_str(), presetName(options.preset), unsigned(options.seed), model->leaves.size(),
                        model->barkTriangleCount(), model->skeleton.size(), size.x, size.y, size.z, bytes->size(),
                        seconds);
            return EXIT_OK;
        }
    }

    void addGenerateCommand(CLI::App& app)
    {
        auto args = std::make_shared<GenerateArgs>();
        CLI::App* cmd = app.add_subcommand("generate", "generate a procedural tree (Weber & Penn style) as .glb");
        cmd->add_option("--preset", args->preset, "oak (= broadleaf), conifer, birch or shrub")->capture_default_str();
        cmd->add_option("--seed", args->seed, "random seed; the same options give the same file")->capture_default_str();
        cmd->add_option("--leaves", args->leaves, "exact leaf count, 100..200000 (default: the preset's)");
        cmd->add_option("--height", args->height, "height of the stems in metres, 0.1..1000 (default: the preset's)");
        cmd->add_option("--texture-size", args->textureSize, "leaf texture size, power of two 16..4096")
            ->capture_default_str();
        cmd->add_option("--leaf-images", args->leafImages,
                        "leaf images, 1..4; above 1 a 2x2 atlas, each leaf mapping one cell")
            ->capture_default_str();
        cmd->add_option("--leaf-materials", args->leafMaterials,
                        "leaf materials, 1..16, each with its own tint and alpha cutoff")
            ->capture_default_str();
        cmd->add_option("--leaf-fold", args->leafFold,
                        "degrees, 0..80: each leaf two quads folded along its midrib, wings raised by this angle")
            ->capture_default_str();
        cmd->add_option("-o,--output", args->output, ".glb file to write")->required();
        cmd->add_flag("-q,--quiet", args->quiet, "no progress display");
        cmd->callback([args]() { setExitCode(runGenerate(*args)); });
    }
}
