// The core descriptor of the ellipsoid tree, bake half: EllipsoidTreeBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/EllipsoidTreeBaker.h"
#include "TreeLod/EllipsoidTreeData.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            EllipsoidTreeOptions options;
            const char* chunk = ELLIPSOID_TREE_CHUNK;
            Result<double> tries = bakeOptionNumber(given, chunk, "tries", options.tries, 1, 16, label);
            Result<double> triedClusters =
                bakeOptionNumber(given, chunk, "triedClusters", options.triedClusters, 1, 4294967295.0, label);
            Result<double> seed = bakeOptionNumber(given, chunk, "seed", double(options.seed), 0, 4294967295.0, label);
            Result<double> divisor =
                bakeOptionNumber(given, chunk, "clustersDivisor", options.clustersDivisor, 2, 64, label);
            Result<double> share = bakeOptionNumber(given, chunk, "minAreaShare", options.minAreaShare, 0, 0.5, label);
            Result<double> resolution =
                bakeOptionNumber(given, chunk, "viewResolution", options.viewResolution, 16, 1024, label);
            Result<double> aoRays = bakeOptionNumber(given, chunk, "aoRays", options.aoRays, 0, 1024, label);
            Result<double> noise = bakeOptionNumber(given, chunk, "noise", options.noise ? 1 : 0, 0, 1, label);
            for (const Result<double>* r : {&tries, &triedClusters, &seed, &divisor, &share, &resolution, &aoRays, &noise})
                if (!*r)
                    return r->error();
            for (const auto& [name, value] : {std::pair<const char*, double>{"tries", tries.value()},
                                              {"triedClusters", triedClusters.value()},
                                              {"seed", seed.value()},
                                              {"clustersDivisor", divisor.value()},
                                              {"viewResolution", resolution.value()},
                                              {"aoRays", aoRays.value()},
                                              {"noise", noise.value()}})
                if (value != std::floor(value))
                    return fail(label, std::string("option '") + chunk + "." + name + "'",
                                std::to_string(value) + " is not a whole number");
            options.tries = std::uint32_t(tries.value());
            options.triedClusters = std::uint32_t(triedClusters.value());
            options.seed = std::uint64_t(seed.value());
            options.clustersDivisor = std::uint32_t(divisor.value());
            options.minAreaShare = float(share.value());
            options.viewResolution = int(resolution.value());
            options.aoRays = std::uint32_t(aoRays.value());
            options.noise = noise.value() != 0.0;
            return addEllipsoidTreeChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {ELLIPSOID_TREE_CHUNK,
             "the leaves as ellipsoids, one per leaf then EM/GMM clusters of a quarter as many per level down "
             "to one, sized by image error (adds reference)",
             &bake,
             {{"tries", "EM runs from random starts per level of at most triedClusters clusters (one above), the best by image error kept, 1 to 16", "4"},
              {"triedClusters", "levels of at most this many clusters get the tries, 1 to 4294967295", "12"},
              {"seed", "random seed of the EM starts, 0 to 4294967295", "1"},
              {"clustersDivisor", "each level has 1 / this of the previous level's clusters, 2 to 64", "4"},
              {"minAreaShare", "ellipsoids under this share of the level's largest surface area are dropped, 0 to 0.5",
               "0.01"},
              {"viewResolution", "pixels a side of the 4 views the image error is taken over, 16 to 1024", "128"},
              {"aoRays", "rays per surface point of the ellipsoids' ambient occlusion, 0 (none) to 1024", "0"},
              {"noise", "1: calibrate each level's noise (alpha holes, area, normal blend) by image error; 0: none",
               "1"}}});
    }
}
