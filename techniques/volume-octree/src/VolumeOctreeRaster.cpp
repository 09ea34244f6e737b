// VolumeOctreeRaster: the CPU twin of VolumeOctreeTree's drawing (contract in VolumeOctreeBaker.h,
// "the CPU twin of the renderer"), and the billboard sources it draws from.
#include "TreeLod/VolumeOctreeBaker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace TreeLod
{
    VolumeBillboardSource volumeOctreeRawSource(const VolumeOctreeReconstruction& reconstruction)
    {
        return [&reconstruction](std::size_t cell, std::uint32_t camera, BillboardTexture& out) {
            const std::uint32_t b = reconstruction.billboardOf[cell * reconstruction.octree.cameraCount() + camera];
            if (b == std::numeric_limits<std::uint32_t>::max())
                return false;
            out = reconstruction.billboards[b];
            fillTransparentTexels(out); // as the codebook's colours are (VectorQuantiser.h)
            return true;
        };
    }

    VolumeBillboardSource volumeOctreeAtlasSource(const VolumeOctreeData& data)
    {
        struct Decoded
        {
            GpuTexture atlas;
            std::vector<VolumeOctreeSlot> slots;
            std::uint32_t cameras = 0, perRow = 0;
        };
        auto decoded = std::make_shared<Decoded>();
        decoded->atlas = decodeGpuTexture(data.atlas);
        decoded->slots = data.slots;
        decoded->cameras = data.cameraCount();
        decoded->perRow = data.atlas.width / VOLUME_BILLBOARD_TEXELS;
        return [decoded](std::size_t cell, std::uint32_t camera, BillboardTexture& out) {
            const VolumeOctreeSlot& slot = decoded->slots[cell * decoded->cameras + camera];
            if (slot.pruned())
                return false;
            const GpuTexture& atlas = decoded->atlas;
            for (std::uint32_t t = 0; t < VOLUME_BILLBOARD_TEXELS; ++t)
                for (std::uint32_t s = 0; s < VOLUME_BILLBOARD_TEXELS; ++s)
                {
                    const auto texel = [&](std::uint32_t block) {
                        const std::size_t x = (block % decoded->perRow) * VOLUME_BILLBOARD_TEXELS + s;
                        const std::size_t y = (block / decoded->perRow) * VOLUME_BILLBOARD_TEXELS + t;
                        return &atlas.data[(y * atlas.width + x) * 4];
                    };
                    std::array<std::uint8_t, 4>& o = out.texels[t * VOLUME_BILLBOARD_TEXELS + s];
                    const std::uint8_t* c = texel(slot.colour);
                    o = {c[0], c[1], c[2], texel(slot.alpha)[3]};
                }
            return true;
        };
    }

    namespace
    {
        /// A billboard at texel coordinates (s, t) in [0, 4]^2, as the GPU samples its atlas block:
        /// sRGB colour and alpha each bilinear between texel centres (clamped to the block), then
        /// premultiplied.
        glm::vec4 sampleBillboard(const BillboardTexture& b, float s, float t)
        {
            const float last = float(VOLUME_BILLBOARD_TEXELS - 1);
            const float x = std::clamp(s - 0.5f, 0.0f, last), y = std::clamp(t - 0.5f, 0.0f, last);
            const int x0 = std::min(int(x), int(last) - 1), y0 = std::min(int(y), int(last) - 1);
            const float fx = x - float(x0), fy = y - float(y0);
            const auto at = [&](int xx, int yy) {
                const std::array<std::uint8_t, 4>& c = b.texels[std::size_t(yy) * VOLUME_BILLBOARD_TEXELS + xx];
                return glm::vec4(byteToUnit(c[0]), byteToUnit(c[1]), byteToUnit(c[2]), byteToUnit(c[3]));
            };
            const glm::vec4 straight = (1.0f - fy) * ((1.0f - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                                       fy * ((1.0f - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
            return glm::vec4(glm::vec3(straight) * straight.a, straight.a);
        }

        struct DrawnCell
        {
            std::size_t index;
            std::uint32_t level;
            float depth;
        };
    }

    Image renderVolumeOctree(const VolumeOctreeData& octree, const VolumeBillboardSource& billboards,
                             const CameraSpec& camera, const VolumeOctreeRenderOptions& options)
    {
        const int w = options.width, h = options.height;
        // Blending happens on sRGB values, as in the GPU's framebuffer (TreeLod's materials write sRGB).
        std::vector<glm::vec4> frame(std::size_t(std::max(w, 0)) * std::max(h, 0), glm::vec4(0.0f));
        if (!options.transparentBackground)
            std::fill(frame.begin(), frame.end(), glm::vec4(options.background, 1.0f));

        const glm::mat4 view = camera.viewMatrix();
        const glm::mat4 projection = camera.projectionMatrix(float(w) / float(std::max(h, 1)));
        const glm::vec3 right(view[0][0], view[1][0], view[2][0]), up(view[0][1], view[1][1], view[2][1]);
        const auto viewDepth = [&](const glm::vec3& p) { return -(view * glm::vec4(p, 1.0f)).z; };

        // The camera pair and the active level (§2.1, §3.1).
        const glm::vec3 centre = octree.origin + 0.5f * octree.size;
        const glm::vec3 towards = camera.orthographic ? glm::normalize(camera.position - camera.target)
                                                      : glm::normalize(camera.position - centre);
        const VolumeCameraPair pair = volumeOctreeCameraPair(octree.cameraDirections, towards);
        float nearest = std::numeric_limits<float>::max();
        for (int k = 0; k < 8; ++k)
            nearest = std::min(nearest, viewDepth(octree.origin + octree.size * glm::vec3(k & 1, (k >> 1) & 1, k >> 2)));
        const float focal = camera.orthographic ? float(h) / camera.orthoHeight * std::max(nearest, 1e-6f)
                                                : 0.5f * float(h) / std::tan(glm::radians(0.5f * camera.fovYDegrees));
        std::uint32_t active = options.activeLevel >= 0
                                   ? std::min(std::uint32_t(options.activeLevel), octree.levelCount - 1)
                                   : volumeOctreeActiveLevel(octree, std::max(nearest, 1e-6f), focal, options.lodPixels);
        // Orthographic views have no depth to plane: the active level alone (and nothing one up).
        const float plane = camera.orthographic ? std::numeric_limits<float>::max()
                                                : volumeOctreePlaneDepth(octree.cellEdge(active), focal, options.lodPixels);

        // Back to front as the GPU draws: the level above first (behind the plane), each level in
        // its order for the view's octant.
        std::vector<DrawnCell> drawn;
        const std::uint32_t octant = volumeOctreeOctant(-towards);
        for (std::uint32_t level = active == 0 ? 0 : active - 1; level <= active; ++level)
        {
            const std::uint32_t first = octree.firstCell(level);
            for (std::uint32_t i : volumeOctreeOctantOrder(octree, level, octant))
            {
                const std::uint32_t code = octree.cells[first + i];
                const float depth = viewDepth(octree.cellCentre(code, level));
                const glm::uvec3 c = volumeCellCoords(code);
                const float parentDepth =
                    level == 0 ? depth : viewDepth(octree.cellCentre(volumeCellCode(c.x / 2, c.y / 2, c.z / 2), level - 1));
                if (volumeOctreeDrawsCell(level, depth, parentDepth, active, plane))
                    drawn.push_back({first + i, level, depth});
            }
        }

        const float w0 = pair.firstWeight, w1 = 1.0f - pair.firstWeight;
        BillboardTexture first, second;
        for (const DrawnCell& d : drawn)
        {
            const bool hasFirst = billboards(d.index, pair.first, first);
            const bool hasSecond = w1 > 0.0f && billboards(d.index, pair.second, second);
            if (!hasFirst && !hasSecond)
                continue;
            const glm::vec3 c = octree.cellCentre(octree.cells[d.index], d.level);
            const float half = 0.5f * octree.cellEdge(d.level);
            if (!camera.orthographic && d.depth <= camera.nearClip)
                continue;
            // The billboard faces the camera: parallel to the image plane, an axis-aligned rectangle.
            const auto toPixel = [&](const glm::vec3& p) {
                const glm::vec4 clip = projection * view * glm::vec4(p, 1.0f);
                return glm::vec2((clip.x / clip.w + 1.0f) * 0.5f * float(w), (1.0f - clip.y / clip.w) * 0.5f * float(h));
            };
            const glm::vec2 lo = toPixel(c - half * right + half * up), hi = toPixel(c + half * right - half * up);
            // Pixel bounds clamped before the conversion to int (a quad just past the near plane
            // projects far outside the image).
            const auto pixelIndex = [](float v) { return int(std::clamp(std::ceil(v - 0.5f), -1e6f, 1e6f)); };
            const int x0 = std::max(0, pixelIndex(lo.x)), x1 = std::min(w - 1, pixelIndex(hi.x) - 1);
            const int y0 = std::max(0, pixelIndex(lo.y)), y1 = std::min(h - 1, pixelIndex(hi.y) - 1);
            const float sx = float(VOLUME_BILLBOARD_TEXELS) / (hi.x - lo.x), sy = float(VOLUME_BILLBOARD_TEXELS) / (hi.y - lo.y);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                {
                    const float s = (float(x) + 0.5f - lo.x) * sx, t = (float(y) + 0.5f - lo.y) * sy;
                    glm::vec4 src(0.0f);
                    if (hasFirst)
                        src += w0 * sampleBillboard(first, s, t);
                    if (hasSecond)
                        src += w1 * sampleBillboard(second, s, t);
                    glm::vec4& dst = frame[std::size_t(y) * w + x];
                    dst = src + (1.0f - src.a) * dst;
                }
        }

        Image image(w, h);
        for (std::size_t i = 0; i < frame.size(); ++i)
        {
            const glm::vec4& p = frame[i];
            const glm::vec3 straight = options.transparentBackground && p.a > 0.0f ? glm::vec3(p) / p.a : glm::vec3(p);
            image.pixels[i] = glm::vec4(glm::clamp(straight, 0.0f, 1.0f), options.transparentBackground ? p.a : 1.0f);
        }
        return image;
    }
}
