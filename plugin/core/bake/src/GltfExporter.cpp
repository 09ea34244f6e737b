// Binary glTF 2.0 writer for TreeModel (layout in GltfExporter.h), through tinygltf.
// Images are encoded to PNG in memory (ImageCodec.h) and stored in the binary buffer
// (image.bufferView), so tinygltf's own image writer is never needed.
#include "TreeLod/GltfExporter.h"

#include "TreeLod/AtomicFile.h"

#include "TreeLod/ImageCodec.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        constexpr int kArrayBuffer = 34962;
        constexpr int kElementArrayBuffer = 34963;

        /// The double nearest to the shortest decimal that reads back as `f`: JSON stays
        /// short ("0.1", not "0.10000000149011612") and a float reader gets `f` exactly.
        double shortDouble(float f)
        {
            char text[32];
            const auto result = std::to_chars(text, text + sizeof(text) - 1, f);
            *result.ptr = '\0';
            return std::strtod(text, nullptr);
        }

        tinygltf::Value numbers(const std::vector<float>& values)
        {
            tinygltf::Value::Array array;
            array.reserve(values.size());
            for (float v : values)
                array.emplace_back(shortDouble(v));
            return tinygltf::Value(std::move(array));
        }

        /// RGB when every texel is opaque, RGBA otherwise; zlib level 9.
        Result<std::vector<unsigned char>> texturePng(const TextureImage& texture)
        {
            bool opaque = true;
            for (std::size_t i = 3; i < texture.rgba.size(); i += 4)
                opaque = opaque && texture.rgba[i] == 255;
            const int channels = opaque ? 3 : 4;
            std::vector<unsigned char> pixels;
            if (opaque)
            {
                pixels.reserve(texture.rgba.size() / 4 * 3);
                for (std::size_t i = 0; i < texture.rgba.size(); i += 4)
                    pixels.insert(pixels.end(), texture.rgba.begin() + std::ptrdiff_t(i),
                                  texture.rgba.begin() + std::ptrdiff_t(i) + 3);
            }
            else
                pixels = texture.rgba;

            Result<std::vector<std::uint8_t>> png = encodePng(pixels.data(), texture.width, texture.height, channels, 9);
            if (!png)
                return fail("", "image '" + texture.name + "'", png.error().reason);
            return png;
        }

        /// Builds buffer views into one binary buffer, each 4-byte aligned.
        class BufferBuilder
        {
        public:
            explicit BufferBuilder(tinygltf::Model& model) : mModel(model) { mModel.buffers.emplace_back(); }

            int addView(const void* data, std::size_t size, int target)
            {
                std::vector<unsigned char>& bytes = mModel.buffers[0].data;
                while (bytes.size() % 4 != 0)
                    bytes.push_back(0);
                tinygltf::BufferView view;
                view.buffer = 0;
                view.byteOffset = bytes.size();
                view.byteLength = size;
                view.target = target;
                const auto* p = static_cast<const unsigned char*>(data);
                bytes.insert(bytes.end(), p, p + size);
                mModel.bufferViews.push_back(view);
                return int(mModel.bufferViews.size()) - 1;
            }

            int addAccessor(const void* data, std::size_t count, int componentType, int type, std::size_t elementSize,
                            int target)
            {
                tinygltf::Accessor accessor;
                accessor.bufferView = addView(data, count * elementSize, target);
                accessor.byteOffset = 0;
                accessor.componentType = componentType;
                accessor.type = type;
                accessor.count = count;
                mModel.accessors.push_back(accessor);
                return int(mModel.accessors.size()) - 1;
            }

        private:
            tinygltf::Model& mModel;
        };

        /// POSITION / NORMAL / TEXCOORD_0 accessors for a vertex array.
        std::map<std::string, int> addVertices(tinygltf::Model& model, BufferBuilder& buffer,
                                               const std::vector<Vertex>& vertices)
        {
            std::vector<float> positions, normals, uvs;
            positions.reserve(vertices.size() * 3);
            normals.reserve(vertices.size() * 3);
            uvs.reserve(vertices.size() * 2);
            std::vector<double> lo(3, std::numeric_limits<double>::max()), hi(3, -std::numeric_limits<double>::max());
            for (const Vertex& v : vertices)
            {
                for (int c = 0; c < 3; ++c)
                {
                    positions.push_back(v.position[c]);
                    normals.push_back(v.normal[c]);
                    lo[std::size_t(c)] = std::min(lo[std::size_t(c)], double(v.position[c]));
                    hi[std::size_t(c)] = std::max(hi[std::size_t(c)], double(v.position[c]));
                }
                uvs.push_back(v.uv.x);
                uvs.push_back(v.uv.y);
            }
            std::map<std::string, int> attributes;
            const int position = buffer.addAccessor(positions.data(), vertices.size(), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                    TINYGLTF_TYPE_VEC3, 12, kArrayBuffer);
            model.accessors[std::size_t(position)].minValues = lo;
            model.accessors[std::size_t(position)].maxValues = hi;
            attributes["POSITION"] = position;
            attributes["NORMAL"] = buffer.addAccessor(normals.data(), vertices.size(), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                      TINYGLTF_TYPE_VEC3, 12, kArrayBuffer);
            attributes["TEXCOORD_0"] = buffer.addAccessor(uvs.data(), vertices.size(), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                          TINYGLTF_TYPE_VEC2, 8, kArrayBuffer);
            return attributes;
        }

        /// Index accessor: 16-bit when every index of the mesh fits (65535 is reserved
        /// as primitive restart), else 32-bit.
        int addIndices(BufferBuilder& buffer, const std::vector<std::uint32_t>& indices, bool wide)
        {
            if (wide)
                return buffer.addAccessor(indices.data(), indices.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                          TINYGLTF_TYPE_SCALAR, 4, kElementArrayBuffer);
            std::vector<std::uint16_t> narrow(indices.begin(), indices.end());
            return buffer.addAccessor(narrow.data(), narrow.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                      TINYGLTF_TYPE_SCALAR, 2, kElementArrayBuffer);
        }

        /// A mesh with one primitive per material that has triangles; -1 if none has.
        int addMesh(tinygltf::Model& model, BufferBuilder& buffer, const std::string& name,
                    const std::vector<Vertex>& vertices, const std::vector<std::vector<std::uint32_t>>& perMaterial)
        {
            bool any = false;
            for (const auto& indices : perMaterial)
                any = any || !indices.empty();
            if (!any)
                return -1;
            const bool wide = vertices.size() >= 65535;
            const std::map<std::string, int> attributes = addVertices(model, buffer, vertices);
            tinygltf::Mesh mesh;
            mesh.name = name;
            for (std::size_t m = 0; m < perMaterial.size(); ++m)
            {
                if (perMaterial[m].empty())
                    continue;
                tinygltf::Primitive primitive;
                primitive.attributes = attributes;
                primitive.indices = addIndices(buffer, perMaterial[m], wide);
                primitive.material = int(m);
                primitive.mode = TINYGLTF_MODE_TRIANGLES;
                mesh.primitives.push_back(primitive);
            }
            model.meshes.push_back(mesh);
            return int(model.meshes.size()) - 1;
        }
    }

    Result<std::vector<std::uint8_t>> encodeGlb(const TreeModel& tree)
    {
        Result<void> valid = tree.validate();
        if (!valid)
            return valid.error();

        tinygltf::Model model;
        model.asset.version = "2.0";
        model.asset.generator = "TreeLod";
        BufferBuilder buffer(model);

        // Images (PNG in the buffer), one texture each, one shared sampler.
        tinygltf::Sampler sampler;
        sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
        sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
        sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;
        sampler.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
        if (!tree.textures.empty())
            model.samplers.push_back(sampler);
        for (std::size_t t = 0; t < tree.textures.size(); ++t)
        {
            Result<std::vector<unsigned char>> png = texturePng(tree.textures[t]);
            if (!png)
                return png.error();
            tinygltf::Image image;
            image.name = tree.textures[t].name;
            image.mimeType = "image/png";
            image.bufferView = buffer.addView(png->data(), png->size(), 0); // no target for images
            model.images.push_back(image);
            tinygltf::Texture texture;
            texture.source = int(t);
            texture.sampler = 0;
            model.textures.push_back(texture);
        }

        for (const Material& m : tree.materials)
        {
            tinygltf::Material material;
            material.name = m.name;
            material.pbrMetallicRoughness.baseColorFactor = {m.baseColour.r, m.baseColour.g, m.baseColour.b,
                                                             m.baseColour.a};
            material.pbrMetallicRoughness.baseColorTexture.index = m.texture;
            material.pbrMetallicRoughness.metallicFactor = 0.0;
            material.pbrMetallicRoughness.roughnessFactor = 1.0;
            material.doubleSided = m.doubleSided;
            if (m.isLeaf)
            {
                material.alphaMode = "MASK";
                material.alphaCutoff = m.alphaCutoff;
                if (m.backColour != glm::vec3(0.0f))
                {
                    tinygltf::Value::Object extras;
                    extras["treelodBackColour"] = numbers({m.backColour.r, m.backColour.g, m.backColour.b});
                    material.extras = tinygltf::Value(std::move(extras));
                }
            }
            else
                material.alphaMode = "OPAQUE";
            model.materials.push_back(material);
        }

        // Bark: indices grouped by triangle material.
        std::vector<std::vector<std::uint32_t>> barkGroups(tree.materials.size());
        for (std::size_t t = 0; t < tree.barkTriangleCount(); ++t)
        {
            auto& group = barkGroups[tree.barkTriangleMaterial[t]];
            group.insert(group.end(), tree.barkIndices.begin() + std::ptrdiff_t(3 * t),
                         tree.barkIndices.begin() + std::ptrdiff_t(3 * t + 3));
        }
        const int barkMesh = addMesh(model, buffer, "Bark", tree.barkVertices, barkGroups);
        if (barkMesh >= 0 && !tree.skeleton.empty())
        {
            std::vector<float> positions, radii;
            tinygltf::Value::Array parents;
            for (const SkeletonNode& node : tree.skeleton)
            {
                positions.insert(positions.end(), {node.position.x, node.position.y, node.position.z});
                radii.push_back(node.radius);
                parents.emplace_back(int(node.parent));
            }
            tinygltf::Value::Object skeleton;
            skeleton["positions"] = numbers(positions);
            skeleton["radii"] = numbers(radii);
            skeleton["parents"] = tinygltf::Value(std::move(parents));
            tinygltf::Value::Object extras;
            extras["treelodSkeleton"] = tinygltf::Value(std::move(skeleton));
            model.meshes[std::size_t(barkMesh)].extras = tinygltf::Value(std::move(extras));
        }

        // Leaves: each leaf's indices go to its material's primitive, in leaf order.
        std::vector<std::vector<std::uint32_t>> leafGroups(tree.materials.size());
        for (const Leaf& leaf : tree.leaves)
        {
            auto& group = leafGroups[leaf.material];
            group.insert(group.end(), tree.leafIndices.begin() + std::ptrdiff_t(leaf.firstIndex),
                         tree.leafIndices.begin() + std::ptrdiff_t(leaf.firstIndex + leaf.indexCount));
        }
        const int leafMesh = addMesh(model, buffer, "Leaves", tree.leafVertices, leafGroups);

        tinygltf::Scene scene;
        scene.name = tree.name;
        if (barkMesh >= 0)
        {
            tinygltf::Node node;
            node.name = "Bark";
            node.mesh = barkMesh;
            model.nodes.push_back(node);
            scene.nodes.push_back(int(model.nodes.size()) - 1);
        }
        if (leafMesh >= 0)
        {
            tinygltf::Node node;
            node.name = "Leaves";
            node.mesh = leafMesh;
            model.nodes.push_back(node);
            scene.nodes.push_back(int(model.nodes.size()) - 1);
        }
        model.scenes.push_back(scene);
        model.defaultScene = 0;

        std::ostringstream stream;
        tinygltf::TinyGLTF writer;
        if (!writer.WriteGltfSceneToStream(&model, stream, false, true))
            return fail("", "glTF", "tinygltf could not serialise the model");
        const std::string bytes = stream.str();
        return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
    }

    Result<void> writeGlb(const TreeModel& model, const std::string& path)
    {
        Result<std::vector<std::uint8_t>> bytes = encodeGlb(model);
        if (!bytes)
        {
            Error error = bytes.error();
            error.file = path;
            return error;
        }
        return writeFileAtomic(path, *bytes);
    }
}
