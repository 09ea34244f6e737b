// TreeViews: how a single tree is framed and compared in image space, shared by the bake-time
// error curves (ErrorCurveMeasurer.h) and the studies in bench/: the tree's extent in an image,
// a square crop around it (image error is taken over the tree's own box, not over a frame of
// sky), and the CPU reference quantised as the GPU's frames are. (The distance at which a tree
// is a given number of pixels tall is Camera.h's distanceForHeight.)
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ReferenceRenderer.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace TreeLod
{
    /// Pixels that differ from the background (as tests/ogre treeCoverage counts them).
    struct Extent
    {
        int minX = std::numeric_limits<int>::max(), minY = std::numeric_limits<int>::max();
        int maxX = -1, maxY = -1;
        bool any() const { return maxX >= 0; }
        int heightPx() const { return any() ? maxY - minY + 1 : 0; }
    };

    /// Whether a pixel differs from the background: a pixel of the tree.
    inline bool isTreePixel(const glm::vec4& pixel, const glm::vec3& background = LightingSpec().background)
    {
        return glm::length(glm::vec3(pixel) - background) > 0.02f;
    }

    inline Extent treeExtent(const Image& image, const glm::vec3& background = LightingSpec().background)
    {
        Extent e;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                if (isTreePixel(image.at(x, y), background))
                {
                    e.minX = std::min(e.minX, x);
                    e.maxX = std::max(e.maxX, x);
                    e.minY = std::min(e.minY, y);
                    e.maxY = std::max(e.maxY, y);
                }
        return e;
    }

    /// Fraction of pixels that differ from the background (the pixels treeExtent bounds).
    inline double treeCoverage(const Image& image, const glm::vec3& background = LightingSpec().background)
    {
        std::size_t covered = 0;
        for (const glm::vec4& p : image.pixels)
            covered += isTreePixel(p, background);
        return image.pixels.empty() ? 0.0 : double(covered) / double(image.pixels.size());
    }

    /// One flag per pixel of `image`: whether it is a tree pixel (isTreePixel).
    inline std::vector<std::uint8_t> treeMask(const Image& image)
    {
        std::vector<std::uint8_t> mask(image.pixels.size());
        for (std::size_t i = 0; i < mask.size(); ++i)
            mask[i] = isTreePixel(image.pixels[i]);
        return mask;
    }

    /// The mean of a FLIP error map (FlipOptions::keepErrorMap) over the pixels that are tree in
    /// either image (their treeMask flags): the error per pixel of the tree, whatever share of the
    /// image the background is; `result.mean` where neither has a tree pixel.
    inline double meanOverTree(const FlipResult& result, const std::vector<std::uint8_t>& reference,
                               const std::vector<std::uint8_t>& test)
    {
        double sum = 0.0;
        std::size_t count = 0;
        for (std::size_t i = 0; i < result.errorMap.size(); ++i)
            if (reference[i] || test[i])
            {
                sum += result.errorMap[i];
                ++count;
            }
        return count > 0 ? sum / double(count) : result.mean;
    }

    /// The same over the tree pixels of `reference` or `test`.
    inline double meanOverTree(const FlipResult& result, const Image& reference, const Image& test)
    {
        return meanOverTree(result, treeMask(reference), treeMask(test));
    }

    inline Extent unite(Extent a, const Extent& b)
    {
        a.minX = std::min(a.minX, b.minX);
        a.minY = std::min(a.minY, b.minY);
        a.maxX = std::max(a.maxX, b.maxX);
        a.maxY = std::max(a.maxY, b.maxY);
        return a;
    }

    struct Crop
    {
        int x = 0, y = 0, side = 0;
    };

    /// A square around the tree with a margin, inside the image (the whole image if none).
    inline Crop cropAround(const Extent& e, int width, int height)
    {
        const int full = std::min(width, height);
        if (!e.any())
            return {0, 0, full};
        const int side = std::clamp(int(std::ceil(1.15 * std::max(e.maxX - e.minX + 1, e.maxY - e.minY + 1))) + 4,
                                    8, full);
        const int cx = (e.minX + e.maxX + 1) / 2, cy = (e.minY + e.maxY + 1) / 2;
        return {std::clamp(cx - side / 2, 0, width - side), std::clamp(cy - side / 2, 0, height - side), side};
    }

    /// The `crop` of `image`, pixel for pixel.
    inline Image cropImage(const Image& image, const Crop& crop)
    {
        Image out(crop.side, crop.side);
        for (int y = 0; y < crop.side; ++y)
            for (int x = 0; x < crop.side; ++x)
                out.at(x, y) = image.at(crop.x + x, crop.y + y);
        return out;
    }

    /// The CPU ray-traced reference at size x size, quantised to 8 bits like the GPU frames
    /// (FLIP's power law turns float-vs-8-bit rounding of a flat sky into ~0.03 mean error).
    inline Image traceReference(const ReferenceRenderer& cpu, const CameraSpec& camera, int size, int supersample)
    {
        RenderOptions options;
        options.width = options.height = size;
        options.samplesPerPixel = supersample * supersample;
        Image traced = cpu.render(camera, options).colour;
        for (glm::vec4& p : traced.pixels)
            p = glm::round(glm::clamp(p, 0.0f, 1.0f) * 255.0f) / 255.0f;
        return traced;
    }
}
