// Image metrics on random-noise images. Targets (512x512, 2-core machine):
// FLIP <= 100 ms, multi-scale RMSE <= 2 ms. FLIP runs on TBB: its CPU column is the
// whole process (all threads), its time column wall clock.
// Run: build/bin/treelod_core_bench --benchmark_filter=Metrics
#include "TreeLod/ImageMetrics.h"

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>

namespace
{
    using namespace TreeLod;

    Image noiseImage(int size, std::uint32_t seed)
    {
        std::mt19937 rng(seed);
        Image image(size, size, glm::vec4(1.0f));
        for (glm::vec4& p : image.pixels)
            for (int c = 0; c < 3; ++c)
                p[c] = float(rng() >> 8) / float(1 << 24);
        return image;
    }

    void BM_MetricsMultiScaleRmse(benchmark::State& state)
    {
        const int size = int(state.range(0));
        const Image a = noiseImage(size, 1), b = noiseImage(size, 2);
        for (auto _ : state)
            benchmark::DoNotOptimize(multiScaleRmse(a, b));
        state.SetItemsProcessed(state.iterations() * size * size);
    }
    BENCHMARK(BM_MetricsMultiScaleRmse)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond);

    void BM_MetricsFlip(benchmark::State& state)
    {
        const int size = int(state.range(0));
        const Image a = noiseImage(size, 1), b = noiseImage(size, 2);
        for (auto _ : state)
            benchmark::DoNotOptimize(flip(a, b));
        state.SetItemsProcessed(state.iterations() * size * size);
    }
    BENCHMARK(BM_MetricsFlip)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

    void BM_MetricsPsnr(benchmark::State& state)
    {
        const int size = int(state.range(0));
        const Image a = noiseImage(size, 1), b = noiseImage(size, 2);
        for (auto _ : state)
            benchmark::DoNotOptimize(psnr(a, b));
        state.SetItemsProcessed(state.iterations() * size * size);
    }
    BENCHMARK(BM_MetricsPsnr)->Arg(512)->Unit(benchmark::kMillisecond);
}
