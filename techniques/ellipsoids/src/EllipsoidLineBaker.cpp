// EllipsoidLineBaker: the line hierarchy of a tree's branches (steps and deviations from the
// ellipsoids-and-lines paper (001) in EllipsoidLineBaker.h, format in EllipsoidLineData.h).
#include "TreeLod/EllipsoidLineBaker.h"

#include "EllipsoidErrorViews.h"

#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/SkeletonExtraction.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <utility>

namespace TreeLod
{
    namespace
    {
        constexpr double PI = 3.14159265358979323846;
        /// Relative to the bark box's diagonal D (EllipsoidLineBaker.h).
        constexpr double MIN_RADIUS = 1e-5;
        constexpr double SAME_NODE = 1e-7;
        /// Samples per pixel side of the error views (2 x 2, as the ellipsoid baker's).
        constexpr int SAMPLES = EllipsoidErrorViews::SAMPLES;
        constexpr std::int32_t NO_PARENT = -1;
        constexpr int CAPSULE_SIDES = 8;

        std::uint64_t splitMix(std::uint64_t& state)
        {
            std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            return z ^ (z >> 31);
        }

        bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        Result<void> checkOptions(const EllipsoidLineOptions& o, const std::string& label)
        {
            if (o.candidates < 1 || o.candidates > 64)
                return fail(label, "ellipsoid-lines option candidates",
                            std::to_string(o.candidates) + " is outside [1, 64]");
            if (o.linesDivisor < 2 || o.linesDivisor > 64)
                return fail(label, "ellipsoid-lines option linesDivisor",
                            std::to_string(o.linesDivisor) + " is outside [2, 64]");
            if (o.viewResolution < 16 || o.viewResolution > 1024 || (o.viewResolution & (o.viewResolution - 1)) != 0)
                return fail(label, "ellipsoid-lines option viewResolution",
                            std::to_string(o.viewResolution) + " is not a power of two in [16, 1024]");
            return {};
        }

        /// A line while merging, in the baker's units (relative to the bark box's centre, over D).
        struct WorkLine
        {
            glm::dvec3 start{0.0}, end{0.0};
            double radius = 0.0;
            double weight = 0.0;
            glm::dvec3 colour{0.0}; ///< linear
            std::int32_t parent = NO_PARENT;
            std::vector<std::int32_t> children;
            bool alive = true;
        };

        double capsuleVolume(double radius, double length)
        {
            return PI * radius * radius * (length + 4.0 * radius / 3.0);
        }

        double segmentDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b)
        {
            const glm::dvec3 ab = b - a;
            const double ll = glm::dot(ab, ab);
            const double t = ll > 0.0 ? std::clamp(glm::dot(p - a, ab) / ll, 0.0, 1.0) : 0.0;
            return glm::length(p - (a + t * ab));
        }

        // ---- Capsule meshes --------------------------------------------------------------------

        /// Appends a capsule of 64 triangles: an octagonal tube and two caps of one ring at 45
        /// degrees, widened so that the octagon's mean width (perimeter / pi) is 2 r.
        void appendCapsule(TreeModel& m, const glm::dvec3& a, const glm::dvec3& b, double radius)
        {
            static const double widen = PI / (8.0 * std::sin(PI / 8.0));
            const double r = radius * widen;
            const glm::dvec3 axis = b - a;
            const double length = glm::length(axis);
            const glm::dvec3 dir = length > 0.0 ? axis / length : glm::dvec3(0, 1, 0);
            const glm::dvec3 helper = std::abs(dir.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
            const glm::dvec3 u = glm::normalize(glm::cross(dir, helper)), v = glm::cross(dir, u);
            const double c45 = std::sqrt(0.5);
            // Rings: (centre, ring radius, normal's axial part); poles first and last.
            const std::array<std::tuple<glm::dvec3, double, double>, 4> rings = {
                std::make_tuple(a - dir * (r * c45), r * c45, -c45), std::make_tuple(a, r, 0.0),
                std::make_tuple(b, r, 0.0), std::make_tuple(b + dir * (r * c45), r * c45, c45)};
            const std::uint32_t first = std::uint32_t(m.barkVertices.size());
            m.barkVertices.push_back({glm::vec3(a - dir * r), glm::vec3(-dir), {}});
            for (const auto& [centre, ringRadius, axial] : rings)
                for (int k = 0; k < CAPSULE_SIDES; ++k)
                {
                    const double angle = 2.0 * PI * double(k) / double(CAPSULE_SIDES);
                    const glm::dvec3 out = std::cos(angle) * u + std::sin(angle) * v;
                    m.barkVertices.push_back(
                        {glm::vec3(centre + ringRadius * out),
                         glm::vec3(glm::normalize(out * std::sqrt(1.0 - axial * axial) + axial * dir)),
                         {}});
                }
            m.barkVertices.push_back({glm::vec3(b + dir * r), glm::vec3(dir), {}});
            const std::uint32_t last = std::uint32_t(m.barkVertices.size() - 1);
            auto ring = [&](int i, int k)
            { return first + 1 + std::uint32_t(i * CAPSULE_SIDES + (k % CAPSULE_SIDES)); };
            for (int k = 0; k < CAPSULE_SIDES; ++k)
            {
                m.barkIndices.insert(m.barkIndices.end(), {first, ring(0, k + 1), ring(0, k)});
                for (int i = 0; i < 3; ++i)
                    m.barkIndices.insert(m.barkIndices.end(), {ring(i, k), ring(i, k + 1), ring(i + 1, k + 1),
                                                               ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)});
                m.barkIndices.insert(m.barkIndices.end(), {last, ring(3, k), ring(3, k + 1)});
            }
        }

        TreeModel emptyCapsuleModel()
        {
            TreeModel m;
            m.name = "ellipsoid lines";
            Material white;
            white.name = "TreeLod/EllipsoidLineBake";
            white.doubleSided = true;
            m.materials.push_back(white);
            return m;
        }

        void finishCapsuleModel(TreeModel& m)
        {
            m.barkTriangleMaterial.assign(m.barkIndices.size() / 3, 0);
            m.updateBounds();
        }

        // ---- The error views (§4) --------------------------------------------------------------

        /// The ellipsoid baker's four orthographic views of the bark box in the baker's units
        /// (centre 0, diagonal 1).
        std::vector<CameraSpec> errorCameras() { return EllipsoidErrorViews::cameras(glm::vec3(0.0f), 0.5f); }

        /// A capsule in one view's sample space (sample (i, j) is centred at (i + 0.5, j + 0.5)): the
        /// projected segment, the radius and the samples its bounding rectangle holds (x0 > x1: none).
        struct Stadium
        {
            glm::dvec2 a{0.0}, b{0.0};
            double radius = 0.0;
            int x0 = 1, x1 = 0, y0 = 1, y1 = 0;

            bool empty() const { return x0 > x1 || y0 > y1; }
            bool covers(int i, int j) const
            {
                if (i < x0 || i > x1 || j < y0 || j > y1)
                    return false;
                const glm::dvec2 p(double(i) + 0.5, double(j) + 0.5), ab = b - a;
                const double ll = glm::dot(ab, ab);
                const double t = ll > 0.0 ? std::clamp(glm::dot(p - a, ab) / ll, 0.0, 1.0) : 0.0;
                const glm::dvec2 d = p - (a + t * ab);
                return glm::dot(d, d) <= radius * radius;
            }
        };

        /// The merge search's image error (EllipsoidLineBaker.h, first deviation): per view, the
        /// number of lines covering each sample, each pixel's covered samples, and for every band k
        /// of the multi-scale RMSE the sums of the difference image (lines - bark, sRGB) over its
        /// 2^k x 2^k blocks with the sum of their squares, so that band k's RMSE is
        /// sqrt(squares_k / (4^k R^2)) exactly as MultiScaleRmse.cpp computes it.
        class CoverageViews
        {
        public:
            CoverageViews(const std::vector<CameraSpec>& cameras, int resolution, const std::vector<Image>& reference)
                : mResolution(resolution), mSize(resolution * SAMPLES)
            {
                while ((1 << (mBands - 1)) < resolution)
                    ++mBands;
                for (int k = 0; k <= SAMPLES * SAMPLES; ++k)
                    mValue[std::size_t(k)] = double(linearToSrgb(float(k) / float(SAMPLES * SAMPLES)));
                for (std::size_t v = 0; v < cameras.size(); ++v)
                {
                    View view;
                    view.clip = glm::dmat4(cameras[v].projectionMatrix(1.0f) * cameras[v].viewMatrix());
                    view.samplesPerUnit = double(mSize) / double(cameras[v].orthoHeight);
                    view.count.assign(std::size_t(mSize) * std::size_t(mSize), 0);
                    view.covered.assign(std::size_t(resolution) * std::size_t(resolution), 0);
                    view.reference.resize(view.covered.size());
                    for (std::size_t p = 0; p < view.reference.size(); ++p)
                        view.reference[p] = double(reference[v].pixels[p].r);
                    mViews.push_back(std::move(view));
                }
            }

            std::size_t viewCount() const { return mViews.size(); }

            Stadium project(std::size_t v, const glm::dvec3& a, const glm::dvec3& b, double radius) const
            {
                const View& view = mViews[v];
                auto toSamples = [&](const glm::dvec3& p)
                {
                    const glm::dvec4 c = view.clip * glm::dvec4(p, 1.0);
                    return glm::dvec2((c.x + 1.0) * 0.5 * double(mSize), (1.0 - c.y) * 0.5 * double(mSize));
                };
                Stadium s;
                s.a = toSamples(a);
                s.b = toSamples(b);
                s.radius = radius * view.samplesPerUnit;
                const glm::dvec2 lo = glm::min(s.a, s.b) - s.radius, hi = glm::max(s.a, s.b) + s.radius;
                if (!(lo.x < double(mSize)) || !(lo.y < double(mSize)) || !(hi.x > 0.0) || !(hi.y > 0.0))
                    return s; // off screen (or not finite): empty
                s.x0 = std::max(0, int(std::ceil(lo.x - 0.5)));
                s.x1 = std::min(mSize - 1, int(std::floor(hi.x - 0.5)));
                s.y0 = std::max(0, int(std::ceil(lo.y - 0.5)));
                s.y1 = std::min(mSize - 1, int(std::floor(hi.y - 0.5)));
                return s;
            }

            /// Adds `stadiums` to the counts and sets every pixel and block sum from scratch.
            void reset(std::size_t v, const std::vector<Stadium>& stadiums)
            {
                View& view = mViews[v];
                std::fill(view.count.begin(), view.count.end(), 0u);
                for (const Stadium& s : stadiums)
                    for (int j = s.y0; j <= s.y1; ++j)
                        for (int i = s.x0; i <= s.x1; ++i)
                            if (s.covers(i, j))
                                ++view.count[std::size_t(j) * std::size_t(mSize) + std::size_t(i)];
                const int r = mResolution;
                view.sums.assign(std::size_t(mBands), {});
                view.sums[0].resize(std::size_t(r) * std::size_t(r));
                for (int y = 0; y < r; ++y)
                    for (int x = 0; x < r; ++x)
                    {
                        int covered = 0;
                        for (int j = 0; j < SAMPLES; ++j)
                            for (int i = 0; i < SAMPLES; ++i)
                                covered += view.count[std::size_t(y * SAMPLES + j) * std::size_t(mSize) +
                                                      std::size_t(x * SAMPLES + i)] > 0;
                        const std::size_t p = std::size_t(y) * std::size_t(r) + std::size_t(x);
                        view.covered[p] = std::uint8_t(covered);
                        view.sums[0][p] = mValue[std::size_t(covered)] - view.reference[p];
                    }
                for (int k = 1; k < mBands; ++k)
                {
                    const int side = r >> k;
                    view.sums[std::size_t(k)].assign(std::size_t(side) * std::size_t(side), 0.0);
                    for (int y = 0; y < 2 * side; ++y)
                        for (int x = 0; x < 2 * side; ++x)
                            view.sums[std::size_t(k)][std::size_t(y / 2) * std::size_t(side) + std::size_t(x / 2)] +=
                                view.sums[std::size_t(k) - 1][std::size_t(y) * std::size_t(2 * side) + std::size_t(x)];
                }
                recomputeSquares(v);
            }

            /// Squares from the sums (removes the rounding that increments gather).
            void recomputeSquares(std::size_t v)
            {
                View& view = mViews[v];
                view.squares.assign(std::size_t(mBands), 0.0);
                for (int k = 0; k < mBands; ++k)
                    for (double s : view.sums[std::size_t(k)])
                        view.squares[std::size_t(k)] += s * s;
            }

            /// The change of every band's squares if the lines `removed` left view `v` and `added`
            /// came (`delta`, one per band); applied to the view when `commit`.
            void change(std::size_t v, const std::vector<Stadium>& removed, const std::vector<Stadium>& added,
                        bool commit, std::vector<double>& delta)
            {
                View& view = mViews[v];
                delta.assign(std::size_t(mBands), 0.0);
                int x0 = mSize, x1 = -1, y0 = mSize, y1 = -1;
                for (const std::vector<Stadium>* list : {&removed, &added})
                    for (const Stadium& s : *list)
                        if (!s.empty())
                        {
                            x0 = std::min(x0, s.x0);
                            x1 = std::max(x1, s.x1);
                            y0 = std::min(y0, s.y0);
                            y1 = std::max(y1, s.y1);
                        }
                if (x0 > x1)
                    return;
                // Band 0: the pixels whose covered samples change, in row order.
                struct Cell
                {
                    std::uint32_t x, y;
                    double delta;
                };
                std::vector<Cell> cells;
                for (int py = y0 / SAMPLES; py <= y1 / SAMPLES; ++py)
                    for (int px = x0 / SAMPLES; px <= x1 / SAMPLES; ++px)
                    {
                        int covered = 0;
                        for (int j = py * SAMPLES; j < (py + 1) * SAMPLES; ++j)
                            for (int i = px * SAMPLES; i < (px + 1) * SAMPLES; ++i)
                            {
                                std::uint32_t& stored =
                                    view.count[std::size_t(j) * std::size_t(mSize) + std::size_t(i)];
                                std::int64_t c = stored;
                                for (const Stadium& s : removed)
                                    c -= s.covers(i, j);
                                for (const Stadium& s : added)
                                    c += s.covers(i, j);
                                c = std::max<std::int64_t>(c, 0);
                                if (commit)
                                    stored = std::uint32_t(c);
                                covered += c > 0;
                            }
                        const std::size_t p = std::size_t(py) * std::size_t(mResolution) + std::size_t(px);
                        if (covered != view.covered[p])
                        {
                            cells.push_back({std::uint32_t(px), std::uint32_t(py),
                                             mValue[std::size_t(covered)] - mValue[view.covered[p]]});
                            if (commit)
                                view.covered[p] = std::uint8_t(covered);
                        }
                    }
                // Every band: the blocks' changes (summed in a fixed order), then their squares.
                for (int k = 0; k < mBands && !cells.empty(); ++k)
                {
                    if (k > 0)
                    {
                        for (Cell& c : cells)
                        {
                            c.x >>= 1;
                            c.y >>= 1;
                        }
                        std::stable_sort(cells.begin(), cells.end(),
                                         [](const Cell& a, const Cell& b)
                                         { return a.y != b.y ? a.y < b.y : a.x < b.x; });
                        std::size_t out = 0;
                        for (std::size_t i = 0; i < cells.size(); ++i)
                        {
                            if (out > 0 && cells[out - 1].x == cells[i].x && cells[out - 1].y == cells[i].y)
                                cells[out - 1].delta += cells[i].delta;
                            else
                                cells[out++] = cells[i];
                        }
                        cells.resize(out);
                    }
                    const std::size_t side = std::size_t(mResolution >> k);
                    std::vector<double>& sums = view.sums[std::size_t(k)];
                    double d = 0.0;
                    for (const Cell& c : cells)
                    {
                        double& s = sums[std::size_t(c.y) * side + std::size_t(c.x)];
                        const double changed = s + c.delta;
                        d += changed * changed - s * s;
                        if (commit)
                            s = changed;
                    }
                    delta[std::size_t(k)] = d;
                    if (commit)
                        view.squares[std::size_t(k)] += d;
                }
            }

            /// The mean over the views of the multi-scale RMSE (the mean of the bands), with each
            /// view's band changes `deltas[v]` when given.
            double error(const std::vector<const std::vector<double>*>* deltas = nullptr) const
            {
                double sum = 0.0;
                const double pixels = double(mResolution) * double(mResolution);
                for (std::size_t v = 0; v < mViews.size(); ++v)
                {
                    double bands = 0.0;
                    for (int k = 0; k < mBands; ++k)
                    {
                        double squares = mViews[v].squares[std::size_t(k)];
                        if (deltas)
                            squares += (*(*deltas)[v])[std::size_t(k)];
                        bands += std::sqrt(std::max(squares, 0.0) / (std::ldexp(1.0, 2 * k) * pixels));
                    }
                    sum += bands / double(mBands);
                }
                return sum / double(mViews.size());
            }

        private:
            struct View
            {
                glm::dmat4 clip{1.0};
                double samplesPerUnit = 1.0;
                std::vector<std::uint32_t> count;
                std::vector<std::uint8_t> covered;
                std::vector<double> reference;
                std::vector<std::vector<double>> sums;
                std::vector<double> squares;
            };
            int mResolution, mSize;
            int mBands = 1;
            std::array<double, SAMPLES * SAMPLES + 1> mValue{};
            std::vector<View> mViews;
        };

        // ---- Bark colours ----------------------------------------------------------------------

        /// Linear colour of each material: base colour times the mean of its texture.
        std::vector<glm::dvec3> materialColours(const TreeModel& model)
        {
            std::vector<glm::dvec3> colours;
            for (const Material& m : model.materials)
            {
                glm::dvec3 c(m.baseColour);
                if (m.texture >= 0 && std::size_t(m.texture) < model.textures.size())
                {
                    const TextureImage& t = model.textures[std::size_t(m.texture)];
                    const std::size_t texels = std::size_t(t.width) * std::size_t(t.height);
                    if (texels > 0 && t.rgba.size() >= texels * 4)
                    {
                        glm::dvec3 sum(0.0);
                        for (std::size_t i = 0; i < texels; ++i)
                            sum += glm::dvec3(srgbByteToLinear(t.rgba[i * 4]), srgbByteToLinear(t.rgba[i * 4 + 1]),
                                              srgbByteToLinear(t.rgba[i * 4 + 2]));
                        c *= sum / double(texels);
                    }
                }
                colours.push_back(c);
            }
            return colours;
        }

        /// The nearest of a set of points, on a sparse grid searched in growing shells.
        class NearestPoint
        {
        public:
            NearestPoint(const std::vector<glm::dvec3>& points, double cell) : mPoints(points), mCell(cell)
            {
                for (std::uint32_t i = 0; i < points.size(); ++i)
                {
                    const glm::ivec3 c = cellOf(points[i]);
                    mCells[key(c)].push_back(i);
                    mLo = i == 0 ? c : glm::min(mLo, c);
                    mHi = i == 0 ? c : glm::max(mHi, c);
                }
            }

            std::uint32_t nearest(const glm::dvec3& p) const
            {
                const glm::ivec3 c = glm::clamp(cellOf(p), mLo, mHi);
                std::uint32_t best = 0;
                double bestDistance = std::numeric_limits<double>::infinity();
                const glm::ivec3 extent = mHi - mLo;
                const int reach = std::max({extent.x, extent.y, extent.z}) + 1;
                for (int shell = 0; shell <= reach; ++shell)
                {
                    for (int z = c.z - shell; z <= c.z + shell; ++z)
                        for (int y = c.y - shell; y <= c.y + shell; ++y)
                            for (int x = c.x - shell; x <= c.x + shell; ++x)
                            {
                                if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != shell)
                                    continue;
                                const auto it = mCells.find(key({x, y, z}));
                                if (it == mCells.end())
                                    continue;
                                for (std::uint32_t i : it->second)
                                {
                                    const double d = glm::length(mPoints[i] - p);
                                    if (d < bestDistance || (d == bestDistance && i < best))
                                    {
                                        bestDistance = d;
                                        best = i;
                                    }
                                }
                            }
                    // Cells beyond this shell are at least shell * cell away from p's (clamped) cell.
                    if (bestDistance < std::numeric_limits<double>::infinity() &&
                        bestDistance <=
                            double(shell) * mCell - glm::length(p - glm::clamp(p, lowCorner(c), lowCorner(c) + mCell)))
                        break;
                }
                return best;
            }

        private:
            glm::ivec3 cellOf(const glm::dvec3& p) const { return glm::ivec3(glm::floor(p / mCell)); }
            glm::dvec3 lowCorner(const glm::ivec3& c) const { return glm::dvec3(c) * mCell; }
            static std::uint64_t key(const glm::ivec3& c)
            {
                const std::uint64_t mask = (1ull << 21) - 1;
                return (std::uint64_t(c.x) & mask) | ((std::uint64_t(c.y) & mask) << 21) |
                       ((std::uint64_t(c.z) & mask) << 42);
            }
            const std::vector<glm::dvec3>& mPoints;
            double mCell;
            glm::ivec3 mLo{0}, mHi{0};
            std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> mCells;
        };

        // ---- The merges (§3.2) ----------------------------------------------------------------

        /// Sums of non-negative counts with prefix search (a Fenwick tree): the mergeable pairs
        /// of each parent slot, for uniform draws over all pairs.
        class PairCounts
        {
        public:
            explicit PairCounts(std::size_t slots) : mTree(slots + 1, 0), mValue(slots, 0) {}
            void set(std::size_t slot, std::int64_t value)
            {
                const std::int64_t d = value - mValue[slot];
                mValue[slot] = value;
                mTotal += d;
                for (std::size_t i = slot + 1; i < mTree.size(); i += i & (~i + 1))
                    mTree[i] += d;
            }
            std::int64_t total() const { return mTotal; }
            /// The slot holding pair number `u` (0 <= u < total()) and `u` within it.
            std::size_t find(std::int64_t& u) const
            {
                std::size_t pos = 0, step = 1;
                while (step * 2 < mTree.size())
                    step *= 2;
                for (; step > 0; step /= 2)
                    if (pos + step < mTree.size() && mTree[pos + step] <= u)
                    {
                        pos += step;
                        u -= mTree[pos];
                    }
                return pos;
            }

        private:
            std::vector<std::int64_t> mTree, mValue;
            std::int64_t mTotal = 0;
        };

        struct Candidate
        {
            bool straighten = false;
            std::int32_t a = 0, b = 0;
            bool operator==(const Candidate& o) const { return straighten == o.straighten && a == o.a && b == o.b; }
        };

        /// A candidate worked out: the merged line, the lines that leave and those that come (the
        /// merged line first, then combine's moved children).
        struct Proposal
        {
            WorkLine merged;
            std::vector<std::int32_t> removed;
            std::vector<std::pair<std::int32_t, WorkLine>> moved; ///< children with their new start
            double cost = 0.0;                                    ///< weighted displacement
        };

        class LineMerger
        {
        public:
            LineMerger(std::vector<WorkLine> lines, CoverageViews& views, std::uint64_t seed)
                : mLines(std::move(lines)), mViews(views), mState(seed ^ 0x6C696E6573ull),
                  mCounts(2 * mLines.size() + 1), mRoot(2 * mLines.size())
            {
                mLines.reserve(2 * mLines.size());
                for (std::size_t i = 0; i < mLines.size(); ++i)
                {
                    const std::int32_t p = mLines[i].parent;
                    (p == NO_PARENT ? mRootChildren : mLines[std::size_t(p)].children).push_back(std::int32_t(i));
                }
                mAlive = mLines.size();
                for (std::size_t i = 0; i < mLines.size(); ++i)
                    mCounts.set(i, pairs(std::int32_t(i)));
                mCounts.set(mRoot, pairs(NO_PARENT));
                for (std::size_t v = 0; v < mViews.viewCount(); ++v)
                {
                    std::vector<Stadium> all;
                    for (const WorkLine& l : mLines)
                        all.push_back(mViews.project(v, l.start, l.end, l.radius));
                    mViews.reset(v, all);
                }
            }

            std::size_t alive() const { return mAlive; }
            const std::vector<WorkLine>& lines() const { return mLines; }

            /// One merge: `candidates` draws, the best applied.
            void step(std::uint32_t candidates)
            {
                std::vector<Candidate> drawn;
                for (std::uint32_t k = 0; k < candidates; ++k)
                {
                    const Candidate c = draw();
                    if (std::find(drawn.begin(), drawn.end(), c) == drawn.end())
                        drawn.push_back(c);
                }
                std::vector<Proposal> proposals;
                for (const Candidate& c : drawn)
                    proposals.push_back(propose(c));
                const std::size_t views = mViews.viewCount();
                std::vector<std::vector<double>> deltas(proposals.size() * views);
                tbb::parallel_for(std::size_t(0), deltas.size(),
                                  [&](std::size_t task)
                                  {
                                      const std::size_t p = task / views, v = task % views;
                                      std::vector<Stadium> removed, added;
                                      stadiums(proposals[p], v, removed, added);
                                      mViews.change(v, removed, added, false, deltas[task]);
                                  });
                std::size_t best = 0;
                double bestError = std::numeric_limits<double>::infinity();
                for (std::size_t p = 0; p < proposals.size(); ++p)
                {
                    std::vector<const std::vector<double>*> own;
                    for (std::size_t v = 0; v < views; ++v)
                        own.push_back(&deltas[p * views + v]);
                    const double e = mViews.error(&own);
                    if (e < bestError || (e == bestError && proposals[p].cost < proposals[best].cost))
                    {
                        bestError = e;
                        best = p;
                    }
                }
                apply(drawn[best], proposals[best]);
            }

            /// Every band's squares from the sums again (no drift over thousands of merges).
            void settle()
            {
                for (std::size_t v = 0; v < mViews.viewCount(); ++v)
                    mViews.recomputeSquares(v);
            }

        private:
            std::vector<std::int32_t>& childrenOf(std::int32_t parent)
            {
                return parent == NO_PARENT ? mRootChildren : mLines[std::size_t(parent)].children;
            }

            std::int64_t pairs(std::int32_t parent)
            {
                const std::int64_t k = std::int64_t(childrenOf(parent).size());
                if (parent != NO_PARENT && k == 1)
                    return 1; // straighten with the only child
                return k * (k - 1) / 2;
            }

            void updateCount(std::int32_t parent)
            {
                mCounts.set(parent == NO_PARENT ? mRoot : std::size_t(parent), pairs(parent));
            }

            Candidate draw()
            {
                if (mCounts.total() <= 0)
                    throw std::logic_error("no mergeable pair among " + std::to_string(mAlive) + " lines");
                std::int64_t u = std::int64_t(splitMix(mState) % std::uint64_t(mCounts.total()));
                const std::size_t slot = mCounts.find(u);
                const std::int32_t parent = slot == mRoot ? NO_PARENT : std::int32_t(slot);
                const std::vector<std::int32_t>& children = childrenOf(parent);
                const std::int64_t k = std::int64_t(children.size());
                if (parent != NO_PARENT && k == 1)
                    return {true, parent, children.front()};
                std::int64_t q = std::int64_t(splitMix(mState) % std::uint64_t(k * (k - 1) / 2));
                for (std::int64_t i = 0; i < k; ++i)
                {
                    const std::int64_t row = k - 1 - i;
                    if (q < row)
                        return {false, children[std::size_t(i)], children[std::size_t(i + 1 + q)]};
                    q -= row;
                }
                return {false, children[0], children[1]}; // not reached
            }

            Proposal propose(const Candidate& c) const
            {
                const WorkLine &a = mLines[std::size_t(c.a)], &b = mLines[std::size_t(c.b)];
                Proposal p;
                const double total = a.weight + b.weight;
                const double fa = total > 0.0 ? a.weight / total : 0.5, fb = 1.0 - fa;
                WorkLine& m = p.merged;
                m.start = c.straighten ? a.start : fa * a.start + fb * b.start;
                m.end = c.straighten ? b.end : fa * a.end + fb * b.end;
                m.radius = fa * a.radius + fb * b.radius;
                m.colour = fa * a.colour + fb * b.colour;
                m.weight = total;
                m.parent = a.parent;
                p.removed = {c.a, c.b};
                if (!c.straighten)
                    for (const WorkLine* l : {&a, &b})
                        for (std::int32_t child : l->children)
                        {
                            p.removed.push_back(child);
                            WorkLine moved = mLines[std::size_t(child)];
                            moved.start = m.end;
                            p.moved.emplace_back(child, std::move(moved));
                        }
                for (const WorkLine* l : {&a, &b})
                    p.cost += l->weight * 0.5 *
                              (segmentDistance(l->start, m.start, m.end) + segmentDistance(l->end, m.start, m.end));
                return p;
            }

            void stadiums(const Proposal& p, std::size_t v, std::vector<Stadium>& removed,
                          std::vector<Stadium>& added) const
            {
                for (std::int32_t id : p.removed)
                {
                    const WorkLine& l = mLines[std::size_t(id)];
                    removed.push_back(mViews.project(v, l.start, l.end, l.radius));
                }
                added.push_back(mViews.project(v, p.merged.start, p.merged.end, p.merged.radius));
                for (const auto& [id, l] : p.moved)
                    added.push_back(mViews.project(v, l.start, l.end, l.radius));
            }

            void apply(const Candidate& c, Proposal& p)
            {
                tbb::parallel_for(std::size_t(0), mViews.viewCount(),
                                  [&](std::size_t v)
                                  {
                                      std::vector<Stadium> removed, added;
                                      stadiums(p, v, removed, added);
                                      std::vector<double> unused;
                                      mViews.change(v, removed, added, true, unused);
                                  });
                const std::int32_t id = std::int32_t(mLines.size());
                const std::int32_t parent = mLines[std::size_t(c.a)].parent;
                WorkLine merged = std::move(p.merged);
                if (c.straighten)
                    merged.children = mLines[std::size_t(c.b)].children;
                else
                {
                    merged.children = mLines[std::size_t(c.a)].children;
                    const std::vector<std::int32_t>& more = mLines[std::size_t(c.b)].children;
                    merged.children.insert(merged.children.end(), more.begin(), more.end());
                    for (auto& [child, moved] : p.moved)
                        mLines[std::size_t(child)].start = moved.start;
                }
                for (std::int32_t child : merged.children)
                    mLines[std::size_t(child)].parent = id;
                std::vector<std::int32_t>& siblings = childrenOf(parent);
                *std::find(siblings.begin(), siblings.end(), c.a) = id;
                if (!c.straighten)
                    siblings.erase(std::find(siblings.begin(), siblings.end(), c.b));
                for (std::int32_t dead : {c.a, c.b})
                {
                    mLines[std::size_t(dead)].alive = false;
                    mLines[std::size_t(dead)].children.clear();
                    mCounts.set(std::size_t(dead), 0);
                }
                mLines.push_back(std::move(merged));
                mCounts.set(std::size_t(id), pairs(id));
                updateCount(parent);
                --mAlive;
            }

            std::vector<WorkLine> mLines;
            CoverageViews& mViews;
            std::uint64_t mState;
            PairCounts mCounts;
            std::size_t mRoot;
            std::vector<std::int32_t> mRootChildren;
            std::size_t mAlive = 0;
        };

        /// The lines of the skeleton (EllipsoidLineBaker.h, step 2) in the baker's units.
        Result<std::vector<WorkLine>> skeletonLines(const TreeModel& model, const std::vector<SkeletonNode>& skeleton,
                                                    const glm::dvec3& origin, double diagonal, const std::string& label)
        {
            const std::size_t n = skeleton.size();
            std::vector<glm::dvec3> position(n);
            std::vector<double> radius(n);
            for (std::size_t i = 0; i < n; ++i)
            {
                const SkeletonNode& node = skeleton[i];
                position[i] = (glm::dvec3(node.position) - origin) / diagonal;
                radius[i] = std::max(double(node.radius), 0.0) / diagonal;
                if (!finite(position[i]) || !std::isfinite(radius[i]))
                    return fail(label, "skeleton node " + std::to_string(i), "position or radius is not finite");
                if (node.parent >= std::int32_t(i))
                    return fail(label, "skeleton node " + std::to_string(i), "parent must come before its child");
            }

            // Each node's bark colour: the mean of the bark triangles nearest it (one colour when the
            // bark has one).
            const std::vector<glm::dvec3> materials = materialColours(model);
            std::vector<glm::dvec3> colourSum(n, glm::dvec3(0.0));
            std::vector<double> areaSum(n, 0.0);
            glm::dvec3 total(0.0);
            double totalArea = 0.0;
            bool oneColour = true;
            std::vector<std::pair<glm::dvec3, std::size_t>> triangles; // centroid, material
            std::vector<double> areas;
            for (std::size_t t = 0; t < model.barkTriangleCount(); ++t)
            {
                const glm::dvec3 a(model.barkVertices[model.barkIndices[3 * t]].position);
                const glm::dvec3 b(model.barkVertices[model.barkIndices[3 * t + 1]].position);
                const glm::dvec3 c(model.barkVertices[model.barkIndices[3 * t + 2]].position);
                if (degenerateTriangle(a, b, c))
                    continue;
                const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
                const std::size_t material = model.barkTriangleMaterial[t];
                triangles.emplace_back(((a + b + c) / 3.0 - origin) / diagonal, material);
                areas.push_back(area);
                total += area * materials[material];
                totalArea += area;
                oneColour = oneColour && materials[material] == materials[triangles.front().second];
            }
            const glm::dvec3 mean = totalArea > 0.0 ? total / totalArea : glm::dvec3(0.5);
            std::vector<glm::dvec3> colour(n, mean);
            if (!oneColour && n > 0)
            {
                const NearestPoint nearest(position, 1.0 / 32.0);
                for (std::size_t t = 0; t < triangles.size(); ++t)
                {
                    const std::uint32_t node = nearest.nearest(triangles[t].first);
                    colourSum[node] += areas[t] * materials[triangles[t].second];
                    areaSum[node] += areas[t];
                }
                for (std::size_t i = 0; i < n; ++i)
                    if (areaSum[i] > 0.0)
                        colour[i] = colourSum[i] / areaSum[i];
            }

            // Lines: a node on its parent is merged into it (its representative).
            std::vector<std::int32_t> representative(n), lineOf(n, NO_PARENT);
            std::vector<std::uint8_t> hasChild(n, 0);
            std::vector<WorkLine> lines;
            for (std::size_t i = 0; i < n; ++i)
            {
                const std::int32_t p = skeleton[i].parent;
                representative[i] = std::int32_t(i);
                if (p < 0)
                    continue;
                const std::int32_t from = representative[std::size_t(p)];
                if (glm::length(position[i] - position[std::size_t(from)]) <= SAME_NODE)
                {
                    representative[i] = from;
                    continue;
                }
                hasChild[std::size_t(from)] = 1;
                WorkLine l;
                l.start = position[std::size_t(from)];
                l.end = position[i];
                l.radius = std::max(0.5 * (radius[std::size_t(from)] + radius[i]), MIN_RADIUS);
                l.weight = capsuleVolume(l.radius, glm::length(l.end - l.start));
                l.colour = colour[i];
                l.parent = lineOf[std::size_t(from)];
                lineOf[i] = std::int32_t(lines.size());
                lines.push_back(l);
            }
            for (std::size_t i = 0; i < n; ++i)
                if (skeleton[i].parent < 0 && !hasChild[i])
                {
                    WorkLine l;
                    l.start = l.end = position[i];
                    l.radius = std::max(radius[i], MIN_RADIUS);
                    l.weight = capsuleVolume(l.radius, 0.0);
                    l.colour = colour[i];
                    lines.push_back(l);
                }
            return lines;
        }

        /// A copy of the lines alive now.
        std::vector<WorkLine> aliveLines(const std::vector<WorkLine>& lines)
        {
            std::vector<WorkLine> out;
            for (const WorkLine& l : lines)
                if (l.alive)
                {
                    out.push_back(l);
                    out.back().children.clear();
                }
            return out;
        }

        /// Up to 256 sRGB colours standing for `colours` (median cut when there are more) and the
        /// index of each.
        std::vector<std::uint8_t> buildPalette(const std::vector<std::array<std::uint8_t, 3>>& colours,
                                               std::vector<std::array<std::uint8_t, 4>>& palette)
        {
            std::map<std::array<std::uint8_t, 3>, std::size_t> counts;
            for (const auto& c : colours)
                ++counts[c];
            std::vector<std::pair<std::array<std::uint8_t, 3>, std::size_t>> unique(counts.begin(), counts.end());
            std::vector<std::vector<std::size_t>> boxes(1);
            for (std::size_t i = 0; i < unique.size(); ++i)
                boxes[0].push_back(i);
            while (boxes.size() < ELLIPSOID_LINE_MAX_PALETTE)
            {
                // Split the box of the widest channel range at its weighted median.
                std::size_t widest = 0;
                int widestRange = 0, widestChannel = 0;
                for (std::size_t b = 0; b < boxes.size(); ++b)
                    for (int ch = 0; ch < 3; ++ch)
                    {
                        int lo = 255, hi = 0;
                        for (std::size_t i : boxes[b])
                        {
                            lo = std::min(lo, int(unique[i].first[std::size_t(ch)]));
                            hi = std::max(hi, int(unique[i].first[std::size_t(ch)]));
                        }
                        if (hi - lo > widestRange)
                        {
                            widestRange = hi - lo;
                            widest = b;
                            widestChannel = ch;
                        }
                    }
                if (widestRange == 0)
                    break; // every box holds one colour
                std::vector<std::size_t>& box = boxes[widest];
                std::stable_sort(box.begin(), box.end(),
                                 [&](std::size_t a, std::size_t b) {
                                     return unique[a].first[std::size_t(widestChannel)] <
                                            unique[b].first[std::size_t(widestChannel)];
                                 });
                std::size_t weight = 0, half = 0;
                for (std::size_t i : box)
                    weight += unique[i].second;
                std::size_t cut = 1;
                for (std::size_t k = 0; k + 1 < box.size(); ++k)
                {
                    half += unique[box[k]].second;
                    cut = k + 1;
                    if (2 * half >= weight)
                        break;
                }
                std::vector<std::size_t> upper(box.begin() + std::ptrdiff_t(cut), box.end());
                box.resize(cut);
                boxes.push_back(std::move(upper));
            }
            std::map<std::array<std::uint8_t, 3>, std::uint8_t> index;
            palette.clear();
            for (const std::vector<std::size_t>& box : boxes)
            {
                glm::dvec3 sum(0.0);
                double weight = 0.0;
                for (std::size_t i : box)
                {
                    sum += double(unique[i].second) *
                           glm::dvec3(unique[i].first[0], unique[i].first[1], unique[i].first[2]);
                    weight += double(unique[i].second);
                    index[unique[i].first] = std::uint8_t(palette.size());
                }
                const glm::dvec3 m = weight > 0.0 ? sum / weight : glm::dvec3(0.0);
                palette.push_back({std::uint8_t(std::lround(m.r)), std::uint8_t(std::lround(m.g)),
                                   std::uint8_t(std::lround(m.b)), 255});
            }
            std::vector<std::uint8_t> out;
            for (const auto& c : colours)
                out.push_back(index.at(c));
            return out;
        }

        /// §6: the length-weighted mean line diameter (units), the plain mean when no line has a length.
        double meanWidth(const std::vector<WorkLine>& lines)
        {
            double widthLength = 0.0, length = 0.0, width = 0.0;
            for (const WorkLine& l : lines)
            {
                const double L = glm::length(l.end - l.start);
                widthLength += 2.0 * l.radius * L;
                length += L;
                width += 2.0 * l.radius;
            }
            return length > 0.0 ? widthLength / length : width / double(std::max<std::size_t>(lines.size(), 1));
        }
    }

    TreeModel ellipsoidLineLevelMesh(const EllipsoidLineData& data, std::size_t level)
    {
        TreeModel m = emptyCapsuleModel();
        if (level < data.levels.size())
        {
            const EllipsoidLineLevel& l = data.levels[level];
            for (std::uint32_t i = l.first; i < l.first + l.count && i < data.lines.size(); ++i)
                appendCapsule(m, glm::dvec3(data.lines[i].start), glm::dvec3(data.lines[i].end),
                              double(data.lines[i].radius));
        }
        finishCapsuleModel(m);
        return m;
    }

    TreeModel flatColourBark(const TreeModel& model)
    {
        TreeModel m;
        m.name = model.name + " (flat bark)";
        m.materials = model.materials;
        for (Material& material : m.materials)
        {
            material.baseColour = glm::vec4(1.0f);
            material.backColour = glm::vec3(0.0f);
            material.texture = -1;
        }
        m.barkVertices = model.barkVertices;
        m.barkIndices = model.barkIndices;
        m.barkTriangleMaterial = model.barkTriangleMaterial;
        m.updateBounds();
        return m;
    }

    Result<EllipsoidLineData> bakeEllipsoidLines(const TreeModel& model, const EllipsoidLineOptions& options,
                                                 const std::string& label, const ProgressCallback& progress,
                                                 std::vector<double>* weights)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = model.validate(label); !valid)
            return valid.error();
        if (weights)
            weights->clear();

        // The bark's box: the baker's unit (scale-free from here on).
        report(progress, "lines: skeleton", 0.0f);
        glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        bool anyArea = false;
        for (std::size_t t = 0; t < model.barkTriangleCount(); ++t)
        {
            const glm::dvec3 a(model.barkVertices[model.barkIndices[3 * t]].position);
            const glm::dvec3 b(model.barkVertices[model.barkIndices[3 * t + 1]].position);
            const glm::dvec3 c(model.barkVertices[model.barkIndices[3 * t + 2]].position);
            if (degenerateTriangle(a, b, c))
                continue;
            anyArea = true;
            lo = glm::min(lo, glm::min(a, glm::min(b, c)));
            hi = glm::max(hi, glm::max(a, glm::max(b, c)));
        }
        const double diagonal = anyArea ? glm::length(hi - lo) : 0.0;
        if (!(diagonal > 0.0) || !std::isfinite(diagonal))
            return EllipsoidLineData{}; // no bark to draw: no lines
        const glm::dvec3 origin = 0.5 * (lo + hi);
        const std::vector<SkeletonNode> skeleton = barkSkeleton(model);
        if (skeleton.empty())
            return EllipsoidLineData{};
        Result<std::vector<WorkLine>> initial = skeletonLines(model, skeleton, origin, diagonal, label);
        if (!initial)
            return initial.error();
        const std::size_t n = initial->size();
        report(progress, "lines: skeleton", 1.0f);

        // The level targets (EllipsoidLineBaker.h, 5.).
        std::vector<std::size_t> targets{n};
        for (std::size_t k = n / options.linesDivisor; k >= 1; k /= options.linesDivisor)
            targets.push_back(k);
        if (targets.back() > 1)
            targets.push_back(1);
        if (targets.size() > ELLIPSOID_LINE_MAX_LEVELS)
            return fail(label, "ellipsoid-lines option linesDivisor",
                        std::to_string(targets.size()) + " levels for " + std::to_string(n) + " lines, at most " +
                            std::to_string(ELLIPSOID_LINE_MAX_LEVELS));

        // The model's whole box height (EllipsoidLineData.h, heightMetres), as TreeModel::updateBounds.
        glm::dvec3 boxLo = lo, boxHi = hi;
        for (const std::vector<Vertex>* vertices : {&model.barkVertices, &model.leafVertices})
            for (const Vertex& v : *vertices)
            {
                boxLo = glm::min(boxLo, glm::dvec3(v.position));
                boxHi = glm::max(boxHi, glm::dvec3(v.position));
            }
        const double height = boxHi.y - boxLo.y > 0.0 ? boxHi.y - boxLo.y : glm::length(boxHi - boxLo);

        std::vector<std::vector<WorkLine>> levels;
        std::vector<double> levelErrors;
        try
        {
            // The reference: the flat bark in the baker's units.
            TreeModel bark = flatColourBark(model);
            for (Vertex& v : bark.barkVertices)
                v.position = glm::vec3((glm::dvec3(v.position) - origin) / diagonal);
            bark.updateBounds();
            const std::vector<CameraSpec> cameras = errorCameras();
            const RenderOptions renderOptions = EllipsoidErrorViews::renderOptions(options.viewResolution);
            std::vector<Image> reference;
            {
                const ReferenceRenderer renderer(bark);
                for (const CameraSpec& c : cameras)
                    reference.push_back(renderer.render(c, renderOptions).colour);
            }

            // 3. The merges, recording the levels on the way.
            report(progress, "lines: merging", 0.0f);
            CoverageViews views(cameras, options.viewResolution, reference);
            LineMerger merger(std::move(initial).value(), views, options.seed);
            levels.push_back(aliveLines(merger.lines()));
            std::size_t next = 1;
            const std::size_t merges = n - 1;
            for (std::size_t m = 0; merger.alive() > 1; ++m)
            {
                merger.step(options.candidates);
                if (next < targets.size() && merger.alive() == targets[next])
                {
                    merger.settle();
                    levels.push_back(aliveLines(merger.lines()));
                    ++next;
                }
                if ((m & 63) == 0)
                    report(progress, "lines: merging", float(m + 1) / float(merges));
            }
            report(progress, "lines: merging", 1.0f);

            // 5. Each level's error, ray-traced.
            for (std::size_t k = 0; k < levels.size(); ++k)
            {
                const std::string step =
                    "lines: level " + std::to_string(k + 1) + " of " + std::to_string(levels.size());
                report(progress, step, 0.0f);
                TreeModel mesh = emptyCapsuleModel();
                for (const WorkLine& l : levels[k])
                    appendCapsule(mesh, l.start, l.end, l.radius);
                finishCapsuleModel(mesh);
                const ReferenceRenderer renderer(mesh);
                double sum = 0.0;
                for (std::size_t v = 0; v < cameras.size(); ++v)
                {
                    Result<MultiScaleRmseResult> e =
                        multiScaleRmse(reference[v], renderer.render(cameras[v], renderOptions).colour);
                    if (!e)
                        throw std::runtime_error(e.error().message());
                    sum += e->combined;
                }
                levelErrors.push_back(sum / double(cameras.size()));
                report(progress, step, 1.0f);
            }
        }
        catch (const std::exception& e)
        {
            return fail(label, "ellipsoid-lines", std::string("rendering failed: ") + e.what());
        }

        // To metres, with the palette.
        EllipsoidLineData data;
        data.radiusUnit = float(diagonal);
        data.heightMetres = float(height);
        std::vector<std::array<std::uint8_t, 3>> colours;
        glm::vec3 endLo(std::numeric_limits<float>::max()), endHi(-std::numeric_limits<float>::max());
        for (std::size_t k = 0; k < levels.size(); ++k)
        {
            EllipsoidLineLevel level;
            level.first = std::uint32_t(data.lines.size());
            level.count = std::uint32_t(levels[k].size());
            level.imageError = float(std::clamp(levelErrors[k], 0.0, 1.0));
            level.targetHeightPx = float(height * double(ELLIPSOID_LINE_TARGET_WIDTH_PX) /
                                         std::max(meanWidth(levels[k]) * diagonal, 1e-30));
            if (k > 0)
                level.targetHeightPx = std::min(level.targetHeightPx, data.levels.back().targetHeightPx);
            data.levels.push_back(level);
            for (const WorkLine& w : levels[k])
            {
                EllipsoidLine l;
                l.start = glm::vec3(origin + diagonal * w.start);
                l.end = glm::vec3(origin + diagonal * w.end);
                l.radius = float(diagonal * w.radius);
                endLo = glm::min(endLo, glm::min(l.start, l.end));
                endHi = glm::max(endHi, glm::max(l.start, l.end));
                colours.push_back({linearToSrgbByte(float(w.colour.r)), linearToSrgbByte(float(w.colour.g)),
                                   linearToSrgbByte(float(w.colour.b))});
                data.lines.push_back(l);
                if (weights)
                    weights->push_back(w.weight * diagonal * diagonal * diagonal);
            }
        }
        data.boundsMin = endLo;
        data.boundsMax = endHi;
        const std::vector<std::uint8_t> index = buildPalette(colours, data.palette);
        for (std::size_t i = 0; i < data.lines.size(); ++i)
            data.lines[i].colour = index[i];
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<void> addEllipsoidLineChunk(PackageWriter& writer, const TreeModel& model,
                                       const EllipsoidLineOptions& options, const std::string& label,
                                       const ProgressCallback& progress)
    {
        if (Result<void> reference = addReferenceChunkIfMissing(writer, model, label, progress); !reference)
            return reference;
        Result<EllipsoidLineData> data = bakeEllipsoidLines(model, options, label, progress);
        if (!data)
            return data.error();
        if (data->lines.empty())
            return {};
        return addEncodedChunk(writer, ELLIPSOID_LINES_CHUNK, ELLIPSOID_LINES_CHUNK_FORMAT_VERSION,
                               encodeEllipsoidLineChunk, data.value(), label);
    }
}
