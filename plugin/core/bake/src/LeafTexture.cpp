// Procedural leaf and bark textures (see LeafTexture.h for the layout contract).
//
// Leaf shapes are inside/outside tests in leaf coordinates (X across, in leaf lengths,
// Y from the petiole end 0 to the tip 1), so shapes keep their proportions on a quad of
// aspect leafAspect(). Coverage is supersampled for an anti-aliased alpha edge; colour is
// evaluated at the texel centre everywhere and then bled outwards into the empty texels.
#include "TreeLod/LeafTexture.h"

#include "TreeLod/Colour.h"
#include "TreeLod/Image.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace TreeLod
{
    namespace
    {

        float clamp01(float v) { return std::clamp(v, 0.0f, 1.0f); }
        float fract(float v) { return v - std::floor(v); }
        float smoothstep(float a, float b, float x)
        {
            const float t = clamp01((x - a) / (b - a));
            return t * t * (3.0f - 2.0f * t);
        }
        glm::vec3 rgb(int r, int g, int b) { return glm::vec3(float(r), float(g), float(b)) / 255.0f; }

        /// Integer hash to [0, 1) (deterministic, no state).
        float hash2(int x, int y, int salt)
        {
            std::uint32_t h = std::uint32_t(x) * 0x8da6b343u ^ std::uint32_t(y) * 0xd8163841u ^ std::uint32_t(salt) * 0xcb1ab31fu;
            h ^= h >> 13;
            h *= 0x5bd1e995u;
            h ^= h >> 15;
            return float(h >> 8) * (1.0f / 16777216.0f);
        }

        /// Value noise on a lattice that wraps every `periodX` x `periodY` cells, so the
        /// result tiles when x and y span whole periods.
        float tileNoise(float x, float y, int periodX, int periodY, int salt)
        {
            const float fx = std::floor(x), fy = std::floor(y);
            const float tx = x - fx, ty = y - fy;
            const float sx = tx * tx * (3.0f - 2.0f * tx), sy = ty * ty * (3.0f - 2.0f * ty);
            auto wrap = [](int v, int p) { return ((v % p) + p) % p; };
            const int x0 = wrap(int(fx), periodX), x1 = wrap(int(fx) + 1, periodX);
            const int y0 = wrap(int(fy), periodY), y1 = wrap(int(fy) + 1, periodY);
            const float a = hash2(x0, y0, salt), b = hash2(x1, y0, salt);
            const float c = hash2(x0, y1, salt), d = hash2(x1, y1, salt);
            return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
        }

        /// Fractal sum of tiling noise: u, v in [0, 1) texture units, base lattice fx x fy.
        float tileFbm(float u, float v, int fx, int fy, int octaves, int salt)
        {
            float sum = 0.0f, amplitude = 0.5f, norm = 0.0f;
            for (int o = 0; o < octaves; ++o)
            {
                const int px = fx << o, py = fy << o;
                sum += amplitude * tileNoise(u * float(px), v * float(py), px, py, salt + o);
                norm += amplitude;
                amplitude *= 0.5f;
            }
            return sum / norm;
        }

        float distanceToSegment(glm::vec2 p, glm::vec2 a, glm::vec2 b, float& along)
        {
            const glm::vec2 ab = b - a;
            along = clamp01(glm::dot(p - a, ab) / glm::dot(ab, ab));
            return glm::length(p - (a + ab * along));
        }

        struct LeafStyle
        {
            glm::vec3 baseColour, tipColour, veinColour, petioleColour;
        };

        LeafStyle leafStyle(TreePreset preset)
        {
            switch (preset)
            {
            case TreePreset::Oak: return {rgb(52, 88, 30), rgb(84, 120, 44), rgb(132, 152, 76), rgb(96, 96, 48)};
            case TreePreset::Conifer: return {rgb(30, 62, 34), rgb(52, 92, 46), rgb(70, 110, 60), rgb(98, 72, 48)};
            case TreePreset::Birch: return {rgb(72, 118, 38), rgb(112, 152, 56), rgb(150, 176, 90), rgb(110, 100, 50)};
            case TreePreset::Shrub: return {rgb(50, 100, 40), rgb(80, 130, 52), rgb(120, 160, 80), rgb(90, 100, 50)};
            }
            return {};
        }

        /// Blade half-width (in leaf lengths) at s in [0, 1] along the blade.
        float bladeHalfWidth(TreePreset preset, float s, bool leftSide, float aspect)
        {
            if (s <= 0.0f || s >= 1.0f)
                return 0.0f;
            const float maxHalf = 0.5f * aspect * 0.96f;
            switch (preset)
            {
            case TreePreset::Oak:
            {
                // Obovate envelope, widest past the middle, with 4-5 rounded lobes per
                // side (sides offset by a quarter lobe, as real lobes alternate).
                const float envelope = std::pow(std::sin(glm::pi<float>() * std::pow(s, 0.75f)), 0.7f) * (0.7f + 0.3f * s);
                const float phase = leftSide ? 0.0f : 0.6f;
                const float lobe = 0.5f + 0.5f * std::cos(2.0f * glm::pi<float>() * 4.5f * s + phase);
                return maxHalf * envelope * (0.55f + 0.45f * std::pow(lobe, 0.7f));
            }
            case TreePreset::Birch:
            {
                // Ovate, widest at a third, drawn-out tip, double-serrate margin.
                const float envelope = std::pow(std::sin(glm::pi<float>() * std::pow(s, 0.62f)), 0.85f);
                const float teeth = 1.0f - 0.045f * fract(s * 16.0f) - 0.025f * fract(s * 32.0f);
                return maxHalf * envelope * teeth;
            }
            case TreePreset::Shrub:
            default:
                return maxHalf * std::pow(std::sin(glm::pi<float>() * std::pow(s, 0.8f)), 0.8f);
            }
        }

        constexpr float kPetiole = 0.1f; ///< petiole length, fraction of the leaf

        /// Conifer spray: a twig up the middle with needles on both sides, angled forward.
        struct Needle
        {
            glm::vec2 a, b;
        };

        std::vector<Needle> sprayNeedles(float aspect)
        {
            std::vector<Needle> needles;
            const float reach = 0.5f * aspect * 0.92f;
            int i = 0;
            for (float y = 0.04f; y < 0.9f; y += 0.02f, ++i)
            {
                for (int side = -1; side <= 1; side += 2)
                {
                    // Forward-angled needles that reach at most `reach` sideways and stay
                    // below the top edge; shorter towards the tip of the spray.
                    const float angle = glm::radians(52.0f + 14.0f * hash2(i, side, 7)); // from the twig
                    const glm::vec2 dir(float(side) * std::sin(angle), std::cos(angle));
                    float length = reach * (1.0f - 0.4f * y) * (0.85f + 0.15f * hash2(i, side, 9)) / dir.x * float(side);
                    length = std::min(length, (0.97f - y) / dir.y);
                    const glm::vec2 a(0.0f, y + 0.01f * float(side));
                    needles.push_back({a, a + dir * length});
                }
            }
            // A tuft at the tip.
            for (int k = -2; k <= 2; ++k)
            {
                const float angle = glm::radians(14.0f * float(k));
                const glm::vec2 a(0.0f, 0.9f);
                needles.push_back({a, a + glm::vec2(std::sin(angle), std::cos(angle)) * 0.085f});
            }
            return needles;
        }

        /// Distance to the nearest needle (and how far along it), or to the twig.
        float sprayDistance(const std::vector<Needle>& needles, glm::vec2 p, float& along, bool& twig)
        {
            float best = 1e9f;
            along = 0.0f;
            twig = false;
            for (const Needle& n : needles)
            {
                if (p.y < std::min(n.a.y, n.b.y) - 0.02f || p.y > std::max(n.a.y, n.b.y) + 0.02f)
                    continue;
                float t;
                const float d = distanceToSegment(p, n.a, n.b, t) + 0.006f * t; // needles taper
                if (d < best)
                {
                    best = d;
                    along = t;
                }
            }
            float t;
            const float dTwig = distanceToSegment(p, {0.0f, 0.0f}, {0.0f, 0.93f}, t) - 0.006f * (1.0f - t);
            if (dTwig < best)
            {
                best = dTwig;
                twig = true;
            }
            return best;
        }
    }

    float leafAspect(TreePreset preset)
    {
        switch (preset)
        {
        case TreePreset::Oak: return 0.62f;
        case TreePreset::Conifer: return 0.7f;
        case TreePreset::Birch: return 0.68f;
        case TreePreset::Shrub: return 0.55f;
        }
        return 0.6f;
    }

    TextureImage drawLeafTexture(TreePreset preset, int size)
    {
        size = std::max(size, 4);
        const float aspect = leafAspect(preset);
        const LeafStyle style = leafStyle(preset);
        const bool spray = preset == TreePreset::Conifer;
        const int ss = size <= 1024 ? 4 : 2; // supersampling per axis for the alpha edge
        const std::vector<Needle> needles = spray ? sprayNeedles(aspect) : std::vector<Needle>();
        const float needleHalf = 0.011f;
        const float texel = 1.0f / float(size);

        // Leaf coordinates: X = (u - 0.5) * aspect across, Y = 1 - v from the petiole end.
        std::vector<glm::vec3> colour(std::size_t(size) * size);
        std::vector<float> alpha(std::size_t(size) * size);
        std::vector<Needle> rowNeedles;
        std::vector<glm::vec2> halfWidths(std::size_t(ss) + 1); // per sub-row (+ centre): left, right
        for (int py = 0; py < size; ++py)
        {
            const float yCentre = 1.0f - (float(py) + 0.5f) * texel;
            // What a row needs, once per row: the needles that can reach it, or the
            // blade's half-widths on both sides at each sub-row and at the centre.
            if (spray)
            {
                rowNeedles.clear();
                for (const Needle& n : needles)
                    if (yCentre + texel + needleHalf >= std::min(n.a.y, n.b.y) - 0.02f &&
                        yCentre - texel - needleHalf <= std::max(n.a.y, n.b.y) + 0.02f)
                        rowNeedles.push_back(n);
            }
            else
                for (int sy = 0; sy <= ss; ++sy)
                {
                    const float y = sy < ss ? 1.0f - (float(py) + (float(sy) + 0.5f) / float(ss)) * texel : yCentre;
                    float left = 0.0f, right = 0.0f;
                    if (y >= 0.0f && y <= 0.985f)
                    {
                        if (y < kPetiole + 0.02f)
                            left = right = 0.012f;
                        const float s = (y - kPetiole) / (0.985f - kPetiole);
                        left = std::max(left, bladeHalfWidth(preset, s, true, aspect));
                        right = std::max(right, bladeHalfWidth(preset, s, false, aspect));
                    }
                    halfWidths[std::size_t(sy)] = {left, right};
                }

            for (int px = 0; px < size; ++px)
            {
                const glm::vec2 c(((float(px) + 0.5f) * texel - 0.5f) * aspect, yCentre);
                float centreAlong = 0.0f, centreDistance = 0.0f;
                bool centreTwig = false;
                if (spray)
                    centreDistance = sprayDistance(rowNeedles, c, centreAlong, centreTwig);
                // The spray's distance changes at most ~1 per unit, so texels whose centre is
                // farther than a texel diagonal from the edge are wholly in or out.
                const float margin = 0.8f * texel * std::max(1.0f, aspect);
                int inside = 0;
                if (spray && centreDistance < needleHalf - margin)
                    inside = ss * ss;
                else if (!spray || centreDistance <= needleHalf + margin)
                {
                    for (int sy = 0; sy < ss; ++sy)
                        for (int sx = 0; sx < ss; ++sx)
                        {
                            const float x = ((float(px) + (float(sx) + 0.5f) / float(ss)) * texel - 0.5f) * aspect;
                            if (spray)
                            {
                                const float y = 1.0f - (float(py) + (float(sy) + 0.5f) / float(ss)) * texel;
                                float along;
                                bool twig;
                                inside += sprayDistance(rowNeedles, {x, y}, along, twig) < needleHalf ? 1 : 0;
                            }
                            else
                            {
                                const glm::vec2 hw = halfWidths[std::size_t(sy)];
                                inside += std::abs(x) < (x < 0.0f ? hw.x : hw.y) ? 1 : 0;
                            }
                        }
                }
                const std::size_t i = std::size_t(py) * size + px;
                alpha[i] = float(inside) / float(ss * ss);

                // Colour at the texel centre.
                const float noise = tileNoise(c.x * 40.0f, c.y * 40.0f, 1 << 20, 1 << 20, 3) - 0.5f;
                glm::vec3 col;
                if (spray)
                    col = centreTwig ? style.petioleColour
                                     : glm::mix(style.baseColour, style.tipColour,
                                                0.3f + 0.5f * centreAlong + 0.2f * c.y);
                else if (c.y < kPetiole)
                    col = style.petioleColour;
                else
                {
                    const float s = (c.y - kPetiole) / (0.985f - kPetiole);
                    col = glm::mix(style.baseColour, style.tipColour, smoothstep(0.0f, 1.0f, s));
                    const glm::vec2 hw = halfWidths[std::size_t(ss)];
                    const float edge = std::abs(c.x) / std::max(1e-3f, c.x < 0.0f ? hw.x : hw.y);
                    col *= 1.0f - 0.12f * smoothstep(0.6f, 1.0f, edge); // darker rim
                    // Midrib, tapering to the tip.
                    const float midrib = 1.0f - smoothstep(0.0f, 0.008f + 0.006f * (1.0f - s), std::abs(c.x));
                    // Side veins running forward from the midrib.
                    const float period = preset == TreePreset::Oak ? 1.0f / 9.0f : 1.0f / 11.0f;
                    const float phase = fract((c.y - 0.9f * std::abs(c.x)) / period);
                    const float vein = (1.0f - smoothstep(0.0f, 0.09f, std::min(phase, 1.0f - phase))) *
                                       (1.0f - smoothstep(0.75f, 1.0f, edge)) * 0.6f;
                    col = glm::mix(col, style.veinColour, clamp01(std::max(midrib, vein)));
                }
                colour[i] = glm::clamp(col * (1.0f + 0.16f * noise), glm::vec3(0.0f), glm::vec3(1.0f));
            }
        }

        // Bleed colour into empty texels: 16 rings outwards, each texel the mean of its
        // already coloured 8-neighbours; beyond that the mean leaf colour. Only the
        // frontier is visited, so the cost is proportional to the texels coloured.
        glm::vec3 mean(0.0f);
        double weight = 0.0;
        std::vector<char> known(alpha.size());
        for (std::size_t i = 0; i < alpha.size(); ++i)
        {
            known[i] = alpha[i] > 0.0f;
            mean += colour[i] * alpha[i];
            weight += alpha[i];
        }
        mean = weight > 0.0 ? mean / float(weight) : style.baseColour;
        auto forNeighbours = [size](std::size_t i, auto&& visit) {
            const int px = int(i % std::size_t(size)), py = int(i / std::size_t(size));
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                {
                    const int x = px + dx, y = py + dy;
                    if ((dx != 0 || dy != 0) && x >= 0 && y >= 0 && x < size && y < size)
                        visit(std::size_t(y) * std::size_t(size) + std::size_t(x));
                }
        };
        std::vector<char> queued(alpha.size(), 0);
        std::vector<std::size_t> frontier, next;
        for (std::size_t i = 0; i < alpha.size(); ++i)
            if (!known[i])
                forNeighbours(i, [&](std::size_t j) {
                    if (known[j] && !queued[i])
                    {
                        queued[i] = 1;
                        frontier.push_back(i);
                    }
                });
        std::vector<glm::vec3> filled;
        for (int ring = 0; ring < 16 && !frontier.empty(); ++ring)
        {
            filled.assign(frontier.size(), glm::vec3(0.0f));
            for (std::size_t k = 0; k < frontier.size(); ++k)
            {
                glm::vec3 sum(0.0f);
                int n = 0;
                forNeighbours(frontier[k], [&](std::size_t j) {
                    if (known[j])
                    {
                        sum += colour[j];
                        ++n;
                    }
                });
                filled[k] = sum / float(std::max(n, 1));
            }
            next.clear();
            for (std::size_t k = 0; k < frontier.size(); ++k)
            {
                colour[frontier[k]] = filled[k];
                known[frontier[k]] = 1;
            }
            for (std::size_t i : frontier)
                forNeighbours(i, [&](std::size_t j) {
                    if (!known[j] && !queued[j])
                    {
                        queued[j] = 1;
                        next.push_back(j);
                    }
                });
            frontier.swap(next);
        }

        TextureImage image;
        image.name = std::string(presetName(preset)) + "_leaf.png";
        image.width = size;
        image.height = size;
        image.rgba.resize(std::size_t(size) * size * 4);
        for (std::size_t i = 0; i < alpha.size(); ++i)
        {
            const glm::vec3 c = known[i] ? colour[i] : mean;
            image.rgba[i * 4 + 0] = unitToByte(c.r);
            image.rgba[i * 4 + 1] = unitToByte(c.g);
            image.rgba[i * 4 + 2] = unitToByte(c.b);
            image.rgba[i * 4 + 3] = unitToByte(alpha[i]);
        }
        return image;
    }

    TextureImage drawBarkTexture(TreePreset preset, int width, int height)
    {
        width = std::max(width, 4);
        height = std::max(height, 4);
        TextureImage image;
        image.name = std::string(presetName(preset)) + "_bark.png";
        image.width = width;
        image.height = height;
        image.rgba.resize(std::size_t(width) * height * 4);
        for (int py = 0; py < height; ++py)
            for (int px = 0; px < width; ++px)
            {
                const float u = (float(px) + 0.5f) / float(width);  // around the stem
                const float v = (float(py) + 0.5f) / float(height); // along the stem
                const float n = tileFbm(u, v, 8, 8, 4, 11);
                glm::vec3 col;
                switch (preset)
                {
                case TreePreset::Oak:
                {
                    // Deep vertical furrows between ridges that wander along the stem.
                    const float warp = tileFbm(u, v, 4, 3, 3, 21) - 0.5f;
                    const float ridge = std::abs(std::sin(glm::pi<float>() * (u * 9.0f + warp * 2.5f)));
                    const float furrow = smoothstep(0.15f, 0.6f, ridge);
                    col = glm::mix(rgb(38, 30, 24), rgb(108, 94, 78), furrow * (0.7f + 0.6f * n));
                    break;
                }
                case TreePreset::Conifer:
                {
                    // Red-brown plates separated by dark cracks.
                    const float cells = tileFbm(u, v, 6, 10, 2, 31);
                    const float crack = smoothstep(0.03f, 0.09f, std::abs(cells - 0.5f));
                    col = glm::mix(rgb(52, 32, 24), rgb(128, 78, 52), crack) * (0.8f + 0.4f * n);
                    break;
                }
                case TreePreset::Birch:
                {
                    // White with dark horizontal lenticels (dashes around the stem) and a
                    // few dark patches.
                    col = rgb(222, 220, 212) * (0.9f + 0.15f * n);
                    const int cx = int(u * 6.0f), cy = int(v * 28.0f);
                    const float fy = v * 28.0f - float(cy), fx = u * 6.0f - float(cx);
                    const float length = 0.25f + 0.5f * hash2(cx, cy, 41);
                    const float startX = hash2(cx, cy, 43) * (1.0f - length);
                    const bool dash = hash2(cx, cy, 47) < 0.55f && std::abs(fy - 0.5f) < 0.09f &&
                                      fx > startX && fx < startX + length;
                    if (dash)
                        col = rgb(40, 34, 32);
                    const float patch = tileFbm(u, v, 4, 12, 3, 53);
                    col = glm::mix(col, rgb(60, 55, 50), smoothstep(0.7f, 0.74f, patch));
                    break;
                }
                case TreePreset::Shrub:
                default:
                    col = glm::mix(rgb(70, 62, 52), rgb(120, 108, 90), n);
                    break;
                }
                col = glm::clamp(col, glm::vec3(0.0f), glm::vec3(1.0f));
                const std::size_t i = (std::size_t(py) * width + px) * 4;
                image.rgba[i + 0] = unitToByte(col.r);
                image.rgba[i + 1] = unitToByte(col.g);
                image.rgba[i + 2] = unitToByte(col.b);
                image.rgba[i + 3] = 255;
            }
        return image;
    }

    glm::vec3 leafMeanColour(const TextureImage& leafTexture)
    {
        glm::dvec3 sum(0.0);
        double weight = 0.0;
        for (std::size_t i = 0; i + 3 < leafTexture.rgba.size(); i += 4)
        {
            const double a = leafTexture.rgba[i + 3] / 255.0;
            if (a < 0.5)
                continue;
            for (int c = 0; c < 3; ++c)
                sum[c] += a * srgbByteToLinear(leafTexture.rgba[i + std::size_t(c)]);
            weight += a;
        }
        return weight > 0.0 ? glm::vec3(sum / weight) : glm::vec3(0.1f, 0.2f, 0.05f);
    }
}
