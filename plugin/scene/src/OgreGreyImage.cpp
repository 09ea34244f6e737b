#include "TreeLod/OgreGreyImage.h"

#include <OgreCodec.h>
#include <OgreDataStream.h>
#include <OgreException.h>
#include <OgreImage.h>
#include <OgrePixelFormat.h>
#include <OgreStringConverter.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace TreeLod
{
    Result<GreyImage> readGreyImageOgre(const std::string& path)
    {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec))
            return fail(path, "", "file does not exist");
        std::string extension = std::filesystem::path(path).extension().string();
        if (!extension.empty())
            extension.erase(0, 1);
        std::transform(extension.begin(), extension.end(), extension.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (!Ogre::Codec::isCodecRegistered(extension))
            return fail(path, "", "no Ogre image codec for '" + extension +
                                      "' files (load Codec_STBI first, e.g. create the OffscreenRenderer)");
        std::ifstream in(path, std::ios::binary);
        std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (!in.good() && !in.eof())
            return fail(path, "", "cannot read the file");
        try
        {
            Ogre::DataStreamPtr stream(new Ogre::MemoryDataStream(bytes.data(), bytes.size(), false, true));
            Ogre::Image image;
            image.load(stream, extension);
            if (image.getDepth() != 1 || image.getWidth() == 0 || image.getHeight() == 0)
                return fail(path, "", "unsupported image size " + std::to_string(image.getWidth()) + "x" +
                                          std::to_string(image.getHeight()) + "x" + std::to_string(image.getDepth()));
            GreyImage grey;
            grey.width = int(image.getWidth());
            grey.height = int(image.getHeight());
            grey.values.resize(std::size_t(grey.width) * std::size_t(grey.height));
            // Any pixel format to one float per pixel: Ogre unpacks grey formats as r = g = b.
            const Ogre::PixelBox target(Ogre::uint32(grey.width), Ogre::uint32(grey.height), 1, Ogre::PF_FLOAT32_R,
                                        grey.values.data());
            Ogre::PixelUtil::bulkPixelConversion(image.getPixelBox(), target);
            for (float& v : grey.values)
                v = std::clamp(v, 0.0f, 1.0f);
            return grey;
        }
        catch (const Ogre::Exception& e)
        {
            return fail(path, "", "not an image Ogre can decode (" + e.getDescription() + ")");
        }
    }
}
