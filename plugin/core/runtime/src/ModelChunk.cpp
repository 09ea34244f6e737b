#include "TreeLod/ModelChunk.h"

#include "TreeLod/ByteReader.h"
#include "TreeLod/ByteWriter.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t ALIGN = 16;
        constexpr std::size_t VERTEX_BYTES = 32;
        constexpr std::size_t LEAF_BYTES = 64;
        constexpr std::size_t NODE_BYTES = 20;
        constexpr std::size_t MATERIAL_MIN_BYTES = 4 + 16 + 12 + 4 + 4 + 4;
        constexpr std::size_t TEXTURE_MIN_BYTES = 4 + 4 * 4 + 8 + 4;
        constexpr std::uint32_t MATERIAL_LEAF = 1u;
        constexpr std::uint32_t MATERIAL_DOUBLE_SIDED = 2u;

        /// Bytes per texel (RGBA8) or per 4x4 block (DXT); 0 for an unknown format.
        std::uint32_t bytesPerUnit(GpuTextureFormat format)
        {
            switch (format)
            {
            case GpuTextureFormat::RGBA8:
                return 4;
            case GpuTextureFormat::DXT1:
                return 8;
            case GpuTextureFormat::DXT5:
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

        // ---- encoding ----

        void writeVertices(ByteWriter& w, const std::vector<Vertex>& vertices)
        {
            w.u32(std::uint32_t(vertices.size()));
            w.align(ALIGN);
            w.reserve(vertices.size() * VERTEX_BYTES);
            for (const Vertex& v : vertices)
            {
                w.vec3(v.position);
                w.vec3(v.normal);
                w.vec2(v.uv);
            }
        }

        void writeU32s(ByteWriter& w, const std::vector<std::uint32_t>& values)
        {
            w.u32(std::uint32_t(values.size()));
            w.align(ALIGN);
            w.reserve(values.size() * 4);
            for (std::uint32_t v : values)
                w.u32(v);
        }

        // ---- decoding: each returns false with the reader's error set ----

        bool readVertices(ByteReader& r, const std::string& what, std::vector<Vertex>& out)
        {
            r.setElement(what);
            std::uint32_t n = r.count(VERTEX_BYTES, ALIGN);
            r.align(ALIGN);
            if (!r.ok())
                return false;
            out.resize(n);
            for (std::uint32_t i = 0; i < n; ++i)
            {
                Vertex& v = out[i];
                v.position = r.vec3();
                v.normal = r.vec3();
                v.uv = r.vec2();
                if (!finite(v.normal) || !finite(v.uv))
                {
                    r.setElement(what + " " + std::to_string(i));
                    r.failHere("normal or uv is not finite");
                    return false;
                }
            }
            return r.ok();
        }

        bool readU32s(ByteReader& r, const std::string& what, std::vector<std::uint32_t>& out)
        {
            r.setElement(what);
            std::uint32_t n = r.count(4, ALIGN);
            r.align(ALIGN);
            if (!r.ok())
                return false;
            out.resize(n);
            for (std::uint32_t i = 0; i < n; ++i)
                out[i] = r.u32();
            return r.ok();
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
        return format == GpuTextureFormat::DXT1 || format == GpuTextureFormat::DXT5;
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
                names += f == GpuTextureFormat::RGBA8 ? "RGBA8" : f == GpuTextureFormat::DXT1 ? "DXT1" : "DXT5";
                ++i;
            }
            return "format " + std::to_string(std::uint32_t(tex.format)) + " (" + names + " needed)";
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

        w.u32(std::uint32_t(m.materials.size()));
        for (const Material& mat : m.materials)
        {
            w.string(mat.name);
            w.vec4(mat.baseColour);
            w.vec3(mat.backColour);
            w.i32(mat.texture);
            w.f32(mat.alphaCutoff);
            w.u32((mat.isLeaf ? MATERIAL_LEAF : 0u) | (mat.doubleSided ? MATERIAL_DOUBLE_SIDED : 0u));
        }

        w.u32(std::uint32_t(chunk.textures.size()));
        for (const GpuTexture& tex : chunk.textures)
            writeGpuTexture(w, tex);

        writeVertices(w, m.barkVertices);
        writeU32s(w, m.barkIndices);
        writeU32s(w, m.barkTriangleMaterial);
        writeVertices(w, m.leafVertices);
        writeU32s(w, m.leafIndices);

        w.u32(std::uint32_t(m.leaves.size()));
        w.align(ALIGN);
        w.reserve(m.leaves.size() * LEAF_BYTES);
        for (const Leaf& leaf : m.leaves)
        {
            w.u32(leaf.firstVertex);
            w.u32(leaf.vertexCount);
            w.u32(leaf.firstIndex);
            w.u32(leaf.indexCount);
            w.u32(leaf.material);
            w.vec3(leaf.centre);
            w.vec3(leaf.normal);
            w.f32(leaf.area);
            w.vec2(leaf.uvMin);
            w.vec2(leaf.uvMax);
        }

        w.u32(std::uint32_t(m.skeleton.size()));
        w.align(ALIGN);
        for (const SkeletonNode& node : m.skeleton)
        {
            w.vec3(node.position);
            w.f32(node.radius);
            w.i32(node.parent);
        }

        w.vec3(m.boundsMin);
        w.vec3(m.boundsMax);
        return w.take();
    }

    bool hasPolygons(const TreeModel& model) { return !model.barkIndices.empty() || !model.leafIndices.empty(); }

    Result<void> requirePolygons(const TreeModel& model, const std::string& label, const std::string& use)
    {
        if (hasPolygons(model))
            return {};
        return fail(label, chunkElement(REFERENCE_CHUNK, 0),
                    "no polygons: the tree was baked from photographs (a capture folder) and only volume-octree "
                    "draws it; " + use + " needs a polygonal tree");
    }

    Result<ReferenceChunk> decodeReferenceChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string chunkName = chunkElement(REFERENCE_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, chunkName);
        ReferenceChunk chunk;
        TreeModel& m = chunk.model;

        m.name = r.string(MODEL_CHUNK_MAX_STRING);

        // ---- materials ----
        r.setElement(chunkName + ", materials");
        const std::uint32_t materialCount = r.count(MATERIAL_MIN_BYTES);
        if (!r.ok())
            return r.error();
        m.materials.resize(materialCount);
        for (std::uint32_t i = 0; i < materialCount; ++i)
        {
            Material& mat = m.materials[i];
            r.setElement(chunkName + ", material " + std::to_string(i));
            mat.name = r.string(MODEL_CHUNK_MAX_STRING);
            r.setElement(chunkName + ", material " + std::to_string(i) + " '" + mat.name + "'");
            mat.baseColour = r.vec4();
            mat.backColour = r.vec3();
            mat.texture = r.i32();
            mat.alphaCutoff = r.f32();
            const std::uint32_t flags = r.u32();
            if (!r.ok())
                return r.error();
            if (flags & ~(MATERIAL_LEAF | MATERIAL_DOUBLE_SIDED))
                r.failHere("unknown flags " + std::to_string(flags));
            else if (!finite(mat.baseColour) || !finite(mat.backColour) || !finite(mat.alphaCutoff))
                r.failHere("colour or alpha cutoff is not finite");
            else if (mat.texture < -1)
                r.failHere("texture index " + std::to_string(mat.texture) + " is negative");
            if (!r.ok())
                return r.error();
            mat.isLeaf = (flags & MATERIAL_LEAF) != 0;
            mat.doubleSided = (flags & MATERIAL_DOUBLE_SIDED) != 0;
        }

        // ---- textures ----
        r.setElement(chunkName + ", textures");
        const std::uint32_t textureCount = r.count(TEXTURE_MIN_BYTES);
        if (!r.ok())
            return r.error();
        chunk.textures.resize(textureCount);
        for (std::uint32_t i = 0; i < textureCount; ++i)
        {
            if (!readGpuTexture(r, chunkName + ", texture " + std::to_string(i), chunk.textures[i]))
                return r.error();
            if (chunk.textures[i].format != GpuTextureFormat::RGBA8)
            {
                r.failHere("format " + std::to_string(std::uint32_t(chunk.textures[i].format)) +
                           ": reference textures are RGBA8");
                return r.error();
            }
        }
        for (std::uint32_t i = 0; i < materialCount; ++i)
            if (m.materials[i].texture >= std::int32_t(textureCount))
                return fail(label, chunkName + ", material " + std::to_string(i) + " '" + m.materials[i].name + "'",
                            "texture " + std::to_string(m.materials[i].texture) + " out of range (" +
                                std::to_string(textureCount) + " textures)");

        // ---- geometry ----
        if (!readVertices(r, chunkName + ", bark vertex", m.barkVertices) ||
            !readU32s(r, chunkName + ", bark indices", m.barkIndices) ||
            !readU32s(r, chunkName + ", bark triangle materials", m.barkTriangleMaterial) ||
            !readVertices(r, chunkName + ", leaf vertex", m.leafVertices) ||
            !readU32s(r, chunkName + ", leaf indices", m.leafIndices))
            return r.error();

        r.setElement(chunkName + ", leaves");
        const std::uint32_t leafCount = r.count(LEAF_BYTES, ALIGN);
        r.align(ALIGN);
        if (!r.ok())
            return r.error();
        m.leaves.resize(leafCount);
        std::uint64_t leafIndexTotal = 0;
        for (std::uint32_t i = 0; i < leafCount; ++i)
        {
            Leaf& leaf = m.leaves[i];
            leaf.firstVertex = r.u32();
            leaf.vertexCount = r.u32();
            leaf.firstIndex = r.u32();
            leaf.indexCount = r.u32();
            leaf.material = r.u32();
            leaf.centre = r.vec3();
            leaf.normal = r.vec3();
            leaf.area = r.f32();
            leaf.uvMin = r.vec2();
            leaf.uvMax = r.vec2();
            if (!finite(leaf.centre) || !finite(leaf.normal) || !finite(leaf.area) || !finite(leaf.uvMin) ||
                !finite(leaf.uvMax))
            {
                r.setElement(chunkName + ", leaf " + std::to_string(i));
                r.failHere("record has a value that is not finite");
            }
            leafIndexTotal += leaf.indexCount;
        }
        if (!r.ok())
            return r.error();
        // Leaves own their index ranges (TreeModel.h), so the ranges are disjoint; this also
        // bounds the work TreeModel::validate does to one pass over the indices.
        if (leafIndexTotal > m.leafIndices.size())
            return fail(label, chunkName + ", leaves",
                        "leaf index ranges overlap (they cover " + std::to_string(leafIndexTotal) +
                            " indices, the model has " + std::to_string(m.leafIndices.size()) + ")");
        std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges; // (firstIndex, leaf)
        ranges.reserve(leafCount);
        for (std::uint32_t i = 0; i < leafCount; ++i)
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
        const std::uint32_t nodeCount = r.count(NODE_BYTES, ALIGN);
        r.align(ALIGN);
        if (!r.ok())
            return r.error();
        m.skeleton.resize(nodeCount);
        for (std::uint32_t i = 0; i < nodeCount; ++i)
        {
            SkeletonNode& node = m.skeleton[i];
            node.position = r.vec3();
            node.radius = r.f32();
            node.parent = r.i32();
            if (r.ok() && (node.parent < -1 || node.parent >= std::int32_t(i)))
            {
                r.setElement(chunkName + ", skeleton node " + std::to_string(i));
                r.failHere("parent " + std::to_string(node.parent) + " must be -1 or an earlier node");
            }
            else if (r.ok() && (!finite(node.position) || !finite(node.radius)))
            {
                r.setElement(chunkName + ", skeleton node " + std::to_string(i));
                r.failHere("position or radius is not finite");
            }
            if (!r.ok())
                return r.error();
        }

        r.setElement(chunkName + ", bounds");
        m.boundsMin = r.vec3();
        m.boundsMax = r.vec3();
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
        for (std::uint32_t i = 0; i < textureCount; ++i)
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
