// EllipsoidNoise: the white-noise cube maps (EllipsoidNoise.h).
#include "TreeLod/EllipsoidNoise.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        std::uint64_t mix64(std::uint64_t z)
        {
            z += 0x9E3779B97F4A7C15ull;
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            return z ^ (z >> 31);
        }

        std::uint8_t toByte(float v) { return std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

        EllipsoidNoiseMaps build()
        {
            EllipsoidNoiseMaps maps;
            constexpr double PI = 3.14159265358979323846;
            const int n = ELLIPSOID_NOISE_SIZE;
            for (int face = 0; face < 6; ++face)
            {
                std::vector<std::uint8_t>& alpha = maps.alpha[0][std::size_t(face)];
                std::vector<std::uint8_t>& normal = maps.normal[0][std::size_t(face)];
                alpha.resize(std::size_t(n) * n);
                normal.resize(std::size_t(n) * n * 4);
                for (int i = 0; i < n * n; ++i)
                {
                    const std::uint64_t h = mix64((std::uint64_t(face) << 32) ^ std::uint64_t(i));
                    alpha[std::size_t(i)] = std::uint8_t(h & 0xFF);
                    // A uniform direction: z uniform in [-1, 1], azimuth uniform.
                    const double z = 2.0 * double((h >> 8) & 0xFFFFFF) / 16777215.0 - 1.0;
                    const double phi = 2.0 * PI * double((h >> 32) & 0xFFFFFF) / 16777216.0;
                    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
                    const float v[3] = {float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)};
                    for (int c = 0; c < 3; ++c)
                        normal[std::size_t(i) * 4 + std::size_t(c)] = toByte(0.5f + 0.5f * v[c]);
                    normal[std::size_t(i) * 4 + 3] = 255;
                }
            }
            for (int level = 1; level < ELLIPSOID_NOISE_LEVELS; ++level)
            {
                const int s = n >> level, fine = n >> (level - 1);
                for (std::size_t face = 0; face < 6; ++face)
                {
                    const std::vector<std::uint8_t>& a = maps.alpha[std::size_t(level - 1)][face];
                    const std::vector<std::uint8_t>& b = maps.normal[std::size_t(level - 1)][face];
                    std::vector<std::uint8_t>& alpha = maps.alpha[std::size_t(level)][face];
                    std::vector<std::uint8_t>& normal = maps.normal[std::size_t(level)][face];
                    alpha.resize(std::size_t(s) * s);
                    normal.resize(std::size_t(s) * s * 4);
                    for (int y = 0; y < s; ++y)
                        for (int x = 0; x < s; ++x)
                        {
                            const std::size_t q[4] = {std::size_t(2 * y) * fine + 2 * x, std::size_t(2 * y) * fine + 2 * x + 1,
                                                      std::size_t(2 * y + 1) * fine + 2 * x,
                                                      std::size_t(2 * y + 1) * fine + 2 * x + 1};
                            const std::size_t o = std::size_t(y) * s + x;
                            alpha[o] = toByte(float(a[q[0]] + a[q[1]] + a[q[2]] + a[q[3]]) / (4.0f * 255.0f));
                            for (std::size_t c = 0; c < 4; ++c)
                                normal[o * 4 + c] = toByte(float(b[q[0] * 4 + c] + b[q[1] * 4 + c] + b[q[2] * 4 + c] +
                                                                 b[q[3] * 4 + c]) /
                                                           (4.0f * 255.0f));
                        }
                }
            }
            return maps;
        }

        /// The face and (s, t) in [0, 1] of a direction (OpenGL 4.6 §8.13, Table 8.19).
        void faceOf(const glm::vec3& d, int& face, float& s, float& t)
        {
            const glm::vec3 a = glm::abs(d);
            float sc, tc, ma;
            if (a.x >= a.y && a.x >= a.z)
            {
                face = d.x >= 0.0f ? 0 : 1;
                sc = d.x >= 0.0f ? -d.z : d.z;
                tc = -d.y;
                ma = a.x;
            }
            else if (a.y >= a.z)
            {
                face = d.y >= 0.0f ? 2 : 3;
                sc = d.x;
                tc = d.y >= 0.0f ? d.z : -d.z;
                ma = a.y;
            }
            else
            {
                face = d.z >= 0.0f ? 4 : 5;
                sc = d.z >= 0.0f ? d.x : -d.x;
                tc = -d.y;
                ma = a.z;
            }
            ma = ma > 0.0f ? ma : 1.0f;
            s = 0.5f * (sc / ma + 1.0f);
            t = 0.5f * (tc / ma + 1.0f);
        }

        /// Bilinear over `channels` bytes a texel of a face of `size`^2 texels, clamped at the edges.
        template <int Channels>
        glm::vec4 bilinear(const std::vector<std::uint8_t>& texels, int size, float s, float t)
        {
            const float x = s * float(size) - 0.5f, y = t * float(size) - 0.5f;
            const float fx = std::floor(x), fy = std::floor(y);
            const float wx = x - fx, wy = y - fy;
            const int x0 = std::clamp(int(fx), 0, size - 1), x1 = std::clamp(int(fx) + 1, 0, size - 1);
            const int y0 = std::clamp(int(fy), 0, size - 1), y1 = std::clamp(int(fy) + 1, 0, size - 1);
            glm::vec4 out(0.0f);
            for (int c = 0; c < Channels; ++c)
            {
                auto at = [&](int xx, int yy) { return float(texels[(std::size_t(yy) * size + xx) * Channels + c]); };
                out[c] = ((1.0f - wy) * ((1.0f - wx) * at(x0, y0) + wx * at(x1, y0)) +
                          wy * ((1.0f - wx) * at(x0, y1) + wx * at(x1, y1))) /
                         255.0f;
            }
            return out;
        }

        template <int Channels>
        glm::vec4 trilinear(const std::array<std::array<std::vector<std::uint8_t>, 6>, ELLIPSOID_NOISE_LEVELS>& levels,
                            const glm::vec3& dir, float lod)
        {
            int face;
            float s, t;
            faceOf(dir, face, s, t);
            lod = std::clamp(std::isfinite(lod) ? lod : 0.0f, 0.0f, float(ELLIPSOID_NOISE_LEVELS - 1));
            const int l0 = std::min(int(lod), ELLIPSOID_NOISE_LEVELS - 1), l1 = std::min(l0 + 1, ELLIPSOID_NOISE_LEVELS - 1);
            const float w = lod - float(l0);
            const glm::vec4 a =
                bilinear<Channels>(levels[std::size_t(l0)][std::size_t(face)], ELLIPSOID_NOISE_SIZE >> l0, s, t);
            if (w <= 0.0f || l1 == l0)
                return a;
            return glm::mix(a, bilinear<Channels>(levels[std::size_t(l1)][std::size_t(face)], ELLIPSOID_NOISE_SIZE >> l1, s, t), w);
        }
    }

    float EllipsoidNoiseMaps::sampleAlpha(const glm::vec3& dir, float lod) const
    {
        return trilinear<1>(alpha, dir, lod).x;
    }

    glm::vec3 EllipsoidNoiseMaps::sampleNormal(const glm::vec3& dir, float lod) const
    {
        return 2.0f * glm::vec3(trilinear<4>(normal, dir, lod)) - 1.0f;
    }

    const EllipsoidNoiseMaps& ellipsoidNoiseMaps()
    {
        static const EllipsoidNoiseMaps maps = build();
        return maps;
    }

    float ellipsoidNoiseBaseLod(float leafWeight)
    {
        const float l = 0.5f * (1.0f + std::log2(std::max(std::isfinite(leafWeight) ? leafWeight : 0.0f, 1e-6f)));
        return std::clamp(std::log2(float(ELLIPSOID_NOISE_SIZE)) - l, 0.0f, float(ELLIPSOID_NOISE_LEVELS - 1));
    }

    float ellipsoidNoiseFootprintLod(float pixelSize, float radius)
    {
        return std::log2(std::max(pixelSize, 1e-30f) * float(ELLIPSOID_NOISE_SIZE) / (2.0f * std::max(radius, 1e-30f)));
    }
}
