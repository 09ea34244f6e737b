// Private helpers shared by the image metrics (MultiScaleRmse.cpp, Flip.cpp, Psnr.cpp).
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/Result.h"

#include <optional>
#include <string>

namespace TreeLod
{
    /// An Error when the two images cannot be compared (different or zero size, or a
    /// pixel array that does not match the stated size); nothing otherwise.
    inline std::optional<Error> checkComparable(const char* metric, const Image& reference, const Image& test)
    {
        auto size = [](const Image& i) { return std::to_string(i.width) + "x" + std::to_string(i.height); };
        if (reference.width != test.width || reference.height != test.height)
            return fail("", metric, "image sizes differ: reference " + size(reference) + ", test " + size(test));
        if (reference.width <= 0 || reference.height <= 0)
            return fail("", metric, "images are empty (" + size(reference) + ")");
        const std::size_t n = std::size_t(reference.width) * reference.height;
        if (reference.pixels.size() != n || test.pixels.size() != n)
            return fail("", metric, "pixel array does not match the image size " + size(reference));
        return std::nullopt;
    }
}
