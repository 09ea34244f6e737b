// EllipsoidTreeBaker: the ellipsoid hierarchy of a tree's leaves (steps and deviations from the
// ellipsoids-and-lines paper (001) in EllipsoidTreeBaker.h, format in EllipsoidTreeData.h).
#include "TreeLod/EllipsoidTreeBaker.h"

#include "EllipsoidErrorViews.h"

#include "TreeLod/EllipsoidLineBaker.h"
#include "TreeLod/GaussianMixture.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/ReferenceRenderer.h"

#include <Eigen/Eigenvalues>
#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <tuple>

namespace TreeLod
{
    namespace
    {
        constexpr double PI = 3.14159265358979323846;
        /// EM parameters in units of the leaves' box diagonal (GaussianMixture.h).
        constexpr double COVARIANCE_FLOOR = 1e-6;  // (a thousandth of the tree)^2
        constexpr std::uint32_t EM_CANDIDATES = 12;
        constexpr std::uint32_t EM_MAX_ITERATIONS = 100;
        constexpr double EM_TOLERANCE = 1e-5;
        constexpr std::uint32_t EM_CANDIDATE_REFRESH = 8;
        /// Calibration factors (§3.1): a coarse grid, extended by its step while the best is at
        /// an end (within [MIN_SCALE, MAX_SCALE]), then +-REFINE around the best.
        constexpr std::array<float, 5> COARSE_SCALES = {0.6f, 0.8f, 1.0f, 1.2f, 1.4f};
        constexpr float COARSE_STEP = 0.2f, REFINE = 0.1f, MIN_SCALE = 0.2f, MAX_SCALE = 3.0f;
        /// Noise calibration (§3.1, Fig. 6): alpha thresholds (0: none), area compensations on
        /// the calibrated scale for each, and normal blends.
        constexpr std::array<float, 5> NOISE_THRESHOLDS = {0.0f, 0.25f, 0.4f, 0.5f, 0.6f};
        constexpr std::array<float, 6> AREA_COMPENSATIONS = {1.0f, 1.1f, 1.2f, 1.35f, 1.5f, 1.7f};
        constexpr std::array<float, 5> NORMAL_BLENDS = {0.0f, 0.15f, 0.3f, 0.5f, 0.7f};

        std::uint64_t splitMix(std::uint64_t& state)
        {
            std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
            z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
            z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
            return z ^ (z >> 31);
        }

        double uniform01(std::uint64_t& state) { return double(splitMix(state) >> 11) * (1.0 / 9007199254740992.0); }

        Result<void> checkOptions(const EllipsoidTreeOptions& o, const std::string& label)
        {
            if (o.tries < 1 || o.tries > 16)
                return fail(label, "ellipsoids option tries", std::to_string(o.tries) + " is outside [1, 16]");
            if (o.triedClusters < 1)
                return fail(label, "ellipsoids option triedClusters", "0 is below 1");
            if (o.clustersDivisor < 2 || o.clustersDivisor > 64)
                return fail(label, "ellipsoids option clustersDivisor",
                            std::to_string(o.clustersDivisor) + " is outside [2, 64]");
            if (!(o.minAreaShare >= 0.0f && o.minAreaShare <= 0.5f))
                return fail(label, "ellipsoids option minAreaShare",
                            std::to_string(o.minAreaShare) + " is outside [0, 0.5]");
            if (o.viewResolution < 16 || o.viewResolution > 1024)
                return fail(label, "ellipsoids option viewResolution",
                            std::to_string(o.viewResolution) + " is outside [16, 1024]");
            if (o.aoRays > 1024)
                return fail(label, "ellipsoids option aoRays", std::to_string(o.aoRays) + " is outside [0, 1024]");
            return {};
        }

        /// The unit icosphere of 80 triangles, scaled so that its surface area is 4 pi (a convex
        /// body's mean projected area is a quarter of its surface: it covers what the sphere does).
        struct Icosphere
        {
            std::vector<glm::vec3> vertices;
            std::vector<std::uint32_t> indices;

            Icosphere()
            {
                const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
                const glm::vec3 base[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
                const std::uint32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
                for (const glm::vec3& v : base)
                    vertices.push_back(glm::normalize(v));
                std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middles;
                auto middle = [&](std::uint32_t a, std::uint32_t b) {
                    const auto key = std::minmax(a, b);
                    auto it = middles.find(key);
                    if (it != middles.end())
                        return it->second;
                    vertices.push_back(glm::normalize(vertices[a] + vertices[b]));
                    return middles[key] = std::uint32_t(vertices.size() - 1);
                };
                for (const auto& f : faces)
                {
                    const std::uint32_t a = middle(f[0], f[1]), b = middle(f[1], f[2]), c = middle(f[2], f[0]);
                    for (std::uint32_t i : {f[0], a, c, f[1], b, a, f[2], c, b, a, b, c})
                        indices.push_back(i);
                }
                double area = 0.0;
                for (std::size_t i = 0; i < indices.size(); i += 3)
                    area += 0.5 * double(glm::length(glm::cross(vertices[indices[i + 1]] - vertices[indices[i]],
                                                                vertices[indices[i + 2]] - vertices[indices[i]])));
                const float grow = float(std::sqrt(4.0 * PI / area));
                for (glm::vec3& v : vertices)
                    v *= grow;
            }
        };

        const Icosphere& icosphere()
        {
            static const Icosphere sphere;
            return sphere;
        }

        /// Opaque double-sided bark of one white material: the ellipsoids, radii times `scale`.
        TreeModel ellipsoidMesh(const std::vector<Ellipsoid>& ellipsoids, float scale)
        {
            const Icosphere& s = icosphere();
            TreeModel m;
            m.name = "ellipsoids";
            Material white;
            white.name = "TreeLod/EllipsoidBake";
            white.doubleSided = true;
            m.materials.push_back(white);
            m.barkVertices.reserve(ellipsoids.size() * s.vertices.size());
            m.barkIndices.reserve(ellipsoids.size() * s.indices.size());
            for (const Ellipsoid& e : ellipsoids)
            {
                const glm::mat3 axes = glm::mat3_cast(e.rotation);
                const std::uint32_t first = std::uint32_t(m.barkVertices.size());
                for (const glm::vec3& u : s.vertices)
                {
                    Vertex v;
                    v.position = e.centre + axes * (scale * e.radii * u);
                    v.normal = glm::normalize(axes * (u / glm::max(e.radii, glm::vec3(1e-30f))));
                    m.barkVertices.push_back(v);
                }
                for (std::uint32_t i : s.indices)
                    m.barkIndices.push_back(first + i);
            }
            m.barkTriangleMaterial.assign(m.barkIndices.size() / 3, 0);
            m.updateBounds();
            return m;
        }

        /// Four orthographic views of the leaves' box and the mean multi-scale RMSE over them (§4).
        class ErrorViews
        {
        public:
            ErrorViews(const glm::vec3& lo, const glm::vec3& hi, int resolution)
                : mCameras(EllipsoidErrorViews::cameras(0.5f * (lo + hi), std::max(0.5f * glm::length(hi - lo), 1e-30f))),
                  mOptions(EllipsoidErrorViews::renderOptions(resolution)),
                  mShaded(EllipsoidErrorViews::shadedRenderOptions(resolution))
            {
            }

            /// Coverage (or shaded) images of a model. Throws std::runtime_error (Embree) like the renderer.
            std::vector<Image> render(const TreeModel& model, bool shaded = false) const
            {
                const ReferenceRenderer renderer(model);
                std::vector<Image> images;
                for (const CameraSpec& c : mCameras)
                    images.push_back(renderer.render(c, shaded ? mShaded : mOptions).colour);
                return images;
            }

            /// The ellipsoids ray cast as the renderer draws them (renderEllipsoids), noise included;
            /// the views in parallel.
            std::vector<Image> renderRayCast(const std::vector<Ellipsoid>& metres, float scale,
                                             const EllipsoidNoiseSetting& noise = {}, bool shaded = false) const
            {
                std::vector<Image> images(mCameras.size());
                tbb::parallel_for(std::size_t(0), mCameras.size(), [&](std::size_t v) {
                    images[v] = renderEllipsoids(metres, scale, noise, mCameras[v], shaded ? mShaded : mOptions);
                });
                return images;
            }

            double error(const std::vector<Image>& reference, const std::vector<Image>& test) const
            {
                double sum = 0.0;
                for (std::size_t v = 0; v < reference.size(); ++v)
                {
                    Result<MultiScaleRmseResult> e = multiScaleRmse(reference[v], test[v]);
                    if (!e)
                        throw std::runtime_error(e.error().message());
                    sum += e->combined;
                }
                return sum / double(reference.size());
            }

        private:
            std::vector<CameraSpec> mCameras;
            RenderOptions mOptions, mShaded;
        };

        /// Linear mean colour of a leaf: base colour times the mean of its texture's texels in its
        /// UV box that pass the alpha test (all of them when none does).
        class LeafColours
        {
        public:
            explicit LeafColours(const TreeModel& model) : mModel(model) {}

            glm::vec3 colour(const Leaf& leaf)
            {
                const auto key = std::make_tuple(leaf.material, leaf.uvMin.x, leaf.uvMin.y, leaf.uvMax.x, leaf.uvMax.y);
                auto it = mCache.find(key);
                if (it != mCache.end())
                    return it->second;
                const Material& m = mModel.materials[leaf.material];
                glm::vec3 colour = glm::vec3(m.baseColour);
                if (m.texture >= 0 && std::size_t(m.texture) < mModel.textures.size())
                {
                    const TextureImage& t = mModel.textures[std::size_t(m.texture)];
                    if (t.width > 0 && t.height > 0 && t.rgba.size() >= std::size_t(t.width) * t.height * 4)
                    {
                        const glm::vec2 lo = glm::clamp(glm::min(leaf.uvMin, leaf.uvMax), 0.0f, 1.0f);
                        const glm::vec2 hi = glm::clamp(glm::max(leaf.uvMin, leaf.uvMax), 0.0f, 1.0f);
                        const int x0 = std::clamp(int(lo.x * float(t.width)), 0, t.width - 1);
                        const int x1 = std::clamp(int(std::ceil(hi.x * float(t.width))) - 1, x0, t.width - 1);
                        const int y0 = std::clamp(int(lo.y * float(t.height)), 0, t.height - 1);
                        const int y1 = std::clamp(int(std::ceil(hi.y * float(t.height))) - 1, y0, t.height - 1);
                        glm::dvec3 passed(0.0), all(0.0);
                        double passedCount = 0.0, allCount = 0.0;
                        for (int y = y0; y <= y1; ++y)
                            for (int x = x0; x <= x1; ++x)
                            {
                                const std::uint8_t* p = t.rgba.data() + (std::size_t(y) * t.width + x) * 4;
                                const glm::dvec3 c(srgbByteToLinear(p[0]), srgbByteToLinear(p[1]), srgbByteToLinear(p[2]));
                                all += c;
                                allCount += 1.0;
                                if (m.baseColour.a * byteToUnit(p[3]) >= m.alphaCutoff)
                                {
                                    passed += c;
                                    passedCount += 1.0;
                                }
                            }
                        const glm::dvec3 mean = passedCount > 0.0 ? passed / passedCount : all / allCount;
                        colour *= glm::vec3(mean);
                    }
                }
                mCache.emplace(key, colour);
                return colour;
            }

        private:
            const TreeModel& mModel;
            std::map<std::tuple<std::uint32_t, float, float, float, float>, glm::vec3> mCache;
        };

        /// One level in the baker's working units: the ellipsoids (centres relative to the leaves'
        /// box centre, lengths over its diagonal) and linear colours.
        struct WorkLevel
        {
            std::vector<Ellipsoid> ellipsoids;
            std::vector<glm::vec3> colours;
        };

        /// From working units to metres.
        std::vector<Ellipsoid> toMetres(const std::vector<Ellipsoid>& unit, const glm::dvec3& origin, double diagonal)
        {
            std::vector<Ellipsoid> out = unit;
            for (Ellipsoid& e : out)
            {
                e.centre = glm::vec3(origin + diagonal * glm::dvec3(e.centre));
                e.radii = glm::vec3(diagonal * glm::dvec3(e.radii));
            }
            return out;
        }

        struct LeafSet
        {
            std::vector<std::size_t> leaves;      ///< model leaf indices (area > 0)
            std::vector<glm::dvec3> centres;      ///< working units
            std::vector<glm::dmat3> covariances;  ///< working units
            std::vector<double> weights;          ///< area, mean 1
            std::vector<glm::vec3> colours;       ///< linear
        };

        /// The ellipsoids of EM's components (Fig. 5): weighted PCA of the leaves' distributions.
        WorkLevel clusterEllipsoids(const LeafSet& set, const GaussianMixtureResult& gmm, float minAreaShare)
        {
            const std::size_t k = gmm.means.size(), n = set.centres.size();
            std::vector<double> mass(k, 0.0), members(k, 0.0);
            std::vector<glm::dvec3> sum(k, glm::dvec3(0.0)), colour(k, glm::dvec3(0.0));
            for (std::size_t i = 0; i < n; ++i)
                for (std::uint32_t e = gmm.offsets[i]; e < gmm.offsets[i + 1]; ++e)
                {
                    const std::uint32_t j = gmm.component[e];
                    const double w = gmm.responsibility[e] * set.weights[i];
                    mass[j] += w;
                    members[j] += gmm.responsibility[e];
                    sum[j] += w * set.centres[i];
                    colour[j] += w * glm::dvec3(set.colours[i]);
                }
            std::vector<glm::dvec3> mean(k);
            for (std::size_t j = 0; j < k; ++j)
                mean[j] = mass[j] > 0.0 ? sum[j] / mass[j] : glm::dvec3(0.0);
            std::vector<glm::dmat3> covariance(k, glm::dmat3(0.0));
            for (std::size_t i = 0; i < n; ++i)
                for (std::uint32_t e = gmm.offsets[i]; e < gmm.offsets[i + 1]; ++e)
                {
                    const std::uint32_t j = gmm.component[e];
                    const double w = gmm.responsibility[e] * set.weights[i];
                    const glm::dvec3 d = set.centres[i] - mean[j];
                    covariance[j] += w * (set.covariances[i] + glm::outerProduct(d, d));
                }
            // Components holding under a thousandth of a mean leaf are empty.
            const double emptyMass = 1e-3;
            std::vector<Ellipsoid> all;
            std::vector<glm::vec3> colours;
            std::vector<double> areas;
            for (std::size_t j = 0; j < k; ++j)
            {
                if (!(mass[j] > emptyMass))
                    continue;
                Ellipsoid e = ellipsoidFromCovariance(mean[j], covariance[j] / mass[j]);
                e.leafWeight = float(members[j]);
                all.push_back(e);
                colours.push_back(glm::vec3(colour[j] / mass[j]));
                areas.push_back(ellipsoidSurfaceArea(glm::dvec3(e.radii)));
            }
            // §3.1: drop those under minAreaShare of the largest's surface area.
            const double largest = areas.empty() ? 0.0 : *std::max_element(areas.begin(), areas.end());
            WorkLevel level;
            for (std::size_t j = 0; j < all.size(); ++j)
                if (areas[j] >= double(minAreaShare) * largest)
                {
                    level.ellipsoids.push_back(all[j]);
                    level.colours.push_back(colours[j]);
                }
            return level;
        }

        /// EM runs of a level of k clusters (Alg. 1's t): `tries` up to triedClusters, one above, and
        /// one for one cluster (every start ends alike).
        std::uint32_t levelTries(std::uint32_t k, const EllipsoidTreeOptions& options)
        {
            return k == 1 ? 1 : (k <= options.triedClusters ? options.tries : 1);
        }

        struct Calibrated
        {
            float scale = 1.0f;
            double error = 0.0;
        };

        /// §3.1: the scale factor with the least image error.
        Calibrated calibrate(const std::vector<Ellipsoid>& metres, const ErrorViews& views,
                             const std::vector<Image>& reference)
        {
            Calibrated best{1.0f, std::numeric_limits<double>::infinity()};
            auto tryScale = [&](float s) {
                const double e = views.error(reference, views.renderRayCast(metres, s));
                if (e < best.error)
                    best = Calibrated{s, e};
            };
            // Grid point g is scale g * COARSE_STEP.
            auto step = [](float s) { return int(std::lround(s / COARSE_STEP)); };
            for (float s : COARSE_SCALES)
                tryScale(s);
            for (int g = step(COARSE_SCALES.front()) - 1; g >= step(MIN_SCALE) && step(best.scale) == g + 1; --g)
                tryScale(float(g) * COARSE_STEP);
            for (int g = step(COARSE_SCALES.back()) + 1; g <= step(MAX_SCALE) && step(best.scale) == g - 1; ++g)
                tryScale(float(g) * COARSE_STEP);
            const float centre = best.scale;
            tryScale(centre - REFINE);
            tryScale(centre + REFINE);
            return best;
        }

        struct NoiseCalibrated
        {
            EllipsoidNoiseSetting noise;
            float compensation = 1.0f; ///< on the level's scale
            double error = 0.0;        ///< coverage, at the chosen threshold and compensation
        };

        /// §3.1, Fig. 6: the alpha threshold and the area compensation with the least coverage
        /// error, then the normal blend with the least shaded error; the ellipsoids ray cast with
        /// their noise as the renderer draws them, the noise's footprint that of `pixelSize`
        /// (the level's size on screen). Candidates run in parallel, the first best kept.
        NoiseCalibrated calibrateNoise(const std::vector<Ellipsoid>& metres, float scale, float pixelSize,
                                       const ErrorViews& views, const std::vector<Image>& reference,
                                       const std::vector<Image>& shadedReference)
        {
            using Candidate = NoiseCalibrated;
            auto evaluate = [&](std::vector<Candidate>& candidates, bool shaded) {
                tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t i) {
                    Candidate& c = candidates[i];
                    c.error = views.error(shaded ? shadedReference : reference,
                                          views.renderRayCast(metres, scale * c.compensation, c.noise, shaded));
                });
                return *std::min_element(candidates.begin(), candidates.end(),
                                         [](const Candidate& a, const Candidate& b) { return a.error < b.error; });
            };
            std::vector<Candidate> holes;
            for (float t : NOISE_THRESHOLDS)
                for (float c : AREA_COMPENSATIONS)
                    if (t > 0.0f || c == 1.0f)
                    {
                        Candidate candidate;
                        candidate.noise.threshold = t;
                        candidate.noise.pixelSize = pixelSize;
                        candidate.compensation = c;
                        holes.push_back(candidate);
                    }
            const Candidate bestHoles = evaluate(holes, false);
            std::vector<Candidate> blends;
            for (float b : NORMAL_BLENDS)
            {
                Candidate candidate = bestHoles;
                candidate.noise.normalBlend = b;
                blends.push_back(candidate);
            }
            NoiseCalibrated out = evaluate(blends, true);
            out.noise.pixelSize = 0.0f;
            out.error = bestHoles.error; // the level's error stays the coverage error
            return out;
        }

        /// §6: the tree height on screen (pixels) at which the level's mean ellipsoid is
        /// ELLIPSOID_TARGET_DIAMETER_PX across.
        float targetHeight(const std::vector<Ellipsoid>& metres, float scale, double treeHeight)
        {
            double diameter = 0.0;
            for (const Ellipsoid& e : metres)
                diameter += 2.0 * double(scale) * std::sqrt(ellipsoidSurfaceArea(glm::dvec3(e.radii)) / (4.0 * PI));
            diameter /= double(std::max<std::size_t>(metres.size(), 1));
            return float(double(ELLIPSOID_TARGET_DIAMETER_PX) * treeHeight / std::max(diameter, 1e-30));
        }
    }

    LeafShape leafShape(const TreeModel& model, std::size_t leaf)
    {
        const Leaf& l = model.leaves[leaf];
        LeafShape shape;
        if (l.indexCount < 3)
            return shape;
        // Moments about the first vertex (precision), E[x x^T] of a triangle = (sum v v^T + s s^T) / 12.
        const glm::dvec3 origin(model.leafVertices[model.leafIndices[l.firstIndex]].position);
        glm::dvec3 first(0.0);
        glm::dmat3 second(0.0);
        for (std::uint32_t t = l.firstIndex; t + 2 < l.firstIndex + l.indexCount; t += 3)
        {
            const glm::dvec3 a = glm::dvec3(model.leafVertices[model.leafIndices[t]].position) - origin;
            const glm::dvec3 b = glm::dvec3(model.leafVertices[model.leafIndices[t + 1]].position) - origin;
            const glm::dvec3 c = glm::dvec3(model.leafVertices[model.leafIndices[t + 2]].position) - origin;
            const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
            if (!(area > 0.0) || !std::isfinite(area))
                continue;
            const glm::dvec3 s = a + b + c;
            shape.area += area;
            first += area * s / 3.0;
            second += (area / 12.0) *
                      (glm::outerProduct(a, a) + glm::outerProduct(b, b) + glm::outerProduct(c, c) + glm::outerProduct(s, s));
        }
        if (!(shape.area > 0.0))
            return LeafShape{};
        const glm::dvec3 mean = first / shape.area;
        shape.mean = origin + mean;
        shape.covariance = second / shape.area - glm::outerProduct(mean, mean);
        return shape;
    }

    Ellipsoid ellipsoidFromCovariance(const glm::dvec3& mean, const glm::dmat3& covariance, float minAxisShare)
    {
        Eigen::Matrix3d m;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
            {
                const double v = 0.5 * (covariance[c][r] + covariance[r][c]); // glm: [column][row]
                m(r, c) = std::isfinite(v) ? v : 0.0;
            }
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(m);
        // Eigenvalues ascending: the largest axis is column 2.
        glm::dvec3 radii;
        glm::dmat3 axes;
        for (int k = 0; k < 3; ++k)
        {
            radii[k] = 2.0 * std::sqrt(std::max(solver.eigenvalues()(2 - k), 0.0));
            const Eigen::Vector3d v = solver.eigenvectors().col(2 - k);
            axes[k] = glm::dvec3(v(0), v(1), v(2));
        }
        if (!(radii.x > 0.0) || !std::isfinite(radii.x))
            radii = glm::dvec3(1e-30); // a point: no extent to give it
        for (int k = 1; k < 3; ++k)
            radii[k] = std::max(radii[k], double(minAxisShare) * radii.x);
        axes[2] = glm::cross(axes[0], axes[1]); // right-handed, for the quaternion
        Ellipsoid e;
        e.centre = glm::vec3(mean);
        e.radii = glm::max(glm::vec3(radii), glm::vec3(std::numeric_limits<float>::min()));
        e.rotation = glm::normalize(glm::quat(glm::mat3(axes)));
        e.leafWeight = 1.0f;
        return e;
    }

    double ellipsoidSurfaceArea(const glm::dvec3& r)
    {
        constexpr double p = 1.6075;
        const double a = std::pow(r.x, p), b = std::pow(r.y, p), c = std::pow(r.z, p);
        return 4.0 * PI * std::pow((a * b + a * c + b * c) / 3.0, 1.0 / p);
    }

    TreeModel ellipsoidLevelMesh(const EllipsoidTreeData& data, std::size_t level, float extraScale)
    {
        if (level >= data.levels.size())
            return ellipsoidMesh({}, 1.0f);
        const EllipsoidLevel& l = data.levels[level];
        const std::vector<Ellipsoid> ellipsoids(data.ellipsoids.begin() + l.first,
                                                data.ellipsoids.begin() + l.first + l.count);
        return ellipsoidMesh(ellipsoids, l.scale * extraScale);
    }

    TreeModel flatColourLeaves(const TreeModel& model)
    {
        TreeModel m;
        m.name = model.name + " (flat leaves)";
        m.materials = model.materials;
        for (Material& material : m.materials)
        {
            material.baseColour = glm::vec4(1.0f, 1.0f, 1.0f, material.baseColour.a);
            material.backColour = glm::vec3(0.0f);
        }
        m.textures = model.textures;
        for (TextureImage& t : m.textures)
            for (std::size_t i = 0; i + 3 < t.rgba.size(); i += 4)
                t.rgba[i] = t.rgba[i + 1] = t.rgba[i + 2] = 255;
        m.leafVertices = model.leafVertices;
        m.leafIndices = model.leafIndices;
        m.leaves = model.leaves;
        m.updateBounds();
        return m;
    }

    Result<EllipsoidTreeData> bakeEllipsoidTree(const TreeModel& model, const EllipsoidTreeOptions& options,
                                                const std::string& label, const ProgressCallback& progress)
    {
        if (Result<void> ok = checkOptions(options, label); !ok)
            return ok.error();
        if (Result<void> valid = model.validate(label); !valid)
            return valid.error();

        // 1. One ellipsoid per leaf (§3.1), in units of the leaves' box (scale-free from here on).
        report(progress, "ellipsoids: leaves", 0.0f);
        std::vector<LeafShape> shapes;
        LeafSet set;
        glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (std::size_t i = 0; i < model.leaves.size(); ++i)
        {
            LeafShape s = leafShape(model, i);
            if (!(s.area > 0.0))
                continue;
            set.leaves.push_back(i);
            shapes.push_back(s);
            const Leaf& l = model.leaves[i];
            for (std::uint32_t v = l.firstVertex; v < l.firstVertex + l.vertexCount; ++v)
            {
                lo = glm::min(lo, glm::dvec3(model.leafVertices[v].position));
                hi = glm::max(hi, glm::dvec3(model.leafVertices[v].position));
            }
        }
        if (set.leaves.empty())
            return fail(label, "ellipsoids", "the model has no leaves of nonzero area: nothing to cluster");
        const double diagonal = glm::length(hi - lo);
        if (!(diagonal > 0.0) || !std::isfinite(diagonal))
            return fail(label, "ellipsoids", "the leaves have no extent");
        const glm::dvec3 origin = 0.5 * (lo + hi);
        const std::size_t n = set.leaves.size();
        double totalArea = 0.0;
        for (const LeafShape& s : shapes)
            totalArea += s.area;
        LeafColours leafColours(model);
        WorkLevel leafLevel;
        glm::dvec3 centreLo(std::numeric_limits<double>::max()), centreHi(-std::numeric_limits<double>::max());
        for (std::size_t i = 0; i < n; ++i)
        {
            const glm::dvec3 c = (shapes[i].mean - origin) / diagonal;
            const glm::dmat3 cov = shapes[i].covariance / (diagonal * diagonal);
            set.centres.push_back(c);
            set.covariances.push_back(cov);
            set.weights.push_back(shapes[i].area * double(n) / totalArea);
            set.colours.push_back(leafColours.colour(model.leaves[set.leaves[i]]));
            leafLevel.ellipsoids.push_back(ellipsoidFromCovariance(c, cov));
            leafLevel.colours.push_back(set.colours.back());
            centreLo = glm::min(centreLo, c);
            centreHi = glm::max(centreHi, c);
        }

        // The targets (Alg. 1): |L| / d, / d per level while >= 1, and one ellipsoid last.
        std::vector<std::uint32_t> targets;
        for (std::size_t k = n / options.clustersDivisor; k >= 1; k /= options.clustersDivisor)
            targets.push_back(std::uint32_t(k));
        if (n > 1 && (targets.empty() || targets.back() > 1))
            targets.push_back(1);
        if (targets.size() + 1 > ELLIPSOID_MAX_LEVELS)
            return fail(label, "ellipsoids option clustersDivisor",
                        std::to_string(targets.size() + 1) + " levels for " + std::to_string(n) + " leaves, at most " +
                            std::to_string(ELLIPSOID_MAX_LEVELS));

        EllipsoidTreeData data;
        data.radiusUnit = float(diagonal);
        const double treeHeight = hi.y - lo.y > 0.0 ? hi.y - lo.y : diagonal;
        try
        {
            const TreeModel flatLeaves = flatColourLeaves(model);
            const ErrorViews views(glm::vec3(lo), glm::vec3(hi), options.viewResolution);
            const std::vector<Image> reference = views.render(flatLeaves);
            const std::vector<Image> shadedReference = options.noise ? views.render(flatLeaves, true) : std::vector<Image>{};
            report(progress, "ellipsoids: leaves", 0.5f);

            auto addLevel = [&](WorkLevel level, const Calibrated& calibrated, const std::vector<Ellipsoid>& metres) {
                EllipsoidLevel l;
                l.first = std::uint32_t(data.ellipsoids.size());
                l.count = std::uint32_t(metres.size());
                l.scale = calibrated.scale;
                l.imageError = float(calibrated.error);
                l.targetHeightPx = targetHeight(metres, calibrated.scale, treeHeight);
                if (options.noise)
                {
                    // The noise at the finest the level is drawn: the tree targetHeightPx tall.
                    const float pixelSize = float(treeHeight) / l.targetHeightPx;
                    const NoiseCalibrated noise =
                        calibrateNoise(metres, l.scale, pixelSize, views, reference, shadedReference);
                    l.scale *= noise.compensation;
                    l.noiseThreshold = noise.noise.threshold;
                    l.normalBlend = noise.noise.normalBlend;
                    l.imageError = float(noise.error);
                    l.targetHeightPx = targetHeight(metres, l.scale, treeHeight);
                }
                data.levels.push_back(l);
                for (std::size_t j = 0; j < metres.size(); ++j)
                {
                    Ellipsoid e = metres[j];
                    const glm::vec3& c = level.colours[j];
                    e.colour = {linearToSrgbByte(c.r), linearToSrgbByte(c.g), linearToSrgbByte(c.b), 255};
                    data.ellipsoids.push_back(e);
                }
            };

            {
                const std::vector<Ellipsoid> metres = toMetres(leafLevel.ellipsoids, origin, diagonal);
                addLevel(leafLevel, calibrate(metres, views, reference), metres);
            }
            report(progress, "ellipsoids: leaves", 1.0f);

            // 2. The cluster levels (Alg. 1): t tries of EM from random starts, the best by image error.
            GaussianMixtureInput input;
            input.points = set.centres;
            input.weights = set.weights;
            input.spreads = set.covariances;
            for (std::size_t t = 0; t < targets.size(); ++t)
            {
                const std::uint32_t k = targets[t];
                const std::string step =
                    "ellipsoids: level " + std::to_string(t + 1) + " of " + std::to_string(targets.size());
                report(progress, step, 0.0f);
                GaussianMixtureOptions em;
                em.maxIterations = EM_MAX_ITERATIONS;
                em.tolerance = EM_TOLERANCE;
                em.candidates = EM_CANDIDATES;
                em.covarianceFloor = COVARIANCE_FLOOR;
                em.candidateRefresh = EM_CANDIDATE_REFRESH;
                const double side = 0.5 / std::cbrt(double(k)); // a start's spread: k of them fill the box
                em.initialVariance = side * side;
                const std::uint32_t tries = levelTries(k, options);
                WorkLevel best;
                std::vector<Ellipsoid> bestMetres;
                double bestError = std::numeric_limits<double>::infinity();
                for (std::uint32_t r = 0; r < tries; ++r)
                {
                    std::uint64_t state = options.seed ^ (0x51ED270B27C1A3F5ull * (std::uint64_t(t) * 64 + r + 1));
                    std::vector<glm::dvec3> starts(k);
                    for (glm::dvec3& s : starts)
                        for (int a = 0; a < 3; ++a)
                            s[a] = centreLo[a] + (centreHi[a] - centreLo[a]) * uniform01(state);
                    const GaussianMixtureResult gmm = fitGaussianMixture(input, starts, em);
                    WorkLevel candidate = clusterEllipsoids(set, gmm, options.minAreaShare);
                    if (candidate.ellipsoids.empty())
                        continue;
                    std::vector<Ellipsoid> metres = toMetres(candidate.ellipsoids, origin, diagonal);
                    const double error = tries == 1 ? 0.0 : views.error(reference, views.renderRayCast(metres, 1.0f));
                    if (error < bestError)
                    {
                        bestError = error;
                        best = std::move(candidate);
                        bestMetres = std::move(metres);
                    }
                    report(progress, step, 0.8f * float(r + 1) / float(tries));
                }
                if (bestMetres.empty())
                    return fail(label, "ellipsoids, level " + std::to_string(t + 1),
                                "every EM run left all clusters empty");
                addLevel(best, calibrate(bestMetres, views, reference), bestMetres);
                report(progress, step, 1.0f);
            }
        }
        catch (const std::exception& e)
        {
            return fail(label, "ellipsoids", std::string("rendering failed: ") + e.what());
        }

        // The centres' box for quantisation.
        glm::vec3 boxLo(std::numeric_limits<float>::max()), boxHi(-std::numeric_limits<float>::max());
        for (const Ellipsoid& e : data.ellipsoids)
        {
            boxLo = glm::min(boxLo, e.centre);
            boxHi = glm::max(boxHi, e.centre);
        }
        data.boundsMin = boxLo;
        data.boundsMax = boxHi;
        if (options.aoRays > 0)
            addEllipsoidAmbientOcclusion(data, model, options.aoRays, options.seed, progress);
        if (Result<void> valid = data.validate(label); !valid)
            return valid.error();
        return data;
    }

    Result<void> addEllipsoidTreeChunk(PackageWriter& writer, const TreeModel& model, const EllipsoidTreeOptions& options,
                                       const std::string& label, const ProgressCallback& progress)
    {
        Result<void> added =
            addBakedChunk(writer, model, label, progress, ELLIPSOID_TREE_CHUNK, ELLIPSOID_TREE_CHUNK_FORMAT_VERSION,
                          encodeEllipsoidTreeChunk, [&]() { return bakeEllipsoidTree(model, options, label, progress); });
        if (!added)
            return added;
        // The branches (§3.2): chunk "ellipsoid-lines" when the model has bark, default line options.
        EllipsoidLineOptions lines;
        lines.seed = options.seed;
        return addEllipsoidLineChunk(writer, model, lines, label, progress);
    }
}
