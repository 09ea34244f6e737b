// The core descriptor of the volumetric octree tree, runtime half: chunk "volume-octree"
// (VolumeOctreeData.h).
#include "TreeLod/TechniqueDescriptor.h"
#include "TreeLod/VolumeOctreeData.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<VolumeOctreeData> data = decodeVolumeOctreeChunk(bytes, label);
            if (!data)
                return data.error();
            const VolumeOctreeData& d = data.value();
            nlohmann::json levels = nlohmann::json::array();
            std::string perLevel;
            for (std::uint32_t l = 0; l < d.levelCount; ++l)
            {
                const std::uint64_t billboards = d.billboardCount(l);
                const std::uint64_t slots = std::uint64_t(d.levelCellCounts[l]) * d.cameraCount();
                levels.push_back({{"cells", d.levelCellCounts[l]}, {"billboards", billboards}, {"slots", slots}});
                char line[96];
                std::snprintf(line, sizeof(line), "%s%u: %u cells, %llu billboards", l ? "; " : "", l,
                              d.levelCellCounts[l], (unsigned long long)billboards);
                perLevel += line;
            }
            char text[320];
            std::snprintf(text, sizeof(text),
                          "%u levels, %u cameras, root cube %.3f m, codebook %u colour / %u alpha (atlas %ux%u %s), "
                          "%llu bytes on the GPU; ",
                          d.levelCount, d.cameraCount(), d.size, d.colourCodewords, d.alphaCodewords, d.atlas.width,
                          d.atlas.height, isBlockCompressed(d.atlas.format) ? "DXT5" : "RGBA8",
                          (unsigned long long)d.gpuBytes());
            ChunkSummary summary;
            summary.text = text + perLevel;
            summary.json = nlohmann::json{{"levelCount", d.levelCount},
                                          {"cameraCount", d.cameraCount()},
                                          {"size", d.size},
                                          {"colourCodewords", d.colourCodewords},
                                          {"alphaCodewords", d.alphaCodewords},
                                          {"compressed", isBlockCompressed(d.atlas.format)},
                                          {"atlasBytes", d.atlas.data.size()},
                                          {"gpuBytes", d.gpuBytes()},
                                          {"levels", levels}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<VolumeOctreeData> decoded = decodeVolumeOctreeChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What the renderer reads: every slot's blocks inside the atlas, every cell's level.
            const VolumeOctreeData& d = decoded.value();
            const std::uint64_t blocks = std::uint64_t(d.atlas.width / 4) * (d.atlas.height / 4);
            for (const VolumeOctreeSlot& s : d.slots)
                if (!s.pruned() && (s.colour >= blocks || s.alpha >= blocks))
                    __builtin_trap();
            if (d.firstCell(d.levelCount) != d.cells.size())
                __builtin_trap();
        }

        const TechniqueRegistration registration(
            {VOLUME_OCTREE_CHUNK,
             "an octree of per-camera 4x4 billboards reconstructed from matted images, VQ-compressed (Linz et al. 2006)",
             VOLUME_OCTREE_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
