// Peak signal-to-noise ratio over RGB with peak 1.0 (alpha ignored).
#include "TreeLod/ImageMetrics.h"

#include "MetricsSupport.h"

#include <cmath>
#include <limits>

namespace TreeLod
{
    Result<double> psnr(const Image& reference, const Image& test)
    {
        if (auto error = checkComparable("PSNR", reference, test))
            return *error;
        double sum = 0.0;
        for (std::size_t i = 0; i < reference.pixels.size(); ++i)
        {
            const glm::vec4& a = reference.pixels[i];
            const glm::vec4& b = test.pixels[i];
            const double dr = double(b.r) - a.r, dg = double(b.g) - a.g, db = double(b.b) - a.b;
            sum += dr * dr + dg * dg + db * db;
        }
        if (sum == 0.0)
            return std::numeric_limits<double>::infinity();
        const double mse = sum / (3.0 * double(reference.pixels.size()));
        return 10.0 * std::log10(1.0 / mse);
    }
}
