// BenchReport: the outputs of `treelod bench` from its measured runs (frames.csv, summary.json, the
// Pareto front, the plots' data and pictures), and what BenchCommand.cpp and it share: the
// command's arguments and the runs as treelod_frames timed them. Private to the CLI.
#pragma once

#include "CliSupport.h"

#include "TreeLod/SceneScript.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#ifdef TREELOD_WITH_OGRE
#include "TreeLod/CacheTreeBaker.h"
#include "TreeLod/Image.h"
#include "TreeLod/OffscreenRenderer.h"
#endif

namespace TreeLod
{
    namespace Bench
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
            double wind = -1.0;                   // the wind's strength; -1: the script's
            std::string motionFrames = "all";     // treelod_frames --motion-frames
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

        Stats statsOf(std::vector<double> values);
        /// A number for summary.json: null when not finite (not measured).
        nlohmann::json num(double v);
        nlohmann::json toJson(const Stats& s);

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
            std::uint32_t occluded = 0;        ///< trees in view not drawn, hidden by others (Forest::setOcclusion)
            std::vector<std::uint32_t> levels; ///< visible instances per level index, all species summed
            std::uint64_t uploadedBytes = 0;   ///< levels made resident in this frame (Forest upload budget)
            std::uint64_t gpuBytes = 0;        ///< GPU bytes after the frame (levels and instance buffers)
            double flip = NAN, msRmse = NAN, temporalNoise = NAN;
            /// Motion frames: FLIP between this frame and the next at the script's frame rate over
            /// the trees' pixels; the level switches between them and the trees visible (-1: not
            /// counted, e.g. a floor that is no Forest).
            double temporalFlip = NAN;
            /// Motion frames of the Forest's runs: FLIP between the next frame with this frame's
            /// levels held and the next frame, over the trees' pixels: what the level switches
            /// alone change (0 without a switch).
            double popFlip = NAN;
            std::int64_t switches = -1, switchVisible = -1;
        };

        /// One (technique, bias) run over the path.
        struct Run
        {
            std::uint32_t count = 0; ///< trees in the scene
            std::string technique;
            float lodBias = 1.0f;
            std::vector<FrameRecord> frames;
            std::uint64_t assetBytes = 0;    ///< GPU bytes of what the run drew, at its end
            std::uint64_t peakGpuBytes = 0;  ///< the most GPU bytes over its frames (levels, instance buffers)
            /// The Forest's runs (-1 / empty for the floors): levels resident at the end, the planned
            /// levels' bytes, the memory budget (0: none) and the budget that binds.
            std::int64_t residentLevels = -1;
            std::uint64_t plannedGpuBytes = 0, memoryBudgetBytes = 0;
            std::string binding;
            double errorBudget = NAN; ///< the budgeted species' error budget at the end (NaN: none)
            bool occlusion = false;   ///< the Forest estimated occlusion (Forest::setOcclusion)
            std::uint64_t instanceBytes = 0; ///< the Forest's instance store on the CPU
            double rssMiB = NAN, peakRssMiB = NAN; ///< treelod_frames' resident memory after the run
            double bakeSeconds = 0.0;
            double motionStepSeconds = 0.0; ///< between a motion frame and its next (the script's frame rate)
            std::string skipped;   ///< the whole run (e.g. too many entities)
            bool hasPicture = false;
        };

        /// The reference on a sampled frame: supersampled image and its temporal noise.
        struct ReferenceSample
        {
            Image image;
            double temporalNoise = NAN;
        };

        /// `v` with `digits` + 2 significant digits; "" when not finite.
        std::string number(double v, int digits = 4);
        Result<void> writeText(const std::string& path, const std::string& text);
        /// Triangles the reference's supersampled images may cost (--reference-image-budget, else --reference-budget).
        double imageBudget(const BenchArgs& args);
        /// Run `argv` and wait; its exit code, or -1 when it could not start or died of a signal.
        /// `searchPath`: argv[0] is looked up on PATH; `silent`: its stdout and stderr, and the
        /// message when it cannot start, go nowhere.
        int runProcess(const std::vector<std::string>& argv, bool searchPath = false, bool silent = false);
        /// Writes every output of the bench into args.output; false (the error printed) when one fails.
        bool writeOutputs(const BenchArgs& args, const SceneScript& script, std::uint32_t frames, int width, int height,
                          const std::vector<Run>& runs,
                          const std::map<std::uint32_t, std::map<std::uint32_t, ReferenceSample>>& references,
                          const CacheTreeBaker& baker);
#endif
    }
}
