// Forest: instances culled and LoD-selected per second on one core, by
// ForestInstances::cull (frustum test, LoD level, counting sort into (kind, level) buckets with
// packed 3x4 world matrices).
// Target: 20 M instances per second or better on one core.
// Input: 1 M instances at random positions in a 10 km square (seed 1), random rotation, scale
// 0.7-1.3, 4 kinds (3 with pixel-count tables of 3-4 levels, 1 with a distance table), a
// 1920 x 1080 viewport, fov 60 degrees. Cameras (the argument):
//   0 ground:   2 m above the centre, far clip 5 km (a walk through the forest);
//   1 overview: 1.5 km above a corner looking at the centre, far clip 20 km (most are visible:
//               the fill pass writes a matrix for each);
//   2 random:   64 cameras (seed 2), one per iteration in turn: anywhere over the square, 2 m to
//               1.5 km high, any heading, pitch 0 to -60 degrees, far clip 5-20 km.
// The second argument: occlusion off (0) or on (1: ForestOcclusion.h; each kind a crown of coverage
// 0.7 over a trunk, the trees' squares on a 128-column grid).
// Counters: visible (instances drawn per frame, the mean over the cameras), occluded (hidden by
// trees in front, not drawn); items = instances culled and selected.
// Run: build/bin/treelod_core_bench --benchmark_filter=Forest --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include "TreeLod/ForestInstances.h"

#include <benchmark/benchmark.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

namespace
{
    using namespace TreeLod;

    constexpr std::size_t kInstances = 1000000;
    constexpr float kHalfExtent = 5000.0f;

    /// A tree's silhouette: a crown of coverage 0.7 (a disc in the square's upper part), a trunk below.
    std::shared_ptr<const OcclusionMask> crownMask()
    {
        auto mask = std::make_shared<OcclusionMask>();
        constexpr int S = OcclusionMask::SIZE;
        for (int y = 0; y < S; ++y)
            for (int x = 0; x < S; ++x)
            {
                const float u = (float(x) + 0.5f) / S - 0.5f, v = (float(y) + 0.5f) / S;
                const bool crown = u * u / 0.09f + (v - 0.6f) * (v - 0.6f) / 0.09f < 1.0f;
                mask->coverage[std::size_t(y * S + x)] = crown ? 0.7f : (std::abs(u) < 0.04f && v < 0.4f ? 1.0f : 0.0f);
            }
        mask->finish();
        return mask;
    }

    ForestKind kind(const char* name, float height, ForestLodMode mode, std::vector<float> thresholds)
    {
        ForestKind k;
        k.occlusionMask = crownMask();
        k.occlusionHeightScales = {1.0f, 0.84f, 0.71f, 0.59f, 0.5f, 0.5f};
        k.name = name;
        k.boundsCentre = glm::vec3(0.0f, 0.5f * height, 0.0f);
        k.boundsRadius = 0.6f * height;
        k.lodMode = mode;
        k.thresholds = std::move(thresholds);
        return k;
    }

    /// The forest, built once, or null after marking the benchmark skipped with the error.
    const ForestInstances* forestOr(benchmark::State& state)
    {
        static const std::pair<ForestInstances, std::string> built = [] {
            std::pair<ForestInstances, std::string> out;
            ForestInstances& forest = out.first;
            for (const ForestKind& k :
                 {kind("oak", 18.0f, ForestLodMode::PixelCount, {1e5f, 1e4f, 1e3f}),
                  kind("pine", 25.0f, ForestLodMode::PixelCount, {5e4f, 2e3f, 200.0f}),
                  kind("birch", 12.0f, ForestLodMode::PixelCount, {2e4f, 500.0f}),
                  kind("beech", 20.0f, ForestLodMode::Distance, {2500.0f, 4e4f, 1e6f})})
                if (Result<std::uint32_t> r = forest.addKind(k); !r)
                {
                    out.second = r.error().message();
                    return out;
                }
            std::mt19937 rng(1);
            std::uniform_real_distribution<float> u(-1.0f, 1.0f);
            std::vector<ForestInstance> instances(kInstances);
            for (ForestInstance& i : instances)
            {
                // z, y, x in this order, named: the order of a call's arguments is unspecified.
                const float z = kHalfExtent * u(rng);
                const float y = 2.0f * u(rng);
                i.position = glm::vec3(kHalfExtent * u(rng), y, z);
                i.rotationY = 3.14159265f * u(rng);
                i.scale = 1.0f + 0.3f * u(rng);
                i.kind = std::uint32_t(rng() % 4);
            }
            // In the Forest's order (Forest::addInstances): blocks are compact, culling skips them.
            const std::vector<std::uint32_t> order = ForestInstances::spatialOrder(instances);
            std::vector<ForestInstance> sorted(instances.size());
            for (std::size_t i = 0; i < order.size(); ++i)
                sorted[i] = instances[order[i]];
            if (Result<std::vector<ForestHandle>> r = forest.add(sorted); !r)
                out.second = r.error().message();
            return out;
        }();
        if (built.second.empty())
            return &built.first;
        state.SkipWithError(built.second.c_str());
        return nullptr;
    }

    void BM_ForestCullAndSelect(benchmark::State& state)
    {
        const ForestInstances* forest = forestOr(state);
        if (!forest)
            return;
        const float width = 1920.0f, height = 1080.0f;
        glm::mat4 view, projection;
        if (state.range(0) == 0)
        {
            view = glm::lookAt(glm::vec3(0.0f, 2.0f, 0.0f), glm::vec3(1.0f, 1.9f, -0.6f), glm::vec3(0, 1, 0));
            projection = glm::perspective(glm::radians(60.0f), width / height, 0.1f, 5000.0f);
        }
        else
        {
            view = glm::lookAt(glm::vec3(-kHalfExtent, 1500.0f, -kHalfExtent), glm::vec3(0.0f), glm::vec3(0, 1, 0));
            projection = glm::perspective(glm::radians(60.0f), width / height, 1.0f, 20000.0f);
        }
        std::vector<CullCamera> cameras = {CullCamera::fromMatrices(view, projection, width, height)};
        if (state.range(0) == 2)
        {
            cameras.clear();
            std::mt19937 rng(2);
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            for (int c = 0; c < 64; ++c)
            {
                const float z = kHalfExtent * (2.0f * u(rng) - 1.0f);
                const float y = 2.0f + 1498.0f * u(rng) * u(rng);
                const glm::vec3 eye(kHalfExtent * (2.0f * u(rng) - 1.0f), y, z);
                const float heading = 6.2831853f * u(rng), pitch = -1.0471976f * u(rng);
                const glm::vec3 forward(std::cos(pitch) * std::sin(heading), std::sin(pitch),
                                        std::cos(pitch) * std::cos(heading));
                cameras.push_back(CullCamera::fromMatrices(
                    glm::lookAt(eye, eye + forward, glm::vec3(0, 1, 0)),
                    glm::perspective(glm::radians(60.0f), width / height, 0.1f, 5000.0f + 15000.0f * u(rng)), width,
                    height));
            }
        }
        for (CullCamera& camera : cameras)
            camera.occlusion = state.range(1) != 0;
        ForestVisibility visibility;
        for (const CullCamera& camera : cameras) // warm-up: arrays reach their size
            if (Result<void> r = forest->cull(camera, 1.0f, visibility); !r)
            {
                state.SkipWithError(r.error().message().c_str());
                return;
            }
        std::size_t next = 0;
        double visible = 0.0, occluded = 0.0;
        for (auto _ : state)
        {
            const CullCamera& camera = cameras[next++ % cameras.size()];
            Result<void> r = forest->cull(camera, 1.0f, visibility);
            benchmark::DoNotOptimize(r);
            benchmark::DoNotOptimize(visibility.getTransforms());
            benchmark::ClobberMemory();
            visible += double(visibility.getVisibleCount());
            occluded += double(visibility.getOccludedCount());
        }
        state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(forest->size()));
        state.counters["visible"] = visible / double(std::max<benchmark::IterationCount>(state.iterations(), 1));
        state.counters["occluded"] = occluded / double(std::max<benchmark::IterationCount>(state.iterations(), 1));
    }
}

BENCHMARK(BM_ForestCullAndSelect)
    ->ArgNames({"camera", "occlusion"})
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
