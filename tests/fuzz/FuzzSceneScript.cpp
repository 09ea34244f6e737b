// libFuzzer target: parseSceneScript on arbitrary bytes (JSON with comments), then, for a script it
// accepts, what a program reading one does next: generatePlacements (as written, and for the
// first entry of a "counts" sweep), cameraAt at and between the keyframes and outside them,
// frameTime, sceneLighting. It must never crash, hang, leak or read out of bounds, and what it
// accepts must keep SceneScript.h's promises: as many trees as the placements (or the sweep)
// ask for, each of a species of the script, on the ground square, with a finite height and
// rotation and a scale > 0; a finite camera that sits on the first and last keyframes at their
// times; a sun above the horizon. The parser bounds a scene at 10,000,000 trees (SceneScript.h);
// above 20,000 the harness places a counts sweep of 20,000 (TREE_BUDGET) to keep inputs fast.
//
// Files: species sources and instance files resolve against
// <tmp>/treelod-fuzz-scene-XXXXXX/samples/scenes, made once per process, whose ../../media holds
// the assets the shipped scenes name (empty files: the parser only checks that they exist) and
// which holds trees.csv (oak and pine trees). The heightfield reader returns the same 3 x 2
// image for any path.
// Seeds: tests/fuzz/corpus/scene/. Run: FuzzSceneScript -max_total_time=30 corpus/scene
#include "TreeLod/SceneScript.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace
{
    namespace fs = std::filesystem;

    constexpr std::uint32_t TREE_BUDGET = 20000;

    void require(bool condition)
    {
        if (!condition)
            std::abort();
    }

    bool finite(const glm::vec3& v)
    {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    }

    void writeFile(const fs::path& path, const std::string& text)
    {
        fs::create_directories(path.parent_path());
        std::ofstream(path, std::ios::binary) << text;
    }

    /// The scripts' folder and the files around it, made on first use, removed at exit.
    struct SceneFolder
    {
        fs::path root;
        std::string scenes;

        SceneFolder()
        {
            std::string pattern = (fs::temp_directory_path() / "treelod-fuzz-scene-XXXXXX").string();
            if (!mkdtemp(pattern.data()))
                std::abort();
            root = pattern;
            for (const char* asset : {"oak.glb", "conifer.glb", "birch.glb", "third-party/ez-tree-pine.glb",
                                      "third-party/ez-tree-aspen.glb", "third-party/ez-tree-oak.glb",
                                      "third-party/ez-tree-ash.glb"})
                writeFile(root / "media" / asset, "");
            scenes = (root / "samples" / "scenes").string();
            writeFile(fs::path(scenes) / "trees.csv", "x,z,species,rotation,scale\n1,2,oak,90,1.1\n-3,4,pine,0,0.9\n");
        }

        ~SceneFolder()
        {
            std::error_code ec;
            fs::remove_all(root, ec);
        }
    };

    const std::string& sceneDir()
    {
        static const SceneFolder folder;
        return folder.scenes;
    }

    TreeLod::Result<TreeLod::GreyImage> greyImage(const std::string&)
    {
        TreeLod::GreyImage image;
        image.width = 3;
        image.height = 2;
        image.values = {0.0f, 0.5f, 1.0f, 0.25f, 0.75f, 0.125f};
        return image;
    }

    void checkTrees(const TreeLod::SceneScript& script, const std::vector<TreeLod::PlacedTree>& trees)
    {
        // Areas lie on the ground; a disc's edge may round a float's step beyond it.
        const float half = 0.5f * script.ground.size * 1.0001f;
        for (const TreeLod::PlacedTree& t : trees)
        {
            require(t.species < script.species.size());
            require(finite(t.position) && std::abs(t.position.x) <= half && std::abs(t.position.z) <= half);
            require(std::isfinite(t.rotation));
            require(std::isfinite(t.scale) && t.scale > 0.0f);
        }
    }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    TreeLod::Result<TreeLod::SceneScript> parsed = TreeLod::parseSceneScript(text, "fuzz.json", sceneDir(), greyImage);
    if (!parsed)
        return 0;
    const TreeLod::SceneScript& script = parsed.value();

    std::uint64_t total = 0;
    for (const TreeLod::ScenePlacement& p : script.placements)
        total += p.random ? p.count : p.positions.size();
    // The parser's bound keeps a scene under a GB, but 10 M trees take 10 s under ASan: above
    // TREE_BUDGET the script is placed as a counts sweep of TREE_BUDGET trees (the same sampling,
    // each placement its share), so an input costs milliseconds.
    TreeLod::PlacementOptions options;
    if (total > TREE_BUDGET)
        options.totalCount = TREE_BUDGET;
    std::vector<TreeLod::PlacedTree> trees = TreeLod::generatePlacements(script, options);
    require(trees.size() == (options.totalCount ? options.totalCount : total));
    checkTrees(script, trees);
    if (!script.counts.empty())
    {
        options.totalCount = std::min(script.counts.front(), TREE_BUDGET);
        trees = TreeLod::generatePlacements(script, options);
        require(trees.size() == options.totalCount);
        checkTrees(script, trees);
    }

    const std::vector<TreeLod::SceneKeyframe>& keys = script.camera.keyframes;
    require(!keys.empty());
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
        for (double s : {0.0, 0.25, 0.5, 0.999})
        {
            const double time =
                i + 1 < keys.size() ? keys[i].time + s * (keys[i + 1].time - keys[i].time) : keys[i].time;
            const TreeLod::CameraSpec camera = TreeLod::cameraAt(script, time);
            require(finite(camera.position) && finite(camera.target));
        }
    }
    const TreeLod::CameraSpec first = TreeLod::cameraAt(script, keys.front().time - 1.0);
    const TreeLod::CameraSpec last = TreeLod::cameraAt(script, keys.back().time + 1.0);
    require(first.position == keys.front().position && first.target == keys.front().target);
    require(last.position == keys.back().position && last.target == keys.back().target);
    for (std::uint32_t frame : {0u, script.frames / 2, script.frames - 1})
    {
        // Both ends included, up to the rounding of first + (last - first) * frame / (n - 1).
        const double time = TreeLod::frameTime(script, frame);
        const double slack = 1e-12 * (std::abs(keys.front().time) + std::abs(keys.back().time));
        require(time >= keys.front().time - slack && time <= keys.back().time + slack);
    }
    const TreeLod::LightingSpec light = TreeLod::sceneLighting(script);
    require(finite(light.sunDirection) && light.sunDirection.y > 0.0f);
    return 0;
}
