// VolumeOctreeData: the "volume-octree" chunk and its camera pair (layout and meaning in
// VolumeOctreeData.h).
#include "TreeLod/VolumeOctreeData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;

        constexpr auto slotFields = [](auto& s, auto& slot) { s.fields(slot.colour, slot.alpha); };

        std::uint32_t spread(std::uint32_t v)
        {
            v &= 1023u;
            v = (v | (v << 16)) & 0x030000FFu;
            v = (v | (v << 8)) & 0x0300F00Fu;
            v = (v | (v << 4)) & 0x030C30C3u;
            v = (v | (v << 2)) & 0x09249249u;
            return v;
        }
    }

    std::uint32_t volumeMortonKey(std::uint32_t code)
    {
        const glm::uvec3 c = volumeCellCoords(code);
        return spread(c.x) | (spread(c.y) << 1) | (spread(c.z) << 2);
    }

    std::uint32_t VolumeOctreeData::firstCell(std::uint32_t level) const
    {
        std::uint32_t first = 0;
        for (std::uint32_t l = 0; l < level && l < levelCellCounts.size(); ++l)
            first += levelCellCounts[l];
        return first;
    }

    glm::vec3 VolumeOctreeData::cellCentre(std::uint32_t code, std::uint32_t level) const
    {
        const glm::uvec3 c = volumeCellCoords(code);
        return origin + cellEdge(level) * (glm::vec3(c) + 0.5f);
    }

    std::uint64_t VolumeOctreeData::billboardCount(std::uint32_t level) const
    {
        const std::size_t first = firstCell(level), c = cameraDirections.size();
        std::uint64_t n = 0;
        for (std::size_t i = first * c; i < (first + levelCellCounts.at(level)) * c; ++i)
            n += slots[i].pruned() ? 0 : 1;
        return n;
    }

    std::uint32_t volumeOctreeActiveLevel(const VolumeOctreeData& data, float nearestDepth, float focalPixels,
                                          float lodPixels)
    {
        for (std::uint32_t l = data.levelCount; l-- > 1;)
            if (volumeOctreePlaneDepth(data.cellEdge(l), focalPixels, lodPixels) > nearestDepth)
                return l;
        return 0;
    }

    std::vector<std::uint32_t> volumeOctreeOctantOrder(const VolumeOctreeData& data, std::uint32_t level,
                                                       std::uint32_t octant)
    {
        const std::uint32_t first = data.firstCell(level), count = data.levelCellCounts[level];
        const std::uint32_t last = (1u << level) - 1;
        const auto key = [&](std::uint32_t i) {
            const glm::uvec3 c = volumeCellCoords(data.cells[first + i]);
            const std::uint32_t x = octant & 1 ? c.x : last - c.x, y = octant & 2 ? c.y : last - c.y,
                                z = octant & 4 ? c.z : last - c.z;
            return (std::uint64_t(z) << 40) | (std::uint64_t(y) << 20) | x;
        };
        std::vector<std::uint32_t> order(count);
        std::iota(order.begin(), order.end(), 0u);
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
        return order;
    }

    VolumeCameraPair volumeOctreeCameraPair(const std::vector<glm::vec3>& cameraDirections, const glm::vec3& towards)
    {
        VolumeCameraPair pair;
        float best = -2.0f, second = -2.0f;
        for (std::uint32_t i = 0; i < cameraDirections.size(); ++i)
        {
            const float d = glm::dot(cameraDirections[i], towards);
            if (d > best)
            {
                second = best;
                pair.second = pair.first;
                best = d;
                pair.first = i;
            }
            else if (d > second)
            {
                second = d;
                pair.second = i;
            }
        }
        if (cameraDirections.size() < 2)
        {
            pair.second = pair.first;
            return pair;
        }
        const float a0 = std::acos(std::clamp(best, -1.0f, 1.0f)), a1 = std::acos(std::clamp(second, -1.0f, 1.0f));
        pair.firstWeight = a0 + a1 > 0.0f ? a1 / (a0 + a1) : 1.0f;
        return pair;
    }

    Result<void> VolumeOctreeData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(VOLUME_OCTREE_CHUNK, 0);
        if (levelCount < 1 || levelCount > VOLUME_OCTREE_MAX_LEVELS || levelCellCounts.size() != levelCount)
            return fail(label, name + ", levels",
                        std::to_string(levelCount) + " levels (1 to " + std::to_string(VOLUME_OCTREE_MAX_LEVELS) +
                            " needed, with one cell count each)");
        if (cameraDirections.empty() || cameraDirections.size() > VOLUME_OCTREE_MAX_CAMERAS)
            return fail(label, name + ", cameras",
                        std::to_string(cameraDirections.size()) + " cameras (1 to " +
                            std::to_string(VOLUME_OCTREE_MAX_CAMERAS) + " needed)");
        for (std::size_t i = 0; i < cameraDirections.size(); ++i)
        {
            const glm::vec3& d = cameraDirections[i];
            if (!std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z) ||
                std::abs(glm::length(d) - 1.0f) > 1e-3f)
                return fail(label, name + ", camera " + std::to_string(i), "direction is not a finite unit vector");
        }
        if (!std::isfinite(origin.x) || !std::isfinite(origin.y) || !std::isfinite(origin.z) || !(size > 0.0f) ||
            !std::isfinite(size))
            return fail(label, name + ", root cube", "origin and size must be finite, size > 0");
        std::uint64_t total = 0;
        for (std::uint32_t l = 0; l < levelCount; ++l)
        {
            if (std::uint64_t(levelCellCounts[l]) > (std::uint64_t(1) << (3 * l)))
                return fail(label, name + ", level " + std::to_string(l),
                            std::to_string(levelCellCounts[l]) + " cells, more than the level's " +
                                std::to_string(std::uint64_t(1) << (3 * l)));
            total += levelCellCounts[l];
        }
        if (total != cells.size())
            return fail(label, name + ", cells",
                        std::to_string(cells.size()) + " cell codes for " + std::to_string(total) + " counted cells");
        std::size_t at = 0;
        for (std::uint32_t l = 0; l < levelCount; ++l)
            for (std::uint32_t i = 0; i < levelCellCounts[l]; ++i, ++at)
            {
                const glm::uvec3 c = volumeCellCoords(cells[at]);
                const std::uint32_t side = 1u << l;
                if ((cells[at] >> 30) != 0 || c.x >= side || c.y >= side || c.z >= side)
                    return fail(label, name + ", level " + std::to_string(l) + " cell " + std::to_string(i),
                                "code " + std::to_string(cells[at]) + " outside the level's " + std::to_string(side) +
                                    " cells a side");
                if (i > 0 && volumeMortonKey(cells[at]) <= volumeMortonKey(cells[at - 1]))
                    return fail(label, name + ", level " + std::to_string(l) + " cell " + std::to_string(i),
                                "cells out of Morton order or repeated");
            }
        if (slots.size() != cells.size() * cameraDirections.size())
            return fail(label, name + ", slots",
                        std::to_string(slots.size()) + " slots for " + std::to_string(cells.size()) + " cells x " +
                            std::to_string(cameraDirections.size()) + " cameras");
        for (std::size_t i = 0; i < slots.size(); ++i)
        {
            const VolumeOctreeSlot& s = slots[i];
            if (s.pruned() != (s.alpha == NO_CODEWORD) ||
                (!s.pruned() && (s.colour >= colourCodewords || s.alpha >= alphaCodewords)))
                return fail(label, name + ", slot " + std::to_string(i),
                            "codewords " + std::to_string(s.colour) + ", " + std::to_string(s.alpha) + " (below " +
                                std::to_string(colourCodewords) + " and " + std::to_string(alphaCodewords) +
                                ", or both " + std::to_string(NO_CODEWORD) + " for a pruned billboard)");
        }
        const std::string atlasName = name + ", atlas '" + atlas.name + "'";
        if (std::string problem = gpuTextureProblem(atlas, {GpuTextureFormat::RGBA8, GpuTextureFormat::DXT5});
            !problem.empty())
            return fail(label, atlasName, problem);
        if (atlas.mipCount != 1 || atlas.width % 4 != 0 || atlas.height % 4 != 0)
            return fail(label, atlasName, "needs one mip level and a size in whole 4x4 blocks");
        const std::uint64_t blocks = std::uint64_t(atlas.width / 4) * (atlas.height / 4);
        if (std::max(colourCodewords, alphaCodewords) > blocks || colourCodewords >= NO_CODEWORD ||
            alphaCodewords >= NO_CODEWORD)
            return fail(label, atlasName,
                        std::to_string(blocks) + " blocks for " + std::to_string(colourCodewords) +
                            " colour and " + std::to_string(alphaCodewords) + " alpha codewords");
        return {};
    }

    std::vector<std::uint8_t> encodeVolumeOctreeChunk(const VolumeOctreeData& data)
    {
        ByteWriter w;
        w.reserve(256 + data.cells.size() * 4 + data.slots.size() * 4 + data.atlas.data.size());
        w.u32(KNOWN_FLAGS);
        w.fields(data.levelCount, data.cameraCount(), data.origin, data.size);
        for (const glm::vec3& d : data.cameraDirections)
            w.vec3(d);
        for (std::uint32_t n : data.levelCellCounts)
            w.u32(n);
        for (std::uint32_t c : data.cells)
            w.u32(c);
        for (const VolumeOctreeSlot& s : data.slots)
            slotFields(w, s);
        w.fields(data.colourCodewords, data.alphaCodewords);
        writeGpuTexture(w, data.atlas);
        return w.take();
    }

    Result<VolumeOctreeData> decodeVolumeOctreeChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(VOLUME_OCTREE_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        VolumeOctreeData data;
        readFlags(r, KNOWN_FLAGS);
        r.setElement(name + ", levels");
        std::uint32_t cameras = 0;
        r.fields(data.levelCount, cameras);
        if (r.ok() && (data.levelCount < 1 || data.levelCount > VOLUME_OCTREE_MAX_LEVELS || cameras < 1 ||
                       cameras > VOLUME_OCTREE_MAX_CAMERAS))
            r.failHere(std::to_string(data.levelCount) + " levels and " + std::to_string(cameras) +
                       " cameras (1 to " + std::to_string(VOLUME_OCTREE_MAX_LEVELS) + " and 1 to " +
                       std::to_string(VOLUME_OCTREE_MAX_CAMERAS) + " needed)");
        r.setElement(name + ", root cube");
        r.fields(data.origin, data.size);
        r.setElement(name + ", cameras");
        for (std::uint32_t i = 0; r.ok() && i < cameras; ++i)
            data.cameraDirections.push_back(r.vec3());
        r.setElement(name + ", levels");
        std::uint64_t total = 0;
        for (std::uint32_t l = 0; r.ok() && l < data.levelCount; ++l)
        {
            data.levelCellCounts.push_back(r.u32());
            total += data.levelCellCounts.back();
        }
        r.setElement(name + ", cells");
        // Check the sizes against what is left before allocating.
        if (r.ok() && total * (4 + 4 * std::uint64_t(cameras)) > r.remaining())
            r.failHere(std::to_string(total) + " cells of " + std::to_string(cameras) + " cameras need " +
                       std::to_string(total * (4 + 4 * std::uint64_t(cameras))) + " bytes, " +
                       std::to_string(r.remaining()) + " left");
        if (r.ok())
        {
            data.cells.resize(total);
            for (std::uint32_t& c : data.cells)
                c = r.u32();
            r.setElement(name + ", slots");
            data.slots.resize(total * cameras);
            for (VolumeOctreeSlot& s : data.slots)
                slotFields(r, s);
        }
        r.setElement(name + ", codebook");
        r.fields(data.colourCodewords, data.alphaCodewords);
        readGpuTexture(r, name + ", atlas", data.atlas);
        return finishDecode(r, label, name, std::move(data));
    }
}
