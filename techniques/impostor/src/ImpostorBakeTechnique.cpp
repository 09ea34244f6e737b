// The core descriptor of the one-quad impostor, bake half: ImpostorBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            ImpostorOptions options;
            Result<double> resolution =
                bakeOptionNumber(given, IMPOSTOR_CHUNK, "resolution", options.resolution, 16, 4096, label);
            Result<double> aoRays = bakeOptionNumber(given, IMPOSTOR_CHUNK, "aoRays", options.aoRays, 0, 4096, label);
            Result<double> cutoff =
                bakeOptionNumber(given, IMPOSTOR_CHUNK, "alphaCutoff", options.alphaCutoff, 1e-3, 1.0, label);
            Result<bool> compress = bakeOptionFlag(given, IMPOSTOR_CHUNK, "compress", options.compress, label);
            for (const Result<double>* r : {&resolution, &aoRays, &cutoff})
                if (!*r)
                    return r->error();
            if (!compress)
                return compress.error();
            options.resolution = std::uint32_t(resolution.value()); // the baker checks the multiple of 4
            options.aoRays = int(aoRays.value());
            options.alphaCutoff = float(cutoff.value());
            options.compress = compress.value();
            return addImpostorChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {IMPOSTOR_CHUNK,
             "one camera-facing quad with baked colour and normal textures, the speed floor (adds reference)",
             &bake,
             {{"resolution", "texels along the quad's longer side, a multiple of 4 in [16, 4096]", "256"},
              {"aoRays", "ambient occlusion rays per vertex, 0 (none) to 4096", "0"},
              {"alphaCutoff", "the quad's alpha test, in (0, 1]", "0.5"},
              {"compress", "DXT5 colour and DXT1 normal (true) or RGBA8 (false: DXT cost more than 0.005 FLIP)", "false"}}});
    }
}
