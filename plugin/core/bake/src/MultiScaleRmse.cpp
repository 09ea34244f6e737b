// Multi-scale RMSE.
//
// This work is based on:
//   "A level-of-detail method for trees based on ellipsoids and lines" (docs/papers.md),
//   §4 "Image Error Metric" and Fig. 8: the RMSE of the difference image
//   (test - reference) at several resolutions, computed in a single scan along a
//   space-filling Z-order curve with one accumulated value per resolution band.
//
// Along the Z curve every aligned run of 4^k pixels is one aligned 2^k x 2^k block,
// i.e. one pixel of the image box-downsampled by 2^k. So one scan keeps a running sum
// of differences per level; when a run of 4^k closes, its mean difference is that
// coarse pixel's difference and its square goes into band k.
//
// Deviation: the paper keeps log2(n) values for an n-wide image; we also keep the
// 1x1 band (the global mean difference, i.e. overall brightness or coverage), so there
// are log2(n) + 1 bands from n x n down to 1x1.
//
// Images that are not power-of-two squares are padded to the next power-of-two square
// n with pixels that do not exist: a block mean is taken over its real pixels only, and
// band k's mean squared error is sum_blocks(realCount * |blockMean|^2) / realPixels.
// For a size divisible by 2^k this is exactly the MSE of the 2^k-downsampled image;
// in general it is the MSE, over the real pixels, of the difference image with every
// pixel replaced by its block mean. Fully padded blocks are skipped in one step.
#include "TreeLod/ImageMetrics.h"

#include "MetricsSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    namespace
    {
        /// Every second bit of v (bits 0, 2, 4, ...) packed into the low 32 bits.
        inline std::uint32_t compactBits(std::uint64_t v)
        {
            v &= 0x5555555555555555ull;
            v = (v | (v >> 1)) & 0x3333333333333333ull;
            v = (v | (v >> 2)) & 0x0f0f0f0f0f0f0f0full;
            v = (v | (v >> 4)) & 0x00ff00ff00ff00ffull;
            v = (v | (v >> 8)) & 0x0000ffff0000ffffull;
            v = (v | (v >> 16)) & 0x00000000ffffffffull;
            return std::uint32_t(v);
        }

        struct BlockSum
        {
            double r = 0.0, g = 0.0, b = 0.0;
            std::uint64_t count = 0;
        };
    }

    Result<MultiScaleRmseResult> multiScaleRmse(const Image& reference, const Image& test)
    {
        if (auto error = checkComparable("multi-scale RMSE", reference, test))
            return *error;

        const std::uint32_t width = std::uint32_t(reference.width), height = std::uint32_t(reference.height);
        int levels = 0; // n = 2^levels >= max(width, height)
        while ((std::uint64_t(1) << levels) < std::max(width, height))
            ++levels;

        // acc[k]: running sum of the current (open) block at level k, k = 2..levels.
        std::vector<BlockSum> acc(std::size_t(levels) + 1);
        std::vector<double> squared(std::size_t(levels) + 1, 0.0);

        auto difference = [&](std::uint32_t x, std::uint32_t y, BlockSum& block) {
            const std::size_t p = std::size_t(y) * width + x;
            const glm::vec4& a = reference.pixels[p];
            const glm::vec4& b = test.pixels[p];
            const double dr = double(b.r) - a.r, dg = double(b.g) - a.g, db = double(b.b) - a.b;
            squared[0] += dr * dr + dg * dg + db * db;
            block.r += dr;
            block.g += dg;
            block.b += db;
            ++block.count;
        };

        if (levels == 0)
        {
            BlockSum unused;
            difference(0, 0, unused);
        }

        // Ellipsoids-and-lines paper §4: one scan of the difference image along the Z curve. The
        // scan steps over 2x2 quads (level-1 blocks, Z-ordered inside) so that band 0 and band 1
        // are done in the same step; coarser blocks close as their runs of quads end.
        const std::uint64_t quads = levels > 0 ? std::uint64_t(1) << (2 * (levels - 1)) : 0;
        std::uint64_t j = 0;
        while (j < quads)
        {
            const std::uint32_t x = 2 * compactBits(j), y = 2 * compactBits(j >> 1);
            std::uint64_t next = j + 1;
            if (x < width && y < height)
            {
                BlockSum quad;
                difference(x, y, quad);
                const bool right = x + 1 < width, below = y + 1 < height;
                if (right)
                    difference(x + 1, y, quad);
                if (below)
                    difference(x, y + 1, quad);
                if (right && below)
                    difference(x + 1, y + 1, quad);
                squared[1] += (quad.r * quad.r + quad.g * quad.g + quad.b * quad.b) / double(quad.count);
                if (levels > 1)
                {
                    BlockSum& parent = acc[2];
                    parent.r += quad.r;
                    parent.g += quad.g;
                    parent.b += quad.b;
                    parent.count += quad.count;
                }
            }
            else
            {
                // The aligned block starting here lies wholly outside the image (its
                // origin does), so jump over the largest such block at once.
                int k = 0;
                while (k + 1 < levels && (j & ((std::uint64_t(1) << (2 * (k + 1))) - 1)) == 0)
                    ++k;
                next = j + (std::uint64_t(1) << (2 * k));
            }

            // Close every block of level >= 2 whose run of quads ends at next - 1; its
            // mean is one coarse pixel: add count * |mean|^2 = |sum|^2 / count.
            for (int k = 2; k <= levels && (next & ((std::uint64_t(1) << (2 * (k - 1))) - 1)) == 0; ++k)
            {
                BlockSum& s = acc[std::size_t(k)];
                if (s.count > 0)
                {
                    squared[std::size_t(k)] += (s.r * s.r + s.g * s.g + s.b * s.b) / double(s.count);
                    if (k < levels)
                    {
                        BlockSum& parent = acc[std::size_t(k) + 1];
                        parent.r += s.r;
                        parent.g += s.g;
                        parent.b += s.b;
                        parent.count += s.count;
                    }
                }
                s = BlockSum();
            }
            j = next;
        }

        MultiScaleRmseResult result;
        const double samples = 3.0 * double(width) * double(height);
        result.bands.reserve(squared.size());
        double sum = 0.0;
        for (double s : squared)
        {
            result.bands.push_back(std::sqrt(s / samples));
            sum += result.bands.back();
        }
        result.combined = sum / double(result.bands.size());
        return result;
    }
}
