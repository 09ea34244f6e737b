#include "TreeLod/Image.h"

#include "TreeLod/AtomicFile.h"

#include "TreeLod/ImageCodec.h"

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
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return fail(path, "", bytes.error().reason);
        Result<DecodedImage> decoded = decodeImage(bytes->data(), bytes->size(), 1u << 20, std::uint64_t(1) << 28);
        if (!decoded)
            return fail(path, "", decoded.error().reason);

        // Channel layout: 1 = grey, 2 = grey + alpha, 3 = RGB, 4 = RGBA.
        const int channels = decoded->channels;
        Image image(decoded->width, decoded->height);
        for (std::size_t i = 0; i < image.pixels.size(); ++i)
        {
            const std::size_t s = i * std::size_t(channels);
            glm::vec4 c(1.0f);
            if (channels < 3)
                c = glm::vec4(glm::vec3(decoded->unit(s)), 1.0f);
            else
                c = glm::vec4(decoded->unit(s), decoded->unit(s + 1), decoded->unit(s + 2), 1.0f);
            if (channels == 2 || channels == 4)
                c.a = decoded->unit(s + std::size_t(channels) - 1);
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

        Result<std::vector<std::uint8_t>> png = encodePng(bytes.data(), image.width, image.height, 4, 6);
        if (!png)
            return fail(path, "", png.error().reason);
        return writeFileAtomic(path, *png);
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
