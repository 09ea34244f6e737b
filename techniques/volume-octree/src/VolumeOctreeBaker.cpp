// VolumeOctreeBaker: the volumetric octree tree's reconstruction and compression (steps in
// VolumeOctreeBaker.h, format in VolumeOctreeData.h).
#include "TreeLod/VolumeOctreeBaker.h"

#include "TreeLod/Package.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        const char* const CHUNK = VOLUME_OCTREE_CHUNK;
        /// Pixel alpha is clamped below 1 so that its optical depth -log(1 - a) stays finite.
        constexpr double MAX_ALPHA = 0.999;
        /// Cells whose optical depth the tomography leaves below this are empty.
        constexpr double MIN_DEPTH = 1e-5;

        Result<void> checkOptions(const VolumeOctreeOptions& o, const std::string& label)
        {
            const std::string option = std::string(CHUNK) + " option ";
            if (o.levelCount < 1 || o.levelCount > VOLUME_OCTREE_MAX_LEVELS)
                return fail(label, option + "levelCount",
                            std::to_string(o.levelCount) + " is outside [1, " +
                                std::to_string(VOLUME_OCTREE_MAX_LEVELS) + "]");
            if (o.tomographyIterations > 32)
                return fail(label, option + "tomographyIterations",
                            std::to_string(o.tomographyIterations) + " is outside [0, 32]");
            if (!(o.pruneAlpha > 0.0f && o.pruneAlpha <= 1.0f))
                return fail(label, option + "pruneAlpha", std::to_string(o.pruneAlpha) + " is outside (0, 1]");
            for (std::uint32_t k : {o.quantisation.colourCodebookSize, o.quantisation.alphaCodebookSize})
                if (k < 1 || k > 16384)
                    return fail(label, option + "codebookSize", std::to_string(k) + " is outside [1, 16384]");
            if (o.quantisation.maxIterations < 1)
                return fail(label, option + "iterations", "at least 1 GLA iteration is needed");
            if (o.maxCells < 1)
                return fail(label, option + "maxCells", "must be at least 1");
            return {};
        }

        // ---- image pyramids --------------------------------------------------------------

        /// Per capture image: mean premultiplied linear RGBA and max alpha, level 0 the image,
        /// each level the 2x2 mean (max) of the one below (an odd edge's last texel alone).
        struct Pyramid
        {
            std::vector<int> width, height;
            std::vector<std::vector<glm::vec4>> mean;
            std::vector<std::vector<float>> maxAlpha;

            int levels() const { return int(width.size()); }
        };

        Pyramid buildPyramid(const Image& image)
        {
            Pyramid p;
            p.width.push_back(image.width);
            p.height.push_back(image.height);
            std::vector<glm::vec4> mean(image.pixels.size());
            std::vector<float> maxAlpha(image.pixels.size());
            for (std::size_t i = 0; i < image.pixels.size(); ++i)
            {
                const glm::vec4& c = image.pixels[i];
                const float a = std::clamp(c.a, 0.0f, 1.0f);
                mean[i] = glm::vec4(srgbToLinear(c.r) * a, srgbToLinear(c.g) * a, srgbToLinear(c.b) * a, a);
                maxAlpha[i] = a;
            }
            p.mean.push_back(std::move(mean));
            p.maxAlpha.push_back(std::move(maxAlpha));
            while (p.width.back() > 1 || p.height.back() > 1)
            {
                const int w = p.width.back(), h = p.height.back();
                const int nw = std::max(1, (w + 1) / 2), nh = std::max(1, (h + 1) / 2);
                const std::vector<glm::vec4>& m = p.mean.back();
                const std::vector<float>& x = p.maxAlpha.back();
                std::vector<glm::vec4> nm(std::size_t(nw) * nh);
                std::vector<float> nx(nm.size());
                for (int y = 0; y < nh; ++y)
                    for (int xx = 0; xx < nw; ++xx)
                    {
                        glm::vec4 sum(0.0f);
                        float mx = 0.0f;
                        int n = 0;
                        for (int dy = 0; dy < 2; ++dy)
                            for (int dx = 0; dx < 2; ++dx)
                            {
                                const int sx = 2 * xx + dx, sy = 2 * y + dy;
                                if (sx >= w || sy >= h)
                                    continue;
                                sum += m[std::size_t(sy) * w + sx];
                                mx = std::max(mx, x[std::size_t(sy) * w + sx]);
                                ++n;
                            }
                        nm[std::size_t(y) * nw + xx] = sum / float(n);
                        nx[std::size_t(y) * nw + xx] = mx;
                    }
                p.width.push_back(nw);
                p.height.push_back(nh);
                p.mean.push_back(std::move(nm));
                p.maxAlpha.push_back(std::move(nx));
            }
            return p;
        }

        /// Bilinear sample of level m at level-0 pixel coordinates (u, v); outside the image is
        /// transparent.
        glm::vec4 sampleLevel(const Pyramid& p, int m, double u, double v)
        {
            const double scale = double(1 << m);
            const double x = u / scale - 0.5, y = v / scale - 0.5;
            const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
            const float fx = float(x - x0), fy = float(y - y0);
            const int w = p.width[m], h = p.height[m];
            const auto at = [&](int xx, int yy) {
                return xx < 0 || yy < 0 || xx >= w || yy >= h ? glm::vec4(0.0f)
                                                               : p.mean[m][std::size_t(yy) * w + xx];
            };
            return (1.0f - fy) * ((1.0f - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                   fy * ((1.0f - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
        }

        /// The image's mean over a footprint of `footprint` pixels about (u, v): trilinear.
        glm::vec4 sampleMean(const Pyramid& p, double u, double v, double footprint)
        {
            const double lod = std::clamp(std::log2(std::max(footprint, 1.0)), 0.0, double(p.levels() - 1));
            const int m0 = int(std::floor(lod)), m1 = std::min(m0 + 1, p.levels() - 1);
            const float f = float(lod - m0);
            const glm::vec4 a = sampleLevel(p, m0, u, v);
            return f > 0.0f ? (1.0f - f) * a + f * sampleLevel(p, m1, u, v) : a;
        }

        /// The largest alpha within `radius` pixels of (u, v) (conservatively: the max-pyramid
        /// texels covering the square about it); -1 when the square lies outside the image.
        float maxAlphaNear(const Pyramid& p, double u, double v, double radius)
        {
            const int m = std::clamp(int(std::ceil(std::log2(std::max(2.0 * radius, 1.0)))), 0, p.levels() - 1);
            const double scale = double(1 << m);
            const int w = p.width[m], h = p.height[m];
            const int x0 = std::max(0, int(std::floor((u - radius) / scale)));
            const int x1 = std::min(w - 1, int(std::floor((u + radius) / scale)));
            const int y0 = std::max(0, int(std::floor((v - radius) / scale)));
            const int y1 = std::min(h - 1, int(std::floor((v + radius) / scale)));
            if (x0 > x1 || y0 > y1)
                return -1.0f;
            float best = 0.0f;
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                    best = std::max(best, p.maxAlpha[m][std::size_t(y) * w + x]);
            return best;
        }

        // ---- cells of one level --------------------------------------------------------

        /// Cell code -> index among a level's cells: a dense table up to 128 cells a side, open
        /// addressing beyond.
        class CellIndex
        {
        public:
            CellIndex(std::uint32_t side, const std::vector<std::uint32_t>& codes) : mSide(side)
            {
                if (side <= 128)
                {
                    mDense.assign(std::size_t(side) * side * side, -1);
                    for (std::size_t i = 0; i < codes.size(); ++i)
                    {
                        const glm::uvec3 c = volumeCellCoords(codes[i]);
                        mDense[(std::size_t(c.z) * side + c.y) * side + c.x] = std::int32_t(i);
                    }
                    return;
                }
                std::size_t capacity = 16;
                while (capacity < 2 * codes.size())
                    capacity *= 2;
                mKeys.assign(capacity, EMPTY);
                mValues.assign(capacity, -1);
                for (std::size_t i = 0; i < codes.size(); ++i)
                {
                    std::size_t at = slot(codes[i]);
                    while (mKeys[at] != EMPTY)
                        at = (at + 1) & (capacity - 1);
                    mKeys[at] = codes[i];
                    mValues[at] = std::int32_t(i);
                }
            }

            std::int32_t find(std::uint32_t x, std::uint32_t y, std::uint32_t z) const
            {
                if (!mDense.empty())
                    return mDense[(std::size_t(z) * mSide + y) * mSide + x];
                const std::uint32_t code = volumeCellCode(x, y, z);
                for (std::size_t at = slot(code);; at = (at + 1) & (mKeys.size() - 1))
                {
                    if (mKeys[at] == code)
                        return mValues[at];
                    if (mKeys[at] == EMPTY)
                        return -1;
                }
            }

        private:
            static constexpr std::uint32_t EMPTY = 0xFFFFFFFFu;
            std::size_t slot(std::uint32_t code) const
            {
                return std::size_t((std::uint64_t(code) * 0x9E3779B97F4A7C15ull) >> 40) & (mKeys.size() - 1);
            }
            std::uint32_t mSide;
            std::vector<std::int32_t> mDense;
            std::vector<std::uint32_t> mKeys;
            std::vector<std::int32_t> mValues;
        };

        /// The cells of a grid of `side` cells of `edge` metres from `origin` that the ray
        /// o + t d, t in [tMin, tMax], crosses, in order (Amanatides and Woo 1987): visit(x, y, z)
        /// returns false to stop.
        template <typename Visit>
        void walkGrid(const glm::dvec3& o, const glm::dvec3& d, double tMin, double tMax, const glm::dvec3& origin,
                      double edge, std::uint32_t side, Visit visit)
        {
            const double extent = edge * side;
            for (int a = 0; a < 3; ++a)
            {
                const double lo = (origin[a] - o[a]), hi = (origin[a] + extent - o[a]);
                if (std::abs(d[a]) < 1e-300)
                {
                    if (lo > 0.0 || hi < 0.0)
                        return;
                    continue;
                }
                double t0 = lo / d[a], t1 = hi / d[a];
                if (t0 > t1)
                    std::swap(t0, t1);
                tMin = std::max(tMin, t0);
                tMax = std::min(tMax, t1);
            }
            if (!(tMin < tMax))
                return;
            const glm::dvec3 start = o + d * tMin;
            int cell[3], step[3];
            double tNext[3], tDelta[3];
            for (int a = 0; a < 3; ++a)
            {
                cell[a] = std::clamp(int(std::floor((start[a] - origin[a]) / edge)), 0, int(side) - 1);
                if (d[a] > 0.0)
                {
                    step[a] = 1;
                    tNext[a] = (origin[a] + (cell[a] + 1) * edge - o[a]) / d[a];
                    tDelta[a] = edge / d[a];
                }
                else if (d[a] < 0.0)
                {
                    step[a] = -1;
                    tNext[a] = (origin[a] + cell[a] * edge - o[a]) / d[a];
                    tDelta[a] = -edge / d[a];
                }
                else
                {
                    step[a] = 0;
                    tNext[a] = std::numeric_limits<double>::infinity();
                    tDelta[a] = std::numeric_limits<double>::infinity();
                }
            }
            for (;;)
            {
                if (!visit(std::uint32_t(cell[0]), std::uint32_t(cell[1]), std::uint32_t(cell[2])))
                    return;
                const int a = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
                if (tNext[a] > tMax)
                    return;
                cell[a] += step[a];
                if (cell[a] < 0 || cell[a] >= int(side))
                    return;
                tNext[a] += tDelta[a];
            }
        }

        /// What a camera knows of a point: pixel, depth, and whether it may speak for a cell of
        /// half-diagonal `radius` around it (the whole cell in front of the camera).
        struct View
        {
            glm::dvec2 pixel{0.0};
            double depth = 0.0;
            bool sees = false;
        };

        View viewOf(const CaptureCamera& camera, const glm::dvec3& centre, double radius)
        {
            View v;
            v.sees = camera.project(centre, v.pixel, v.depth) && v.depth > radius;
            return v;
        }

        double focalOf(const CaptureCamera& camera) { return 0.5 * (camera.fx + camera.fy); }

        std::vector<std::uint32_t> childrenOf(const std::vector<std::uint32_t>& parents)
        {
            std::vector<std::uint32_t> children;
            children.reserve(parents.size() * 8);
            for (std::uint32_t p : parents)
            {
                const glm::uvec3 c = volumeCellCoords(p);
                for (std::uint32_t k = 0; k < 8; ++k) // Morton order of the children: x lowest
                    children.push_back(volumeCellCode(2 * c.x + (k & 1), 2 * c.y + ((k >> 1) & 1),
                                                      2 * c.z + ((k >> 2) & 1)));
            }
            return children;
        }

        std::uint8_t linearToSrgbByteOf(float linear) { return linearToSrgbByte(std::clamp(linear, 0.0f, 1.0f)); }
    }

    Result<VolumeOctreeReconstruction> reconstructVolumeOctree(const CaptureSet& capture,
                                                               const VolumeOctreeOptions& options,
                                                               const std::string& label,
                                                               const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = capture.validate(label); !valid)
            return valid.error();
        if (capture.cameras.size() > VOLUME_OCTREE_MAX_CAMERAS)
            return fail(label, "capture set", std::to_string(capture.cameras.size()) + " cameras, at most " +
                                                  std::to_string(VOLUME_OCTREE_MAX_CAMERAS) + " are supported");
        const std::size_t cameraCount = capture.cameras.size();

        // The root cube: the volume's box made cubic about its centre.
        const glm::dvec3 boxCentre = 0.5 * (capture.volumeMin + capture.volumeMax);
        const glm::dvec3 extent = capture.volumeMax - capture.volumeMin;
        const double rootSize = std::max({extent.x, extent.y, extent.z});
        const glm::dvec3 rootOrigin = boxCentre - 0.5 * rootSize;

        VolumeOctreeReconstruction out;
        VolumeOctreeData& octree = out.octree;
        octree.levelCount = options.levelCount;
        octree.origin = glm::vec3(rootOrigin);
        octree.size = float(rootSize);
        for (const CaptureCamera& camera : capture.cameras)
            octree.cameraDirections.push_back(glm::vec3(glm::normalize(camera.position() - boxCentre)));

        std::vector<Pyramid> pyramids(cameraCount);
        tbb::parallel_for(std::size_t(0), cameraCount, [&](std::size_t c) { pyramids[c] = buildPyramid(capture.images[c]); });

        std::vector<std::uint32_t> parents;
        std::size_t totalCells = 0;
        for (std::uint32_t level = 0; level < options.levelCount; ++level)
        {
            const std::string step = "volume octree: level " + std::to_string(level);
            report(progress, step, 0.0f);
            const std::uint32_t side = 1u << level;
            const double edge = rootSize / side, radius = 0.5 * std::sqrt(3.0) * edge;
            const auto centreOf = [&](std::uint32_t code) {
                return rootOrigin + edge * (glm::dvec3(volumeCellCoords(code)) + 0.5);
            };
            VolumeOctreeReconstruction::LevelStats stats;
            const std::vector<std::uint32_t> candidates =
                level == 0 ? std::vector<std::uint32_t>{volumeCellCode(0, 0, 0)} : childrenOf(parents);
            stats.candidates = candidates.size();
            if (totalCells + candidates.size() > options.maxCells)
                return fail(label, std::string(CHUNK) + " level " + std::to_string(level),
                            std::to_string(totalCells + candidates.size()) + " cells exceed the bound of " +
                                std::to_string(options.maxCells) + " (option maxCells; fewer levels need less)");

            // 1. Visual hull.
            std::vector<std::uint8_t> inHull(candidates.size(), 0);
            tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t i) {
                const glm::dvec3 centre = centreOf(candidates[i]);
                for (std::size_t c = 0; c < cameraCount; ++c)
                {
                    const View v = viewOf(capture.cameras[c], centre, radius);
                    if (!v.sees)
                        continue;
                    const float m = maxAlphaNear(pyramids[c], v.pixel.x, v.pixel.y,
                                                 radius * focalOf(capture.cameras[c]) / v.depth);
                    if (m >= 0.0f && m < 0.5f / 255.0f)
                        return;
                }
                inHull[i] = 1;
            });
            std::vector<std::uint32_t> hull;
            for (std::size_t i = 0; i < candidates.size(); ++i)
                if (inHull[i])
                    hull.push_back(candidates[i]);
            report(progress, step, 0.2f);

            // 2. Opacity by tomography: optical depths tau (opacity 1 - exp(-tau)) such that along the
            // ray from every camera through every cell's centre the hull cells' depths add up to what
            // the image saw there, T = -log(1 - a). Start from an even share along each ray, then
            // multiplicative updates (MART, Gordon, Bender and Herman 1970), all cells at once.
            const CellIndex hullIndex(side, hull);
            std::vector<float> observed(hull.size() * cameraCount, -1.0f); // T per (cell, camera); -1: unseen
            std::vector<double> tau(hull.size(), 0.0);
            const auto rayDepth = [&](std::size_t i, std::size_t c, const std::vector<double>* depths) {
                const glm::dvec3 centre = centreOf(hull[i]), from = capture.cameras[c].position();
                double sum = 0.0;
                walkGrid(from, glm::normalize(centre - from), 0.0, std::numeric_limits<double>::infinity(), rootOrigin,
                         edge, side, [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
                             const std::int32_t j = hullIndex.find(x, y, z);
                             if (j >= 0)
                                 sum += depths ? (*depths)[std::size_t(j)] : 1.0;
                             return true;
                         });
                return sum;
            };
            tbb::parallel_for(std::size_t(0), hull.size(), [&](std::size_t i) {
                const glm::dvec3 centre = centreOf(hull[i]);
                double sum = 0.0;
                int seen = 0;
                for (std::size_t c = 0; c < cameraCount; ++c)
                {
                    const CaptureCamera& camera = capture.cameras[c];
                    const View v = viewOf(camera, centre, radius);
                    if (!v.sees)
                        continue;
                    const double a = std::min(
                        double(sampleMean(pyramids[c], v.pixel.x, v.pixel.y, edge * focalOf(camera) / v.depth).a),
                        MAX_ALPHA);
                    const double t = -std::log(1.0 - a);
                    observed[i * cameraCount + c] = float(t);
                    sum += t / std::max(rayDepth(i, c, nullptr), 1.0);
                    ++seen;
                }
                tau[i] = seen ? sum / seen : 0.0;
            });
            for (std::uint32_t iteration = 0; iteration < options.tomographyIterations; ++iteration)
            {
                std::vector<double> next(hull.size());
                tbb::parallel_for(std::size_t(0), hull.size(), [&](std::size_t i) {
                    double logSum = 0.0;
                    int seen = 0;
                    for (std::size_t c = 0; c < cameraCount; ++c)
                    {
                        const float t = observed[i * cameraCount + c];
                        if (t < 0.0f)
                            continue;
                        const double along = rayDepth(i, c, &tau);
                        logSum += std::log(std::clamp(along > 0.0 ? double(t) / along : 1e4, 1e-4, 1e4));
                        ++seen;
                    }
                    next[i] = seen ? tau[i] * std::exp(logSum / seen) : 0.0;
                });
                tau = std::move(next);
                report(progress, step, 0.2f + 0.2f * float(iteration + 1) / float(options.tomographyIterations));
            }
            // Each cell's share of the optical depth along each camera's ray through it: a texel
            // keeps that share of what its pixel saw (1 - (1 - a)^share), so the cells along the
            // ray give the image back.
            std::vector<float> share(hull.size() * cameraCount, 0.0f);
            tbb::parallel_for(std::size_t(0), hull.size(), [&](std::size_t i) {
                for (std::size_t c = 0; c < cameraCount; ++c)
                    if (observed[i * cameraCount + c] >= 0.0f && tau[i] > 0.0)
                        share[i * cameraCount + c] = float(tau[i] / std::max(rayDepth(i, c, &tau), tau[i]));
            });
            report(progress, step, 0.5f);

            std::vector<std::uint32_t> kept;
            std::vector<std::size_t> keptFrom; // index into hull
            for (std::size_t i = 0; i < hull.size(); ++i)
                if (tau[i] > MIN_DEPTH)
                {
                    kept.push_back(hull[i]);
                    keptFrom.push_back(i);
                }
            if (kept.empty())
                return fail(label, std::string(CHUNK) + " level " + std::to_string(level),
                            "every cell was carved away: the mattes leave no matter inside the volume that every "
                            "camera agrees on (empty mattes, or cameras that do not see the same box)");

            // 3 and 4. Billboards and pruning, per cell, blocks of cells concatenated in order.
            const CellIndex keptIndex(side, kept);
            const std::size_t blockSize = 64, blockCount = (kept.size() + blockSize - 1) / blockSize;
            std::vector<std::vector<BillboardTexture>> blockBillboards(blockCount);
            std::vector<std::uint32_t> slotLocal(kept.size() * cameraCount, std::numeric_limits<std::uint32_t>::max());
            std::vector<VolumeOctreeReconstruction::LevelStats> blockStats(blockCount);
            tbb::parallel_for(std::size_t(0), blockCount, [&](std::size_t b) {
                VolumeOctreeReconstruction::LevelStats& s = blockStats[b];
                for (std::size_t i = b * blockSize; i < std::min(kept.size(), (b + 1) * blockSize); ++i)
                {
                    const glm::dvec3 centre = centreOf(kept[i]);
                    for (std::size_t c = 0; c < cameraCount; ++c)
                    {
                        ++s.slots;
                        const CaptureCamera& camera = capture.cameras[c];
                        const View v = viewOf(camera, centre, radius);
                        if (!v.sees)
                        {
                            ++s.empty;
                            continue;
                        }
                        // §3.2: the alpha accumulated by the cells in front, front to back.
                        if (options.prune)
                        {
                            const glm::dvec3 from = camera.position(), d = glm::normalize(centre - from);
                            double transmittance = 1.0;
                            const std::uint32_t self = kept[i];
                            walkGrid(from, d, 0.0, glm::length(centre - from), rootOrigin, edge, side,
                                     [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
                                         if (volumeCellCode(x, y, z) == self)
                                             return false;
                                         const std::int32_t j = keptIndex.find(x, y, z);
                                         if (j >= 0)
                                             transmittance *= std::exp(-tau[keptFrom[std::size_t(j)]]);
                                         return transmittance >= 1.0 - options.pruneAlpha;
                                     });
                            if (1.0 - transmittance > options.pruneAlpha)
                            {
                                ++s.hidden;
                                continue;
                            }
                        }
                        // The billboard on camera c's image axes.
                        const glm::dmat4& m = camera.worldToCamera;
                        const glm::dvec3 right(m[0][0], m[1][0], m[2][0]), up(m[0][1], m[1][1], m[2][1]);
                        const double texelShare = share[keptFrom[i] * cameraCount + c];
                        BillboardTexture texture;
                        bool any = false;
                        for (std::uint32_t t = 0; t < VOLUME_BILLBOARD_TEXELS; ++t)
                            for (std::uint32_t sx = 0; sx < VOLUME_BILLBOARD_TEXELS; ++sx)
                            {
                                const double fs = (sx + 0.5) / VOLUME_BILLBOARD_TEXELS - 0.5;
                                const double ft = 0.5 - (t + 0.5) / VOLUME_BILLBOARD_TEXELS;
                                const glm::dvec3 p = centre + edge * (fs * right + ft * up);
                                glm::dvec2 pixel;
                                double depth;
                                std::array<std::uint8_t, 4>& texel = texture.texels[t * VOLUME_BILLBOARD_TEXELS + sx];
                                if (!camera.project(p, pixel, depth))
                                    continue;
                                const glm::vec4 sample = sampleMean(
                                    pyramids[c], pixel.x, pixel.y, edge / VOLUME_BILLBOARD_TEXELS * focalOf(camera) / depth);
                                const double a = std::min(double(sample.a), MAX_ALPHA);
                                const std::uint8_t alpha = unitToByte(float(1.0 - std::pow(1.0 - a, texelShare)));
                                if (alpha == 0)
                                    continue;
                                any = true;
                                texel = {linearToSrgbByteOf(sample.r / sample.a), linearToSrgbByteOf(sample.g / sample.a),
                                         linearToSrgbByteOf(sample.b / sample.a), alpha};
                            }
                        if (!any)
                        {
                            ++s.empty;
                            continue;
                        }
                        slotLocal[i * cameraCount + c] = std::uint32_t(blockBillboards[b].size());
                        blockBillboards[b].push_back(texture);
                    }
                }
            });

            // Concatenate in cell order. A cell without a billboard for any camera (hidden or empty
            // from everywhere) is dropped with its subtree: the pruning applied recursively (§3.2).
            std::vector<std::uint32_t> stored;
            for (std::size_t b = 0; b < blockCount; ++b)
            {
                const std::uint32_t base = std::uint32_t(out.billboards.size());
                for (std::size_t i = b * blockSize; i < std::min(kept.size(), (b + 1) * blockSize); ++i)
                {
                    const auto slots = slotLocal.begin() + std::ptrdiff_t(i * cameraCount);
                    if (std::all_of(slots, slots + std::ptrdiff_t(cameraCount),
                                    [](std::uint32_t local) { return local == std::numeric_limits<std::uint32_t>::max(); }))
                        continue;
                    stored.push_back(kept[i]);
                    for (std::size_t c = 0; c < cameraCount; ++c)
                        out.billboardOf.push_back(slots[std::ptrdiff_t(c)] == std::numeric_limits<std::uint32_t>::max()
                                                      ? std::numeric_limits<std::uint32_t>::max()
                                                      : base + slots[std::ptrdiff_t(c)]);
                }
                out.billboards.insert(out.billboards.end(), blockBillboards[b].begin(), blockBillboards[b].end());
                stats.slots += blockStats[b].slots;
                stats.hidden += blockStats[b].hidden;
                stats.empty += blockStats[b].empty;
            }
            if (stored.empty())
                return fail(label, std::string(CHUNK) + " level " + std::to_string(level),
                            "no cell has a billboard any camera sees");
            stats.cells = stored.size();
            stats.dropped = kept.size() - stored.size();
            stats.billboards = stats.slots - stats.hidden - stats.empty;
            octree.levelCellCounts.push_back(std::uint32_t(stored.size()));
            octree.cells.insert(octree.cells.end(), stored.begin(), stored.end());
            out.levels.push_back(stats);
            totalCells += stored.size();
            parents = std::move(stored);
            report(progress, step, 1.0f);
        }
        return out;
    }

    Result<VolumeOctreeData> compressVolumeOctree(const VolumeOctreeReconstruction& reconstruction,
                                                  const VolumeOctreeOptions& options, const std::string& label,
                                                  const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (reconstruction.billboards.empty())
            return fail(label, CHUNK, "no billboard survived the pruning: nothing to draw");
        report(progress, "volume octree: vector quantisation", 0.0f);
        const QuantisedBillboards q =
            quantiseBillboards(reconstruction.billboards, options.quantisation, [&](const std::string&, float fraction) {
                report(progress, "volume octree: vector quantisation", fraction);
            });
        report(progress, "volume octree: vector quantisation", 1.0f);

        VolumeOctreeData data = reconstruction.octree;
        data.colourCodewords = std::uint32_t(q.colourCodebook.size());
        data.alphaCodewords = std::uint32_t(q.alphaCodebook.size());
        data.slots.assign(reconstruction.billboardOf.size(), VolumeOctreeSlot{});
        for (std::size_t i = 0; i < data.slots.size(); ++i)
        {
            const std::uint32_t b = reconstruction.billboardOf[i];
            if (b != std::numeric_limits<std::uint32_t>::max())
                data.slots[i] = {std::uint16_t(q.colourIndex[b]), std::uint16_t(q.alphaIndex[b])};
        }

        // The atlas (§4.1.2): colour codeword i in block i's RGB, alpha codeword j in block j's A.
        const std::uint32_t blocks = std::max(data.colourCodewords, data.alphaCodewords);
        const std::uint32_t perRow = std::uint32_t(std::ceil(std::sqrt(double(blocks))));
        const std::uint32_t rows = (blocks + perRow - 1) / perRow;
        GpuTexture atlas;
        atlas.name = "volume octree codebook";
        atlas.format = GpuTextureFormat::RGBA8;
        atlas.width = perRow * VOLUME_BILLBOARD_TEXELS;
        atlas.height = rows * VOLUME_BILLBOARD_TEXELS;
        atlas.mipCount = 1;
        atlas.data.assign(std::size_t(atlas.width) * atlas.height * 4, 0);
        for (std::uint32_t i = 0; i < blocks; ++i)
            for (std::uint32_t t = 0; t < VOLUME_BILLBOARD_TEXELS; ++t)
                for (std::uint32_t s = 0; s < VOLUME_BILLBOARD_TEXELS; ++s)
                {
                    const std::size_t x = (i % perRow) * VOLUME_BILLBOARD_TEXELS + s;
                    const std::size_t y = (i / perRow) * VOLUME_BILLBOARD_TEXELS + t;
                    std::uint8_t* texel = &atlas.data[(y * atlas.width + x) * 4];
                    const std::size_t k = t * VOLUME_BILLBOARD_TEXELS + s;
                    if (i < data.colourCodewords)
                        std::copy_n(q.colourCodebook[i].texels[k].begin(), 3, texel);
                    if (i < data.alphaCodewords)
                        texel[3] = q.alphaCodebook[i].texels[k][3];
                }
        data.atlas = options.compress ? compressTexture(atlas, GpuTextureFormat::DXT5) : std::move(atlas);
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<VolumeOctreeData> bakeVolumeOctree(const CaptureSet& capture, const VolumeOctreeOptions& options,
                                              const std::string& label, const ProgressCallback& progress)
    {
        Result<VolumeOctreeReconstruction> reconstruction = reconstructVolumeOctree(capture, options, label, progress);
        if (!reconstruction)
            return reconstruction.error();
        return compressVolumeOctree(reconstruction.value(), options, label, progress);
    }

    Result<void> addVolumeOctreeChunk(PackageWriter& writer, const TreeModel& model,
                                      const CaptureSynthesisOptions& capture, const VolumeOctreeOptions& options,
                                      const std::string& label, const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok;
        return addBakedChunk(writer, model, label, progress, VOLUME_OCTREE_CHUNK, VOLUME_OCTREE_CHUNK_FORMAT_VERSION,
                             encodeVolumeOctreeChunk, [&]() -> Result<VolumeOctreeData> {
                                 Result<CaptureSet> set = synthesiseCaptureSet(model, capture, label, progress);
                                 if (!set)
                                     return set.error();
                                 return bakeVolumeOctree(set.value(), options, label, progress);
                             });
    }

    Result<void> addVolumeOctreeChunk(PackageWriter& writer, const CaptureSet& capture, const std::string& name,
                                      const VolumeOctreeOptions& options, const std::string& label,
                                      const ProgressCallback& progress)
    {
        if (writer.hasChunk(REFERENCE_CHUNK, 0))
            return fail(label, chunkElement(REFERENCE_CHUNK, 0),
                        "present already: a tree baked from photographs has a reference of bounds only");
        Result<VolumeOctreeData> data = bakeVolumeOctree(capture, options, label, progress);
        if (!data)
            return data.error();
        // No geometry: the bounds the Forest and the cameras frame the tree by.
        TreeModel bounds;
        bounds.name = name;
        bounds.boundsMin = glm::vec3(capture.volumeMin);
        bounds.boundsMax = glm::vec3(capture.volumeMax);
        if (Result<void> reference = addReferenceChunk(writer, bounds, label, progress); !reference)
            return reference;
        return addEncodedChunk(writer, VOLUME_OCTREE_CHUNK, VOLUME_OCTREE_CHUNK_FORMAT_VERSION, encodeVolumeOctreeChunk,
                               data.value(), label);
    }
}
