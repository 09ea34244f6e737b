// LoDF (Rebollo et al. 2006 §5, Figs. 10-11): per level-of-detail change, extraction time and bytes
// uploaded, LoDF against a rebuild-everything baseline, on a generated oak of 100k leaves
// (preset oak, seed 1, built once).
// Target: a 1 % change at 100k leaves costs at least 5x less time and bytes than the
// rebuild.
//   LoDF:    setLeafCount + writeCluster<uint32_t> of each changed cluster into a CPU mirror
//            of the index buffer at its firstSlot (§4: only the changed groups are sent);
//            bytes = 4 x slotCount of each changed cluster.
//   Rebuild: the VDF-like approach the paper compares with: setLeafCount, then walk every
//            cluster and write the whole packed list of active indices; bytes = 4 x active
//            indices.
//   *Sweep/steps: L -> min in `steps` uniform steps and back (2 x steps changes per iteration,
//            the paper's traversal with a uniform step). *OnePercent/start%: one change of
//            1 % of L (1000 leaves) per iteration, from a start level of 100/75/50/25 % of L,
//            alternating down and up. Counters: bytes_per_change, changes (per iteration),
//            per_change (time of one change).
// Run: build/bin/treelod_core_bench --benchmark_filter='Lodf|Rebuild' --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodState.h"
#include "TreeLod/TreeGenerator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace
{
    using namespace TreeLod;

    constexpr std::uint32_t kLodfLeaves = 100000;

    /// F^r of the generated oak, or an error message.
    struct Input
    {
        FoliageLodData data;
        std::string error;
    };

    const Input& input()
    {
        static const Input in = [] {
            Input out;
            GeneratorOptions options;
            options.preset = TreePreset::Oak;
            options.leafCount = kLodfLeaves;
            options.textureSize = 32;
            Result<TreeModel> model = generateTree(options);
            if (!model)
            {
                out.error = model.error().message();
                return out;
            }
            Result<FoliageLodData> data = buildFoliageLod(*model, {}, "generated oak");
            if (!data)
                out.error = data.error().message();
            else
                out.data = std::move(data).value();
            return out;
        }();
        return in;
    }

    /// The input, or null after marking the benchmark skipped with the error.
    const FoliageLodData* inputOr(benchmark::State& state)
    {
        const Input& in = input();
        if (in.error.empty())
            return &in.data;
        state.SkipWithError(in.error.c_str());
        return nullptr;
    }

    /// One change, LoDF: only the changed clusters' regions are rewritten. Returns bytes sent.
    std::uint64_t lodfChange(FoliageLodState& state, std::vector<std::uint32_t>& mirror, std::uint32_t target)
    {
        state.setLeafCount(target);
        const FoliageLodData& d = state.data();
        std::uint64_t bytes = 0;
        for (std::uint32_t c : state.changedClusters())
        {
            const FoliageLodCluster& k = d.clusters[c];
            state.writeCluster(c, mirror.data() + k.firstSlot);
            bytes += 4ull * k.slotCount;
        }
        benchmark::DoNotOptimize(mirror.data());
        benchmark::ClobberMemory();
        return bytes;
    }

    /// One change, rebuild: every cluster's active indices written packed. Returns bytes sent.
    std::uint64_t rebuildChange(FoliageLodState& state, std::vector<std::uint32_t>& packed, std::uint32_t target)
    {
        state.setLeafCount(target);
        const FoliageLodData& d = state.data();
        std::uint32_t* out = packed.data();
        for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
        {
            state.forEachActive(c, [&](const FoliageLodEntry& e) {
                out = std::copy_n(d.indices.data() + e.firstIndex, e.indexCount, out);
            });
        }
        benchmark::DoNotOptimize(packed.data());
        benchmark::ClobberMemory();
        return 4ull * std::uint64_t(out - packed.data());
    }

    using Change = std::uint64_t (*)(FoliageLodState&, std::vector<std::uint32_t>&, std::uint32_t);

    void setCounters(benchmark::State& state, std::uint64_t bytes, std::uint64_t changes, double changesPerIteration)
    {
        state.counters["bytes_per_change"] = changes ? double(bytes) / double(changes) : 0.0;
        state.counters["changes"] = changesPerIteration;
        state.counters["per_change"] = benchmark::Counter(
            changesPerIteration, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
    }

    /// L -> min in state.range(0) uniform steps, then back to L.
    void sweep(benchmark::State& state, Change change)
    {
        const FoliageLodData* data = inputOr(state);
        if (!data)
            return;
        const FoliageLodData& d = *data;
        const std::uint32_t steps = std::uint32_t(state.range(0));
        const std::uint32_t L = d.maxLeafCount(), lo = d.minLeafCount();
        std::vector<std::uint32_t> targets;
        for (std::uint32_t i = 1; i <= steps; ++i)
            targets.push_back(L - std::uint32_t(std::uint64_t(L - lo) * i / steps));
        for (std::uint32_t i = 1; i <= steps; ++i)
            targets.push_back(lo + std::uint32_t(std::uint64_t(L - lo) * i / steps));
        FoliageLodState lod(d);
        std::vector<std::uint32_t> buffer(d.slotCount());
        std::uint64_t bytes = 0, changes = 0;
        for (auto _ : state)
            for (std::uint32_t target : targets)
            {
                bytes += change(lod, buffer, target);
                ++changes;
            }
        setCounters(state, bytes, changes, double(targets.size()));
    }

    /// One change of 1 % of L per iteration, between state.range(0) % of L and 1 % fewer.
    void onePercent(benchmark::State& state, Change change)
    {
        const FoliageLodData* data = inputOr(state);
        if (!data)
            return;
        const FoliageLodData& d = *data;
        const std::uint32_t L = d.maxLeafCount();
        const std::uint32_t high = std::uint32_t(std::uint64_t(L) * std::uint64_t(state.range(0)) / 100);
        const std::uint32_t low = high - L / 100;
        FoliageLodState lod(d);
        std::vector<std::uint32_t> buffer(d.slotCount());
        change(lod, buffer, high); // start level, not timed
        for (std::uint32_t c = 0; c < d.clusters.size(); ++c)
            lod.writeCluster(c, buffer.data() + d.clusters[c].firstSlot);
        std::uint64_t bytes = 0, changes = 0;
        bool down = true;
        for (auto _ : state)
        {
            bytes += change(lod, buffer, down ? low : high);
            down = !down;
            ++changes;
        }
        setCounters(state, bytes, changes, 1.0);
    }

    void BM_LodfSweep(benchmark::State& state) { sweep(state, lodfChange); }
    void BM_RebuildSweep(benchmark::State& state) { sweep(state, rebuildChange); }
    void BM_LodfOnePercent(benchmark::State& state) { onePercent(state, lodfChange); }
    void BM_RebuildOnePercent(benchmark::State& state) { onePercent(state, rebuildChange); }
}

BENCHMARK(BM_LodfSweep)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RebuildSweep)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LodfOnePercent)->Arg(100)->Arg(75)->Arg(50)->Arg(25)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RebuildOnePercent)->Arg(100)->Arg(75)->Arg(50)->Arg(25)->Unit(benchmark::kMicrosecond);
