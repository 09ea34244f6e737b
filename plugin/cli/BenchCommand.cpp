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

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

namespace TreeLod
{
    namespace
    {
        struct BenchArgs
        {
            std::string scene;
            std::string output;
            std::string techniques; // set where the option is added: defaultBenchTechniques()
            std::string lodBiases = "1,0.5,0.25";
            std::uint32_t frames = 0; // 0 = the script's
            double scale = 1.0;
            std::string size;         // "" = the script's resolution
            std::uint32_t samples = 4; // sampled frames for the error measures
            double referenceBudget = 3e6;      // triangles: the reference's timed frames
            double referenceImageBudget = 0.0; // triangles: its supersampled images; 0 = referenceBudget
            std::string cacheDirectory;
            std::string counts;       // "" = the script's counts
            std::uint64_t uploadBudget = 8000000; // bytes of Forest levels built per frame (0 = no limit)
            int shadowSize = -1;                  // -1: the script's; 0: off (applyShadowOptions)
            double shadowLodBias = 0.0;           // 0: the script's
            bool bakeOnly = false;    // bake, write packages.json, print the treelod_frames command
            std::string framesFrom;   // "" = run treelod_frames here; else read its output from this directory
            bool json = false;
            bool quiet = false;
        };

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

        /// A number for summary.json: null when not finite (not measured).
        nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

        nlohmann::json toJson(const Stats& s)
        {
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
            std::uint64_t uploadedBytes = 0;   ///< levels made resident in this frame (Forest upload budget)
            double flip = NAN, msRmse = NAN, temporalNoise = NAN;
        };

        /// One (technique, bias) run over the path.
        struct Run
        {
            std::uint32_t count = 0; ///< trees in the scene
            std::string technique;
            float lodBias = 1.0f;
            std::vector<FrameRecord> frames;
            std::uint64_t assetBytes = 0;    ///< GPU bytes of what the run drew
            std::uint64_t instanceBytes = 0; ///< the Forest's instance store on the CPU
            double rssMiB = NAN, peakRssMiB = NAN; ///< treelod_frames' resident memory after the run
            double bakeSeconds = 0.0;
            std::string skipped;   ///< the whole run (e.g. too many entities)
            bool hasPicture = false;
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

        double imageBudget(const BenchArgs& args)
        {
            return args.referenceImageBudget > 0.0 ? args.referenceImageBudget : args.referenceBudget;
        }

        std::string treesText(std::uint32_t count) { return std::to_string(count) + (count == 1 ? " tree" : " trees"); }

        Result<void> writeText(const std::string& path, const std::string& text)
        {
            return writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
        }

        /// A CSV field: quoted, quotes doubled.
        std::string csvField(const std::string& text)
        {
            std::string out = "\"";
            for (char c : text)
                out += c == '"' ? std::string("\"\"") : std::string(1, c);
            return out + "\"";
        }

        int runProcess(const std::vector<std::string>& argv, bool searchPath = false, bool silent = false);

        /// bench/plot.py: $TREELOD_PLOT_SCRIPT, else share/TreeLod/plot.py beside this executable
        /// (installed, or the build tree's link to bench/plot.py).
        std::string plotScript()
        {
            if (const char* env = std::getenv("TREELOD_PLOT_SCRIPT"); env && *env)
                return env;
            return dataDirectory() + "/plot.py";
        }

        /// Draw DIR/plots.json's plots with bench/plot.py when python3 has matplotlib; otherwise one
        /// line saying how. False when the script ran and failed.
        bool drawPlots(const std::string& directory)
        {
            const std::string script = plotScript();
            std::error_code ec;
            if (!std::filesystem::is_regular_file(script, ec) ||
                runProcess({"python3", "-c", "import matplotlib"}, true, true) != 0)
            {
                std::fprintf(stderr,
                             "treelod: bench: plots not drawn (python3 with matplotlib needed: apt install "
                             "python3-matplotlib); draw them with: python3 %s %s\n",
                             script.c_str(), directory.c_str());
                return true;
            }
            if (const int code = runProcess({"python3", script, directory}, true); code != 0)
            {
                std::fprintf(stderr, "treelod: bench: python3 %s %s failed (exit %d)\n", script.c_str(),
                             directory.c_str(), code);
                return false;
            }
            return true;
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
                    if (run.count != count || run.frames.empty() || (!withReference && run.technique == REFERENCE_TECHNIQUE))
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

        /// A run's point in the trade plot: median frame ms over the frames every run of its tree
        /// count timed (commonTimedFrames), mean FLIP on its sampled frames; NaN where not measured.
        struct TradePoint
        {
            double medianFrameMs = NAN, meanFlip = NAN;
            bool measured() const { return std::isfinite(medianFrameMs) && std::isfinite(meanFlip); }
        };

        /// The trade point of each run, in the order of `runs`.
        std::vector<TradePoint> tradePoints(const std::vector<Run>& runs)
        {
            std::map<std::uint32_t, std::vector<bool>> common; // trees -> frames every run timed
            std::vector<TradePoint> points;
            for (const Run& run : runs)
            {
                auto it = common.find(run.count);
                if (it == common.end())
                    it = common.emplace(run.count, commonTimedFrames(runs, run.count)).first;
                std::vector<double> ms, flips;
                for (std::size_t f = 0; f < run.frames.size(); ++f)
                {
                    if (run.frames[f].timed && f < it->second.size() && it->second[f])
                        ms.push_back(run.frames[f].timing.frameMilliseconds);
                    flips.push_back(run.frames[f].flip);
                }
                points.push_back({statsOf(ms).median, statsOf(flips).mean});
            }
            return points;
        }

        /// The runs (indices) of the same tree count whose trade point dominates that of `runs[i]`:
        /// at least as fast and as accurate, strictly better in one. None: on the Pareto front, if measured.
        std::vector<std::size_t> dominatorsOf(std::size_t i, const std::vector<Run>& runs,
                                              const std::vector<TradePoint>& points)
        {
            std::vector<std::size_t> out;
            const TradePoint& p = points[i];
            for (std::size_t j = 0; j < runs.size(); ++j)
            {
                const TradePoint& q = points[j];
                if (runs[j].count == runs[i].count && p.measured() && q.measured() &&
                    q.medianFrameMs <= p.medianFrameMs && q.meanFlip <= p.meanFlip &&
                    (q.medianFrameMs < p.medianFrameMs || q.meanFlip < p.meanFlip))
                    out.push_back(j);
            }
            return out;
        }

        /// "auto", auto with an error budget ("auto@0.02") or a frame budget ("auto~40").
        bool isAutoRun(const std::string& technique) { return technique.rfind("auto", 0) == 0; }

        /// A run as the Pareto line names it: "lodf", or "lodf@0.5" at a bias other than 1.
        std::string runName(const Run& run)
        {
            return run.technique + (run.lodBias == 1.0f ? "" : "@" + number(run.lodBias, 3));
        }

        bool writeOutputs(const BenchArgs& args, const SceneScript& script, std::uint32_t frames, int width, int height,
                          const std::vector<Run>& runs,
                          const std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>>& references,
                          const CacheTreeBaker& baker)
        {
            // frames.csv: one row per run and frame.
            std::string csv = "trees,technique,lod_bias,frame,time_s,timed,cpu_ms,frame_ms,batches,triangles,visible,"
                              "instances_per_level,flip,ms_rmse,temporal_noise,skipped,uploaded_bytes\n";
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
                           r.skipped + "\"," + (r.timed ? std::to_string(r.uploadedBytes) : "") + "\n";
            if (Result<void> w = writeText(args.output + "/frames.csv", csv); !w)
                return printError(w.error()), false;

            // summary.json
            using nlohmann::json;
            json summary = {{"scene", script.name},
                            {"file", script.file},
                            {"resolution", {width, height}},
                            {"frames", frames},
                            {"scale", args.scale},
                            {"shadowMap", script.shadows.enabled ? script.shadows.textureSize : 0},
                            {"shadowLodBias", script.shadows.lodBias},
                            {"referenceBudgetTriangles", args.referenceBudget},
                            {"referenceImageBudgetTriangles", imageBudget(args)},
                            {"timing", "frame_ms: wall time until a one-pixel read-back (GPU-bounded; Ogre's GL3Plus "
                                       "offers no timer queries); cpu_ms: until the commands are submitted"}};
            json bakes = json::array();
            for (const BakeCacheEntry& e : baker.getEntries())
                bakes.push_back(e.describe());
            summary["bake"] = bakes;
            // Peak resident memory: of the frame timer (its largest over the runs) and of this
            // process (bakes, reference images, metrics).
            double framesPeakMiB = NAN;
            for (const Run& run : runs)
                framesPeakMiB = std::fmax(framesPeakMiB, run.peakRssMiB); // NaN: not measured
            const double benchPeakMiB = residentMemory().peakMiB;
            summary["peakRssMiB"] = {{"frameTimer", num(framesPeakMiB)}, {"bench", num(benchPeakMiB)}};
            // The Pareto front of each tree count over the trade plot's points: the runs no other
            // run dominates; for auto runs off it, the runs that dominate them.
            const std::vector<TradePoint> points = tradePoints(runs);
            std::vector<std::vector<std::size_t>> dominators;
            for (std::size_t i = 0; i < runs.size(); ++i)
                dominators.push_back(dominatorsOf(i, runs, points));
            auto onFront = [&](std::size_t i) { return points[i].measured() && dominators[i].empty(); };
            auto pointJson = [&](std::size_t i) {
                return json{{"technique", runs[i].technique},
                            {"lodBias", runs[i].lodBias},
                            {"medianFrameMs", num(points[i].medianFrameMs)},
                            {"meanFlip", num(points[i].meanFlip)}};
            };
            std::vector<std::uint32_t> counts;
            for (const Run& run : runs)
                if (std::find(counts.begin(), counts.end(), run.count) == counts.end())
                    counts.push_back(run.count);
            json pareto = json::array();
            for (std::uint32_t count : counts)
            {
                std::vector<std::size_t> front, autoOff; // autoOff: measured auto runs off the front
                bool anyAuto = false;
                for (std::size_t i = 0; i < runs.size(); ++i)
                {
                    if (runs[i].count != count || !points[i].measured())
                        continue;
                    if (onFront(i))
                        front.push_back(i);
                    if (isAutoRun(runs[i].technique))
                    {
                        anyAuto = true;
                        if (!onFront(i))
                            autoOff.push_back(i);
                    }
                }
                const bool autoFront = std::any_of(front.begin(), front.end(),
                                                   [&](std::size_t i) { return isAutoRun(runs[i].technique); });
                std::stable_sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
                    return points[a].medianFrameMs < points[b].medianFrameMs;
                });
                json frontJson = json::array(), dominatedBy = json::array();
                std::string line;
                for (std::size_t i : front)
                {
                    frontJson.push_back(pointJson(i));
                    char text[96];
                    std::snprintf(text, sizeof text, " %.3g ms %.3g", points[i].medianFrameMs, points[i].meanFlip);
                    line += (line.empty() ? "" : ", ") + runName(runs[i]) + text;
                }
                if (front.empty())
                    line = "no run has both a frame time and a FLIP";
                if (autoFront)
                    line += "; auto on the front";
                for (std::size_t i : autoOff)
                {
                    json entry = pointJson(i);
                    entry["by"] = json::array();
                    std::string by;
                    for (std::size_t j : dominators[i])
                    {
                        entry["by"].push_back(pointJson(j));
                        by += (by.empty() ? "" : ", ") + runName(runs[j]);
                    }
                    dominatedBy.push_back(entry);
                    if (!autoFront)
                        line += "; " + runName(runs[i]) + " is dominated by " + by;
                }
                pareto.push_back({{"trees", count},
                                  {"front", frontJson},
                                  {"autoOnFront", anyAuto ? json(autoFront) : json(nullptr)},
                                  {"dominatedBy", dominatedBy}});
                if (!args.quiet)
                    std::printf("Pareto front (%s): %s\n", treesText(count).c_str(), line.c_str());
            }
            summary["pareto"] = pareto;
            if (!args.quiet)
                std::printf("peak resident memory: frame timer %.0f MiB, bench %.0f MiB\n", framesPeakMiB,
                            benchPeakMiB);
            json results = json::array();
            for (std::size_t i = 0; i < runs.size(); ++i)
            {
                const Run& run = runs[i];
                const Run* reference = nullptr;
                for (const Run& other : runs)
                    if (other.count == run.count && other.technique == REFERENCE_TECHNIQUE)
                        reference = &other;
                std::vector<double> frameMs, cpuMs, flips, rmse, noise, refNoise;
                std::vector<std::string> skipped;
                if (!run.skipped.empty())
                    skipped.push_back(run.skipped);
                json worst = nullptr;
                std::uint64_t maxUploaded = 0;
                for (const FrameRecord& r : run.frames)
                {
                    if (r.timed)
                    {
                        frameMs.push_back(r.timing.frameMilliseconds);
                        cpuMs.push_back(r.timing.cpuMilliseconds);
                        if (worst.is_null() || r.timing.frameMilliseconds > worst["frameMs"].get<double>())
                            worst = {{"frame", r.frame}, {"time", r.time}, {"frameMs", r.timing.frameMilliseconds},
                                     {"uploadedBytes", r.uploadedBytes}};
                        maxUploaded = std::max(maxUploaded, r.uploadedBytes);
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
                const Stats frameStats = statsOf(frameMs);
                const double techniqueOnShared = reference ? medianOver(run, reference) : NAN;
                const double referenceOnShared = reference ? medianOver(*reference, &run) : NAN;
                // Ratios of medians measured in this run (the floors' own medians over their timed frames).
                const std::string floor = TechniqueRegistry::getSingleton().getFloor().name;
                json ratios = json::object();
                for (const ComparisonRun& c : comparisonRuns())
                    if (c.technique != REFERENCE_TECHNIQUE)
                        for (const Run& other : runs)
                            if (other.count == run.count && other.technique == c.technique)
                                ratios[c.technique] = num(frameStats.median / medianOver(other, nullptr));
                results.push_back({{"trees", run.count},
                                   {"technique", run.technique},
                                   {"lodBias", run.lodBias},
                                   {"frameMs", toJson(frameStats)},
                                   {"p95OverMedian", num(frameStats.p95 / frameStats.median)},
                                   {"worstFrame", worst},
                                   {"cpuMs", toJson(statsOf(cpuMs))},
                                   {"speedupVsReference", num(referenceOnShared / techniqueOnShared)},
                                   {"ratioToFloor", ratios.contains(floor) ? ratios[floor] : json(nullptr)},
                                   {"ratioToFloors", ratios},
                                   {"maxUploadedBytesPerFrame", maxUploaded},
                                   {"instanceBytes", run.instanceBytes},
                                   {"instanceBytesPerTree", num(run.count ? double(run.instanceBytes) / run.count : NAN)},
                                   {"rssMiB", num(run.rssMiB)},
                                   {"peakRssMiB", num(run.peakRssMiB)},
                                   {"flip", {{"mean", num(flipStats.mean)}, {"max", num(flipStats.max)},
                                             {"samples", flipStats.count}}},
                                   {"msRmse", num(statsOf(rmse).mean)},
                                   {"temporalNoise", num(statsOf(noise).mean)},
                                   {"referenceTemporalNoise", num(statsOf(refNoise).mean)},
                                   {"assetBytes", run.assetBytes},
                                   {"bakeSeconds", run.bakeSeconds},
                                   {"trade", {{"medianFrameMs", num(points[i].medianFrameMs)},
                                              {"meanFlip", num(points[i].meanFlip)}}},
                                   {"onParetoFront", points[i].measured() ? json(onFront(i)) : json(nullptr)},
                                   {"skipped", skipped}});
            }
            summary["results"] = results;
            if (Result<void> w = writeText(args.output + "/summary.json", summary.dump(2) + "\n"); !w)
                return printError(w.error()), false;
            if (args.json)
                std::printf("%s\n", summary.dump(2).c_str());

            // Plot data, one set per tree count: a CSV per plot and DIR/plots.json saying how to draw
            // each (bench/plot.py draws them).
            json plots = json::array();
            auto addPlot = [&](const std::string& name, const std::string& csvText, json spec) {
                spec["csv"] = name + ".csv";
                spec["png"] = name + ".png";
                plots.push_back(std::move(spec));
                return writeText(args.output + "/" + name + ".csv", csvText);
            };
            for (std::uint32_t count : counts)
            {
                const std::string suffix = counts.size() > 1 ? "-" + std::to_string(count) : "";
                // frame-time: per run at bias 1 (and the comparisons), frame ms along the path; empty
                // where the frame was not timed (a gap in the line).
                std::string timeCsv = "series,label,time_s,frame_ms\n";
                // trade: one curve per technique over the biases; the comparisons are single points
                // drawn with their `marker` (ComparisonRun::marker). on_front: 1 for the runs on the
                // Pareto front.
                std::string tradeCsv = "series,label,lod_bias,median_frame_ms,mean_flip,marker,on_front\n";
                std::vector<std::string> curveRows;
                for (std::size_t i = 0; i < runs.size(); ++i)
                {
                    const Run& run = runs[i];
                    if (run.count != count)
                        continue;
                    const std::string point = number(run.lodBias, 3) + "," + number(points[i].medianFrameMs, 6) + "," +
                                              number(points[i].meanFlip, 6) + ",";
                    const std::string front = onFront(i) ? ",1\n" : ",0\n";
                    if (isComparisonRun(run.technique))
                    {
                        for (const ComparisonRun& c : comparisonRuns())
                            if (c.technique == run.technique)
                                tradeCsv += csvField(run.technique) + "," + csvField(c.label) + "," + point +
                                            std::string(1, c.marker) + front;
                    }
                    else
                        curveRows.push_back(csvField(run.technique) + "," +
                                            csvField(run.technique + " (LoD bias " + args.lodBiases + ")") + "," +
                                            point + front);
                    if (run.lodBias == 1.0f || isComparisonRun(run.technique))
                    {
                        std::string label = run.technique;
                        for (const ComparisonRun& c : comparisonRuns())
                            if (c.technique == run.technique)
                                label = c.label;
                        if (std::none_of(run.frames.begin(), run.frames.end(),
                                         [](const FrameRecord& r) { return r.timed; }))
                            label += ": every frame over the triangle budget, skipped";
                        for (const FrameRecord& r : run.frames)
                            timeCsv += csvField(run.technique) + "," + csvField(label) + "," + number(r.time, 6) +
                                       "," + (r.timed ? number(r.timing.frameMilliseconds, 6) : "") + "\n";
                    }
                }
                // Curves after the markers, by technique name.
                std::stable_sort(curveRows.begin(), curveRows.end(), [](const std::string& a, const std::string& b) {
                    return a.substr(0, a.find(',')) < b.substr(0, b.find(','));
                });
                for (const std::string& row : curveRows)
                    tradeCsv += row;
                const std::string frameTimeTitle = script.name + ": frame time along the path (" + treesText(count) +
                                                   ", " + std::to_string(width) + "x" + std::to_string(height) + ")";
                if (Result<void> w = addPlot("frame-time" + suffix, timeCsv,
                                             {{"title", frameTimeTitle},
                                              {"x", "time_s"},
                                              {"y", "frame_ms"},
                                              {"xLabel", "path time (s)"},
                                              {"yLabel", "frame ms"},
                                              {"logX", false},
                                              {"logY", true},
                                              {"markers", false}});
                    !w)
                    return printError(w.error()), false;
                if (Result<void> w = addPlot("trade" + suffix, tradeCsv,
                                             {{"title", script.name + ": error against frame time (" +
                                                            treesText(count) + ")"},
                                              {"x", "median_frame_ms"},
                                              {"y", "mean_flip"},
                                              {"xLabel", "median frame ms (over the frames every run timed)"},
                                              {"yLabel", "mean FLIP vs supersampled reference"},
                                              {"logX", true},
                                              {"logY", false},
                                              {"markers", true}});
                    !w)
                    return printError(w.error()), false;
            }
            if (counts.size() > 1) // García et al. 2007 Table 2: frame time against the number of trees
            {
                std::string treesCsv = "series,label,trees,median_frame_ms\n";
                std::vector<std::string> rows;
                for (const Run& run : runs)
                    if (run.lodBias == 1.0f)
                        rows.push_back(csvField(run.technique) + "," + csvField(run.technique) + "," +
                                       std::to_string(run.count) + "," + number(medianOver(run, nullptr), 6) + "\n");
                std::stable_sort(rows.begin(), rows.end(), [](const std::string& a, const std::string& b) {
                    return a.substr(0, a.find(',')) < b.substr(0, b.find(','));
                });
                for (const std::string& row : rows)
                    treesCsv += row;
                if (Result<void> w = addPlot("trees", treesCsv,
                                             {{"title", script.name + ": median frame ms against trees (LoD bias 1)"},
                                              {"x", "trees"},
                                              {"y", "median_frame_ms"},
                                              {"xLabel", "trees"},
                                              {"yLabel", "median frame ms"},
                                              {"logX", true},
                                              {"logY", true},
                                              {"markers", true}});
                    !w)
                    return printError(w.error()), false;
            }
            // The error curves budgeted auto chose by: FLIP against screen height per level and package.
            for (const BakeCacheEntry& entry : baker.getEntries())
            {
                Result<PackageReader> package = PackageReader::open(entry.path);
                if (!package || package->findChunk(ERROR_CURVES_CHUNK, 0) < 0)
                    continue;
                Result<std::vector<std::uint8_t>> bytes = package->readChunk(ERROR_CURVES_CHUNK, 0);
                Result<ErrorCurves> curves = bytes ? decodeErrorCurves(*bytes, entry.path) : Result<ErrorCurves>(bytes.error());
                if (!curves)
                    return printError(curves.error()), false;
                std::string csv = "series,label,height_px,flip,flip_max,ms_rmse\n";
                for (const ErrorCurveLevel& level : curves->levels)
                {
                    const std::string label = level.technique + " " + std::to_string(level.techniqueLevel) +
                                              (level.lowRes ? " low-res" : "");
                    for (std::size_t h = 0; h < curves->heightsPx.size(); ++h)
                        csv += csvField(label) + "," + csvField(label) + "," + number(curves->heightsPx[h], 6) + "," +
                               number(level.flip[h], 6) + "," + number(level.flipMax[h], 6) + "," +
                               number(level.rmse[h], 6) + "\n";
                }
                std::string fileName = entry.name;
                for (char& c : fileName)
                    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_')
                        c = '_';
                if (Result<void> w = addPlot("curves-" + fileName, csv,
                                             {{"title", entry.name + ": error curves (FLIP per tree pixel against the "
                                                                     "CPU reference, mean of " +
                                                            std::to_string(curves->views) + " views)"},
                                              {"x", "height_px"},
                                              {"y", "flip"},
                                              {"xLabel", "tree height on screen (px)"},
                                              {"yLabel", "mean FLIP"},
                                              {"logX", true},
                                              {"logY", false},
                                              {"markers", true}});
                    !w)
                    return printError(w.error()), false;
            }
            if (Result<void> w = writeText(args.output + "/plots.json", json{{"plots", plots}}.dump(2) + "\n"); !w)
                return printError(w.error()), false;
            return drawPlots(args.output);
        }

        /// treelod_frames: $TREELOD_FRAMES, else beside this executable.
        std::string framesExecutable()
        {
            if (const char* env = std::getenv("TREELOD_FRAMES"); env && *env)
                return env;
            std::error_code ec;
            const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
            return (ec ? std::filesystem::path("treelod_frames") : self.parent_path() / "treelod_frames").string();
        }

        /// Run `argv` and wait; its exit code, or -1 when it could not start or died of a signal.
        /// `searchPath`: argv[0] is looked up on PATH; `silent`: its stdout and stderr, and the
        /// message when it cannot start, go nowhere.
        int runProcess(const std::vector<std::string>& argv, bool searchPath, bool silent)
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
            auto load = [&](const std::string& stem) -> Result<Image> {
                return readImage(directory + "/images/" + stem + ".png");
            };
            std::vector<Run> runs;
            for (const nlohmann::json& r : timings["runs"])
            {
                Run run;
                run.count = r.value("trees", 0u);
                run.technique = r.value("technique", "");
                run.lodBias = r.value("lodBias", 1.0f);
                run.assetBytes = r.value("gpuBytes", std::uint64_t(0));
                run.instanceBytes = r.value("instanceBytes", std::uint64_t(0));
                run.rssMiB = r.value("rssMiB", NAN);
                run.peakRssMiB = r.value("peakRssMiB", NAN);
                run.skipped = r.value("skipped", "");
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
                        record.levels = f.value("levels", std::vector<std::uint32_t>{});
                        record.uploadedBytes = f.value("uploadedBytes", std::uint64_t(0));
                    }
                    std::map<std::uint32_t, ReferenceSample>& refs = references[run.count];
                    if (f.contains("referenceImage"))
                    {
                        const std::string stem = f["referenceImage"];
                        Result<Image> image = load(stem), next = load(stem + "-next");
                        if (!image)
                            return image.error();
                        if (!next)
                            return next.error();
                        ReferenceSample sample;
                        sample.image = std::move(*image);
                        if (Result<MultiScaleRmseResult> m = multiScaleRmse(sample.image, *next))
                            sample.temporalNoise = m->combined;
                        refs[record.frame] = std::move(sample);
                    }
                    if (f.contains("image"))
                    {
                        const std::string stem = f["image"];
                        if (auto it = refs.find(record.frame); it != refs.end())
                        {
                            Result<Image> image = load(stem), next = load(stem + "-next");
                            if (!image)
                                return image.error();
                            if (!next)
                                return next.error();
                            if (Result<FlipResult> m = flip(it->second.image, *image))
                                record.flip = m->mean;
                            if (Result<MultiScaleRmseResult> m = multiScaleRmse(it->second.image, *image))
                                record.msRmse = m->combined;
                            if (Result<MultiScaleRmseResult> m = multiScaleRmse(*image, *next))
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
                                                number(args.shadowLodBias, 8)};
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
                        "MS milliseconds) or any of " + known)
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
        cmd->add_option("--upload-budget", args->uploadBudget,
                        "bytes of Forest levels built per frame (0 = no limit); levels waiting draw a coarser one")
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
