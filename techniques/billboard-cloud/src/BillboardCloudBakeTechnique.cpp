// The core descriptors of the billboard clouds (García et al. 2007), bake half:
// BillboardCloudBaker.h. Two techniques: the multi-layered cloud and the classic cloud it is
// measured against at equal memory (Fig. 13).
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudData.h"

namespace TreeLod
{
    namespace
    {
        /// The options both clouds read, into `options`.
        Result<void> readOptions(const BakeOptions& given, const char* technique, const std::string& label,
                                 BillboardCloudOptions& options)
        {
            Result<double> billboards =
                bakeOptionNumber(given, technique, "billboardCount", options.billboardCount, 0, 65535, label);
            Result<double> listFactor =
                bakeOptionNumber(given, technique, "listFactor", options.listFactor, 0.0, 64.0, label);
            Result<double> aoRays = bakeOptionNumber(given, technique, "aoRays", options.aoRays, 0, 4096, label);
            Result<double> tileSize = bakeOptionNumber(given, technique, "tileSize", options.tileSize, 8, 1024, label);
            Result<double> maxTexels = bakeOptionNumber(given, technique, "maxLeavesTexels", double(options.maxLeavesTexels),
                                                        0, double(1u << 28), label);
            Result<double> planeError =
                bakeOptionNumber(given, technique, "maxPlaneError", options.maxPlaneError, 0.0, 1.0, label);
            Result<double> tries = bakeOptionNumber(given, technique, "clusteringTries", options.clusteringTries, 1,
                                                    CLUSTERING_TRIES_MAX, label);
            Result<double> areaGrowth = bakeOptionNumber(given, technique, "clusteringAreaGrowth",
                                                         options.clusteringAreaGrowth, 0.0, 100.0, label);
            Result<double> lowResRatio = bakeOptionNumber(given, technique, "lowResLeafRatio", options.lowResLeafRatio,
                                                          0.05, 16.0, label);
            Result<bool> compress = bakeOptionFlag(given, technique, "compress", options.compress, label);
            for (const Result<double>* r : {&billboards, &listFactor, &aoRays, &tileSize, &maxTexels, &planeError, &tries, &areaGrowth,
                                       &lowResRatio})
                if (!*r)
                    return r->error();
            if (!compress)
                return compress.error();
            options.billboardCount = std::uint32_t(billboards.value());
            options.listFactor = float(listFactor.value());
            options.aoRays = int(aoRays.value());
            options.tileSize = std::uint32_t(tileSize.value()); // a power of two: checked by the baker
            options.maxLeavesTexels = std::uint64_t(maxTexels.value());
            options.maxPlaneError = float(planeError.value());
            options.clusteringTries = std::uint32_t(tries.value());
            options.clusteringAreaGrowth = float(areaGrowth.value());
            options.lowResLeafRatio = float(lowResRatio.value());
            options.compress = compress.value();
            return {};
        }

        Result<void> bakeLayered(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                                 const std::string& label, const ProgressCallback& progress)
        {
            BillboardCloudOptions options;
            if (Result<void> read = readOptions(given, BILLBOARD_CLOUD_CHUNK, label, options); !read)
                return read;
            return addBillboardCloudChunk(writer, model, options, label, progress);
        }

        Result<void> bakeClassic(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                                 const std::string& label, const ProgressCallback& progress)
        {
            ClassicBillboardCloudOptions options;
            if (Result<void> read = readOptions(given, CLASSIC_BILLBOARD_CLOUD_CHUNK, label, options.cloud); !read)
                return read;
            Result<double> memory = bakeOptionNumber(given, CLASSIC_BILLBOARD_CLOUD_CHUNK, "memoryBytes",
                                                     double(options.memoryBytes), 0.0, 4294967295.0, label);
            if (!memory)
                return memory.error();
            options.memoryBytes = std::uint64_t(memory.value());
            return addClassicBillboardCloudChunk(writer, model, options, label, progress);
        }

        std::vector<BakeOptionInfo> cloudOptions()
        {
            return {{"billboardCount", "billboards of the finest cloud, 0 (from the leaf count) to 65535", "0"},
                    {"listFactor", "shader LoD: list entries per pixel of projected cell diagonal, 0 to 64", "8"},
                    {"aoRays", "ambient occlusion rays per leaf vertex, 0 to 4096", "32"},
                    {"tileSize", "Leaves Texture tile edge in texels, a power of two in 8..1024", "64"},
                    {"maxLeavesTexels",
                     "Leaves Texture budget in texels, 0 (none) to 2^28: the tile edge halves to fit, not below 16",
                     "2097152"},
                    {"maxPlaneError",
                     "plane-fitting bound: largest leaf vertex distance from its billboard over the tree's "
                     "box diagonal, 0 to 1",
                     "0.02"},
                    {"clusteringTries",
                     "clusterings tried per level, 1 to 6, the one kept judged by image error from around and above",
                     "6"},
                    {"clusteringAreaGrowth",
                     "largest growth of billboard area (memory) a judged clustering may take over the default "
                     "weights', 0 (no bound) to 100",
                     "0.05"},
                    {"lowResLeafRatio",
                     "low-res texel edge of the finest level in median leaf lengths (coarser levels 2x, 4x), 0.05 to 16",
                     "0.75"},
                    {"compress", "DXT-compressed textures (true) or RGBA8 (false)", "true"}};
        }

        const BakeTechniqueRegistration layered(
            {BILLBOARD_CLOUD_CHUNK,
             "billboard cloud, multi-layered indirect texturing, García et al. 2007 (adds reference)", &bakeLayered,
             cloudOptions()});
        std::vector<BakeOptionInfo> classicOptions()
        {
            std::vector<BakeOptionInfo> options = cloudOptions();
            options.push_back({"memoryBytes",
                               "GPU bytes of the billboard textures, 0 (those of the multi-layered cloud with the same "
                               "options) to 4294967295",
                               "0"});
            return options;
        }

        const BakeTechniqueRegistration classic(
            {CLASSIC_BILLBOARD_CLOUD_CHUNK,
             "classic billboard cloud at equal memory, García et al. 2007 Fig. 13 (adds reference)", &bakeClassic,
             classicOptions()});
    }
}
