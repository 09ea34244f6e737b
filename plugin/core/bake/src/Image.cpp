#include "TreeLod/Image.h"

#include "TreeLod/AtomicFile.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>

namespace TreeLod
{
    Result<Image> readImage(const std::string& path)
    {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec))
            return fail(path, "", "file does not exist");
        if (std::filesystem::is_directory(path, ec))
            return fail(path, "", "is a directory, not an image");

        // Ask for straight (unassociated) alpha: by default OpenImageIO premultiplies
        // PNG colour by alpha on read, which would change the stored values.
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path, &config);
        if (!in)
        {
            std::string why = OIIO::geterror();
            return fail(path, "", "not an image or unsupported format" + (why.empty() ? "" : " (" + why + ")"));
        }
        const OIIO::ImageSpec spec = in->spec();
        if (spec.deep)
            return fail(path, "", "unsupported: deep image");
        if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1)
            return fail(path, "", "unsupported size " + std::to_string(spec.width) + "x" +
                                      std::to_string(spec.height) + "x" + std::to_string(spec.depth));
        if (spec.nchannels <= 0)
            return fail(path, "", "unsupported: no channels");
        if (std::int64_t(spec.width) * spec.height > std::int64_t(1) << 28)
            return fail(path, "", "unsupported: image too large (" + std::to_string(spec.width) + "x" +
                                      std::to_string(spec.height) + ")");

        const int channels = spec.nchannels;
        std::vector<float> data(std::size_t(spec.width) * spec.height * channels);
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, data.data()))
            return fail(path, "", "cannot decode pixels: " + in->geterror());
        in->close();

        // Channel layout: 1 = grey, 2 = grey + alpha, 3 = RGB, 4+ = RGBA (extra channels
        // dropped). A declared alpha channel wins over the position rule.
        int alpha = spec.alpha_channel;
        if (alpha < 0 && (channels == 2 || channels >= 4))
            alpha = channels == 2 ? 1 : 3;
        const bool grey = channels < 3;

        Image image(spec.width, spec.height);
        for (std::size_t i = 0; i < image.pixels.size(); ++i)
        {
            const float* p = &data[i * channels];
            glm::vec4 c;
            if (grey)
                c = glm::vec4(p[0], p[0], p[0], 1.0f);
            else
                c = glm::vec4(p[0], p[1], p[2], 1.0f);
            if (alpha >= 0 && alpha < channels)
                c.a = p[alpha];
            image.pixels[i] = c;
        }
        return image;
    }

    Result<void> writePng(const std::string& path, const Image& image)
    {
        if (image.width <= 0 || image.height <= 0 ||
            image.pixels.size() != std::size_t(image.width) * image.height)
            return fail(path, "", "cannot write an empty or inconsistent image (" + std::to_string(image.width) +
                                      "x" + std::to_string(image.height) + ", " +
                                      std::to_string(image.pixels.size()) + " pixels)");

        std::vector<std::uint8_t> bytes(image.pixels.size() * 4);
        for (std::size_t i = 0; i < image.pixels.size(); ++i)
            for (int c = 0; c < 4; ++c)
            {
                float v = image.pixels[i][c];
                v = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
                bytes[i * 4 + c] = std::uint8_t(std::lround(v * 255.0f));
            }

        return writeFileAtomicVia(path, [&](const std::string& temp) -> Result<void> {
            std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("png");
            if (!out)
                return fail(path, "", "PNG writer unavailable: " + OIIO::geterror());
            OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT8);
            spec.alpha_channel = 3;
            // The bytes are straight alpha already; stop the writer dividing by alpha.
            spec.attribute("oiio:UnassociatedAlpha", 1);
            if (!out->open(temp, spec))
                return fail(path, "", "cannot open for writing: " + out->geterror());
            if (!out->write_image(OIIO::TypeDesc::UINT8, bytes.data()))
                return fail(path, "", "cannot write pixels: " + out->geterror());
            if (!out->close())
                return fail(path, "", "cannot finish file: " + out->geterror());
            return {};
        });
    }

    // IEC 61966-2-1 piecewise transfer functions.
    float srgbToLinear(float c)
    {
        return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }

    float linearToSrgb(float c)
    {
        return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    }
}
