// treelod bench SCENE.json -o DIR [--techniques a,b] [--lod-bias 1,0.5,0.25] [--frames N] [--scale S]
//
// Scripted scene benchmark (issue 5): the scene's camera path rendered headless for each
// technique and LoD bias, with the polygonal reference ("mesh") and the one-quad-per-tree floor
// ("quad") in the same run. Per frame: CPU time (until the frame's commands are submitted),
// frame time bounded by a one-pixel read-back (Ogre's GL3Plus render system offers no timer
// queries, so the GPU time is the glFinish-bounded wall time), batches, triangles, instances
// per level. On sampled frames: the polygonal reference supersampled 2x2, and against it FLIP
// and multi-scale RMSE (paper 001 §4), and temporal noise: the multi-scale RMSE between the
// frame and the next frame of the path (paper 001 §5, Fig. 13), for the reference too.
// A reference frame whose triangle count would exceed --reference-budget is skipped and said
// so, never estimated. Writes DIR/frames.csv, DIR/summary.json and PNG plots (frame time along
// the path, paper 001 Fig. 11; the speed/accuracy trade over the LoD biases).
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/ImageMetrics.h"
#include "TreeLod/Plot.h"
#include "TreeLod/SceneScript.h"

#include <nlohmann/json.hpp>

#include <algorithm>
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
#include "TreeLod/ForestScene.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/RgbaImageConversion.h"
#include "TreeLod/TreeAssetManager.h"
#endif

namespace TreeLod
{
    namespace
    {
        struct BenchArgs
        {
            std::string scene;
            std::string output;
            std::string techniques = "auto,lodf,billboard-cloud";
            std::string lodBiases = "1,0.5,0.25";
            std::uint32_t frames = 0; // 0 = the script's
            double scale = 1.0;
            std::string size;         // "" = the script's resolution
            std::uint32_t samples = 4; // sampled frames for the error measures
            double referenceBudget = 3e6;      // triangles: the reference's timed frames
            double referenceImageBudget = 0.0; // triangles: its supersampled images; 0 = referenceBudget
            std::string cacheDirectory;
            std::string counts;       // "" = the script's counts
            bool json = false;
            bool quiet = false;
        };

        std::vector<std::string> splitList(const std::string& text)
        {
            std::vector<std::string> out;
            std::stringstream in(text);
            std::string item;
            while (std::getline(in, item, ','))
                if (!item.empty())
                    out.push_back(item);
            return out;
        }

        struct Stats
        {
            double mean = NAN, median = NAN, p95 = NAN, max = NAN;
            std::size_t count = 0;
        };

        Stats statsOf(std::vector<double> values)
        {
            Stats s;
            values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
                         values.end());
            s.count = values.size();
            if (values.empty())
                return s;
            std::sort(values.begin(), values.end());
            s.mean = std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
            const std::size_t n = values.size();
            s.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
            s.p95 = values[std::min(n - 1, std::size_t(std::ceil(0.95 * double(n))) - 1)];
            s.max = values.back();
            return s;
        }

        nlohmann::json toJson(const Stats& s)
        {
            auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
            return {{"mean", num(s.mean)}, {"median", num(s.median)}, {"p95", num(s.p95)}, {"max", num(s.max)},
                    {"count", s.count}};
        }

#ifdef TREELOD_WITH_OGRE
        /// One frame of one run.
        struct FrameRecord
        {
            std::uint32_t frame = 0;
            double time = 0.0;
            bool timed = false;
            std::string skipped; ///< why the frame was not timed or not compared
            FrameTiming timing;
            std::uint32_t visible = 0;
            std::vector<std::uint32_t> levels; ///< visible instances per level index, all species summed
            double flip = NAN, msRmse = NAN, temporalNoise = NAN;
        };

        /// One (technique, bias) run over the path.
        struct Run
        {
            std::uint32_t count = 0; ///< trees in the scene
            std::string technique;
            float lodBias = 1.0f;
            std::vector<FrameRecord> frames;
            std::uint64_t assetBytes = 0;
            double bakeSeconds = 0.0;
        };

        /// The reference on a sampled frame: supersampled image and its temporal noise.
        struct ReferenceSample
        {
            Image image;
            double temporalNoise = NAN;
        };

        std::string levelsText(const std::vector<std::uint32_t>& levels)
        {
            std::string out;
            for (std::size_t i = 0; i < levels.size(); ++i)
                out += (i ? ";" : "") + std::to_string(levels[i]);
            return out;
        }

        std::string number(double v, int digits = 4)
        {
            if (!std::isfinite(v))
                return "";
            char text[64];
            std::snprintf(text, sizeof text, "%.*g", digits + 2, v);
            return text;
        }

        /// Triangles the polygonal reference would submit from `camera`: visible trees times
        /// their reference triangle counts (an exact count of what would be drawn, not a guess
        /// at time: the budget is in triangles).
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

        double imageBudget(const BenchArgs& args)
        {
            return args.referenceImageBudget > 0.0 ? args.referenceImageBudget : args.referenceBudget;
        }

        std::string treesText(std::uint32_t count) { return std::to_string(count) + (count == 1 ? " tree" : " trees"); }

        Result<void> writeText(const std::string& path, const std::string& text)
        {
            return writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
        }

        /// Median frame ms of `run` over the frames where `other` was timed too (all when null).
        double medianOver(const Run& run, const Run* other)
        {
            std::vector<double> ms;
            for (std::size_t f = 0; f < run.frames.size(); ++f)
                if (run.frames[f].timed && (!other || (f < other->frames.size() && other->frames[f].timed)))
                    ms.push_back(run.frames[f].timing.frameMilliseconds);
            return statsOf(ms).median;
        }

        /// Frames that every run of `count` trees timed; the reference's runs count only when that
        /// leaves some (it is skipped where too costly), so the trade plot compares like with like.
        std::vector<bool> commonTimedFrames(const std::vector<Run>& runs, std::uint32_t count)
        {
            for (bool withReference : {true, false})
            {
                std::vector<bool> common;
                for (const Run& run : runs)
                {
                    if (run.count != count || (!withReference && run.technique == "mesh"))
                        continue;
                    if (common.empty())
                        common.assign(run.frames.size(), true);
                    for (std::size_t f = 0; f < run.frames.size() && f < common.size(); ++f)
                        common[f] = common[f] && run.frames[f].timed;
                }
                if (std::find(common.begin(), common.end(), true) != common.end())
                    return common;
            }
            return {};
        }

        bool writeOutputs(const BenchArgs& args, const SceneScript& script, std::uint32_t frames, int width, int height,
                          const std::vector<Run>& runs,
                          const std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>>& references,
                          const CacheTreeBaker& baker)
        {
            // frames.csv: one row per run and frame.
            std::string csv = "trees,technique,lod_bias,frame,time_s,timed,cpu_ms,frame_ms,batches,triangles,visible,"
                              "instances_per_level,flip,ms_rmse,temporal_noise,skipped\n";
            for (const Run& run : runs)
                for (const FrameRecord& r : run.frames)
                    csv += std::to_string(run.count) + "," + run.technique + "," + number(run.lodBias, 3) + "," +
                           std::to_string(r.frame) + "," + number(r.time, 5) + "," + (r.timed ? "1" : "0") + "," +
                           (r.timed ? number(r.timing.cpuMilliseconds) : "") + "," +
                           (r.timed ? number(r.timing.frameMilliseconds) : "") + "," +
                           (r.timed ? std::to_string(r.timing.batches) : "") + "," +
                           (r.timed ? std::to_string(r.timing.triangles) : "") + "," +
                           (r.timed ? std::to_string(r.visible) : "") + "," + levelsText(r.levels) + "," +
                           number(r.flip) + "," + number(r.msRmse) + "," + number(r.temporalNoise) + ",\"" +
                           r.skipped + "\"\n";
            if (Result<void> w = writeText(args.output + "/frames.csv", csv); !w)
                return printError(w.error()), false;

            // summary.json
            using nlohmann::json;
            json summary = {{"scene", script.name},
                            {"file", script.file},
                            {"resolution", {width, height}},
                            {"frames", frames},
                            {"scale", args.scale},
                            {"referenceBudgetTriangles", args.referenceBudget},
                            {"referenceImageBudgetTriangles", imageBudget(args)},
                            {"timing", "frame_ms: wall time until a one-pixel read-back (GPU-bounded; Ogre's GL3Plus "
                                       "offers no timer queries); cpu_ms: until the commands are submitted"}};
            json bakes = json::array();
            for (const BakeCacheEntry& e : baker.getEntries())
                bakes.push_back(e.describe());
            summary["bake"] = bakes;
            json results = json::array();
            for (const Run& run : runs)
            {
                const Run* reference = nullptr;
                const Run* floor = nullptr;
                for (const Run& other : runs)
                    if (other.count == run.count && other.technique == "mesh")
                        reference = &other;
                    else if (other.count == run.count && other.technique == "quad")
                        floor = &other;
                std::vector<double> frameMs, cpuMs, flips, rmse, noise, refNoise;
                std::vector<std::string> skipped;
                for (const FrameRecord& r : run.frames)
                {
                    if (r.timed)
                    {
                        frameMs.push_back(r.timing.frameMilliseconds);
                        cpuMs.push_back(r.timing.cpuMilliseconds);
                    }
                    flips.push_back(r.flip);
                    rmse.push_back(r.msRmse);
                    noise.push_back(r.temporalNoise);
                    if (!r.skipped.empty())
                        skipped.push_back("frame " + std::to_string(r.frame) + ": " + r.skipped);
                }
                if (auto it = references.find(run.count); it != references.end())
                    for (const auto& [frame, sample] : it->second)
                        refNoise.push_back(sample.temporalNoise);
                const Stats flipStats = statsOf(flips);
                const double techniqueOnShared = reference ? medianOver(run, reference) : NAN;
                const double referenceOnShared = reference ? medianOver(*reference, &run) : NAN;
                const double ownMedian = statsOf(frameMs).median;
                const double floorMedian = floor ? statsOf([&] {
                    std::vector<double> v;
                    for (const FrameRecord& r : floor->frames)
                        if (r.timed)
                            v.push_back(r.timing.frameMilliseconds);
                    return v;
                }()).median
                                                 : NAN;
                auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
                results.push_back({{"trees", run.count},
                                   {"technique", run.technique},
                                   {"lodBias", run.lodBias},
                                   {"frameMs", toJson(statsOf(frameMs))},
                                   {"cpuMs", toJson(statsOf(cpuMs))},
                                   {"speedupVsReference", num(referenceOnShared / techniqueOnShared)},
                                   {"ratioToFloor", num(ownMedian / floorMedian)},
                                   {"flip", {{"mean", num(flipStats.mean)}, {"max", num(flipStats.max)},
                                             {"samples", flipStats.count}}},
                                   {"msRmse", num(statsOf(rmse).mean)},
                                   {"temporalNoise", num(statsOf(noise).mean)},
                                   {"referenceTemporalNoise", num(statsOf(refNoise).mean)},
                                   {"assetBytes", run.assetBytes},
                                   {"bakeSeconds", run.bakeSeconds},
                                   {"skipped", skipped}});
            }
            summary["results"] = results;
            if (Result<void> w = writeText(args.output + "/summary.json", summary.dump(2) + "\n"); !w)
                return printError(w.error()), false;
            if (args.json)
                std::printf("%s\n", summary.dump(2).c_str());

            // Plots, one set per tree count.
            std::vector<std::uint32_t> counts;
            for (const Run& run : runs)
                if (std::find(counts.begin(), counts.end(), run.count) == counts.end())
                    counts.push_back(run.count);
            for (std::uint32_t count : counts)
            {
                const std::string suffix = counts.size() > 1 ? "-" + std::to_string(count) : "";
                PlotSpec time;
                time.title = script.name + ": frame time along the path (" + treesText(count) + ", " +
                             std::to_string(width) + "x" + std::to_string(height) + ")";
                time.xLabel = "path time (s)";
                time.yLabel = "frame ms";
                time.logY = true;
                PlotSpec trade;
                trade.title = script.name + ": error against frame time (" + treesText(count) + ")";
                trade.xLabel = "median frame ms (over the frames every run timed)";
                const std::vector<bool> common = commonTimedFrames(runs, count);
                trade.yLabel = "mean FLIP vs supersampled reference";
                trade.logX = true;
                std::map<std::string, PlotSeries> curves;
                for (const Run& run : runs)
                {
                    if (run.count != count)
                        continue;
                    const double median = statsOf([&] {
                        std::vector<double> v;
                        for (std::size_t f = 0; f < run.frames.size(); ++f)
                            if (run.frames[f].timed && f < common.size() && common[f])
                                v.push_back(run.frames[f].timing.frameMilliseconds);
                        return v;
                    }()).median;
                    std::vector<double> flips;
                    for (const FrameRecord& r : run.frames)
                        flips.push_back(r.flip);
                    const double meanFlip = statsOf(flips).mean;
                    if (run.technique == "mesh" || run.technique == "quad")
                        trade.markers.push_back(PlotMarker{run.technique == "mesh" ? "polygonal reference (mesh, 1 spp)"
                                                                                   : "floor: one quad per tree",
                                                           glm::dvec2(median, meanFlip), glm::vec3(0.0f),
                                                           run.technique == "mesh" ? 'o' : 's'});
                    else
                    {
                        PlotSeries& curve = curves[run.technique];
                        curve.label = run.technique + " (LoD bias " + args.lodBiases + ")";
                        curve.points.push_back(glm::dvec2(median, meanFlip));
                    }
                    if (run.lodBias == 1.0f || run.technique == "mesh" || run.technique == "quad")
                    {
                        PlotSeries series;
                        series.label = run.technique == "mesh"   ? "polygonal reference (mesh)"
                                       : run.technique == "quad" ? "floor (one quad per tree)"
                                                                 : run.technique;
                        series.markers = false;
                        if (std::none_of(run.frames.begin(), run.frames.end(),
                                         [](const FrameRecord& r) { return r.timed; }))
                            series.label += ": every frame over the triangle budget, skipped";
                        for (const FrameRecord& r : run.frames)
                            series.points.push_back(
                                glm::dvec2(r.time, r.timed ? r.timing.frameMilliseconds : std::nan("")));
                        time.series.push_back(std::move(series));
                    }
                }
                for (auto& [name, curve] : curves)
                    trade.series.push_back(std::move(curve));
                for (const auto& [spec, name] : {std::pair<const PlotSpec*, std::string>{&time, "frame-time"},
                                                 {&trade, "trade"}})
                    if (Result<void> w = writePlot(args.output + "/" + name + suffix + ".png", *spec); !w)
                        return printError(w.error()), false;
            }
            if (counts.size() > 1) // paper 000 Table 2: frame time against the number of trees
            {
                PlotSpec table;
                table.title = script.name + ": median frame ms against trees (LoD bias 1)";
                table.xLabel = "trees";
                table.yLabel = "median frame ms";
                table.logX = table.logY = true;
                std::map<std::string, PlotSeries> curves;
                for (const Run& run : runs)
                    if (run.lodBias == 1.0f)
                    {
                        PlotSeries& curve = curves[run.technique];
                        curve.label = run.technique;
                        curve.points.push_back(glm::dvec2(run.count, medianOver(run, nullptr)));
                    }
                for (auto& [name, curve] : curves)
                    table.series.push_back(std::move(curve));
                if (Result<void> w = writePlot(args.output + "/trees.png", table); !w)
                    return printError(w.error()), false;
            }
            return true;
        }

        int runBench(const BenchArgs& args)
        {
            Result<SceneScript> loaded = loadSceneScript(args.scene);
            if (!loaded)
                return printError(loaded.error());
            SceneScript script = *loaded;
            if (!(args.scale > 0.0) || !std::isfinite(args.scale))
                return printError(fail("", "--scale", "must be a positive number"));
            int width = script.width, height = script.height;
            if (!args.size.empty() && (std::sscanf(args.size.c_str(), "%dx%d", &width, &height) != 2 || width <= 0 ||
                                       height <= 0 || width > 16384 || height > 16384))
                return printError(fail("", "--size", "'" + args.size + "' is not WxH with 1..16384"));
            const std::uint32_t frames = args.frames ? args.frames : script.frames;
            std::vector<float> biases;
            for (const std::string& b : splitList(args.lodBiases))
            {
                char* end = nullptr;
                const double v = std::strtod(b.c_str(), &end);
                if (*end != '\0' || !(v > 0.0) || !std::isfinite(v))
                    return printError(fail("", "--lod-bias", "'" + b + "' is not a positive number"));
                biases.push_back(float(v));
            }
            if (biases.empty())
                return printError(fail("", "--lod-bias", "needs at least one value"));
            std::vector<std::string> techniques = splitList(args.techniques);
            for (const std::string& t : techniques)
                if (t != "auto" && bakeTechniqueOf(t).empty())
                    return printError(fail("", "--techniques",
                                           "unknown technique '" + t +
                                               "' (known: auto, mesh, lodf, billboard-cloud, classic-billboard-cloud, quad)"));
            techniques.erase(std::remove_if(techniques.begin(), techniques.end(),
                                            [](const std::string& t) { return t == "mesh" || t == "quad"; }),
                             techniques.end());
            std::vector<std::uint32_t> counts = script.counts;
            if (!args.counts.empty())
            {
                counts.clear();
                for (const std::string& c : splitList(args.counts))
                    counts.push_back(std::uint32_t(std::strtoul(c.c_str(), nullptr, 10)));
            }
            if (counts.empty())
                counts.push_back(0); // as the script places them
            if (args.samples == 0 || frames == 0)
                return printError(fail("", "--frames/--samples", "must be >= 1"));

            std::error_code ec;
            std::filesystem::create_directories(args.output, ec);
            if (ec)
                return printError(fail(args.output, "", "cannot create the output directory: " + ec.message()));

            ProgressCallback progress = makeProgress(args.quiet);
            OffscreenRenderer renderer;
            renderer.setLighting(sceneLighting(script));
            CacheTreeBaker baker(args.cacheDirectory.empty() ? defaultBakeCacheDirectory() : args.cacheDirectory,
                                 progress);
            TreeAssetManager::getSingleton().setBaker(&baker);
            struct BakerReset
            {
                ~BakerReset() { TreeAssetManager::getSingleton().setBaker(nullptr); }
            } bakerReset;

            // Sampled frames: evenly along the path (never the last: its successor is the temporal pair).
            std::vector<std::uint32_t> sampled;
            const std::uint32_t samples = std::min(args.samples, std::max<std::uint32_t>(1, frames - 1));
            for (std::uint32_t i = 0; i < samples; ++i)
                sampled.push_back(frames <= 1 ? 0 : std::uint32_t((std::uint64_t(i) * 2 + 1) * (frames - 1) / (2 * samples)));
            auto isSampled = [&](std::uint32_t f) { return std::find(sampled.begin(), sampled.end(), f) != sampled.end(); };
            // The temporal pair: the next frame at the script's own frame rate (not --frames'), so
            // temporal noise does not depend on how much the bench thins the path out.
            const double nativeStep =
                script.frames > 1 ? frameTime(script, 1, script.frames) - frameTime(script, 0, script.frames) : 0.0;
            auto nextCamera = [&](std::uint32_t f) { return cameraAt(script, frameTime(script, f, frames) + nativeStep); };

            std::vector<Run> runs;
            std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>> references; // trees -> frame ->

            for (std::uint32_t count : counts)
            {
                ForestSceneOptions options;
                options.placement.totalCount = count;
                options.placement.scale = args.scale;
                std::vector<std::pair<std::string, std::vector<float>>> plan = {{"mesh", {1.0f}}, {"quad", {1.0f}}};
                for (const std::string& t : techniques)
                    plan.push_back({t, biases});
                for (const auto& [technique, runBiases] : plan)
                {
                    const std::size_t entriesBefore = baker.getEntries().size();
                    options.technique = technique == "auto" ? "" : technique;
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
                    if (script.shadows.enabled)
                        renderer.setShadowFarDistance(ForestScene::getShadowFarDistance());
                    const std::uint32_t trees = std::uint32_t(scene->getPlacements().size());
                    double bakeSeconds = 0.0;
                    for (std::size_t e = entriesBefore; e < baker.getEntries().size(); ++e)
                    {
                        bakeSeconds += baker.getEntries()[e].bakeSeconds;
                        if (!args.quiet)
                            std::fprintf(stderr, "%s\n", baker.getEntries()[e].describe().c_str());
                    }
                    for (float bias : runBiases)
                    {
                        // Untimed warm-up along the path: GL3Plus links each program on first use,
                        // which would otherwise land in the first frame that shows a level.
                        renderer.setLodBias(bias);
                        for (std::uint32_t w = 0; w < std::min<std::uint32_t>(frames, 4); ++w)
                            renderer.renderTimedFrame(scene->cameraAtFrame(w * (frames - 1) / 3, frames), width, height);
                        Run run;
                        run.count = trees;
                        run.technique = technique;
                        run.lodBias = bias;
                        run.bakeSeconds = bakeSeconds;
                        renderer.setLodBias(bias);
                        const std::string label = technique + " bias " + number(bias, 2) + " (" + treesText(trees) + ")";
                        for (std::uint32_t f = 0; f < frames; ++f)
                        {
                            progress(label, float(f) / float(frames));
                            FrameRecord record;
                            record.frame = f;
                            record.time = frameTime(script, f, frames);
                            const CameraSpec camera = scene->cameraAtFrame(f, frames);
                            std::uint64_t referenceCost = 0;
                            if (technique == "mesh")
                                referenceCost = referenceTriangles(*scene, camera, width, height);
                            if (technique == "mesh" && double(referenceCost) > args.referenceBudget)
                                record.skipped = "reference too costly: " + std::to_string(referenceCost) +
                                                 " triangles > budget " + number(args.referenceBudget, 3);
                            else
                            {
                                record.timing = renderer.renderTimedFrame(camera, width, height);
                                record.timed = true;
                                record.visible = scene->getForest().getStats().visibleInstances;
                                record.levels = levelHistogram(scene->getForest());
                            }
                            if (isSampled(f))
                            {
                                std::map<std::uint32_t, ReferenceSample>& refs = references[trees];
                                if (technique == "mesh")
                                {
                                    if (double(referenceCost) <= imageBudget(args))
                                    {
                                        ReferenceSample sample;
                                        sample.image = toImage(renderer.render(camera, width, height, 2));
                                        const Image next = toImage(renderer.render(nextCamera(f), width, height, 2));
                                        if (Result<MultiScaleRmseResult> r = multiScaleRmse(sample.image, next))
                                            sample.temporalNoise = r->combined;
                                        refs[f] = std::move(sample);
                                    }
                                }
                                if (refs.count(f))
                                {
                                    const Image image = toImage(renderer.render(camera, width, height, 1));
                                    const Image next = toImage(renderer.render(nextCamera(f), width, height, 1));
                                    if (Result<FlipResult> r = flip(refs[f].image, image))
                                        record.flip = r->mean;
                                    if (Result<MultiScaleRmseResult> r = multiScaleRmse(refs[f].image, image))
                                        record.msRmse = r->combined;
                                    if (Result<MultiScaleRmseResult> r = multiScaleRmse(image, next))
                                        record.temporalNoise = r->combined;
                                }
                                else if (technique == "mesh")
                                    record.skipped += std::string(record.skipped.empty() ? "" : "; ") +
                                                      "reference image too costly: " + std::to_string(referenceCost) +
                                                      " triangles > image budget " + number(imageBudget(args), 3);
                                else
                                    record.skipped = "no reference image for this frame (too costly)";
                                if (f == sampled.front()) // a picture of every run
                                    OffscreenRenderer::savePng(renderer.render(camera, width, height, 1),
                                                               args.output + "/frame-" + std::to_string(trees) + "-" +
                                                                   technique + "-" + number(bias, 2) + ".png");
                            }
                            run.frames.push_back(std::move(record));
                        }
                        progress(label, 1.0f);
                        run.assetBytes = scene->getGpuBytes();
                        runs.push_back(std::move(run));
                    }
                    scene.reset();
                }
            }
            return writeOutputs(args, script, frames, width, height, runs, references, baker) ? EXIT_OK : EXIT_FAILURE_RUN;
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
        cmd->add_option("--techniques", args->techniques,
                        "comma-separated techniques besides the reference (mesh) and the floor (quad): auto (the "
                        "script's choice), lodf, billboard-cloud, classic-billboard-cloud")
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
        cmd->add_option("--cache", args->cacheDirectory, "bake cache directory (default: $XDG_CACHE_HOME/treelod)");
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
