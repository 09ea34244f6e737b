// libFuzzer target: instance files (a placement's "file", CSV, docs/scene-format.md "Instance
// files") on arbitrary bytes, through the public API: the input is written to trees.csv in a
// folder made once per process, a fixed script whose placement names that file (species oak, pine
// and birch on a 100 m heightfield) is parsed and, when it parses, its trees are placed. It must
// never crash, hang, leak or read out of bounds. A refused file is an error naming trees.csv and
// a line; an accepted one gives what the format promises: x and z on the ground, rotation
// within a turn either way, scale in (0, 1000], per-tree species of the placement's and y in
// [-1e6, 1e6] when the file has those columns, and the trees stand at their y or on the ground.
// Seeds: tests/fuzz/corpus/instances/. Run: FuzzInstanceFile -max_total_time=30 corpus/instances
#include "TreeLod/SceneScript.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace
{
    namespace fs = std::filesystem;

    const char* const SCRIPT = R"({
  "name": "instances",
  "ground": {"kind": "heightfield", "size": 100, "image": "heights.png", "heightScale": 10},
  "species": [{"name": "oak", "source": "preset:oak", "techniques": "auto"},
              {"name": "pine", "source": "preset:conifer", "techniques": "auto"},
              {"name": "birch", "source": "preset:birch", "techniques": "auto"}],
  "placements": [{"species": ["oak", "pine", "birch"], "file": "trees.csv"}],
  "camera": {"keyframes": [{"time": 0, "position": [0, 2, 60], "target": [0, 2, 0]}]},
  "resolution": [64, 64],
  "frames": 1
})";

    void require(bool condition)
    {
        if (!condition)
            std::abort();
    }

    /// The script's folder, made on first use and removed at exit; trees.csv is rewritten per input.
    struct CsvFolder
    {
        fs::path dir;
        std::string csv;

        CsvFolder()
        {
            std::string pattern = (fs::temp_directory_path() / "treelod-fuzz-instances-XXXXXX").string();
            if (!mkdtemp(pattern.data()))
                std::abort();
            dir = pattern;
            csv = (dir / "trees.csv").string();
        }

        ~CsvFolder()
        {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    };

    TreeLod::Result<TreeLod::GreyImage> greyImage(const std::string&)
    {
        TreeLod::GreyImage image;
        image.width = 2;
        image.height = 2;
        image.values = {0.0f, 0.5f, 1.0f, 0.25f};
        return image;
    }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const CsvFolder folder;
    {
        std::ofstream out(folder.csv, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
        require(bool(out));
    }
    TreeLod::Result<TreeLod::SceneScript> parsed =
        TreeLod::parseSceneScript(SCRIPT, "instances.json", folder.dir.string(), greyImage);
    if (!parsed)
    {
        require(parsed.error().file == folder.csv && parsed.error().element.rfind("line ", 0) == 0);
        return 0;
    }
    const TreeLod::SceneScript& script = parsed.value();
    require(script.placements.size() == 1);
    const TreeLod::ScenePlacement& p = script.placements[0];
    const std::size_t n = p.positions.size();
    require(n > 0 && (p.positionSpecies.empty() || p.positionSpecies.size() == n) &&
            (p.positionY.empty() || p.positionY.size() == n));
    for (std::size_t i = 0; i < n; ++i)
    {
        const glm::vec4& e = p.positions[i];
        require(std::abs(e.x) <= 50.0f && std::abs(e.y) <= 50.0f);
        require(std::abs(e.z) <= 6.2832f);
        require(e.w > 0.0f && e.w <= 1000.0f);
        require(p.positionSpecies.empty() || p.positionSpecies[i] < 3);
        require(p.positionY.empty() || std::isnan(p.positionY[i]) || std::abs(p.positionY[i]) <= 1e6f);
    }

    const std::vector<TreeLod::PlacedTree> trees = TreeLod::generatePlacements(script);
    require(trees.size() == n);
    for (std::size_t i = 0; i < n; ++i)
    {
        const TreeLod::PlacedTree& t = trees[i];
        require(t.position.x == p.positions[i].x && t.position.z == p.positions[i].y);
        require(t.rotation == p.positions[i].z && t.scale == p.positions[i].w);
        require(t.species == (p.positionSpecies.empty() ? p.species[0] : p.positionSpecies[i]));
        if (p.positionY.empty() || std::isnan(p.positionY[i]))
            require(t.position.y >= 0.0f && t.position.y <= 10.0f);
        else
            require(t.position.y == p.positionY[i]);
    }
    return 0;
}
