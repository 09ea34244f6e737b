#include "TreeLod/TreeModel.h"

#include <cmath>
#include <limits>

namespace TreeLod
{
    namespace
    {
        bool isFinite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
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
