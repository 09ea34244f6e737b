// Image: a float RGBA picture for the CPU renderer and the image metrics.
// Values are display-encoded (sRGB) in [0, 1] unless a function says otherwise;
// rows run top to bottom, pixels are interleaved RGBA.
#pragma once

#include "TreeLod/Colour.h" // srgbToLinear, linearToSrgb, unitToByte: colours as the images hold them
#include "TreeLod/GreyImage.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <string>
#include <vector>

namespace TreeLod
{
    struct Image
    {
        int width = 0;
        int height = 0;
        std::vector<glm::vec4> pixels; ///< width * height

        Image() = default;
        Image(int w, int h, const glm::vec4& fill = glm::vec4(0.0f))
            : width(w), height(h), pixels(std::size_t(w) * h, fill) {}

        glm::vec4& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
        const glm::vec4& at(int x, int y) const { return pixels[std::size_t(y) * width + x]; }
        bool empty() const { return pixels.empty(); }
    };

    /// Read a PNG or JPEG as RGBA in [0, 1] (samples as stored: no gamma or colour-space
    /// conversion); grey and RGB get alpha 1, palette images keep their tRNS alpha.
    Result<Image> readImage(const std::string& path);

    /// readImage's red channel, clamped to [0, 1] (16-bit PNGs keep their precision):
    /// the GreyImageReader of the bake side (scene scripts' heightfields, SceneScript.h).
    Result<GreyImage> readGreyImage(const std::string& path);

    /// Write an 8-bit RGBA PNG atomically (values clamped to [0, 1]).
    Result<void> writePng(const std::string& path, const Image& image);

    /// Bleeding: fill the texels of a width x height grid (row-major) where `known` is 0 with
    /// the values of their known neighbours, so that bilinear filtering, mips and block
    /// compression next to them do not pull in an unrelated (dark) value. `rings` rings
    /// outwards, each texel the mean of its already filled 8-neighbours; texels still empty
    /// then take the mean of the known texels (`fallback` when none is known). Work is
    /// proportional to the texels filled. Deterministic.
    void bleedValues(std::vector<glm::vec3>& values, const std::vector<std::uint8_t>& known, int width, int height,
                     int rings, const glm::vec3& fallback);

    /// A width x height RGBA8 texture `name` of linear albedo (stored as sRGB) and coverage
    /// `alpha` in [0, 1] (stored linear), row-major: what the impostor-like bakers upload.
    TextureImage albedoTexture(const std::string& name, int width, int height, const std::vector<glm::vec3>& albedo,
                               const std::vector<float>& alpha);
}
