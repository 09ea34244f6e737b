#include "TreeLod/TreeModel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace TreeLod
{
    namespace
    {
        bool isFinite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
    }

    std::vector<std::vector<std::uint32_t>> TreeModel::leafPlanes(std::size_t i, float parallel, float minShare) const
    {
        const Leaf& leaf = leaves[i];
        struct Plane
        {
            glm::vec3 seed{0.0f};
            float area = 0.0f;
            std::vector<std::uint32_t> indices;
        };
        const auto at = [&](std::uint32_t t, std::uint32_t k) { return leafIndices[leaf.firstIndex + 3 * t + k]; };
        const auto cross = [&](std::uint32_t t) {
            const glm::vec3 a = leafVertices[at(t, 0)].position;
            return glm::cross(leafVertices[at(t, 1)].position - a, leafVertices[at(t, 2)].position - a);
        };
        std::vector<std::uint32_t> triangles(leaf.indexCount / 3);
        std::iota(triangles.begin(), triangles.end(), 0u);
        std::vector<float> twice(triangles.size());
        for (std::uint32_t t : triangles)
            twice[t] = glm::length(cross(t));
        std::stable_sort(triangles.begin(), triangles.end(), [&](std::uint32_t x, std::uint32_t y) {
            return twice[x] > twice[y];
        });
        std::vector<Plane> planes;
        std::vector<std::uint32_t> degenerate;
        for (std::uint32_t t : triangles)
        {
            if (!(twice[t] > 0.0f) || !std::isfinite(twice[t]))
            {
                degenerate.insert(degenerate.end(), {at(t, 0), at(t, 1), at(t, 2)});
                continue;
            }
            const glm::vec3 n = cross(t) / twice[t];
            std::size_t best = planes.size();
            float bestDot = parallel;
            for (std::size_t p = 0; p < planes.size(); ++p)
                if (const float d = std::abs(glm::dot(planes[p].seed, n)); d >= bestDot)
                {
                    bestDot = d;
                    best = p;
                }
            if (best == planes.size())
            {
                planes.emplace_back();
                planes.back().seed = n;
            }
            planes[best].area += 0.5f * twice[t];
            planes[best].indices.insert(planes[best].indices.end(), {at(t, 0), at(t, 1), at(t, 2)});
        }
        std::stable_sort(planes.begin(), planes.end(), [](const Plane& x, const Plane& y) { return x.area > y.area; });
        std::size_t keep = std::max<std::size_t>(planes.size(), 1);
        while (keep > 1 && planes[keep - 1].area < minShare * leaf.area)
            --keep;
        std::vector<std::vector<std::uint32_t>> out(keep);
        for (std::size_t p = 0; p < planes.size(); ++p)
        {
            std::size_t into = p;
            if (p >= keep)
            {
                into = 0;
                for (std::size_t q = 1; q < keep; ++q)
                    if (std::abs(glm::dot(planes[q].seed, planes[p].seed)) >
                        std::abs(glm::dot(planes[into].seed, planes[p].seed)))
                        into = q;
            }
            out[into].insert(out[into].end(), planes[p].indices.begin(), planes[p].indices.end());
        }
        out[0].insert(out[0].end(), degenerate.begin(), degenerate.end());
        return out;
    }

    std::optional<TreeModel> leafPlanesAsLeaves(const TreeModel& model)
    {
        std::vector<std::vector<std::vector<std::uint32_t>>> planes(model.leaves.size());
        bool several = false;
        for (std::size_t i = 0; i < model.leaves.size(); ++i)
        {
            planes[i] = model.leafPlanes(i);
            several = several || planes[i].size() > 1;
        }
        if (!several)
            return std::nullopt;
        TreeModel out = model;
        out.leafVertices.clear();
        out.leafIndices.clear();
        out.leaves.clear();
        std::vector<std::uint32_t> remap(model.leafVertices.size(), ~0u);
        for (std::size_t i = 0; i < model.leaves.size(); ++i)
        {
            const Leaf& leaf = model.leaves[i];
            for (const std::vector<std::uint32_t>& plane : planes[i])
            {
                Leaf part = leaf;
                part.firstVertex = std::uint32_t(out.leafVertices.size());
                part.firstIndex = std::uint32_t(out.leafIndices.size());
                for (std::uint32_t v : plane)
                {
                    if (remap[v] == ~0u || remap[v] < part.firstVertex)
                    {
                        remap[v] = std::uint32_t(out.leafVertices.size());
                        out.leafVertices.push_back(model.leafVertices[v]);
                    }
                    out.leafIndices.push_back(remap[v]);
                }
                part.vertexCount = std::uint32_t(out.leafVertices.size()) - part.firstVertex;
                part.indexCount = std::uint32_t(plane.size());
                out.leaves.push_back(part);
                out.updateLeafRecord(out.leaves.size() - 1);
            }
        }
        return out;
    }

    void TreeModel::updateBounds()
    {
        glm::vec3 lo(std::numeric_limits<float>::max());
        glm::vec3 hi(-std::numeric_limits<float>::max());
        for (const Vertex& v : barkVertices)
        {
            lo = glm::min(lo, v.position);
            hi = glm::max(hi, v.position);
        }
        for (const Vertex& v : leafVertices)
        {
            lo = glm::min(lo, v.position);
            hi = glm::max(hi, v.position);
        }
        if (lo.x > hi.x)
            lo = hi = glm::vec3(0.0f);
        boundsMin = lo;
        boundsMax = hi;
    }

    void TreeModel::updateLeafRecord(std::size_t i)
    {
        Leaf& leaf = leaves[i];
        glm::vec3 weighted(0.0f), normalSum(0.0f), centroid(0.0f);
        float area = 0.0f;
        for (std::uint32_t t = leaf.firstIndex; t + 3 <= leaf.firstIndex + leaf.indexCount; t += 3)
        {
            const glm::vec3& a = leafVertices[leafIndices[t]].position;
            const glm::vec3& b = leafVertices[leafIndices[t + 1]].position;
            const glm::vec3& c = leafVertices[leafIndices[t + 2]].position;
            glm::vec3 n = glm::cross(b - a, c - a);
            float twiceArea = glm::length(n);
            area += 0.5f * twiceArea;
            normalSum += n; // length-weighted = area-weighted
            weighted += 0.5f * twiceArea * (a + b + c) / 3.0f;
        }
        glm::vec2 uvLo(std::numeric_limits<float>::max()), uvHi(-std::numeric_limits<float>::max());
        for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
        {
            centroid += leafVertices[v].position;
            uvLo = glm::min(uvLo, leafVertices[v].uv);
            uvHi = glm::max(uvHi, leafVertices[v].uv);
        }
        if (leaf.vertexCount > 0)
            centroid /= float(leaf.vertexCount);
        else
            uvLo = uvHi = glm::vec2(0.0f);
        leaf.area = area;
        leaf.centre = area > 0.0f ? weighted / area : centroid;
        float len = glm::length(normalSum);
        leaf.normal = len > 0.0f ? normalSum / len : glm::vec3(0.0f, 1.0f, 0.0f);
        leaf.uvMin = uvLo;
        leaf.uvMax = uvHi;
    }

    Result<void> TreeModel::validate(const std::string& file) const
    {
        if (barkIndices.size() % 3 != 0)
            return fail(file, "bark", "index count " + std::to_string(barkIndices.size()) + " is not a multiple of 3");
        if (barkTriangleMaterial.size() != barkIndices.size() / 3)
            return fail(file, "bark", "one material per triangle expected");
        for (std::size_t i = 0; i < barkIndices.size(); ++i)
            if (barkIndices[i] >= barkVertices.size())
                return fail(file, "bark index " + std::to_string(i),
                            "vertex " + std::to_string(barkIndices[i]) + " out of range (" +
                                std::to_string(barkVertices.size()) + " vertices)");
        for (std::size_t t = 0; t < barkTriangleMaterial.size(); ++t)
            if (barkTriangleMaterial[t] >= materials.size())
                return fail(file, "bark triangle " + std::to_string(t), "material out of range");
        for (std::size_t i = 0; i < barkVertices.size(); ++i)
            if (!isFinite(barkVertices[i].position))
                return fail(file, "bark vertex " + std::to_string(i), "position is not finite");
        for (std::size_t i = 0; i < leafVertices.size(); ++i)
            if (!isFinite(leafVertices[i].position))
                return fail(file, "leaf vertex " + std::to_string(i), "position is not finite");
        for (std::size_t l = 0; l < leaves.size(); ++l)
        {
            const Leaf& leaf = leaves[l];
            const std::string where = "leaf " + std::to_string(l);
            if (std::uint64_t(leaf.firstVertex) + leaf.vertexCount > leafVertices.size())
                return fail(file, where, "vertex range out of bounds");
            if (std::uint64_t(leaf.firstIndex) + leaf.indexCount > leafIndices.size() || leaf.indexCount % 3 != 0)
                return fail(file, where, "index range out of bounds or not triangles");
            for (std::uint32_t k = leaf.firstIndex; k < leaf.firstIndex + leaf.indexCount; ++k)
                if (leafIndices[k] < leaf.firstVertex || leafIndices[k] >= leaf.firstVertex + leaf.vertexCount)
                    return fail(file, where, "index " + std::to_string(leafIndices[k]) + " outside the leaf's vertex range");
            if (leaf.material >= materials.size())
                return fail(file, where, "material out of range");
        }
        for (std::size_t m = 0; m < materials.size(); ++m)
            if (materials[m].texture >= std::int32_t(textures.size()))
                return fail(file, "material " + std::to_string(m) + " '" + materials[m].name + "'", "texture out of range");
        for (std::size_t t = 0; t < textures.size(); ++t)
            if (textures[t].rgba.size() != std::size_t(textures[t].width) * textures[t].height * 4)
                return fail(file, "texture " + std::to_string(t) + " '" + textures[t].name + "'", "pixel data size mismatch");
        for (std::size_t n = 0; n < skeleton.size(); ++n)
            if (skeleton[n].parent >= std::int32_t(n))
                return fail(file, "skeleton node " + std::to_string(n), "parent must come before its child");
        return {};
    }
}
