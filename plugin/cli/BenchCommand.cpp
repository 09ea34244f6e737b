// treelod bench SCENE.json -o DIR [--techniques a,b] [--lod-bias 1,0.5,0.25] [--frames N] [--scale S]
//
// Scripted scene benchmark: the scene's camera path rendered headless for each
// technique and LoD bias, with the polygonal reference ("mesh") and four floors in the same run:
// the Forest's one-quad level ("impostor"), one plain Ogre Entity per tree ("entities": what Ogre users
// pay today), every tree's quad merged into a few static batches ("merged-quads") and a plain Ogre
// BillboardSet per species, unlit ("billboard-set": what an Ogre user writes by hand, the honest floor). The bench bakes what the runs draw (BakeCache), writes the package list and
// runs treelod_frames, which renders and times the frames and links no baker (docs/architecture.md, "Runtime
// vs bake"); then it compares the frames treelod_frames saved. Per frame: CPU time (until the
// frame's commands are submitted), frame time bounded by a one-pixel read-back (Ogre's GL3Plus
// render system offers no timer queries, so the GPU time is the glFinish-bounded wall time),
// batches, triangles, instances per level, bytes of Forest levels built in the frame (at most
// --upload-budget plus one level). On sampled frames: the polygonal
// reference supersampled 2x2, and against it FLIP and multi-scale RMSE (the ellipsoids-and-lines paper §4), and
// temporal noise: the multi-scale RMSE between the frame and the next frame of the path (the ellipsoids-and-lines paper
// §5, Fig. 13), for the reference too. A reference frame whose triangle count would exceed
// --reference-budget is skipped and said so, never estimated. Writes DIR/frames.csv,
// DIR/summary.json and the data of the plots as CSV (frame time along the path, the ellipsoids-and-lines paper Fig. 11;
// the speed/accuracy trade over the LoD biases with the reference and the floors marked, and its
// Pareto front, also in summary.json and printed) with DIR/plots.json; bench/plot.py draws them as
// PNG when python3 has matplotlib.
#include "BenchReport.h"
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ProcessMemory.h"
#include "TreeLod/SceneScript.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#ifdef TREELOD_WITH_OGRE
#include "TreeLod/AtomicFile.h"
#include "TreeLod/CacheTreeBaker.h"
#include "TreeLod/ErrorCurveMeasurer.h"
#include "TreeLod/ErrorCurves.h"
#include "TreeLod/Package.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/Image.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/OgreBootstrap.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeViews.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

namespace TreeLod
{
    using namespace Bench;

#ifdef TREELOD_WITH_OGRE
    int Bench::runProcess(const std::vector<std::string>& argv, bool searchPath, bool silent)
    {
        std::vector<char*> args;
        for (const std::string& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        const pid_t pid = fork();
        if (pid < 0)
            return -1;
        if (pid == 0)
        {
            if (silent)
                if (const int null = open("/dev/null", O_WRONLY); null >= 0)
                {
                    dup2(null, 1);
                    dup2(null, 2);
                }
            (searchPath ? execvp : execv)(args[0], args.data());
            if (!silent)
                std::fprintf(stderr, "treelod: bench: cannot run %s: %s\n", args[0], std::strerror(errno));
            _exit(127);
        }
        int status = 0;
        while (waitpid(pid, &status, 0) < 0)
            if (errno != EINTR)
                return -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
#endif

    namespace
    {
#ifdef TREELOD_WITH_OGRE
        /// treelod_frames: $TREELOD_FRAMES, else beside this executable.
        std::string framesExecutable()
        {
            if (const char* env = std::getenv("TREELOD_FRAMES"); env && *env)
                return env;
            std::error_code ec;
            const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
            return (ec ? std::filesystem::path("treelod_frames") : self.parent_path() / "treelod_frames").string();
        }

        /// The runs treelod_frames timed (DIR/timings.json), with the image metrics of their sampled
        /// frames computed here from the PNGs it saved; each run's first picture is copied to `output`.
        Result<std::vector<Run>> readRuns(const std::string& directory, const std::string& output,
                                          std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>>& references)
        {
            const std::string path = directory + "/timings.json";
            std::ifstream in(path);
            nlohmann::json timings = nlohmann::json::parse(in, nullptr, false);
            if (timings.is_discarded() || !timings.contains("runs"))
                return fail(path, "", "not the timings treelod_frames writes");
            if (!timings.value("complete", true))
                std::fprintf(stderr, "treelod: %s: incomplete (the frame timer stopped after %zu runs); reporting those\n",
                             path.c_str(), timings["runs"].size());
            // A saved frame and the next one: DIR/images/STEM.png and STEM-next.png.
            auto loadPair = [&](const std::string& stem) -> Result<std::pair<Image, Image>> {
                Result<Image> image = readImage(directory + "/images/" + stem + ".png");
                if (!image)
                    return image.error();
                Result<Image> next = readImage(directory + "/images/" + stem + "-next.png");
                if (!next)
                    return next.error();
                return std::make_pair(std::move(*image), std::move(*next));
            };
            std::vector<Run> runs;
            for (const nlohmann::json& r : timings["runs"])
            {
                Run run;
                run.count = r.value("trees", 0u);
                run.technique = r.value("technique", "");
                run.lodBias = r.value("lodBias", 1.0f);
                run.assetBytes = r.value("gpuBytes", std::uint64_t(0));
                run.peakGpuBytes = r.value("peakGpuBytes", run.assetBytes);
                run.residentLevels = r.value("residentLevels", std::int64_t(-1));
                run.plannedGpuBytes = r.value("plannedGpuBytes", std::uint64_t(0));
                run.memoryBudgetBytes = r.value("memoryBudgetBytes", std::uint64_t(0));
                run.binding = r.value("binding", "");
                run.errorBudget = r.value("errorBudget", double(NAN));
                run.occlusion = r.value("occlusion", false);
                run.instanceBytes = r.value("instanceBytes", std::uint64_t(0));
                run.rssMiB = r.value("rssMiB", NAN);
                run.peakRssMiB = r.value("peakRssMiB", NAN);
                run.skipped = r.value("skipped", "");
                run.motionStepSeconds = timings.value("motionStepSeconds", 0.0);
                for (const nlohmann::json& f : r["frames"])
                {
                    FrameRecord record;
                    record.frame = f.value("frame", 0u);
                    record.time = f.value("time", 0.0);
                    record.skipped = f.value("skipped", "");
                    record.timed = f.contains("frameMs");
                    if (record.timed)
                    {
                        record.timing.cpuMilliseconds = f["cpuMs"];
                        record.timing.frameMilliseconds = f["frameMs"];
                        record.timing.batches = f["batches"];
                        record.timing.triangles = f["triangles"];
                        record.visible = f.value("visible", 0u);
                        record.occluded = f.value("occluded", 0u);
                        record.levels = f.value("levels", std::vector<std::uint32_t>{});
                        record.uploadedBytes = f.value("uploadedBytes", std::uint64_t(0));
                        record.gpuBytes = f.value("gpuBytes", std::uint64_t(0));
                    }
                    if (f.contains("motionImage"))
                    {
                        // Temporal error over the trees' pixels (drawn against the background).
                        Result<std::pair<Image, Image>> pair = loadPair(f["motionImage"]);
                        if (!pair)
                            return pair.error();
                        const auto& [image, next] = *pair;
                        FlipOptions options;
                        options.keepErrorMap = true;
                        if (Result<FlipResult> m = flip(image, next, options))
                            record.temporalFlip = meanOverTree(*m, image, next);
                        if (f.value("motionHeld", false))
                        {
                            Result<Image> held = readImage(directory + "/images/" + f["motionImage"].get<std::string>() +
                                                           "-held.png");
                            if (!held)
                                return held.error();
                            if (Result<FlipResult> m = flip(*held, next, options))
                                record.popFlip = meanOverTree(*m, *held, next);
                        }
                        record.switches = f.value("motionSwitches", std::int64_t(-1));
                        record.switchVisible = f.value("motionVisible", std::int64_t(-1));
                    }
                    std::map<std::uint32_t, ReferenceSample>& refs = references[run.count];
                    if (f.contains("referenceImage"))
                    {
                        Result<std::pair<Image, Image>> pair = loadPair(f["referenceImage"]);
                        if (!pair)
                            return pair.error();
                        ReferenceSample sample;
                        sample.image = std::move(pair->first);
                        if (Result<MultiScaleRmseResult> m = multiScaleRmse(sample.image, pair->second))
                            sample.temporalNoise = m->combined;
                        refs[record.frame] = std::move(sample);
                    }
                    if (f.contains("image"))
                    {
                        const std::string stem = f["image"];
                        if (auto it = refs.find(record.frame); it != refs.end())
                        {
                            Result<std::pair<Image, Image>> pair = loadPair(stem);
                            if (!pair)
                                return pair.error();
                            const auto& [image, next] = *pair;
                            if (Result<FlipResult> m = flip(it->second.image, image))
                                record.flip = m->mean;
                            if (Result<MultiScaleRmseResult> m = multiScaleRmse(it->second.image, image))
                                record.msRmse = m->combined;
                            if (Result<MultiScaleRmseResult> m = multiScaleRmse(image, next))
                                record.temporalNoise = m->combined;
                        }
                        else
                            record.skipped += std::string(record.skipped.empty() ? "" : "; ") +
                                              "no reference image for this frame (too costly)";
                        if (run.frames.empty() || !run.hasPicture) // a picture of every run
                        {
                            std::error_code ec;
                            std::filesystem::copy_file(directory + "/images/" + stem + ".png",
                                                       output + "/frame-" + std::to_string(run.count) + "-" +
                                                           run.technique + "-" + number(run.lodBias, 2) + ".png",
                                                       std::filesystem::copy_options::overwrite_existing, ec);
                            run.hasPicture = !ec;
                        }
                    }
                    run.frames.push_back(std::move(record));
                }
                runs.push_back(std::move(run));
            }
            return runs;
        }

        /// The error curves of every package that the budgeted auto choices draw, measured here (an
        /// OffscreenRenderer of this process) where a package lacks them: treelod_frames links no baker.
        Result<void> bakeErrorCurves(const SceneScript& script, const std::vector<LodPolicy>& autoChoices,
                                     const CacheTreeBaker& baker, const ProgressCallback& progress)
        {
            if (autoChoices.empty())
                return {};
            std::unique_ptr<OffscreenRenderer> renderer;
            for (const auto& [source, techniques] : scenePackages(script, autoChoices))
                for (const BakeCacheEntry& entry : baker.getEntries())
                    if (entry.source == source)
                    {
                        if (!renderer)
                            renderer = std::make_unique<OffscreenRenderer>();
                        const auto start = std::chrono::steady_clock::now();
                        Result<bool> measured = ensureErrorCurves(*renderer, entry.path, {}, progress);
                        if (!measured)
                            return measured.error();
                        const double seconds =
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                        if (*measured)
                            report(progress, "error curves of " + entry.name + " measured in " + number(seconds, 1) + " s",
                                   1.0f);
                        break;
                    }
            return {};
        }

        int runBench(const BenchArgs& args)
        {
            Result<SceneScript> loaded = loadSceneScript(args.scene, readGreyImage);
            if (!loaded)
                return printError(loaded.error());
            SceneScript& script = *loaded;
            if (Result<void> shadows = applyShadowOptions(args.shadowSize, args.shadowLodBias, script.shadows); !shadows)
                return printError(shadows.error());
            if (Result<void> wind = applyWindOption(args.wind, script.wind); !wind)
                return printError(wind.error());
            if (!(args.scale > 0.0) || !std::isfinite(args.scale))
                return printError(fail("", "--scale", "must be a positive number"));
            int width = script.width, height = script.height;
            if (Result<void> size = parseSize(args.size, width, height); !size)
                return printError(size.error());
            const std::uint32_t frames = args.frames ? args.frames : script.frames;
            if (Result<std::vector<float>> biases = parseLodBiases(args.lodBiases); !biases)
                return printError(biases.error());
            // Every run draws from these: the reference, the floors, then the techniques.
            Result<std::vector<BenchRun>> asked = parseBenchRuns(splitList(args.techniques));
            if (!asked)
                return printError(asked.error());
            std::vector<LodPolicy> drawn;
            for (const BenchRun& c : comparisonBenchRuns())
                drawn.push_back(c.policy);
            std::vector<LodPolicy> autoChoices; // budgeted auto needs the error curves of what it draws
            for (const BenchRun& run : *asked)
            {
                drawn.push_back(run.policy);
                if (run.policy.mode != LodPolicy::Mode::Fixed)
                    autoChoices.push_back(run.policy);
            }
            if (args.samples == 0 || frames == 0)
                return printError(fail("", "--frames/--samples", "must be >= 1"));
            if (Result<std::vector<std::uint32_t>> motion = parseMotionFrames(args.motionFrames, frames); !motion)
                return printError(motion.error());

            std::error_code ec;
            std::filesystem::create_directories(args.output, ec);
            if (ec)
                return printError(fail(args.output, "", "cannot create the output directory: " + ec.message()));

            // Bake what the runs draw, once per distinct source; treelod_frames reads the list.
            ProgressCallback progress = makeProgress(args.quiet);
            CacheTreeBaker baker(args.cacheDirectory.empty() ? defaultBakeCacheDirectory() : args.cacheDirectory,
                                 progress);
            double bakeSeconds = 0.0;
            try
            {
                for (const auto& [source, techniques] : scenePackages(script, drawn))
                {
                    baker.requirePackage(source, techniques);
                    bakeSeconds += baker.getEntries().back().bakeSeconds;
                    if (!args.quiet)
                        std::fprintf(stderr, "%s\n", baker.getEntries().back().describe().c_str());
                }
            }
            catch (const Ogre::Exception& e)
            {
                return printError(fail(args.scene, "species", e.getDescription()));
            }
            if (Result<void> curves = bakeErrorCurves(script, autoChoices, baker, progress); !curves)
                return printError(curves.error());
            const std::string packageList = args.output + "/packages.json";
            if (Result<void> w = baker.writePackageList(packageList); !w)
                return printError(w.error());

            std::vector<std::string> command = {framesExecutable(), args.scene, "--packages", packageList, "-o",
                                                args.output, "--techniques", args.techniques, "--lod-bias",
                                                args.lodBiases, "--samples", std::to_string(args.samples),
                                                "--reference-budget", number(args.referenceBudget, 6),
                                                "--reference-image-budget", number(imageBudget(args), 6),
                                                "--scale", number(args.scale, 8), "--size",
                                                std::to_string(width) + "x" + std::to_string(height), "--frames",
                                                std::to_string(frames), "--upload-budget",
                                                std::to_string(args.uploadBudget), "--shadow-size",
                                                std::to_string(args.shadowSize), "--shadow-lod-bias",
                                                number(args.shadowLodBias, 8), "--wind", number(args.wind, 8),
                                                "--motion-frames", args.motionFrames};
            if (!args.counts.empty())
                command.insert(command.end(), {"--counts", args.counts});
            if (args.quiet)
                command.push_back("-q");
            if (args.bakeOnly)
            {
                // For a GPU machine (bench/gpu-run.sh bundles it): run this there, bring DIR back, then
                // `treelod bench ... --frames-from DIR` here computes the image metrics and the plots.
                std::string line;
                for (const std::string& a : command)
                    line += (line.empty() ? "" : " ") + ("'" + a + "'");
                std::printf("%s\n", line.c_str());
                return EXIT_OK;
            }
            if (args.framesFrom.empty())
                if (const int code = runProcess(command); code != 0)
                {
                    std::fprintf(stderr, "treelod: bench: %s failed (exit %d)\n", command[0].c_str(), code);
                    return code == EXIT_BAD_INPUT ? EXIT_BAD_INPUT : EXIT_FAILURE_RUN;
                }

            std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>> references; // trees -> frame ->
            Result<std::vector<Run>> runs = readRuns(args.framesFrom.empty() ? args.output : args.framesFrom, args.output, references);
            if (!runs)
                return printError(runs.error());
            for (Run& run : *runs)
                run.bakeSeconds = bakeSeconds;
            return writeOutputs(args, script, frames, width, height, *runs, references, baker) ? EXIT_OK
                                                                                               : EXIT_FAILURE_RUN;
        }
#endif
    }

    void addBenchCommand(CLI::App& app)
    {
        auto args = std::make_shared<BenchArgs>();
        CLI::App* cmd = app.add_subcommand(
            "bench", "Render a scene script's camera path per technique and LoD bias; write frames.csv, summary.json "
                     "and plots (speed against the polygonal reference and the one-quad floor, error, temporal noise)");
        cmd->add_option("scene", args->scene, "scene script (samples/scenes/*.json)")->required();
        cmd->add_option("-o,--output", args->output, "output directory")->required();
#ifdef TREELOD_WITH_OGRE
        const std::string known = knownSceneTechniques();
        const std::string comparisons = describeComparisonRuns();
        args->techniques = defaultBenchTechniques();
#else
        const std::string known = "(none: this build has no Ogre plugin)";
        const std::string comparisons = known;
#endif
        cmd->add_option("--techniques", args->techniques,
                        "comma-separated techniques besides the comparison runs (" + comparisons + "): auto (the "
                        "script's choice), auto@E (budgeted auto at error budget E), auto~MS (under a frame budget of "
                        "MS milliseconds) or any of " + known + "; each may end in +fadeT (level transitions of length T, 0: hard switches) and +memMB (auto: a GPU memory budget of MB megabytes)")
            ->capture_default_str();
        cmd->add_option("--lod-bias", args->lodBiases, "comma-separated LoD biases (< 1 = less detail)")
            ->capture_default_str();
        cmd->add_option("--frames", args->frames, "frames along the path (default: the script's)");
        cmd->add_option("--scale", args->scale, "tree count factor of random placements (llvmpipe: e.g. 0.05)")
            ->capture_default_str();
        cmd->add_option("--counts", args->counts, "comma-separated total tree counts (default: the script's \"counts\")");
        cmd->add_option("--size", args->size, "WxH (default: the script's resolution)");
        cmd->add_option("--samples", args->samples, "frames compared with the supersampled reference")
            ->capture_default_str();
        cmd->add_option("--reference-budget", args->referenceBudget,
                        "skip reference frames that would submit more triangles than this")
            ->capture_default_str();
        cmd->add_option("--reference-image-budget", args->referenceImageBudget,
                        "the same for the reference's supersampled images on sampled frames (default: "
                        "--reference-budget); images cost no timed frames, so this may be larger");
        cmd->add_option("--shadow-size", args->shadowSize,
                        "shadow map size over the script's (-1: the script's, 0: off; scaled-down runs on llvmpipe)")
            ->capture_default_str();
        cmd->add_option("--shadow-lod-bias", args->shadowLodBias,
                        "LoD bias of the Forest's shadow casters over the script's (0: the script's; < 1: coarser)")
            ->capture_default_str();
        cmd->add_option("--wind", args->wind, "the wind's strength over the script's (-1: the script's, 0: calm)")
            ->capture_default_str();
        cmd->add_option("--upload-budget", args->uploadBudget,
                        "bytes of Forest levels built per frame (0 = no limit); levels waiting draw a coarser one")
            ->capture_default_str();
        cmd->add_option("--motion-frames", args->motionFrames,
                        "frames measured in motion: FLIP between the frame and the next at the script's frame rate "
                        "over the trees' pixels, and the level switches between them; all, or a count evenly along "
                        "the path (0: none)")
            ->capture_default_str();
        cmd->add_option("--cache", args->cacheDirectory, "bake cache directory (default: $XDG_CACHE_HOME/treelod)");
        cmd->add_flag("--bake-only", args->bakeOnly,
                      "bake and write DIR/packages.json, print the treelod_frames command (to run on a GPU machine)");
        cmd->add_option("--frames-from", args->framesFrom,
                        "read treelod_frames' output (timings.json, images/) from this directory instead of running it");
        cmd->add_flag("--json", args->json, "also print summary.json");
        cmd->add_flag("-q,--quiet", args->quiet, "no progress");
        cmd->callback([args] {
#ifdef TREELOD_WITH_OGRE
            try
            {
                setExitCode(runBench(*args));
            }
            catch (const Ogre::Exception& e)
            {
                std::fprintf(stderr, "treelod: bench: %s\n", e.getDescription().c_str());
                setExitCode(EXIT_FAILURE_RUN);
            }
#else
            setExitCode(printError(fail("", "bench", "this treelod was built without Ogre")));
#endif
        });
    }
}
