// Ambient occlusion of the ellipsoids (the ellipsoids-and-lines paper (001) §5): "for the LoD
// primitives, we choose random points on the primitive surfaces, rejecting those inside other
// primitives". Here the points are fixed ones (the centroids of 8 spread faces of each
// ellipsoid's icosphere, ellipsoidLevelMesh), AO at each is the shared ray caster's
// (AmbientOcclusion.h) against the level's own ellipsoids and the tree's bark, and an
// ellipsoid's AO is the mean over its points outside every other ellipsoid of its level.
#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/EllipsoidTreeBaker.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t POINTS_PER_ELLIPSOID = 8;

        /// The ellipsoids of one level as point-inside tests, with a grid over their centres whose
        /// cell is at least every ellipsoid's reach (an ellipsoid holding p has its centre in p's
        /// cell or a neighbour).
        class InsideTest
        {
        public:
            InsideTest(const EllipsoidTreeData& data, const EllipsoidLevel& level)
            {
                for (std::uint32_t e = level.first; e < level.first + level.count; ++e)
                {
                    const Ellipsoid& ellipsoid = data.ellipsoids[e];
                    const glm::vec3 radii = glm::max(ellipsoid.radii * level.scale, glm::vec3(1e-30f));
                    // toUnit = diag(1 / radii) R^T
                    const glm::mat3 rotation = glm::mat3_cast(ellipsoid.rotation);
                    glm::mat3 toUnit = glm::transpose(rotation);
                    for (int r = 0; r < 3; ++r)
                        for (int c = 0; c < 3; ++c)
                            toUnit[c][r] /= radii[r];
                    mCentres.push_back(ellipsoid.centre);
                    mToUnit.push_back(toUnit);
                    mCell = std::max(mCell, std::max(radii.x, std::max(radii.y, radii.z)));
                }
                for (std::size_t i = 0; i < mCentres.size(); ++i)
                    mGrid[key(cellOf(mCentres[i]))].push_back(i);
            }

            /// Whether `p` is inside an ellipsoid of the level other than `self`.
            bool insideOther(const glm::vec3& p, std::size_t self) const
            {
                const glm::ivec3 at = cellOf(p);
                for (int dz = -1; dz <= 1; ++dz)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx)
                        {
                            const auto found = mGrid.find(key(at + glm::ivec3(dx, dy, dz)));
                            if (found == mGrid.end())
                                continue;
                            for (const std::size_t i : found->second)
                            {
                                if (i == self)
                                    continue;
                                const glm::vec3 u = mToUnit[i] * (p - mCentres[i]);
                                if (glm::dot(u, u) < 1.0f - 1e-4f)
                                    return true;
                            }
                        }
                return false;
            }

        private:
            glm::ivec3 cellOf(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / mCell)); }
            static std::uint64_t key(const glm::ivec3& c)
            {
                const auto part = [](int v) { return std::uint64_t(std::uint32_t(v) & 0x1FFFFFu); };
                return part(c.x) | part(c.y) << 21 | part(c.z) << 42;
            }

            std::vector<glm::vec3> mCentres;
            std::vector<glm::mat3> mToUnit;
            float mCell = 1e-30f;
            std::unordered_map<std::uint64_t, std::vector<std::size_t>> mGrid;
        };

        /// The level's ellipsoids as icospheres (material 0) and `model`'s bark behind them.
        TreeModel occluders(const EllipsoidTreeData& data, std::size_t level, const TreeModel& model)
        {
            TreeModel m = ellipsoidLevelMesh(data, level);
            const std::uint32_t vertexBase = std::uint32_t(m.barkVertices.size());
            const std::uint32_t materialBase = std::uint32_t(m.materials.size());
            m.textures = model.textures;
            m.materials.insert(m.materials.end(), model.materials.begin(), model.materials.end());
            m.barkVertices.insert(m.barkVertices.end(), model.barkVertices.begin(), model.barkVertices.end());
            for (const std::uint32_t i : model.barkIndices)
                m.barkIndices.push_back(vertexBase + i);
            for (const std::uint32_t material : model.barkTriangleMaterial)
                m.barkTriangleMaterial.push_back(materialBase + material);
            m.updateBounds();
            return m;
        }
    }

    void addEllipsoidAmbientOcclusion(EllipsoidTreeData& data, const TreeModel& model, std::uint32_t rays,
                                      std::uint64_t seed, const ProgressCallback& progress)
    {
        const char* step = "ellipsoids: ambient occlusion";
        for (std::size_t l = 0; l < data.levels.size(); ++l)
        {
            const EllipsoidLevel& level = data.levels[l];
            report(progress, step, float(l) / float(data.levels.size()));
            const TreeModel mesh = occluders(data, l, model);
            const std::size_t trianglesEach =
                (mesh.barkTriangleCount() - model.barkTriangleCount()) / std::max<std::size_t>(level.count, 1);
            if (trianglesEach < POINTS_PER_ELLIPSOID)
                continue;
            const InsideTest inside(data, level);
            std::vector<AoPoint> points;
            std::vector<bool> kept;
            points.reserve(level.count * POINTS_PER_ELLIPSOID);
            for (std::uint32_t j = 0; j < level.count; ++j)
                for (std::size_t p = 0; p < POINTS_PER_ELLIPSOID; ++p)
                {
                    // Faces spread over the icosphere: every (trianglesEach / 8)th.
                    const std::size_t t = j * trianglesEach + p * (trianglesEach / POINTS_PER_ELLIPSOID);
                    AoPoint point;
                    for (int c = 0; c < 3; ++c)
                    {
                        const Vertex& v = mesh.barkVertices[mesh.barkIndices[3 * t + std::size_t(c)]];
                        point.position += v.position / 3.0f;
                        point.normal += v.normal;
                    }
                    points.push_back(point);
                    kept.push_back(!inside.insideOther(point.position, j));
                }
            AoOptions options;
            options.raysPerPoint = int(rays);
            options.seed = std::uint32_t(seed ^ (seed >> 32)) + std::uint32_t(l);
            const std::vector<float> ao = computeAmbientOcclusionAt(mesh, points, options);
            for (std::uint32_t j = 0; j < level.count; ++j)
            {
                double sum = 0.0, all = 0.0;
                std::size_t count = 0;
                for (std::size_t p = 0; p < POINTS_PER_ELLIPSOID; ++p)
                {
                    const std::size_t i = j * POINTS_PER_ELLIPSOID + p;
                    all += ao[i];
                    if (kept[i])
                    {
                        sum += ao[i];
                        ++count;
                    }
                }
                // Every point inside others: the ellipsoid shows nowhere; the mean over all stands in.
                const double value = count ? sum / double(count) : all / double(POINTS_PER_ELLIPSOID);
                data.ellipsoids[level.first + j].colour[3] =
                    std::uint8_t(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
            }
        }
        report(progress, step, 1.0f);
    }
}
