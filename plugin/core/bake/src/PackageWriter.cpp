// This work is based on:
// - Castaño, "Computing Alpha Mipmaps", The Witness blog / NVIDIA Texture Tools, 2010:
//   rescale each mip level's alpha so the fraction of texels passing the alpha test stays
//   that of the full-resolution texture.
#include "TreeLod/PackageWriter.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/ByteWriter.h"
#include "TreeLod/Crc32.h"
#include "TreeLod/Image.h"
#include "TreeLod/Package.h"

#include <nlohmann/json.hpp>
#include <squish.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace TreeLod
{
    namespace
    {
        std::uint64_t alignUp(std::uint64_t v) { return (v + PACKAGE_ALIGNMENT - 1) / PACKAGE_ALIGNMENT * PACKAGE_ALIGNMENT; }

        /// A mip level in float: linear RGB (not premultiplied) and alpha, row-major.
        struct Level
        {
            std::uint32_t width = 0, height = 0;
            std::vector<glm::vec4> texels;
        };

        /// Source texels and weights (summing to 1) under destination texel `d` when `srcSize`
        /// texels are box-filtered to `dstSize`: the source interval [d*s/D, (d+1)*s/D).
        struct Taps
        {
            std::array<std::uint32_t, 3> index{};
            std::array<float, 3> weight{};
            int count = 0;
        };

        std::vector<Taps> boxTaps(std::uint32_t srcSize, std::uint32_t dstSize)
        {
            std::vector<Taps> taps(dstSize);
            for (std::uint32_t d = 0; d < dstSize; ++d)
            {
                const double a = double(d) * srcSize / dstSize, b = double(d + 1) * srcSize / dstSize;
                Taps& t = taps[d];
                for (std::uint32_t s = std::uint32_t(a); s < srcSize && double(s) < b && t.count < 3; ++s)
                {
                    const double overlap = std::min(b, double(s + 1)) - std::max(a, double(s));
                    if (overlap <= 0.0)
                        continue;
                    t.index[t.count] = s;
                    t.weight[t.count] = float(overlap / (b - a));
                    ++t.count;
                }
            }
            return taps;
        }

        /// Next smaller level: colour weighted by alpha (averaged plainly where all alpha is 0).
        Level downsample(const Level& src)
        {
            Level dst;
            dst.width = std::max(1u, src.width / 2);
            dst.height = std::max(1u, src.height / 2);
            dst.texels.resize(std::size_t(dst.width) * dst.height);
            const std::vector<Taps> tx = boxTaps(src.width, dst.width), ty = boxTaps(src.height, dst.height);
            for (std::uint32_t y = 0; y < dst.height; ++y)
                for (std::uint32_t x = 0; x < dst.width; ++x)
                {
                    glm::vec3 premultiplied(0.0f), plain(0.0f);
                    float alpha = 0.0f;
                    for (int j = 0; j < ty[y].count; ++j)
                        for (int i = 0; i < tx[x].count; ++i)
                        {
                            const float w = ty[y].weight[j] * tx[x].weight[i];
                            const glm::vec4& s = src.texels[std::size_t(ty[y].index[j]) * src.width + tx[x].index[i]];
                            premultiplied += w * s.a * glm::vec3(s);
                            plain += w * glm::vec3(s);
                            alpha += w * s.a;
                        }
                    const glm::vec3 colour = alpha > 0.0f ? premultiplied / alpha : plain;
                    dst.texels[std::size_t(y) * dst.width + x] = glm::vec4(colour, alpha);
                }
            return dst;
        }

        /// Smallest 8-bit alpha that passes `alpha >= cutoff` in a shader reading a / 255.
        std::uint32_t cutoffByte(float cutoff)
        {
            std::uint32_t k = std::uint32_t(std::ceil(double(cutoff) * 255.0 - 1e-6));
            return std::clamp(k, 1u, 255u);
        }

        /// Castaño 2010: choose the alpha threshold t whose coverage in this level is closest
        /// to `target` texels, then map alpha a -> a * K / t (K = cutoff byte) so that exactly
        /// the texels with a >= t pass. Ties go to the t nearest K (the smallest change).
        void preserveCoverage(std::uint8_t* rgba, std::size_t texelCount, double target, std::uint32_t K)
        {
            std::array<std::size_t, 257> atLeast{}; // atLeast[t] = texels with alpha >= t
            for (std::size_t i = 0; i < texelCount; ++i)
                ++atLeast[rgba[4 * i + 3]];
            for (int t = 255; t >= 0; --t)
                atLeast[t] += atLeast[t + 1];
            std::uint32_t best = K;
            double bestError = std::abs(double(atLeast[K]) - target);
            for (std::uint32_t t = 0; t <= 256; ++t)
            {
                const double error = std::abs(double(atLeast[t]) - target);
                const auto distance = [&](std::uint32_t v) { return v > K ? v - K : K - v; };
                if (error < bestError || (error == bestError && distance(t) < distance(best)))
                {
                    best = t;
                    bestError = error;
                }
            }
            if (best == K)
                return;
            for (std::size_t i = 0; i < texelCount; ++i)
            {
                const std::uint32_t a = rgba[4 * i + 3];
                std::uint32_t scaled = best == 0 ? std::max(a, K) : std::uint32_t(std::lround(double(a) * K / best));
                scaled = a >= best ? std::clamp(scaled, K, 255u) : std::min(scaled, K - 1);
                rgba[4 * i + 3] = std::uint8_t(scaled);
            }
        }

        bool printableTechnique(const std::string& technique)
        {
            if (technique.empty() || technique.size() > PACKAGE_MAX_TECHNIQUE_NAME)
                return false;
            for (char c : technique)
                if (std::uint8_t(c) < 0x20 || std::uint8_t(c) >= 0x7f)
                    return false;
            return true;
        }
    }

    // ---- PackageWriter ------------------------------------------------------------------

    Result<void> PackageWriter::addChunk(const std::string& technique, std::uint32_t level,
                                         std::uint32_t formatVersion, std::vector<std::uint8_t> bytes)
    {
        if (!printableTechnique(technique))
            return fail("", chunkElement(technique, level),
                        "technique name must be 1 to 32 printable ASCII characters");
        mChunks[{technique, level}] = Payload{formatVersion, std::move(bytes)};
        return {};
    }

    std::vector<std::uint8_t> PackageWriter::toBytes() const
    {
        const std::uint64_t tableOffset = PACKAGE_HEADER_SIZE;
        const std::uint64_t tableSize = mChunks.size() * PACKAGE_TABLE_ENTRY_SIZE;

        ByteWriter table;
        std::uint64_t cursor = alignUp(tableOffset + tableSize);
        std::uint64_t fileSize = tableOffset + tableSize;
        for (const auto& [key, payload] : mChunks)
        {
            char name[PACKAGE_MAX_TECHNIQUE_NAME] = {};
            std::copy(key.first.begin(), key.first.end(), name);
            table.bytes(name, sizeof(name));
            table.u32(key.second);
            table.u32(payload.formatVersion);
            table.u64(cursor);
            table.u64(payload.bytes.size());
            table.u32(crc32(payload.bytes.data(), payload.bytes.size()));
            table.u32(0);
            fileSize = cursor + payload.bytes.size();
            cursor = alignUp(fileSize);
        }

        ByteWriter out;
        out.reserve(fileSize);
        out.bytes(PACKAGE_MAGIC, 4);
        out.u32(PACKAGE_VERSION);
        out.u32(std::uint32_t(mChunks.size()));
        out.u32(0); // flags
        out.u64(tableOffset);
        out.u32(crc32(table.data().data(), table.size()));
        out.u32(crc32(out.data().data(), out.size()));
        out.bytes(table.data().data(), table.size());
        for (const auto& entry : mChunks)
        {
            out.align(PACKAGE_ALIGNMENT);
            out.bytes(entry.second.bytes.data(), entry.second.bytes.size());
        }
        return out.take();
    }

    Result<void> PackageWriter::write(const std::string& path) const { return writeFileAtomic(path, toBytes()); }

    // ---- mip chains ---------------------------------------------------------------------

    GpuTexture buildMipChain(const TextureImage& image, const MipChainOptions& options)
    {
        GpuTexture tex;
        tex.name = image.name;
        tex.format = GpuTextureFormat::RGBA8;
        if (image.width <= 0 || image.height <= 0 ||
            image.rgba.size() != std::size_t(image.width) * std::size_t(image.height) * 4)
            return tex;
        tex.width = std::uint32_t(image.width);
        tex.height = std::uint32_t(image.height);
        tex.mipCount = fullMipCount(tex.width, tex.height);
        tex.data.resize(gpuTextureBytes(tex.format, tex.width, tex.height, tex.mipCount));
        std::copy(image.rgba.begin(), image.rgba.end(), tex.data.begin());

        Level level;
        level.width = tex.width;
        level.height = tex.height;
        level.texels.resize(std::size_t(tex.width) * tex.height);
        std::size_t covered = 0;
        const std::uint32_t K = cutoffByte(options.alphaCutoff);
        for (std::size_t i = 0; i < level.texels.size(); ++i)
        {
            const std::uint8_t* p = &image.rgba[4 * i];
            level.texels[i] = glm::vec4(srgbByteToLinear(p[0]), srgbByteToLinear(p[1]), srgbByteToLinear(p[2]),
                                        byteToUnit(p[3]));
            covered += p[3] >= K ? 1 : 0;
        }
        const double coverage = double(covered) / double(level.texels.size());
        const bool preserve = options.preserveAlphaCoverage && options.alphaCutoff > 0.0f && options.alphaCutoff <= 1.0f;

        for (std::uint32_t mip = 1; mip < tex.mipCount; ++mip)
        {
            level = downsample(level);
            std::uint8_t* out = tex.data.data() + tex.mipOffset(mip);
            for (std::size_t i = 0; i < level.texels.size(); ++i)
            {
                const glm::vec4& t = level.texels[i];
                out[4 * i + 0] = linearToSrgbByte(t.r);
                out[4 * i + 1] = linearToSrgbByte(t.g);
                out[4 * i + 2] = linearToSrgbByte(t.b);
                out[4 * i + 3] = unitToByte(t.a);
            }
            if (preserve)
                preserveCoverage(out, level.texels.size(), coverage * double(level.texels.size()), K);
        }
        return tex;
    }

    GpuTexture compressTexture(const GpuTexture& src, GpuTextureFormat format)
    {
        GpuTexture out;
        out.name = src.name;
        out.format = format;
        out.width = src.width;
        out.height = src.height;
        out.mipCount = src.mipCount;
        out.data.resize(gpuTextureBytes(format, src.width, src.height, src.mipCount));
        int flags = squish::kDxt1 | squish::kColourClusterFit;
        if (format == GpuTextureFormat::DXT5)
            flags = squish::kDxt5 | squish::kColourClusterFit;
        else if (format == GpuTextureFormat::BC4)
            flags = squish::kBc4;
        else if (format == GpuTextureFormat::BC5)
            flags = squish::kBc5;
        const std::size_t blockBytes = format == GpuTextureFormat::DXT1 || format == GpuTextureFormat::BC4 ? 8 : 16;
        for (std::uint32_t mip = 0; mip < src.mipCount; ++mip)
        {
            const std::uint32_t w = src.mipWidth(mip), h = src.mipHeight(mip);
            const std::uint8_t* in = src.data.data() + src.mipOffset(mip);
            std::uint8_t* blocks = out.data.data() + out.mipOffset(mip);
            const std::size_t rowBytes = std::size_t((w + 3) / 4) * blockBytes;
            tbb::parallel_for(std::uint32_t(0), (h + 3) / 4, [&](std::uint32_t r) {
                const std::uint32_t rows = std::min(4u, h - 4 * r);
                squish::CompressImage(in + std::size_t(4 * r) * w * 4, int(w), int(rows), blocks + r * rowBytes,
                                      flags);
            });
        }
        return out;
    }

    ReferenceChunk makeReferenceChunk(const TreeModel& model)
    {
        ReferenceChunk chunk;
        chunk.model = model;
        chunk.model.textures.clear();
        chunk.textures.reserve(model.textures.size());
        std::vector<std::pair<std::size_t, std::size_t>> extra; // (material, texture) of further cutoffs
        for (std::size_t t = 0; t < model.textures.size(); ++t)
        {
            MipChainOptions options;
            options.preserveAlphaCoverage = false;
            std::vector<std::pair<float, std::int32_t>> cutoffs; // cutoff -> chunk texture
            for (std::size_t m = 0; m < model.materials.size(); ++m)
            {
                const Material& material = model.materials[m];
                if (!material.isLeaf || material.texture != std::int32_t(t))
                    continue;
                const auto same = std::find_if(cutoffs.begin(), cutoffs.end(),
                                               [&](const auto& c) { return c.first == material.alphaCutoff; });
                if (same != cutoffs.end())
                    chunk.model.materials[m].texture = same->second;
                else if (cutoffs.empty())
                {
                    options.preserveAlphaCoverage = true;
                    options.alphaCutoff = material.alphaCutoff;
                    cutoffs.emplace_back(material.alphaCutoff, std::int32_t(t));
                }
                else
                {
                    const std::int32_t index = std::int32_t(model.textures.size() + extra.size());
                    cutoffs.emplace_back(material.alphaCutoff, index);
                    chunk.model.materials[m].texture = index;
                    extra.emplace_back(m, t);
                }
            }
            chunk.textures.push_back(buildMipChain(model.textures[t], options));
        }
        for (const auto& [m, t] : extra)
        {
            MipChainOptions options;
            options.alphaCutoff = model.materials[m].alphaCutoff;
            GpuTexture chain = buildMipChain(model.textures[t], options);
            char cutoff[32];
            std::snprintf(cutoff, sizeof cutoff, "%g", double(options.alphaCutoff));
            chain.name = chunk.textures[t].name + " at cutoff " + cutoff;
            chunk.textures.push_back(std::move(chain));
        }
        return chunk;
    }

    // ---- meta and bake --------------------------------------------------------------------


    std::string PackageMeta::toJson() const
    {
        nlohmann::json j;
        j["generator"] = "treelod";
        j["source"] = source;
        j["sourceHash"] = sourceHash;
        nlohmann::json options = nlohmann::json::parse(optionsJson, nullptr, false);
        j["options"] = options.is_discarded() ? nlohmann::json(optionsJson) : options;
        j["techniques"] = techniques;
        return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    }

    Result<void> addReferenceChunkIfMissing(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                            const ProgressCallback& progress)
    {
        if (writer.hasChunk(REFERENCE_CHUNK, 0))
            return {};
        return addReferenceChunk(writer, model, label, progress);
    }

    Result<void> addReferenceChunk(PackageWriter& writer, const TreeModel& model, const std::string& label,
                                   const ProgressCallback& progress)
    {
        Result<void> valid = model.validate(label);
        if (!valid)
            return fail(label, "model '" + model.name + "', " + valid.error().element, valid.error().reason);
        // What decodeReferenceChunk would refuse is refused here, before anything is written.
        const auto tooLong = [](const std::string& s) { return s.size() > MODEL_CHUNK_MAX_STRING; };
        const std::string tooLongReason = "name longer than " + std::to_string(MODEL_CHUNK_MAX_STRING) + " bytes";
        if (tooLong(model.name))
            return fail(label, "model", tooLongReason);
        for (std::size_t m = 0; m < model.materials.size(); ++m)
            if (tooLong(model.materials[m].name))
                return fail(label, "material " + std::to_string(m), tooLongReason);
        for (std::size_t t = 0; t < model.textures.size(); ++t)
        {
            const TextureImage& image = model.textures[t];
            const std::string element = "texture " + std::to_string(t) + " '" + image.name + "'";
            if (tooLong(image.name))
                return fail(label, "texture " + std::to_string(t), tooLongReason);
            if (image.width <= 0 || image.height <= 0)
                return fail(label, element, "empty image cannot be stored");
            if (image.width > int(GPU_TEXTURE_MAX_SIZE) || image.height > int(GPU_TEXTURE_MAX_SIZE))
                return fail(label, element,
                            std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " is larger than the " + std::to_string(GPU_TEXTURE_MAX_SIZE) + " texels a GPU texture may have");
        }

        report(progress, "mip chains", 0.0f);
        const ReferenceChunk chunk = makeReferenceChunk(model);
        report(progress, "mip chains", 1.0f);
        report(progress, "encode", 0.0f);
        Result<void> added = writer.addChunk(REFERENCE_CHUNK, 0, REFERENCE_CHUNK_FORMAT_VERSION, encodeReferenceChunk(chunk));
        report(progress, "encode", 1.0f);
        return added;
    }

    Result<void> addMetaChunk(PackageWriter& writer, const PackageMeta& meta)
    {
        const std::string text = meta.toJson();
        return writer.addChunk(META_CHUNK, 0, 1, std::vector<std::uint8_t>(text.begin(), text.end()));
    }

    Result<void> bakeReferencePackage(const TreeModel& model, const std::string& path, const PackageMeta& meta,
                                      const ProgressCallback& progress)
    {
        PackageWriter writer;
        Result<void> added = addReferenceChunk(writer, model, path, progress);
        if (!added)
            return added;
        PackageMeta withTechniques = meta;
        if (std::find(withTechniques.techniques.begin(), withTechniques.techniques.end(), REFERENCE_CHUNK) ==
            withTechniques.techniques.end())
            withTechniques.techniques.push_back(REFERENCE_CHUNK);
        added = addMetaChunk(writer, withTechniques);
        if (!added)
            return fail(path, added.error().element, added.error().reason);

        report(progress, "write", 0.0f);
        Result<void> written = writer.write(path);
        report(progress, "write", 1.0f);
        return written;
    }

    Result<void> bakeReferencePackage(const TreeModel& model, const std::string& path,
                                      const std::string& sourceDescription)
    {
        PackageMeta meta;
        meta.source = sourceDescription;
        return bakeReferencePackage(model, path, meta);
    }
}
