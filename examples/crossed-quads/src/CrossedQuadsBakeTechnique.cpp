// The core descriptor of the crossed quads, bake half: CrossedQuadsBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/CrossedQuadsBaker.h"
#include "TreeLod/CrossedQuadsData.h"

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            CrossedQuadsOptions options;
            Result<double> resolution =
                bakeOptionNumber(given, CROSSED_QUADS_CHUNK, "resolution", options.resolution, 16, 4096, label);
            Result<double> cutoff =
                bakeOptionNumber(given, CROSSED_QUADS_CHUNK, "alphaCutoff", options.alphaCutoff, 1e-3, 1.0, label);
            Result<bool> compress = bakeOptionFlag(given, CROSSED_QUADS_CHUNK, "compress", options.compress, label);
            if (!resolution)
                return resolution.error();
            if (!cutoff)
                return cutoff.error();
            if (!compress)
                return compress.error();
            options.resolution = std::uint32_t(resolution.value()); // the baker checks the multiple of 4
            options.alphaCutoff = float(cutoff.value());
            options.compress = compress.value();
            return addCrossedQuadsChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {CROSSED_QUADS_CHUNK,
             "two or three textured vertical quads crossing on the trunk axis, an example (adds reference)", &bake,
             {{"resolution", "texels along each quad's longer side, a multiple of 4 in [16, 4096]", "256"},
              {"alphaCutoff", "the quads' alpha test, in (0, 1]", "0.5"},
              {"compress", "DXT5 (true) or RGBA8 (false)", "true"}}});
    }
}
