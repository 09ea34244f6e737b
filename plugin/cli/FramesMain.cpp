// treelod_frames SCENE.json --packages LIST -o DIR [--techniques] [--lod-bias] [--frames] [--scale] [--counts]
//                [--size] [--samples] [--reference-budget] [--reference-image-budget] [--entity-limit]
//                [--upload-budget] [--shadow-size] [--shadow-lod-bias] [--wind] [--preload] [--skip-comparisons] [-q]
//
// The program that renders and times the frames of `treelod bench`: it links OGRE and the
// runtime only (Plugin_TreeLod, TreeLodOffscreen, TreeLodScene, TreeLodScript, TreeLodRuntime), never
// TreeLodBake (docs/architecture.md, "Runtime vs bake"), so it fits the GPU bundle that
// bench/gpu-run.sh prepares.
// It bakes nothing: packages come from the list `treelod bench` writes after baking them
// (PackageListBaker). `treelod bench` runs it and then computes the image metrics from the frames it
// saved; on a GPU machine run it directly with the same options and the bench's package list.
//
// Runs per tree count: the polygonal reference ("mesh"), the floors ("impostor": the Forest's one-quad
// level; "entities": one Ogre Entity per tree; "merged-quads": all quads merged into a few static
// batches; "billboard-set": a plain Ogre BillboardSet per species, unlit), then every technique
// at every LoD bias. Writes DIR/timings.json (per run: per frame
// CPU ms, frame ms (bounded by a one-pixel read-back), batches, triangles, visible trees, trees per
// level, bytes uploaded, pending levels; run totals: GPU bytes, instance bytes, resident memory) and,
// on sampled frames, PNGs under DIR/images: the reference supersampled 2x2 and every run at one
// sample per pixel, each with the next frame at the script's frame rate (temporal noise). Motion
// frames (--motion-frames): after a run's timed frames, for each chosen frame a run-in frame one
// step of the script's frame rate before it (so the Forest's levels and hysteresis are as motion
// leaves them), the frame, the next with the Forest's levels held (Forest::setLodFrozen) and the
// next, at one sample per pixel with the ground hidden (the trees against the background), the
// last three saved as PNGs with the level switches between the frame and the next.
#include "CliSupport.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/ErrorCurves.h"
#include "TreeLod/ForestScene.h"
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/Wind.h"
#include "TreeLod/PackageListBaker.h"
#include "TreeLod/ProcessMemory.h"
#include "TreeLod/SceneScript.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        struct FramesArgs
        {
            std::string scene;
            std::string packages;
            std::string output;
            std::string techniques = defaultBenchTechniques();
            std::string lodBiases = "1,0.5,0.25";
            std::uint32_t frames = 0; // 0 = the script's
            double scale = 1.0;
            std::string size;
            std::uint32_t samples = 4;
            double referenceBudget = 3e6;
            double referenceImageBudget = 0.0;
            std::string counts;
            std::uint64_t entityLimit = 200000;
            std::uint64_t uploadBudget = 8000000; // bytes per frame (Forest::setUploadBudget; 0 = no limit)
            int shadowSize = -1;          // -1: the script's; 0: off (applyShadowOptions)
            double shadowLodBias = 0.0;   // 0: the script's
            double wind = -1.0;           // the wind's strength; -1: the script's
            bool preload = false;         // every Forest level built before the frames (no uploads timed)
            bool skipComparisons = false; // only the techniques: no reference, no floors (memory of one scene)
            std::string motionFrames = "all"; // frames measured in motion: "all", or a count evenly along the path
            std::string calibration;      // "" = userCacheDirectory(): where cost calibrations are kept
            bool quiet = false;
        };

        /// Triangles the polygonal reference would submit from `camera`: visible trees times their
        /// reference triangle counts (exact, not a guess at time: the budget is in triangles).
        std::uint64_t referenceTriangles(ForestScene& scene, const CameraSpec& camera, int width, int height)
        {
            Forest& forest = scene.getForest();
            ForestVisibility visibility;
            const CullCamera cull = CullCamera::fromSpec(camera, float(width), float(height));
            if (!forest.getInstances().cull(cull, 1.0f, visibility))
                return 0;
            std::uint64_t triangles = 0;
            for (const ForestBucket& bucket : visibility.getBuckets())
            {
                const ReferenceChunk& reference = forest.getAsset(bucket.kind)->getReference();
                triangles += std::uint64_t(bucket.count) *
                             (reference.model.barkIndices.size() + reference.model.leafIndices.size()) / 3;
            }
            return triangles;
        }

        std::vector<std::uint32_t> levelHistogram(const Forest& forest)
        {
            std::vector<std::uint32_t> levels;
            for (const std::vector<std::uint32_t>& species : forest.getStats().levelCounts)
            {
                if (levels.size() < species.size())
                    levels.resize(species.size(), 0);
                for (std::size_t l = 0; l < species.size(); ++l)
                    levels[l] += species[l];
            }
            return levels;
        }

        std::string biasText(float bias)
        {
            char text[32];
            std::snprintf(text, sizeof text, "%g", double(bias));
            return text;
        }

        /// The file name stem of a run's sampled frame (the bench reads the same names).
        std::string imageStem(std::uint32_t trees, const std::string& technique, float bias, std::uint32_t frame)
        {
            return std::to_string(trees) + "-" + technique + "-" + biasText(bias) + "-" + std::to_string(frame);
        }

        int runFrames(const FramesArgs& args)
        {
            // The renderer first: readGreyImageOgre (heightfields) needs Ogre's image codecs.
            OffscreenRenderer renderer;
            Result<SceneScript> loaded = loadSceneScript(args.scene, readGreyImageOgre);
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
            if (args.samples == 0 || frames == 0)
                return printError(fail("", "--frames/--samples", "must be >= 1"));
            Result<std::vector<float>> parsedBiases = parseLodBiases(args.lodBiases);
            if (!parsedBiases)
                return printError(parsedBiases.error());
            const std::vector<float>& biases = *parsedBiases;
            Result<std::vector<BenchRun>> asked = parseBenchRuns(splitList(args.techniques));
            if (!asked)
                return printError(asked.error());
            std::vector<BenchRun> techniques;
            for (const BenchRun& run : *asked)
                if (args.skipComparisons || !isComparisonRun(run.name))
                    techniques.push_back(run); // otherwise run once below, with the comparisons
            std::vector<std::uint32_t> counts = script.counts;
            if (!args.counts.empty())
            {
                counts.clear();
                for (const std::string& c : splitList(args.counts))
                {
                    char* end = nullptr;
                    const unsigned long v = std::strtoul(c.c_str(), &end, 10);
                    if (*end != '\0' || v == 0 || v > 0xFFFFFFFFul)
                        return printError(fail("", "--counts", "'" + c + "' is not a tree count >= 1"));
                    counts.push_back(std::uint32_t(v));
                }
            }
            if (counts.empty())
                counts.push_back(0); // as the script places them
            const double imageBudget = args.referenceImageBudget > 0.0 ? args.referenceImageBudget : args.referenceBudget;
            Result<std::vector<std::uint32_t>> motionFrames = parseMotionFrames(args.motionFrames, frames);
            if (!motionFrames)
                return printError(motionFrames.error());
            const std::vector<std::uint32_t>& motion = *motionFrames;

            std::error_code ec;
            std::filesystem::create_directories(args.output + "/images", ec);
            if (ec)
                return printError(fail(args.output, "", "cannot create the output directory: " + ec.message()));

            ProgressCallback progress = makeProgress(args.quiet);
            renderer.setLighting(sceneLighting(script));
            PackageListBaker packages(args.packages);
            TreeAssetManager::getSingleton().setBaker(&packages);
            struct BakerReset
            {
                ~BakerReset() { TreeAssetManager::getSingleton().setBaker(nullptr); }
            } bakerReset;

            // Sampled frames: evenly along the path (never the last: its successor is the temporal pair).
            std::vector<std::uint32_t> sampled;
            const std::uint32_t samples = std::min(args.samples, std::max<std::uint32_t>(1, frames - 1));
            for (std::uint32_t i = 0; i < samples; ++i)
                sampled.push_back(frames <= 1 ? 0
                                              : std::uint32_t((std::uint64_t(i) * 2 + 1) * (frames - 1) / (2 * samples)));
            auto isSampled = [&](std::uint32_t f) { return std::find(sampled.begin(), sampled.end(), f) != sampled.end(); };
            // The temporal pair: the next frame at the script's own frame rate (not --frames'), so
            // temporal noise does not depend on how much the bench thins the path out.
            const double nativeStep =
                script.frames > 1 ? frameTime(script, 1, script.frames) - frameTime(script, 0, script.frames) : 0.0;
            // The camera at path time t, with the wind's clock set to t: the reference and every
            // technique see the same wind in the same frame.
            auto frameAt = [&](double t) {
                Wind::setTime(t);
                return cameraAt(script, t);
            };
            auto nextCamera = [&](std::uint32_t f) { return frameAt(frameTime(script, f, frames) + nativeStep); };
            auto save = [&](const RgbaImage& image, const std::string& stem) {
                OffscreenRenderer::savePng(image, args.output + "/images/" + stem + ".png");
            };

            // Block-compressed textures as this renderer samples them faster: measured once per renderer
            // (cached with the costs), before any texture is uploaded.
            const std::string calibrationDir = args.calibration.empty() ? userCacheDirectory() : args.calibration;
            if (Result<TextureSamplingCost> sampling = requireTextureUpload(renderer, calibrationDir, {}, progress);
                !sampling)
                return printError(sampling.error());
            else if (!args.quiet)
                std::fprintf(stderr, "block-compressed textures on %s: %s (sampling %.2f ms, RGBA8 %.2f ms)\n",
                             rendererString(renderer.getRoot()).c_str(),
                             TreeAssetManager::getSingleton().getCompressedTextureUpload() ==
                                     CompressedTextureUpload::Decoded
                                 ? "decoded at load"
                                 : "as stored",
                             sampling->compressedMs, sampling->decodedMs);
            // Budgeted auto needs this machine's cost of every level: calibrated once per package and
            // renderer (cached), before any scene exists, since calibrating draws alone.
            std::map<std::string, std::vector<LevelCost>> levelCosts; // by assetCostKey
            std::vector<LodPolicy> autoChoices;
            for (const BenchRun& run : techniques)
                if (run.policy.mode != LodPolicy::Mode::Fixed)
                    autoChoices.push_back(run.policy);
            if (!autoChoices.empty())
                for (const auto& [source, bake] : scenePackages(script, autoChoices))
                {
                    TreeAssetPtr asset = TreeAssetManager::getSingleton().require(source, bake, "TreeLod");
                    if (!asset->hasChunk(ERROR_CURVES_CHUNK))
                        continue; // auto draws the fixed bands (ForestScene logs why)
                    bool calibrated = false;
                    Result<std::vector<LevelCost>> costs = requireLevelCosts(
                        renderer, *asset, calibrationDir, {}, progress, &calibrated);
                    if (!costs)
                        return printError(costs.error());
                    if (calibrated && !args.quiet)
                        std::fprintf(stderr, "calibrated %zu levels of %s on %s\n", costs->size(), source.c_str(),
                                     rendererString(renderer.getRoot()).c_str());
                    levelCosts[levelCostKey(*asset)] = std::move(costs.value());
                }

            using nlohmann::json;
            json runsJson = json::array();
            // Rewritten whole after every run ("complete": false until the last): a run cut short
            // (the GPU machine's time limit) keeps the runs it finished.
            auto writeTimings = [&](bool complete) {
                const json out = {{"scene", script.name},
                                  {"file", script.file},
                                  {"resolution", {width, height}},
                                  {"frames", frames},
                                  {"sampled", sampled},
                                  {"motionFrames", motion},
                                  {"motionStepSeconds", nativeStep},
                                  {"scale", args.scale},
                                  {"shadowMap", script.shadows.enabled ? script.shadows.textureSize : 0},
                                  {"shadowLodBias", script.shadows.lodBias},
                                  {"windStrength", script.wind.strength},
                                  {"renderer", renderer.getRoot().getRenderSystem()->getName()},
                                  {"complete", complete},
                                  {"runs", runsJson}};
                const std::string text = out.dump(1) + "\n";
                return writeFileAtomic(args.output + "/timings.json",
                                       std::vector<std::uint8_t>(text.begin(), text.end()));
            };
            for (std::uint32_t count : counts)
            {
                ForestSceneOptions options;
                options.levelCosts = [&](TreeAsset& asset) {
                    const auto found = levelCosts.find(levelCostKey(asset));
                    if (found == levelCosts.end())
                        OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "no calibrated costs for " + asset.getName(),
                                    "treelod_frames");
                    return found->second;
                };
                options.placement.totalCount = count;
                options.placement.scale = args.scale;
                options.uploadBudget = args.uploadBudget;
                std::vector<std::pair<BenchRun, std::vector<float>>> plan;
                if (!args.skipComparisons)
                    for (const BenchRun& c : comparisonBenchRuns())
                        plan.push_back({c, {1.0f}});
                for (const BenchRun& t : techniques)
                    plan.push_back({t, biases});
                for (const auto& [benchRun, runBiases] : plan)
                {
                    const std::string& technique = benchRun.name;
                    options.policy = benchRun.policy;
                    const std::uint32_t placed = std::uint32_t(generatePlacements(script, options.placement).size());
                    const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
                    const BaselineInfo* baseline = registry.findBaseline(technique);
                    if (baseline && baseline->oneObjectPerTree && placed > args.entityLimit)
                    {
                        json run = {{"trees", placed}, {"technique", technique}, {"lodBias", 1.0},
                                    {"skipped", std::to_string(placed) + " objects > --entity-limit " +
                                                    std::to_string(args.entityLimit)},
                                    {"frames", json::array()}};
                        runsJson.push_back(run);
                        continue;
                    }
                    const auto buildStart = std::chrono::steady_clock::now();
                    std::unique_ptr<ForestScene> scene;
                    try
                    {
                        scene = std::make_unique<ForestScene>(renderer.getSceneManager(), renderer.getContentNode(),
                                                              script, options);
                    }
                    catch (const Ogre::Exception& e)
                    {
                        return printError(fail(args.scene, "technique " + technique, e.getDescription()));
                    }
                    if (args.preload)
                        scene->getForest().makeAllResident();
                    const double buildSeconds =
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - buildStart).count();
                    if (script.shadows.enabled)
                        renderer.setShadowFarDistance(ForestScene::getShadowFarDistance());
                    const std::uint32_t trees = std::uint32_t(scene->getPlacements().size());
                    for (float bias : runBiases)
                    {
                        // Untimed warm-up along the path: GL3Plus links each program on first use, which would
                        // otherwise land in the first frame that shows a level. Levels the warm-up does not see
                        // become resident during the timed frames, within the upload budget (worst frame).
                        renderer.setLodBias(bias);
                        for (std::uint32_t w = 0; w < std::min<std::uint32_t>(frames, 4); ++w)
                            renderer.renderTimedFrame(frameAt(frameTime(script, w * (frames - 1) / 3, frames)), width, height);
                        json run = {{"trees", trees}, {"technique", technique}, {"lodBias", bias},
                                    {"buildSeconds", buildSeconds}};
                        json frameRows = json::array();
                        std::uint64_t peakGpuBytes = scene->getGpuBytes();
                        const std::string label = technique + " bias " + biasText(bias) + " (" + std::to_string(trees) +
                                                  (trees == 1 ? " tree)" : " trees)");
                        for (std::uint32_t f = 0; f < frames; ++f)
                        {
                            progress(label, float(f) / float(frames));
                            const double time = frameTime(script, f, frames);
                            json row = {{"frame", f}, {"time", time}};
                            const CameraSpec camera = frameAt(time);
                            std::uint64_t referenceCost = 0;
                            if (technique == REFERENCE_TECHNIQUE)
                                referenceCost = referenceTriangles(*scene, camera, width, height);
                            std::string skipped;
                            if (technique == REFERENCE_TECHNIQUE && double(referenceCost) > args.referenceBudget)
                                skipped = "reference too costly: " + std::to_string(referenceCost) +
                                          " triangles > budget " + std::to_string(std::uint64_t(args.referenceBudget));
                            else
                            {
                                const FrameTiming timing = renderer.renderTimedFrame(camera, width, height);
                                const ForestStats& stats = scene->getForest().getStats();
                                row["cpuMs"] = timing.cpuMilliseconds;
                                row["frameMs"] = timing.frameMilliseconds;
                                row["batches"] = timing.batches;
                                row["triangles"] = timing.triangles;
                                const std::uint64_t gpuBytes = scene->getGpuBytes(); // walks every part
                                row["gpuBytes"] = gpuBytes;
                                peakGpuBytes = std::max(peakGpuBytes, gpuBytes);
                                if (!baseline)
                                {
                                    row["visible"] = stats.visibleInstances;
                                    row["occluded"] = stats.occludedInstances;
                                    row["levels"] = levelHistogram(scene->getForest());
                                    row["cullMs"] = stats.cullMilliseconds;
                                    row["uploadedBytes"] = stats.uploadedBytes;
                                    row["pendingLevels"] = stats.pendingLevels;
                                    row["fallbackTrees"] = stats.fallbackInstances;
                                    if (scene->getForest().getFrameBudgetMs() > 0.0f)
                                    {
                                        // The frame budget's model at its last re-plan, and its choice.
                                        scene->getForest().notifyFrameTime(float(timing.frameMilliseconds));
                                        row["predictedMs"] = stats.predictedMilliseconds;
                                        row["errorBudget"] = scene->getForest().getErrorBudget();
                                        row["frameTimeRatio"] = scene->getForest().getFrameTimeRatio();
                                    }
                                }
                            }
                            if (isSampled(f))
                            {
                                const std::string stem = imageStem(trees, technique, bias, f);
                                if (technique == REFERENCE_TECHNIQUE)
                                {
                                    if (double(referenceCost) <= imageBudget)
                                    {
                                        // Every tree in view: the truth hides nothing by estimate.
                                        const bool occlusion = scene->getForest().getOcclusion();
                                        scene->getForest().setOcclusion(false);
                                        save(renderer.render(frameAt(time), width, height, 2), stem + "-ref");
                                        save(renderer.render(nextCamera(f), width, height, 2), stem + "-ref-next");
                                        scene->getForest().setOcclusion(occlusion);
                                        row["referenceImage"] = stem + "-ref";
                                    }
                                    else
                                        skipped += std::string(skipped.empty() ? "" : "; ") +
                                                   "reference image too costly: " + std::to_string(referenceCost) +
                                                   " triangles > image budget " +
                                                   std::to_string(std::uint64_t(imageBudget));
                                }
                                if (technique != REFERENCE_TECHNIQUE || double(referenceCost) <= imageBudget)
                                {
                                    save(renderer.render(frameAt(time), width, height, 1), stem);
                                    save(renderer.render(nextCamera(f), width, height, 1), stem + "-next");
                                    row["image"] = stem;
                                }
                            }
                            if (!skipped.empty())
                                row["skipped"] = skipped;
                            frameRows.push_back(std::move(row));
                        }
                        // Motion frames (see the file comment), after the timed ones so that they
                        // change no timed frame's levels or uploads.
                        if (!motion.empty() && nativeStep > 0.0)
                        {
                            scene->setGroundVisible(false);
                            const double pathEnd = frameTime(script, frames - 1, frames);
                            for (std::uint32_t f : motion)
                            {
                                json& row = frameRows[f];
                                const double t = frameTime(script, f, frames);
                                if (!row.contains("frameMs") || t + nativeStep > pathEnd + 1e-6)
                                    continue; // not drawn (over the reference budget), or no next frame
                                renderer.render(frameAt(t - nativeStep), width, height, 1);
                                const std::string stem = imageStem(trees, technique, bias, f) + "-motion";
                                save(renderer.render(frameAt(t), width, height, 1), stem);
                                if (!baseline)
                                {
                                    // The next frame with the levels held (the LoD camera of this
                                    // one): what it would show without the switches.
                                    scene->getForest().setLodFrozen(true);
                                    save(renderer.render(frameAt(t + nativeStep), width, height, 1), stem + "-held");
                                    scene->getForest().setLodFrozen(false);
                                    row["motionHeld"] = true;
                                }
                                save(renderer.render(frameAt(t + nativeStep), width, height, 1), stem + "-next");
                                row["motionImage"] = stem;
                                if (!baseline)
                                {
                                    const ForestStats& stats = scene->getForest().getStats();
                                    row["motionSwitches"] = stats.levelSwitches;
                                    row["motionVisible"] = stats.visibleInstances;
                                }
                            }
                            scene->setGroundVisible(true);
                        }
                        progress(label, 1.0f);
                        const auto [rss, peak] = residentMemory();
                        run["frames"] = std::move(frameRows);
                        run["levelNotes"] = scene->getLevelNotes();
                        run["gpuBytes"] = scene->getGpuBytes();
                        run["peakGpuBytes"] = std::max(peakGpuBytes, scene->getGpuBytes());
                        if (!baseline)
                        {
                            const Forest& forest = scene->getForest();
                            run["residentLevels"] = forest.getResidentLevelCount();
                            run["plannedGpuBytes"] = forest.getStats().plannedGpuBytes;
                            run["memoryBudgetBytes"] = forest.getMemoryBudget();
                            bool budgeted = false;
                            for (std::uint32_t s = 0; s < forest.getSpeciesCount(); ++s)
                                budgeted = budgeted || forest.isBudgeted(s);
                            if (budgeted)
                            {
                                run["binding"] = toString(forest.getBindingBudget());
                                run["errorBudget"] = forest.getErrorBudget();
                            }
                            run["occlusion"] = forest.getOcclusion();
                        }
                        run["instanceBytes"] = scene->getForest().getInstances().getMemoryBytes();
                        run["rssMiB"] = rss;
                        run["peakRssMiB"] = peak;
                        runsJson.push_back(std::move(run));
                        if (Result<void> w = writeTimings(false); !w)
                            return printError(w.error());
                    }
                    scene.reset();
                }
            }
            if (Result<void> w = writeTimings(true); !w)
                return printError(w.error());
            return EXIT_OK;
        }
    }
}

int main(int argc, char** argv)
{
    using namespace TreeLod;
    FramesArgs args;
    CLI::App app{"treelod_frames: render and time a scene script's camera path (the frames of `treelod bench`; "
                 "links OGRE and the TreeLod runtime only)"};
    app.add_option("scene", args.scene, "scene script (samples/scenes/*.json)")->required();
    app.add_option("--packages", args.packages, "package list written by `treelod bench` (packages.json)")->required();
    app.add_option("-o,--output", args.output, "output directory (timings.json, images/)")->required();
    app.add_option("--techniques", args.techniques,
                   "techniques besides the comparison runs (" + describeComparisonRuns() + ")")
        ->capture_default_str();
    app.add_option("--lod-bias", args.lodBiases, "comma-separated LoD biases")->capture_default_str();
    app.add_option("--frames", args.frames, "frames along the path (default: the script's)");
    app.add_option("--scale", args.scale, "tree count factor of random placements")->capture_default_str();
    app.add_option("--counts", args.counts, "comma-separated total tree counts (default: the script's)");
    app.add_option("--size", args.size, "WxH (default: the script's resolution)");
    app.add_option("--samples", args.samples, "frames saved as images for the error measures")->capture_default_str();
    app.add_option("--reference-budget", args.referenceBudget, "skip reference frames over this many triangles")
        ->capture_default_str();
    app.add_option("--reference-image-budget", args.referenceImageBudget,
                   "the same for the reference's supersampled images (default: --reference-budget)");
    app.add_option("--entity-limit", args.entityLimit, "skip the entities floor above this many trees")
        ->capture_default_str();
    app.add_option("--upload-budget", args.uploadBudget,
                   "bytes of Forest levels built per frame (0 = no limit); levels waiting draw a coarser one")
        ->capture_default_str();
    app.add_option("--shadow-size", args.shadowSize, "shadow map size over the script's (-1: the script's, 0: off)")
        ->capture_default_str();
    app.add_option("--shadow-lod-bias", args.shadowLodBias,
                   "LoD bias of the Forest's shadow casters over the script's (0: the script's; < 1: coarser)")
        ->capture_default_str();
    app.add_option("--wind", args.wind, "the wind's strength over the script's (-1: the script's, 0: calm)")
        ->capture_default_str();
    app.add_option("--motion-frames", args.motionFrames,
                   "frames measured in motion (the frame and the next at the script's frame rate, after a "
                   "run-in frame, and the next with the levels held; 1 sample per pixel, ground hidden): all, or "
                   "a count evenly along the path (0: none)")
        ->capture_default_str();
    app.add_flag("--preload", args.preload,
                 "build every Forest level before the frames (Forest::makeAllResident: nothing uploaded while timing)");
    app.add_flag("--skip-comparisons", args.skipComparisons,
                 "run only --techniques: no reference, no floors (e.g. to read one scene's resident memory)");
    app.add_option("--calibration", args.calibration,
                   "folder of the cost calibrations budgeted auto reads and writes (default: the user's cache)");
    app.add_flag("-q,--quiet", args.quiet, "no progress");
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        const int rc = app.exit(e);
        return rc == 0 ? 0 : EXIT_BAD_INPUT;
    }
    try
    {
        return runFrames(args);
    }
    catch (const Ogre::Exception& e)
    {
        std::fprintf(stderr, "treelod_frames: %s\n", e.getDescription().c_str());
        return EXIT_FAILURE_RUN;
    }
}
