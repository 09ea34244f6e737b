// Placements: uniform and Thomas-clustered scattering over rect and disc areas with
// exclusions, explicit trees, and the heightfield ground they stand on.
//
// This work is based on:
//   M. Thomas, "A generalization of Poisson's binomial limit for use in ecology",
//   Biometrika 36, 1949 (parents uniform, offspring Gaussian around them), the clumped
//   point process of forest ecology; here with a fixed total count instead of Poisson counts.
#include "Placement.h"

#include "SceneScriptDetail.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace TreeLod
{
    namespace SceneScriptDetail
    {
        bool excluded(const std::vector<SceneArea>& exclude, const glm::vec2& p)
        {
            for (const SceneArea& e : exclude)
                if (e.contains(p))
                    return true;
            return false;
        }

        double freeArea(const SceneArea& area, const std::vector<SceneArea>& exclude)
        {
            if (exclude.empty())
                return area.areaM2();
            glm::vec2 lo = area.kind == SceneArea::Kind::Rect ? area.min : area.centre - glm::vec2(area.radius);
            glm::vec2 hi = area.kind == SceneArea::Kind::Rect ? area.max : area.centre + glm::vec2(area.radius);
            const int n = 512;
            std::size_t free = 0;
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x)
                {
                    glm::vec2 p = lo + (hi - lo) * glm::vec2((x + 0.5f) / n, (y + 0.5f) / n);
                    free += area.contains(p) && !excluded(exclude, p);
                }
            return double(hi.x - lo.x) * double(hi.y - lo.y) * double(free) / (double(n) * n);
        }
    }

    namespace
    {
        using namespace SceneScriptDetail;

        /// Uniform in [0, 1) from two 32-bit draws (53 bits), in a fixed order.
        double uniform(std::mt19937& rng)
        {
            std::uint64_t a = rng() >> 5, b = rng() >> 6;
            return double(a * 67108864ull + b) / 9007199254740992.0;
        }

        /// Standard normal pair by Box-Muller.
        glm::dvec2 gaussian(std::mt19937& rng)
        {
            double u = 1.0 - uniform(rng), v = uniform(rng);
            double r = std::sqrt(-2.0 * std::log(u));
            return glm::dvec2(r * std::cos(2.0 * PI * v), r * std::sin(2.0 * PI * v));
        }

        glm::vec2 uniformIn(const SceneArea& a, std::mt19937& rng)
        {
            double u = uniform(rng), v = uniform(rng);
            if (a.kind == SceneArea::Kind::Rect)
                return glm::vec2(float(a.min.x + u * (a.max.x - a.min.x)), float(a.min.y + v * (a.max.y - a.min.y)));
            double r2 = double(a.innerRadius) * a.innerRadius;
            double r = std::sqrt(r2 + u * (double(a.radius) * a.radius - r2));
            return a.centre + glm::vec2(float(r * std::cos(2.0 * PI * v)), float(r * std::sin(2.0 * PI * v)));
        }

        /// A free point: uniform in the area outside the exclusions (rejection; after 1000
        /// misses, which freeArea() > 0 makes vanishingly rare, the last point is kept).
        glm::vec2 freePoint(const ScenePlacement& p, std::mt19937& rng)
        {
            glm::vec2 q = uniformIn(p.area, rng);
            for (int tries = 0; tries < 1000 && excluded(p.exclude, q); ++tries)
                q = uniformIn(p.area, rng);
            return q;
        }

        /// `n` positions of a random placement. clumping 0: uniform. clumping c > 0: a Thomas
        /// process with a fixed total: k = round(n / (1 + 19c)) cluster centres uniform in the
        /// free area, each tree joins a random cluster and lies at a Gaussian offset of
        /// sigma = (0.25 - 0.1875c) * sqrt(freeArea / k) (a quarter of the cluster spacing at
        /// c -> 0, a sixteenth at c = 1); offsets outside the free area are drawn again.
        std::vector<glm::vec2> samplePositions(const ScenePlacement& p, std::uint32_t n, std::mt19937& rng)
        {
            std::vector<glm::vec2> out;
            out.reserve(n);
            if (p.clumping <= 0.0f)
            {
                for (std::uint32_t i = 0; i < n; ++i)
                    out.push_back(freePoint(p, rng));
                return out;
            }
            const std::uint32_t k =
                std::max<std::uint32_t>(1, std::uint32_t(std::lround(n / (1.0 + 19.0 * p.clumping))));
            // The parser's figure; a placement built in code (freeAreaM2 0) is sampled here.
            const double free = p.freeAreaM2 > 0.0 ? p.freeAreaM2 : freeArea(p.area, p.exclude);
            std::vector<glm::vec2> centres;
            for (std::uint32_t i = 0; i < k; ++i)
                centres.push_back(freePoint(p, rng));
            const double sigma = (0.25 - 0.1875 * p.clumping) * std::sqrt(free / k);
            for (std::uint32_t i = 0; i < n; ++i)
            {
                glm::vec2 q;
                bool placed = false;
                for (int tries = 0; tries < 100 && !placed; ++tries)
                {
                    const glm::vec2& c = centres[std::min<std::uint32_t>(k - 1, std::uint32_t(uniform(rng) * k))];
                    glm::dvec2 g = gaussian(rng) * sigma;
                    q = c + glm::vec2(g);
                    placed = p.area.contains(q) && !excluded(p.exclude, q);
                }
                out.push_back(placed ? q : freePoint(p, rng));
            }
            return out;
        }
    }

    bool SceneArea::contains(const glm::vec2& p) const
    {
        if (kind == Kind::Rect)
            return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y;
        float d = glm::length(p - centre);
        return d <= radius && d >= innerRadius;
    }

    float SceneArea::areaM2() const
    {
        if (kind == Kind::Rect)
            return (max.x - min.x) * (max.y - min.y);
        return float(PI * (double(radius) * radius - double(innerRadius) * innerRadius));
    }

    float groundHeight(const SceneGround& ground, float x, float z)
    {
        if (ground.kind == SceneGround::Kind::Plane || ground.heights.empty())
            return 0.0f;
        const int w = ground.heightsWidth, h = ground.heightsHeight;
        float u = glm::clamp((x / ground.size + 0.5f) * float(w - 1), 0.0f, float(w - 1));
        float v = glm::clamp((z / ground.size + 0.5f) * float(h - 1), 0.0f, float(h - 1));
        int x0 = std::min(int(u), w - 2), y0 = std::min(int(v), h - 2);
        float fx = u - float(x0), fy = v - float(y0);
        auto at = [&](int px, int py) { return ground.heights[std::size_t(py) * w + px]; };
        float top = at(x0, y0) + fx * (at(x0 + 1, y0) - at(x0, y0));
        float bottom = at(x0, y0 + 1) + fx * (at(x0 + 1, y0 + 1) - at(x0, y0 + 1));
        return ground.heightScale * (top + fy * (bottom - top));
    }

    std::vector<PlacedTree> generatePlacements(const SceneScript& script, const PlacementOptions& options)
    {
        // Tree counts per placement: explicit ones as listed, random ones from the script,
        // then the total (largest remainder over the random placements), then the scale.
        std::vector<std::uint64_t> counts;
        std::uint64_t explicitTotal = 0, randomTotal = 0;
        for (const ScenePlacement& p : script.placements)
        {
            counts.push_back(p.random ? p.count : p.positions.size());
            (p.random ? randomTotal : explicitTotal) += counts.back();
        }
        if (options.totalCount > 0)
        {
            std::uint64_t keepExplicit = std::min<std::uint64_t>(options.totalCount, explicitTotal);
            std::uint64_t wantRandom = options.totalCount - keepExplicit;
            std::vector<std::pair<double, std::size_t>> remainders;
            std::uint64_t given = 0;
            for (std::size_t i = 0; i < counts.size(); ++i)
            {
                if (script.placements[i].random)
                {
                    double exact = randomTotal ? double(wantRandom) * double(counts[i]) / double(randomTotal) : 0.0;
                    counts[i] = std::uint64_t(exact);
                    given += counts[i];
                    remainders.emplace_back(-(exact - std::floor(exact)), i); // largest first, then script order
                }
                else
                {
                    counts[i] = std::min<std::uint64_t>(counts[i], keepExplicit);
                    keepExplicit -= counts[i];
                }
            }
            std::sort(remainders.begin(), remainders.end());
            for (std::size_t r = 0; given < wantRandom && r < remainders.size(); ++r, ++given)
                ++counts[remainders[r].second];
        }
        if (options.scale != 1.0 && options.scale > 0.0)
            for (std::size_t i = 0; i < counts.size(); ++i)
                if (script.placements[i].random && counts[i] > 0)
                    counts[i] =
                        std::max<std::uint64_t>(1, std::uint64_t(std::llround(double(counts[i]) * options.scale)));

        std::vector<PlacedTree> trees;
        // Explicit placements first, then random ones, each in script order.
        for (int pass = 0; pass < 2; ++pass)
            for (std::size_t i = 0; i < script.placements.size(); ++i)
            {
                const ScenePlacement& p = script.placements[i];
                if (p.random != (pass == 1))
                    continue;
                if (!p.random)
                {
                    for (std::size_t k = 0; k < counts[i]; ++k)
                    {
                        const glm::vec4& e = p.positions[k];
                        const float y = p.positionY.empty() || std::isnan(p.positionY[k])
                                            ? groundHeight(script.ground, e.x, e.y)
                                            : p.positionY[k];
                        trees.push_back({p.positionSpecies.empty() ? p.species[0] : p.positionSpecies[k],
                                         glm::vec3(e.x, y, e.y), e.z, e.w});
                    }
                    continue;
                }
                std::mt19937 rng(p.seed);
                std::vector<glm::vec2> positions = samplePositions(p, std::uint32_t(counts[i]), rng);
                for (const glm::vec2& q : positions)
                {
                    PlacedTree t;
                    t.species = p.species[std::min<std::size_t>(p.species.size() - 1,
                                                                std::size_t(uniform(rng) * p.species.size()))];
                    t.position = glm::vec3(q.x, groundHeight(script.ground, q.x, q.y), q.y);
                    t.rotation = float(uniform(rng) * 2.0 * PI);
                    const SceneSpecies& s = script.species[t.species];
                    t.scale = float(s.scaleMin + uniform(rng) * (s.scaleMax - s.scaleMin));
                    trees.push_back(t);
                }
            }
        return trees;
    }
}
