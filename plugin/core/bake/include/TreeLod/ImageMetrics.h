// ImageMetrics: how different a test image is from a reference image.
//
// All metrics take display-encoded (sRGB) images with values in [0, 1] and compare
// RGB only: alpha is ignored (composite onto a background first if coverage matters).
// Both images must have the same, non-zero size; otherwise the Error names both sizes.
// Results are deterministic regardless of the number of threads.
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/Result.h"

#include <memory>
#include <vector>

namespace TreeLod
{
    /// Multi-scale RMSE (ellipsoids-and-lines paper §4): the RMSE of the difference image at full
    /// resolution and at every halved resolution down to 1x1, found in one pass along a
    /// Z-order curve.
    struct MultiScaleRmseResult
    {
        /// bands[0] = finest (full resolution), then each halved resolution down to 1x1:
        /// log2(n) + 1 entries for an image whose larger side pads to n = 2^k.
        /// Band k is the RMSE (over RGB, in [0, 1]) of the per-pixel difference after
        /// box-downsampling both images by 2^k (averaging aligned 2^k x 2^k blocks).
        std::vector<double> bands;
        /// Mean of bands (documented combination; in [0, 1]).
        double combined = 0.0;
    };

    /// Non-square or non-power-of-two images are padded (conceptually) to the next
    /// power-of-two square with zero difference; each band's squared error is divided by
    /// the number of real pixels that band's blocks cover, i.e. a block mean is the sum
    /// of real differences over the count of real pixels in it.
    Result<MultiScaleRmseResult> multiScaleRmse(const Image& reference, const Image& test);

    /// Options for FLIP (Andersson et al., HPG 2020), LDR version.
    struct FlipOptions
    {
        /// Pixels per degree of visual angle. 0 = the paper's default: 0.7 m viewing
        /// distance, 0.7 m wide 3840-pixel monitor (about 67.0 ppd).
        double pixelsPerDegree = 0.0;
        /// Keep the per-pixel error map in FlipResult::errorMap.
        bool keepErrorMap = false;
    };

    struct FlipResult
    {
        double mean = 0.0;           ///< mean per-pixel error, in [0, 1]
        double max = 0.0;            ///< largest per-pixel error, in [0, 1]
        double weightedMedian = 0.0; ///< plain median of the per-pixel errors, in [0, 1]
        std::vector<float> errorMap; ///< width * height, row-major; empty unless keepErrorMap
        int width = 0, height = 0;
    };

    /// FLIP error between `reference` and `test`. Symmetric in its two inputs.
    /// Borders are handled by clamp-to-edge in every filter.
    Result<FlipResult> flip(const Image& reference, const Image& test, const FlipOptions& options = {});

    /// A reference image filtered once (colour CSF and feature detectors) for comparing several
    /// test images with it: flip(FlipReference, test) equals flip(reference, test) exactly.
    /// Shareable between threads.
    class FlipReference
    {
    public:
        /// Errors: an empty image or pixels per degree out of (0, 10000].
        static Result<FlipReference> make(const Image& reference, const FlipOptions& options = {});
        int width() const;
        int height() const;

        struct Analysed;
        std::shared_ptr<const Analysed> analysed;
    };

    /// FLIP error between the prepared reference and `test` (its options; `keepErrorMap` here).
    Result<FlipResult> flip(const FlipReference& reference, const Image& test, bool keepErrorMap = false);
    /// FLIP error between two prepared images (one size, one pixels per degree), neither filtered
    /// again: equals flip(reference's image, test's image) exactly.
    Result<FlipResult> flip(const FlipReference& reference, const FlipReference& test, bool keepErrorMap = false);

    /// The error map as an opaque colour image (magma-like: black -> purple -> orange ->
    /// pale yellow as the error goes 0 -> 1), for difference views. Needs a result made
    /// with keepErrorMap; returns an empty Image otherwise.
    Image flipHeatmap(const FlipResult& result);

    /// PSNR over RGB with peak 1.0, in dB; +infinity when the images are identical.
    Result<double> psnr(const Image& reference, const Image& test);

    /// The default FLIP pixels per degree (0.7 m away, 0.7 m wide, 3840 pixels).
    double flipDefaultPixelsPerDegree();
}
