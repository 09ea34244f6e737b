#include "TreeLod/ModelChunk.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t ALIGN = 16;
        constexpr ArrayLayout MATERIALS{4 + 16 + 12 + 4 + 4 + 4};
        constexpr ArrayLayout TEXTURES{4 + 4 * 4 + 8 + 4};
        constexpr ArrayLayout VERTICES{32, ALIGN};
        constexpr ArrayLayout WORDS{4, ALIGN};
        constexpr ArrayLayout LEAVES{64, ALIGN};
        constexpr ArrayLayout NODES{20, ALIGN};
        constexpr std::uint32_t MATERIAL_LEAF = 1u;
        constexpr std::uint32_t MATERIAL_DOUBLE_SIDED = 2u;

        /// Bytes per texel (RGBA8) or per 4x4 block (BC1-BC5); 0 for an unknown format.
        std::uint32_t bytesPerUnit(GpuTextureFormat format)
        {
            switch (format)
            {
            case GpuTextureFormat::RGBA8:
                return 4;
            case GpuTextureFormat::DXT1:
            case GpuTextureFormat::BC4:
                return 8;
            case GpuTextureFormat::DXT5:
            case GpuTextureFormat::BC5:
                return 16;
            }
            return 0;
        }

        std::uint64_t levelBytes(GpuTextureFormat format, std::uint64_t w, std::uint64_t h)
        {
            if (isBlockCompressed(format))
                return ((w + 3) / 4) * ((h + 3) / 4) * bytesPerUnit(format);
            return w * h * bytesPerUnit(format);
        }

        bool finite(float v) { return std::isfinite(v); }
        bool finite(const glm::vec2& v) { return finite(v.x) && finite(v.y); }
        bool finite(const glm::vec3& v) { return finite(v.x) && finite(v.y) && finite(v.z); }
        bool finite(const glm::vec4& v) { return finite(glm::vec3(v)) && finite(v.w); }

        // Record fields, one list for the encoder and the decoder.
        constexpr auto vertexFields = [](auto& s, auto& v) { s.fields(v.position, v.normal, v.uv); };
        constexpr auto wordField = [](auto& s, auto& v) { s.fields(v); };
        constexpr auto leafFields = [](auto& s, auto& l) {
            s.fields(l.firstVertex, l.vertexCount, l.firstIndex, l.indexCount, l.material, l.centre, l.normal, l.area,
                     l.uvMin, l.uvMax);
        };
        constexpr auto nodeFields = [](auto& s, auto& n) { s.fields(n.position, n.radius, n.parent); };

        /// Vertices whose normal and uv are finite; false with the reader's error set.
        bool readVertices(ByteReader& r, const std::string& what, std::vector<Vertex>& out)
        {
            r.setElement(what);
            return readArray(r, out, VERTICES, [&](ByteReader& r, Vertex& v, std::uint32_t i) {
                vertexFields(r, v);
                if (!finite(v.normal) || !finite(v.uv))
                {
                    r.setElement(what + " " + std::to_string(i));
                    r.failHere("normal or uv is not finite");
                }
            });
        }

        bool readWords(ByteReader& r, const std::string& what, std::vector<std::uint32_t>& out)
        {
            r.setElement(what);
            return readArray(r, out, WORDS, wordField);
        }
    }

    std::uint32_t fullMipCount(std::uint32_t width, std::uint32_t height)
    {
        if (width == 0 || height == 0)
            return 0;
        std::uint32_t largest = width > height ? width : height, count = 1;
        while (largest > 1)
        {
            largest >>= 1;
            ++count;
        }
        return count;
    }

    std::uint64_t gpuTextureBytes(GpuTextureFormat format, std::uint32_t width, std::uint32_t height,
                                  std::uint32_t mipCount)
    {
        std::uint64_t total = 0;
        for (std::uint32_t level = 0; level < mipCount && level < 32; ++level)
        {
            std::uint64_t w = width >> level ? width >> level : 1, h = height >> level ? height >> level : 1;
            total += levelBytes(format, w, h);
        }
        return total;
    }

    std::uint64_t GpuTexture::mipOffset(std::uint32_t level) const
    {
        return gpuTextureBytes(format, width, height, level);
    }

    std::uint64_t GpuTexture::mipBytes(std::uint32_t level) const
    {
        return levelBytes(format, mipWidth(level), mipHeight(level));
    }

    bool isBlockCompressed(GpuTextureFormat format)
    {
        return format == GpuTextureFormat::DXT1 || format == GpuTextureFormat::DXT5 || format == GpuTextureFormat::BC4 ||
               format == GpuTextureFormat::BC5;
    }

    std::string gpuTextureFormatName(GpuTextureFormat format)
    {
        switch (format)
        {
        case GpuTextureFormat::RGBA8:
            return "RGBA8";
        case GpuTextureFormat::DXT1:
            return "DXT1";
        case GpuTextureFormat::DXT5:
            return "DXT5";
        case GpuTextureFormat::BC4:
            return "BC4";
        case GpuTextureFormat::BC5:
            return "BC5";
        }
        return "format " + std::to_string(std::uint32_t(format));
    }

    std::string gpuTextureProblem(const GpuTexture& tex, std::initializer_list<GpuTextureFormat> formats)
    {
        auto size = [](std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); };
        if (std::find(formats.begin(), formats.end(), tex.format) == formats.end())
        {
            std::string names;
            std::size_t i = 0;
            for (GpuTextureFormat f : formats)
            {
                names += i == 0 ? "" : (i + 1 == formats.size() ? " or " : ", ");
                names += gpuTextureFormatName(f);
                ++i;
            }
            const std::string given = bytesPerUnit(tex.format) ? " (" + gpuTextureFormatName(tex.format) + ")" : "";
            return "format " + std::to_string(std::uint32_t(tex.format)) + given + ": " + names + " needed";
        }
        if (tex.width < 1 || tex.height < 1 || tex.width > GPU_TEXTURE_MAX_SIZE || tex.height > GPU_TEXTURE_MAX_SIZE)
            return "size " + size(tex.width, tex.height) + " outside 1.." + std::to_string(GPU_TEXTURE_MAX_SIZE);
        if (tex.mipCount < 1 || tex.mipCount > fullMipCount(tex.width, tex.height))
            return std::to_string(tex.mipCount) + " mip levels for a " + size(tex.width, tex.height) + " texture";
        const std::uint64_t expected = gpuTextureBytes(tex.format, tex.width, tex.height, tex.mipCount);
        if (tex.data.size() != expected)
            return std::to_string(tex.data.size()) + " bytes of texel data, expected " + std::to_string(expected);
        return {};
    }

    void writeGpuTexture(ByteWriter& w, const GpuTexture& tex)
    {
        w.string(tex.name);
        w.u32(std::uint32_t(tex.format));
        w.u32(tex.width);
        w.u32(tex.height);
        w.u32(tex.mipCount);
        w.u64(tex.data.size());
        w.align(ALIGN);
        w.bytes(tex.data.data(), tex.data.size());
    }

    bool readGpuTexture(ByteReader& r, const std::string& element, GpuTexture& tex)
    {
        r.setElement(element);
        tex.name = r.string(MODEL_CHUNK_MAX_STRING);
        r.setElement(element + " '" + tex.name + "'");
        const std::uint32_t format = r.u32();
        tex.width = r.u32();
        tex.height = r.u32();
        tex.mipCount = r.u32();
        const std::uint64_t dataBytes = r.u64();
        if (!r.ok())
            return false;
        tex.format = GpuTextureFormat(format);
        if (bytesPerUnit(tex.format) == 0)
            r.failHere("unknown format " + std::to_string(format));
        else if (tex.width < 1 || tex.height < 1 || tex.width > GPU_TEXTURE_MAX_SIZE ||
                 tex.height > GPU_TEXTURE_MAX_SIZE)
            r.failHere("size " + std::to_string(tex.width) + "x" + std::to_string(tex.height) + " outside 1.." +
                       std::to_string(GPU_TEXTURE_MAX_SIZE));
        else if (tex.mipCount < 1 || tex.mipCount > fullMipCount(tex.width, tex.height))
            r.failHere(std::to_string(tex.mipCount) + " mip levels, a " + std::to_string(tex.width) + "x" +
                       std::to_string(tex.height) + " texture has 1.." +
                       std::to_string(fullMipCount(tex.width, tex.height)));
        else if (dataBytes != gpuTextureBytes(tex.format, tex.width, tex.height, tex.mipCount))
            r.failHere(std::to_string(dataBytes) + " bytes of texel data, expected " +
                       std::to_string(gpuTextureBytes(tex.format, tex.width, tex.height, tex.mipCount)));
        if (!r.ok())
            return false;
        r.align(ALIGN);
        const std::uint8_t* texels = r.take(std::size_t(dataBytes));
        if (!texels)
            return false;
        tex.data.assign(texels, texels + dataBytes);
        return true;
    }

    std::vector<std::uint8_t> encodeReferenceChunk(const ReferenceChunk& chunk)
    {
        const TreeModel& m = chunk.model;
        ByteWriter w;
        w.string(m.name);
        writeArray(w, m.materials, MATERIALS, [](ByteWriter& w, const Material& mat) {
            w.string(mat.name);
            w.fields(mat.baseColour, mat.backColour, mat.texture, mat.alphaCutoff,
                     (mat.isLeaf ? MATERIAL_LEAF : 0u) | (mat.doubleSided ? MATERIAL_DOUBLE_SIDED : 0u));
        });
        writeArray(w, chunk.textures, TEXTURES, writeGpuTexture);
        writeArray(w, m.barkVertices, VERTICES, vertexFields);
        writeArray(w, m.barkIndices, WORDS, wordField);
        writeArray(w, m.barkTriangleMaterial, WORDS, wordField);
        writeArray(w, m.leafVertices, VERTICES, vertexFields);
        writeArray(w, m.leafIndices, WORDS, wordField);
        writeArray(w, m.leaves, LEAVES, leafFields);
        writeArray(w, m.skeleton, NODES, nodeFields);
        w.fields(m.boundsMin, m.boundsMax);
        return w.take();
    }

    bool hasPolygons(const TreeModel& model) { return !model.barkIndices.empty() || !model.leafIndices.empty(); }

    Result<void> requirePolygons(const TreeModel& model, const std::string& label, const std::string& use)
    {
        if (hasPolygons(model))
            return {};
        return fail(label, chunkElement(REFERENCE_CHUNK, 0),
                    "no polygons: the tree was baked from photographs (a capture folder) and only the techniques "
                    "baked from photographs draw it; " + use + " needs a polygonal tree");
    }

    Result<ReferenceChunk> decodeReferenceChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string chunkName = chunkElement(REFERENCE_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, chunkName);
        ReferenceChunk chunk;
        TreeModel& m = chunk.model;

        m.name = r.string(MODEL_CHUNK_MAX_STRING);

        // ---- materials and textures ----
        r.setElement(chunkName + ", materials");
        readArray(r, m.materials, MATERIALS, [&](ByteReader& r, Material& mat, std::uint32_t i) {
            const std::string element = chunkName + ", material " + std::to_string(i);
            r.setElement(element);
            mat.name = r.string(MODEL_CHUNK_MAX_STRING);
            r.setElement(element + " '" + mat.name + "'");
            std::uint32_t flags = 0;
            r.fields(mat.baseColour, mat.backColour, mat.texture, mat.alphaCutoff, flags);
            checkFlags(r, flags, MATERIAL_LEAF | MATERIAL_DOUBLE_SIDED);
            if (!finite(mat.baseColour) || !finite(mat.backColour) || !finite(mat.alphaCutoff))
                r.failHere("colour or alpha cutoff is not finite");
            if (mat.texture < -1)
                r.failHere("texture index " + std::to_string(mat.texture) + " is negative");
            mat.isLeaf = (flags & MATERIAL_LEAF) != 0;
            mat.doubleSided = (flags & MATERIAL_DOUBLE_SIDED) != 0;
        });
        r.setElement(chunkName + ", textures");
        readArray(r, chunk.textures, TEXTURES, [&](ByteReader& r, GpuTexture& tex, std::uint32_t i) {
            if (readGpuTexture(r, chunkName + ", texture " + std::to_string(i), tex) &&
                tex.format != GpuTextureFormat::RGBA8)
                r.failHere("format " + gpuTextureFormatName(tex.format) + ": reference textures are RGBA8");
        });
        if (!r.ok())
            return r.error();
        const std::size_t textureCount = chunk.textures.size();
        for (std::size_t i = 0; i < m.materials.size(); ++i)
            if (m.materials[i].texture >= std::int32_t(textureCount))
                return fail(label, chunkName + ", material " + std::to_string(i) + " '" + m.materials[i].name + "'",
                            "texture " + std::to_string(m.materials[i].texture) + " out of range (" +
                                std::to_string(textureCount) + " textures)");

        // ---- geometry ----
        if (!readVertices(r, chunkName + ", bark vertex", m.barkVertices) ||
            !readWords(r, chunkName + ", bark indices", m.barkIndices) ||
            !readWords(r, chunkName + ", bark triangle materials", m.barkTriangleMaterial) ||
            !readVertices(r, chunkName + ", leaf vertex", m.leafVertices) ||
            !readWords(r, chunkName + ", leaf indices", m.leafIndices))
            return r.error();

        r.setElement(chunkName + ", leaves");
        readArray(r, m.leaves, LEAVES, [&](ByteReader& r, Leaf& leaf, std::uint32_t i) {
            leafFields(r, leaf);
            if (!finite(leaf.centre) || !finite(leaf.normal) || !finite(leaf.area) || !finite(leaf.uvMin) ||
                !finite(leaf.uvMax))
            {
                r.setElement(chunkName + ", leaf " + std::to_string(i));
                r.failHere("record has a value that is not finite");
            }
        });
        if (!r.ok())
            return r.error();
        std::uint64_t leafIndexTotal = 0;
        for (const Leaf& leaf : m.leaves)
            leafIndexTotal += leaf.indexCount;
        // Leaves own their index ranges (TreeModel.h), so the ranges are disjoint; this also
        // bounds the work TreeModel::validate does to one pass over the indices.
        if (leafIndexTotal > m.leafIndices.size())
            return fail(label, chunkName + ", leaves",
                        "leaf index ranges overlap (they cover " + std::to_string(leafIndexTotal) +
                            " indices, the model has " + std::to_string(m.leafIndices.size()) + ")");
        std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges; // (firstIndex, leaf)
        ranges.reserve(m.leaves.size());
        for (std::uint32_t i = 0; i < m.leaves.size(); ++i)
            if (m.leaves[i].indexCount > 0)
                ranges.emplace_back(m.leaves[i].firstIndex, i);
        std::sort(ranges.begin(), ranges.end());
        for (std::size_t k = 1; k < ranges.size(); ++k)
        {
            const Leaf& previous = m.leaves[ranges[k - 1].second];
            if (std::uint64_t(previous.firstIndex) + previous.indexCount > ranges[k].first)
                return fail(label, chunkName + ", leaf " + std::to_string(ranges[k].second),
                            "index range overlaps that of leaf " + std::to_string(ranges[k - 1].second));
        }

        r.setElement(chunkName + ", skeleton");
        readArray(r, m.skeleton, NODES, [&](ByteReader& r, SkeletonNode& node, std::uint32_t i) {
            nodeFields(r, node);
            std::string problem;
            if (node.parent < -1 || node.parent >= std::int32_t(i))
                problem = "parent " + std::to_string(node.parent) + " must be -1 or an earlier node";
            else if (!finite(node.position) || !finite(node.radius))
                problem = "position or radius is not finite";
            if (!problem.empty())
            {
                r.setElement(chunkName + ", skeleton node " + std::to_string(i));
                r.failHere(problem);
            }
        });
        if (!r.ok())
            return r.error();

        r.setElement(chunkName + ", bounds");
        r.fields(m.boundsMin, m.boundsMax);
        if (!r.ok())
            return r.error();
        if (!finite(m.boundsMin) || !finite(m.boundsMax))
            return fail(label, chunkName + ", bounds", "not finite");
        if (r.remaining() != 0)
            return fail(label, chunkName,
                        std::to_string(r.remaining()) + " trailing bytes after the model (at offset " +
                            std::to_string(r.offset()) + ")");

        // model.textures: a copy of mip level 0 of each texture (see the header).
        m.textures.resize(textureCount);
        for (std::size_t i = 0; i < textureCount; ++i)
        {
            const GpuTexture& tex = chunk.textures[i];
            TextureImage& image = m.textures[i];
            image.name = tex.name;
            image.width = int(tex.width);
            image.height = int(tex.height);
            image.rgba.assign(tex.data.begin(), tex.data.begin() + std::ptrdiff_t(tex.mipBytes(0)));
        }

        Result<void> valid = m.validate(label);
        if (!valid)
            return fail(label, chunkName + ", " + valid.error().element, valid.error().reason);
        return chunk;
    }
}
