// The core descriptor of the volumetric octree tree, bake half: VolumeOctreeBaker.h. A polygonal
// tree is photographed by the reference renderer (synthesiseCaptureSet), then reconstructed; the
// options are parsed here for that bake and for one from a capture folder.
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/CaptureSet.h"
#include "TreeLod/VolumeOctreeBaker.h"
#include "TreeLod/VolumeOctreeData.h"

#include <cmath>

namespace TreeLod
{
    const std::vector<std::string>& volumeOctreeSynthesisOptions()
    {
        static const std::vector<std::string> names = {"cameras", "resolution", "samplesPerPixel"};
        return names;
    }

    Result<void> parseVolumeOctreeBakeOptions(const BakeOptions& given, VolumeOctreeOptions& options,
                                              CaptureSynthesisOptions* synthesis, const std::string& label)
    {
        const char* chunk = VOLUME_OCTREE_CHUNK;
        if (!synthesis)
            for (const std::string& name : volumeOctreeSynthesisOptions())
                if (given.count(name))
                    return fail(label, std::string("option '") + chunk + "." + name + "'",
                                "applies only to photographs synthesised from a polygonal tree; a capture "
                                "folder's cameras and images are its own");
        CaptureSynthesisOptions unused;
        CaptureSynthesisOptions& capture = synthesis ? *synthesis : unused;
        BillboardQuantisationOptions& q = options.quantisation;
        Result<double> levels =
            bakeOptionNumber(given, chunk, "levels", options.levelCount, 1, VOLUME_OCTREE_MAX_LEVELS, label);
        Result<double> tomography =
            bakeOptionNumber(given, chunk, "tomographyIterations", options.tomographyIterations, 0, 32, label);
        Result<double> cameras =
            bakeOptionNumber(given, chunk, "cameras", capture.cameraCount, 1, VOLUME_OCTREE_MAX_CAMERAS, label);
        Result<double> resolution = bakeOptionNumber(given, chunk, "resolution", capture.resolution, 16, 4096, label);
        Result<double> samples =
            bakeOptionNumber(given, chunk, "samplesPerPixel", capture.samplesPerPixel, 1, 256, label);
        Result<double> colours = bakeOptionNumber(given, chunk, "codebookSize", q.colourCodebookSize, 1, 16384, label);
        Result<double> alphas =
            bakeOptionNumber(given, chunk, "alphaCodebookSize", q.alphaCodebookSize, 1, 16384, label);
        Result<double> prune = bakeOptionNumber(given, chunk, "pruneAlpha", options.pruneAlpha, 1e-3, 1.0, label);
        Result<double> seed = bakeOptionNumber(given, chunk, "seed", double(q.seed), 0, 4294967295.0, label);
        Result<double> training = bakeOptionNumber(given, chunk, "trainingBillboards", double(q.maxTrainingVectors), 0,
                                                   4294967295.0, label);
        Result<bool> compress = bakeOptionFlag(given, chunk, "compress", options.compress, label);
        Result<bool> lab = bakeOptionFlag(given, chunk, "lab", q.space == QuantisationSpace::Lab, label);
        Result<bool> modified = bakeOptionFlag(given, chunk, "modifiedGla", q.nearestInput, label);
        for (const Result<double>* r : {&levels, &tomography, &cameras, &resolution, &samples, &colours, &alphas, &prune,
                                        &seed, &training})
            if (!*r)
                return r->error();
        for (const Result<bool>* r : {&compress, &lab, &modified})
            if (!*r)
                return r->error();
        for (const auto& [name, value] : {std::pair<const char*, double>{"levels", levels.value()},
                                          {"tomographyIterations", tomography.value()},
                                          {"cameras", cameras.value()},
                                          {"resolution", resolution.value()},
                                          {"samplesPerPixel", samples.value()},
                                          {"codebookSize", colours.value()},
                                          {"alphaCodebookSize", alphas.value()},
                                          {"seed", seed.value()},
                                          {"trainingBillboards", training.value()}})
            if (value != std::floor(value))
                return fail(label, std::string("option '") + chunk + "." + name + "'",
                            std::to_string(value) + " is not a whole number");
        options.levelCount = std::uint32_t(levels.value());
        options.tomographyIterations = std::uint32_t(tomography.value());
        capture.cameraCount = int(cameras.value());
        capture.resolution = int(resolution.value());
        capture.samplesPerPixel = int(samples.value());
        q.colourCodebookSize = std::uint32_t(colours.value());
        q.alphaCodebookSize = std::uint32_t(alphas.value());
        q.seed = std::uint64_t(seed.value());
        q.maxTrainingVectors = std::size_t(training.value());
        q.space = lab.value() ? QuantisationSpace::Lab : QuantisationSpace::Rgb;
        q.nearestInput = modified.value();
        options.pruneAlpha = float(prune.value());
        options.compress = compress.value();
        return {};
    }

    namespace
    {
        Result<void> bake(PackageWriter& writer, const TreeModel& model, const BakeOptions& given,
                          const std::string& label, const ProgressCallback& progress)
        {
            VolumeOctreeOptions options;
            CaptureSynthesisOptions capture;
            if (Result<void> parsed = parseVolumeOctreeBakeOptions(given, options, &capture, label); !parsed)
                return parsed;
            return addVolumeOctreeChunk(writer, model, capture, options, label, progress);
        }

        /// A capture folder (CaptureSet.h): the photographs' octree, without the synthesis options.
        Result<void> bakeCapture(PackageWriter& writer, const std::string& folder, const std::string& source,
                                 const BakeOptions& given, const std::string& label, const ProgressCallback& progress)
        {
            VolumeOctreeOptions options;
            if (Result<void> parsed = parseVolumeOctreeBakeOptions(given, options, nullptr, label); !parsed)
                return parsed;
            report(progress, "capture: read", 0.0f);
            Result<CaptureSet> capture = readCaptureSet(folder);
            if (!capture)
                return capture.error();
            report(progress, "capture: read", 1.0f);
            return addVolumeOctreeChunk(writer, capture.value(), source, options, label, progress);
        }

        const BakeTechniqueRegistration registration(
            {VOLUME_OCTREE_CHUNK,
             "the tree photographed from N cameras by the reference renderer, then an octree of per-camera 4x4 "
             "billboards reconstructed from the mattes, pruned and VQ-compressed (adds reference)",
             &bake,
             {{"levels", "octree levels, 1 to 10: the finest has 2^(levels-1) cells a side", "7"},
              {"tomographyIterations", "multiplicative updates of the cells' opacities, 0 to 32", "4"},
              {"cameras", "synthetic photographs on rings around the tree, 1 to 64 (not for a capture folder)", "24"},
              {"resolution", "pixels a side of every photograph, 16 to 4096 (not for a capture folder)", "256"},
              {"samplesPerPixel",
               "reference samples per photograph pixel, a square in [1, 256] (not for a capture folder)", "4"},
              {"codebookSize", "colour codewords of the vector quantisation, 1 to 16384", "512"},
              {"alphaCodebookSize", "alpha codewords, 1 to 16384", "512"},
              {"pruneAlpha", "accumulated alpha in front that hides a billboard, (0, 1]", "0.95"},
              {"seed", "seed of the codebook's initial codewords, 0 to 4294967295", "1"},
              {"trainingBillboards",
               "billboards the codebooks are trained on (an even stride through all; every billboard still gets its "
               "nearest codeword), 0 (all) to 4294967295",
               std::to_string(BillboardQuantisationOptions{}.maxTrainingVectors)},
              {"compress", "DXT5 codebook atlas (true) or RGBA8", "true"},
              {"lab", "quantise colour in CIELab (true) or RGB", "true"},
              {"modifiedGla", "replace each codeword by its nearest training billboard (true) or keep the mean",
               "true"}},
             &bakeCapture});
    }
}
