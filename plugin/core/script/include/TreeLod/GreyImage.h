// GreyImage: one channel of a picture, what a scene script's heightfield needs. The script
// library reads no image formats itself (docs/architecture.md, "Runtime vs bake"): the caller
// injects a GreyImageReader, readGreyImage (Image.h, TreeLodBake, libpng and libjpeg) on the bake side,
// readGreyImageOgre (OgreGreyImage.h, TreeLodScene, Ogre::Image) on the runtime side.
#pragma once

#include "TreeLod/Result.h"

#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    struct GreyImage
    {
        int width = 0;
        int height = 0;
        std::vector<float> values; ///< width * height, row-major, top row first; the red channel in [0, 1]
    };

    /// Reads the image at `path`; an Error naming the file when it cannot.
    using GreyImageReader = std::function<Result<GreyImage>(const std::string& path)>;
}
