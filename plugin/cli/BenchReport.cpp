// treelod bench's outputs (BenchReport.h).
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

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

namespace TreeLod
{
    namespace Bench
    {
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
        std::string levelsText(const std::vector<std::uint32_t>& levels)
        {
            std::string out;
            for (std::size_t i = 0; i < levels.size(); ++i)
                out += (i ? ";" : "") + std::to_string(levels[i]);
            return out;
        }

        std::string number(double v, int digits)
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

        /// A budget kept as a float (0.04f) as the decimal it was written as (to 1e-6).
        double decimal(double v) { return std::round(v * 1e6) / 1e6; }

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

        /// A run as the Pareto line names it: "<technique>", or "<technique>@0.5" at a bias other than 1.
        std::string runName(const Run& run)
        {
            return run.technique + (run.lodBias == 1.0f ? "" : "@" + number(run.lodBias, 3));
        }

        /// Mean of a per-frame figure of `run` over the frames that have it (NaN without any).
        double meanOf(const Run& run, double FrameRecord::*figure)
        {
            std::vector<double> values;
            for (const FrameRecord& r : run.frames)
                values.push_back(r.*figure);
            return statsOf(values).mean;
        }

        /// A per-frame figure of `run` over its frames that have it (`all`, with the worst frame
        /// named `name`), and over the frames where `reference` has it too, its own and the
        /// reference's (`own`, `ref`).
        struct FigureStats
        {
            Stats all, own, ref;
            nlohmann::json worst = nullptr;
        };

        FigureStats figureStats(const Run& run, const Run* reference, double FrameRecord::*figure, const char* name)
        {
            std::vector<double> all, own, ref;
            FigureStats out;
            for (std::size_t f = 0; f < run.frames.size(); ++f)
            {
                const FrameRecord& r = run.frames[f];
                if (!std::isfinite(r.*figure))
                    continue;
                all.push_back(r.*figure);
                if (out.worst.is_null() || r.*figure > out.worst[name].get<double>())
                    out.worst = {{"frame", r.frame}, {"time", r.time}, {name, r.*figure}};
                if (reference && f < reference->frames.size() && std::isfinite(reference->frames[f].*figure))
                {
                    own.push_back(r.*figure);
                    ref.push_back(reference->frames[f].*figure);
                }
            }
            out.all = statsOf(all);
            out.own = statsOf(own);
            out.ref = statsOf(ref);
            return out;
        }

        /// What `run` does in motion (summary.json's "motion"): its temporal FLIP over the motion
        /// frames with the worst one; the reference's over the frames both measured, and the
        /// ratios of the means and of the worst frames there; the pop FLIP (FrameRecord::popFlip)
        /// with its worst frame and the reference's; level switches per visible tree per second
        /// of the path (null where not counted).
        nlohmann::json motionJson(const Run& run, const Run* reference)
        {
            using nlohmann::json;
            const FigureStats motion = figureStats(run, reference, &FrameRecord::temporalFlip, "temporalFlip");
            const FigureStats pops = figureStats(run, reference, &FrameRecord::popFlip, "popFlip");
            std::int64_t switches = 0, visible = 0;
            bool counted = false;
            for (const FrameRecord& r : run.frames)
                if (std::isfinite(r.temporalFlip) && r.switches >= 0 && r.switchVisible >= 0)
                {
                    switches += r.switches;
                    visible += r.switchVisible;
                    counted = true;
                }
            const auto summary = [](const Stats& s) {
                return json{{"mean", num(s.mean)}, {"max", num(s.max)}, {"frames", s.count}};
            };
            const bool rate = counted && visible > 0 && run.motionStepSeconds > 0.0;
            return {{"temporalFlip", summary(motion.all)},
                    {"worstFrame", motion.worst},
                    {"reference", summary(motion.ref)},
                    {"meanOverReference", num(motion.own.mean / motion.ref.mean)},
                    {"worstOverReference", num(motion.own.max / motion.ref.max)},
                    {"popFlip", summary(pops.all)},
                    {"worstPopFrame", pops.worst},
                    {"referencePopFlip", summary(pops.ref)},
                    {"levelSwitches", counted ? json(switches) : json(nullptr)},
                    {"switchesPerTreePerSecond",
                     rate ? num(double(switches) / double(visible) / run.motionStepSeconds) : json(nullptr)}};
        }

        bool writeOutputs(const BenchArgs& args, const SceneScript& script, std::uint32_t frames, int width, int height,
                          const std::vector<Run>& runs,
                          const std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>>& references,
                          const CacheTreeBaker& baker)
        {
            // frames.csv: one row per run and frame.
            std::string csv = "trees,technique,lod_bias,frame,time_s,timed,cpu_ms,frame_ms,batches,triangles,visible,"
                              "instances_per_level,flip,ms_rmse,temporal_noise,temporal_flip,pop_flip,level_switches,skipped,"
                              "uploaded_bytes,gpu_bytes\n";
            for (const Run& run : runs)
                for (const FrameRecord& r : run.frames)
                    csv += std::to_string(run.count) + "," + run.technique + "," + number(run.lodBias, 3) + "," +
                           std::to_string(r.frame) + "," + number(r.time, 5) + "," + (r.timed ? "1" : "0") + "," +
                           (r.timed ? number(r.timing.cpuMilliseconds) : "") + "," +
                           (r.timed ? number(r.timing.frameMilliseconds) : "") + "," +
                           (r.timed ? std::to_string(r.timing.batches) : "") + "," +
                           (r.timed ? std::to_string(r.timing.triangles) : "") + "," +
                           (r.timed ? std::to_string(r.visible) : "") + "," + levelsText(r.levels) + "," +
                           number(r.flip) + "," + number(r.msRmse) + "," + number(r.temporalNoise) + "," +
                           number(r.temporalFlip) + "," + number(r.popFlip) + "," +
                           (r.switches >= 0 ? std::to_string(r.switches) : "") + ",\"" +
                           r.skipped + "\"," + (r.timed ? std::to_string(r.uploadedBytes) : "") + "," +
                           (r.timed ? std::to_string(r.gpuBytes) : "") + "\n";
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
                            {"windStrength", script.wind.strength},
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
                            {"meanFlip", num(points[i].meanFlip)},
                            {"meanTemporalFlip", num(meanOf(runs[i], &FrameRecord::temporalFlip))},
                            {"meanPopFlip", num(meanOf(runs[i], &FrameRecord::popFlip))},
                            {"peakGpuBytes", runs[i].peakGpuBytes}};
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
                    char text[160];
                    const double motion = meanOf(runs[i], &FrameRecord::temporalFlip);
                    const double pops = meanOf(runs[i], &FrameRecord::popFlip);
                    const double megabytes = double(runs[i].peakGpuBytes) / 1e6;
                    if (std::isfinite(motion) && std::isfinite(pops))
                        std::snprintf(text, sizeof text, " %.3g ms %.3g %.3g MB (motion %.3g pops %.3g)",
                                      points[i].medianFrameMs, points[i].meanFlip, megabytes, motion, pops);
                    else if (std::isfinite(motion))
                        std::snprintf(text, sizeof text, " %.3g ms %.3g %.3g MB (motion %.3g)", points[i].medianFrameMs,
                                      points[i].meanFlip, megabytes, motion);
                    else
                        std::snprintf(text, sizeof text, " %.3g ms %.3g %.3g MB", points[i].medianFrameMs,
                                      points[i].meanFlip, megabytes);
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
            // The scene's GPU memory: each run's peak (levels and instance buffers), the largest.
            std::uint64_t scenePeakGpu = 0;
            std::string gpuLine;
            for (const Run& run : runs)
            {
                scenePeakGpu = std::max(scenePeakGpu, run.peakGpuBytes);
                char text[96];
                std::snprintf(text, sizeof text, " %.3g MB", double(run.peakGpuBytes) / 1e6);
                gpuLine += (gpuLine.empty() ? "" : ", ") + runName(run) + text +
                           (run.binding.empty() ? "" : " (" + run.binding + " binds)");
            }
            summary["peakGpuBytes"] = scenePeakGpu;
            if (!args.quiet && !runs.empty())
                std::printf("peak GPU memory: %s\n", gpuLine.c_str());
            if (!args.quiet)
                std::printf("peak resident memory: frame timer %.0f MiB, bench %.0f MiB\n", framesPeakMiB,
                            benchPeakMiB);
            json results = json::array();
            // Per tree count, the budgeted runs' error used against their budgets (the calibration below).
            struct BudgetPoint
            {
                std::string name;
                double budget, used, speedup;
            };
            std::map<std::uint32_t, std::vector<BudgetPoint>> budgetPoints;
            for (std::size_t i = 0; i < runs.size(); ++i)
            {
                const Run& run = runs[i];
                const Run* reference = nullptr;
                for (const Run& other : runs)
                    if (other.count == run.count && other.technique == REFERENCE_TECHNIQUE)
                        reference = &other;
                std::vector<double> frameMs, cpuMs, flips, rmse, noise, refNoise, occluded, used;
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
                        occluded.push_back(double(r.occluded));
                    }
                    // The error used: this run's FLIP over the polygonal tree's own on the same frame.
                    const std::size_t f = std::size_t(&r - run.frames.data());
                    if (reference && &run != reference && f < reference->frames.size() && std::isfinite(r.flip))
                        if (const double own = reference->frames[f].flip; std::isfinite(own))
                            used.push_back(r.flip - own);
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
                if (std::isfinite(run.errorBudget) && !used.empty())
                    budgetPoints[run.count].push_back(
                        {runName(run), run.errorBudget, statsOf(used).mean, referenceOnShared / techniqueOnShared});
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
                                   {"motion", motionJson(run, reference)},
                                   {"occludedTrees", num(statsOf(occluded).mean)},
                                   {"occlusion", run.occlusion},
                                   {"errorBudget", num(decimal(run.errorBudget))},
                                   {"sceneError", {{"used", num(statsOf(used).mean)},
                                                   {"allowed", decimal(SCENE_ERROR_MARGIN)},
                                                   {"frames", used.size()}}},
                                   {"assetBytes", run.assetBytes},
                                   {"gpu", {{"peakBytes", run.peakGpuBytes},
                                            {"residentLevels", run.residentLevels >= 0 ? json(run.residentLevels) : json(nullptr)},
                                            {"plannedBytes", run.residentLevels >= 0 ? json(run.plannedGpuBytes) : json(nullptr)},
                                            {"memoryBudgetBytes", run.memoryBudgetBytes},
                                            {"binding", run.binding.empty() ? json(nullptr) : json(run.binding)}}},
                                   {"bakeSeconds", run.bakeSeconds},
                                   {"trade", {{"medianFrameMs", num(points[i].medianFrameMs)},
                                              {"meanFlip", num(points[i].meanFlip)}}},
                                   {"onParetoFront", points[i].measured() ? json(onFront(i)) : json(nullptr)},
                                   {"skipped", skipped}});
            }
            summary["results"] = results;
            // The calibration step: of the budgeted runs, the largest per-tree error budget whose error
            // used stays within the margin (bench.md, "Error used"); run several (auto@0.04,auto@0.08)
            // to choose a scene's "lod" maxError.
            json calibration = json::array();
            for (auto& [count, points] : budgetPoints)
            {
                std::sort(points.begin(), points.end(),
                          [](const BudgetPoint& a, const BudgetPoint& b) { return a.budget < b.budget; });
                json tried = json::array();
                const BudgetPoint* best = nullptr;
                std::string line;
                for (const BudgetPoint& p : points)
                {
                    tried.push_back({{"run", p.name},
                                     {"errorBudget", decimal(p.budget)},
                                     {"used", p.used},
                                     {"speedupVsReference", num(p.speedup)}});
                    if (p.used <= SCENE_ERROR_MARGIN && (!best || p.budget > best->budget))
                        best = &p;
                    line += (line.empty() ? "" : ", ") + p.name + " " + number(p.used, 2);
                }
                calibration.push_back({{"trees", count},
                                       {"allowed", decimal(SCENE_ERROR_MARGIN)},
                                       {"tried", tried},
                                       {"largestWithinMargin", best ? json(decimal(best->budget)) : json(nullptr)}});
                if (!args.quiet)
                    std::printf("error used (%s) of %g allowed: %s; the largest budget within it: %s\n",
                                treesText(count).c_str(), double(SCENE_ERROR_MARGIN), line.c_str(),
                                best ? number(best->budget, 2).c_str() : "none");
            }
            summary["budgetCalibration"] = calibration;
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
                // motion: the same runs' temporal FLIP along the path (motion frames only).
                std::string motionCsv = "series,label,time_s,temporal_flip\n";
                std::string popCsv = "series,label,time_s,pop_flip\n";
                bool anyMotion = false, anyPop = false;
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
                        {
                            timeCsv += csvField(run.technique) + "," + csvField(label) + "," + number(r.time, 6) +
                                       "," + (r.timed ? number(r.timing.frameMilliseconds, 6) : "") + "\n";
                            if (std::isfinite(r.temporalFlip))
                            {
                                motionCsv += csvField(run.technique) + "," + csvField(label) + "," +
                                             number(r.time, 6) + "," + number(r.temporalFlip, 6) + "\n";
                                anyMotion = true;
                            }
                            if (std::isfinite(r.popFlip))
                            {
                                popCsv += csvField(run.technique) + "," + csvField(label) + "," + number(r.time, 6) +
                                          "," + number(r.popFlip, 6) + "\n";
                                anyPop = true;
                            }
                        }
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
                if (anyMotion)
                    if (Result<void> w = addPlot("motion" + suffix, motionCsv,
                                                 {{"title", script.name + ": change between consecutive frames (" +
                                                                treesText(count) + ", LoD bias 1)"},
                                                  {"x", "time_s"},
                                                  {"y", "temporal_flip"},
                                                  {"xLabel", "path time (s)"},
                                                  {"yLabel", "FLIP between a frame and the next, over the trees"},
                                                  {"logX", false},
                                                  {"logY", false},
                                                  {"markers", true}});
                        !w)
                        return printError(w.error()), false;
                if (anyPop)
                    if (Result<void> w = addPlot("pops" + suffix, popCsv,
                                                 {{"title", script.name + ": what level switches change between two "
                                                                          "frames (" + treesText(count) + ", LoD bias 1)"},
                                                  {"x", "time_s"},
                                                  {"y", "pop_flip"},
                                                  {"xLabel", "path time (s)"},
                                                  {"yLabel", "FLIP, next frame with levels held vs switched"},
                                                  {"logX", false},
                                                  {"logY", false},
                                                  {"markers", true}});
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
                const std::size_t chunk = std::size_t(package->findChunk(ERROR_CURVES_CHUNK, 0));
                Result<std::vector<std::uint8_t>> bytes = package->readChunk(chunk);
                Result<ErrorCurves> curves =
                    bytes ? decodeErrorCurves(*bytes, entry.path, package->chunks()[chunk].formatVersion)
                          : Result<ErrorCurves>(bytes.error());
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
#endif
    }
}
