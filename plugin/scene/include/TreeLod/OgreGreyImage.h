// readGreyImageOgre: the runtime side's GreyImageReader (GreyImage.h) over Ogre::Image, for
// programs that read scene scripts without TreeLodBake (treelod_frames; docs/architecture.md,
// "Runtime vs bake"). The bake side's reader is readGreyImage (Image.h, libpng and libjpeg).
#pragma once

#include "TreeLod/GreyImage.h"

#include <string>

namespace TreeLod
{
    /// The red channel of the image at `path` in [0, 1], top row first (grey formats give their
    /// grey). Decoded by the Ogre codec registered for the file's extension (Codec_STBI reads
    /// PNG, JPEG, TGA, BMP): the process must have loaded one (an OffscreenRenderer or any Root
    /// with Codec_STBI) before, else an Error naming the file and the missing codec. Never throws.
    Result<GreyImage> readGreyImageOgre(const std::string& path);
}
