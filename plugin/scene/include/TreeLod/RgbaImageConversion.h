// RgbaImage (the Ogre renderer's 8-bit output) as core's Image (what the image metrics read).
#pragma once

#include "TreeLod/Colour.h"
#include "TreeLod/Image.h"
#include "TreeLod/OffscreenRenderer.h"

namespace TreeLod
{
    /// Values / 255, sRGB kept (the metrics convert), rows in the same order.
    inline Image toImage(const RgbaImage& rgba)
    {
        Image image(rgba.width, rgba.height);
        for (std::size_t i = 0; i < image.pixels.size(); ++i)
            image.pixels[i] = glm::vec4(byteToUnit(rgba.pixels[4 * i]), byteToUnit(rgba.pixels[4 * i + 1]),
                                        byteToUnit(rgba.pixels[4 * i + 2]), byteToUnit(rgba.pixels[4 * i + 3]));
        return image;
    }
}
