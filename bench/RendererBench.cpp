// CPU reference renderer and ambient occlusion on a synthetic 30k-leaf tree.
// Target: a 512 x 512 render with 4 samples per pixel in 1 s or less on 2 cores.
//   build/bin/treelod_core_bench --benchmark_filter=Render
// TREELOD_BENCH_THREADS=N limits TBB (and Embree's builder) to N threads. The CPU column is the
// process's CPU time (all threads): on a busy machine, CPU / threads estimates the idle wall time.
#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/ReferenceRenderer.h"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <memory>

using namespace TreeLod;

namespace
{
    /// splitmix64: portable, so every machine benchmarks the same tree.
    struct Random
    {
        std::uint64_t state;
        explicit Random(std::uint64_t seed) : state(seed) {}
        float next()
        {
            std::uint64_t x = (state += 0x9E3779B97F4A7C15ull);
            x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
            x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
            return float((x ^ (x >> 31)) >> 40) / 16777216.0f;
        }
        float range(float lo, float hi) { return lo + (hi - lo) * next(); }
        /// A point of [-1, 1]^3, drawn z, y, x (named: the order of a call's arguments is unspecified).
        glm::vec3 inCube()
        {
            const float z = range(-1.0f, 1.0f);
            const float y = range(-1.0f, 1.0f);
            return glm::vec3(range(-1.0f, 1.0f), y, z);
        }
    };

    /// About 11 m tall: a tapered trunk cylinder (24 sides, 12 rings) and `leafCount` leaf quads
    /// (12 x 8 cm) placed and turned at random in an ellipsoidal crown, with a 128 x 128
    /// procedural leaf texture whose alpha cuts out a serrated leaf shape (~70 % opaque).
    TreeModel benchTree(int leafCount)
    {
        TreeModel m;
        m.name = "bench";
        Material bark;
        bark.name = "bark";
        bark.baseColour = {0.32f, 0.22f, 0.14f, 1.0f};
        m.materials.push_back(bark);
        Material leaf;
        leaf.name = "leaf";
        leaf.texture = 0;
        leaf.backColour = {0.8f, 0.95f, 0.5f};
        leaf.isLeaf = true;
        leaf.doubleSided = true;
        m.materials.push_back(leaf);

        TextureImage tex;
        tex.name = "leaf";
        tex.width = tex.height = 128;
        for (int y = 0; y < 128; ++y)
            for (int x = 0; x < 128; ++x)
            {
                float u = (x + 0.5f) / 128.0f - 0.5f, v = (y + 0.5f) / 128.0f - 0.5f;
                float angle = std::atan2(v, u);
                float edge = 1.0f + 0.06f * std::sin(14.0f * angle); // serrated outline
                bool inside = (u / 0.49f) * (u / 0.49f) + (v / 0.34f) * (v / 0.34f) < edge;
                bool vein = std::abs(v) < 0.012f || std::abs(std::abs(u) * 0.6f - std::abs(v)) < 0.008f;
                tex.rgba.insert(tex.rgba.end(), {std::uint8_t(vein ? 130 : 62), std::uint8_t(vein ? 175 : 124),
                                                 std::uint8_t(vein ? 80 : 38), std::uint8_t(inside ? 255 : 0)});
            }
        m.textures.push_back(tex);

        const int sides = 24, rings = 12;
        for (int r = 0; r <= rings; ++r)
            for (int s = 0; s <= sides; ++s)
            {
                float h = 7.0f * r / rings, radius = 0.4f - 0.28f * r / rings;
                float a = 6.2831853f * s / sides;
                glm::vec3 n(std::cos(a), 0.0f, -std::sin(a));
                m.barkVertices.push_back({glm::vec3(0.0f, h, 0.0f) + radius * n, n, {float(s) / sides, float(r) / rings}});
            }
        for (int r = 0; r < rings; ++r)
            for (int s = 0; s < sides; ++s)
            {
                std::uint32_t a = r * (sides + 1) + s, b = a + 1, c = a + sides + 1, d = c + 1;
                for (std::uint32_t i : {a, b, d, a, d, c})
                    m.barkIndices.push_back(i);
                m.barkTriangleMaterial.insert(m.barkTriangleMaterial.end(), {0u, 0u});
            }

        Random rng(2024);
        m.leafVertices.reserve(std::size_t(leafCount) * 4);
        m.leafIndices.reserve(std::size_t(leafCount) * 6);
        for (int i = 0; i < leafCount; ++i)
        {
            glm::vec3 p, n;
            do
                p = rng.inCube();
            while (glm::dot(p, p) > 1.0f);
            glm::vec3 centre = glm::vec3(0.0f, 7.5f, 0.0f) + p * glm::vec3(4.0f, 3.5f, 4.0f);
            do
                n = rng.inCube();
            while (glm::dot(n, n) > 1.0f || glm::dot(n, n) < 1e-3f);
            n = glm::normalize(n);
            glm::vec3 t = glm::normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
            glm::vec3 u = t * 0.12f, v = glm::cross(n, t) * 0.08f, corner = centre - 0.5f * (u + v);
            Leaf l;
            l.firstVertex = std::uint32_t(m.leafVertices.size());
            l.vertexCount = 4;
            l.firstIndex = std::uint32_t(m.leafIndices.size());
            l.indexCount = 6;
            l.material = 1;
            m.leafVertices.push_back({corner, n, {0.0f, 1.0f}});
            m.leafVertices.push_back({corner + u, n, {1.0f, 1.0f}});
            m.leafVertices.push_back({corner + u + v, n, {1.0f, 0.0f}});
            m.leafVertices.push_back({corner + v, n, {0.0f, 0.0f}});
            for (std::uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
                m.leafIndices.push_back(l.firstVertex + k);
            m.leaves.push_back(l);
            m.updateLeafRecord(m.leaves.size() - 1);
        }
        m.updateBounds();
        return m;
    }

    const TreeModel& tree30k()
    {
        static const TreeModel model = benchTree(30000);
        return model;
    }

    std::unique_ptr<tbb::global_control> threadLimit()
    {
        const char* env = std::getenv("TREELOD_BENCH_THREADS");
        int n = env ? std::atoi(env) : 0;
        if (n <= 0)
            return nullptr;
        return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(n));
    }

    void BM_RendererBuildScene30k(benchmark::State& state)
    {
        auto limit = threadLimit();
        const TreeModel& model = tree30k();
        for (auto _ : state)
        {
            ReferenceRenderer renderer(model);
            benchmark::ClobberMemory();
        }
        state.counters["leaves"] = double(model.leaves.size());
    }
    BENCHMARK(BM_RendererBuildScene30k)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

    void BM_RendererFrame30k(benchmark::State& state)
    {
        auto limit = threadLimit();
        const TreeModel& model = tree30k();
        ReferenceRenderer renderer(model);
        // Framed by the bounding sphere at range(2) percent of the distance that just fits it.
        CameraSpec camera =
            CameraSpec::framing(model.boundsMin, model.boundsMax, 30.0f, 10.0f, float(state.range(2)) / 100.0f);
        RenderOptions options;
        options.width = options.height = int(state.range(0));
        options.samplesPerPixel = int(state.range(1));
        double coverage = 0.0;
        for (auto _ : state)
        {
            RenderImages images = renderer.render(camera, options);
            coverage = 0.0;
            for (float a : images.alpha)
                coverage += a;
            benchmark::DoNotOptimize(images.colour.pixels.data());
        }
        double rays = double(options.width) * options.height * options.samplesPerPixel;
        state.counters["coverage"] = coverage / (double(options.width) * options.height);
        state.counters["rays/s"] = benchmark::Counter(rays * state.iterations(), benchmark::Counter::kIsRate);
    }
    // Args: size, samples per pixel, camera distance in percent.
    BENCHMARK(BM_RendererFrame30k)->Args({512, 4, 100})->Args({512, 4, 60})->Args({512, 1, 100})->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

    void BM_RendererAmbientOcclusion30k(benchmark::State& state)
    {
        auto limit = threadLimit();
        const TreeModel& model = tree30k();
        AoOptions options;
        options.raysPerPoint = int(state.range(0));
        double mean = 0.0;
        for (auto _ : state)
        {
            AmbientOcclusion ao = computeAmbientOcclusion(model, options);
            mean = 0.0;
            for (float a : ao.leafVertex)
                mean += a;
            mean /= double(ao.leafVertex.size());
        }
        double rays = double(model.barkVertices.size() + model.leafVertices.size()) * options.raysPerPoint;
        state.counters["meanLeafAo"] = mean;
        state.counters["rays/s"] = benchmark::Counter(rays * state.iterations(), benchmark::Counter::kIsRate);
    }
    BENCHMARK(BM_RendererAmbientOcclusion30k)->Arg(64)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime()->Iterations(1);
}
