// treelod compare REFERENCE TEST [--json] [--heatmap OUT.png] [--ppd X]
// Prints FLIP (mean, max, median), multi-scale RMSE (ellipsoids-and-lines paper §4: bands and
// combined) and PSNR of TEST against REFERENCE. Alpha is ignored; sizes must match.
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

namespace TreeLod
{
    namespace
    {
        struct CompareOptions
        {
            std::string reference;
            std::string test;
            std::string heatmap;
            double pixelsPerDegree = 0.0;
            bool json = false;
        };

        std::string bandSize(int width, int height, std::size_t band)
        {
            // Band k is the image box-downsampled by 2^k (partial blocks rounded up).
            const long long scale = 1ll << band;
            return std::to_string((width + scale - 1) / scale) + "x" + std::to_string((height + scale - 1) / scale);
        }

        int runCompare(const CompareOptions& options)
        {
            Result<Image> reference = readImage(options.reference);
            if (!reference)
                return printError(reference.error());
            Result<Image> test = readImage(options.test);
            if (!test)
                return printError(test.error());

            auto withFiles = [&](Error error) {
                if (error.file.empty())
                    error.file = options.reference + " vs " + options.test;
                return error;
            };

            FlipOptions flipOptions;
            flipOptions.pixelsPerDegree = options.pixelsPerDegree;
            flipOptions.keepErrorMap = !options.heatmap.empty();
            Result<FlipResult> flipResult = flip(*reference, *test, flipOptions);
            if (!flipResult)
                return printError(withFiles(flipResult.error()));
            Result<MultiScaleRmseResult> rmse = multiScaleRmse(*reference, *test);
            if (!rmse)
                return printError(withFiles(rmse.error()));
            Result<double> psnrResult = psnr(*reference, *test);
            if (!psnrResult)
                return printError(withFiles(psnrResult.error()));

            if (!options.heatmap.empty())
            {
                Result<void> written = writePng(options.heatmap, flipHeatmap(*flipResult));
                if (!written)
                    return printError(written.error());
            }

            const double ppd = options.pixelsPerDegree > 0.0 ? options.pixelsPerDegree : flipDefaultPixelsPerDegree();
            const int width = reference->width, height = reference->height;
            const bool identical = std::isinf(*psnrResult);
            if (options.json)
            {
                nlohmann::json bands = nlohmann::json::array();
                for (std::size_t k = 0; k < rmse->bands.size(); ++k)
                    bands.push_back({{"size", bandSize(width, height, k)}, {"rmse", rmse->bands[k]}});
                nlohmann::json out = {
                    {"reference", options.reference},
                    {"test", options.test},
                    {"width", width},
                    {"height", height},
                    {"flip",
                     {{"mean", flipResult->mean},
                      {"max", flipResult->max},
                      {"median", flipResult->weightedMedian},
                      {"pixelsPerDegree", ppd}}},
                    {"multiScaleRmse", {{"bands", bands}, {"combined", rmse->combined}}},
                    // JSON has no infinity: identical images give "psnr": null.
                    {"psnr", identical ? nlohmann::json(nullptr) : nlohmann::json(*psnrResult)},
                    {"identical", identical}};
                if (!options.heatmap.empty())
                    out["heatmap"] = options.heatmap;
                std::printf("%s\n", out.dump(2).c_str());
            }
            else
            {
                std::printf("reference: %s (%dx%d)\n", options.reference.c_str(), width, height);
                std::printf("test:      %s\n", options.test.c_str());
                std::printf("FLIP (%.2f ppd): mean %.6f  max %.6f  median %.6f\n", ppd, flipResult->mean,
                            flipResult->max, flipResult->weightedMedian);
                std::printf("multi-scale RMSE: combined %.6f\n", rmse->combined);
                for (std::size_t k = 0; k < rmse->bands.size(); ++k)
                    std::printf("  %-11s %.6f\n", bandSize(width, height, k).c_str(), rmse->bands[k]);
                if (identical)
                    std::printf("PSNR: inf (identical)\n");
                else
                    std::printf("PSNR: %.3f dB\n", *psnrResult);
                if (!options.heatmap.empty())
                    std::printf("heatmap:   %s\n", options.heatmap.c_str());
            }
            return EXIT_OK;
        }
    }

    void addCompareCommand(CLI::App& app)
    {
        auto options = std::make_shared<CompareOptions>();
        CLI::App* command = app.add_subcommand(
            "compare", "Compare a test image with a reference: FLIP, multi-scale RMSE (per band), PSNR");
        command->add_option("reference", options->reference, "Reference image (PNG or JPEG)")
            ->required();
        command->add_option("test", options->test, "Test image, same size as the reference")->required();
        command->add_flag("--json", options->json, "Print one JSON object instead of text");
        command->add_option("--heatmap", options->heatmap, "Write the FLIP error map as a colour PNG");
        command->add_option("--ppd", options->pixelsPerDegree,
                            "FLIP pixels per degree (default: 0.7 m from a 0.7 m wide 3840-pixel monitor, 67.02)")
            ->check(CLI::Range(1e-3, 1e4));
        command->callback([options]() { setExitCode(runCompare(*options)); });
    }
}
