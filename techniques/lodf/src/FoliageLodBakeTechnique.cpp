// The core descriptor of LoDF (Rebollo et al. 2006), bake half: FoliageLodBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodData.h"

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            FoliageLodOptions options;
            Result<double> clusterSize =
                bakeOptionNumber(given, FOLIAGE_LOD_CHUNK, "clusterSize", options.clusterSize, 1, 4096, label);
            if (!clusterSize)
                return clusterSize.error();
            Result<double> costBands =
                bakeOptionNumber(given, FOLIAGE_LOD_CHUNK, "costBands", options.costBands, 0, 64, label);
            if (!costBands)
                return costBands.error();
            Result<bool> crossed = bakeOptionFlag(given, FOLIAGE_LOD_CHUNK, "crossedLeaves", options.crossedLeaves, label);
            if (!crossed)
                return crossed.error();
            options.clusterSize = std::uint32_t(clusterSize.value());
            options.costBands = std::uint32_t(costBands.value());
            options.crossedLeaves = crossed.value();
            return addFoliageLodChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {FOLIAGE_LOD_CHUNK,
             "LoDF continuous foliage by leaf collapse, Rebollo et al. 2006 (adds reference)",
             &bake,
             {{"clusterSize", "leaves per independent cluster, 1 to 4096", "64"},
              {"costBands", "bands of Changed_group, 0 (the paper's global order) to 64", "4"},
              {"crossedLeaves", "quads through one centre collapse part with part (true) or as flat leaves (false)",
               "true"}}});
    }
}
