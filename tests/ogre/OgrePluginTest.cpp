// Plugin_TreeLod loaded into a headless Root: install, the TreeAsset resource type,
// packages found through resource groups, the reference mesh, bad packages, the LoD strategy.
#include "OgreTestSupport.h"

#include "TreeLod/LevelCalibration.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreEntity.h>
#include <OgreLodStrategyManager.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgrePixelCountLodStrategy.h>
#include <OgrePlugin.h>
#include <OgreSubMesh.h>
#include <OgreTextureManager.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace TreeLod
{
    namespace
    {
        /// A generated tree baked into `dir/name` (reference chunk only).
        std::string bakeGenerated(const std::string& dir, const std::string& name, std::uint32_t leaves)
        {
            GeneratorOptions options;
            options.preset = TreePreset::Birch;
            options.leafCount = leaves;
            options.textureSize = 64;
            Result<TreeModel> model = generateTree(options);
            EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
            const std::string path = dir + "/" + name;
            Result<void> written = bakeReferencePackage(model.value(), path, PackageMeta{});
            EXPECT_TRUE(written.ok()) << (written.ok() ? "" : written.error().message());
            return path;
        }

        Ogre::String packageGroup()
        {
            static bool once = [] {
                Ogre::ResourceGroupManager::getSingleton().addResourceLocation(
                    OgreEnvironment::outDir() + "/packages", "FileSystem", "TreeLodTestPackages");
                return true;
            }();
            (void)once;
            return "TreeLodTestPackages";
        }

        /// Initialise packageGroup(), or index the packages written since it was: Ogre indexes a
        /// location's files when the location is added (tests that share a process bake in turn).
        void indexPackages()
        {
            Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
            const Ogre::String group = packageGroup();
            if (!rgm.isResourceGroupInitialised(group))
                return rgm.initialiseResourceGroup(group);
            const std::string dir = OgreEnvironment::outDir() + "/packages";
            rgm.removeResourceLocation(dir, group);
            rgm.addResourceLocation(dir, "FileSystem", group);
        }
    }

    // A display that cannot be opened (as when Xvfb resets between two clients) is an exception
    // that names the display and says why, readable after the failed start has unloaded the
    // render system; and the process can start Ogre again afterwards.
    TEST(OgrePlugin, failedStartIsAReadableErrorAndLeavesNothingBehind)
    {
        const std::string display = std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "";
        ASSERT_FALSE(display.empty()) << "run under xvfb-run";
        ::setenv("DISPLAY", ":31999", 1);
        std::string message;
        try
        {
            OffscreenOptions options;
            options.pluginPath = TREELOD_PLUGIN_PATH;
            OffscreenRenderer failed(options);
            ADD_FAILURE() << "Ogre started on a display that does not exist";
        }
        catch (const Ogre::RenderingAPIException& e)
        {
            message = e.what(); // the full description: type name, file and line, all ours
        }
        ::setenv("DISPLAY", display.c_str(), 1);
        EXPECT_NE(message.find(":31999"), std::string::npos) << message;
        EXPECT_NE(message.find("open X display"), std::string::npos) << message;
        EXPECT_NE(message.find("OffscreenRenderer.cpp"), std::string::npos) << message;
        EXPECT_EQ(Ogre::Root::getSingletonPtr(), nullptr);
        EXPECT_EQ(Ogre::LogManager::getSingletonPtr(), nullptr);

        OffscreenRenderer& r = OgreEnvironment::renderer();
        EXPECT_NE(r.getRoot().getRenderSystem(), nullptr);
        const RgbaImage image = r.render(CameraSpec{}, 8, 8);
        EXPECT_EQ(image.pixels.size(), 8u * 8u * 4u);
    }

    TEST(OgrePlugin, installsFromSharedLibrary)
    {
        // Loading the .so runs dllStartPlugin, which installs the plugin: the resource
        // manager and the technique registry exist afterwards.
        OffscreenRenderer& r = OgreEnvironment::renderer();
        bool found = false;
        for (Ogre::Plugin* p : r.getRoot().getInstalledPlugins())
            found = found || p->getName() == "TreeLod";
        EXPECT_TRUE(found);
        ASSERT_NE(TreeAssetManager::getSingletonPtr(), nullptr);
        EXPECT_EQ(TreeAssetManager::getSingleton().getResourceType(), "TreeAsset");
        ASSERT_NE(TechniqueRegistry::getSingletonPtr(), nullptr);
        EXPECT_NE(TechniqueRegistry::getSingleton().find("mesh"), nullptr);
    }

    TEST(OgrePlugin, loadsPackageThroughResourceGroupAndBuildsReferenceMesh)
    {
        OgreEnvironment::renderer();
        std::filesystem::create_directories(OgreEnvironment::outDir() + "/packages");
        bakeGenerated(OgreEnvironment::outDir() + "/packages", "birch-300.treelod", 300);
        indexPackages();

        TreeAssetPtr asset = TreeAssetManager::getSingleton().load("birch-300.treelod", packageGroup());
        ASSERT_TRUE(asset);
        EXPECT_TRUE(asset->hasChunk("reference"));
        Ogre::MeshPtr mesh = asset->getReferenceMesh();
        ASSERT_TRUE(mesh);
        const TreeModel& model = asset->getReference().model;
        EXPECT_EQ(model.leaves.size(), 300u);

        // Bark first (one material), leaves after: every leaf triangle is in the leaf submesh.
        std::size_t leafIndices = 0, barkIndices = 0;
        for (Ogre::SubMesh* sub : mesh->getSubMeshes())
        {
            bool leaf = sub->getMaterialName().find("TreeLod/birch-300.treelod/") == 0 &&
                        model.materials[std::stoul(sub->getMaterialName().substr(26))].isLeaf;
            (leaf ? leafIndices : barkIndices) += sub->indexData->indexCount;
        }
        EXPECT_EQ(leafIndices, model.leafIndices.size());
        EXPECT_EQ(barkIndices, model.barkIndices.size());
        // MeshLodGenerator levels for the bark, full leaves at each level.
        EXPECT_GT(mesh->getNumLodLevels(), 1u);
        for (Ogre::SubMesh* sub : mesh->getSubMeshes())
        {
            ASSERT_EQ(sub->mLodFaceList.size(), mesh->getNumLodLevels() - 1u);
            if (sub->indexData->indexCount == leafIndices)
            {
                for (Ogre::IndexData* lod : sub->mLodFaceList)
                    EXPECT_EQ(lod->indexCount, leafIndices);
            }
        }
        EXPECT_LT(mesh->getSubMesh(0)->mLodFaceList.back()->indexCount, mesh->getSubMesh(0)->indexData->indexCount);
    }

    TEST(OgrePlugin, uses32BitIndicesBeyond65535Vertices)
    {
        // 20,000 quads = 80,000 leaf vertices in one submesh: 16-bit indices cannot address them.
        OgreEnvironment::renderer();
        std::filesystem::create_directories(OgreEnvironment::outDir() + "/packages");
        bakeGenerated(OgreEnvironment::outDir() + "/packages", "birch-20k.treelod", 20000);
        indexPackages();
        TreeAssetPtr asset = TreeAssetManager::getSingleton().load("birch-20k.treelod", packageGroup());
        Ogre::MeshPtr mesh = asset->getReferenceMesh();
        Ogre::SubMesh* leaves = mesh->getSubMesh(mesh->getNumSubMeshes() - 1);
        EXPECT_EQ(leaves->vertexData->vertexCount, 80000u);
        EXPECT_EQ(leaves->indexData->indexBuffer->getType(), Ogre::HardwareIndexBuffer::IT_32BIT);
        EXPECT_EQ(mesh->getSubMesh(0)->indexData->indexBuffer->getType(), Ogre::HardwareIndexBuffer::IT_16BIT);
    }

    TEST(OgrePlugin, corruptPackageRaisesErrorNamingResourceAndReason)
    {
        OgreEnvironment::renderer();
        const std::string dir = OgreEnvironment::outDir() + "/packages";
        std::filesystem::create_directories(dir);
        std::string good = bakeGenerated(dir, "flip-source.treelod", 100);
        std::ifstream in(good, std::ios::binary);
        std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ASSERT_GT(bytes.size(), 200u);
        bytes[bytes.size() - 100] ^= 0x40; // inside the reference chunk's payload

        TreeAssetPtr asset = TreeAssetManager::getSingleton().loadFromBytes("flipped.treelod", Ogre::RGN_DEFAULT, bytes);
        try
        {
            asset->getReferenceMesh();
            FAIL() << "a bit flip in the payload must be detected by the chunk checksum";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("flipped.treelod"), std::string::npos) << e.getDescription();
            EXPECT_NE(e.getDescription().find("reference"), std::string::npos) << e.getDescription();
            EXPECT_NE(e.getDescription().find("checksum"), std::string::npos) << e.getDescription();
        }

        // Truncated: the header and table are checked at load.
        std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + 20);
        EXPECT_THROW(TreeAssetManager::getSingleton().loadFromBytes("cut.treelod", Ogre::RGN_DEFAULT, cut),
                     Ogre::Exception);
    }

    TEST(OgrePlugin, unknownTechniqueNamesTheKnownOnes)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        std::filesystem::create_directories(OgreEnvironment::outDir() + "/packages");
        std::string path = bakeGenerated(OgreEnvironment::outDir() + "/packages", "tech.treelod", 100);
        std::ifstream in(path, std::ios::binary);
        std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        TreeAssetPtr asset = TreeAssetManager::getSingleton().loadFromBytes("tech-mem.treelod", Ogre::RGN_DEFAULT, bytes);
        try
        {
            TechniqueRegistry::getSingleton().createInstance("nosuch", r.getSceneManager(), "x", *asset);
            FAIL();
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("nosuch"), std::string::npos);
            EXPECT_NE(e.getDescription().find("mesh"), std::string::npos);
        }
    }
}

namespace TreeLod
{
    // ScreenSizeLodStrategy: registered by the plugin under its name, chosen by a material script
    // and by a mesh; its value is 4 pi r_px^2 of the scaled bounding sphere with the LoD camera's
    // bias in it (Ogre's pixel_count counts pi r_px^2 and leaves the bias out), perspective and
    // orthographic alike; an Entity whose mesh names it switches its LoD levels by it.
    TEST(ScreenSizeLodStrategy, namedByMaterialsAndMeshesAndHonoursTheCameraBias)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::LodStrategy* strategy = Ogre::LodStrategyManager::getSingleton().getStrategy("treelod_screen_size");
        ASSERT_NE(strategy, nullptr);
        EXPECT_EQ(strategy, ScreenSizeLodStrategy::getSingletonPtr());

        const std::string script = "material TreeLodTest/ScreenSizeLod\n{\n    lod_strategy treelod_screen_size\n"
                                   "    lod_values 40000 10000\n    technique\n    {\n        pass {}\n    }\n"
                                   "    technique\n    {\n        lod_index 1\n        pass {}\n    }\n"
                                   "    technique\n    {\n        lod_index 2\n        pass {}\n    }\n}\n";
        Ogre::DataStreamPtr stream(new Ogre::MemoryDataStream("ScreenSizeLod.material",
                                                              const_cast<char*>(script.data()), script.size()));
        Ogre::MaterialManager::getSingleton().parseScript(stream, "TreeLod");
        Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName("TreeLodTest/ScreenSizeLod", "TreeLod");
        ASSERT_TRUE(material);
        EXPECT_EQ(material->getLodStrategy(), strategy);
        EXPECT_EQ(material->getLodIndex(50000.0f), 0u);
        EXPECT_EQ(material->getLodIndex(20000.0f), 1u);
        EXPECT_EQ(material->getLodIndex(100.0f), 2u);

        std::filesystem::create_directories(OgreEnvironment::outDir() + "/packages");
        bakeGenerated(OgreEnvironment::outDir() + "/packages", "birch-lod-strategy.treelod", 300);
        indexPackages();
        TreeAssetPtr asset = TreeAssetManager::getSingleton().load("birch-lod-strategy.treelod", packageGroup());
        ASSERT_TRUE(asset);
        // A copy of the reference mesh (its MeshLodGenerator levels: 250k, 62.5k, 15.6k) that names
        // the strategy: its lod values are now TreeLod screen sizes.
        Ogre::MeshPtr mesh = asset->getReferenceMesh()->clone("TreeLodTest/ScreenSizeLodMesh");
        mesh->setLodStrategy(strategy);
        ASSERT_GT(mesh->getNumLodLevels(), 2u);
        Ogre::SceneManager& sm = r.getSceneManager();
        Ogre::Entity* entity = sm.createEntity("screenSizeLodEntity", mesh);
        Ogre::SceneNode* node = r.getContentNode().createChildSceneNode();
        node->attachObject(entity);
        node->setScale(2.0f, 2.0f, 2.0f);
        Ogre::Camera* camera = sm.getCamera("TreeLodOffscreenCamera");
        const TreeModel& model = asset->getReference().model;
        auto spec = [&](const char* text) {
            CameraSpec s;
            std::string error;
            EXPECT_TRUE(CameraSpec::parse(text, model.boundsMin * 2.0f, model.boundsMax * 2.0f, s, error)) << error;
            return s;
        };
        const Ogre::LodStrategy& ogrePixels = Ogre::AbsolutePixelCountLodStrategy::getSingleton();
        const std::vector<const char*> views{"orbit:30,10,0.5", "orbit:30,10,1", "orbit:30,10,2", "orbit:30,10,4",
                                             "orbit:30,10,60"};
        std::vector<Ogre::ushort> indices;
        for (const char* view : views)
        {
            r.render(spec(view), 256, 256, 1);
            const Ogre::Real value = strategy->getValue(entity, camera);
            EXPECT_NEAR(value, 4.0f * ogrePixels.getValue(entity, camera), 1e-4f * value) << view;
            EXPECT_EQ(entity->getCurrentLodIndex(), mesh->getLodIndex(value)) << view;
            indices.push_back(entity->getCurrentLodIndex());
        }
        std::printf("mesh LoD index at 0.5, 1, 2, 4, 60 tree sizes: %u %u %u %u %u\n", indices[0], indices[1], indices[2],
                    indices[3], indices[4]);
        EXPECT_EQ(indices.front(), 0u);
        EXPECT_EQ(indices.back(), mesh->getNumLodLevels() - 1u);
        for (std::size_t i = 1; i < indices.size(); ++i)
            EXPECT_GE(indices[i], indices[i - 1]);

        // The camera's LoD bias multiplies the value (Ogre's pixel_count ignores it): where the
        // mesh first leaves level 0, a bias of 16 brings a finer level back.
        const std::size_t coarser = std::size_t(std::find_if(indices.begin(), indices.end(),
                                                             [](Ogre::ushort i) { return i > 0; }) - indices.begin());
        ASSERT_LT(coarser, views.size());
        r.render(spec(views[coarser]), 256, 256, 1);
        const Ogre::Real unbiased = strategy->getValue(entity, camera);
        const Ogre::Real ogreUnbiased = ogrePixels.getValue(entity, camera);
        r.setLodBias(16.0f);
        r.render(spec(views[coarser]), 256, 256, 1);
        EXPECT_NEAR(strategy->getValue(entity, camera), 16.0f * unbiased, 1e-4f * 16.0f * unbiased);
        EXPECT_NEAR(ogrePixels.getValue(entity, camera), ogreUnbiased, 1e-4f * ogreUnbiased);
        EXPECT_LT(entity->getCurrentLodIndex(), indices[coarser]) << views[coarser];
        r.setLodBias(1.0f);

        // Orthographic: the same units.
        r.render(spec("ortho:30,10,2"), 256, 256, 1);
        const Ogre::Real ortho = strategy->getValue(entity, camera);
        EXPECT_GT(ortho, 0.0f);
        EXPECT_NEAR(ortho, 4.0f * ogrePixels.getValue(entity, camera), 1e-4f * ortho);

        node->detachAllObjects();
        sm.destroyEntity(entity);
        r.getContentNode().removeAndDestroyChild(node);
        Ogre::MeshManager::getSingleton().remove(mesh);
        Ogre::MaterialManager::getSingleton().remove(material);
    }

    TEST(TreeAssetManager, theUsersTextureUploadChoiceWinsOverTheMeasuredOne)
    {
        OgreEnvironment::renderer(); // Ogre and the render system up first
        TreeAssetManager& manager = TreeAssetManager::getSingleton();
        const std::optional<CompressedTextureUpload> chosen =
            manager.isCompressedTextureUploadChosen() ? std::optional(manager.getCompressedTextureUpload()) : std::nullopt;
        manager.setCompressedTextureUpload(std::nullopt);
        manager.adoptMeasuredTextureUpload(CompressedTextureUpload::Decoded);
        EXPECT_EQ(manager.getCompressedTextureUpload(), CompressedTextureUpload::Decoded);
        auto texture = [](GpuTextureFormat format) { // 64², the full chain
            GpuTexture t;
            t.format = format;
            t.width = t.height = 64;
            t.mipCount = 7;
            return t;
        };
        for (GpuTextureFormat f : {GpuTextureFormat::DXT1, GpuTextureFormat::DXT5, GpuTextureFormat::BC4, GpuTextureFormat::BC5})
            EXPECT_TRUE(manager.decodesAtLoad(texture(f))) << gpuTextureFormatName(f);
        EXPECT_FALSE(manager.decodesAtLoad(texture(GpuTextureFormat::RGBA8)));
        manager.setCompressedTextureUpload(CompressedTextureUpload::AsStored);
        manager.adoptMeasuredTextureUpload(CompressedTextureUpload::Decoded);
        EXPECT_EQ(manager.getCompressedTextureUpload(), CompressedTextureUpload::AsStored) << "the user's choice stays";
        EXPECT_TRUE(manager.isCompressedTextureUploadChosen());
        // As stored, a block format is decoded only where the render system cannot sample it.
        const Ogre::RenderSystemCapabilities* caps = Ogre::Root::getSingleton().getRenderSystem()->getCapabilities();
        EXPECT_EQ(manager.decodesAtLoad(texture(GpuTextureFormat::DXT5)),
                  !caps->hasCapability(Ogre::RSC_TEXTURE_COMPRESSION_DXT));
        EXPECT_EQ(manager.decodesAtLoad(texture(GpuTextureFormat::BC5)),
                  !caps->hasCapability(Ogre::RSC_TEXTURE_COMPRESSION_BC4_BC5));
        manager.setCompressedTextureUpload(std::nullopt);
        EXPECT_EQ(manager.getCompressedTextureUpload(), CompressedTextureUpload::Decoded) << "the measured one again";
        manager.adoptMeasuredTextureUpload(CompressedTextureUpload::AsStored);
        manager.setCompressedTextureUpload(chosen);
    }

    TEST(LevelCalibration, measuresTextureSamplingAndLeavesNothingBehind)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        CalibrationOptions options;
        options.viewport = 128;
        options.frames = 1;
        Result<TextureSamplingCost> cost = measureTextureSampling(r, options);
        ASSERT_TRUE(cost) << cost.error().message();
        std::printf("texture sampling at 128 px: compressed %.3f ms, decoded %.3f ms\n", cost->compressedMs,
                    cost->decodedMs);
        EXPECT_TRUE(std::isfinite(cost->compressedMs) && std::isfinite(cost->decodedMs));
        EXPECT_GT(cost->compressedMs + cost->decodedMs, 0.0) << "four layers of four reads take time";
        EXPECT_FALSE(Ogre::TextureManager::getSingleton().resourceExists("TreeLod/Calibration/Compressed",
                                                                        Ogre::RGN_INTERNAL));
        EXPECT_FALSE(Ogre::MaterialManager::getSingleton().resourceExists("TreeLod/Calibration/Decoded",
                                                                         Ogre::RGN_INTERNAL));
        EXPECT_EQ(r.getContentNode().numAttachedObjects(), 0u);
    }
}
