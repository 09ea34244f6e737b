// PNG and JPEG in memory, through libpng and libjpeg-turbo: what the bake side reads (textures
// of glTF files, heightfields, reference images) and writes (PNG images, glTF textures).
// Samples come back as stored: straight alpha, no gamma or colour-space conversion, 8 or 16
// bits. The decoders are told the size limit before they allocate a frame.
#pragma once

#include "TreeLod/Result.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// Interleaved samples of a decoded image, rows top to bottom.
    struct DecodedImage
    {
        int width = 0;
        int height = 0;
        int channels = 0; ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
        int bits = 8;     ///< 8 or 16
        std::vector<std::uint16_t> samples; ///< width * height * channels, in [0, 2^bits - 1]

        /// Sample i in [0, 1].
        float unit(std::size_t i) const { return float(samples[i]) / float(bits == 16 ? 65535 : 255); }
        /// Sample i as a byte (16-bit samples rounded to 8).
        std::uint8_t byte(std::size_t i) const
        {
            return bits == 16 ? std::uint8_t((std::uint32_t(samples[i]) * 255u + 32767u) / 65535u)
                              : std::uint8_t(samples[i]);
        }
    };

    enum class ImageFormat
    {
        Unknown,
        Png,
        Jpeg
    };

    /// The format the first bytes announce (PNG signature, JPEG start-of-image).
    ImageFormat sniffImageFormat(const std::uint8_t* data, std::size_t size);

    /// Decode PNG or JPEG bytes. Palette, low-bit grey and tRNS colour keys expand to 8-bit grey,
    /// RGB or RGBA; 16-bit PNGs keep 16 bits; CMYK JPEGs become RGB. An image wider or higher
    /// than maxSide, or of more than maxPixels, is refused before its pixels are allocated.
    /// The error's reason says what the decoder found; its file and element are empty.
    Result<DecodedImage> decodeImage(const std::uint8_t* data, std::size_t size, std::uint32_t maxSide,
                                     std::uint64_t maxPixels);

    /// Encode 8-bit grey (1), grey + alpha (2), RGB (3) or RGBA (4) samples as a PNG, zlib
    /// level 0-9. The error's reason says why; its file and element are empty.
    Result<std::vector<std::uint8_t>> encodePng(const std::uint8_t* samples, int width, int height, int channels,
                                                int level);
}
