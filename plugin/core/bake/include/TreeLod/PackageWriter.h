// Writing *.treelod packages (format in TreeLod/Package.h), GPU-ready mip chains and their
// block compression, and the reference bake: TreeModel -> "reference" + "meta" chunks -> file.
#pragma once

#include "TreeLod/Crc32.h" // fnv1a64
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/TreeModel.h"

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace TreeLod
{
    /// Collects chunks and lays out a package. The output depends only on the chunks added
    /// (entries sorted by technique then level, payloads in table order, zero padding), never
    /// on the order of addChunk calls or the time.
    class PackageWriter
    {
    public:
        /// Add the chunk (technique, level), replacing one added before with the same key.
        /// Error if `technique` is empty, longer than 32 bytes or not printable ASCII.
        Result<void> addChunk(const std::string& technique, std::uint32_t level, std::uint32_t formatVersion,
                              std::vector<std::uint8_t> bytes);

        std::size_t chunkCount() const { return mChunks.size(); }
        bool hasChunk(const std::string& technique, std::uint32_t level) const
        {
            return mChunks.count({technique, level}) != 0;
        }
        /// The bytes of chunk (technique, level), or null if none was added.
        const std::vector<std::uint8_t>* chunkBytes(const std::string& technique, std::uint32_t level) const
        {
            const auto it = mChunks.find({technique, level});
            return it == mChunks.end() ? nullptr : &it->second.bytes;
        }

        /// The whole package.
        std::vector<std::uint8_t> toBytes() const;

        /// Write the package atomically (temp file beside `path`, then rename): on error
        /// nothing exists at `path` that was not there before.
        Result<void> write(const std::string& path) const;

    private:
        struct Payload
        {
            std::uint32_t formatVersion = 1;
            std::vector<std::uint8_t> bytes;
        };
        std::map<std::pair<std::string, std::uint32_t>, Payload> mChunks;
    };

    /// How buildMipChain filters.
    struct MipChainOptions
    {
        /// Keep the fraction of texels with alpha >= alphaCutoff the same in every level as in
        /// level 0, for alpha-tested leaves (Castaño, "Computing Alpha Mipmaps", 2010). Without
        /// it, thin leaf parts fade below the cutoff and distant foliage goes bald.
        bool preserveAlphaCoverage = true;
        float alphaCutoff = 0.5f; ///< the material's alpha test threshold, in (0, 1]
    };

    /// RGBA8 mip chain of `image` down to 1x1 (fullMipCount levels), level 0 an exact copy.
    /// Each level is a box filter of the one above (2x2 texels for even sizes, area-weighted
    /// 3 taps along an odd edge, so non-power-of-two sizes work): colour averaged in linear
    /// light and weighted by alpha (transparent texels lend no colour, so leaf edges do not
    /// darken), alpha averaged plainly. With preserveAlphaCoverage, each level's alpha is then
    /// scaled by cutoff / t, where t is the alpha whose coverage is closest to level 0's; the
    /// coverage then matches level 0 as closely as the level's alpha histogram allows.
    /// An empty image (0x0) gives a GpuTexture with mipCount 0 and no data.
    GpuTexture buildMipChain(const TextureImage& image, const MipChainOptions& options = {});

    /// `rgba8` (an RGBA8 GpuTexture, every mip level) block-compressed to `format` with libsquish,
    /// level by level: DXT1 and DXT5 with its cluster fit, BC4 from the R channel, BC5 from R and
    /// G. Block rows run in parallel; each block depends on its own texels only, so the bytes do
    /// not depend on the thread count. Decoding is the runtime's decodeGpuTexture (ModelChunk.h).
    GpuTexture compressTexture(const GpuTexture& rgba8, GpuTextureFormat format);

    /// The reference chunk of `model`: the model without its decoded textures plus a mip chain
    /// per texture, alpha-coverage preserving (with that material's cutoff) for the textures
    /// that a leaf material uses, plain box filtered for the others. Leaf materials that share a
    /// texture under different cutoffs get a chain each: the first cutoff keeps the texture's
    /// index, the others' chains are appended (named "<texture> at cutoff <c>") and those
    /// materials point at them, so every material's coverage is kept at its own cutoff.
    ReferenceChunk makeReferenceChunk(const TreeModel& model);


    /// What the "meta" chunk records, as one JSON object with sorted keys, e.g.
    /// {"generator":"treelod 0.1.0","options":{"leafMaterials":["Leaves"]},
    ///  "source":"oak.glb","sourceHash":"fnv1a64:0123456789abcdef","techniques":["reference"]}
    struct PackageMeta
    {
        std::string source;       ///< input file name without directories (so moving it changes nothing)
        std::string sourceHash;   ///< sourceHashOf(input) (BakeCache.h): "fnv1a64:" + 16 hex digits
        std::string optionsJson = "{}"; ///< bake options as a JSON object (stored as a string if not JSON)
        std::vector<std::string> techniques; ///< chunks the bake produced, besides "meta"

        std::string toJson() const;
    };

    /// Validate `model` and add its reference chunk (makeReferenceChunk, encodeReferenceChunk)
    /// to `writer`. `label` names the output in errors ("model 'oak', leaf 3: ...").
    Result<void> addReferenceChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                   const ProgressCallback& progress = {});
    /// addReferenceChunk unless `writer` has the reference chunk already: what every technique's
    /// package glue does first (the Forest takes a tree's bounds from the reference).
    Result<void> addReferenceChunkIfMissing(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                            const ProgressCallback& progress = {});

    /// Add chunk (technique, level 0, formatVersion) holding `encode(data)`; an error names `label`.
    template <typename Data>
    Result<void> addEncodedChunk(PackageWriter& writer, const std::string& technique, std::uint32_t formatVersion,
                                 std::vector<std::uint8_t> (*encode)(const Data&), const Data& data,
                                 const std::string& label)
    {
        Result<void> added = writer.addChunk(technique, 0, formatVersion, encode(data));
        if (!added)
            return fail(label, added.error().element, added.error().reason);
        return {};
    }

    /// What an add<X>Chunk does: the reference chunk unless `writer` has it, then `bake()` (a
    /// Result<Data>), then addEncodedChunk. The first error is returned; nothing is added after it.
    template <typename Data, typename Bake>
    Result<void> addBakedChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                               const ProgressCallback& progress, const std::string& technique,
                               std::uint32_t formatVersion, std::vector<std::uint8_t> (*encode)(const Data&), Bake bake)
    {
        if (Result<void> reference = addReferenceChunkIfMissing(writer, model, label, progress); !reference)
            return reference;
        Result<Data> data = bake();
        if (!data)
            return data.error();
        return addEncodedChunk(writer, technique, formatVersion, encode, data.value(), label);
    }

    /// Add the "meta" chunk (level 0, format 1): meta.toJson() as UTF-8 text.
    Result<void> addMetaChunk(PackageWriter& writer, const PackageMeta& meta);

    /// Bake the reference chunk of `model` and a meta chunk from `meta`, and write them to
    /// `path` atomically. Fails (writing nothing) if the model does not validate or the file
    /// cannot be written.
    Result<void> bakeReferencePackage(const TreeModel& model, const std::string& path, const PackageMeta& meta,
                                      const ProgressCallback& progress = {});

    /// Same, with meta.source = sourceDescription and no hash or options.
    Result<void> bakeReferencePackage(const TreeModel& model, const std::string& path,
                                      const std::string& sourceDescription);
}
