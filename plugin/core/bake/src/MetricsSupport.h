// Private helpers shared by the image metrics (MultiScaleRmse.cpp, Flip.cpp, Psnr.cpp).
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/Result.h"

#include <algorithm>
#include <optional>
#include <string>

namespace TreeLod
{
    /// An Error when the two images cannot be compared (different or zero size, or a
    /// pixel array that does not match the stated size); nothing otherwise.
    /// The same for a reference known by its size alone (its pixels checked when it was prepared).
    inline std::optional<Error> checkComparable(const char* metric, int width, int height, const Image& test)
    {
        auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
        if (width != test.width || height != test.height)
            return fail("", metric, "image sizes differ: reference " + size(width, height) + ", test " +
                                        size(test.width, test.height));
        if (width <= 0 || height <= 0)
            return fail("", metric, "images are empty (" + size(width, height) + ")");
        if (test.pixels.size() != std::size_t(width) * height)
            return fail("", metric, "pixel array does not match the image size " + size(width, height));
        return std::nullopt;
    }

    inline std::optional<Error> checkComparable(const char* metric, const Image& reference, const Image& test)
    {
        if (reference.pixels.size() != std::size_t(std::max(reference.width, 0)) * std::size_t(std::max(reference.height, 0)))
            return fail("", metric, "pixel array does not match the image size " + std::to_string(reference.width) +
                                        "x" + std::to_string(reference.height));
        return checkComparable(metric, reference.width, reference.height, test);
    }
}
