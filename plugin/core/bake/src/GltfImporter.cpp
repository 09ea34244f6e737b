// glTF 2.0 import. Parsing is tinygltf's (Debian's shared library); everything it does not
// check is checked here before use: every index into accessors, buffer views and buffers,
// every byte range, the .glb chunk layout, and JSON nesting. tinygltf reads files only through
// the FsCallbacks below and decodes no image: its image callback keeps the encoded bytes, and
// libpng and libjpeg-turbo decode the images that materials use (ImageCodec.h; palette PNGs keep
// tRNS alpha).
#include "TreeLod/GltfImporter.h"

#include "TreeLod/LeafExtraction.h"

#include "TreeLod/ImageCodec.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t kMaxJsonDepth = 128;
        constexpr int kMaxImageSide = 16384;
        constexpr std::uint64_t kMaxImagePixels = std::uint64_t(1) << 26; // 64 Mpixel = 256 MB RGBA8
        constexpr double kLargeModelMetres = 1000.0;

        std::string inQuotes(const std::string& s) { return "'" + s + "'"; }

        std::string fmt(double v)
        {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%g", v);
            return buf;
        }

        std::uint32_t readU32(const std::uint8_t* p)
        {
            return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
        }

        // ---- file access for tinygltf: only below baseDir, never written, no shell expansion

        struct FsContext
        {
            std::string baseDir; ///< empty: no file may be read
        };

        bool underBaseDir(const std::string& path, const FsContext& ctx)
        {
            if (ctx.baseDir.empty())
                return false;
            std::string prefix = ctx.baseDir.back() == '/' ? ctx.baseDir : ctx.baseDir + "/";
            return path.compare(0, prefix.size(), prefix) == 0;
        }

        bool fsFileExists(const std::string& path, void* user)
        {
            const FsContext& ctx = *static_cast<const FsContext*>(user);
            std::error_code ec;
            return underBaseDir(path, ctx) && std::filesystem::is_regular_file(path, ec);
        }

        std::string fsExpandFilePath(const std::string& path, void*) { return path; }

        bool readWholeFile(const std::string& path, std::vector<unsigned char>& out, std::string& reason)
        {
            std::error_code ec;
            if (!std::filesystem::exists(path, ec))
            {
                reason = "file does not exist";
                return false;
            }
            if (std::filesystem::is_directory(path, ec))
            {
                reason = "is a directory, not a file";
                return false;
            }
            std::FILE* f = std::fopen(path.c_str(), "rb");
            if (!f)
            {
                reason = std::string("cannot open: ") + std::strerror(errno);
                return false;
            }
            std::uintmax_t size = std::filesystem::file_size(path, ec);
            if (ec)
                size = 0;
            out.resize(std::size_t(size));
            std::size_t got = size ? std::fread(out.data(), 1, out.size(), f) : 0;
            bool bad = got != out.size() || std::ferror(f);
            std::fclose(f);
            if (bad)
            {
                reason = "read error";
                return false;
            }
            return true;
        }

        bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user)
        {
            const FsContext& ctx = *static_cast<const FsContext*>(user);
            std::string reason;
            if (!underBaseDir(path, ctx))
                reason = "outside the base directory";
            else if (readWholeFile(path, *out, reason))
                return true;
            if (err)
                *err += reason;
            return false;
        }

        bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*)
        {
            if (err)
                *err += "the importer writes no file";
            return false;
        }

        /// tinygltf image callback: keep the encoded bytes of URI images; bufferView images are
        /// read later with their ranges checked (tinygltf does not check them).
        bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                              const unsigned char* bytes, int size, void*)
        {
            if (image->bufferView < 0 && bytes && size > 0)
                image->image.assign(bytes, bytes + size);
            return true;
        }

        /// Deepest nesting of JSON arrays/objects (tinygltf converts extras recursively).
        std::size_t jsonDepth(const char* s, std::size_t n)
        {
            std::size_t depth = 0, deepest = 0;
            bool inString = false;
            for (std::size_t i = 0; i < n; ++i)
            {
                char c = s[i];
                if (inString)
                {
                    if (c == '\\')
                        ++i;
                    else if (c == '"')
                        inString = false;
                }
                else if (c == '"')
                    inString = true;
                else if (c == '{' || c == '[')
                    deepest = std::max(deepest, ++depth);
                else if ((c == '}' || c == ']') && depth > 0)
                    --depth;
            }
            return deepest;
        }

        std::string oneLine(std::string s)
        {
            while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
                s.pop_back();
            for (char& c : s)
                if (c == '\n')
                    c = ';';
            return s;
        }

        /// Check the .glb layout (header, JSON chunk, optional BIN chunk) strictly enough that
        /// tinygltf never reads past the data. Returns the GLB's declared length.
        Result<std::uint32_t> checkGlb(const std::uint8_t* d, std::size_t n, const std::string& file)
        {
            if (n < 12)
                return fail(file, "glb header",
                            "truncated .glb: " + std::to_string(n) + " bytes, the header alone needs 12");
            std::uint32_t version = readU32(d + 4);
            std::uint32_t length = readU32(d + 8);
            if (version != 2)
                return fail(file, "glb header", "version " + std::to_string(version) + ", only glTF 2 is supported");
            if (length > n)
                return fail(file, "glb header", "truncated .glb: the header says " + std::to_string(length) +
                                                    " bytes, the data has " + std::to_string(n));
            if (length < 20)
                return fail(file, "glb header", "length " + std::to_string(length) + " leaves no room for the JSON chunk");
            std::uint32_t jsonLength = readU32(d + 12);
            if (readU32(d + 16) != 0x4E4F534Au)
                return fail(file, "glb chunk 0", "the first chunk is not JSON");
            if (jsonLength == 0 || jsonLength > length - 20)
                return fail(file, "glb chunk 0 (JSON)", "truncated: the chunk says " + std::to_string(jsonLength) +
                                                            " bytes, " + std::to_string(length - 20) + " remain");
            std::uint64_t binStart = 20ull + jsonLength;
            if (binStart < length)
            {
                if (binStart + 8 > length)
                    return fail(file, "glb chunk 1", "truncated chunk header");
                std::uint32_t binLength = readU32(d + binStart);
                if (readU32(d + binStart + 4) != 0x004E4942u)
                    return fail(file, "glb chunk 1", "the second chunk is not BIN");
                if (binStart + 8 + binLength > length)
                    return fail(file, "glb chunk 1 (BIN)", "truncated: the chunk says " + std::to_string(binLength) +
                                                               " bytes, " + std::to_string(length - binStart - 8) + " remain");
                if (binLength < 4 || binLength % 4 != 0)
                    return fail(file, "glb chunk 1 (BIN)", "length " + std::to_string(binLength) +
                                                               " is not a positive multiple of 4");
            }
            if (jsonDepth(reinterpret_cast<const char*>(d + 20), jsonLength) > kMaxJsonDepth)
                return fail(file, "glb chunk 0 (JSON)", "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
            return length;
        }

        // ---- accessors -------------------------------------------------------------------

        struct AccessorView
        {
            const std::uint8_t* data = nullptr; ///< first element
            std::size_t count = 0;
            std::size_t stride = 0;
            int componentType = 0;
            int components = 0;
            bool normalized = false;
        };

        const char* typeName(int type)
        {
            switch (type)
            {
            case TINYGLTF_TYPE_SCALAR: return "SCALAR";
            case TINYGLTF_TYPE_VEC2: return "VEC2";
            case TINYGLTF_TYPE_VEC3: return "VEC3";
            case TINYGLTF_TYPE_VEC4: return "VEC4";
            case TINYGLTF_TYPE_MAT2: return "MAT2";
            case TINYGLTF_TYPE_MAT3: return "MAT3";
            case TINYGLTF_TYPE_MAT4: return "MAT4";
            default: return "unknown";
            }
        }

        /// double -> float without undefined behaviour: out-of-range values become +-inf.
        float narrow(double d)
        {
            if (d > double(std::numeric_limits<float>::max()))
                return std::numeric_limits<float>::infinity();
            if (d < -double(std::numeric_limits<float>::max()))
                return -std::numeric_limits<float>::infinity();
            return float(d);
        }

        glm::vec3 narrow(const glm::dvec3& v) { return glm::vec3(narrow(v.x), narrow(v.y), narrow(v.z)); }

        float readComponent(const std::uint8_t* p, int componentType, bool normalized)
        {
            switch (componentType)
            {
            case TINYGLTF_COMPONENT_TYPE_FLOAT:
            {
                float v;
                std::memcpy(&v, p, 4);
                return v;
            }
            case TINYGLTF_COMPONENT_TYPE_BYTE:
            {
                std::int8_t v;
                std::memcpy(&v, p, 1);
                return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(p[0]) / 255.0f : float(p[0]);
            case TINYGLTF_COMPONENT_TYPE_SHORT:
            {
                std::int16_t v;
                std::memcpy(&v, p, 2);
                return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            {
                std::uint16_t v;
                std::memcpy(&v, p, 2);
                return normalized ? float(v) / 65535.0f : float(v);
            }
            case TINYGLTF_COMPONENT_TYPE_INT:
            {
                std::int32_t v;
                std::memcpy(&v, p, 4);
                return float(v);
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            {
                std::uint32_t v;
                std::memcpy(&v, p, 4);
                return normalized ? float(double(v) / 4294967295.0) : float(v);
            }
            case TINYGLTF_COMPONENT_TYPE_DOUBLE:
            {
                double v;
                std::memcpy(&v, p, 8);
                return narrow(v);
            }
            default: return 0.0f;
            }
        }

        void readVec(const AccessorView& v, std::size_t i, float* out)
        {
            const std::uint8_t* p = v.data + i * v.stride;
            if (v.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
            {
                std::memcpy(out, p, 4 * std::size_t(v.components));
                return;
            }
            const std::size_t size = std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(v.componentType)));
            for (int c = 0; c < v.components; ++c)
                out[c] = readComponent(p + c * size, v.componentType, v.normalized);
        }

        std::uint32_t readIndex(const AccessorView& v, std::size_t i)
        {
            const std::uint8_t* p = v.data + i * v.stride;
            switch (v.componentType)
            {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            {
                std::uint16_t x;
                std::memcpy(&x, p, 2);
                return x;
            }
            default:
            {
                std::uint32_t x;
                std::memcpy(&x, p, 4);
                return x;
            }
            }
        }

        bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        std::string vecText(const glm::vec3& v) { return "(" + fmt(v.x) + ", " + fmt(v.y) + ", " + fmt(v.z) + ")"; }

        // ---- images ------------------------------------------------------------------------

        std::uint32_t readU32BE(const std::uint8_t* p)
        {
            return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | std::uint32_t(p[3]);
        }

        /// Walk the PNG chunks (after the signature) up to IEND: a PNG that ends early is refused
        /// naming the chunk, a clearer message than the decoder's.
        Result<void> checkPngChunks(const std::uint8_t* data, std::size_t size, const std::string& file,
                                    const std::string& where)
        {
            std::size_t pos = 8;
            for (int index = 0;; ++index)
            {
                if (size - pos < 12)
                    return fail(file, where, "truncated PNG: chunk " + std::to_string(index) + " header at byte " +
                                                 std::to_string(pos) + " runs past the end (" + std::to_string(size) +
                                                 " bytes)");
                const std::uint32_t length = readU32BE(data + pos);
                const std::string type(reinterpret_cast<const char*>(data + pos + 4), 4);
                if (length > 0x7fffffffu || length > size - pos - 12)
                    return fail(file, where, "truncated PNG: chunk " + std::to_string(index) + " of " +
                                                 std::to_string(length) + " bytes runs past the end");
                pos += 12 + std::size_t(length);
                if (type == "IEND")
                    return {};
            }
        }

        /// Width and height an image's header declares, read without decoding: the PNG's IHDR
        /// (its first chunk), or a JPEG's first start-of-frame marker (SOF0..SOF15; C4, C8 and CC
        /// are other markers). False when the header does not say; the decoder then reports why.
        bool declaredSize(const std::uint8_t* data, std::size_t size, bool png, std::uint64_t& width,
                          std::uint64_t& height)
        {
            if (png)
            {
                if (size < 24 || std::memcmp(data + 12, "IHDR", 4) != 0)
                    return false;
                width = readU32BE(data + 16);
                height = readU32BE(data + 20);
                return true;
            }
            auto u16 = [&](std::size_t at) { return std::uint64_t(data[at]) << 8 | data[at + 1]; };
            std::size_t pos = 2; // after SOI
            while (pos + 4 <= size && data[pos] == 0xFF)
            {
                const std::uint8_t marker = data[pos + 1];
                if (marker == 0xFF) // fill byte
                    ++pos;
                else if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8)) // no length field
                    pos += 2;
                else if (marker == 0xD9 || marker == 0xDA) // end of image or a scan: no frame before
                    return false;
                else if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
                {
                    if (pos + 9 > size) // length, precision, height, width
                        return false;
                    height = u16(pos + 5);
                    width = u16(pos + 7);
                    return true;
                }
                else
                {
                    const std::size_t length = std::size_t(u16(pos + 2));
                    if (length < 2)
                        return false;
                    pos += 2 + length;
                }
            }
            return false;
        }

        bool beyondSizeLimit(std::uint64_t width, std::uint64_t height)
        {
            return width > std::uint64_t(kMaxImageSide) || height > std::uint64_t(kMaxImageSide) ||
                   width * height > kMaxImagePixels;
        }

        std::string sizeLimit()
        {
            return "the limit (" + std::to_string(kMaxImageSide) + " per side, 64 Mpixel)";
        }

        /// Decode PNG or JPEG bytes to RGBA8 (straight alpha; grey and RGB get alpha 255).
        Result<TextureImage> decodeTexture(const std::uint8_t* data, std::size_t size, const std::string& file,
                                           const std::string& where)
        {
            const ImageFormat format = sniffImageFormat(data, size);
            if (format == ImageFormat::Unknown)
                return fail(file, where, "unsupported image format (not PNG or JPEG)");
            const bool png = format == ImageFormat::Png;
            if (png)
                if (auto r = checkPngChunks(data, size, file, where); !r)
                    return r.error();

            // The size the header claims is checked before the decoder sees the bytes: opening a
            // progressive JPEG that claims 65500 x 65500 has libjpeg allocate 1 GB for its frame.
            std::uint64_t declaredWidth = 0, declaredHeight = 0;
            if (declaredSize(data, size, png, declaredWidth, declaredHeight) &&
                beyondSizeLimit(declaredWidth, declaredHeight))
                return fail(file, where, std::string(png ? "PNG" : "JPEG") + " header declares " +
                                             std::to_string(declaredWidth) + "x" + std::to_string(declaredHeight) +
                                             " pixels, larger than " + sizeLimit() + "; not decoded");

            Result<DecodedImage> decoded = decodeImage(data, size, std::uint32_t(kMaxImageSide), kMaxImagePixels);
            if (!decoded)
                return fail(file, where, oneLine(decoded.error().reason));
            const DecodedImage& image = *decoded;
            TextureImage out;
            out.width = image.width;
            out.height = image.height;
            out.rgba.resize(std::size_t(image.width) * std::size_t(image.height) * 4);
            const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
            const std::size_t channels = std::size_t(image.channels);
            for (std::size_t i = 0; i < n; ++i)
            {
                const std::size_t s = i * channels;
                std::uint8_t* o = &out.rgba[i * 4];
                const bool grey = channels < 3;
                o[0] = image.byte(s);
                o[1] = image.byte(grey ? s : s + 1);
                o[2] = image.byte(grey ? s : s + 2);
                o[3] = channels == 2 || channels == 4 ? image.byte(s + channels - 1) : 255;
            }
            return out;
        }

        // ---- the reader ----------------------------------------------------------------------

        class GltfReader
        {
        public:
            GltfReader(const tinygltf::Model& gltf, const std::string& file, const std::string& baseDir,
                       const ImportOptions& options, ImportReport& report)
                : mGltf(gltf), mFile(file), mBaseDir(baseDir), mOptions(options), mReport(report)
            {
            }

            Result<TreeModel> read(const std::string& name);

        private:
            Result<void> readMaterials();
            Result<std::int32_t> textureOfImage(int image);
            Result<void> readScene();
            Result<void> readMesh(int node, int mesh, const glm::dmat4& world);
            Result<void> readPrimitive(int meshIndex, int primitiveIndex, const glm::dmat4& world, int node);
            Result<void> readSkeleton(int meshIndex, const glm::dmat4& world);
            Result<AccessorView> viewAccessor(int accessor, const std::string& where, const char* role);
            std::uint32_t materialFor(int gltfMaterial);

            std::string meshName(int mesh) const
            {
                return "mesh " + std::to_string(mesh) + " " + inQuotes(mGltf.meshes[std::size_t(mesh)].name);
            }
            void warn(const std::string& text) { mReport.warnings.push_back(text); }

            const tinygltf::Model& mGltf;
            std::string mFile;
            std::string mBaseDir;
            const ImportOptions& mOptions;
            ImportReport& mReport;

            TreeModel mModel;
            detail::LeafSoup mLeafSoup;
            std::vector<std::int32_t> mTextureOfImage; ///< per glTF image, -1 = not decoded yet
            std::int32_t mDefaultMaterial = -1;
            std::vector<char> mWarnedPrimitive; ///< per mesh: a skipped-primitive warning was given
        };

        Result<TreeModel> GltfReader::read(const std::string& name)
        {
            const tinygltf::Asset& asset = mGltf.asset;
            if (!asset.version.empty() && asset.version[0] != '2')
                return fail(mFile, "asset", "glTF version " + asset.version + ", only 2.x is supported");
            for (const std::string& ext : mGltf.extensionsRequired)
                if (ext != "KHR_mesh_quantization") // the accessor reader handles any component type
                    return fail(mFile, "extensionsRequired", "extension " + ext + " is required but not supported");

            mModel.name = name;
            if (auto r = readMaterials(); !r)
                return r.error();
            report(mOptions.progress, "images", 1.0f);
            if (auto r = readScene(); !r)
                return r.error();

            const std::size_t barkTriangles = mModel.barkTriangleCount();
            const std::size_t leafTriangles = mLeafSoup.indices.size() / 3;
            if (barkTriangles + leafTriangles == 0)
                return fail(mFile, "scene", "no triangles: the scene has no triangle primitives");

            detail::LeafExtractionStats stats = detail::extractLeaves(mLeafSoup, mModel, mOptions.progress);
            mLeafSoup = {};
            mReport.droppedDegenerateLeaves += stats.degenerate;
            mReport.duplicateLeaves += stats.duplicates;
            if (barkTriangles == 0 && mModel.leaves.empty())
                return fail(mFile, "leaves", "no triangles left: all " + std::to_string(stats.degenerate) +
                                                 " leaves have zero area");
            if (stats.degenerate > 0)
                warn("leaves of zero area dropped: " + std::to_string(stats.degenerate));
            if (stats.duplicates > 0)
                warn("leaves that exactly copy an earlier leaf (kept): " + std::to_string(stats.duplicates));

            mModel.updateBounds();
            glm::vec3 extent = mModel.boundsMax - mModel.boundsMin;
            double size = std::max({extent.x, extent.y, extent.z});
            if (size > kLargeModelMetres)
                warn("the model is " + fmt(size) + " m across (more than 1 km); units are metres");
            if (auto r = mModel.validate(mFile); !r)
                return r.error();
            return std::move(mModel);
        }

        Result<void> GltfReader::readMaterials()
        {
            mTextureOfImage.assign(mGltf.images.size(), -1);
            for (const std::string& wanted : mOptions.leafMaterials)
                if (std::none_of(mGltf.materials.begin(), mGltf.materials.end(),
                                 [&](const tinygltf::Material& m) { return m.name == wanted; }))
                    warn("leaf material " + inQuotes(wanted) + " is not in the file");

            for (std::size_t i = 0; i < mGltf.materials.size(); ++i)
            {
                const tinygltf::Material& src = mGltf.materials[i];
                const std::string where = "material " + std::to_string(i) + " " + inQuotes(src.name);
                Material m;
                m.name = src.name;
                const std::vector<double>& f = src.pbrMetallicRoughness.baseColorFactor;
                if (f.size() == 4)
                    m.baseColour = glm::vec4(narrow(f[0]), narrow(f[1]), narrow(f[2]), narrow(f[3]));
                else
                    warn(where + ": baseColorFactor has " + std::to_string(f.size()) + " values, not 4; using white");
                if (!std::isfinite(m.baseColour.x) || !std::isfinite(m.baseColour.y) || !std::isfinite(m.baseColour.z) ||
                    !std::isfinite(m.baseColour.w))
                    return fail(mFile, where, "baseColorFactor is not finite");
                m.alphaCutoff = std::isfinite(narrow(src.alphaCutoff)) ? narrow(src.alphaCutoff) : 0.5f;
                m.doubleSided = src.doubleSided;
                if (mOptions.leafMaterials.empty())
                    m.isLeaf = src.alphaMode == "MASK" || src.alphaMode == "BLEND";
                else
                    m.isLeaf = std::find(mOptions.leafMaterials.begin(), mOptions.leafMaterials.end(), src.name) !=
                               mOptions.leafMaterials.end();

                if (src.extras.IsObject() && src.extras.Has("treelodBackColour"))
                {
                    const tinygltf::Value& c = src.extras.Get("treelodBackColour");
                    bool ok = c.IsArray() && c.ArrayLen() == 3;
                    for (int k = 0; ok && k < 3; ++k)
                        ok = c.Get(k).IsNumber() && std::isfinite(narrow(c.Get(k).GetNumberAsDouble()));
                    if (ok)
                        m.backColour = glm::vec3(narrow(c.Get(0).GetNumberAsDouble()), narrow(c.Get(1).GetNumberAsDouble()),
                                                 narrow(c.Get(2).GetNumberAsDouble()));
                    else
                        warn(where + ": extras treelodBackColour is not 3 numbers; ignored");
                }

                const int texture = src.pbrMetallicRoughness.baseColorTexture.index;
                if (texture >= 0)
                {
                    if (std::size_t(texture) >= mGltf.textures.size())
                        return fail(mFile, where, "baseColorTexture " + std::to_string(texture) + " out of range (" +
                                                      std::to_string(mGltf.textures.size()) + " textures)");
                    const int image = mGltf.textures[std::size_t(texture)].source;
                    if (image < 0)
                        warn(where + ": texture " + std::to_string(texture) + " has no PNG/JPEG source; untextured");
                    else if (std::size_t(image) >= mGltf.images.size())
                        return fail(mFile, "texture " + std::to_string(texture),
                                    "image " + std::to_string(image) + " out of range (" +
                                        std::to_string(mGltf.images.size()) + " images)");
                    else
                    {
                        auto t = textureOfImage(image);
                        if (!t)
                            return t.error();
                        m.texture = *t;
                    }
                }
                mModel.materials.push_back(m);
                report(mOptions.progress, "images", float(i + 1) / float(mGltf.materials.size()));
            }
            return {};
        }

        Result<std::int32_t> GltfReader::textureOfImage(int imageIndex)
        {
            if (mTextureOfImage[std::size_t(imageIndex)] >= 0)
                return mTextureOfImage[std::size_t(imageIndex)];
            const tinygltf::Image& image = mGltf.images[std::size_t(imageIndex)];
            const std::string where = "image " + std::to_string(imageIndex) + " " + inQuotes(image.name);
            const std::uint8_t* bytes = nullptr;
            std::size_t size = 0;
            if (image.bufferView >= 0)
            {
                const std::string bvWhere = where + " bufferView " + std::to_string(image.bufferView);
                if (std::size_t(image.bufferView) >= mGltf.bufferViews.size())
                    return fail(mFile, bvWhere, "out of range (" + std::to_string(mGltf.bufferViews.size()) + " buffer views)");
                const tinygltf::BufferView& bv = mGltf.bufferViews[std::size_t(image.bufferView)];
                if (bv.buffer < 0 || std::size_t(bv.buffer) >= mGltf.buffers.size())
                    return fail(mFile, bvWhere, "buffer " + std::to_string(bv.buffer) + " out of range");
                const std::vector<unsigned char>& data = mGltf.buffers[std::size_t(bv.buffer)].data;
                if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
                    return fail(mFile, bvWhere, "bytes " + std::to_string(bv.byteOffset) + ".." +
                                                    std::to_string(bv.byteOffset + bv.byteLength) + " out of range (buffer has " +
                                                    std::to_string(data.size()) + ")");
                bytes = data.data() + bv.byteOffset;
                size = bv.byteLength;
            }
            else if (!image.image.empty())
            {
                bytes = image.image.data();
                size = image.image.size();
            }
            else if (!image.uri.empty())
            {
                if (mBaseDir.empty())
                    return fail(mFile, where, "external file " + inQuotes(image.uri) +
                                                  " cannot be read: in-memory data has no base directory");
                std::string path = (std::filesystem::path(mBaseDir) / image.uri).string();
                std::vector<unsigned char> probe;
                std::string reason;
                if (!readWholeFile(path, probe, reason))
                    return fail(mFile, where, "external file " + inQuotes(path) + ": " + reason);
                return fail(mFile, where, "external file " + inQuotes(path) + " is empty or could not be loaded");
            }
            else
                return fail(mFile, where, "no image data");

            auto decoded = decodeTexture(bytes, size, mFile, where);
            if (!decoded)
                return decoded.error();
            TextureImage& tex = *decoded;
            if (!image.uri.empty() && image.uri.compare(0, 5, "data:") != 0)
                tex.name = image.uri;
            else if (!image.name.empty())
                tex.name = image.name;
            else
                tex.name = "image " + std::to_string(imageIndex);
            mModel.textures.push_back(std::move(tex));
            mTextureOfImage[std::size_t(imageIndex)] = std::int32_t(mModel.textures.size() - 1);
            return mTextureOfImage[std::size_t(imageIndex)];
        }

        std::uint32_t GltfReader::materialFor(int gltfMaterial)
        {
            if (gltfMaterial >= 0)
                return std::uint32_t(gltfMaterial);
            if (mDefaultMaterial < 0)
            {
                Material m;
                m.name = "(default)";
                m.isLeaf = std::find(mOptions.leafMaterials.begin(), mOptions.leafMaterials.end(), m.name) !=
                           mOptions.leafMaterials.end();
                mModel.materials.push_back(m);
                mDefaultMaterial = std::int32_t(mModel.materials.size() - 1);
            }
            return std::uint32_t(mDefaultMaterial);
        }

        Result<void> GltfReader::readScene()
        {
            const std::size_t nodeCount = mGltf.nodes.size();
            std::vector<int> roots;
            if (!mGltf.scenes.empty())
            {
                std::size_t scene = 0;
                if (mGltf.defaultScene >= 0 && std::size_t(mGltf.defaultScene) < mGltf.scenes.size())
                    scene = std::size_t(mGltf.defaultScene);
                else if (mGltf.defaultScene >= 0)
                    warn("default scene " + std::to_string(mGltf.defaultScene) + " out of range; using scene 0");
                for (int n : mGltf.scenes[scene].nodes)
                {
                    if (n < 0 || std::size_t(n) >= nodeCount)
                        return fail(mFile, "scene " + std::to_string(scene),
                                    "node " + std::to_string(n) + " out of range (" + std::to_string(nodeCount) + " nodes)");
                    roots.push_back(n);
                }
            }
            else
            {
                // No scene: every node that is nobody's child is a root.
                std::vector<char> isChild(nodeCount, 0);
                for (const tinygltf::Node& node : mGltf.nodes)
                    for (int c : node.children)
                        if (c >= 0 && std::size_t(c) < nodeCount)
                            isChild[std::size_t(c)] = 1;
                for (std::size_t n = 0; n < nodeCount; ++n)
                    if (!isChild[n])
                        roots.push_back(int(n));
            }

            mWarnedPrimitive.assign(mGltf.meshes.size(), 0);
            std::vector<char> visited(nodeCount, 0);
            struct Item
            {
                int node;
                glm::dmat4 parent;
            };
            std::vector<Item> stack;
            for (auto it = roots.rbegin(); it != roots.rend(); ++it)
                stack.push_back({*it, glm::dmat4(1.0)});
            std::size_t done = 0;
            while (!stack.empty())
            {
                Item item = stack.back();
                stack.pop_back();
                const std::string where = "node " + std::to_string(item.node);
                if (visited[std::size_t(item.node)])
                    return fail(mFile, where, "appears twice in the node hierarchy (a cycle or a shared child)");
                visited[std::size_t(item.node)] = 1;
                const tinygltf::Node& node = mGltf.nodes[std::size_t(item.node)];

                glm::dmat4 local(1.0);
                if (!node.matrix.empty())
                {
                    if (node.matrix.size() != 16)
                        return fail(mFile, where, "matrix has " + std::to_string(node.matrix.size()) + " values, not 16");
                    local = glm::make_mat4(node.matrix.data()); // column-major, as glTF
                }
                else
                {
                    if (!node.translation.empty() && node.translation.size() != 3)
                        return fail(mFile, where, "translation has " + std::to_string(node.translation.size()) + " values, not 3");
                    if (!node.rotation.empty() && node.rotation.size() != 4)
                        return fail(mFile, where, "rotation has " + std::to_string(node.rotation.size()) + " values, not 4");
                    if (!node.scale.empty() && node.scale.size() != 3)
                        return fail(mFile, where, "scale has " + std::to_string(node.scale.size()) + " values, not 3");
                    glm::dvec3 t(0.0), s(1.0);
                    glm::dquat r(1.0, 0.0, 0.0, 0.0);
                    if (!node.translation.empty())
                        t = glm::dvec3(node.translation[0], node.translation[1], node.translation[2]);
                    if (!node.scale.empty())
                        s = glm::dvec3(node.scale[0], node.scale[1], node.scale[2]);
                    if (!node.rotation.empty())
                    {
                        r = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
                        double len = glm::length(r);
                        if (!(len > 0.0) || !std::isfinite(len))
                            return fail(mFile, where, "rotation is not a unit quaternion");
                        r /= len;
                    }
                    local = glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
                }
                for (int c = 0; c < 4; ++c)
                    for (int k = 0; k < 4; ++k)
                        if (!std::isfinite(local[c][k]))
                            return fail(mFile, where, "transform is not finite");
                const glm::dmat4 world = item.parent * local;

                if (node.mesh >= 0)
                {
                    if (std::size_t(node.mesh) >= mGltf.meshes.size())
                        return fail(mFile, where, "mesh " + std::to_string(node.mesh) + " out of range (" +
                                                      std::to_string(mGltf.meshes.size()) + " meshes)");
                    if (auto r = readMesh(item.node, node.mesh, world); !r)
                        return r;
                }
                for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
                {
                    if (*it < 0 || std::size_t(*it) >= nodeCount)
                        return fail(mFile, where, "child " + std::to_string(*it) + " out of range (" +
                                                      std::to_string(nodeCount) + " nodes)");
                    stack.push_back({*it, world});
                }
                report(mOptions.progress, "meshes", float(++done) / float(std::max<std::size_t>(nodeCount, 1)));
            }
            return {};
        }

        Result<void> GltfReader::readMesh(int node, int meshIndex, const glm::dmat4& world)
        {
            const tinygltf::Mesh& mesh = mGltf.meshes[std::size_t(meshIndex)];
            for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
                if (auto r = readPrimitive(meshIndex, int(p), world, node); !r)
                    return r;
            if (mesh.extras.IsObject() && mesh.extras.Has("treelodSkeleton"))
                return readSkeleton(meshIndex, world);
            return {};
        }

        Result<AccessorView> GltfReader::viewAccessor(int index, const std::string& primitiveWhere, const char* role)
        {
            const std::string where = primitiveWhere + " accessor " + std::to_string(index) + " (" + role + ")";
            if (index < 0 || std::size_t(index) >= mGltf.accessors.size())
                return fail(mFile, where, "out of range (" + std::to_string(mGltf.accessors.size()) + " accessors)");
            const tinygltf::Accessor& acc = mGltf.accessors[std::size_t(index)];
            if (acc.sparse.isSparse)
                return fail(mFile, where, "sparse accessors are not supported");
            const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
            const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
            if (components <= 0)
                return fail(mFile, where, "unknown type " + std::to_string(acc.type));
            if (componentSize <= 0)
                return fail(mFile, where, "unknown componentType " + std::to_string(acc.componentType));
            AccessorView view;
            view.count = acc.count;
            view.componentType = acc.componentType;
            view.components = components;
            view.normalized = acc.normalized;
            if (acc.count == 0)
                return view;
            if (acc.bufferView < 0 || std::size_t(acc.bufferView) >= mGltf.bufferViews.size())
                return fail(mFile, where, "bufferView " + std::to_string(acc.bufferView) + " missing or out of range (" +
                                              std::to_string(mGltf.bufferViews.size()) + " buffer views)");
            const tinygltf::BufferView& bv = mGltf.bufferViews[std::size_t(acc.bufferView)];
            const std::string bvWhere = where + " bufferView " + std::to_string(acc.bufferView);
            if (bv.buffer < 0 || std::size_t(bv.buffer) >= mGltf.buffers.size())
                return fail(mFile, bvWhere, "buffer " + std::to_string(bv.buffer) + " out of range (" +
                                                std::to_string(mGltf.buffers.size()) + " buffers)");
            const std::vector<unsigned char>& data = mGltf.buffers[std::size_t(bv.buffer)].data;
            if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
                return fail(mFile, bvWhere, "byte range " + std::to_string(bv.byteOffset) + " + " +
                                                std::to_string(bv.byteLength) + " exceeds buffer " +
                                                std::to_string(bv.buffer) + " (" + std::to_string(data.size()) + " bytes)");
            const std::size_t elementSize = std::size_t(components) * std::size_t(componentSize);
            const std::size_t stride = bv.byteStride ? bv.byteStride : elementSize;
            if (stride < elementSize)
                return fail(mFile, bvWhere, "byteStride " + std::to_string(stride) + " is smaller than an element (" +
                                                std::to_string(elementSize) + " bytes)");
            // Last element must end inside the view: offset + (count-1)*stride + elementSize <= length,
            // checked without overflow.
            bool fits = acc.byteOffset <= bv.byteLength && elementSize <= bv.byteLength - acc.byteOffset;
            if (fits)
            {
                const std::size_t room = bv.byteLength - acc.byteOffset - elementSize;
                fits = (acc.count - 1) <= room / stride;
            }
            if (!fits)
                return fail(mFile, where, std::to_string(acc.count) + " elements of " + std::to_string(elementSize) +
                                              " bytes (stride " + std::to_string(stride) + ") at offset " +
                                              std::to_string(acc.byteOffset) + " overrun bufferView " +
                                              std::to_string(acc.bufferView) + " (" + std::to_string(bv.byteLength) +
                                              " bytes)");
            view.data = data.data() + bv.byteOffset + acc.byteOffset;
            view.stride = stride;
            return view;
        }

        Result<void> GltfReader::readPrimitive(int meshIndex, int primitiveIndex, const glm::dmat4& world, int node)
        {
            const tinygltf::Mesh& mesh = mGltf.meshes[std::size_t(meshIndex)];
            const tinygltf::Primitive& prim = mesh.primitives[std::size_t(primitiveIndex)];
            const std::string where = meshName(meshIndex) + " primitive " + std::to_string(primitiveIndex);

            const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode < TINYGLTF_MODE_TRIANGLES)
            {
                ++mReport.skippedPrimitives;
                if (!mWarnedPrimitive[std::size_t(meshIndex)])
                    warn(where + ": points or lines (mode " + std::to_string(mode) + ") skipped");
                mWarnedPrimitive[std::size_t(meshIndex)] = 1;
                return {};
            }
            if (mode > TINYGLTF_MODE_TRIANGLE_FAN)
                return fail(mFile, where, "unknown mode " + std::to_string(mode));

            if (prim.material < -1 || (prim.material >= 0 && std::size_t(prim.material) >= mGltf.materials.size()))
                return fail(mFile, where, "material " + std::to_string(prim.material) + " out of range (" +
                                              std::to_string(mGltf.materials.size()) + " materials)");
            const std::uint32_t material = materialFor(prim.material);
            const bool isLeaf = mModel.materials[material].isLeaf;

            auto findAttribute = [&](const std::string& name)
            {
                auto it = prim.attributes.find(name);
                return it == prim.attributes.end() ? -1 : it->second;
            };
            const int positionAccessor = findAttribute("POSITION");
            if (positionAccessor < 0)
                return fail(mFile, where, "no POSITION attribute");
            auto positions = viewAccessor(positionAccessor, where, "POSITION");
            if (!positions)
                return positions.error();
            const std::string positionWhere = where + " accessor " + std::to_string(positionAccessor) + " (POSITION)";
            if (mGltf.accessors[std::size_t(positionAccessor)].type != TINYGLTF_TYPE_VEC3)
                return fail(mFile, positionWhere, std::string("type ") + typeName(mGltf.accessors[std::size_t(positionAccessor)].type) +
                                                      ", expected VEC3");
            const std::size_t vertexCount = positions->count;
            if (vertexCount == 0)
                return {};

            std::vector<Vertex>& targetVertices = isLeaf ? mLeafSoup.vertices : mModel.barkVertices;
            if (targetVertices.size() + vertexCount > std::numeric_limits<std::uint32_t>::max())
                return fail(mFile, where, "more than 2^32 vertices in all");
            const std::size_t base = targetVertices.size();

            // Positions: finite as stored and after the node's transform.
            std::vector<Vertex> vertices(vertexCount);
            for (std::size_t i = 0; i < vertexCount; ++i)
            {
                glm::vec3 p;
                readVec(*positions, i, &p.x);
                if (!finite3(p))
                    return fail(mFile, positionWhere, "vertex " + std::to_string(i) + " position is not finite " + vecText(p));
                glm::vec3 q = narrow(glm::dvec3(world * glm::dvec4(p, 1.0)));
                if (!finite3(q))
                    return fail(mFile, positionWhere, "vertex " + std::to_string(i) +
                                                          " position is not finite after the transform of node " +
                                                          std::to_string(node));
                vertices[i].position = q;
            }

            // Normals: the normal matrix (inverse transpose, sign of the determinant kept).
            const glm::dmat3 linear(world);
            const double det = glm::determinant(linear);
            bool haveNormals = false;
            const int normalAccessor = findAttribute("NORMAL");
            if (normalAccessor >= 0)
            {
                auto normals = viewAccessor(normalAccessor, where, "NORMAL");
                if (!normals)
                    return normals.error();
                const std::string normalWhere = where + " accessor " + std::to_string(normalAccessor) + " (NORMAL)";
                if (mGltf.accessors[std::size_t(normalAccessor)].type != TINYGLTF_TYPE_VEC3)
                    return fail(mFile, normalWhere, std::string("type ") + typeName(mGltf.accessors[std::size_t(normalAccessor)].type) +
                                                        ", expected VEC3");
                if (normals->count != vertexCount)
                    return fail(mFile, normalWhere, std::to_string(normals->count) + " normals for " +
                                                        std::to_string(vertexCount) + " positions");
                haveNormals = det != 0.0;
                const glm::mat3 normalMatrix(glm::transpose(glm::inverse(linear)));
                for (std::size_t i = 0; haveNormals && i < vertexCount; ++i)
                {
                    glm::vec3 n;
                    readVec(*normals, i, &n.x);
                    n = normalMatrix * n;
                    float len = glm::length(n);
                    if (!(len > 0.0f) || !std::isfinite(len))
                    {
                        warn(normalWhere + ": vertex " + std::to_string(i) + " normal is zero or not finite; normals recomputed");
                        haveNormals = false;
                        break;
                    }
                    vertices[i].normal = n / len;
                }
            }

            // UVs from the set the base colour texture uses (TEXCOORD_0 by default).
            int uvSet = 0;
            if (prim.material >= 0)
                uvSet = std::max(0, mGltf.materials[std::size_t(prim.material)].pbrMetallicRoughness.baseColorTexture.texCoord);
            const std::string uvName = "TEXCOORD_" + std::to_string(uvSet);
            const int uvAccessor = findAttribute(uvName);
            if (uvAccessor >= 0)
            {
                auto uvs = viewAccessor(uvAccessor, where, uvName.c_str());
                if (!uvs)
                    return uvs.error();
                const std::string uvWhere = where + " accessor " + std::to_string(uvAccessor) + " (" + uvName + ")";
                if (mGltf.accessors[std::size_t(uvAccessor)].type != TINYGLTF_TYPE_VEC2)
                    return fail(mFile, uvWhere, std::string("type ") + typeName(mGltf.accessors[std::size_t(uvAccessor)].type) +
                                                    ", expected VEC2");
                if (uvs->count != vertexCount)
                    return fail(mFile, uvWhere, std::to_string(uvs->count) + " UVs for " + std::to_string(vertexCount) + " positions");
                std::size_t bad = 0;
                for (std::size_t i = 0; i < vertexCount; ++i)
                {
                    glm::vec2 uv;
                    readVec(*uvs, i, &uv.x);
                    if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
                    {
                        uv = glm::vec2(0.0f);
                        ++bad;
                    }
                    vertices[i].uv = uv;
                }
                if (bad)
                    warn(uvWhere + ": " + std::to_string(bad) + " UVs are not finite; set to 0");
            }

            // Triangles (local indices); strips and fans converted (glTF 2.0 §3.7.2.1).
            std::vector<std::uint32_t> corners;
            if (prim.indices >= 0)
            {
                auto indices = viewAccessor(prim.indices, where, "indices");
                if (!indices)
                    return indices.error();
                const std::string indexWhere = where + " accessor " + std::to_string(prim.indices) + " (indices)";
                const tinygltf::Accessor& acc = mGltf.accessors[std::size_t(prim.indices)];
                if (acc.type != TINYGLTF_TYPE_SCALAR)
                    return fail(mFile, indexWhere, std::string("type ") + typeName(acc.type) + ", expected SCALAR");
                if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                    acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                    acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                    return fail(mFile, indexWhere, "componentType " + std::to_string(acc.componentType) +
                                                       " is not an unsigned 8, 16 or 32-bit integer");
                corners.resize(indices->count);
                for (std::size_t i = 0; i < indices->count; ++i)
                {
                    std::uint32_t v = readIndex(*indices, i);
                    if (v >= vertexCount)
                        return fail(mFile, indexWhere, "index " + std::to_string(v) + " out of range (" +
                                                           std::to_string(vertexCount) + " vertices)");
                    corners[i] = v;
                }
            }
            else
            {
                corners.resize(vertexCount);
                for (std::size_t i = 0; i < vertexCount; ++i)
                    corners[i] = std::uint32_t(i);
            }

            std::vector<std::uint32_t> triangles;
            auto addTriangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c)
            {
                // A triangle that repeats a vertex has no area and would only join neighbours.
                if (a == b || b == c || a == c)
                    return;
                if (det < 0.0) // a mirroring transform flips the winding (glTF 2.0 §3.5.3)
                    std::swap(b, c);
                triangles.insert(triangles.end(), {a, b, c});
            };
            if (mode == TINYGLTF_MODE_TRIANGLES)
            {
                if (corners.size() % 3 != 0)
                    warn(where + ": " + std::to_string(corners.size()) + " vertices is not a multiple of 3; the rest is ignored");
                triangles.reserve(corners.size());
                for (std::size_t i = 0; i + 2 < corners.size(); i += 3)
                    addTriangle(corners[i], corners[i + 1], corners[i + 2]);
            }
            else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
            {
                for (std::size_t i = 0; i + 2 < corners.size(); ++i)
                    if (i % 2 == 0)
                        addTriangle(corners[i], corners[i + 1], corners[i + 2]);
                    else
                        addTriangle(corners[i], corners[i + 2], corners[i + 1]);
            }
            else
            {
                for (std::size_t i = 1; i + 1 < corners.size(); ++i)
                    addTriangle(corners[i], corners[i + 1], corners[0]);
            }

            // Missing normals: area-weighted face normals summed over shared indices.
            if (!haveNormals)
            {
                std::vector<glm::vec3> sum(vertexCount, glm::vec3(0.0f));
                for (std::size_t t = 0; t < triangles.size(); t += 3)
                {
                    const glm::vec3& a = vertices[triangles[t]].position;
                    const glm::vec3& b = vertices[triangles[t + 1]].position;
                    const glm::vec3& c = vertices[triangles[t + 2]].position;
                    glm::vec3 n = glm::cross(b - a, c - a);
                    for (int k = 0; k < 3; ++k)
                        sum[triangles[t + k]] += n;
                }
                for (std::size_t i = 0; i < vertexCount; ++i)
                {
                    float len = glm::length(sum[i]);
                    vertices[i].normal = len > 0.0f && std::isfinite(len) ? sum[i] / len : glm::vec3(0.0f, 1.0f, 0.0f);
                }
            }

            targetVertices.insert(targetVertices.end(), vertices.begin(), vertices.end());
            std::vector<std::uint32_t>& targetIndices = isLeaf ? mLeafSoup.indices : mModel.barkIndices;
            std::vector<std::uint32_t>& targetMaterial = isLeaf ? mLeafSoup.triangleMaterial : mModel.barkTriangleMaterial;
            for (std::uint32_t v : triangles)
                targetIndices.push_back(std::uint32_t(base + v));
            targetMaterial.insert(targetMaterial.end(), triangles.size() / 3, material);
            return {};
        }

        Result<void> GltfReader::readSkeleton(int meshIndex, const glm::dmat4& world)
        {
            const std::string where = meshName(meshIndex) + " extras treelodSkeleton";
            const tinygltf::Value& s = mGltf.meshes[std::size_t(meshIndex)].extras.Get("treelodSkeleton");
            if (!s.IsObject() || !s.Has("positions") || !s.Has("radii") || !s.Has("parents"))
                return fail(mFile, where, "expected an object with positions, radii and parents");
            const tinygltf::Value& positions = s.Get("positions");
            const tinygltf::Value& radii = s.Get("radii");
            const tinygltf::Value& parents = s.Get("parents");
            const std::size_t n = radii.ArrayLen();
            if (!positions.IsArray() || !radii.IsArray() || !parents.IsArray() || positions.ArrayLen() != 3 * n ||
                parents.ArrayLen() != n)
                return fail(mFile, where, "expected arrays of 3n positions, n radii and n parents (n = " +
                                              std::to_string(n) + ", " + std::to_string(positions.ArrayLen()) +
                                              " position values, " + std::to_string(parents.ArrayLen()) + " parents)");
            if (n > std::size_t(std::numeric_limits<std::int32_t>::max()) / 2)
                return fail(mFile, where, "too many nodes");
            const std::int32_t offset = std::int32_t(mModel.skeleton.size());
            // Radii scale with the cube root of the volume scale: exact for uniform scales.
            const double radiusScale = std::cbrt(std::abs(glm::determinant(glm::dmat3(world))));
            for (std::size_t i = 0; i < n; ++i)
            {
                const std::string nodeWhere = where + " node " + std::to_string(i);
                double p[3];
                for (int k = 0; k < 3; ++k)
                {
                    const tinygltf::Value& v = positions.Get(int(3 * i + k));
                    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
                        return fail(mFile, nodeWhere, "position is not a finite number");
                    p[k] = v.GetNumberAsDouble();
                }
                const tinygltf::Value& r = radii.Get(int(i));
                const tinygltf::Value& parent = parents.Get(int(i));
                if (!r.IsNumber() || !std::isfinite(r.GetNumberAsDouble()) || r.GetNumberAsDouble() < 0.0)
                    return fail(mFile, nodeWhere, "radius is not a finite number >= 0");
                if (!parent.IsNumber() || parent.GetNumberAsDouble() != std::floor(parent.GetNumberAsDouble()) ||
                    parent.GetNumberAsDouble() < -1.0 || parent.GetNumberAsDouble() >= double(i))
                    return fail(mFile, nodeWhere, "parent must be -1 or the index of an earlier node");
                SkeletonNode sn;
                sn.position = narrow(glm::dvec3(world * glm::dvec4(p[0], p[1], p[2], 1.0)));
                if (!finite3(sn.position))
                    return fail(mFile, nodeWhere, "position is not finite after the node transform");
                sn.radius = narrow(r.GetNumberAsDouble() * radiusScale);
                if (!std::isfinite(sn.radius))
                    return fail(mFile, nodeWhere, "radius is not finite after the node transform");
                const int pi = int(parent.GetNumberAsDouble());
                sn.parent = pi < 0 ? -1 : offset + pi;
                mModel.skeleton.push_back(sn);
            }
            return {};
        }

        std::string stemOf(const std::string& label)
        {
            std::string stem = std::filesystem::path(label).stem().string();
            return stem.empty() ? label : stem;
        }

        Result<TreeModel> importBytes(const std::uint8_t* data, std::size_t size, const std::string& file,
                                      const std::string& baseDir, const ImportOptions& options, ImportReport* reportOut)
        {
            ImportReport localReport;
            ImportReport& rep = reportOut ? *reportOut : localReport;
            rep = ImportReport{};
            report(options.progress, "read", 0.0f);

            if (size == 0)
                return fail(file, "", "not glTF: the data is empty");
            if (size > std::numeric_limits<unsigned int>::max())
                return fail(file, "", "larger than 4 GB, which glTF cannot address");

            tinygltf::TinyGLTF loader;
            FsContext fsContext{baseDir};
            tinygltf::FsCallbacks fs{};
            fs.FileExists = &fsFileExists;
            fs.ExpandFilePath = &fsExpandFilePath;
            fs.ReadWholeFile = &fsReadWholeFile;
            fs.WriteWholeFile = &fsWriteWholeFile;
            fs.user_data = &fsContext;
            loader.SetFsCallbacks(fs);
            loader.SetImageLoader(&keepEncodedImage, nullptr);

            tinygltf::Model gltf;
            std::string err, warnings;
            bool ok = false;
            const bool isGlb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
            try
            {
                if (isGlb)
                {
                    auto length = checkGlb(data, size, file);
                    if (!length)
                        return length.error();
                    ok = loader.LoadBinaryFromMemory(&gltf, &err, &warnings, data, *length, baseDir);
                }
                else
                {
                    std::size_t start = 0;
                    if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF)
                        start = 3; // UTF-8 byte order mark
                    while (start < size && std::isspace(data[start]))
                        ++start;
                    if (start == size || data[start] != '{')
                        return fail(file, "", "not glTF: neither binary glTF (magic 'glTF') nor a JSON object");
                    const char* text = reinterpret_cast<const char*>(data);
                    if (jsonDepth(text, size) > kMaxJsonDepth)
                        return fail(file, "JSON", "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
                    ok = loader.LoadASCIIFromString(&gltf, &err, &warnings, text, (unsigned int)size, baseDir);
                }
            }
            catch (const std::exception& e)
            {
                return fail(file, "glTF", std::string("parser failed: ") + e.what());
            }
            if (!ok)
            {
                std::string reason = oneLine(err.empty() ? warnings : err);
                return fail(file, "glTF", "not valid glTF: " + (reason.empty() ? std::string("the parser gave no reason") : reason));
            }
            if (!warnings.empty())
                rep.warnings.push_back("glTF: " + oneLine(warnings));
            report(options.progress, "read", 1.0f);

            GltfReader reader(gltf, file, baseDir, options, rep);
            return reader.read(stemOf(file));
        }
    }

    Result<TreeModel> importGltf(const std::string& path, const ImportOptions& options, ImportReport* report)
    {
        std::vector<unsigned char> bytes;
        std::string reason;
        if (!readWholeFile(path, bytes, reason))
            return fail(path, "", reason);
        std::string baseDir = std::filesystem::path(path).parent_path().string();
        if (baseDir.empty())
            baseDir = ".";
        return importBytes(bytes.data(), bytes.size(), path, baseDir, options, report);
    }

    Result<TreeModel> importGltfFromMemory(const std::uint8_t* data, std::size_t size, const std::string& label,
                                           const std::string& baseDir, const ImportOptions& options,
                                           ImportReport* report)
    {
        if (!data && size > 0)
            return fail(label, "", "no data");
        return importBytes(data, size, label, baseDir, options, report);
    }
}
