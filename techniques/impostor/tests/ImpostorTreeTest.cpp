// The one-quad impostor through Plugin_TreeLod: ImpostorResources::getGpu (quad, textures,
// materials and their shadow caster, a missing chunk named, unload), and the quad drawn
// instanced as the Forest draws it (a Renderable with an instance buffer of uv4 / uv5): it
// turns to face the camera, it looks like the polygonal tree at a distance (FLIP against the
// reference mesh), it casts and receives texture shadows, and a golden image.
#include "OgreTestSupport.h"

#include "TreeLod/ImpostorBaker.h"
#include "TreeLod/ImpostorData.h"
#include "TreeLod/ImpostorResources.h"
#include "TreeLod/ImpostorTree.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include <OgreHardwareBufferManager.h>
#include <OgreEntity.h>
#include <OgreMaterialManager.h>
#include <OgreMeshManager.h>
#include <OgreSceneManager.h>
#include <OgreSimpleRenderable.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>

#include <cmath>

namespace TreeLod::ImpostorTreeTests
{
    namespace
    {
        struct BakedOak
        {
            TreeModel model;
            ImpostorData data;
            TreeAssetPtr asset;
        };

        /// A generated oak with the reference and impostor chunks, loaded as asset `name`.
        const BakedOak& oak()
        {
            return OgreEnvironment::keep<BakedOak>("impostor.oak", [] {
                BakedOak t;
                GeneratorOptions generator;
                generator.leafCount = 3000;
                generator.textureSize = 64;
                Result<TreeModel> model = generateTree(generator);
                EXPECT_TRUE(model.ok());
                t.model = std::move(model.value());
                ImpostorOptions options;
                options.aoRays = 8;
                Result<ImpostorData> data = bakeImpostor(t.model, options, "oak");
                EXPECT_TRUE(data.ok()) << (data.ok() ? "" : data.error().message());
                t.data = data.value();
                PackageWriter writer;
                EXPECT_TRUE(addReferenceChunk(writer, t.model, "oak").ok());
                EXPECT_TRUE(writer.addChunk(IMPOSTOR_CHUNK, 0, IMPOSTOR_CHUNK_FORMAT_VERSION,
                                            encodeImpostorChunk(t.data)).ok());
                t.asset = TreeAssetManager::getSingleton().loadFromBytes("oak.impostor-test", Ogre::RGN_DEFAULT,
                                                                         writer.toBytes());
                return t;
            });
        }

        /// The impostor's quad drawn instanced, as the Forest draws it: instance buffer in
        /// binding 1 with uv4 = position + scale and uv5 = cos, sin of the rotation.
        class InstancedImpostor : public Ogre::SimpleRenderable
        {
        public:
            InstancedImpostor(const ImpostorGpu& gpu, const std::vector<Ogre::Vector4>& instances,
                              const Ogre::String& material, const Ogre::AxisAlignedBox& treeBounds)
                : Ogre::SimpleRenderable("impostor-" + std::to_string(msSerial++))
            {
                mRenderOp.operationType = Ogre::RenderOperation::OT_TRIANGLE_LIST;
                mRenderOp.vertexData = gpu.vertexData->clone(false);
                Ogre::VertexDeclaration* decl = mRenderOp.vertexData->vertexDeclaration;
                decl->addElement(1, 0, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 4);
                decl->addElement(1, 16, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 5);
                std::vector<float> data;
                Ogre::AxisAlignedBox bounds;
                for (const Ogre::Vector4& i : instances)
                {
                    data.insert(data.end(), {i.x, i.y, i.z, i.w, 1.0f, 0.0f});
                    const Ogre::Vector3 at(i.x, i.y, i.z);
                    const Ogre::Real r =
                        i.w * std::max(treeBounds.getMaximum().length(), treeBounds.getMinimum().length());
                    bounds.merge(Ogre::AxisAlignedBox(at - r, at + r));
                }
                Ogre::HardwareVertexBufferSharedPtr buffer =
                    Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                        6 * sizeof(float), instances.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
                buffer->writeData(0, buffer->getSizeInBytes(), data.data(), true);
                buffer->setIsInstanceData(true);
                buffer->setInstanceDataStepRate(1);
                mRenderOp.vertexData->vertexBufferBinding->setBinding(1, buffer);
                mRenderOp.useIndexes = true;
                mRenderOp.indexData = new Ogre::IndexData();
                mRenderOp.indexData->indexBuffer = gpu.indexBuffer;
                mRenderOp.indexData->indexStart = 0;
                mRenderOp.indexData->indexCount = 6;
                mRenderOp.numberOfInstances = instances.size();
                setMaterial(Ogre::MaterialManager::getSingleton().getByName(material));
                setBoundingBox(bounds);
                mRadius = std::max(bounds.getMaximum().length(), bounds.getMinimum().length());
            }
            ~InstancedImpostor() override
            {
                delete mRenderOp.vertexData;
                delete mRenderOp.indexData;
            }
            Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override
            {
                return getParentNode()->getSquaredViewDepth(camera);
            }
            Ogre::Real getBoundingRadius() const override { return mRadius; }

        private:
            Ogre::Real mRadius = 0.0f;
            static int msSerial;
        };
        int InstancedImpostor::msSerial = 0;

        Ogre::AxisAlignedBox bounds(const TreeModel& m)
        {
            return Ogre::AxisAlignedBox(m.boundsMin.x, m.boundsMin.y, m.boundsMin.z, m.boundsMax.x, m.boundsMax.y,
                                        m.boundsMax.z);
        }

        /// The drawn impostors: owned here, no factory, so detached before clearContent.
        std::unique_ptr<InstancedImpostor>& drawn()
        {
            return OgreEnvironment::keep<std::unique_ptr<InstancedImpostor>>(
                "impostor.drawn", [] { return std::unique_ptr<InstancedImpostor>(); });
        }

        void clearContent()
        {
            if (drawn())
            {
                drawn()->detachFromParent();
                drawn().reset();
            }
            OgreEnvironment::renderer().clearContent();
        }

        /// Clear the content node and draw the impostor's instances (x, y, z, scale).
        void placeImpostors(const std::vector<Ogre::Vector4>& instances, bool shadowed)
        {
            const BakedOak& t = oak();
            clearContent();
            const ImpostorGpu& gpu = ImpostorResources::of(*t.asset).getGpu();
            drawn() = std::make_unique<InstancedImpostor>(
                gpu, instances, shadowed ? gpu.shadowedMaterial : gpu.material, bounds(t.model));
            OgreEnvironment::renderer().getContentNode().createChildSceneNode()->attachObject(drawn().get());
        }

        /// The polygonal reference at the same places.
        void placeReference(const std::vector<Ogre::Vector4>& instances)
        {
            const BakedOak& t = oak();
            OffscreenRenderer& r = OgreEnvironment::renderer();
            clearContent();
            Ogre::MeshPtr mesh = t.asset->getReferenceMesh();
            for (const Ogre::Vector4& i : instances)
            {
                Ogre::SceneNode* node = r.getContentNode().createChildSceneNode(Ogre::Vector3(i.x, i.y, i.z));
                node->setScale(Ogre::Vector3(i.w));
                node->attachObject(r.getSceneManager().createEntity(mesh));
            }
        }

        /// Width in pixels of the columns that hold anything but the background.
        int coveredWidth(const Image& image, const glm::vec3& background)
        {
            int first = image.width, last = -1;
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                    if (isTreePixel(image.at(x, y), background))
                    {
                        first = std::min(first, x);
                        last = std::max(last, x);
                    }
            return last >= first ? last - first + 1 : 0;
        }

        const glm::vec3 BACKGROUND = LightingSpec().background; // sRGB, as the images store it

        /// From azimuth `degrees` (0 = from +Z), 5 degrees up, the tree filling the view.
        CameraSpec view(const TreeModel& m, float degrees, float distanceFactor = 1.0f)
        {
            return CameraSpec::framing(m.boundsMin, m.boundsMax, degrees, 5.0f, distanceFactor);
        }
    }

    TEST(Impostor, getGpuBuildsTheQuadTexturesAndMaterials)
    {
        const BakedOak& t = oak();
        ASSERT_TRUE(t.asset);
        const ImpostorGpu& gpu = ImpostorResources::of(*t.asset).getGpu();
        EXPECT_EQ(&gpu, &ImpostorResources::of(*t.asset).getGpu()); // built once

        ASSERT_TRUE(gpu.vertexData);
        EXPECT_EQ(gpu.vertexData->vertexCount, 4u);
        ASSERT_TRUE(gpu.indexBuffer);
        EXPECT_EQ(gpu.indexBuffer->getNumIndexes(), 6u);
        EXPECT_EQ(gpu.gpuBytes, t.data.gpuBytes() + 4 * 5 * sizeof(float) + 6 * 2);
        EXPECT_LT(gpu.gpuBytes, 800u * 1024u); // RGBA8 by default (ImpostorOptions::compress)

        for (const auto& [name, chunk] : {std::make_pair(gpu.texture, &t.data.colour),
                                          std::make_pair(gpu.normalTexture, &t.data.normal)})
        {
            Ogre::TexturePtr texture = Ogre::TextureManager::getSingleton().getByName(name, Ogre::RGN_DEFAULT);
            ASSERT_TRUE(texture) << name;
            EXPECT_EQ(texture->getWidth(), chunk->width);
            EXPECT_EQ(texture->getHeight(), chunk->height);
            EXPECT_EQ(texture->getNumMipmaps() + 1, chunk->mipCount);
            EXPECT_EQ(texture->getFormat(), ogreFormat(chunk->format));
        }
        for (const Ogre::String& name : {gpu.material, gpu.shadowedMaterial})
        {
            Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(name, Ogre::RGN_DEFAULT);
            ASSERT_TRUE(material) << name;
            Ogre::Technique* tech = material->getBestTechnique();
            ASSERT_NE(tech, nullptr) << name << " has no supported technique";
            Ogre::Pass* pass = tech->getPass(0);
            EXPECT_EQ(pass->getTextureUnitState("Colour")->getTextureName(), gpu.texture);
            EXPECT_EQ(pass->getTextureUnitState("Normal")->getTextureName(), gpu.normalTexture);
            EXPECT_EQ(pass->getTextureUnitState("Shadow") != nullptr, name == gpu.shadowedMaterial);
            Ogre::MaterialPtr caster = tech->getShadowCasterMaterial();
            ASSERT_TRUE(caster) << name;
            EXPECT_EQ(caster->getName(), gpu.material + "/Caster");
            EXPECT_EQ(caster->getTechnique(0)->getPass(0)->getTextureUnitState("Colour")->getTextureName(),
                      gpu.texture);
        }
    }

    TEST(Impostor, missingChunkIsNamedAndUnloadFreesEverything)
    {
        OgreEnvironment::renderer();
        GeneratorOptions generator;
        generator.leafCount = 200;
        generator.textureSize = 16;
        Result<TreeModel> model = generateTree(generator);
        ASSERT_TRUE(model.ok());
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, model.value(), "plain").ok());
        TreeAssetPtr plain =
            TreeAssetManager::getSingleton().loadFromBytes("plain.impostor-test", Ogre::RGN_DEFAULT, writer.toBytes());
        try
        {
            ImpostorResources::of(*plain).getGpu();
            FAIL() << "a package without the impostor chunk must throw";
        }
        catch (const Ogre::Exception& e)
        {
            const std::string text = e.getDescription();
            EXPECT_NE(text.find("plain.impostor-test"), std::string::npos) << text;
            EXPECT_NE(text.find("chunk 'impostor' level 0"), std::string::npos) << text;
            EXPECT_NE(text.find("--technique impostor"), std::string::npos) << text;
        }

        ASSERT_TRUE(addImpostorChunk(writer, model.value(), "small").ok()); // the table's default options
        TreeAssetPtr small =
            TreeAssetManager::getSingleton().loadFromBytes("small.impostor-test", Ogre::RGN_DEFAULT, writer.toBytes());
        const ImpostorGpu& gpu = ImpostorResources::of(*small).getGpu();
        const std::vector<Ogre::String> materials = {gpu.material, gpu.shadowedMaterial, gpu.material + "/Caster"};
        const std::vector<Ogre::String> textures = {gpu.texture, gpu.normalTexture};
        for (const Ogre::String& m : materials)
            EXPECT_TRUE(Ogre::MaterialManager::getSingleton().resourceExists(m, Ogre::RGN_DEFAULT)) << m;
        small->unload();
        for (const Ogre::String& m : materials)
            EXPECT_FALSE(Ogre::MaterialManager::getSingleton().resourceExists(m, Ogre::RGN_DEFAULT)) << m;
        for (const Ogre::String& t : textures)
            EXPECT_FALSE(Ogre::TextureManager::getSingleton().resourceExists(t, Ogre::RGN_DEFAULT)) << t;
        small->load();
        EXPECT_TRUE(ImpostorResources::of(*small).getGpu().vertexData); // built again after a reload
        TreeAssetManager::getSingleton().remove(small);
        TreeAssetManager::getSingleton().remove(plain);
    }

    TEST(Impostor, quadFacesTheCameraAndLooksLikeTheTree)
    {
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.setShadows(false);
        const std::vector<Ogre::Vector4> one = {Ogre::Vector4(0, 0, 0, 1)};
        std::vector<Image> impostors, references;
        std::vector<int> widths;
        for (float azimuth : {0.0f, 90.0f, 225.0f})
        {
            const CameraSpec camera = view(t.model, azimuth);
            placeImpostors(one, false);
            impostors.push_back(toImage(r.render(camera, 160, 160, 2)));
            placeReference(one);
            references.push_back(toImage(r.render(camera, 160, 160, 2)));
            widths.push_back(coveredWidth(impostors.back(), BACKGROUND));
        }
        clearContent();
        writePng(OgreEnvironment::outDir() + "/impostor-azimuths.png",
                 sideBySide({impostors[0], impostors[1], impostors[2]}));
        writePng(OgreEnvironment::outDir() + "/impostor-vs-reference.png",
                 sideBySide({references[0], impostors[0], references[1], impostors[1]}));
        for (std::size_t i = 0; i < impostors.size(); ++i)
        {
            // Turned to the camera: as wide from every side (a fixed quad is a line from 90 degrees).
            // (The quad stands on the trunk axis, the camera aims at the bounds' centre: the
            // distance to the quad, and so its width, changes a little with the azimuth.)
            EXPECT_GT(treeCoverage(impostors[i], BACKGROUND), 0.08) << "view " << i;
            EXPECT_NEAR(double(widths[i]), double(widths[0]), 0.1 * double(widths[0])) << "view " << i;
            // Like the polygonal tree: the same size on screen, a small per-pixel error.
            const double coverage = treeCoverage(impostors[i], BACKGROUND);
            const double reference = treeCoverage(references[i], BACKGROUND);
            EXPECT_NEAR(coverage, reference, 0.25 * reference) << "view " << i;
            const double error = flipMean(references[i], impostors[i], FlipOver::Tree);
            std::printf("view %zu: impostor width %d px, coverage %.3f (reference %.3f), FLIP %.4f\n", i, widths[i],
                        coverage, reference, error);
            EXPECT_LT(error, 0.62) << "view " << i; // over the tree's pixels, measured 0.357-0.557
        }
        // From the side the bake saw (+Z), the picture is nearly the tree's own.
        EXPECT_LT(flipMean(references[0], impostors[0], FlipOver::Tree), flipMean(references[1], impostors[1], FlipOver::Tree) + 0.02);
        compareWithGolden(impostors[1], "oak-impostor", 0.02); // turned 90 degrees from the bake
    }

    // The impostor as a single tree: an ImpostorTree made by its factory draws the picture the
    // Forest's instanced quad draws for one instance at the origin, from every side.
    TEST(Impostor, impostorTreeDrawsWhatTheInstancedQuadDraws)
    {
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.setShadows(false);
        const Ogre::NameValuePairList params = {{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
        std::vector<Image> trees, quads;
        for (float azimuth : {0.0f, 120.0f})
        {
            const CameraSpec camera = view(t.model, azimuth);
            placeImpostors({Ogre::Vector4(0, 0, 0, 1)}, false);
            quads.push_back(toImage(r.render(camera, 160, 160, 2)));
            clearContent();
            Ogre::MovableObject* tree = r.getSceneManager().createMovableObject(
                "oak-impostor", ImpostorTreeFactory::FACTORY_TYPE_NAME, &params);
            ASSERT_EQ(tree->getMovableType(), ImpostorTreeFactory::FACTORY_TYPE_NAME);
            r.getContentNode().attachObject(tree);
            trees.push_back(toImage(r.render(camera, 160, 160, 2)));
            // The box the quad sweeps turning about +Y holds the tree's footprint.
            const Ogre::AxisAlignedBox box = tree->getBoundingBox();
            EXPECT_LE(box.getMinimum().y, t.model.boundsMin.y + 1e-3f);
            EXPECT_GE(box.getMaximum().y, t.model.boundsMax.y - 1e-3f);
            r.clearContent(); // destroys the object through its factory
            EXPECT_FALSE(r.getSceneManager().hasMovableObject("oak-impostor", ImpostorTreeFactory::FACTORY_TYPE_NAME));
        }
        writePng(OgreEnvironment::outDir() + "/impostor-tree-vs-instanced.png",
                 sideBySide({trees[0], quads[0], trees[1], quads[1]}));
        for (std::size_t i = 0; i < trees.size(); ++i)
        {
            EXPECT_GT(treeCoverage(trees[i], BACKGROUND), 0.08) << "view " << i;
            const double error = flipMean(quads[i], trees[i], FlipOver::Tree);
            std::printf("view %zu: ImpostorTree against the instanced quad FLIP %.5f\n", i, error);
            EXPECT_LT(error, 0.002) << "view " << i;
        }
        compareWithGolden(trees[1], "oak-impostor-tree", 0.02);
    }

    // The DXT-compressed impostor (ImpostorOptions::compress, off by default) draws what the
    // default RGBA8 one draws, through the same materials.
    TEST(Impostor, compressedImpostorDrawsWhatTheDefaultDraws)
    {
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.setShadows(false);
        ImpostorOptions options;
        options.aoRays = 8;
        options.compress = true;
        Result<ImpostorData> data = bakeImpostor(t.model, options, "oak");
        ASSERT_TRUE(data.ok()) << data.error().message();
        ASSERT_EQ(data->colour.format, GpuTextureFormat::DXT5);
        PackageWriter writer;
        ASSERT_TRUE(addReferenceChunk(writer, t.model, "oak").ok());
        ASSERT_TRUE(writer.addChunk(IMPOSTOR_CHUNK, 0, IMPOSTOR_CHUNK_FORMAT_VERSION, encodeImpostorChunk(*data)).ok());
        TreeAssetPtr dxt =
            TreeAssetManager::getSingleton().loadFromBytes("oak-dxt.impostor-test", Ogre::RGN_DEFAULT, writer.toBytes());
        const CameraSpec camera = view(t.model, 120.0f);
        std::vector<Image> images;
        for (const TreeAssetPtr& asset : {t.asset, dxt})
        {
            const Ogre::NameValuePairList params = {{"asset", asset->getName()}, {"group", asset->getGroup()}};
            r.getContentNode().attachObject(r.getSceneManager().createMovableObject(
                "oak-impostor-format", ImpostorTreeFactory::FACTORY_TYPE_NAME, &params));
            images.push_back(toImage(r.render(camera, 160, 160, 2)));
            r.clearContent();
        }
        TreeAssetManager::getSingleton().remove(dxt);
        writePng(OgreEnvironment::outDir() + "/impostor-rgba8-vs-dxt.png", sideBySide(images));
        EXPECT_GT(treeCoverage(images[1], BACKGROUND), 0.08);
        const double error = flipMean(images[0], images[1], FlipOver::Tree);
        std::printf("DXT against RGBA8 impostor: FLIP %.4f\n", error);
        EXPECT_LT(error, 0.07); // over the tree's pixels, measured 0.058
    }

    // A missing asset parameter and an asset without the chunk are named.
    TEST(Impostor, impostorTreeFactoryNamesWhatIsMissing)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        try
        {
            r.getSceneManager().createMovableObject("no-asset", ImpostorTreeFactory::FACTORY_TYPE_NAME);
            ADD_FAILURE() << "no asset parameter must throw";
        }
        catch (const Ogre::Exception& e)
        {
            EXPECT_NE(e.getDescription().find("parameter 'asset' is required"), std::string::npos) << e.getDescription();
        }
    }

    TEST(Impostor, instancesScaleCastAndReceiveShadows)
    {
        // Three trees in a row on a white ground, the middle one twice as big and farther: each
        // instance has its own place and scale. Under texture shadows the quads cast on the
        // ground (the caster faces the sun) and on themselves (the receiver faces the camera).
        const BakedOak& t = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        const float h = t.model.boundsMax.y - t.model.boundsMin.y;
        const std::vector<Ogre::Vector4> row = {Ogre::Vector4(-2.0f * h, 0, 0, 1), Ogre::Vector4(0, 0, -0.5f * h, 2),
                                                Ogre::Vector4(2.0f * h, 0, 0, 1)};
        CameraSpec camera;
        camera.position = glm::vec3(0.0f, 1.5f * h, 4.5f * h);
        camera.target = glm::vec3(0.0f, 0.4f * h, 0.0f);
        camera.nearClip = 0.1f * h;
        camera.farClip = 20.0f * h;
        Ogre::MeshPtr plane = Ogre::MeshManager::getSingleton().getByName("impostor-test-ground", Ogre::RGN_DEFAULT);
        if (!plane)
            plane = Ogre::MeshManager::getSingleton().createPlane(
                "impostor-test-ground", Ogre::RGN_DEFAULT, Ogre::Plane(Ogre::Vector3::UNIT_Y, 0.0f), 12.0f * h,
                12.0f * h, 1, 1, true, 1, 1.0f, 1.0f, Ogre::Vector3::NEGATIVE_UNIT_Z);
        auto render = [&](bool shadows) {
            placeImpostors(row, shadows);
            Ogre::Entity* ground = r.getSceneManager().createEntity(plane);
            ground->setMaterialName(shadows ? "TreeLod/BarkShadowed" : "TreeLod/Bark");
            ground->setCastShadows(false);
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            r.setShadows(shadows, 1024, ShadowCamera::Focused);
            return toImage(r.render(camera, 256, 128, 2));
        };
        const Image plain = render(false);
        const Image shadowed = render(true);
        r.setShadows(false);
        clearContent();
        writePng(OgreEnvironment::outDir() + "/impostor-row-shadows.png", sideBySide({plain, shadowed}));

        // Tree pixels are the dark ones (sky 0.7, sunlit white ground 1.0 in luminance).
        auto luminance = [](const glm::vec4& p) { return 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b; };
        auto widthIn = [&](int x0, int x1) {
            int first = x1, last = -1;
            for (int y = 0; y < plain.height; ++y)
                for (int x = x0; x < x1; ++x)
                    if (luminance(plain.at(x, y)) < 0.45)
                    {
                        first = std::min(first, x);
                        last = std::max(last, x);
                    }
            return last >= first ? last - first + 1 : 0;
        };
        const int left = widthIn(0, 90), middle = widthIn(90, 166), right = widthIn(166, 256);
        double treeDrop = 0.0;
        std::size_t treePixels = 0, groundShadow = 0;
        for (std::size_t i = 0; i < plain.pixels.size(); ++i)
        {
            const double before = luminance(plain.pixels[i]), after = luminance(shadowed.pixels[i]);
            if (before < 0.45)
            {
                treeDrop += before - after;
                ++treePixels;
            }
            groundShadow += before > 0.95 && after < before - 0.1;
        }
        treeDrop /= double(std::max<std::size_t>(treePixels, 1));
        std::printf("widths: %d %d %d px; crowns darker by %.4f, %zu ground pixels in shadow\n", left, middle, right,
                    treeDrop, groundShadow);
        EXPECT_GT(left, 10);
        EXPECT_NEAR(double(left), double(right), 0.15 * double(left));
        EXPECT_GT(double(middle), 1.5 * double(left));
        EXPECT_GT(treeDrop, 0.005);     // received: the crowns shade themselves
        EXPECT_GT(groundShadow, 100u);  // cast: on the ground
        EXPECT_EQ(shadowed.pixels[0], plain.pixels[0]); // the sky is untouched
        compareWithGolden(shadowed, "oak-impostor-shadows", 0.02);
    }
}

namespace TreeLod::ImpostorTreeTests
{
    TEST(Impostor, materialLodBiasActsAsEntitys)
    {
        // One quad, one mesh level. The material's own LoD strategy and values pick its technique,
        // biased and clamped by setMaterialLodBias: here a second technique beyond 1 m.
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.clearContent();
        r.setShadows(false);
        const BakedOak& t = oak();
        Ogre::NameValuePairList params{{"asset", t.asset->getName()}, {"group", t.asset->getGroup()}};
        auto* tree = static_cast<ImpostorTree*>(r.getSceneManager().createMovableObject(
            "impostor-lod-bias", ImpostorTreeFactory::FACTORY_TYPE_NAME, &params));
        r.getContentNode().attachObject(tree);
        const Ogre::MaterialPtr& material = tree->getMaterial();
        Ogre::Technique* far = material->createTechnique();
        *far = *material->getTechnique(0);
        far->setLodIndex(1);
        material->setLodLevels({1.0f});
        material->compile();
        const CameraSpec view = CameraSpec::framing(t.model.boundsMin, t.model.boundsMax, 30.0f, 10.0f, 4.0f);
        r.render(view, 64, 64, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 1u);
        EXPECT_EQ(tree->getTechnique(), far);
        tree->setMaterialLodBias(1e6f);
        r.render(view, 64, 64, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        tree->setMaterialLodBias(1.0f, 0, 0);
        r.render(view, 64, 64, 1);
        EXPECT_EQ(tree->getMaterialLodIndex(), 0u);
        tree->setMeshLodBias(2.0f);
        EXPECT_FLOAT_EQ(tree->getLodBias().meshFactor, 2.0f);
        EXPECT_THROW(tree->setMeshLodBias(-1.0f), Ogre::InvalidParametersException);
        material->removeTechnique(1);
        material->setLodLevels({});
        material->compile();
        r.clearContent();
    }
}
