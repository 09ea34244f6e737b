// The core descriptor of the octahedral impostor, bake half: OctahedralImpostorBaker.h.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/OctahedralImpostorBaker.h"
#include "TreeLod/OctahedralImpostorData.h"

namespace TreeLod
{
    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            OctahedralImpostorOptions options;
            const char* chunk = OCTAHEDRAL_IMPOSTOR_CHUNK;
            Result<double> frames = bakeOptionNumber(given, chunk, "framesPerSide", options.framesPerSide, 2, 32, label);
            Result<double> resolution =
                bakeOptionNumber(given, chunk, "frameResolution", options.frameResolution, 8, 1024, label);
            Result<double> samples =
                bakeOptionNumber(given, chunk, "samplesPerPixel", options.samplesPerPixel, 1, 256, label);
            Result<double> aoRays = bakeOptionNumber(given, chunk, "aoRays", options.aoRays, 0, 4096, label);
            Result<double> cutoff = bakeOptionNumber(given, chunk, "alphaCutoff", options.alphaCutoff, 1e-3, 1.0, label);
            Result<bool> compress = bakeOptionFlag(given, chunk, "compress", options.compress, label);
            for (const Result<double>* r : {&frames, &resolution, &samples, &aoRays, &cutoff})
                if (!*r)
                    return r->error();
            if (!compress)
                return compress.error();
            options.framesPerSide = std::uint32_t(frames.value());
            options.frameResolution = std::uint32_t(resolution.value()); // the baker checks the multiple of 4
            options.samplesPerPixel = int(samples.value());                // and the square
            options.aoRays = int(aoRays.value());
            options.alphaCutoff = float(cutoff.value());
            options.compress = compress.value();
            return addOctahedralImpostorChunk(writer, model, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {OCTAHEDRAL_IMPOSTOR_CHUNK,
             "the tree baked from N x N directions over the upper hemisphere, the three nearest views blended on "
             "one quad (adds reference)",
             &bake,
             {{"framesPerSide", "views a side of the hemi-octahedral grid, 2 to 32", "8"},
              {"frameResolution", "texels a side of one view, a multiple of 4 in [8, 1024]", "64"},
              {"samplesPerPixel", "reference samples per texel, a square in [1, 256]", "9"},
              {"aoRays", "ambient occlusion rays per vertex, 0 (none) to 4096", "0"},
              {"alphaCutoff", "the quad's alpha test, in (0, 1]", "0.5"},
              {"compress", "DXT5 colour and normal (true) or RGBA8 (false)", "true"}}});
    }
}
