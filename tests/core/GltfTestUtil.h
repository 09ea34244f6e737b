// Test helpers: build tiny glTF files and PNG images in code.
//
// GltfBuilder collects JSON (nlohmann) and one binary buffer; write it as .glb, as .gltf
// with an external .bin, or as .gltf with the buffer in a data URI. Indices returned by the
// add* functions are glTF indices (accessor, material, mesh, node...).
#pragma once

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace test
    {
        /// A directory for this test's files under TREELOD_TEST_OUT (created, emptied).
        std::string testDir(const std::string& name);

        /// Write bytes to a file (test helper, not atomic). Returns false on failure.
        bool writeBytes(const std::string& path, const std::vector<std::uint8_t>& bytes);

        std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);
        std::uint32_t adler32(const std::uint8_t* data, std::size_t size);

        /// A PNG from raw rows (bytes per row as the colour type and depth need, no filter
        /// byte): IHDR, optional PLTE and tRNS, one IDAT of stored deflate blocks, IEND.
        std::vector<std::uint8_t> makePng(int width, int height, int colourType, int bitDepth,
                                          const std::vector<std::uint8_t>& rows,
                                          const std::vector<std::uint8_t>& plte = {},
                                          const std::vector<std::uint8_t>& trns = {});

        /// An 8-bit RGBA PNG.
        std::vector<std::uint8_t> makeRgbaPng(int width, int height, const std::vector<std::uint8_t>& rgba);

        /// `png` with the width and height in its IHDR replaced (CRC updated); the pixel data
        /// stays what it was, so the file claims a size its bytes do not hold.
        std::vector<std::uint8_t> withPngSize(std::vector<std::uint8_t> png, std::uint32_t width,
                                              std::uint32_t height);

        /// The start of a greyscale JPEG claiming width x height (at most 65535 each): SOI, a
        /// quantisation table, a baseline (SOF0) or progressive (SOF2) frame header, Huffman
        /// tables, the first scan header and four bytes of scan data; no end. Enough for a
        /// decoder to read the header, not an image.
        std::vector<std::uint8_t> makeJpegHeader(std::uint16_t width, std::uint16_t height, bool progressive);

        /// Base64 (for data URIs).
        std::string base64(const std::vector<std::uint8_t>& bytes);

        /// Corners and triangles of one quad: centre +- u +- v, UVs (0..1).
        struct Quad
        {
            std::vector<glm::vec3> positions;
            std::vector<glm::vec2> uvs;
            std::vector<std::uint32_t> indices; ///< two triangles, local 0..3
        };
        Quad makeQuad(const glm::vec3& centre, const glm::vec3& u, const glm::vec3& v);

        /// Geometry of one primitive before it is written.
        struct PrimitiveData
        {
            std::vector<glm::vec3> positions;
            std::vector<glm::vec3> normals;     ///< empty: no NORMAL attribute
            std::vector<glm::vec2> uvs;         ///< empty: no TEXCOORD_0
            std::vector<std::uint32_t> indices; ///< empty: non-indexed
            int indexBits = 32;                 ///< 8, 16 or 32
            int material = -1;
            int mode = 4;

            /// Append a quad (offsetting its indices).
            void add(const Quad& q);
        };

        class GltfBuilder
        {
        public:
            GltfBuilder();

            nlohmann::json& json() { return mJson; }
            std::vector<std::uint8_t>& bin() { return mBin; }

            int addBufferView(const void* data, std::size_t bytes, std::size_t stride = 0);
            int addAccessor(int bufferView, int componentType, std::size_t count, const std::string& type,
                            std::size_t byteOffset = 0, bool normalized = false);
            int addPositions(const std::vector<glm::vec3>& p);
            int addNormals(const std::vector<glm::vec3>& n);
            int addUvs(const std::vector<glm::vec2>& uv);
            int addIndices(const std::vector<std::uint32_t>& indices, int bits);

            int addMaterial(const std::string& name, const std::string& alphaMode, int texture = -1,
                            const nlohmann::json& extras = nullptr);
            int addImageEmbedded(const std::vector<std::uint8_t>& png); ///< bufferView image
            int addImageUri(const std::string& uri);
            int addTexture(int image);

            /// One primitive from data (writes its accessors); returns its JSON.
            nlohmann::json primitive(const PrimitiveData& d);
            int addMesh(const std::string& name, const std::vector<nlohmann::json>& primitives,
                        const nlohmann::json& extras = nullptr);
            int addNode(const nlohmann::json& node);
            /// Scene 0 with these root nodes (call once; default scene 0).
            void setScene(const std::vector<int>& roots);

            /// Convenience: one mesh with one primitive in one root node, scene set.
            int addMeshNode(const std::string& name, const PrimitiveData& d);

            std::vector<std::uint8_t> glb() const;
            std::string gltfWithDataUri() const;
            /// .gltf text referencing `binName` (written beside it by writeGltf).
            std::string gltfWithExternalBin(const std::string& binName) const;
            bool writeGlb(const std::string& path) const;
            bool writeGltf(const std::string& path) const; ///< + path.bin beside it

        private:
            nlohmann::json mJson;
            std::vector<std::uint8_t> mBin;
            std::vector<int> mRoots;
        };
    }
}
