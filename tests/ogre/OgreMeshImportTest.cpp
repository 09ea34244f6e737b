// Ogre .mesh import: a mesh written by MeshSerializer comes back as the same tree.
#include "OgreTestSupport.h"

#include "TreeLod/OgreMeshImporter.h"
#include "TreeLod/TreeGenerator.h"
#include "TreeLod/TreeMeshBuilder.h"

#include <OgreAnimation.h>
#include <OgreAnimationTrack.h>
#include <OgreHardwareBufferManager.h>
#include <OgreKeyFrame.h>
#include <OgreMaterialManager.h>
#include <OgreMeshFileFormat.h>
#include <OgreMeshManager.h>
#include <OgreMeshSerializer.h>
#include <OgrePose.h>
#include <OgreSubMesh.h>

#include <cmath>
#include <cstring>
#include <fstream>

namespace TreeLod
{
    TEST(OgreMeshImport, roundTripsAGeneratedTree)
    {
        // buildTreeMesh -> MeshSerializer -> importOgreMesh keeps every leaf (one quad each,
        // split again by connectivity) and every bark triangle.
        OgreEnvironment::renderer();
        GeneratorOptions options;
        options.preset = TreePreset::Shrub;
        options.leafCount = 200;
        options.textureSize = 32;
        Result<TreeModel> model = generateTree(options);
        ASSERT_TRUE(model.ok());
        // Material names that the default rule recognises: "Leaves" is a leaf, "Bark" is not.
        std::vector<Ogre::String> names;
        for (const Material& m : model->materials)
            names.push_back(m.isLeaf ? "Test/Leaves" : "Test/Bark");
        // SubMesh keeps (and the serializer writes) only names of materials Ogre knows.
        for (const Ogre::String& name : names)
            if (!Ogre::MaterialManager::getSingleton().resourceExists(name, Ogre::RGN_DEFAULT))
                Ogre::MaterialManager::getSingleton().create(name, Ogre::RGN_DEFAULT);
        MeshBuildOptions build;
        build.barkLodLevels = 0;
        Ogre::MeshPtr mesh = buildTreeMesh("roundtrip.mesh", Ogre::RGN_DEFAULT, model.value(), names, build);
        const std::string path = OgreEnvironment::outDir() + "/roundtrip.mesh";
        Ogre::MeshSerializer().exportMesh(mesh.get(), path);
        Ogre::MeshManager::getSingleton().remove(mesh);

        std::vector<std::string> warnings;
        OgreMeshImportOptions importOptions;
        importOptions.warnings = &warnings;
        Result<TreeModel> back = importOgreMesh(path, importOptions);
        ASSERT_TRUE(back.ok()) << back.error().message();
        EXPECT_EQ(back->leaves.size(), 200u);
        EXPECT_EQ(back->barkTriangleCount(), model->barkTriangleCount());
        EXPECT_EQ(back->leafTriangleCount(), model->leafTriangleCount());
        EXPECT_NEAR(glm::length(back->boundsMax - model->boundsMax), 0.0f, 1e-4f);
        EXPECT_FALSE(warnings.empty()) << "untextured materials are reported";
    }

    TEST(OgreMeshImport, acceptsSharedVertexData)
    {
        // Two submeshes over one shared vertex buffer: a bark triangle and a leaf quad.
        OgreEnvironment::renderer();
        Ogre::MeshPtr mesh = Ogre::MeshManager::getSingleton().createManual("shared.mesh", Ogre::RGN_DEFAULT);
        mesh->load(); // empty; Ogre frees a mesh's submeshes only when it unloads a loaded one
        mesh->sharedVertexData = new Ogre::VertexData();
        Ogre::VertexData* vd = mesh->sharedVertexData;
        vd->vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION);
        const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /* leaf */ 0, 2, 0, 1, 2, 0, 1, 3, 0, 0, 3, 0};
        vd->vertexCount = 7;
        auto vb = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            12, 7, Ogre::HardwareBuffer::HBU_STATIC, true);
        vb->writeData(0, sizeof(positions), positions);
        vd->vertexBufferBinding->setBinding(0, vb);
        auto addSub = [&](const std::vector<std::uint16_t>& idx, const char* material) {
            Ogre::SubMesh* sub = mesh->createSubMesh();
            sub->useSharedVertices = true;
            sub->setMaterialName(material);
            sub->indexData->indexCount = idx.size();
            sub->indexData->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                Ogre::HardwareIndexBuffer::IT_16BIT, idx.size(), Ogre::HardwareBuffer::HBU_STATIC, true);
            sub->indexData->indexBuffer->writeData(0, idx.size() * 2, idx.data());
        };
        for (const char* name : {"trunk", "oak_leaf"})
            if (!Ogre::MaterialManager::getSingleton().resourceExists(name, Ogre::RGN_DEFAULT))
                Ogre::MaterialManager::getSingleton().create(name, Ogre::RGN_DEFAULT);
        addSub({0, 1, 2}, "trunk");
        addSub({3, 4, 5, 3, 5, 6}, "oak_leaf");
        mesh->_setBounds(Ogre::AxisAlignedBox(0, 0, 0, 1, 3, 0));
        const std::string path = OgreEnvironment::outDir() + "/shared.mesh";
        Ogre::MeshSerializer().exportMesh(mesh.get(), path);
        Ogre::MeshManager::getSingleton().remove(mesh);

        Result<TreeModel> back = importOgreMesh(path);
        ASSERT_TRUE(back.ok()) << back.error().message();
        EXPECT_EQ(back->barkTriangleCount(), 1u);
        ASSERT_EQ(back->leaves.size(), 1u);
        EXPECT_FLOAT_EQ(back->leaves[0].area, 1.0f);
    }

    TEST(OgreMeshImport, badFilesNameFileAndReason)
    {
        OgreEnvironment::renderer();
        Result<TreeModel> missing = importOgreMesh(OgreEnvironment::outDir() + "/nope.mesh");
        ASSERT_FALSE(missing.ok());
        EXPECT_NE(missing.error().message().find("nope.mesh"), std::string::npos);

        const std::string junk = OgreEnvironment::outDir() + "/junk.mesh";
        std::ofstream(junk) << "this is not a mesh";
        Result<TreeModel> bad = importOgreMesh(junk);
        ASSERT_FALSE(bad.ok());
        EXPECT_EQ(bad.error().file, junk);
        EXPECT_EQ(bad.error().element, "header");
    }

    namespace
    {
        /// A .mesh file written byte by byte; chunk lengths are filled in when a chunk closes.
        struct MeshBytes
        {
            std::vector<std::uint8_t> bytes;
            bool bigEndian = false;
            std::vector<std::size_t> open;

            void put(std::uint64_t v, int size)
            {
                for (int i = 0; i < size; ++i)
                    bytes.push_back(std::uint8_t(v >> 8 * (bigEndian ? size - 1 - i : i)));
            }
            void u16(std::uint16_t v) { put(v, 2); }
            void u32(std::uint32_t v) { put(v, 4); }
            void f32(float v)
            {
                std::uint32_t bits;
                std::memcpy(&bits, &v, 4);
                put(bits, 4);
            }
            void line(const std::string& text)
            {
                bytes.insert(bytes.end(), text.begin(), text.end());
                bytes.push_back('\n');
            }
            void chunk(std::uint16_t id)
            {
                open.push_back(bytes.size());
                u16(id);
                u32(0);
            }
            void close()
            {
                const std::size_t at = open.back();
                open.pop_back();
                const std::uint32_t length = std::uint32_t(bytes.size() - at);
                for (int i = 0; i < 4; ++i)
                    bytes[at + 2 + i] = std::uint8_t(length >> 8 * (bigEndian ? 3 - i : i));
            }
        };

        /// One triangle (3 vertices, position float3, 16-bit indices) in one submesh, as
        /// Ogre's MeshSerializer v1.100 lays it out; the offsets of the fields tests change.
        /// `colour`: a second buffer with a VET_UBYTE4_NORM colour per vertex.
        struct TriangleMesh
        {
            std::vector<std::uint8_t> bytes;
            std::size_t meshAt = 0, submeshAt = 0, indexCountAt = 0, geometryAt = 0, vertexCountAt = 0,
                        elementOffsetAt = 0, colourElementAt = 0, dataAt = 0, boundsAt = 0;
        };

        TriangleMesh triangleMesh(bool bigEndian = false, bool colour = false)
        {
            TriangleMesh t;
            MeshBytes m;
            m.bigEndian = bigEndian;
            m.u16(0x1000);
            m.line("[MeshSerializer_v1.100]");
            t.meshAt = m.bytes.size();
            m.chunk(Ogre::M_MESH);
            m.bytes.push_back(0); // not skeletally animated
            t.submeshAt = m.bytes.size();
            m.chunk(Ogre::M_SUBMESH);
            m.line("trunk");
            m.bytes.push_back(0); // own vertices
            t.indexCountAt = m.bytes.size();
            m.u32(3);
            m.bytes.push_back(0); // 16-bit indices
            for (std::uint16_t i : {0, 1, 2})
                m.u16(i);
            t.geometryAt = m.bytes.size();
            m.chunk(Ogre::M_GEOMETRY);
            t.vertexCountAt = m.bytes.size();
            m.u32(3);
            m.chunk(Ogre::M_GEOMETRY_VERTEX_DECLARATION);
            m.chunk(Ogre::M_GEOMETRY_VERTEX_ELEMENT);
            m.u16(0);                   // source
            m.u16(Ogre::VET_FLOAT3);
            m.u16(Ogre::VES_POSITION);
            t.elementOffsetAt = m.bytes.size();
            m.u16(0);                   // offset
            m.u16(0);                   // index
            m.close();
            if (colour)
            {
                t.colourElementAt = m.bytes.size();
                m.chunk(Ogre::M_GEOMETRY_VERTEX_ELEMENT);
                for (std::uint16_t v : {1, int(Ogre::VET_UBYTE4_NORM), int(Ogre::VES_DIFFUSE), 0, 0})
                    m.u16(v);
                m.close();
            }
            m.close();
            m.chunk(Ogre::M_GEOMETRY_VERTEX_BUFFER);
            m.u16(0);  // bind index
            m.u16(12); // vertex size
            t.dataAt = m.bytes.size();
            m.chunk(Ogre::M_GEOMETRY_VERTEX_BUFFER_DATA);
            for (float v : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f})
                m.f32(v);
            m.close();
            m.close();
            if (colour)
            {
                m.chunk(Ogre::M_GEOMETRY_VERTEX_BUFFER);
                m.u16(1); // bind index
                m.u16(4); // vertex size
                m.chunk(Ogre::M_GEOMETRY_VERTEX_BUFFER_DATA);
                for (int i = 0; i < 12; ++i)
                    m.bytes.push_back(std::uint8_t(40 * i));
                m.close();
                m.close();
            }
            m.close(); // M_GEOMETRY
            m.chunk(Ogre::M_SUBMESH_OPERATION);
            m.u16(Ogre::RenderOperation::OT_TRIANGLE_LIST);
            m.close();
            m.close(); // M_SUBMESH
            t.boundsAt = m.bytes.size();
            m.chunk(Ogre::M_MESH_BOUNDS);
            for (float v : {0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 0.0f, 1.5f})
                m.f32(v);
            m.close();
            m.close(); // M_MESH
            t.bytes = m.bytes;
            return t;
        }

        void putU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t v)
        {
            for (int i = 0; i < 4; ++i)
                bytes[at + i] = std::uint8_t(v >> 8 * i);
        }

        std::string writeMesh(const std::string& name, const std::vector<std::uint8_t>& bytes)
        {
            const std::string path = OgreEnvironment::outDir() + "/" + name;
            std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                        std::streamsize(bytes.size()));
            return path;
        }

        /// Imports `bytes`; expects an error naming the file and `element`, its reason containing `reason`.
        void expectRefused(const std::string& name, const std::vector<std::uint8_t>& bytes, const std::string& element,
                           const std::string& reason)
        {
            const std::string path = writeMesh(name, bytes);
            Result<TreeModel> r = importOgreMesh(path);
            ASSERT_FALSE(r.ok()) << name;
            EXPECT_EQ(r.error().file, path);
            EXPECT_EQ(r.error().element, element) << r.error().message();
            EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
        }
    }

    namespace
    {
        Ogre::HardwareVertexBufferSharedPtr floatBuffer(const std::vector<float>& values, std::size_t perVertex)
        {
            auto vb = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                perVertex * 4, values.size() / perVertex, Ogre::HardwareBuffer::HBU_STATIC, true);
            vb->writeData(0, values.size() * 4, values.data());
            return vb;
        }

        Ogre::HardwareIndexBufferSharedPtr indexBuffer(const std::vector<std::uint16_t>& indices)
        {
            auto ib = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                Ogre::HardwareIndexBuffer::IT_16BIT, indices.size(), Ogre::HardwareBuffer::HBU_STATIC, true);
            ib->writeData(0, indices.size() * 2, indices.data());
            return ib;
        }

        Ogre::IndexData* lodFaces(const Ogre::HardwareIndexBufferSharedPtr& buffer, std::size_t count)
        {
            auto* faces = new Ogre::IndexData();
            faces->indexBuffer = buffer;
            faces->indexCount = count;
            return faces;
        }

        /// A shrub small enough for a fuzzer seed: a tapered six-sided trunk of four segments
        /// and ten leaf quads around its top.
        TreeModel smallShrub()
        {
            TreeModel model;
            model.name = "small-shrub";
            model.materials.resize(2);
            model.materials[0].name = "Bark";
            model.materials[1].name = "Leaves";
            model.materials[1].isLeaf = model.materials[1].doubleSided = true;
            const int sides = 6, rings = 5;
            for (int r = 0; r < rings; ++r)
                for (int k = 0; k < sides; ++k)
                {
                    const float a = 6.2831853f * float(k) / sides, radius = 0.1f * (1.0f - 0.15f * float(r));
                    Vertex v;
                    v.position = {radius * std::cos(a), 0.5f * float(r), radius * std::sin(a)};
                    v.normal = {std::cos(a), 0.0f, std::sin(a)};
                    v.uv = {float(k) / sides, float(r)};
                    model.barkVertices.push_back(v);
                }
            for (int r = 0; r + 1 < rings; ++r)
                for (int k = 0; k < sides; ++k)
                {
                    const std::uint32_t a = std::uint32_t(r * sides + k);
                    const std::uint32_t b = std::uint32_t(r * sides + (k + 1) % sides);
                    for (std::uint32_t i : {a, a + sides, b, b, a + sides, b + sides})
                        model.barkIndices.push_back(i);
                    model.barkTriangleMaterial.insert(model.barkTriangleMaterial.end(), 2, 0u);
                }
            for (std::uint32_t l = 0; l < 10; ++l)
            {
                const float a = 0.6283185f * float(l), x = 0.4f * std::cos(a), z = 0.4f * std::sin(a);
                const std::uint32_t first = std::uint32_t(model.leafVertices.size());
                for (int c = 0; c < 4; ++c)
                {
                    Vertex v;
                    v.position = {x + 0.1f * float(c == 1 || c == 2), 1.8f + 0.15f * float(c >= 2), z};
                    v.normal = {0.0f, 0.0f, 1.0f};
                    v.uv = {float(c == 1 || c == 2), float(c >= 2)};
                    model.leafVertices.push_back(v);
                }
                for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
                    model.leafIndices.push_back(first + i);
                Leaf leaf;
                leaf.firstVertex = first;
                leaf.vertexCount = 4;
                leaf.firstIndex = l * 6;
                leaf.indexCount = 6;
                leaf.material = 1;
                model.leaves.push_back(leaf);
                model.updateLeafRecord(l);
            }
            model.updateBounds();
            return model;
        }
    }

    TEST(OgreMeshImport, checkAcceptsEveryChunkOgreWrites)
    {
        // The pre-pass must pass what Ogre's own MeshSerializer writes. A shrub with generated
        // bark LoD levels, edge lists and an AO colour buffer, also in the v1.8 format, and
        // big-endian without the colour; a mesh with the other chunks (shared vertices, manual
        // and generated LoD levels, one sharing another's index buffer, a skeleton link, bone
        // assignments, poses, pose and morph animations, a name table, extremes, a texture
        // alias) in both byte orders. The files are the seeds of the FuzzOgreMeshImport fuzzer
        // (tests/fuzz/corpus/ogremesh).
        OgreEnvironment::renderer();
        const TreeModel model = smallShrub();
        ASSERT_TRUE(model.validate().ok());
        const std::vector<Ogre::String> names = {"Test/Bark", "Test/Leaves"};
        for (const Ogre::String& name : names)
            if (!Ogre::MaterialManager::getSingleton().resourceExists(name, Ogre::RGN_DEFAULT))
                Ogre::MaterialManager::getSingleton().create(name, Ogre::RGN_DEFAULT);
        MeshBuildOptions build;
        build.barkLodLevels = 2;
        build.barkVertexAo.assign(model.barkVertices.size(), 200);
        Ogre::MeshPtr shrub = buildTreeMesh("checked-shrub.mesh", Ogre::RGN_DEFAULT, model, names, build);
        ASSERT_EQ(shrub->getNumLodLevels(), 3u);
        shrub->buildEdgeList();
        const std::string dir = OgreEnvironment::outDir();
        Ogre::MeshSerializer serializer;
        serializer.exportMesh(shrub.get(), dir + "/shrub.mesh");
        serializer.exportMesh(shrub.get(), dir + "/shrub-v1.8.mesh", Ogre::MESH_VERSION_1_8);
        Ogre::MeshManager::getSingleton().remove(shrub);
        // Ogre cannot swap the bytes of the AO colour (UBYTE4_NORM): big-endian without it
        build.barkVertexAo.clear();
        shrub = buildTreeMesh("checked-shrub-plain.mesh", Ogre::RGN_DEFAULT, model, names, build);
        shrub->buildEdgeList();
        serializer.exportMesh(shrub.get(), dir + "/shrub-big-endian.mesh", Ogre::MeshSerializer::ENDIAN_BIG);
        Ogre::MeshManager::getSingleton().remove(shrub);
        for (const char* file : {"shrub.mesh", "shrub-big-endian.mesh", "shrub-v1.8.mesh"})
        {
            Result<TreeModel> back = importOgreMesh(dir + "/" + file);
            ASSERT_TRUE(back.ok()) << back.error().message();
            EXPECT_EQ(back->leaves.size(), 10u) << file;
            EXPECT_EQ(back->barkTriangleCount(), model.barkTriangleCount()) << file;
        }

        // Shared vertices: a bark triangle and a leaf quad; a third submesh with its own quad.
        Ogre::MeshPtr mesh = Ogre::MeshManager::getSingleton().createManual("checked-chunks.mesh", Ogre::RGN_DEFAULT);
        mesh->load(); // empty, as in acceptsSharedVertexData
        mesh->sharedVertexData = new Ogre::VertexData();
        mesh->sharedVertexData->vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION);
        mesh->sharedVertexData->vertexCount = 7;
        mesh->sharedVertexData->vertexBufferBinding->setBinding(
            0, floatBuffer({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 2, 0, 1, 2, 0, 1, 3, 0, 0, 3, 0}, 3));
        for (const char* material : {"trunk", "oak_leaf"})
            if (!Ogre::MaterialManager::getSingleton().resourceExists(material, Ogre::RGN_DEFAULT))
                Ogre::MaterialManager::getSingleton().create(material, Ogre::RGN_DEFAULT);
        const std::vector<std::vector<std::uint16_t>> faces = {{0, 1, 2}, {3, 4, 5, 3, 5, 6}, {0, 1, 2, 0, 2, 3}};
        for (std::size_t i = 0; i < faces.size(); ++i)
        {
            Ogre::SubMesh* sub = mesh->createSubMesh();
            sub->useSharedVertices = i < 2;
            sub->setMaterialName(i == 0 ? "trunk" : "oak_leaf");
            sub->indexData->indexCount = faces[i].size();
            sub->indexData->indexBuffer = indexBuffer(faces[i]);
            if (i == 2)
            {
                sub->vertexData = new Ogre::VertexData();
                sub->vertexData->vertexDeclaration->addElement(0, 0, Ogre::VET_FLOAT3, Ogre::VES_POSITION);
                sub->vertexData->vertexDeclaration->addElement(0, 12, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES);
                sub->vertexData->vertexCount = 4;
                sub->vertexData->vertexBufferBinding->setBinding(
                    0, floatBuffer({2, 0, 0, 0, 0, 3, 0, 0, 1, 0, 3, 1, 0, 1, 1, 2, 1, 0, 0, 1}, 5));
                sub->addBoneAssignment({1, 0, 1.0f});
                sub->addTextureAlias("diffuse", "leaf.png");
                sub->extremityPoints.push_back(Ogre::Vector3(2.5f, 0.5f, 0.0f));
            }
        }
        mesh->nameSubMesh("bark", 0);
        mesh->nameSubMesh("crown", 1);
        mesh->setSkeletonName("absent.skeleton"); // not loadable: Ogre logs it and writes the link
        mesh->addBoneAssignment({0, 0, 1.0f});
        // LoD: level 1 manual, level 2 generated, level 3 sharing level 2's index buffers. Face
        // lists first (Ogre asserts a level is not manual when it is given faces); the writer
        // reads level 1's, empty, when it looks for shared buffers.
        mesh->_setLodInfo(4);
        for (unsigned short s = 0; s < 3; ++s)
        {
            auto buffer = indexBuffer(faces[s]);
            mesh->_setSubMeshLodFaceList(s, 1, new Ogre::IndexData());
            mesh->_setSubMeshLodFaceList(s, 2, lodFaces(buffer, faces[s].size()));
            mesh->_setSubMeshLodFaceList(s, 3, lodFaces(buffer, 3));
        }
        Ogre::MeshLodUsage usage;
        usage.userValue = 10.0f;
        usage.manualName = "checked-chunks-far.mesh";
        mesh->_setLodUsage(1, usage);
        usage.manualName.clear();
        for (unsigned short level : {2, 3})
        {
            usage.userValue = 20.0f * level;
            mesh->_setLodUsage(level, usage);
        }
        mesh->createPose(0, "lift")->addVertex(4, Ogre::Vector3(0, 0.5f, 0));
        mesh->createPose(3, "bend")->addVertex(2, Ogre::Vector3(0.1f, 0, 0), Ogre::Vector3(0, 0, 1));
        Ogre::Animation* sway = mesh->createAnimation("sway", 2.0f);
        sway->setUseBaseKeyFrame(true, 0.0f, "");
        Ogre::VertexData* own = mesh->getSubMesh(2)->vertexData;
        Ogre::VertexAnimationTrack* poses = sway->createVertexTrack(0, mesh->sharedVertexData, Ogre::VAT_POSE);
        poses->createVertexPoseKeyFrame(0.0f)->addPoseReference(0, 1.0f);
        poses->createVertexPoseKeyFrame(1.0f);
        sway->createVertexTrack(3, own, Ogre::VAT_POSE)->createVertexPoseKeyFrame(0.5f)->addPoseReference(1, 0.5f);
        Ogre::Animation* grow = mesh->createAnimation("grow", 1.0f);
        grow->createVertexTrack(0, mesh->sharedVertexData, Ogre::VAT_MORPH)
            ->createVertexMorphKeyFrame(0.0f)
            ->setVertexBuffer(floatBuffer(std::vector<float>(7 * 6, 0.5f), 6)); // with normals
        grow->createVertexTrack(3, own, Ogre::VAT_MORPH)
            ->createVertexMorphKeyFrame(0.0f)
            ->setVertexBuffer(floatBuffer(std::vector<float>(4 * 3, 0.25f), 3));
        mesh->_setBounds(Ogre::AxisAlignedBox(0, 0, 0, 2, 3, 0));
        serializer.exportMesh(mesh.get(), dir + "/chunks.mesh");
        serializer.exportMesh(mesh.get(), dir + "/chunks-big-endian.mesh", Ogre::MeshSerializer::ENDIAN_BIG);
        Ogre::MeshManager::getSingleton().remove(mesh);
        for (const char* file : {"chunks.mesh", "chunks-big-endian.mesh"})
        {
            Result<TreeModel> back = importOgreMesh(dir + "/" + file);
            ASSERT_TRUE(back.ok()) << back.error().message();
            EXPECT_EQ(back->barkTriangleCount(), 1u) << file;
            EXPECT_EQ(back->leaves.size(), 2u) << file;
        }
    }

    TEST(OgreMeshImport, checkReadsAHandWrittenMeshInBothByteOrders)
    {
        // The byte-by-byte file of the tests below is one Ogre reads: a triangle.
        OgreEnvironment::renderer();
        for (bool bigEndian : {false, true})
        {
            // with a colour buffer in this machine's byte order (Ogre cannot swap a colour's bytes)
            const std::string path = writeMesh(bigEndian ? "triangle-be.mesh" : "triangle.mesh",
                                               triangleMesh(bigEndian, !bigEndian).bytes);
            Result<TreeModel> r = importOgreMesh(path);
            ASSERT_TRUE(r.ok()) << r.error().message();
            EXPECT_EQ(r->barkTriangleCount(), 1u);
            EXPECT_FLOAT_EQ(r->boundsMax.y, 1.0f);
        }
    }

    TEST(OgreMeshImport, checkRefusesABadHeaderNamingFileAndReason)
    {
        OgreEnvironment::renderer();
        TriangleMesh t = triangleMesh();
        std::vector<std::uint8_t> bytes = t.bytes;
        bytes[1] = 0x20; // 0x2000
        expectRefused("bad-id.mesh", bytes, "header", "the file starts with 0x2000, not the .mesh header 0x1000");

        bytes.assign(t.bytes.begin(), t.bytes.begin() + 2);
        const std::string older = "[MeshSerializer_v1.41]\n";
        bytes.insert(bytes.end(), older.begin(), older.end());
        bytes.insert(bytes.end(), t.bytes.begin() + std::ptrdiff_t(t.meshAt), t.bytes.end());
        expectRefused("old-version.mesh", bytes, "header", "upgrade the file with OgreMeshUpgrader");

        bytes = {0x00, 0x10, '[', 'M', 'e', 's', 'h'}; // no line feed
        expectRefused("no-line-feed.mesh", bytes, "header", "the string at offset 2 has no line feed before offset 7");
        expectRefused("empty.mesh", {}, "header", "truncated: needs 2 bytes at offset 0, the file ends at 0");
    }

    TEST(OgreMeshImport, checkRefusesATruncatedMeshNamingTheChunk)
    {
        OgreEnvironment::renderer();
        TriangleMesh t = triangleMesh();
        std::vector<std::uint8_t> bytes(t.bytes.begin(), t.bytes.end() - 10);
        expectRefused("truncated.mesh", bytes, "chunk M_MESH at offset " + std::to_string(t.meshAt),
                      "length " + std::to_string(t.bytes.size() - t.meshAt) + " runs to offset " +
                          std::to_string(t.bytes.size()) + ", past the end of the file at " +
                          std::to_string(bytes.size()));
        // Lengths that still nest, but the vertex data chunk is 8 bytes short of 3 x 12.
        bytes = t.bytes;
        bytes.erase(bytes.begin() + t.dataAt + 6 + 28, bytes.begin() + t.dataAt + 6 + 36);
        for (std::size_t at : {t.meshAt, t.submeshAt, t.geometryAt, t.dataAt - 10, t.dataAt})
            putU32(bytes, at + 2, std::uint32_t(t.bytes[at + 2] | t.bytes[at + 3] << 8) - 8);
        expectRefused("short-data.mesh", bytes,
                      "chunk M_GEOMETRY_VERTEX_BUFFER_DATA at offset " + std::to_string(t.dataAt),
                      "3 vertices x 12 bytes need 36 bytes at offset " + std::to_string(t.dataAt + 6) +
                          ", the chunk has 28");
    }

    TEST(OgreMeshImport, checkRefusesCountsBeyondTheFile)
    {
        // Ogre would allocate what the count says (24 GB here) and read past the data.
        OgreEnvironment::renderer();
        TriangleMesh t = triangleMesh();
        std::vector<std::uint8_t> bytes = t.bytes;
        putU32(bytes, t.vertexCountAt, 0x7fffffffu);
        expectRefused("vertex-count.mesh", bytes,
                      "chunk M_GEOMETRY_VERTEX_BUFFER_DATA at offset " + std::to_string(t.dataAt),
                      "2147483647 vertices x 12 bytes need 25769803764 bytes at offset " +
                          std::to_string(t.dataAt + 6) + ", the chunk has 36");

        bytes = t.bytes;
        putU32(bytes, t.indexCountAt, 1000000000u);
        expectRefused("index-count.mesh", bytes, "chunk M_SUBMESH at offset " + std::to_string(t.submeshAt),
                      "1000000000 indices x 2 bytes need 2000000000 bytes");

        // A vertex element beyond the 12-byte vertex: Ogre would read past each vertex.
        bytes = t.bytes;
        bytes[t.elementOffsetAt] = 100;
        expectRefused("element-offset.mesh", bytes, "chunk M_GEOMETRY at offset " + std::to_string(t.geometryAt),
                      "vertex element 0 (offset 100, 12 bytes) lies outside the 12-byte vertices of source 0");

        // A bool that is neither 0 nor 1 (the submesh's "shared vertices").
        bytes = t.bytes;
        bytes[t.indexCountAt - 1] = 2;
        expectRefused("bool.mesh", bytes, "chunk M_SUBMESH at offset " + std::to_string(t.submeshAt),
                      "byte 2 at offset " + std::to_string(t.indexCountAt - 1) + " is not a bool (0 or 1)");
    }

    TEST(OgreMeshImport, checkRefusesWhatOgreAssertsOn)
    {
        // Debian's Ogre keeps its asserts: these would abort the process inside MeshSerializer.
        OgreEnvironment::renderer();
        TriangleMesh t = triangleMesh();
        std::vector<std::uint8_t> bytes = t.bytes;
        const float two = 2.0f; // the bounds' minimum x above its maximum (1)
        std::memcpy(&bytes[t.boundsAt + 6], &two, 4);
        expectRefused("bounds.mesh", bytes, "chunk M_MESH_BOUNDS at offset " + std::to_string(t.boundsAt),
                      "the bounds' x runs from 2 to 1 (the minimum must not exceed the maximum)");

        // flipEndian has no case for a colour in bytes: only in this machine's byte order
        TriangleMesh swapped = triangleMesh(true, true);
        expectRefused("colour-be.mesh", swapped.bytes,
                      "chunk M_GEOMETRY_VERTEX_ELEMENT at offset " + std::to_string(swapped.colourElementAt),
                      "vertex element type " + std::to_string(int(Ogre::VET_UBYTE4_NORM)) +
                          " in a file of the other byte order");
    }
}
