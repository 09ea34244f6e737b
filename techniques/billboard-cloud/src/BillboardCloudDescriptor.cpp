// The core descriptors of the billboard clouds (García et al. 2007), runtime half: chunks
// "billboard-cloud" (multi-layered indirect texturing) and "classic-billboard-cloud" (one RGBA
// texture per billboard at equal memory, the paper's Fig. 13 baseline), BillboardCloudData.h.
#include "TreeLod/BillboardCloudData.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label, bool classic)
        {
            Result<BillboardCloudData> data = decodeBillboardCloudChunk(bytes, label);
            if (!data)
                return data.error();
            const BillboardCloudData& cloud = data.value();
            const char* chunk = classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK;
            if (cloud.classic != classic)
                return fail(label, chunkElement(chunk, 0), classic ? "not a classic cloud" : "a classic cloud");
            std::string counts;
            nlohmann::json levels = nlohmann::json::array();
            for (const BillboardCloudLevel& level : cloud.levels)
            {
                counts += (counts.empty() ? "" : " / ") + std::to_string(level.billboardCount) +
                          (level.layered ? "" : " (low-res)");
                levels.push_back({{"billboards", level.billboardCount},
                                  {"layered", level.layered},
                                  {"cellSize", level.cellSize},
                                  {"lowResTexelSize", level.lowResTexelSize}});
            }
            char text[512];
            std::snprintf(text, sizeof(text),
                          "%s billboards, %zu list entries, hash atlas %ux%u, lists atlas %ux%u, leaves texture %ux%u, "
                          "low-res texture %ux%u, %llu bytes on the GPU",
                          counts.c_str(), cloud.entries.size(), cloud.hashAtlasWidth, cloud.hashAtlasHeight,
                          cloud.listsAtlasWidth, cloud.listsAtlasHeight, cloud.leavesColour.width,
                          cloud.leavesColour.height, cloud.lowRes.width, cloud.lowRes.height,
                          (unsigned long long)cloud.gpuBytes());
            ChunkSummary summary;
            summary.text = text;
            summary.json = nlohmann::json{{"levels", levels},
                                          {"listEntries", cloud.entries.size()},
                                          {"hashAtlas", {cloud.hashAtlasWidth, cloud.hashAtlasHeight}},
                                          {"listsAtlas", {cloud.listsAtlasWidth, cloud.listsAtlasHeight}},
                                          {"leavesTexture", {cloud.leavesColour.width, cloud.leavesColour.height}},
                                          {"lowResTexture", {cloud.lowRes.width, cloud.lowRes.height}},
                                          {"gpuBytes", cloud.gpuBytes()}}
                               .dump();
            return summary;
        }

        Result<ChunkSummary> inspectLayered(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            return inspect(bytes, label, false);
        }

        Result<ChunkSummary> inspectClassic(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            return inspect(bytes, label, true);
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<BillboardCloudData> decoded = decodeBillboardCloudChunk(bytes, "fuzz");
            if (!decoded)
                return;
            // What the shader does per fragment (§5): hash fetch, list walk from either end;
            // every entry and tile it reads must exist.
            const BillboardCloudSampler sampler(decoded.value());
            const std::uint32_t billboards = std::uint32_t(decoded->billboards.size());
            for (std::uint32_t b = 0; b < billboards && b < 64; ++b)
                for (float uv : {0.0f, 0.37f, 0.5f, 1.0f})
                    for (bool front : {true, false})
                        for (const BillboardCloudSampler::Fragment& f : sampler.walk(b, uv, 1.0f - uv, front))
                            if (f.entry >= decoded->entries.size() || f.tile >= decoded->tileCount())
                                __builtin_trap();
            sampler.walk(billboards, 0.5f, 0.5f, true); // out of range: no fragments, no crash
        }

        const TechniqueRegistration layered(
            {BILLBOARD_CLOUD_CHUNK,
             "billboard clouds with multi-layered indirect texturing and shader LoD (García et al. 2007)",
             BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION, &inspectLayered, &fuzz});
        const TechniqueRegistration classic(
            {CLASSIC_BILLBOARD_CLOUD_CHUNK,
             "classic billboard cloud: one RGBA texture per billboard, García et al. 2007 Fig. 13 baseline",
             BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION, &inspectClassic, &fuzz});
    }
}
