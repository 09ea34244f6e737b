// The core descriptor of the ellipsoid tree's lines, bake half: EllipsoidLineBaker.h. The
// "ellipsoids" technique writes the same chunk with its default options; this one bakes the lines
// alone (every registered descriptor has a baker of its name, TechniqueDescriptor.h).
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/EllipsoidLineBaker.h"
#include "TreeLod/EllipsoidLineData.h"

#include <cmath>

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            EllipsoidLineOptions options;
            const char* chunk = ELLIPSOID_LINES_CHUNK;
            Result<double> candidates = bakeOptionNumber(given, chunk, "candidates", options.candidates, 1, 64, label);
            Result<double> seed = bakeOptionNumber(given, chunk, "seed", double(options.seed), 0, 4294967295.0, label);
            Result<double> divisor = bakeOptionNumber(given, chunk, "linesDivisor", options.linesDivisor, 2, 64, label);
            Result<double> resolution =
                bakeOptionNumber(given, chunk, "viewResolution", options.viewResolution, 16, 1024, label);
            for (const Result<double>* r : {&candidates, &seed, &divisor, &resolution})
                if (!*r)
                    return r->error();
            for (const auto& [name, value] : {std::pair<const char*, double>{"candidates", candidates.value()},
                                              {"seed", seed.value()},
                                              {"linesDivisor", divisor.value()},
                                              {"viewResolution", resolution.value()}})
                if (value != std::floor(value))
                    return fail(label, std::string("option '") + chunk + "." + name + "'",
                                std::to_string(value) + " is not a whole number");
            options.candidates = std::uint32_t(candidates.value());
            options.seed = std::uint64_t(seed.value());
            options.linesDivisor = std::uint32_t(divisor.value());
            options.viewResolution = int(resolution.value());
            return addEllipsoidLineChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {ELLIPSOID_LINES_CHUNK,
             "the branches as lines, one per skeleton segment (extracted from the bark when the model has no "
             "skeleton), merged by image error down to one, a level per quarter (adds reference; no chunk without "
             "bark; also baked by 'ellipsoids')",
             &bake,
             {{"candidates", "mergeable pairs drawn per merge, the least image error applied, 1 to 64", "8"},
              {"seed", "random seed of the draws, 0 to 4294967295", "1"},
              {"linesDivisor", "each level has 1 / this of the previous level's lines, 2 to 64", "4"},
              {"viewResolution",
               "pixels a side of the 4 views the image error is taken over, a power of two from 16 to 1024", "128"}}});
    }
}
