// glTF import + leaf extraction of a 200k-leaf tree. Target: 2 s or less.
// The .glb files are built once per run in the system temp directory:
//   synthetic: 200,000 leaf quads (4 own vertices each, scattered in a crown) + a small
//              trunk cylinder, written by encodeGlb;
//   generated: `treelod generate` oak with 200,000 leaves, written by writeGlb.
// The timed part is importGltf: read, parse, accessors, transforms, leaf components.
// Run: build/bin/treelod_core_bench --benchmark_filter=Import
#include "TreeLod/GltfExporter.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/TreeGenerator.h"
#include "TestTrees.h"

#include <benchmark/benchmark.h>
#include <glm/gtc/constants.hpp>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

namespace
{
    using namespace TreeLod;

    constexpr std::uint32_t kLeaves = 200000;

    TreeModel syntheticTree()
    {
        TreeModel model;
        Material bark;
        bark.name = "Bark";
        model.materials = {bark, TreeLod::test::leafMaterial("Leaf")};

        // Trunk: 16 sides x 8 rings, 0.3 m radius, 4 m tall.
        const int sides = 16, rings = 8;
        for (int r = 0; r <= rings; ++r)
            for (int s = 0; s < sides; ++s)
            {
                float a = glm::two_pi<float>() * float(s) / float(sides);
                Vertex v;
                v.normal = glm::vec3(std::cos(a), 0.0f, std::sin(a));
                v.position = glm::vec3(0.3f * v.normal.x, 4.0f * float(r) / float(rings), 0.3f * v.normal.z);
                v.uv = glm::vec2(float(s) / float(sides), float(r) / float(rings));
                model.barkVertices.push_back(v);
            }
        for (int r = 0; r < rings; ++r)
            for (int s = 0; s < sides; ++s)
            {
                std::uint32_t a = std::uint32_t(r * sides + s), b = std::uint32_t(r * sides + (s + 1) % sides);
                std::uint32_t c = a + sides, d = b + sides;
                model.barkIndices.insert(model.barkIndices.end(), {a, c, b, b, c, d});
                model.barkTriangleMaterial.insert(model.barkTriangleMaterial.end(), {0u, 0u});
            }

        // Leaves: 5 cm quads at random places and orientations in a 3 m crown at 6 m.
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
        model.leafVertices.reserve(4 * kLeaves);
        model.leafIndices.reserve(6 * kLeaves);
        // z, y, x in this order, named: the order of a call's arguments is unspecified.
        const auto draw = [&] {
            const float z = unit(rng);
            const float y = unit(rng);
            return glm::vec3(unit(rng), y, z);
        };
        for (std::uint32_t i = 0; i < kLeaves; ++i)
        {
            const glm::vec3 c = glm::vec3(0.0f, 6.0f, 0.0f) + 3.0f * draw();
            glm::vec3 n = glm::normalize(draw() + glm::vec3(0.0f, 0.01f, 0.0f));
            glm::vec3 u = glm::normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
            glm::vec3 v = glm::cross(n, u);
            u *= 0.025f;
            v *= 0.025f;
            TreeLod::test::addQuadLeaf(model, c, u, v, n, 1);
        }
        model.updateBounds();
        return model;
    }

    /// Path of the benchmark's .glb, built on first use; "" (and the error) on failure.
    const std::string& benchFile(bool generated, std::string& error)
    {
        static std::string paths[2];
        static std::string errors[2];
        static bool built[2] = {false, false};
        const int k = generated ? 1 : 0;
        if (!built[k])
        {
            built[k] = true;
            std::string path = (std::filesystem::temp_directory_path() /
                                (generated ? "treelod-bench-oak-200k.glb" : "treelod-bench-synthetic-200k.glb"))
                                   .string();
            Result<void> written = Error{};
            if (generated)
            {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.leafCount = kLeaves;
                auto tree = generateTree(options);
                written = tree ? writeGlb(*tree, path) : Result<void>(tree.error());
            }
            else
                written = writeGlb(syntheticTree(), path);
            if (written)
                paths[k] = path;
            else
                errors[k] = written.error().message();
        }
        error = errors[k];
        return paths[k];
    }

    void runImport(benchmark::State& state, bool generated)
    {
        std::string error;
        const std::string& path = benchFile(generated, error);
        if (path.empty())
        {
            state.SkipWithError(("cannot build the input: " + error).c_str());
            return;
        }
        std::size_t leaves = 0, vertices = 0;
        for (auto _ : state)
        {
            auto model = importGltf(path);
            if (!model)
            {
                state.SkipWithError(model.error().message().c_str());
                return;
            }
            leaves = model->leaves.size();
            vertices = model->leafVertices.size() + model->barkVertices.size();
            benchmark::DoNotOptimize(model->leaves.data());
        }
        state.counters["leaves"] = double(leaves);
        state.counters["vertices"] = double(vertices);
        std::error_code ec;
        state.counters["MB"] = double(std::filesystem::file_size(path, ec)) / 1e6;
    }

    void BM_ImportGltfSynthetic200kLeaves(benchmark::State& state) { runImport(state, false); }
    void BM_ImportGltfGeneratedOak200kLeaves(benchmark::State& state) { runImport(state, true); }
}

BENCHMARK(BM_ImportGltfSynthetic200kLeaves)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_ImportGltfGeneratedOak200kLeaves)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
