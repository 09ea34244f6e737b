// BillboardCloudData: the "billboard-cloud" / "classic-billboard-cloud" chunk format of
// García et al. 2007 (billboard clouds with multi-layered indirect texturing): list entry
// quantisation (§4.2, Fig. 8), the hemi-octahedral orientations of the Leaves Texture (§3, §5),
// validation of every invariant the shader relies on, the chunk encoder/decoder, and
// BillboardCloudSampler, the shader's hash and list addressing (§4.2, §5) evaluated on the CPU
// with the same float steps.
#include "TreeLod/BillboardCloudData.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t ALIGN = 16;
        constexpr ArrayLayout LEVELS{20};
        constexpr ArrayLayout BILLBOARDS{80, ALIGN};
        constexpr ArrayLayout BARK_AO{1, ALIGN};
        constexpr std::size_t ENTRY_BYTES = 8;   ///< u16 x 4 in the Lists atlas
        constexpr std::size_t ENTRY_AO_BYTES = 4; ///< RGBA8 in the AO atlas
        constexpr std::size_t LEAF_IMAGE_BYTES = 24;
        constexpr std::uint32_t FLAG_CLASSIC = 1u;
        constexpr std::uint32_t MAX_TILES = 1u << 15; ///< orientation field of an entry: 15 bits
        constexpr double TWO_PI = 6.283185307179586;

        // Record fields, one list for the encoder and the decoder.
        constexpr auto billboardFields = [](auto& s, auto& b) {
            s.fields(b.origin, b.axisU, b.axisV, b.normal, b.hashX, b.hashY, b.hashWidth, b.hashHeight, b.lowResX,
                     b.lowResY, b.lowResWidth, b.lowResHeight);
        };
        constexpr auto leafImageFields = [](auto& s, auto& m) { s.fields(m.material, m.alphaCutoff, m.uvMin, m.uvMax); };
        constexpr auto byteField = [](auto& s, auto& v) { s.fields(v); };

        bool finite(float v) { return std::isfinite(v); }
        bool finite(const glm::vec3& v) { return finite(v.x) && finite(v.y) && finite(v.z); }

        std::string chunkName(bool classic) { return classic ? CLASSIC_BILLBOARD_CLOUD_CHUNK : BILLBOARD_CLOUD_CHUNK; }

        std::string rect(std::uint32_t x, std::uint32_t y, std::uint32_t w, std::uint32_t h)
        {
            return "[" + std::to_string(x) + ", " + std::to_string(std::uint64_t(x) + w) + ") x [" +
                   std::to_string(y) + ", " + std::to_string(std::uint64_t(y) + h) + ")";
        }

        bool rectInside(std::uint32_t x, std::uint32_t y, std::uint32_t w, std::uint32_t h, std::uint32_t width,
                        std::uint32_t height)
        {
            return std::uint64_t(x) + w <= width && std::uint64_t(y) + h <= height;
        }

        bool overlaps(const Billboard& a, const Billboard& b)
        {
            return a.hashX < std::uint64_t(b.hashX) + b.hashWidth && b.hashX < std::uint64_t(a.hashX) + a.hashWidth &&
                   a.hashY < std::uint64_t(b.hashY) + b.hashHeight && b.hashY < std::uint64_t(a.hashY) + a.hashHeight;
        }

    }

    // ---- list entries (§4.2, Fig. 8) -------------------------------------------------------

    std::uint32_t billboardGridCell(float g, std::uint32_t size)
    {
        const float f = std::floor(g);
        if (!(f >= 0.0f))
            return 0;
        if (f >= float(size - 1))
            return size - 1;
        return std::uint32_t(f);
    }

    float BillboardListEntry::side() const { return std::exp2((float(words[3] & 0xffu) - 128.0f) / 32.0f); }

    BillboardListEntry BillboardListEntry::encode(float centreX, float centreY, std::uint32_t orientation,
                                                  bool mirrored, float rotation, float side)
    {
        // Round to the nearest code, clamped to the codes that exist; NaN centres and angles
        // become 0, a NaN or non-positive side the smallest.
        auto centre = [](float c) {
            const double t = std::isnan(c) ? 32767.5 : (double(c) + BILLBOARD_CENTRE_RANGE) /
                                                          (2.0 * BILLBOARD_CENTRE_RANGE) * 65535.0;
            return std::uint16_t(std::lround(std::clamp(t, 0.0, 65535.0)));
        };
        std::uint32_t angle = 0;
        if (std::isfinite(rotation))
        {
            double turns = double(rotation) / TWO_PI * 256.0;
            turns -= 256.0 * std::floor(turns / 256.0);
            angle = std::uint32_t(std::lround(turns)) & 0xffu;
        }
        std::uint32_t scale = 0;
        if (side > 0.0f)
        {
            const double code = std::isfinite(side) ? 128.0 + 32.0 * std::log2(double(side)) : 255.0;
            scale = std::uint32_t(std::lround(std::clamp(code, 0.0, 255.0)));
        }
        BillboardListEntry e;
        e.words[0] = centre(centreX);
        e.words[1] = centre(centreY);
        e.words[2] = std::uint16_t(std::min<std::uint32_t>(orientation, 0x7fffu) | (mirrored ? 0x8000u : 0u));
        e.words[3] = std::uint16_t(angle << 8 | scale);
        return e;
    }

    // ---- BillboardCloudData -----------------------------------------------------------------

    std::pair<std::uint32_t, std::uint32_t> BillboardCloudData::cell(std::uint32_t billboard, std::uint32_t i,
                                                                     std::uint32_t j) const
    {
        if (billboard >= billboards.size())
            return {0, 0};
        const Billboard& b = billboards[billboard];
        if (i >= b.hashWidth || j >= b.hashHeight)
            return {0, 0};
        const std::uint64_t texel = (std::uint64_t(b.hashY) + j) * hashAtlasWidth + b.hashX + i;
        if (texel * 4 + 4 > hashAtlas.size())
            return {0, 0};
        const std::uint8_t* t = &hashAtlas[texel * 4];
        return {std::uint32_t(t[0]) | std::uint32_t(t[1]) << 8 | std::uint32_t(t[2]) << 16, t[3]};
    }

    std::uint64_t BillboardCloudData::gpuBytes() const
    {
        // Table 1: the atlases as the GPU allocates them (whole textures, AO indexed like the
        // Lists), the textures with all their mips, and the trunk's AO.
        const std::uint64_t hashTexels = std::uint64_t(hashAtlasWidth) * hashAtlasHeight;
        const std::uint64_t listTexels = std::uint64_t(listsAtlasWidth) * listsAtlasHeight;
        return hashTexels * 4 + listTexels * (ENTRY_BYTES + ENTRY_AO_BYTES) + leavesColour.data.size() +
               leavesNormal.data.size() + lowRes.data.size() + barkAo.size();
    }

    Result<void> BillboardCloudData::validate(const std::string& label) const
    {
        const std::string name = chunkName(classic);
        if (!finite(listFactor) || listFactor <= 0.0f)
            return fail(label, name, "list factor " + std::to_string(listFactor) + " is not a positive number");
        if (!finite(boundsMin) || !finite(boundsMax) || boundsMin.x > boundsMax.x || boundsMin.y > boundsMax.y ||
            boundsMin.z > boundsMax.z)
            return fail(label, name, "bounds not finite or min > max");

        // Levels cover the billboards in order, without gaps or overlaps (§6).
        std::vector<std::uint8_t> layeredBillboard(billboards.size(), 0);
        std::uint64_t next = 0;
        for (std::size_t l = 0; l < levels.size(); ++l)
        {
            const BillboardCloudLevel& level = levels[l];
            const std::string element = name + " level " + std::to_string(l);
            if (level.firstBillboard != next)
                return fail(label, element, "first billboard " + std::to_string(level.firstBillboard) + ", expected " +
                                                std::to_string(next));
            next += level.billboardCount;
            if (next > billboards.size())
                return fail(label, element, "billboards up to " + std::to_string(next) + ", the cloud has " +
                                                std::to_string(billboards.size()));
            if (classic && level.layered)
                return fail(label, element, "layered level in a classic cloud");
            if (!finite(level.cellSize) || (level.layered ? level.cellSize <= 0.0f : level.cellSize != 0.0f))
                return fail(label, element, "cell size " + std::to_string(level.cellSize) +
                                                (level.layered ? " (a layered level needs > 0)" : " (needs 0)"));
            if (!finite(level.lowResTexelSize) || level.lowResTexelSize < 0.0f)
                return fail(label, element, "low-res texel size " + std::to_string(level.lowResTexelSize));
            std::fill(layeredBillboard.begin() + level.firstBillboard, layeredBillboard.begin() + std::size_t(next),
                      std::uint8_t(level.layered));
        }
        if (next != billboards.size())
            return fail(label, name + " levels", "levels cover " + std::to_string(next) + " of " +
                                                     std::to_string(billboards.size()) + " billboards");

        // Textures (placeholders included).
        const std::pair<const GpuTexture*, const char*> textures[] = {
            {&leavesColour, "leaves colour texture"},
            {&leavesNormal, "leaves normal texture"},
            {&lowRes, "low-res texture"}};
        for (const auto& [tex, what] : textures)
        {
            std::string problem =
                gpuTextureProblem(*tex, {GpuTextureFormat::RGBA8, GpuTextureFormat::DXT1, GpuTextureFormat::DXT5});
            if (!problem.empty())
                return fail(label, name + " " + what + " '" + tex->name + "'", problem);
        }

        // Atlas sizes.
        if ((hashAtlasWidth == 0) != (hashAtlasHeight == 0) || hashAtlasWidth > GPU_TEXTURE_MAX_SIZE ||
            hashAtlasHeight > GPU_TEXTURE_MAX_SIZE)
            return fail(label, name + " hash atlas", "size " + std::to_string(hashAtlasWidth) + "x" +
                                                         std::to_string(hashAtlasHeight));
        if (hashAtlas.size() != std::uint64_t(hashAtlasWidth) * hashAtlasHeight * 4)
            return fail(label, name + " hash atlas", std::to_string(hashAtlas.size()) + " bytes for " +
                                                         std::to_string(hashAtlasWidth) + "x" +
                                                         std::to_string(hashAtlasHeight) + " RGBA8 texels");
        if ((listsAtlasWidth == 0) != (listsAtlasHeight == 0) || listsAtlasWidth > GPU_TEXTURE_MAX_SIZE ||
            listsAtlasHeight > GPU_TEXTURE_MAX_SIZE)
            return fail(label, name + " lists atlas", "size " + std::to_string(listsAtlasWidth) + "x" +
                                                          std::to_string(listsAtlasHeight));
        if (entries.size() > std::uint64_t(listsAtlasWidth) * listsAtlasHeight ||
            entries.size() > BILLBOARD_MAX_ENTRIES)
            return fail(label, name + " lists atlas", std::to_string(entries.size()) + " entries do not fit " +
                                                          std::to_string(listsAtlasWidth) + "x" +
                                                          std::to_string(listsAtlasHeight) + " texels (at most 2^24)");
        if (entryAo.size() != entries.size() * ENTRY_AO_BYTES)
            return fail(label, name + " AO atlas", std::to_string(entryAo.size()) + " bytes for " +
                                                       std::to_string(entries.size()) + " entries (4 each)");

        // Leaves Texture (§3, §5).
        const std::uint64_t orientations = std::uint64_t(orientationGrid) * orientationGrid;
        const std::uint64_t tiles = leafImages.size() * 2 * orientations;
        if (!leafImages.empty())
        {
            const std::string element = name + " leaves";
            if (tileSize == 0 || (tileSize & (tileSize - 1)) != 0)
                return fail(label, element, "tile size " + std::to_string(tileSize) + " is not a power of two");
            if (orientationGrid == 0 || tileColumns == 0 || tiles > MAX_TILES)
                return fail(label, element, std::to_string(tiles) + " tiles (orientation grid " +
                                                std::to_string(orientationGrid) + ", " + std::to_string(tileColumns) +
                                                " columns; 1.." + std::to_string(MAX_TILES) + " allowed)");
            const std::uint64_t rows = (tiles + tileColumns - 1) / tileColumns;
            if (std::uint64_t(tileColumns) * tileSize > leavesColour.width || rows * tileSize > leavesColour.height)
                return fail(label, element, std::to_string(tileColumns) + " x " + std::to_string(rows) + " tiles of " +
                                                std::to_string(tileSize) + " texels do not fit the " +
                                                std::to_string(leavesColour.width) + "x" +
                                                std::to_string(leavesColour.height) + " leaves texture");
            if (leavesNormal.width != leavesColour.width || leavesNormal.height != leavesColour.height)
                return fail(label, element, "normal and colour textures differ in size");
            for (std::size_t m = 0; m < leafImages.size(); ++m)
                if (!finite(leafImages[m].alphaCutoff) || leafImages[m].alphaCutoff < 0.0f ||
                    leafImages[m].alphaCutoff > 1.0f)
                    return fail(label, name + " leaf image " + std::to_string(m),
                                "alpha cutoff " + std::to_string(leafImages[m].alphaCutoff) + " outside [0, 1]");
                else if (!finite(leafImages[m].uvMin.x + leafImages[m].uvMin.y + leafImages[m].uvMax.x +
                                 leafImages[m].uvMax.y))
                    return fail(label, name + " leaf image " + std::to_string(m), "UV rectangle is not finite");
        }
        if (leavesMaxLod >= leavesColour.mipCount || leavesMaxLod >= leavesNormal.mipCount)
            return fail(label, name + " leaves", "max LoD " + std::to_string(leavesMaxLod) + ", the textures have " +
                                                     std::to_string(leavesColour.mipCount) + " and " +
                                                     std::to_string(leavesNormal.mipCount) + " mip levels");

        // Entries: side-0 tiles of an existing leaf image (§5).
        for (std::size_t e = 0; e < entries.size(); ++e)
        {
            const std::uint32_t k = entries[e].orientation();
            if (k >= tiles || k % (2 * orientations) >= orientations)
                return fail(label, name + " entry " + std::to_string(e),
                            "orientation " + std::to_string(k) + " is not a side-0 tile of the " +
                                std::to_string(tiles) +
                                " tiles (" + std::to_string(orientations) + " orientations per side)");
        }

        // Billboards: geometry, rects inside their atlases, hash rects disjoint.
        std::vector<std::uint64_t> used((std::uint64_t(hashAtlasWidth) * hashAtlasHeight + 63) / 64);
        for (std::size_t b = 0; b < billboards.size(); ++b)
        {
            const Billboard& bb = billboards[b];
            const std::string element = name + " billboard " + std::to_string(b);
            if (!finite(bb.origin) || !finite(bb.axisU) || !finite(bb.axisV) || !finite(bb.normal))
                return fail(label, element, "geometry is not finite");
            const float lu = glm::length(bb.axisU), lv = glm::length(bb.axisV);
            if (!(lu > 0.0f) || !(lv > 0.0f) || !finite(lu) || !finite(lv))
                return fail(label, element, "zero or overflowing axis");
            if (std::abs(glm::length(bb.normal) - 1.0f) > 1e-3f)
                return fail(label, element, "normal of length " + std::to_string(glm::length(bb.normal)));
            const glm::vec3 u = bb.axisU / lu, v = bb.axisV / lv;
            if (std::abs(glm::dot(u, v)) > 1e-3f || std::abs(glm::dot(u, bb.normal)) > 1e-3f ||
                std::abs(glm::dot(v, bb.normal)) > 1e-3f || glm::dot(glm::cross(u, v), bb.normal) <= 0.0f)
                return fail(label, element, "axes not orthogonal or normal not cross(axisU, axisV)");
            if (bb.lowResWidth < 1 || bb.lowResHeight < 1 ||
                !rectInside(bb.lowResX, bb.lowResY, bb.lowResWidth, bb.lowResHeight, lowRes.width, lowRes.height))
                return fail(label, element,
                            "low-res rect " + rect(bb.lowResX, bb.lowResY, bb.lowResWidth, bb.lowResHeight) +
                                " empty or outside the " + std::to_string(lowRes.width) + "x" +
                                std::to_string(lowRes.height) + " low-res texture");
            if (!layeredBillboard[b])
            {
                if (bb.hashWidth != 0 || bb.hashHeight != 0)
                    return fail(label, element, "hash grid on a billboard of a level that is not layered");
                continue;
            }
            if (bb.hashWidth < 1 || bb.hashHeight < 1 ||
                !rectInside(bb.hashX, bb.hashY, bb.hashWidth, bb.hashHeight, hashAtlasWidth, hashAtlasHeight))
                return fail(label, element, "hash rect " + rect(bb.hashX, bb.hashY, bb.hashWidth, bb.hashHeight) +
                                                " empty or outside the " + std::to_string(hashAtlasWidth) + "x" +
                                                std::to_string(hashAtlasHeight) + " hash atlas");
            // Occupancy bitmap: O(atlas texels) in all, since the first shared texel stops.
            for (std::uint32_t y = bb.hashY; y < bb.hashY + bb.hashHeight; ++y)
                for (std::uint32_t x = bb.hashX; x < bb.hashX + bb.hashWidth; ++x)
                {
                    const std::uint64_t bit = std::uint64_t(y) * hashAtlasWidth + x;
                    std::uint64_t& word = used[bit / 64];
                    const std::uint64_t mask = std::uint64_t(1) << (bit % 64);
                    if (word & mask)
                    {
                        std::size_t other = 0;
                        while (other < b && !(layeredBillboard[other] && overlaps(billboards[other], bb)))
                            ++other;
                        return fail(label, element,
                                    "hash rect " + rect(bb.hashX, bb.hashY, bb.hashWidth, bb.hashHeight) +
                                        " overlaps billboard " + std::to_string(other) + "'s");
                    }
                    word |= mask;
                }
        }

        // Every non-empty hash texel's list lies inside the entries (§4.2).
        const std::size_t texels = hashAtlas.size() / 4;
        for (std::size_t t = 0; t < texels; ++t)
        {
            const std::uint8_t* h = &hashAtlas[t * 4];
            if (h[3] == 0)
                continue;
            const std::uint64_t start = std::uint32_t(h[0]) | std::uint32_t(h[1]) << 8 | std::uint32_t(h[2]) << 16;
            if (start + h[3] > entries.size())
                return fail(label,
                            name + " hash texel (" + std::to_string(t % hashAtlasWidth) + ", " +
                                std::to_string(t / hashAtlasWidth) + ")",
                            "list [" + std::to_string(start) + ", " + std::to_string(start + h[3]) + ") outside the " +
                                std::to_string(entries.size()) + " entries");
        }
        return {};
    }

    // ---- orientations (§3, §5): hemi-octahedral grid --------------------------------------

    glm::vec3 billboardOrientationDirection(std::uint32_t k, std::uint32_t grid)
    {
        if (grid == 0)
            return {0.0f, 0.0f, 1.0f};
        const std::uint32_t x = k % grid, y = std::min(k / grid, grid - 1);
        const float cx = (float(x) + 0.5f) / float(grid) * 2.0f - 1.0f;
        const float cy = (float(y) + 0.5f) / float(grid) * 2.0f - 1.0f;
        // The square [-1, 1]^2 turned 45 degrees onto the diamond |a| + |b| <= 1.
        const float a = (cx + cy) * 0.5f, b = (cy - cx) * 0.5f;
        return glm::normalize(glm::vec3(a, b, 1.0f - std::abs(a) - std::abs(b)));
    }

    std::uint32_t billboardOrientationIndex(const glm::vec3& d, std::uint32_t grid)
    {
        if (grid == 0)
            return 0;
        glm::vec3 p(d.x, d.y, std::max(d.z, 0.0f));
        float s = std::abs(p.x) + std::abs(p.y) + p.z;
        if (!finite(p) || !(s > 0.0f) || !finite(s))
        {
            p = glm::vec3(0.0f, 0.0f, 1.0f);
            s = 1.0f;
        }
        // Onto the octahedron |a| + |b| + z = 1, then the diamond back onto the square.
        const float a = p.x / s, b = p.y / s;
        const float cx = a - b, cy = a + b;
        auto cell = [grid](float c) {
            const float f = std::floor((c + 1.0f) * 0.5f * float(grid));
            return f <= 0.0f ? 0u : f >= float(grid - 1) ? grid - 1 : std::uint32_t(f);
        };
        return cell(cx) + grid * cell(cy);
    }

    // ---- chunk ------------------------------------------------------------------------------

    std::vector<std::uint8_t> encodeBillboardCloudChunk(const BillboardCloudData& data)
    {
        ByteWriter w;
        w.reserve(256 + data.hashAtlas.size() + data.entries.size() * ENTRY_BYTES + data.entryAo.size() +
                  data.leafImages.size() * LEAF_IMAGE_BYTES + data.leavesColour.data.size() +
                  data.leavesNormal.data.size() + data.lowRes.data.size() + 4 * 64);
        w.u32(data.classic ? FLAG_CLASSIC : 0u);
        w.fields(data.listFactor, data.boundsMin, data.boundsMax);
        writeArray(w, data.levels, LEVELS, [](ByteWriter& w, const BillboardCloudLevel& level) {
            w.fields(level.firstBillboard, level.billboardCount, std::uint32_t(level.layered ? 1 : 0), level.cellSize,
                     level.lowResTexelSize);
        });
        writeArray(w, data.billboards, BILLBOARDS, billboardFields);

        w.fields(data.hashAtlasWidth, data.hashAtlasHeight);
        w.align(ALIGN);
        w.bytes(data.hashAtlas.data(), data.hashAtlas.size());

        w.fields(data.listsAtlasWidth, data.listsAtlasHeight, std::uint32_t(data.entries.size()));
        w.align(ALIGN);
        for (const BillboardListEntry& e : data.entries)
            w.fields(e.words[0], e.words[1], e.words[2], e.words[3]);
        w.align(ALIGN);
        w.bytes(data.entryAo.data(), data.entryAo.size());

        w.fields(data.tileSize, data.tileColumns, data.orientationGrid, std::uint32_t(data.leafImages.size()),
                 data.leavesMaxLod);
        for (const BillboardLeafImage& m : data.leafImages)
            leafImageFields(w, m);
        writeGpuTexture(w, data.leavesColour);
        writeGpuTexture(w, data.leavesNormal);
        writeGpuTexture(w, data.lowRes);
        writeArray(w, data.barkAo, BARK_AO, byteField);
        return w.take();
    }

    Result<BillboardCloudData> decodeBillboardCloudChunk(const std::vector<std::uint8_t>& bytes,
                                                         const std::string& label)
    {
        ByteReader r(bytes.data(), bytes.size(), label, chunkElement(BILLBOARD_CLOUD_CHUNK, 0));
        BillboardCloudData data;
        const std::uint32_t flags = r.u32();
        data.classic = (flags & FLAG_CLASSIC) != 0;
        const std::string name = chunkElement(chunkName(data.classic), 0);
        r.setElement(name); // the flags name the chunk
        checkFlags(r, flags, FLAG_CLASSIC);
        r.fields(data.listFactor, data.boundsMin, data.boundsMax);

        r.setElement(name + ", levels");
        readArray(r, data.levels, LEVELS, [&](ByteReader& r, BillboardCloudLevel& level, std::uint32_t l) {
            std::uint32_t layered = 0;
            r.fields(level.firstBillboard, level.billboardCount, layered, level.cellSize, level.lowResTexelSize);
            if (layered > 1)
            {
                r.setElement(name + ", level " + std::to_string(l));
                r.failHere("layered flag " + std::to_string(layered) + " is not 0 or 1");
            }
            level.layered = layered == 1;
        });

        r.setElement(name + ", billboards");
        readArray(r, data.billboards, BILLBOARDS, billboardFields);

        r.setElement(name + ", hash atlas");
        r.fields(data.hashAtlasWidth, data.hashAtlasHeight);
        if (r.ok() && (data.hashAtlasWidth > GPU_TEXTURE_MAX_SIZE || data.hashAtlasHeight > GPU_TEXTURE_MAX_SIZE))
            r.failHere("size " + std::to_string(data.hashAtlasWidth) + "x" + std::to_string(data.hashAtlasHeight) +
                       " over " + std::to_string(GPU_TEXTURE_MAX_SIZE));
        r.align(ALIGN);
        const std::size_t hashBytes = std::size_t(data.hashAtlasWidth) * data.hashAtlasHeight * 4;
        if (const std::uint8_t* p = r.ok() ? r.take(hashBytes) : nullptr)
            data.hashAtlas.assign(p, p + hashBytes);

        r.setElement(name + ", lists atlas");
        r.fields(data.listsAtlasWidth, data.listsAtlasHeight);
        if (r.ok() && (data.listsAtlasWidth > GPU_TEXTURE_MAX_SIZE || data.listsAtlasHeight > GPU_TEXTURE_MAX_SIZE))
            r.failHere("size " + std::to_string(data.listsAtlasWidth) + "x" + std::to_string(data.listsAtlasHeight) +
                       " over " + std::to_string(GPU_TEXTURE_MAX_SIZE));
        const std::uint32_t entryCount = r.ok() ? r.count(ENTRY_BYTES + ENTRY_AO_BYTES, ALIGN) : 0;
        r.align(ALIGN);
        if (const std::uint8_t* p = r.ok() ? r.take(entryCount * ENTRY_BYTES) : nullptr)
        {
            data.entries.resize(entryCount);
            for (std::size_t e = 0; e < entryCount; ++e, p += ENTRY_BYTES)
                for (int k = 0; k < 4; ++k)
                    data.entries[e].words[k] = std::uint16_t(p[2 * k] | p[2 * k + 1] << 8);
        }
        r.setElement(name + ", AO atlas");
        r.align(ALIGN);
        if (const std::uint8_t* p = r.ok() ? r.take(entryCount * ENTRY_AO_BYTES) : nullptr)
            data.entryAo.assign(p, p + entryCount * ENTRY_AO_BYTES);

        r.setElement(name + ", leaves");
        r.fields(data.tileSize, data.tileColumns, data.orientationGrid);
        const std::uint32_t imageCount = r.ok() ? r.count(LEAF_IMAGE_BYTES) : 0;
        data.leavesMaxLod = r.u32();
        data.leafImages.resize(imageCount);
        for (BillboardLeafImage& m : data.leafImages)
            leafImageFields(r, m);
        readGpuTexture(r, name + ", leaves colour texture", data.leavesColour);
        readGpuTexture(r, name + ", leaves normal texture", data.leavesNormal);
        readGpuTexture(r, name + ", low-res texture", data.lowRes);

        r.setElement(name + ", bark AO");
        readArray(r, data.barkAo, BARK_AO, byteField);
        return finishDecode(r, label, name, std::move(data));
    }

    // ---- BillboardCloudSampler: the fragment shader's addressing (§4.2, §5) ------------------

    BillboardCloudSampler::Cell BillboardCloudSampler::lookup(std::uint32_t billboard, float u, float v) const
    {
        Cell cell;
        if (billboard >= mData.billboards.size())
            return cell;
        const Billboard& b = mData.billboards[billboard];
        if (b.hashWidth == 0 || b.hashHeight == 0)
            return cell;
        // GLSL:
        //   vec2 g = uv * vec2(hashSize);
        //   vec2 cell = clamp(floor(g), vec2(0.0), vec2(hashSize) - 1.0);
        //   uvec4 h = uvec4(texelFetch(hashAtlas, ivec2(hashOrigin) + ivec2(cell), 0) * 255.0 + 0.5);
        //   uint start = h.r | (h.g << 8u) | (h.b << 16u), length = h.a;
        cell.i = billboardGridCell(u * float(b.hashWidth), b.hashWidth);
        cell.j = billboardGridCell(v * float(b.hashHeight), b.hashHeight);
        const auto [start, length] = mData.cell(billboard, cell.i, cell.j);
        cell.start = start;
        cell.length = length;
        return cell;
    }

    std::vector<BillboardCloudSampler::Fragment> BillboardCloudSampler::walk(std::uint32_t billboard, float u, float v,
                                                                             bool frontSide,
                                                                             std::uint32_t maxEntries) const
    {
        std::vector<Fragment> out;
        const Cell cell = lookup(billboard, u, v);
        if (cell.length == 0 || std::uint64_t(cell.start) + cell.length > mData.entries.size())
            return out;
        const Billboard& b = mData.billboards[billboard];
        // Position in the cell: p = g - cell, in [0, 1]^2 (1 only at the grid's far edge).
        const float px = u * float(b.hashWidth) - float(cell.i);
        const float py = v * float(b.hashHeight) - float(cell.j);
        const std::uint32_t side = frontSide ? 0u : 1u;
        const std::uint32_t count = std::min(cell.length, maxEntries);
        // Front side: the list in order (front to back from +normal); back side: reversed (§5).
        // GLSL per entry e (lists and AO atlases: texel ivec2(e % W, e / W), integer ops only):
        //   uvec4 w = uvec4(texelFetch(listsAtlas, ivec2(e % W, e / W), 0) * 65535.0 + 0.5);
        //   vec2 q = p - (vec2(w.rg) / 65535.0 * 64.0 - 32.0);
        //   float psi = float(w.a >> 8u) * 6.28318530718 / 256.0;
        //   float side = exp2((float(w.a & 255u) - 128.0) / 32.0);
        //   float c = cos(psi), s = sin(psi);
        //   vec2 local = vec2(c * q.x + s * q.y, -s * q.x + c * q.y) / side + 0.5;   // R(-psi) q / side + 0.5
        //   uint m = w.b >> 15u;  if (m == 1u) local.x = 1.0 - local.x;
        //   if (any(lessThan(local, vec2(0.0))) || any(greaterThan(local, vec2(1.0)))) continue;
        //   uint tile = (w.b & 0x7fffu) + (viewSide ^ m) * orientationCount;
        for (std::uint32_t n = 0; n < count; ++n)
        {
            const std::uint32_t e = frontSide ? cell.start + n : cell.start + cell.length - 1 - n;
            const BillboardListEntry& entry = mData.entries[e];
            const float qx = px - entry.centreX();
            const float qy = py - entry.centreY();
            const float psi = entry.rotation();
            const float c = std::cos(psi), s = std::sin(psi);
            const std::uint32_t mirror = entry.mirrored() ? 1u : 0u;
            const glm::vec2 local = billboardTileLocal(glm::vec2(qx, qy), c, s, 1.0f / entry.side(), mirror != 0);
            if (!(local.x >= 0.0f && local.x <= 1.0f && local.y >= 0.0f && local.y <= 1.0f))
                continue;
            out.push_back({e, entry.orientation() + (side ^ mirror) * mData.orientationCount(), local});
        }
        return out;
    }
}
