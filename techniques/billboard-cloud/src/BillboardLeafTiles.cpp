// BillboardLeafTiles: the Leaves Texture of García et al. 2007 (§3, §5, §5.2) and the placement of
// a leaf on a billboard plane. Contract: BillboardLeafTiles.h and the "Lists atlas", "AO atlas" and
// "Leaves Texture" sections of BillboardCloudData.h.
//
// Coordinates used below:
//   leaf frame   (w, t, n): a leaf point is centre + length * (a w + b t), (a, b) in leaf
//                lengths; the canonical rectangle is |a| <= aspect / 2, |b| <= 1 / 2, texture
//                s = a / aspect + 1/2 (u), 1 - s_v = b + 1/2 (tip at v = uvMin.y).
//   tile frame   (x, y, z) in leaf-frame coordinates, z = d_k; a leaf point P projects to
//                tile-local l = (P.x, P.y) / E + 1/2, E = the tile edge in leaf lengths.
//   plane        (U, V, N), N = cross(U, V); plane coordinates q = (dot(p, U), dot(p, V)).
#include "BillboardLeafTiles.h"

#include "TreeLod/Image.h"

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr float kTwoPi = 6.28318530718f;
        constexpr int kSuper = 4; ///< sub-samples per texel axis for the coverage edge
        /// Bump strength of the normal map (§5.2): surface slope per unit change of linear
        /// luminance per source texel. Small on purpose: veins tilt the normal by ~5-10 degrees.
        constexpr float kBumpStrength = 2.0f;
        constexpr int kBleedRings = 16;

        /// A material texture decoded to linear colour, straight alpha; empty = white.
        struct LinearImage
        {
            int width = 0, height = 0;
            std::vector<glm::vec4> texels;

            /// Bilinear lookup, REPEAT wrapping, texel centres at ((i + 0.5) / w, (j + 0.5) / h),
            /// as the reference renderer samples.
            glm::vec4 sample(glm::vec2 uv) const
            {
                if (width <= 0 || height <= 0)
                    return glm::vec4(1.0f);
                auto wrap = [](float x) {
                    if (!std::isfinite(x))
                        return 0.0f;
                    x -= std::floor(x);
                    return x < 1.0f ? x : 0.0f;
                };
                const float x = wrap(uv.x) * float(width) - 0.5f, y = wrap(uv.y) * float(height) - 0.5f;
                const float fx = std::floor(x), fy = std::floor(y);
                int x0 = int(fx), y0 = int(fy), x1 = x0 + 1, y1 = y0 + 1;
                if (x0 < 0)
                    x0 += width;
                if (y0 < 0)
                    y0 += height;
                if (x1 >= width)
                    x1 -= width;
                if (y1 >= height)
                    y1 -= height;
                const float ax = x - fx, ay = y - fy;
                auto at = [&](int px, int py)
                { return texels[std::size_t(py) * std::size_t(width) + std::size_t(px)]; };
                const glm::vec4 top = glm::mix(at(x0, y0), at(x1, y0), ax);
                const glm::vec4 bottom = glm::mix(at(x0, y1), at(x1, y1), ax);
                return glm::mix(top, bottom, ay);
            }
        };

        float luminance(const glm::vec4& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

        glm::vec3 anyOrthogonal(const glm::vec3& n)
        {
            const glm::vec3 e = std::abs(n.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
            return glm::normalize(glm::cross(n, e));
        }

        float median(std::vector<float> v, float fallback)
        {
            if (v.empty())
                return fallback;
            std::sort(v.begin(), v.end());
            const std::size_t h = v.size() / 2;
            return v.size() % 2 ? v[h] : 0.5f * (v[h - 1] + v[h]);
        }

        /// Least-squares fit of a leaf's positions to its UVs: P ~ pMean + A (u - uMean) + B (v - vMean).
        struct UvFit
        {
            glm::vec3 pMean{0.0f}, a{0.0f}, b{0.0f};
            glm::vec2 uvMean{0.0f};
            bool hasA = false, hasB = false;
        };

        UvFit fitUv(const TreeModel& model, const Leaf& leaf)
        {
            UvFit fit;
            const std::size_t first = std::min<std::size_t>(leaf.firstVertex, model.leafVertices.size());
            const std::size_t count = std::min<std::size_t>(leaf.vertexCount, model.leafVertices.size() - first);
            if (count == 0)
                return fit;
            glm::dvec3 p(0.0);
            glm::dvec2 uv(0.0);
            for (std::size_t i = 0; i < count; ++i)
            {
                p += glm::dvec3(model.leafVertices[first + i].position);
                uv += glm::dvec2(model.leafVertices[first + i].uv);
            }
            p /= double(count);
            uv /= double(count);
            double suu = 0, suv = 0, svv = 0;
            glm::dvec3 sup(0.0), svp(0.0);
            for (std::size_t i = 0; i < count; ++i)
            {
                const Vertex& v = model.leafVertices[first + i];
                const double du = v.uv.x - uv.x, dv = v.uv.y - uv.y;
                const glm::dvec3 dp = glm::dvec3(v.position) - p;
                suu += du * du;
                suv += du * dv;
                svv += dv * dv;
                sup += du * dp;
                svp += dv * dp;
            }
            fit.pMean = glm::vec3(p);
            fit.uvMean = glm::vec2(uv);
            const double eps = 1e-14;
            const double det = suu * svv - suv * suv;
            if (suu > eps && svv > eps && det > 1e-6 * suu * svv)
            {
                fit.a = glm::vec3((svv * sup - suv * svp) / det);
                fit.b = glm::vec3((suu * svp - suv * sup) / det);
                fit.hasA = fit.hasB = true;
            }
            else if (suu > eps)
            {
                fit.a = glm::vec3(sup / suu);
                fit.hasA = true;
            }
            else if (svv > eps)
            {
                fit.b = glm::vec3(svp / svv);
                fit.hasB = true;
            }
            const auto finite = [](const glm::vec3& v)
            { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
            fit.hasA = fit.hasA && finite(fit.a) && glm::length(fit.a) > 0.0f;
            fit.hasB = fit.hasB && finite(fit.b) && glm::length(fit.b) > 0.0f;
            return fit;
        }

        constexpr std::uint32_t NO_IMAGE = ~0u;
        /// Leaf images a material may have; the leaves of further UV rectangles are drawn with
        /// the nearest of them, and a warning says so.
        constexpr std::size_t MAX_IMAGES_PER_MATERIAL = 64;
        /// A leaf belongs to an image when its UV rectangle overlaps the image's first one by at
        /// least this intersection over union (atlas cells do not overlap; one image's jittered
        /// or trimmed UVs do).
        constexpr float SAME_IMAGE_IOU = 0.5f;

        float rectIou(const glm::vec4& a, const glm::vec4& b)
        {
            const float pad = 1.0f / 4096.0f; // degenerate rectangles compare by position
            const glm::vec2 aMin = glm::vec2(a.x, a.y) - pad, aMax = glm::vec2(a.z, a.w) + pad;
            const glm::vec2 bMin = glm::vec2(b.x, b.y) - pad, bMax = glm::vec2(b.z, b.w) + pad;
            const glm::vec2 i = glm::max(glm::min(aMax, bMax) - glm::max(aMin, bMin), glm::vec2(0.0f));
            const float inter = i.x * i.y;
            const glm::vec2 sa = aMax - aMin, sb = bMax - bMin;
            const float uni = sa.x * sa.y + sb.x * sb.y - inter;
            return uni > 0.0f ? inter / uni : 0.0f;
        }

        /// The leaf images (BillboardCloudData.h, "Leaves Texture"): per material some leaf uses,
        /// in increasing material index, a leaf joins the image whose first UV rectangle overlaps
        /// its own most when the IoU is at least SAME_IMAGE_IOU, else starts an image; an image's
        /// rectangle is the union of its leaves'. Returns each leaf's image (NO_IMAGE for a leaf
        /// of a material index out of range).
        std::vector<std::uint32_t> groupLeafImages(const TreeModel& model, std::vector<BillboardLeafImage>& images,
                                                   std::vector<std::string>& warnings)
        {
            std::vector<std::uint32_t> out(model.leaves.size(), NO_IMAGE);
            std::vector<std::vector<std::uint32_t>> byMaterial(model.materials.size());
            for (std::size_t l = 0; l < model.leaves.size(); ++l)
                if (model.leaves[l].material < byMaterial.size())
                    byMaterial[model.leaves[l].material].push_back(std::uint32_t(l));
            for (std::size_t m = 0; m < byMaterial.size(); ++m)
            {
                if (byMaterial[m].empty())
                    continue;
                const std::size_t first = images.size();
                std::vector<glm::vec4> keys; // each image's first rectangle
                std::size_t merged = 0;
                std::uint32_t firstMerged = 0;
                for (std::uint32_t l : byMaterial[m])
                {
                    const Leaf& leaf = model.leaves[l];
                    glm::vec4 r(leaf.uvMin, leaf.uvMax);
                    if (!std::isfinite(r.x + r.y + r.z + r.w) || r.x > r.z || r.y > r.w)
                        r = glm::vec4(0.0f);
                    std::size_t best = keys.size();
                    float bestIou = 0.0f;
                    for (std::size_t i = 0; i < keys.size(); ++i)
                        if (const float iou = rectIou(r, keys[i]); iou > bestIou)
                        {
                            bestIou = iou;
                            best = i;
                        }
                    if (bestIou < SAME_IMAGE_IOU && keys.size() < MAX_IMAGES_PER_MATERIAL)
                    {
                        best = keys.size();
                        keys.push_back(r);
                        BillboardLeafImage image;
                        image.material = std::uint32_t(m);
                        image.alphaCutoff = model.materials[m].alphaCutoff;
                        image.uvMin = glm::vec2(r.x, r.y);
                        image.uvMax = glm::vec2(r.z, r.w);
                        images.push_back(image);
                    }
                    else if (bestIou < SAME_IMAGE_IOU)
                    {
                        if (merged++ == 0)
                            firstMerged = l;
                        if (best == keys.size()) // no overlap at all: the nearest centre
                        {
                            float nearest = INFINITY;
                            const glm::vec2 c(0.5f * (r.x + r.z), 0.5f * (r.y + r.w));
                            for (std::size_t i = 0; i < keys.size(); ++i)
                            {
                                const glm::vec2 k(0.5f * (keys[i].x + keys[i].z), 0.5f * (keys[i].y + keys[i].w));
                                if (const float d = glm::length(c - k); d < nearest)
                                {
                                    nearest = d;
                                    best = i;
                                }
                            }
                        }
                    }
                    BillboardLeafImage& image = images[first + best];
                    image.uvMin = glm::min(image.uvMin, glm::vec2(r.x, r.y));
                    image.uvMax = glm::max(image.uvMax, glm::vec2(r.z, r.w));
                    out[l] = std::uint32_t(first + best);
                }
                if (merged > 0)
                    warnings.push_back("leaf material '" + model.materials[m].name + "': its leaves map more than " +
                                       std::to_string(MAX_IMAGES_PER_MATERIAL) +
                                       " different texture rectangles; " + std::to_string(merged) +
                                       " leaves (the first is leaf " + std::to_string(firstMerged) +
                                       ") are drawn with the nearest of " +
                                       std::to_string(MAX_IMAGES_PER_MATERIAL) + " leaf images");
            }
            return out;
        }

        /// The tile frame of direction d (unit, d.z >= 0), in leaf-frame coordinates.
        glm::mat3 tileAxes(const glm::vec3& d)
        {
            const glm::vec3 z = d;
            glm::vec3 y = glm::vec3(0, 1, 0) - z * z.y; // the tip direction projected
            if (glm::length(y) < 1e-4f)
            {
                // t parallel to d: the projection of w, rotated a quarter turn about z.
                const glm::vec3 w = glm::vec3(1, 0, 0) - z * z.x;
                y = glm::cross(z, w);
            }
            y = glm::normalize(y);
            const glm::vec3 x = glm::cross(y, z);
            return glm::mat3(x, y, z);
        }
    }

    BillboardLeafTiles::BillboardLeafTiles(const TreeModel& model, std::uint32_t tileSize, std::uint32_t grid,
                                           std::uint64_t maxTexels)
        : mTileSize(std::max<std::uint32_t>(tileSize, 8)), mGrid(std::max<std::uint32_t>(grid, 1)), mModel(model)
    {
        const std::uint32_t orientationCount = mGrid * mGrid;

        // Leaf images (blocks): per material some leaf uses, in increasing material index, the
        // UV rectangles its leaves map, grouped (leafImageGroups).
        const std::vector<std::uint32_t> groups = groupLeafImages(model, mImages, mWarnings);
        mLeafBlock.assign(model.leaves.size(), -1);
        for (std::size_t l = 0; l < model.leaves.size(); ++l)
            mLeafBlock[l] = groups[l] == NO_IMAGE ? -1 : std::int32_t(groups[l]);
        const std::size_t blocks = mImages.size();
        while (maxTexels > 0 && mTileSize > 16 &&
               std::uint64_t(blocks) * 2 * orientationCount * mTileSize * mTileSize > maxTexels)
            mTileSize /= 2;

        // Leaf frames (header: w, t fitted to dP/du and -dP/dv, orthonormalised around n).
        std::vector<UvFit> fits(model.leaves.size());
        mFrames.resize(model.leaves.size());
        for (std::size_t l = 0; l < model.leaves.size(); ++l)
        {
            const Leaf& leaf = model.leaves[l];
            const UvFit& fit = fits[l] = fitUv(model, leaf);
            LeafFrame& f = mFrames[l];
            glm::vec3 n = leaf.normal;
            n = glm::length(n) > 0.0f && std::isfinite(n.x + n.y + n.z) ? glm::normalize(n) : glm::vec3(0, 1, 0);
            glm::vec3 t(0.0f), w(0.0f);
            bool hasT = false, hasW = false;
            if (fit.hasB)
            {
                t = -fit.b - n * glm::dot(-fit.b, n);
                hasT = glm::length(t) > 1e-3f * glm::length(fit.b);
                if (hasT)
                    t = glm::normalize(t);
            }
            if (fit.hasA)
            {
                w = fit.a - n * glm::dot(fit.a, n);
                if (hasT)
                    w -= t * glm::dot(w, t);
                hasW = glm::length(w) > 1e-3f * glm::length(fit.a);
                if (hasW)
                    w = glm::normalize(w);
            }
            if (hasT && hasW && glm::dot(glm::cross(w, t), n) < 0.0f)
                n = -n; // texture mirrored on this leaf: keep its image, swap front and back
            if (!hasT)
                t = hasW ? glm::normalize(glm::cross(n, w)) : anyOrthogonal(n);
            f.w = glm::normalize(glm::cross(t, n));
            f.t = t;
            f.n = n;
        }

        // Canonical leaves: the union UV rectangle with the median aspect; per leaf its length
        // (metres per canonical rectangle along t) and the rectangle's centre.
        std::vector<std::vector<float>> aspects(blocks);
        std::vector<float> widthOf(model.leaves.size()), lengthOf(model.leaves.size());
        for (std::size_t l = 0; l < model.leaves.size(); ++l)
        {
            const Leaf& leaf = model.leaves[l];
            const std::int32_t block = mLeafBlock[l];
            const BillboardLeafImage* image = block >= 0 ? &mImages[std::size_t(block)] : nullptr;
            const glm::vec2 size = image ? glm::max(image->uvMax - image->uvMin, glm::vec2(0.0f)) : glm::vec2(0.0f);
            const glm::vec2 uvCentre = image ? 0.5f * (image->uvMin + image->uvMax) : glm::vec2(0.0f);
            const UvFit& fit = fits[l];
            LeafFrame& f = mFrames[l];
            // Vertex extents in the leaf plane (fallback where the UV fit says nothing).
            glm::vec2 lo(1e30f), hi(-1e30f);
            const std::size_t end = std::min<std::size_t>(std::size_t(leaf.firstVertex) + leaf.vertexCount,
                                                          model.leafVertices.size());
            for (std::size_t v = leaf.firstVertex; v < end; ++v)
            {
                const glm::vec3 d = model.leafVertices[v].position - leaf.centre;
                const glm::vec2 c(glm::dot(d, f.w), glm::dot(d, f.t));
                lo = glm::min(lo, c);
                hi = glm::max(hi, c);
            }
            if (lo.x > hi.x)
                lo = hi = glm::vec2(0.0f);
            float width = fit.hasA ? std::abs(glm::dot(fit.a, f.w)) * size.x : 0.0f;
            float length = fit.hasB ? std::abs(glm::dot(fit.b, f.t)) * size.y : 0.0f;
            glm::vec3 centre = fit.pMean;
            if (fit.hasA)
                centre += fit.a * (uvCentre.x - fit.uvMean.x);
            if (fit.hasB)
                centre += fit.b * (uvCentre.y - fit.uvMean.y);
            if (!(width > 0.0f))
            {
                width = hi.x - lo.x;
                centre += f.w * (0.5f * (lo.x + hi.x) - glm::dot(centre - leaf.centre, f.w));
            }
            if (!(length > 0.0f))
            {
                length = hi.y - lo.y;
                centre += f.t * (0.5f * (lo.y + hi.y) - glm::dot(centre - leaf.centre, f.t));
            }
            centre -= f.n * glm::dot(centre - leaf.centre, f.n); // onto the leaf's plane
            f.centre = std::isfinite(centre.x + centre.y + centre.z) ? centre : leaf.centre;
            widthOf[l] = width;
            lengthOf[l] = length;
            if (block >= 0 && width > 0.0f && length > 0.0f && std::isfinite(width / length))
                aspects[std::size_t(block)].push_back(width / length);
        }
        std::vector<float> aspect(blocks);
        for (std::size_t b = 0; b < blocks; ++b)
            aspect[b] = std::clamp(median(aspects[b], 1.0f), 1e-3f, 1e3f);
        for (std::size_t l = 0; l < model.leaves.size(); ++l)
        {
            float length = lengthOf[l];
            const std::int32_t block = mLeafBlock[l];
            if (!(length > 0.0f) && block >= 0)
                length = widthOf[l] / aspect[std::size_t(block)]; // a leaf with no extent along t
            mFrames[l].length = std::isfinite(length) ? std::max(length, 1e-6f) : 1e-6f;
        }

        // Tile frames and tile edges: the canonical rectangle projected along d_k fits the
        // inner (1 - 2 TILE_MARGIN) of the tile (García et al. 2007 §3: one leaf image per
        // orientation).
        mTileAxes.resize(orientationCount);
        for (std::uint32_t k = 0; k < orientationCount; ++k)
            mTileAxes[k] = tileAxes(glm::normalize(billboardOrientationDirection(k, mGrid)));
        mTileExtent.assign(tileCount(), 1.0f);
        for (std::size_t b = 0; b < blocks; ++b)
            for (std::uint32_t k = 0; k < orientationCount; ++k)
            {
                float h = 0.0f;
                for (int cx = -1; cx <= 1; cx += 2)
                    for (int cy = -1; cy <= 1; cy += 2)
                    {
                        const glm::vec3 p(0.5f * aspect[b] * float(cx), 0.5f * float(cy), 0.0f);
                        h = std::max(
                            {h, std::abs(glm::dot(p, mTileAxes[k][0])), std::abs(glm::dot(p, mTileAxes[k][1]))});
                    }
                const float extent = std::max(2.0f * h / (1.0f - 2.0f * TILE_MARGIN), 1e-4f);
                mTileExtent[b * 2 * orientationCount + k] = extent;
                mTileExtent[b * 2 * orientationCount + orientationCount + k] = extent;
            }

        // Layout: near-square grid of tiles, power-of-two columns.
        const std::uint32_t count = tileCount();
        mColumns = 1;
        while (std::uint64_t(mColumns) * mColumns < count)
            mColumns *= 2;
        if (count == 0)
            return; // no leaves: empty images
        const std::uint32_t rows = (count + mColumns - 1) / mColumns;
        const std::uint32_t T = mTileSize;
        for (TextureImage* image : {&mColour, &mNormal})
        {
            image->width = int(mColumns * T);
            image->height = int(rows * T);
            image->rgba.assign(std::size_t(image->width) * std::size_t(image->height) * 4, 0);
        }
        mColour.name = "billboard leaves colour";
        mNormal.name = "billboard leaves normal";
        for (std::size_t i = 0; i < mNormal.rgba.size(); i += 4)
        {
            mNormal.rgba[i + 0] = 128;
            mNormal.rgba[i + 1] = 128;
            mNormal.rgba[i + 2] = 255;
            mNormal.rgba[i + 3] = 255;
        }

        // Linear copies of the textures the blocks read.
        std::vector<LinearImage> images(blocks);
        for (std::size_t b = 0; b < blocks; ++b)
        {
            const std::int32_t tex = model.materials[mImages[b].material].texture;
            if (tex < 0 || std::size_t(tex) >= model.textures.size())
                continue;
            const TextureImage& src = model.textures[std::size_t(tex)];
            const std::size_t texels = std::size_t(std::max(src.width, 0)) * std::size_t(std::max(src.height, 0));
            if (texels == 0 || src.rgba.size() < texels * 4)
                continue; // unusable: white, as the reference renderer
            LinearImage& dst = images[b];
            dst.width = src.width;
            dst.height = src.height;
            dst.texels.resize(texels);
            for (std::size_t p = 0; p < texels; ++p)
                dst.texels[p] = glm::vec4(srgbByteToLinear(src.rgba[p * 4]), srgbByteToLinear(src.rgba[p * 4 + 1]),
                                          srgbByteToLinear(src.rgba[p * 4 + 2]), byteToUnit(src.rgba[p * 4 + 3]));
        }

        // Rasterise: one job per (block, orientation) writes its side 0 and side 1 tiles.
        tbb::parallel_for(std::size_t(0), blocks * orientationCount, [&](std::size_t job) {
            const std::size_t b = job / orientationCount;
            const std::uint32_t k = std::uint32_t(job % orientationCount);
            const Material& material = model.materials[mImages[b].material];
            const LinearImage& image = images[b];
            const glm::vec2 uv0 = mImages[b].uvMin;
            const glm::vec2 uvSize = mImages[b].uvMax - mImages[b].uvMin;
            const float W = aspect[b];
            const glm::vec3 x = mTileAxes[k][0], y = mTileAxes[k][1], z = mTileAxes[k][2];
            const float E = mTileExtent[b * 2 * orientationCount + k];
            const float cutoff = material.alphaCutoff;
            const float baseAlpha = material.baseColour.a;
            const glm::vec3 frontTint(material.baseColour);
            const glm::vec3 backTint = glm::any(glm::greaterThan(material.backColour, glm::vec3(0.0f)))
                                           ? material.backColour
                                           : frontTint;

            // Tile-local point -> leaf (s, v) in [0, 1]^2 along the ray through it along d_k;
            // false outside the canonical rectangle.
            auto leafPoint = [&](glm::vec2 local, glm::vec2& sv) {
                const glm::vec2 o = (local - 0.5f) * E;
                const glm::vec3 q = o.x * x + o.y * y;
                if (z.z <= 1e-6f)
                    return false;
                const glm::vec3 p = q - z * (q.z / z.z); // on the leaf plane (c = 0)
                sv = glm::vec2(p.x / W + 0.5f, 0.5f - p.y);
                return sv.x >= 0.0f && sv.x <= 1.0f && sv.y >= 0.0f && sv.y <= 1.0f;
            };

            std::vector<glm::vec3> albedo(std::size_t(T) * T, glm::vec3(0.0f)); // untinted, linear
            std::vector<float> coverage(std::size_t(T) * T, 0.0f);
            std::vector<glm::vec3> normal(std::size_t(T) * T, glm::vec3(0, 0, 1)); // leaf frame, front
            const glm::vec2 texel = image.width > 0 ? glm::vec2(1.0f / float(image.width), 1.0f / float(image.height))
                                                    : glm::vec2(0.0f);
            for (std::uint32_t py = 0; py < T; ++py)
                for (std::uint32_t px = 0; px < T; ++px)
                {
                    int inside = 0;
                    glm::vec3 sum(0.0f);
                    for (int sy = 0; sy < kSuper; ++sy)
                        for (int sx = 0; sx < kSuper; ++sx)
                        {
                            const glm::vec2 local((float(px) + (float(sx) + 0.5f) / kSuper) / float(T),
                                                  (float(py) + (float(sy) + 0.5f) / kSuper) / float(T));
                            glm::vec2 sv(0.5f);
                            if (!leafPoint(local, sv))
                                continue;
                            const glm::vec4 c = image.sample(uv0 + sv * uvSize);
                            if (baseAlpha * c.a < cutoff)
                                continue;
                            ++inside;
                            sum += glm::vec3(c);
                        }
                    if (inside == 0)
                        continue;
                    const std::size_t i = std::size_t(py) * T + px;
                    coverage[i] = float(inside) / float(kSuper * kSuper);
                    albedo[i] = sum / float(inside);
                    // §5.2: normal map with a bump from the luminance gradient (height = luminance)
                    // at the texel centre's leaf point (clamped into the rectangle).
                    glm::vec2 sv(0.5f);
                    leafPoint(glm::vec2((float(px) + 0.5f) / float(T), (float(py) + 0.5f) / float(T)), sv);
                    const glm::vec2 uv = uv0 + glm::clamp(sv, glm::vec2(0.0f), glm::vec2(1.0f)) * uvSize;
                    const float gu = 0.5f * (luminance(image.sample(uv + glm::vec2(texel.x, 0.0f))) -
                                             luminance(image.sample(uv - glm::vec2(texel.x, 0.0f))));
                    const float gv = 0.5f * (luminance(image.sample(uv + glm::vec2(0.0f, texel.y))) -
                                             luminance(image.sample(uv - glm::vec2(0.0f, texel.y))));
                    // w = +u, t = -v: slope along w is gu, along t is -gv.
                    normal[i] = glm::normalize(glm::vec3(-kBumpStrength * gu, kBumpStrength * gv, 1.0f));
                }

            // Bleed colour into the transparent texels (as LeafTexture.cpp): rings of the mean
            // of coloured 8-neighbours, then the tile's mean colour, so mips keep the leaf's hue.
            std::vector<char> known(coverage.size());
            glm::vec3 mean(0.0f);
            float weight = 0.0f;
            for (std::size_t i = 0; i < coverage.size(); ++i)
            {
                known[i] = coverage[i] > 0.0f;
                mean += albedo[i] * coverage[i];
                weight += coverage[i];
            }
            mean = weight > 0.0f ? mean / weight : glm::vec3(1.0f);
            std::vector<std::size_t> ring;
            for (int r = 0; r < kBleedRings; ++r)
            {
                ring.clear();
                std::vector<glm::vec3> filled;
                for (std::uint32_t py = 0; py < T; ++py)
                    for (std::uint32_t px = 0; px < T; ++px)
                    {
                        const std::size_t i = std::size_t(py) * T + px;
                        if (known[i])
                            continue;
                        glm::vec3 s(0.0f);
                        int n = 0;
                        for (int dy = -1; dy <= 1; ++dy)
                            for (int dx = -1; dx <= 1; ++dx)
                            {
                                const int nx = int(px) + dx, ny = int(py) + dy;
                                if (nx < 0 || ny < 0 || nx >= int(T) || ny >= int(T))
                                    continue;
                                const std::size_t j = std::size_t(ny) * T + std::size_t(nx);
                                if (known[j])
                                {
                                    s += albedo[j];
                                    ++n;
                                }
                            }
                        if (n > 0)
                        {
                            ring.push_back(i);
                            filled.push_back(s / float(n));
                        }
                    }
                if (ring.empty())
                    break;
                for (std::size_t r2 = 0; r2 < ring.size(); ++r2)
                {
                    albedo[ring[r2]] = filled[r2];
                    known[ring[r2]] = 1;
                }
            }

            // Write both sides: side 0 sees the front (d_k.z > 0), side 1 the back.
            for (int side = 0; side < 2; ++side)
            {
                const std::uint32_t tile =
                    std::uint32_t(b) * 2 * orientationCount + std::uint32_t(side) * orientationCount + k;
                const std::uint32_t ox = (tile % mColumns) * T, oy = (tile / mColumns) * T;
                const glm::vec3 tint = side == 0 ? frontTint : backTint;
                for (std::uint32_t py = 0; py < T; ++py)
                    for (std::uint32_t px = 0; px < T; ++px)
                    {
                        const std::size_t i = std::size_t(py) * T + px;
                        const std::size_t o = (std::size_t(oy + py) * mColour.width + ox + px) * 4;
                        const glm::vec3 c = tint * (known[i] ? albedo[i] : mean);
                        mColour.rgba[o + 0] = linearToSrgbByte(c.r);
                        mColour.rgba[o + 1] = linearToSrgbByte(c.g);
                        mColour.rgba[o + 2] = linearToSrgbByte(c.b);
                        mColour.rgba[o + 3] = unitToByte(coverage[i]);
                        // The normal facing this side's viewer, in the tile frame.
                        const glm::vec3 nl = side == 0 ? normal[i] : -normal[i];
                        const glm::vec3 nt(glm::dot(nl, x), glm::dot(nl, y), glm::dot(nl, z));
                        mNormal.rgba[o + 0] = unitToByte(nt.x * 0.5f + 0.5f);
                        mNormal.rgba[o + 1] = unitToByte(nt.y * 0.5f + 0.5f);
                        mNormal.rgba[o + 2] = unitToByte(nt.z * 0.5f + 0.5f);
                        mNormal.rgba[o + 3] = 255;
                    }
            }
        });
    }

    std::uint32_t BillboardLeafTiles::tileCount() const
    {
        return std::uint32_t(mImages.size()) * 2 * mGrid * mGrid;
    }

    LeafPlacement BillboardLeafTiles::place(std::uint32_t leaf, const glm::vec3& origin, const glm::vec3& U,
                                            const glm::vec3& V, const glm::vec3& N) const
    {
        LeafPlacement out;
        if (leaf >= mFrames.size() || mTileExtent.empty())
            return out;
        const LeafFrame& f = mFrames[leaf];
        const std::int32_t block = mLeafBlock[leaf];
        const std::uint32_t orientationCount = mGrid * mGrid;

        // The billboard normal in the leaf frame; the hemisphere d.z >= 0 holds the tiles, the
        // other half is the same image mirrored (BillboardCloudData.h, "Leaves Texture").
        glm::vec3 d(glm::dot(N, f.w), glm::dot(N, f.t), glm::dot(N, f.n));
        d = glm::length(d) > 0.0f ? glm::normalize(d) : glm::vec3(0, 0, 1);
        out.mirrored = d.z < 0.0f;
        if (out.mirrored)
            d = -d;
        const std::uint32_t k = std::min(billboardOrientationIndex(d, mGrid), orientationCount - 1);
        out.orientation = std::uint32_t(std::max(block, 0)) * 2 * orientationCount + k;

        // Rotation psi. The shader maps a plane offset q to local = F R(-psi) q / side + 1/2
        // (F = diag(-1, 1) when mirrored, else identity), i.e. q = R(psi) F (local - 1/2) side.
        // The tile shows a leaf point (a, b) (leaf lengths) at local - 1/2 = G (a, b) / E with
        // G = [x.xy; y.xy] (tile axes, rows), and the plane shows it at q = length * M (a, b),
        // M = [w.U t.U; w.V t.V]. With side = E * length, we need R(psi) F G = M. When d == d_k
        // this holds exactly for one psi (F G and M are both the orthographic projection, F
        // making the tile frame's handedness match (U, V, N) when z = -N); otherwise the
        // Procrustes rotation minimises |R F G - M|: R = polar factor of C = M (F G)^T,
        // psi = atan2(C10 - C01, C00 + C11).
        const glm::mat3& axes = mTileAxes[k];
        const float sign = out.mirrored ? -1.0f : 1.0f;
        const float g00 = sign * axes[0].x, g01 = sign * axes[0].y, g10 = axes[1].x, g11 = axes[1].y;
        const float m00 = glm::dot(f.w, U), m01 = glm::dot(f.t, U), m10 = glm::dot(f.w, V), m11 = glm::dot(f.t, V);
        // C = M G^T
        const float c00 = m00 * g00 + m01 * g01, c01 = m00 * g10 + m01 * g11;
        const float c10 = m10 * g00 + m11 * g01, c11 = m10 * g10 + m11 * g11;
        float psi = std::atan2(c10 - c01, c00 + c11);
        if (!std::isfinite(psi))
            psi = 0.0f;
        if (psi < 0.0f)
            psi += kTwoPi;
        if (psi >= kTwoPi)
            psi -= kTwoPi;
        out.rotation = psi;

        out.side = mTileExtent[out.orientation] * f.length;
        const glm::vec3 c = f.centre - origin;
        out.centre = glm::vec2(glm::dot(c, U), glm::dot(c, V));
        out.depth = glm::dot(c, N);
        return out;
    }

    glm::vec2 BillboardLeafTiles::sideRange(std::uint32_t leaf) const
    {
        const std::int32_t block = imageOf(leaf);
        if (block < 0 || leaf >= mFrames.size())
            return glm::vec2(0.0f);
        const std::uint32_t orientationCount = mGrid * mGrid;
        glm::vec2 range(INFINITY, 0.0f);
        for (std::uint32_t k = 0; k < orientationCount; ++k)
        {
            const float extent = mTileExtent[std::size_t(block) * 2 * orientationCount + k];
            range = glm::vec2(std::min(range.x, extent), std::max(range.y, extent));
        }
        return range * mFrames[leaf].length;
    }

    BillboardListEntry BillboardLeafTiles::entryFor(const LeafPlacement& placement, float cellSize, std::uint32_t i,
                                                    std::uint32_t j) const
    {
        return BillboardListEntry::encode(placement.centre.x / cellSize - float(i),
                                          placement.centre.y / cellSize - float(j), placement.orientation,
                                          placement.mirrored, placement.rotation, placement.side / cellSize);
    }

    std::array<std::uint8_t, 4> BillboardLeafTiles::fitAo(std::uint32_t leaf, const LeafPlacement& placement,
                                                          const glm::vec3& origin, const glm::vec3& U,
                                                          const glm::vec3& V,
                                                          const std::vector<float>& leafVertexAo) const
    {
        std::array<std::uint8_t, 4> out{255, 255, 255, 255};
        if (leaf >= mModel.leaves.size())
            return out;
        const Leaf& l = mModel.leaves[leaf];
        const std::size_t end = std::min({std::size_t(l.firstVertex) + l.vertexCount, mModel.leafVertices.size(),
                                          leafVertexAo.size()});
        // §5.2, Fig. 11: least squares of f(l) = a00 (1-x)(1-y) + a10 x (1-y) + a01 (1-x) y + a11 x y
        // to the vertex AO at the vertices' tile-local positions (the shader's map), with a small
        // ridge towards the mean so collinear or coincident vertices stay well-posed.
        Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
        Eigen::Vector4d atb = Eigen::Vector4d::Zero();
        double mean = 0.0;
        std::size_t n = 0;
        const float c = std::cos(placement.rotation), s = std::sin(placement.rotation);
        const float side = placement.side > 0.0f ? placement.side : 1.0f;
        for (std::size_t v = l.firstVertex; v < end; ++v)
        {
            const float ao = leafVertexAo[v];
            if (!std::isfinite(ao))
                continue;
            const glm::vec3 p = mModel.leafVertices[v].position - origin;
            const glm::vec2 q = glm::vec2(glm::dot(p, U), glm::dot(p, V)) - placement.centre;
            const glm::vec2 local = billboardTileLocal(q, c, s, 1.0f / side, placement.mirrored);
            if (!std::isfinite(local.x) || !std::isfinite(local.y))
                continue;
            const Eigen::Vector4d basis((1.0 - local.x) * (1.0 - local.y), local.x * (1.0 - local.y),
                                        (1.0 - local.x) * local.y, double(local.x) * local.y);
            ata += basis * basis.transpose();
            atb += basis * double(ao);
            mean += ao;
            ++n;
        }
        if (n == 0)
            return out;
        mean /= double(n);
        const double ridge = 1e-4 * double(n);
        ata += ridge * Eigen::Matrix4d::Identity();
        atb += ridge * mean * Eigen::Vector4d::Ones();
        const Eigen::Vector4d a = ata.ldlt().solve(atb);
        for (int i = 0; i < 4; ++i)
        {
            const double value = std::isfinite(a[i]) ? a[i] : mean;
            out[std::size_t(i)] = std::uint8_t(std::lround(std::clamp(value, 0.0, 1.0) * 255.0));
        }
        return out;
    }

    glm::vec4 BillboardLeafTiles::sample(std::uint32_t tile, const glm::vec2& local) const
    {
        if (tile >= tileCount() || !(local.x >= 0.0f && local.x <= 1.0f && local.y >= 0.0f && local.y <= 1.0f))
            return glm::vec4(0.0f);
        const int T = int(mTileSize);
        const int ox = int(tile % mColumns) * T, oy = int(tile / mColumns) * T;
        // Bilinear within the tile (texel centres at (i + 0.5) / T, clamped at its edges).
        const float fx = local.x * float(T) - 0.5f, fy = local.y * float(T) - 0.5f;
        const float x0f = std::floor(fx), y0f = std::floor(fy);
        const float ax = fx - x0f, ay = fy - y0f;
        auto texel = [&](int x, int y) {
            x = std::clamp(x, 0, T - 1);
            y = std::clamp(y, 0, T - 1);
            const std::uint8_t* p =
                &mColour.rgba[(std::size_t(oy + y) * std::size_t(mColour.width) + std::size_t(ox + x)) * 4];
            return glm::vec4(srgbByteToLinear(p[0]), srgbByteToLinear(p[1]), srgbByteToLinear(p[2]),
                             float(p[3]) / 255.0f);
        };
        const int x0 = int(x0f), y0 = int(y0f);
        const glm::vec4 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), ax);
        const glm::vec4 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), ax);
        return glm::mix(top, bottom, ay);
    }

    glm::vec3 BillboardLeafTiles::sampleNormal(std::uint32_t tile, const glm::vec2& local) const
    {
        if (tile >= tileCount())
            return glm::vec3(0, 0, 1);
        const int T = int(mTileSize);
        const int x = std::clamp(int(std::floor(local.x * float(T))), 0, T - 1);
        const int y = std::clamp(int(std::floor(local.y * float(T))), 0, T - 1);
        const std::size_t o = (std::size_t(int(tile / mColumns) * T + y) * std::size_t(mNormal.width) +
                               std::size_t(int(tile % mColumns) * T + x)) * 4;
        const glm::vec3 n(float(mNormal.rgba[o]) / 255.0f * 2.0f - 1.0f,
                          float(mNormal.rgba[o + 1]) / 255.0f * 2.0f - 1.0f,
                          float(mNormal.rgba[o + 2]) / 255.0f * 2.0f - 1.0f);
        return glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0, 0, 1);
    }

    std::uint32_t BillboardLeafTiles::maxLod() const
    {
        // Level L averages 2^L x 2^L texels; a tile's content stays m = TILE_MARGIN * tileSize
        // texels from its edge, so a bilinear fetch at level L (reaching one level-L texel
        // outwards) stays inside its own tile while 2^L <= m.
        const float margin = TILE_MARGIN * float(mTileSize);
        std::uint32_t level = 0;
        while (float(1u << (level + 1)) <= margin && (1u << (level + 1)) <= mTileSize)
            ++level;
        return level;
    }
}
