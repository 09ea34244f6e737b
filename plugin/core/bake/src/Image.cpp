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

    Result<GreyImage> readGreyImage(const std::string& path)
    {
        Result<Image> image = readImage(path);
        if (!image)
            return image.error();
        GreyImage grey;
        grey.width = image->width;
        grey.height = image->height;
        grey.values.reserve(image->pixels.size());
        for (const glm::vec4& p : image->pixels)
            grey.values.push_back(std::clamp(p.r, 0.0f, 1.0f));
        return grey;
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
                const float v = image.pixels[i][c];
                bytes[i * 4 + c] = unitToByte(std::isnan(v) ? 0.0f : v);
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

    void bleedValues(std::vector<glm::vec3>& values, const std::vector<std::uint8_t>& known, int width, int height,
                     int rings, const glm::vec3& fallback)
    {
        const std::size_t count = std::size_t(std::max(width, 0)) * std::size_t(std::max(height, 0));
        if (values.size() != count || known.size() != count)
            return;
        std::vector<std::uint8_t> filled(known);
        glm::dvec3 sum(0.0);
        std::size_t knownCount = 0;
        for (std::size_t i = 0; i < count; ++i)
            if (filled[i])
            {
                sum += glm::dvec3(values[i]);
                ++knownCount;
            }
        auto forNeighbours = [width, height](std::size_t i, auto&& visit) {
            const int px = int(i % std::size_t(width)), py = int(i / std::size_t(width));
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                {
                    const int x = px + dx, y = py + dy;
                    if ((dx != 0 || dy != 0) && x >= 0 && y >= 0 && x < width && y < height)
                        visit(std::size_t(y) * std::size_t(width) + std::size_t(x));
                }
        };
        // The frontier: empty texels next to a filled one, in index order.
        std::vector<std::uint8_t> queued(count, 0);
        std::vector<std::size_t> frontier, next;
        for (std::size_t i = 0; i < count; ++i)
            if (!filled[i])
                forNeighbours(i, [&](std::size_t j) {
                    if (filled[j] && !queued[i])
                    {
                        queued[i] = 1;
                        frontier.push_back(i);
                    }
                });
        std::vector<glm::vec3> ring;
        for (int r = 0; r < rings && !frontier.empty(); ++r)
        {
            ring.assign(frontier.size(), glm::vec3(0.0f));
            for (std::size_t k = 0; k < frontier.size(); ++k)
            {
                glm::vec3 s(0.0f);
                int n = 0;
                forNeighbours(frontier[k], [&](std::size_t j) {
                    if (filled[j])
                    {
                        s += values[j];
                        ++n;
                    }
                });
                ring[k] = s / float(n);
            }
            next.clear();
            for (std::size_t k = 0; k < frontier.size(); ++k)
            {
                values[frontier[k]] = ring[k];
                filled[frontier[k]] = 1;
            }
            for (std::size_t i : frontier)
                forNeighbours(i, [&](std::size_t j) {
                    if (!filled[j] && !queued[j])
                    {
                        queued[j] = 1;
                        next.push_back(j);
                    }
                });
            std::sort(next.begin(), next.end());
            frontier.swap(next);
        }
        const glm::vec3 mean = knownCount ? glm::vec3(sum / double(knownCount)) : fallback;
        for (std::size_t i = 0; i < count; ++i)
            if (!filled[i])
                values[i] = mean;
    }

    TextureImage albedoTexture(const std::string& name, int width, int height, const std::vector<glm::vec3>& albedo,
                               const std::vector<float>& alpha)
    {
        const std::size_t count = std::size_t(std::max(width, 0)) * std::size_t(std::max(height, 0));
        TextureImage image;
        image.name = name;
        image.width = width;
        image.height = height;
        image.rgba.resize(count * 4);
        for (std::size_t i = 0; i < count && i < albedo.size() && i < alpha.size(); ++i)
        {
            image.rgba[4 * i + 0] = linearToSrgbByte(albedo[i].r);
            image.rgba[4 * i + 1] = linearToSrgbByte(albedo[i].g);
            image.rgba[4 * i + 2] = linearToSrgbByte(albedo[i].b);
            image.rgba[4 * i + 3] = unitToByte(alpha[i]);
        }
        return image;
    }
}
