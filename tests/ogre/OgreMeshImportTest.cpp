// Ogre .mesh import: a mesh written by MeshSerializer comes back as the same tree.
#include "OgreTestSupport.h"

#include "TreeLod/OgreMeshImporter.h"
#include "TreeLod/TreeGenerator.h"
#include "TreeLod/TreeMeshBuilder.h"

#include <OgreHardwareBufferManager.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgreMeshSerializer.h>
#include <OgreSubMesh.h>

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
        EXPECT_EQ(bad.error().element, "mesh");
    }
}
