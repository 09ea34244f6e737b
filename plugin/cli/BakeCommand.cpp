// treelod bake INPUT.glb -o OUT.treelod [--technique NAME]... [--leaf-material NAME]... [--error-curves] [-q]
// treelod bake CAPTURE_FOLDER -o OUT.treelod [--technique NAME]... [--option NAME.OPTION=VALUE]... [-q]
// Imports the tree, bakes one chunk set per technique plus the "meta" chunk (source file
// name, its sourceHashOf() as the bake cache records it, options) and writes the package atomically:
// on any error nothing is written and the exit code is 2. A capture folder (photographs and their
// cameras) bakes the techniques that bake from photographs (BakeTechnique::bakeCapture), with a
// reference of bounds only (ModelChunk.h).
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/BakeCache.h"
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/ErrorCurves.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"

#ifdef TREELOD_WITH_OGRE
#include "TreeLod/ErrorCurveMeasurer.h"
#include "TreeLod/OffscreenRenderer.h"
#endif

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

namespace TreeLod
{
    namespace
    {
        struct BakeArgs
        {
            std::string input;
            std::string output;
            std::vector<std::string> techniques;
            std::vector<std::string> leafMaterials;
            std::vector<std::string> options; ///< TECHNIQUE.NAME=VALUE
            bool errorCurves = false;
            bool quiet = false;
        };

        /// The name of the folder at `path`: "photos" for "photos/", the working directory's for ".".
        std::string folderName(const std::string& path)
        {
            std::error_code ec;
            std::filesystem::path p = std::filesystem::absolute(path, ec).lexically_normal();
            if (p.filename().empty())
                p = p.parent_path();
            return p.filename().string();
        }

        /// The registered bakers that bake from a capture folder, comma-separated, for messages.
        std::string captureBakers()
        {
            std::string names;
            for (const BakeTechnique& t : bakeTechniques())
                if (t.bakeCapture)
                    names += (names.empty() ? "" : ", ") + std::string(t.name);
            return names;
        }

        /// `treelod bake CAPTURE_FOLDER`: the chunks of the techniques that bake from photographs
        /// (BakeTechnique::bakeCapture; all of them without --technique) and a reference of bounds only.
        int runBakeCapture(const BakeArgs& args)
        {
            const std::string& folder = args.input;
            std::vector<const BakeTechnique*> techniques;
            for (const BakeTechnique& t : bakeTechniques())
                if (t.bakeCapture && args.techniques.empty())
                    techniques.push_back(&t);
            for (const std::string& name : args.techniques)
            {
                const BakeTechnique* t = findBakeTechnique(name);
                if (!t || !t->bakeCapture)
                    return printError(fail(folder, "option --technique",
                                           "'" + name + "': a capture folder (photographs) can only bake " +
                                               captureBakers()));
                if (std::find(techniques.begin(), techniques.end(), t) == techniques.end())
                    techniques.push_back(t);
            }
            if (techniques.empty())
                return printError(fail(folder, "", "this build has no technique that bakes from photographs"));
            if (!args.leafMaterials.empty())
                return printError(fail(folder, "option --leaf-material", "applies to glTF input, not to photographs"));
            if (args.errorCurves)
                return printError(fail(folder, "option --error-curves",
                                       "error curves compare the levels with the polygonal tree, and photographs "
                                       "have none"));
            std::map<const BakeTechnique*, BakeOptions> values;
            nlohmann::json optionsJson = nlohmann::json::object();
            for (const std::string& option : args.options)
            {
                Result<BakeOptionAssignment> parsed = parseBakeOptionAssignment(option);
                if (!parsed)
                    return printError(parsed.error());
                const auto& [name, key, value] = parsed.value();
                const BakeTechnique* t = findBakeTechnique(name);
                if (!t || std::find(techniques.begin(), techniques.end(), t) == techniques.end())
                    return printError(fail("", "option --option '" + option + "'",
                                           "'" + name + "' is not a technique being baked"));
                values[t][key] = value;
                optionsJson[name][key] = value;
            }
            for (const auto& [technique, given] : values)
                if (Result<void> checked = checkBakeOptions(*technique, given, args.output); !checked)
                    return printError(checked.error());

            const std::filesystem::path outDir = std::filesystem::path(args.output).parent_path();
            std::error_code ec;
            if (!outDir.empty() && !std::filesystem::is_directory(outDir, ec))
                return printError(fail(args.output, "", "directory '" + outDir.string() + "' does not exist"));

            const ProgressCallback progress = makeProgress(args.quiet);
            Result<std::string> hash = sourceHashOf(folder);
            if (!hash)
                return printError(hash.error());
            PackageWriter writer;
            PackageMeta meta;
            meta.source = folderName(folder);
            meta.sourceHash = hash.value();
            meta.optionsJson = optionsJson.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
            meta.techniques = {REFERENCE_CHUNK};
            std::string baked = REFERENCE_CHUNK;
            for (const BakeTechnique* t : techniques)
            {
                if (Result<void> added = t->bakeCapture(writer, folder, meta.source, values[t], args.output, progress);
                    !added)
                    return printError(added.error());
                meta.techniques.push_back(t->name);
                baked += std::string(", ") + t->name;
            }
            if (Result<void> added = addMetaChunk(writer, meta); !added)
                return printError(added.error());

            const std::vector<std::uint8_t> bytes = writer.toBytes();
            report(progress, "write", 0.0f);
            if (Result<void> written = writeFileAtomic(args.output, bytes); !written)
                return printError(written.error());
            report(progress, "write", 1.0f);
            std::printf("wrote %s: %zu chunks (%s + meta), %zu bytes; from photographs, no polygons\n",
                        args.output.c_str(), writer.chunkCount(), baked.c_str(), bytes.size());
            return EXIT_OK;
        }

        int runBake(const BakeArgs& args)
        {
            std::error_code isDirectoryError;
            if (std::filesystem::is_directory(args.input, isDirectoryError))
                return runBakeCapture(args);
            std::vector<const BakeTechnique*> techniques;
            for (const std::string& name : args.techniques.empty() ? std::vector<std::string>{REFERENCE_CHUNK}
                                                                   : args.techniques)
            {
                const BakeTechnique* t = findBakeTechnique(name);
                if (!t)
                    return printError(fail("", "option --technique",
                                           "'" + name + "' is not a known technique (known: " + knownBakeTechniques() +
                                               ")"));
                if (std::find(techniques.begin(), techniques.end(), t) == techniques.end())
                    techniques.push_back(t);
            }

            // --option TECHNIQUE.NAME=VALUE, for a technique being baked and an option it declares.
            std::map<const BakeTechnique*, BakeOptions> options;
            nlohmann::json optionsJson = {{"leafMaterials", args.leafMaterials}};
            for (const std::string& option : args.options)
            {
                Result<BakeOptionAssignment> parsed = parseBakeOptionAssignment(option);
                if (!parsed)
                    return printError(parsed.error());
                const auto& [technique, name, value] = parsed.value();
                const BakeTechnique* t = findBakeTechnique(technique);
                if (!t || std::find(techniques.begin(), techniques.end(), t) == techniques.end())
                    return printError(fail("", "option --option '" + option + "'",
                                           "'" + technique + "' is not a technique being baked"));
                options[t][name] = value;
                optionsJson[technique][name] = value;
            }
            for (const auto& [technique, values] : options)
                if (Result<void> checked = checkBakeOptions(*technique, values, args.output); !checked)
                    return printError(checked.error());

            // Fail before the import, not after it, when the output cannot be written.
            const std::filesystem::path outDir = std::filesystem::path(args.output).parent_path();
            std::error_code ec;
            if (!outDir.empty() && !std::filesystem::is_directory(outDir, ec))
                return printError(fail(args.output, "", "directory '" + outDir.string() + "' does not exist"));

            const std::string ext = lowerCaseExtension(args.input);
            if (ext != ".glb" && ext != ".gltf")
                return printError(fail(args.input, "",
                                       "unknown tree format '" + ext +
                                           "' (expected .glb, .gltf or a capture folder holding cameras.json)"));
            Result<std::string> hash = sourceHashOf(args.input);
            if (!hash)
                return printError(hash.error());

            const ProgressCallback progress = makeProgress(args.quiet);
            ImportReport importReport;
            Result<TreeModel> model = importTreeFile(args.input, args.leafMaterials, progress, {}, &importReport);
            if (!model)
                return printError(model.error());
            for (const std::string& w : importReport.warnings)
                std::fprintf(stderr, "treelod: %s: warning: %s\n", args.input.c_str(), w.c_str());

            PackageWriter writer;
            PackageMeta meta;
            meta.source = std::filesystem::path(args.input).filename().string();
            meta.sourceHash = hash.value();
            meta.optionsJson = optionsJson.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
            for (const BakeTechnique* t : techniques)
            {
                Result<void> baked = t->bake(writer, model.value(), options[t], args.output, progress);
                if (!baked)
                    return printError(baked.error());
                meta.techniques.push_back(t->name);
            }
            // Techniques that index the reference chunk add it themselves: list it too.
            if (writer.hasChunk(REFERENCE_CHUNK, 0) &&
                std::find(meta.techniques.begin(), meta.techniques.end(), REFERENCE_CHUNK) == meta.techniques.end())
                meta.techniques.insert(meta.techniques.begin(), REFERENCE_CHUNK);
            Result<void> added = addMetaChunk(writer, meta);
            if (!added)
                return printError(added.error());

            std::vector<std::uint8_t> bytes = writer.toBytes();
            if (args.errorCurves)
            {
#ifdef TREELOD_WITH_OGRE
                try
                {
                    OffscreenRenderer renderer;
                    Result<std::vector<std::uint8_t>> measured =
                        addErrorCurves(renderer, bytes, args.output, {}, progress);
                    if (!measured)
                        return printError(measured.error());
                    bytes = std::move(measured.value());
                    meta.techniques.push_back(ERROR_CURVES_CHUNK);
                }
                catch (const Ogre::Exception& e)
                {
                    return printError(fail(args.output, "error curves", e.getDescription()));
                }
#else
                return printError(fail("", "--error-curves", "this build has no Ogre plugin to draw the levels with"));
#endif
            }
            report(progress, "write", 0.0f);
            Result<void> written = writeFileAtomic(args.output, bytes);
            if (!written)
                return printError(written.error());
            report(progress, "write", 1.0f);

            std::string list;
            for (const std::string& t : meta.techniques)
                list += (list.empty() ? "" : ", ") + t;
            std::printf("wrote %s: %zu chunks (%s + meta), %zu bytes; %zu leaves, %zu bark triangles\n",
                        args.output.c_str(), writer.chunkCount() + (args.errorCurves ? 1 : 0), list.c_str(),
                        bytes.size(), model->leaves.size(), model->barkTriangleCount());
            return EXIT_OK;
        }
    }

    void addBakeCommand(CLI::App& app)
    {
        auto args = std::make_shared<BakeArgs>();
        std::string help = "technique to bake (repeatable; default reference). Known:";
        std::string optionHelp = "a baker's option, TECHNIQUE.NAME=VALUE (repeatable). Known:";
        for (const BakeTechnique& t : bakeTechniques())
        {
            help += std::string("\n  ") + t.name + ": " + t.description;
            for (const BakeOptionInfo& o : t.options)
                optionHelp += std::string("\n  ") + t.name + "." + o.name + " (default " + o.defaultValue + "): " +
                              o.description;
        }
        CLI::App* cmd = app.add_subcommand(
            "bake", "bake a .glb/.gltf tree, or a capture folder of photographs, into a .treelod package");
        cmd->add_option("input", args->input,
                        ".glb or .gltf file, or a capture folder (cameras.json and RGBA photographs), which only "
                        "the techniques that bake from photographs take: " + captureBakers())
            ->required();
        cmd->add_option("-o,--output", args->output, ".treelod file to write (atomically)")->required();
        cmd->add_option("--technique", args->techniques, help)->allow_extra_args(false);
        cmd->add_option("--leaf-material", args->leafMaterials,
                        "materials with this name are leaves (repeatable; default: alphaMode MASK/BLEND)")
            ->allow_extra_args(false);
        cmd->add_option("--option", args->options, optionHelp)->allow_extra_args(false);
        cmd->add_flag("--error-curves", args->errorCurves,
                      "also measure the error curves of every level (image error against screen height, drawn "
                      "through Ogre against the CPU reference): what budgeted auto chooses levels by");
        cmd->add_flag("-q,--quiet", args->quiet, "no progress display");
        cmd->callback([args]() { setExitCode(runBake(*args)); });
    }
}
