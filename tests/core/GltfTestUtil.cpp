#include "GltfTestUtil.h"
#include "TestOutput.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace TreeLod
{
    namespace test
    {
        std::string testDir(const std::string& name) { return freshTestDir("gltf", name); }

        bool writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes)
        {
            std::ofstream f(path, std::ios::binary);
            f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            return bool(f);
        }

        std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc)
        {
            crc = ~crc;
            for (std::size_t i = 0; i < size; ++i)
            {
                crc ^= data[i];
                for (int k = 0; k < 8; ++k)
                    crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
            }
            return ~crc;
        }

        std::uint32_t adler32(const std::uint8_t* data, std::size_t size)
        {
            std::uint32_t a = 1, b = 0;
            for (std::size_t i = 0; i < size; ++i)
            {
                a = (a + data[i]) % 65521u;
                b = (b + a) % 65521u;
            }
            return (b << 16) | a;
        }

        namespace
        {
            void putBE32(std::vector<std::uint8_t>& out, std::uint32_t v)
            {
                for (int s = 24; s >= 0; s -= 8)
                    out.push_back(std::uint8_t(v >> s));
            }

            void putLE32(std::vector<std::uint8_t>& out, std::uint32_t v)
            {
                for (int s = 0; s < 32; s += 8)
                    out.push_back(std::uint8_t(v >> s));
            }

            void chunk(std::vector<std::uint8_t>& png, const char* type, const std::vector<std::uint8_t>& data)
            {
                putBE32(png, std::uint32_t(data.size()));
                std::vector<std::uint8_t> typed(type, type + 4);
                typed.insert(typed.end(), data.begin(), data.end());
                png.insert(png.end(), typed.begin(), typed.end());
                putBE32(png, crc32(typed.data(), typed.size()));
            }

            int bitsPerPixel(int colourType, int bitDepth)
            {
                switch (colourType)
                {
                case 0: return bitDepth;
                case 2: return 3 * bitDepth;
                case 3: return bitDepth;
                case 4: return 2 * bitDepth;
                default: return 4 * bitDepth;
                }
            }
        }

        std::vector<std::uint8_t> makePng(int width, int height, int colourType, int bitDepth,
                                          const std::vector<std::uint8_t>& rows, const std::vector<std::uint8_t>& plte,
                                          const std::vector<std::uint8_t>& trns)
        {
            std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
            std::vector<std::uint8_t> ihdr;
            putBE32(ihdr, std::uint32_t(width));
            putBE32(ihdr, std::uint32_t(height));
            ihdr.insert(ihdr.end(), {std::uint8_t(bitDepth), std::uint8_t(colourType), 0, 0, 0});
            chunk(png, "IHDR", ihdr);
            if (!plte.empty())
                chunk(png, "PLTE", plte);
            if (!trns.empty())
                chunk(png, "tRNS", trns);

            // Raw scanlines, each with filter byte 0 (None).
            const std::size_t rowBytes = (std::size_t(width) * bitsPerPixel(colourType, bitDepth) + 7) / 8;
            std::vector<std::uint8_t> raw;
            for (int y = 0; y < height; ++y)
            {
                raw.push_back(0);
                raw.insert(raw.end(), rows.begin() + std::ptrdiff_t(y * rowBytes),
                           rows.begin() + std::ptrdiff_t((y + 1) * rowBytes));
            }
            // zlib stream: header, stored deflate blocks (<= 65535 bytes each), Adler-32.
            std::vector<std::uint8_t> z = {0x78, 0x01};
            std::size_t pos = 0;
            do
            {
                std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
                bool last = pos + n == raw.size();
                z.push_back(last ? 1 : 0);
                z.push_back(std::uint8_t(n & 0xff));
                z.push_back(std::uint8_t(n >> 8));
                z.push_back(std::uint8_t(~n & 0xff));
                z.push_back(std::uint8_t((~n >> 8) & 0xff));
                z.insert(z.end(), raw.begin() + std::ptrdiff_t(pos), raw.begin() + std::ptrdiff_t(pos + n));
                pos += n;
            } while (pos < raw.size());
            putBE32(z, adler32(raw.data(), raw.size()));
            chunk(png, "IDAT", z);
            chunk(png, "IEND", {});
            return png;
        }

        std::vector<std::uint8_t> makeRgbaPng(int width, int height, const std::vector<std::uint8_t>& rgba)
        {
            return makePng(width, height, 6, 8, rgba);
        }

        std::vector<std::uint8_t> withPngSize(std::vector<std::uint8_t> png, std::uint32_t width,
                                              std::uint32_t height)
        {
            // Signature (8), IHDR length (4), "IHDR" at 12, width at 16, height at 20, CRC at 29.
            for (int i = 0; i < 4; ++i)
            {
                png[16 + i] = std::uint8_t(width >> (24 - 8 * i));
                png[20 + i] = std::uint8_t(height >> (24 - 8 * i));
            }
            const std::uint32_t crc = crc32(png.data() + 12, 17);
            for (int i = 0; i < 4; ++i)
                png[29 + i] = std::uint8_t(crc >> (24 - 8 * i));
            return png;
        }

        std::vector<std::uint8_t> makeJpegHeader(std::uint16_t width, std::uint16_t height, bool progressive)
        {
            std::vector<std::uint8_t> j = {0xFF, 0xD8};
            auto segment = [&](std::uint8_t marker, const std::vector<std::uint8_t>& body) {
                const std::size_t length = body.size() + 2;
                j.insert(j.end(), {0xFF, marker, std::uint8_t(length >> 8), std::uint8_t(length & 0xFF)});
                j.insert(j.end(), body.begin(), body.end());
            };
            std::vector<std::uint8_t> dqt = {0x00}; // 8-bit table 0
            dqt.resize(65, 1);
            segment(0xDB, dqt);
            segment(progressive ? 0xC2 : 0xC0,
                    {8, std::uint8_t(height >> 8), std::uint8_t(height & 0xFF), std::uint8_t(width >> 8),
                     std::uint8_t(width & 0xFF), 1, 1, 0x11, 0}); // one component: id 1, 1x1, table 0
            for (std::uint8_t tableClass : {0x00, 0x10}) // DC 0, AC 0: one 1-bit code for symbol 0
            {
                std::vector<std::uint8_t> dht = {tableClass, 1};
                dht.resize(17, 0);
                dht.push_back(0);
                segment(0xC4, dht);
            }
            segment(0xDA, {1, 1, 0x00, 0, std::uint8_t(progressive ? 0 : 63), 0});
            j.insert(j.end(), {0x00, 0x00, 0x00, 0x00});
            return j;
        }

        std::string base64(const std::vector<std::uint8_t>& bytes)
        {
            static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
            std::string out;
            std::size_t i = 0;
            for (; i + 2 < bytes.size(); i += 3)
            {
                std::uint32_t v = std::uint32_t(bytes[i]) << 16 | std::uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
                for (int s = 18; s >= 0; s -= 6)
                    out += table[(v >> s) & 63];
            }
            if (i + 1 == bytes.size())
            {
                std::uint32_t v = std::uint32_t(bytes[i]) << 16;
                out += table[(v >> 18) & 63];
                out += table[(v >> 12) & 63];
                out += "==";
            }
            else if (i + 2 == bytes.size())
            {
                std::uint32_t v = std::uint32_t(bytes[i]) << 16 | std::uint32_t(bytes[i + 1]) << 8;
                out += table[(v >> 18) & 63];
                out += table[(v >> 12) & 63];
                out += table[(v >> 6) & 63];
                out += '=';
            }
            return out;
        }

        Quad makeQuad(const glm::vec3& centre, const glm::vec3& u, const glm::vec3& v)
        {
            Quad q;
            q.positions = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
            q.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
            q.indices = {0, 1, 2, 0, 2, 3};
            return q;
        }

        void PrimitiveData::add(const Quad& q)
        {
            const std::uint32_t base = std::uint32_t(positions.size());
            positions.insert(positions.end(), q.positions.begin(), q.positions.end());
            uvs.insert(uvs.end(), q.uvs.begin(), q.uvs.end());
            for (std::uint32_t i : q.indices)
                indices.push_back(base + i);
        }

        GltfBuilder::GltfBuilder()
        {
            mJson["asset"] = {{"version", "2.0"}, {"generator", "TreeLod tests"}};
        }

        int GltfBuilder::addBufferView(const void* data, std::size_t bytes, std::size_t stride)
        {
            while (mBin.size() % 4)
                mBin.push_back(0);
            nlohmann::json bv = {{"buffer", 0}, {"byteOffset", mBin.size()}, {"byteLength", bytes}};
            if (stride)
                bv["byteStride"] = stride;
            const std::uint8_t* p = static_cast<const std::uint8_t*>(data);
            mBin.insert(mBin.end(), p, p + bytes);
            mJson["bufferViews"].push_back(bv);
            return int(mJson["bufferViews"].size() - 1);
        }

        int GltfBuilder::addAccessor(int bufferView, int componentType, std::size_t count, const std::string& type,
                                     std::size_t byteOffset, bool normalized)
        {
            nlohmann::json a = {{"bufferView", bufferView}, {"componentType", componentType}, {"count", count}, {"type", type}};
            if (byteOffset)
                a["byteOffset"] = byteOffset;
            if (normalized)
                a["normalized"] = true;
            mJson["accessors"].push_back(a);
            return int(mJson["accessors"].size() - 1);
        }

        int GltfBuilder::addPositions(const std::vector<glm::vec3>& p)
        {
            int bv = addBufferView(p.data(), p.size() * sizeof(glm::vec3));
            int a = addAccessor(bv, 5126, p.size(), "VEC3");
            bool finite = true;
            for (const glm::vec3& q : p)
                finite = finite && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
            if (!p.empty() && finite)
            {
                glm::vec3 lo = p[0], hi = p[0];
                for (const glm::vec3& q : p)
                {
                    lo = glm::min(lo, q);
                    hi = glm::max(hi, q);
                }
                mJson["accessors"][std::size_t(a)]["min"] = {lo.x, lo.y, lo.z};
                mJson["accessors"][std::size_t(a)]["max"] = {hi.x, hi.y, hi.z};
            }
            return a;
        }

        int GltfBuilder::addNormals(const std::vector<glm::vec3>& n)
        {
            return addAccessor(addBufferView(n.data(), n.size() * sizeof(glm::vec3)), 5126, n.size(), "VEC3");
        }

        int GltfBuilder::addUvs(const std::vector<glm::vec2>& uv)
        {
            return addAccessor(addBufferView(uv.data(), uv.size() * sizeof(glm::vec2)), 5126, uv.size(), "VEC2");
        }

        int GltfBuilder::addIndices(const std::vector<std::uint32_t>& indices, int bits)
        {
            if (bits == 8)
            {
                std::vector<std::uint8_t> v(indices.begin(), indices.end());
                return addAccessor(addBufferView(v.data(), v.size()), 5121, v.size(), "SCALAR");
            }
            if (bits == 16)
            {
                std::vector<std::uint16_t> v(indices.begin(), indices.end());
                return addAccessor(addBufferView(v.data(), v.size() * 2), 5123, v.size(), "SCALAR");
            }
            return addAccessor(addBufferView(indices.data(), indices.size() * 4), 5125, indices.size(), "SCALAR");
        }

        int GltfBuilder::addMaterial(const std::string& name, const std::string& alphaMode, int texture,
                                     const nlohmann::json& extras)
        {
            nlohmann::json m = {{"name", name}, {"alphaMode", alphaMode}};
            m["pbrMetallicRoughness"] = {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}}};
            if (texture >= 0)
                m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", texture}};
            if (!extras.is_null())
                m["extras"] = extras;
            mJson["materials"].push_back(m);
            return int(mJson["materials"].size() - 1);
        }

        int GltfBuilder::addImageEmbedded(const std::vector<std::uint8_t>& png)
        {
            int bv = addBufferView(png.data(), png.size());
            mJson["images"].push_back({{"bufferView", bv}, {"mimeType", "image/png"}});
            return int(mJson["images"].size() - 1);
        }

        int GltfBuilder::addImageUri(const std::string& uri)
        {
            mJson["images"].push_back({{"uri", uri}});
            return int(mJson["images"].size() - 1);
        }

        int GltfBuilder::addTexture(int image)
        {
            mJson["textures"].push_back({{"source", image}});
            return int(mJson["textures"].size() - 1);
        }

        nlohmann::json GltfBuilder::primitive(const PrimitiveData& d)
        {
            nlohmann::json p;
            p["attributes"]["POSITION"] = addPositions(d.positions);
            if (!d.normals.empty())
                p["attributes"]["NORMAL"] = addNormals(d.normals);
            if (!d.uvs.empty())
                p["attributes"]["TEXCOORD_0"] = addUvs(d.uvs);
            if (!d.indices.empty())
                p["indices"] = addIndices(d.indices, d.indexBits);
            if (d.material >= 0)
                p["material"] = d.material;
            if (d.mode != 4)
                p["mode"] = d.mode;
            return p;
        }

        int GltfBuilder::addMesh(const std::string& name, const std::vector<nlohmann::json>& primitives,
                                 const nlohmann::json& extras)
        {
            nlohmann::json m = {{"name", name}, {"primitives", primitives}};
            if (!extras.is_null())
                m["extras"] = extras;
            mJson["meshes"].push_back(m);
            return int(mJson["meshes"].size() - 1);
        }

        int GltfBuilder::addNode(const nlohmann::json& node)
        {
            mJson["nodes"].push_back(node);
            return int(mJson["nodes"].size() - 1);
        }

        void GltfBuilder::setScene(const std::vector<int>& roots)
        {
            mJson["scenes"] = nlohmann::json::array({{{"nodes", roots}}});
            mJson["scene"] = 0;
        }

        int GltfBuilder::addMeshNode(const std::string& name, const PrimitiveData& d)
        {
            int mesh = addMesh(name, {primitive(d)});
            int node = addNode({{"mesh", mesh}});
            mRoots.push_back(node);
            setScene(mRoots);
            return node;
        }

        std::vector<std::uint8_t> GltfBuilder::glb() const
        {
            nlohmann::json j = mJson;
            std::vector<std::uint8_t> bin = mBin;
            while (bin.size() % 4)
                bin.push_back(0);
            if (!bin.empty())
                j["buffers"] = nlohmann::json::array({{{"byteLength", mBin.size()}}});
            std::string text = j.dump();
            while (text.size() % 4)
                text += ' ';
            std::vector<std::uint8_t> out = {'g', 'l', 'T', 'F'};
            putLE32(out, 2);
            putLE32(out, std::uint32_t(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
            putLE32(out, std::uint32_t(text.size()));
            putLE32(out, 0x4E4F534Au);
            out.insert(out.end(), text.begin(), text.end());
            if (!bin.empty())
            {
                putLE32(out, std::uint32_t(bin.size()));
                putLE32(out, 0x004E4942u);
                out.insert(out.end(), bin.begin(), bin.end());
            }
            return out;
        }

        std::string GltfBuilder::gltfWithDataUri() const
        {
            nlohmann::json j = mJson;
            if (!mBin.empty())
                j["buffers"] = nlohmann::json::array(
                    {{{"byteLength", mBin.size()}, {"uri", "data:application/octet-stream;base64," + base64(mBin)}}});
            return j.dump(1);
        }

        std::string GltfBuilder::gltfWithExternalBin(const std::string& binName) const
        {
            nlohmann::json j = mJson;
            if (!mBin.empty())
                j["buffers"] = nlohmann::json::array({{{"byteLength", mBin.size()}, {"uri", binName}}});
            return j.dump(1);
        }

        bool GltfBuilder::writeGlb(const std::string& path) const { return writeBytes(path, glb()); }

        bool GltfBuilder::writeGltf(const std::string& path) const
        {
            std::filesystem::path p(path);
            std::string binName = p.stem().string() + ".bin";
            std::string text = gltfWithExternalBin(binName);
            return writeBytes(path, std::vector<std::uint8_t>(text.begin(), text.end())) &&
                   (mBin.empty() || writeBytes((p.parent_path() / binName).string(), mBin));
        }
    }
}
