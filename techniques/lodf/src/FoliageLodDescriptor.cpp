// The core descriptor of LoDF (Rebollo et al. 2006), runtime half: chunk "lodf" (FoliageLodData.h).
#include "TreeLod/FoliageLodData.h"
#include "TreeLod/FoliageLodState.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

namespace TreeLod
{
    namespace
    {
        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            Result<FoliageLodData> data = decodeFoliageLodChunk(bytes, label);
            if (!data)
                return data.error();
            const FoliageLodData& d = data.value();
            ChunkSummary summary;
            summary.text = std::to_string(d.maxLeafCount()) + " leaves down to " + std::to_string(d.minLeafCount()) +
                           " (" + std::to_string(d.clusters.size()) + " clusters), " +
                           std::to_string(d.entries.size()) + " stored leaves (2L - clusters), " +
                           std::to_string(d.paperWords()) + " words as Rebollo et al. 2006 count them (eq. 9: " +
                           std::to_string(d.paperEq9Words()) + "), " + std::to_string(d.byteSize()) + " bytes";
            summary.json = nlohmann::json{{"leaves", d.maxLeafCount()},
                                          {"coarsestLeaves", d.minLeafCount()},
                                          {"clusters", d.clusters.size()},
                                          {"storedLeaves", d.entries.size()},
                                          {"collapses", d.changedGroup.size()},
                                          {"paperWords", d.paperWords()},
                                          {"eq9Words", d.paperEq9Words()},
                                          {"bytes", d.byteSize()}}
                               .dump();
            return summary;
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<FoliageLodData> decoded = decodeFoliageLodChunk(bytes, "fuzz");
            if (!decoded)
                return;
            FoliageLodState state(decoded.value());
            const std::uint32_t lo = decoded->minLeafCount(), hi = decoded->maxLeafCount();
            for (std::uint32_t target : {lo, (lo + hi) / 2, hi + 1, 0u})
            {
                state.setLeafCount(target);
                for (std::uint32_t c : state.changedClusters())
                {
                    // A region of exactly slotCount: ASan reports any write past it.
                    std::vector<std::uint32_t> region(decoded->clusters[c].slotCount);
                    if (!region.empty() && state.writeCluster(c, region.data()) > region.size())
                        __builtin_trap();
                }
            }
        }

        const TechniqueRegistration registration({FOLIAGE_LOD_CHUNK,
                                                  "LoDF continuous foliage by leaf collapse (Rebollo et al. 2006)",
                                                  FOLIAGE_LOD_CHUNK_FORMAT_VERSION, &inspect, &fuzz});
    }
}
