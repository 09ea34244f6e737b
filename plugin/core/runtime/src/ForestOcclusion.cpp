#include "TreeLod/ForestOcclusion.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace TreeLod
{
    void OcclusionMask::finish()
    {
        constexpr int S = SIZE + 1;
        double total = 0.0;
        for (int v = 0; v <= SIZE; ++v)
            for (int u = 0; u <= SIZE; ++u)
                sums[std::size_t(v * S + u)] =
                    u == 0 || v == 0 ? 0.0f
                                     : coverage[std::size_t((v - 1) * SIZE + u - 1)] + sums[std::size_t((v - 1) * S + u)] +
                                           sums[std::size_t(v * S + u - 1)] - sums[std::size_t((v - 1) * S + u - 1)];
        for (float c : coverage)
            total += c;
        mean = float(total / double(SIZE * SIZE));
    }

    float OcclusionMask::meanOver(float u0, float v0, float u1, float v1) const
    {
        u0 = std::clamp(u0, 0.0f, float(SIZE));
        u1 = std::clamp(u1, 0.0f, float(SIZE));
        v0 = std::clamp(v0, 0.0f, float(SIZE));
        v1 = std::clamp(v1, 0.0f, float(SIZE));
        const float area = (u1 - u0) * (v1 - v0);
        if (!(area > 1e-12f))
            return 0.0f;
        // The integral from the origin: bilinear between the table's corners, exact for coverage
        // that is constant over each cell.
        auto integral = [this](float u, float v) {
            constexpr int S = SIZE + 1;
            const int iu = std::min(int(u), SIZE - 1), iv = std::min(int(v), SIZE - 1);
            const float fu = u - float(iu), fv = v - float(iv);
            const float s00 = sums[std::size_t(iv * S + iu)], s10 = sums[std::size_t(iv * S + iu + 1)];
            const float s01 = sums[std::size_t((iv + 1) * S + iu)], s11 = sums[std::size_t((iv + 1) * S + iu + 1)];
            return (s00 * (1.0f - fu) + s10 * fu) * (1.0f - fv) + (s01 * (1.0f - fu) + s11 * fu) * fv;
        };
        const float sum = integral(u1, v1) - integral(u0, v1) - integral(u1, v0) + integral(u0, v0);
        return std::clamp(sum / area, 0.0f, 1.0f);
    }

    float OcclusionMask::minOver(float u0, float v0, float u1, float v1) const
    {
        const int i0 = std::clamp(int(std::floor(u0)), 0, SIZE - 1), i1 = std::clamp(int(std::ceil(u1)), i0 + 1, SIZE);
        const int j0 = std::clamp(int(std::floor(v0)), 0, SIZE - 1), j1 = std::clamp(int(std::ceil(v1)), j0 + 1, SIZE);
        float least = 1.0f;
        for (int j = j0; j < j1; ++j)
            for (int i = i0; i < i1; ++i)
                least = std::min(least, solid[std::size_t(j * SIZE + i)]);
        return least;
    }

    namespace
    {
        /// The share of texels of `texture` (decoded) within [uvMin, uvMax] whose alpha passes
        /// `cutoff`, from a summed-area table of the test per texel.
        class AlphaCoverage
        {
        public:
            AlphaCoverage(const GpuTexture& texture, float cutoff)
            {
                const GpuTexture rgba = isBlockCompressed(texture.format) ? decodeGpuTexture(texture) : GpuTexture();
                const GpuTexture& t = isBlockCompressed(texture.format) ? rgba : texture;
                mWidth = int(t.width);
                mHeight = int(t.height);
                mSums.assign(std::size_t(mWidth + 1) * std::size_t(mHeight + 1), 0.0);
                const auto threshold = std::uint8_t(std::clamp(std::ceil(cutoff * 255.0f), 0.0f, 255.0f));
                for (int y = 0; y < mHeight; ++y)
                    for (int x = 0; x < mWidth; ++x)
                    {
                        const bool kept = t.data[(std::size_t(y) * std::size_t(mWidth) + std::size_t(x)) * 4 + 3] >= threshold;
                        at(x + 1, y + 1) = (kept ? 1.0 : 0.0) + at(x, y + 1) + at(x + 1, y) - at(x, y);
                    }
            }
            float share(const glm::vec2& uvMin, const glm::vec2& uvMax) const
            {
                auto texel = [](float uv, int size) { return std::clamp(int(std::floor(uv * float(size))), 0, size); };
                int x0 = texel(std::min(uvMin.x, uvMax.x) - std::floor(std::min(uvMin.x, uvMax.x)), mWidth);
                int x1 = texel(std::max(uvMin.x, uvMax.x) - std::floor(std::min(uvMin.x, uvMax.x)), mWidth);
                int y0 = texel(std::min(uvMin.y, uvMax.y) - std::floor(std::min(uvMin.y, uvMax.y)), mHeight);
                int y1 = texel(std::max(uvMin.y, uvMax.y) - std::floor(std::min(uvMin.y, uvMax.y)), mHeight);
                x1 = std::max(x1, std::min(x0 + 1, mWidth));
                y1 = std::max(y1, std::min(y0 + 1, mHeight));
                x0 = std::min(x0, x1 - 1);
                y0 = std::min(y0, y1 - 1);
                if (x0 < 0 || y0 < 0) // an empty texture
                    return 1.0f;
                const double kept = at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
                return float(kept / double((x1 - x0) * (y1 - y0)));
            }

        private:
            double& at(int x, int y) { return mSums[std::size_t(y) * std::size_t(mWidth + 1) + std::size_t(x)]; }
            double at(int x, int y) const { return mSums[std::size_t(y) * std::size_t(mWidth + 1) + std::size_t(x)]; }
            int mWidth = 0, mHeight = 0;
            std::vector<double> mSums;
        };

        /// A side view's transmittance on a raster of RES x RES samples over the sphere's square.
        struct SideView
        {
            static constexpr int RES = 16 * OcclusionMask::SIZE;
            std::vector<float> transmittance = std::vector<float>(RES * RES, 1.0f);
            glm::vec2 origin{0.0f}; ///< the square's bottom-left (across, up), metres
            float sample = 1.0f;    ///< metres per sample
            int axis = 0;           ///< the world axis across (0: x, seen along z; 2: z, seen along x)

            /// Triangle (a, b, c) of opacity `opacity`: the samples it covers (an area of two samples
            /// or more), or its area at its centroid (a smaller one: a needle, a far leaf).
            void add(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, float opacity)
            {
                const glm::vec2 pa = (glm::vec2(a[axis], a.y) - origin) / sample;
                const glm::vec2 pb = (glm::vec2(b[axis], b.y) - origin) / sample;
                const glm::vec2 pc = (glm::vec2(c[axis], c.y) - origin) / sample;
                const float cross = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);
                const float area = 0.5f * std::abs(cross);
                if (!(area > 0.0f) || !(opacity > 0.0f) || !std::isfinite(area))
                    return;
                if (area < 2.0f)
                {
                    const glm::vec2 g = (pa + pb + pc) / 3.0f;
                    if (g.x >= 0.0f && g.y >= 0.0f && g.x < float(RES) && g.y < float(RES))
                        transmittance[std::size_t(int(g.y) * RES + int(g.x))] *= 1.0f - std::min(1.0f, opacity * area);
                    return;
                }
                const int x0 = std::max(int(std::floor(std::min({pa.x, pb.x, pc.x}))), 0);
                const int x1 = std::min(int(std::ceil(std::max({pa.x, pb.x, pc.x}))), RES - 1);
                const int y0 = std::max(int(std::floor(std::min({pa.y, pb.y, pc.y}))), 0);
                const int y1 = std::min(int(std::ceil(std::max({pa.y, pb.y, pc.y}))), RES - 1);
                // Counter-clockwise; a sample on an edge belongs to the triangle left or below of it
                // only (the top-left rule turned to y up), so that triangles sharing an edge cover
                // its samples once.
                const glm::vec2 q0 = pa, q1 = cross > 0.0f ? pb : pc, q2 = cross > 0.0f ? pc : pb;
                auto inside = [](const glm::vec2& p, const glm::vec2& q, const glm::vec2& r) {
                    const float w = (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
                    const glm::vec2 d = q - p;
                    return w > 0.0f || (w == 0.0f && (d.y > 0.0f || (d.y == 0.0f && d.x < 0.0f)));
                };
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x)
                    {
                        const glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
                        if (inside(q0, q1, p) && inside(q1, q2, p) && inside(q2, q0, p))
                            transmittance[std::size_t(y * RES + x)] *= 1.0f - opacity;
                    }
            }
        };
    }

    OcclusionMask makeOcclusionMask(const ReferenceChunk& reference, const glm::vec3& centre, float radius)
    {
        OcclusionMask mask;
        const TreeModel& model = reference.model;
        if (!(radius > 0.0f) || !std::isfinite(radius))
        {
            mask.finish();
            return mask;
        }
        std::array<SideView, 2> views;
        for (int v = 0; v < 2; ++v)
        {
            views[std::size_t(v)].axis = v == 0 ? 0 : 2;
            views[std::size_t(v)].origin = glm::vec2(centre[v == 0 ? 0 : 2] - radius, centre.y - radius);
            views[std::size_t(v)].sample = 2.0f * radius / float(SideView::RES);
        }
        auto addTriangle = [&](const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, float opacity) {
            for (SideView& view : views)
                view.add(a, b, c, opacity);
        };
        for (std::size_t t = 0; t + 2 < model.barkIndices.size(); t += 3)
            addTriangle(model.barkVertices[model.barkIndices[t]].position, model.barkVertices[model.barkIndices[t + 1]].position,
                        model.barkVertices[model.barkIndices[t + 2]].position, 1.0f);
        // Leaves: each weighed by the share of its texture rectangle the alpha test keeps.
        std::map<std::size_t, AlphaCoverage> alpha; // by material
        for (const Leaf& leaf : model.leaves)
        {
            float opacity = 1.0f;
            if (leaf.material < model.materials.size())
            {
                const Material& material = model.materials[leaf.material];
                const std::int32_t tex = material.texture;
                if (tex >= 0 && std::size_t(tex) < reference.textures.size() && reference.textures[std::size_t(tex)].width > 0)
                {
                    auto found = alpha.find(leaf.material);
                    if (found == alpha.end())
                        found = alpha.emplace(leaf.material, AlphaCoverage(reference.textures[std::size_t(tex)],
                                                                           material.alphaCutoff)).first;
                    opacity = found->second.share(leaf.uvMin, leaf.uvMax);
                }
            }
            for (std::uint32_t k = leaf.firstIndex; k + 2 < leaf.firstIndex + leaf.indexCount; k += 3)
                addTriangle(model.leafVertices[model.leafIndices[k]].position,
                            model.leafVertices[model.leafIndices[k + 1]].position,
                            model.leafVertices[model.leafIndices[k + 2]].position, opacity);
        }
        // Per mask cell, the mean over its samples and the two views of 1 - T (coverage), and the
        // least such mean over its 4 x 4 blocks (solid).
        constexpr int F = SideView::RES / OcclusionMask::SIZE, B = F / 4;
        for (int y = 0; y < OcclusionMask::SIZE; ++y)
            for (int x = 0; x < OcclusionMask::SIZE; ++x)
            {
                double sum = 0.0, least = 1.0;
                for (int by = 0; by < 4; ++by)
                    for (int bx = 0; bx < 4; ++bx)
                    {
                        double block = 0.0;
                        for (const SideView& view : views)
                            for (int dy = 0; dy < B; ++dy)
                                for (int dx = 0; dx < B; ++dx)
                                    block += 1.0 - double(view.transmittance[std::size_t(
                                                       (y * F + by * B + dy) * SideView::RES + x * F + bx * B + dx)]);
                        sum += block;
                        least = std::min(least, block / double(2 * B * B));
                    }
                mask.coverage[std::size_t(y * OcclusionMask::SIZE + x)] = float(sum / double(2 * F * F));
                mask.solid[std::size_t(y * OcclusionMask::SIZE + x)] = float(least);
            }
        mask.finish();
        return mask;
    }

    void OcclusionGrid::clear(int columns, int rows)
    {
        mColumns = std::max(columns, 1);
        mRows = std::max(rows, 1);
        mCells.assign(std::size_t(mColumns) * std::size_t(mRows), 1.0f);
        mSolidCells.assign(mCells.size(), 1.0f);
    }

    OcclusionShare OcclusionGrid::addTree(const OcclusionMask* mask, float x0, float y0, float x1, float y1,
                                          bool occludes)
    {
        // Grid units: cell (i, j) is [i, i + 1] x [j, j + 1].
        const float gx0 = (x0 + 1.0f) * 0.5f * float(mColumns), gx1 = (x1 + 1.0f) * 0.5f * float(mColumns);
        const float gy0 = (y0 + 1.0f) * 0.5f * float(mRows), gy1 = (y1 + 1.0f) * 0.5f * float(mRows);
        if (!(gx1 > gx0) || !(gy1 > gy0) || !std::isfinite(gx0 + gx1 + gy0 + gy1))
            return {};
        const int i0 = std::max(int(std::floor(gx0)), 0), i1 = std::min(int(std::ceil(gx1)), mColumns);
        const int j0 = std::max(int(std::floor(gy0)), 0), j1 = std::min(int(std::ceil(gy1)), mRows);
        // Grid units to mask cells. A square of at least a mask cell per grid cell (a near tree)
        // reads its mask cell by cell (a grid cell touches at most 2 x 2 of them); a smaller one by
        // its summed-area table.
        const float su = float(OcclusionMask::SIZE) / (gx1 - gx0), sv = float(OcclusionMask::SIZE) / (gy1 - gy0);
        const bool fine = mask && su <= 1.0f && sv <= 1.0f;
        constexpr int S = OcclusionMask::SIZE;
        double weighted = 0.0, weightedSolid = 0.0, weights = 0.0;
        for (int j = j0; j < j1; ++j)
        {
            const float ya = std::max(gy0, float(j)), yb = std::min(gy1, float(j + 1));
            for (int i = i0; i < i1; ++i)
            {
                const float xa = std::max(gx0, float(i)), xb = std::min(gx1, float(i + 1));
                const float a = (xb - xa) * (yb - ya);
                if (!(a > 0.0f))
                    continue;
                const std::size_t cell = std::size_t(j * mColumns + i);
                float& t = mCells[cell];
                float& solid = mSolidCells[cell];
                const float u0 = (xa - gx0) * su, v0 = (ya - gy0) * sv, u1 = (xb - gx0) * su, v1 = (yb - gy0) * sv;
                int mu0 = 0, mv0 = 0, mu1 = 0, mv1 = 0;
                float m = 1.0f;
                if (fine)
                {
                    mu0 = std::min(int(u0), S - 1);
                    mv0 = std::min(int(v0), S - 1);
                    mu1 = std::clamp(int(std::ceil(u1)) - 1, mu0, S - 1);
                    mv1 = std::clamp(int(std::ceil(v1)) - 1, mv0, S - 1);
                    m = mask->coverage[std::size_t(std::min(int(0.5f * (v0 + v1)), S - 1) * S +
                                                   std::min(int(0.5f * (u0 + u1)), S - 1))];
                }
                else if (mask)
                    m = mask->meanOver(u0, v0, u1, v1);
                const float w = a * m;
                weighted += double(w) * double(t);
                weightedSolid += double(w) * double(solid);
                weights += double(w);
                if (mask && occludes)
                {
                    t *= 1.0f - std::min(w, 1.0f);
                    // Only cells inside the square, by the least solid coverage there.
                    if (a >= 1.0f - 1e-4f)
                    {
                        float least = mask->solid[std::size_t(mv0 * S + mu0)];
                        if (fine)
                            least = std::min({least, mask->solid[std::size_t(mv0 * S + mu1)],
                                              mask->solid[std::size_t(mv1 * S + mu0)], mask->solid[std::size_t(mv1 * S + mu1)]});
                        else
                            least = mask->minOver(u0, v0, u1, v1);
                        solid *= 1.0f - least;
                    }
                }
            }
        }
        if (!(weights > 0.0))
            return {};
        return {float(std::clamp(weighted / weights, 0.0, 1.0)), float(std::clamp(weightedSolid / weights, 0.0, 1.0))};
    }
}
