// The "reference" chunk of a *.treelod package (Package.h): the polygonal tree, every
// TreeModel field, with its textures stored GPU-ready (whole mip chains). A tree baked from
// photographs has a reference with no geometry, materials or textures: its bounds only
// (hasPolygons below).
//
// Layout, formatVersion 1 (REFERENCE_CHUNK_FORMAT_VERSION), little-endian. "string" is a
// u32 byte length + UTF-8 bytes (at most MODEL_CHUNK_MAX_STRING); "align16" is zero bytes up to the next
// multiple of 16 from the chunk start, so that bulk arrays and texel data are 16-byte
// aligned in the file (chunks start 16-aligned) and can be handed to the GPU as they are.
//
//   string name
//   u32 materialCount, per material:
//       string name, f32x4 baseColour, f32x3 backColour, i32 texture (-1 = none),
//       f32 alphaCutoff, u32 flags (bit 0 isLeaf, bit 1 doubleSided, others 0)
//   u32 textureCount, per texture (GpuTexture):
//       string name, u32 format (GpuTextureFormat), u32 width, u32 height, u32 mipCount,
//       u64 dataBytes, align16, dataBytes bytes of texel data
//   u32 barkVertexCount, align16, vertices of 32 bytes:
//       f32x3 position, f32x3 normal, f32x2 uv          (the layout of struct Vertex)
//   u32 barkIndexCount, align16, u32 indices
//   u32 barkTriangleMaterialCount, align16, u32 material per triangle
//   u32 leafVertexCount, align16, vertices (32 bytes, as above)
//   u32 leafIndexCount, align16, u32 indices
//   u32 leafCount, align16, leaves of 64 bytes:
//       u32 firstVertex, vertexCount, firstIndex, indexCount, material,
//       f32x3 centre, f32x3 normal, f32 area, f32x2 uvMin, f32x2 uvMax
//   u32 skeletonNodeCount, align16, nodes of 20 bytes: f32x3 position, f32 radius, i32 parent
//   f32x3 boundsMin, f32x3 boundsMax
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr std::uint32_t REFERENCE_CHUNK_FORMAT_VERSION = 1;

    /// Longest name (model, material, texture) a reference chunk may hold, in bytes.
    constexpr std::uint32_t MODEL_CHUNK_MAX_STRING = 65535;

    /// Largest texture edge a chunk may hold (the GL 3.3 guaranteed minimum of GPUs we target).
    constexpr std::uint32_t GPU_TEXTURE_MAX_SIZE = 16384;

    enum class GpuTextureFormat : std::uint32_t
    {
        RGBA8 = 1, ///< 4 bytes per texel, R G B A; colour sRGB-encoded, alpha straight (linear)
        DXT1 = 2,  ///< BC1, 8 bytes per 4x4 block (levels under 4 texels still take one block)
        DXT5 = 3,  ///< BC3, 16 bytes per 4x4 block
        BC4 = 4,   ///< one channel (R), 8 bytes per 4x4 block; sampled as (r, 0, 0, 1)
        BC5 = 5    ///< two channels (R, G), 16 bytes per 4x4 block; sampled as (r, g, 0, 1)
    };

    /// True for the 4x4 block formats (DXT1, DXT5, BC4, BC5).
    bool isBlockCompressed(GpuTextureFormat format);
    /// "RGBA8", "DXT1", "DXT5", "BC4", "BC5"; "format N" for a value outside the enum.
    std::string gpuTextureFormatName(GpuTextureFormat format);

    struct GpuTexture;
    /// `texture` decoded to RGBA8, every mip level, as a GPU samples it (Microsoft's BC1-BC5
    /// block formats; DXT5's colour block always in its four-colour mode; BC4 as (r, 0, 0, 255),
    /// BC5 as (r, g, 0, 255)). RGBA8 comes back as it is. The caller validates first
    /// (gpuTextureProblem): the texel bytes must be the size's.
    GpuTexture decodeGpuTexture(const GpuTexture& texture);

    /// A texture as the GPU takes it: every mip level, largest first.
    struct GpuTexture
    {
        std::string name;
        GpuTextureFormat format = GpuTextureFormat::RGBA8;
        std::uint32_t width = 0;   ///< of level 0, >= 1
        std::uint32_t height = 0;  ///< of level 0, >= 1
        std::uint32_t mipCount = 0; ///< 1 .. fullMipCount(width, height)
        /// All levels, largest first, tightly packed, rows top to bottom (glTF/PNG and Ogre
        /// Image order). Level i is max(1, width >> i) x max(1, height >> i).
        std::vector<std::uint8_t> data;

        std::uint32_t mipWidth(std::uint32_t level) const { return width >> level ? width >> level : 1; }
        std::uint32_t mipHeight(std::uint32_t level) const { return height >> level ? height >> level : 1; }
        /// Byte offset of `level` in data, and its byte size.
        std::uint64_t mipOffset(std::uint32_t level) const;
        std::uint64_t mipBytes(std::uint32_t level) const;
    };

    /// Levels of a full chain down to 1x1: floor(log2(max(width, height))) + 1 (0 for an empty image).
    std::uint32_t fullMipCount(std::uint32_t width, std::uint32_t height);

    /// Bytes of `mipCount` levels of a width x height texture in `format`.
    std::uint64_t gpuTextureBytes(GpuTextureFormat format, std::uint32_t width, std::uint32_t height,
                                  std::uint32_t mipCount);

    /// What is wrong with `tex` as a chunk's texture, "" when nothing: a format other than
    /// `formats` ("format 3 (RGBA8 or DXT1 needed)"), a size outside 1..GPU_TEXTURE_MAX_SIZE, a mip
    /// count outside 1..fullMipCount, texel bytes that are not the size's.
    std::string gpuTextureProblem(const GpuTexture& tex, std::initializer_list<GpuTextureFormat> formats);

    struct ReferenceChunk
    {
        /// The tree. encodeReferenceChunk ignores model.textures (it writes `textures` below);
        /// makeReferenceChunk leaves it empty.
        TreeModel model;
        /// GPU-ready textures, same indices as model.materials[i].texture.
        std::vector<GpuTexture> textures;
    };

    class ByteWriter;
    class ByteReader;
    /// A GpuTexture in the layout above (string name, u32 format, width, height, mipCount,
    /// u64 dataBytes, align16, data); every chunk that stores textures uses these two.
    void writeGpuTexture(ByteWriter& writer, const GpuTexture& texture);
    /// Reads and checks format, size, mip count and byte count; false with the reader's error
    /// set (element `element`, then "<element> '<name>'").
    bool readGpuTexture(ByteReader& reader, const std::string& element, GpuTexture& texture);

    /// Serialise `chunk` in the layout above. Deterministic: equal chunks give equal bytes.
    /// Does not check consistency; decodeReferenceChunk does.
    std::vector<std::uint8_t> encodeReferenceChunk(const ReferenceChunk& chunk);

    /// Whether `model` holds a triangle. A reference without one holds only its bounds: the tree
    /// was baked from photographs (`treelod bake CAPTURE_FOLDER`, VolumeOctreeBaker.h) and its
    /// bounds are the capture's volume box. The glTF importer refuses a model without triangles,
    /// so no polygonal tree reads as one.
    bool hasPolygons(const TreeModel& model);

    /// For consumers that need the polygons: an error naming `label` (the package) and the
    /// reference chunk when `model` has none, saying that the tree was baked from photographs and
    /// that `use` ("technique 'mesh'", "error curves", ...) needs a polygonal tree.
    Result<void> requirePolygons(const TreeModel& model, const std::string& label, const std::string& use);

    /// Parse and check a reference chunk: every count and range against the chunk size,
    /// texture formats, sizes and mip counts, material texture indices, skeleton parents,
    /// finite vertex attributes, then TreeModel::validate. `label` names the package in errors;
    /// elements are "chunk 'reference' level 0", "texture 2 'leaf'", "material 1 'Bark'", ...
    ///
    /// model.textures is refilled with a copy of mip level 0 of each texture (RGBA8), so the
    /// decoded model equals the one that was baked; callers that only upload `textures` may
    /// clear it.
    Result<ReferenceChunk> decodeReferenceChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
