// renderEllipsoids (EllipsoidTreeBaker.h): the ellipsoids ray cast on the CPU as
// TreeLodEllipsoid.frag casts them on the GPU, noise included, for the baker's image error.
#include "TreeLod/EllipsoidNoise.h"
#include "TreeLod/EllipsoidTreeBaker.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    float ellipsoidNoiseRadius(const glm::vec3& scaledRadii)
    {
        const glm::vec3 r = glm::abs(scaledRadii);
        const float smallest = std::min(r.x, std::min(r.y, r.z));
        return std::sqrt(r.x * r.y * r.z / std::max(smallest, 1e-30f));
    }

    Image renderEllipsoids(const std::vector<Ellipsoid>& ellipsoids, float scale, const EllipsoidNoiseSetting& noise,
                           const CameraSpec& camera, const RenderOptions& options)
    {
        const int width = std::max(options.width, 0), height = std::max(options.height, 0);
        const int grid = int(std::lround(std::sqrt(double(std::max(options.samplesPerPixel, 1)))));
        const LightingSpec& light = options.lighting;
        Image image(width, height, glm::vec4(light.background, 1.0f));
        if (width == 0 || height == 0)
            return image;
        const int samplesX = width * grid, samplesY = height * grid;
        const std::size_t sampleCount = std::size_t(samplesX) * std::size_t(samplesY);

        // The rays of the samples (row-major over the supersampled grid), as ReferenceRenderer's.
        const glm::dmat4 viewProjection = glm::dmat4(camera.projectionMatrix(float(width) / float(height))) *
                                          glm::dmat4(camera.viewMatrix());
        const glm::dmat4 inverse = glm::inverse(viewProjection);
        std::vector<glm::vec3> origins(sampleCount), directions(sampleCount);
        std::vector<float> lengths(sampleCount);
        for (int sy = 0; sy < samplesY; ++sy)
            for (int sx = 0; sx < samplesX; ++sx)
            {
                const double x = (sx + 0.5) / grid, y = (sy + 0.5) / grid;
                const double ndcX = 2.0 * x / width - 1.0, ndcY = 1.0 - 2.0 * y / height;
                const glm::dvec4 n = inverse * glm::dvec4(ndcX, ndcY, -1.0, 1.0);
                const glm::dvec4 f = inverse * glm::dvec4(ndcX, ndcY, 1.0, 1.0);
                const glm::dvec3 nearP = glm::dvec3(n) / n.w, span = glm::dvec3(f) / f.w - nearP;
                const std::size_t i = std::size_t(sy) * samplesX + sx;
                const double length = glm::length(span);
                origins[i] = glm::vec3(nearP);
                directions[i] = length > 0.0 ? glm::vec3(span / length) : glm::vec3(0.0f);
                lengths[i] = std::isfinite(length) ? float(length) : 0.0f;
            }

        std::vector<float> depth(sampleCount, std::numeric_limits<float>::infinity());
        std::vector<glm::vec3> colour(sampleCount, glm::vec3(0.0f)); // linear, white albedo
        const float sunLength = glm::length(light.sunDirection);
        const glm::vec3 sun = sunLength > 0.0f ? light.sunDirection / sunLength : glm::vec3(0.0f);
        const EllipsoidNoiseMaps* maps =
            noise.threshold > 0.0f || noise.normalBlend > 0.0f ? &ellipsoidNoiseMaps() : nullptr;

        for (const Ellipsoid& e : ellipsoids)
        {
            const glm::mat3 rotation = glm::mat3_cast(e.rotation);
            const glm::vec3 radii = glm::max(scale * e.radii, glm::vec3(1e-30f));
            // toUnit = diag(1 / radii) R^T: world offsets to the frame where the ellipsoid is the unit sphere.
            const glm::mat3 toUnit = glm::transpose(glm::mat3(rotation[0] / radii.x, rotation[1] / radii.y, rotation[2] / radii.z));
            // Its samples: the pixel rectangle of its box's corners (all of the image if one is behind the eye).
            int x0 = 0, y0 = 0, x1 = samplesX - 1, y1 = samplesY - 1;
            {
                glm::dvec2 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
                bool behind = false;
                for (int c = 0; c < 8; ++c)
                {
                    const glm::vec3 s((c & 1) ? 1.0f : -1.0f, (c & 2) ? 1.0f : -1.0f, (c & 4) ? 1.0f : -1.0f);
                    const glm::vec3 corner = e.centre + rotation * (radii * s);
                    const glm::dvec4 clip = viewProjection * glm::dvec4(glm::dvec3(corner), 1.0);
                    if (!(clip.w > 0.0))
                    {
                        behind = true;
                        break;
                    }
                    const glm::dvec2 p((clip.x / clip.w * 0.5 + 0.5) * samplesX, (0.5 - clip.y / clip.w * 0.5) * samplesY);
                    lo = glm::min(lo, p);
                    hi = glm::max(hi, p);
                }
                if (!behind)
                {
                    if (!(hi.x >= 0.0 && hi.y >= 0.0 && lo.x <= samplesX && lo.y <= samplesY))
                        continue;
                    x0 = std::max(0, int(std::floor(lo.x - 0.5)));
                    y0 = std::max(0, int(std::floor(lo.y - 0.5)));
                    x1 = std::min(samplesX - 1, int(std::ceil(hi.x)));
                    y1 = std::min(samplesY - 1, int(std::ceil(hi.y)));
                }
            }
            float lod = ellipsoidNoiseBaseLod(e.leafWeight);
            if (noise.pixelSize > 0.0f)
                lod = std::max(lod, ellipsoidNoiseFootprintLod(noise.pixelSize, ellipsoidNoiseRadius(radii)));
            for (int sy = y0; sy <= y1; ++sy)
                for (int sx = x0; sx <= x1; ++sx)
                {
                    const std::size_t i = std::size_t(sy) * samplesX + sx;
                    // From the ray's point nearest the centre (t = mid), so that the quadratic does
                    // not cancel for small ellipsoids far from the ray's origin.
                    const glm::vec3 k = toUnit * directions[i];
                    const float a = glm::dot(k, k);
                    if (!(a > 0.0f))
                        continue;
                    const glm::vec3 from = toUnit * (origins[i] - e.centre);
                    const float mid = -glm::dot(from, k) / a;
                    const glm::vec3 o = from + mid * k;
                    const float c = glm::dot(o, o) - 1.0f;
                    if (!(c <= 0.0f))
                        continue;
                    const float half = std::sqrt(-c / a);
                    // The near side, and where its alpha test fails or it is behind the near plane, the far side.
                    for (float t : {mid - half, mid + half})
                    {
                        if (t < 0.0f || t > lengths[i] || t >= depth[i])
                            continue;
                        const glm::vec3 u = o + (t - mid) * k;
                        if (maps && noise.threshold > 0.0f && maps->sampleAlpha(u, lod) < noise.threshold)
                            continue;
                        glm::vec3 unitNormal = u;
                        if (maps && noise.normalBlend > 0.0f)
                            unitNormal = glm::mix(u, maps->sampleNormal(u, lod), noise.normalBlend);
                        glm::vec3 n = glm::transpose(toUnit) * unitNormal;
                        const float length = glm::length(n);
                        n = length > 0.0f ? n / length : -directions[i];
                        if (glm::dot(n, directions[i]) > 0.0f)
                            n = -n;
                        depth[i] = t;
                        colour[i] = light.ambientColour + light.sunColour * std::max(0.0f, glm::dot(n, sun));
                        break;
                    }
                }
        }

        const glm::vec3 background(srgbToLinear(light.background.r), srgbToLinear(light.background.g),
                                   srgbToLinear(light.background.b));
        const float inverseSamples = 1.0f / float(grid * grid);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
            {
                glm::vec3 sum(0.0f);
                bool any = false;
                for (int sy = 0; sy < grid; ++sy)
                    for (int sx = 0; sx < grid; ++sx)
                    {
                        const std::size_t i = std::size_t(y * grid + sy) * samplesX + std::size_t(x * grid + sx);
                        const bool hit = std::isfinite(depth[i]);
                        any = any || hit;
                        sum += hit ? glm::clamp(colour[i], glm::vec3(0.0f), glm::vec3(1.0f)) : background;
                    }
                if (!any)
                    continue;
                const glm::vec3 linear = sum * inverseSamples;
                image.at(x, y) = glm::vec4(linearToSrgb(linear.r), linearToSrgb(linear.g), linearToSrgb(linear.b), 1.0f);
            }
        return image;
    }
}
