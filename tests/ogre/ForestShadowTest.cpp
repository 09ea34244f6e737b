// The Forest's shadows through Plugin_TreeLod: texture shadows cast and received, PSSM reaching the
// far trees, casters following Ogre's shadow technique (stencil refused), and an application drawn
// by the RTSS.
#include "ForestTestSupport.h"

namespace TreeLod
{
    TEST(Forest, castsAndReceivesTextureShadows)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        // A ground material receiving the sun's shadow (TreeLod/BarkShadowed, untextured).
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const char* suffix : {"", "Shadowed"})
        {
            const Ogre::String name = Ogre::String("ForestTest/Ground") + suffix;
            if (materials.resourceExists(name, "TreeLod"))
                continue;
            Ogre::MaterialPtr ground =
                materials.getByName(Ogre::String("TreeLod/Bark") + suffix, "TreeLod")->clone(name);
            ground->getTechnique(0)->getPass(0)->getFragmentProgramParameters()->setNamedConstant(
                "baseColour", Ogre::ColourValue(0.45f, 0.5f, 0.3f, 1.0f));
            ground->load();
        }
        auto place = [&](const std::function<void(Ogre::SceneNode&)>& trees, bool shadowed) {
            r.clearContent();
            Ogre::ManualObject* ground = sm.createManualObject();
            ground->setCastShadows(false);
            ground->begin(shadowed ? "ForestTest/GroundShadowed" : "ForestTest/Ground",
                          Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float s = 4.0f * h;
            for (const glm::vec2 c : {glm::vec2(-s, -s), glm::vec2(s, -s), glm::vec2(s, s), glm::vec2(-s, s)})
            {
                ground->position(c.x, 0.0f, c.y);
                ground->normal(0.0f, 1.0f, 0.0f);
                ground->textureCoord(0.0f, 0.0f);
            }
            ground->quad(0, 3, 2, 1); // counter-clockwise seen from above
            ground->end();
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            trees(*r.getContentNode().createChildSceneNode());
        };
        const std::vector<ForestInstance> trees = {instance(-0.6f * h, 0, 0.3f * h, 0.5f, 0.9f),
                                                   instance(0.5f * h, 0, -0.4f * h, 2.0f, 1.1f)};
        // The polygonal trees: the Forest's mesh level against Entities of the reference mesh
        // with its shadow-receiving materials and full bark detail.
        // A Forest of `trees` drawn with `levels`.
        auto forestOf = [&](const std::vector<ForestLevel>& levels) {
            return [&, levels](Ogre::SceneNode& node) {
                static int serial = 0;
                auto* forest =
                    static_cast<Forest*>(sm.createMovableObject("forestShadow" + std::to_string(serial++), "Forest"));
                forest->addSpecies(tree.asset, levels);
                forest->addInstances(trees);
                node.attachObject(forest);
            };
        };
        const auto forestTrees = forestOf({ForestLevel{"mesh", 0, false, 0.0f}});
        auto separateTrees = [&](Ogre::SceneNode& node) {
            const std::vector<Ogre::String>& plainNames = tree.asset->getMaterialNames();
            const std::vector<Ogre::String>& shadowedNames = tree.asset->getShadowedMaterialNames();
            for (const ForestInstance& t : trees)
            {
                Ogre::SceneNode* child = instanceNode(node, t);
                Ogre::Entity* entity = sm.createEntity(tree.asset->getReferenceMesh());
                entity->setMeshLodBias(1.0f, 0, 0);
                for (unsigned i = 0; i < entity->getNumSubEntities(); ++i)
                {
                    Ogre::SubEntity* sub = entity->getSubEntity(i);
                    const auto it = std::find(plainNames.begin(), plainNames.end(), sub->getMaterialName());
                    ASSERT_NE(it, plainNames.end());
                    sub->setMaterialName(shadowedNames[std::size_t(it - plainNames.begin())], tree.asset->getGroup());
                }
                child->attachObject(entity);
            }
        };
        const CameraSpec view = look(glm::vec3(0.5f * h, 1.3f * h, 2.3f * h), glm::vec3(0.0f, 0.25f * h, 0.0f), 45.0f);
        place(forestTrees, false);
        const Image plain = toImage(r.render(view, 192, 160, 2));
        place(forestTrees, true);
        r.setShadows(true, 1024);
        const Image shadowed = toImage(r.render(view, 192, 160, 2));
        place(separateTrees, true);
        const Image separate = toImage(r.render(view, 192, 160, 2));
        // Billboard clouds (their own levels): the cloud's instanced casters against BillboardCloudTrees'.
        const auto forestClouds = forestOf(Forest::levelsForBands(*tree.asset, {{"billboard-cloud", 0.0f}}));
        auto separateClouds = [&](Ogre::SceneNode& node) {
            static int serial = 0;
            for (const ForestInstance& t : trees)
            {
                Ogre::SceneNode* child = instanceNode(node, t);
                Ogre::NameValuePairList params{{"asset", tree.asset->getName()}};
                child->attachObject(sm.createMovableObject("cloudShadow" + std::to_string(serial++),
                                                           BillboardCloudTreeFactory::FACTORY_TYPE_NAME, &params));
            }
        };
        place(forestClouds, true);
        const Image cloudForest = toImage(r.render(view, 192, 160, 2));
        place(separateClouds, true);
        const Image cloudSeparate = toImage(r.render(view, 192, 160, 2));
        // Shadow LoD bias: the view keeps its levels (the mesh), the casters drop to the quad.
        Forest* biased = nullptr;
        auto meshOrQuad = [&](Ogre::Real shadowLodBias) {
            return [&, shadowLodBias](Ogre::SceneNode& node) {
                forestOf({ForestLevel{"mesh", 0, false, 1.0f}, ForestLevel{"impostor", 0, false, 0.0f}})(node);
                biased = static_cast<Forest*>(node.getAttachedObject(0));
                biased->setShadowLodBias(shadowLodBias);
            };
        };
        place(meshOrQuad(1.0f), true);
        const Image casterMesh = toImage(r.render(view, 192, 160, 2));
        place(meshOrQuad(1e-9f), true);
        const Image casterQuad = toImage(r.render(view, 192, 160, 2));
        EXPECT_EQ(biased->getStats().levelCounts.at(0), (std::vector<std::uint32_t>{2u, 0u})) << "the view's levels";
        EXPECT_THROW(biased->setShadowLodBias(0.0f), Ogre::InvalidParametersException);
        EXPECT_THROW(biased->setShadowLodBias(std::nanf("")), Ogre::InvalidParametersException);
        // LiSPSM (García et al. 2007 §5.2): a perspective shadow camera with its own matrices culls too.
        place(forestTrees, true);
        r.setShadows(true, 1024, ShadowCamera::LiSPSM);
        const Image lispsm = toImage(r.render(view, 192, 160, 2));
        r.setShadows(false);
        r.clearContent();
        const double drop = meanLuminance(plain) - meanLuminance(shadowed);
        const double error = flipMean(shadowed, separate);
        std::printf("shadows: luminance drop %.4f, Forest vs separate Entities FLIP %.5f\n", drop, error);
        EXPECT_GT(drop, 0.01) << "the trees' shadows must darken the ground and the crowns";
        const double cloudError = flipMean(cloudForest, cloudSeparate);
        std::printf("shadows: billboard-cloud Forest vs separate BillboardCloudTrees FLIP %.5f\n", cloudError);
        EXPECT_LT(cloudError, 0.015);
        const double dropLispsm = meanLuminance(plain) - meanLuminance(lispsm);
        std::printf("LiSPSM: luminance drop %.4f\n", dropLispsm);
        EXPECT_NEAR(dropLispsm, drop, 0.5 * drop);
        // Not 0: the focused shadow camera frames the Forest's bounds (spheres), not the
        // Entities' boxes, so the shadow texels fall differently.
        EXPECT_LT(error, 0.015) << "instanced casters and receivers as the separate objects'";
        const double sameCasters = flipMean(casterMesh, shadowed), quadCasters = flipMean(casterQuad, casterMesh);
        const double dropQuadCasters = meanLuminance(plain) - meanLuminance(casterQuad);
        std::printf("shadow LoD bias: mesh casters vs the mesh Forest FLIP %.5f, quad casters vs mesh casters FLIP "
                    "%.5f, luminance drop %.4f\n", sameCasters, quadCasters, dropQuadCasters);
        // Not 0 either: this Forest's bounds hold the quad level too (the focused camera frames them).
        EXPECT_LT(sameCasters, 0.015) << "bias 1: the casters are the view's levels";
        EXPECT_GT(quadCasters, 3.0 * sameCasters) << "bias 1e-9: the casters must be the quads";
        EXPECT_GT(dropQuadCasters, 0.25 * drop) << "quad casters still shade the ground";
        writePng(OgreEnvironment::outDir() + "/forest-shadows-strip.png",
                 sideBySide({plain, shadowed, separate, lispsm, cloudForest, cloudSeparate, casterMesh, casterQuad}));
        compareWithGolden(shadowed, "forest-shadows", 0.02);
    }

    /// Texture shadows for the tests below: Forest trees (mesh level) on a ground (placeGround), or
    /// none where `groundSize` is 0.
    void placeShadowScene(const std::vector<ForestInstance>& trees, float groundSize, bool receiving)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        r.clearContent();
        if (groundSize > 0.0f)
            placeGround(groundSize, receiving);
        static int serial = 0;
        auto* forest = static_cast<Forest*>(sm.createMovableObject("shadowSetup" + std::to_string(serial++), "Forest"));
        forest->addSpecies(oak().asset, {ForestLevel{"mesh", 0, false, 0.0f}});
        forest->addInstances(trees);
        r.getContentNode().createChildSceneNode()->attachObject(forest);
    }

    /// Whether a render target's texture reads back (RenderSystem_GLES2 reads zeros: ES has no
    /// texture read-back).
    bool texturesReadBack()
    {
        return Ogre::Root::getSingleton().getRenderSystem()->getName().find("OpenGL ES") == Ogre::String::npos;
    }

    /// Mean luminance of the rows [top, bottom) of `image` (fractions of its height).
    double bandLuminance(const Image& image, double top, double bottom)
    {
        Image band;
        band.width = image.width;
        const int y0 = int(top * image.height), y1 = int(bottom * image.height);
        band.height = y1 - y0;
        band.pixels.assign(image.pixels.begin() + std::ptrdiff_t(y0) * image.width,
                           image.pixels.begin() + std::ptrdiff_t(y1) * image.width);
        return meanLuminance(band);
    }

    // PSSM (three splits, as OGRE's Terrain sample) through setupSunShadows: every split's texture
    // holds casters, and the receivers read the far splits too, so the far trees' shadows are there.
    TEST(Forest, pssmShadowsReachTheFarTrees)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        // The first tree stands within the first split (about 0.5 h from a near clip of 0.05 h).
        std::vector<ForestInstance> row;
        for (int i = 0; i < 8; ++i)
            row.push_back(instance((i % 2 ? 0.5f : -0.5f) * h, 0.0f, -1.6f * h * float(i), 0.7f * float(i)));
        CameraSpec view = look(glm::vec3(0.1f * h, 0.6f * h, 0.5f * h), glm::vec3(0.0f, 0.3f * h, -6.0f * h), 60.0f);
        view.nearClip = 0.05f * h;
        const float far = 12.0f * h;
        r.setShadowFarDistance(far);
        auto render = [&](Ogre::ShadowTechnique technique, ShadowCamera camera) {
            SunShadowSettings settings;
            settings.technique = technique;
            settings.camera = camera;
            settings.textureSize = 1024;
            placeShadowScene(row, 20.0f * h, technique != Ogre::SHADOWTYPE_NONE);
            r.setShadows(settings);
            r.render(view, 256, 160, 1); // Ogre frames shadow cameras with the previous frame's receivers
            return toImage(r.render(view, 256, 160, 2));
        };
        const Image plain = render(Ogre::SHADOWTYPE_NONE, ShadowCamera::Focused);
        const Image focused = render(Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED, ShadowCamera::Focused);
        const Image pssm = render(Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED, ShadowCamera::PSSM);
        ASSERT_EQ(sm.getShadowTextureConfigList().size(), std::size_t(PSSM_SPLITS));
        std::vector<double> casterFraction;
        for (std::size_t i = 0; i < std::size_t(texturesReadBack() ? PSSM_SPLITS : 0); ++i)
        {
            const Ogre::TexturePtr& texture = sm.getShadowTexture(i);
            ASSERT_EQ(texture->getFormat(), Ogre::PF_FLOAT32_R);
            std::vector<float> depth(texture->getWidth() * texture->getHeight());
            texture->getBuffer()->blitToMemory(
                Ogre::PixelBox(texture->getWidth(), texture->getHeight(), 1, Ogre::PF_FLOAT32_R, depth.data()));
            casterFraction.push_back(double(std::count_if(depth.begin(), depth.end(), [](float d) { return d < 1.0f; })) /
                                     double(depth.size()));
        }
        r.setShadows(false);
        r.setShadowFarDistance(0.0f);
        r.clearContent();
        const double nearDrop = bandLuminance(plain, 0.6, 1.0) - bandLuminance(pssm, 0.6, 1.0);
        const double farDrop = bandLuminance(plain, 0.3, 0.6) - bandLuminance(pssm, 0.3, 0.6);
        const double focusedDrop = meanLuminance(plain) - meanLuminance(focused);
        for (double f : casterFraction)
            std::printf("PSSM: casters cover %.3f of a split's texture\n", f);
        std::printf("PSSM: luminance drop near %.4f, far %.4f; focused drop %.4f, PSSM %.4f\n", nearDrop, farDrop,
                    focusedDrop, meanLuminance(plain) - meanLuminance(pssm));
        writePng(OgreEnvironment::outDir() + "/forest-shadows-pssm-strip.png", sideBySide({plain, focused, pssm}));
        for (double f : casterFraction)
            EXPECT_GT(f, 0.001) << "every split's texture holds casters";
        EXPECT_GT(nearDrop, 0.014) << "the near trees' shadows (the first splits)";
        EXPECT_GT(farDrop, 0.01) << "the far trees' shadows: the receivers read the far splits (0.006 with the first only)";
        EXPECT_NEAR(meanLuminance(plain) - meanLuminance(pssm), focusedDrop, 0.5 * focusedDrop);
        compareWithGolden(pssm, "forest-shadows-pssm", 0.02);
    }

    // Ogre's colour texture shadows: the casters write what Ogre's own caster pass would (the
    // shadow colour, black), and the trees, casters that do not receive there, draw as unshadowed.
    // Stencil shadows are refused by setupSunShadows and logged once by the objects.
    TEST(Forest, castersFollowOgresShadowTechniqueAndStencilIsRefused)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        const std::vector<ForestInstance> trees = {instance(-0.6f * h, 0, 0.3f * h, 0.5f, 0.9f),
                                                   instance(0.5f * h, 0, -0.4f * h, 2.0f, 1.1f)};
        const CameraSpec view = look(glm::vec3(0.5f * h, 1.3f * h, 2.3f * h), glm::vec3(0.0f, 0.25f * h, 0.0f), 45.0f);
        placeShadowScene(trees, 0.0f, false);
        r.setShadows(false);
        const Image plain = toImage(r.render(view, 160, 128, 1));
        /// The shadow texture's darkest and brightest red, 0..1.
        auto textureRange = [&] {
            const Ogre::TexturePtr& texture = sm.getShadowTexture(0);
            std::vector<float> red(texture->getWidth() * texture->getHeight() * 4);
            texture->getBuffer()->blitToMemory(
                Ogre::PixelBox(texture->getWidth(), texture->getHeight(), 1, Ogre::PF_FLOAT32_RGBA, red.data()));
            float lo = 1e9f, hi = -1e9f;
            for (std::size_t i = 0; i < red.size(); i += 4)
            {
                lo = std::min(lo, red[i]);
                hi = std::max(hi, red[i]);
            }
            return std::make_pair(lo, hi);
        };
        sm.setShadowColour(Ogre::ColourValue(0.25f, 0.25f, 0.25f));
        for (Ogre::ShadowTechnique technique : {Ogre::SHADOWTYPE_TEXTURE_MODULATIVE, Ogre::SHADOWTYPE_TEXTURE_ADDITIVE,
                                                Ogre::SHADOWTYPE_TEXTURE_ADDITIVE_INTEGRATED})
        {
            SunShadowSettings settings;
            settings.technique = technique;
            settings.textureSize = 512;
            r.setShadows(settings);
            const Image shadowed = toImage(r.render(view, 160, 128, 1));
            const bool integrated = technique & Ogre::SHADOWDETAILTYPE_INTEGRATED;
            if (!integrated)
            {
                EXPECT_LT(flipMean(shadowed, plain), 0.002) << "casters do not receive colour shadows";
            }
            if (!texturesReadBack())
                continue;
            const auto [lo, hi] = textureRange();
            std::printf("shadow technique %d: shadow texture red %.3f..%.3f; FLIP against unshadowed %.5f\n",
                        int(technique), lo, hi, flipMean(shadowed, plain));
            EXPECT_FLOAT_EQ(hi, 1.0f) << "cleared where nothing casts";
            if (technique == Ogre::SHADOWTYPE_TEXTURE_MODULATIVE)
            {
                EXPECT_NEAR(lo, 0.25f, 0.01f) << "modulative casters write the shadow colour";
            }
            else if (!integrated)
            {
                EXPECT_NEAR(lo, 0.0f, 0.01f) << "additive casters write black";
            }
            else
            {
                EXPECT_GT(lo, 0.0f) << "integrated casters write depth";
                EXPECT_LT(lo, 1.0f);
            }
        }
        // Stencil: refused by the set-up, logged once by the objects when set on Ogre directly.
        SunShadowSettings stencil;
        stencil.technique = Ogre::SHADOWTYPE_STENCIL_MODULATIVE;
        try
        {
            r.setShadows(stencil);
            ADD_FAILURE() << "stencil shadows must be refused";
        }
        catch (const Ogre::InvalidParametersException& e)
        {
            EXPECT_NE(e.getDescription().find("stencil"), std::string::npos) << e.getDescription();
        }
        struct Counter : Ogre::LogListener
        {
            int stencilLines = 0;
            void messageLogged(const Ogre::String& message, Ogre::LogMessageLevel, bool, const Ogre::String&,
                               bool&) override
            {
                stencilLines += message.find("do not support stencil shadows") != Ogre::String::npos;
            }
        } counter;
        Ogre::LogManager::getSingleton().getDefaultLog()->addListener(&counter);
        sm.setShadowTechnique(Ogre::SHADOWTYPE_STENCIL_MODULATIVE);
        const Image stencilled = toImage(r.render(view, 160, 128, 1));
        r.render(view, 160, 128, 1);
        Ogre::LogManager::getSingleton().getDefaultLog()->removeListener(&counter);
        r.setShadows(false);
        r.clearContent();
        EXPECT_EQ(counter.stencilLines, 1) << "one log line per scene manager";
        EXPECT_LT(flipMean(stencilled, plain), 0.002) << "trees draw unshadowed under stencil shadows";
    }

    /// An application's own materials drawn by OGRE's RTSS (the way OgreBites does it): the
    /// shader generator on the renderer's scene manager, its scheme on the viewport, techniques
    /// generated for materials without programs; with `pssm`, the RTSS's integrated PSSM
    /// receiver (IntegratedPSSM3, as OGRE's Shadows and Terrain samples) on the generated
    /// techniques. Undone by its destructor.
    class RtssApplication : public Ogre::MaterialManager::Listener
    {
    public:
        RtssApplication()
        {
            Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
            for (const char* folder : {"/RTShaderLib/GLSL", "/RTShaderLib/materials"})
                rgm.addResourceLocation(ogreMediaDirectory() + folder, "FileSystem", GROUP);
            rgm.initialiseResourceGroup(GROUP);
            EXPECT_TRUE(Ogre::RTShader::ShaderGenerator::initialize());
            mGenerator = Ogre::RTShader::ShaderGenerator::getSingletonPtr();
            mGenerator->addSceneManager(&OgreEnvironment::renderer().getSceneManager());
            Ogre::MaterialManager::getSingleton().addListener(this);
            OgreEnvironment::renderer().setMaterialScheme(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
        }
        ~RtssApplication() override
        {
            OgreEnvironment::renderer().setMaterialScheme(Ogre::MaterialManager::DEFAULT_SCHEME_NAME);
            Ogre::MaterialManager::getSingleton().removeListener(this);
            Ogre::RTShader::ShaderGenerator::destroy();
            Ogre::ResourceGroupManager::getSingleton().destroyResourceGroup(GROUP);
        }

        /// Integrated PSSM receiving on every generated technique, split at the scene manager's
        /// PSSM camera setup's points.
        void receivePssm()
        {
            auto* setup = dynamic_cast<Ogre::PSSMShadowCameraSetup*>(
                OgreEnvironment::renderer().getSceneManager().getShadowCameraSetup().get());
            ASSERT_TRUE(setup);
            Ogre::RTShader::RenderState* state =
                mGenerator->getRenderState(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
            if (!mPssm)
            {
                mPssm = static_cast<Ogre::RTShader::IntegratedPSSM3*>(
                    mGenerator->createSubRenderState(Ogre::RTShader::IntegratedPSSM3::Type));
                state->addTemplateSubRenderState(mPssm);
            }
            mPssm->setSplitPoints(setup->getSplitPoints());
            mGenerator->invalidateScheme(Ogre::RTShader::ShaderGenerator::DEFAULT_SCHEME_NAME);
        }

        Ogre::Technique* handleSchemeNotFound(unsigned short, const Ogre::String& scheme, Ogre::Material* material,
                                              unsigned short, const Ogre::Renderable*) override
        {
            // TreeLod's materials have programs: the RTSS leaves them, Ogre draws their own technique.
            if (!mGenerator->createShaderBasedTechnique(*material, Ogre::MaterialManager::DEFAULT_SCHEME_NAME, scheme))
                return nullptr;
            mGenerator->validateMaterial(scheme, material->getName(), material->getGroup());
            for (Ogre::Technique* technique : material->getTechniques())
                if (technique->getSchemeName() == scheme)
                    return technique;
            return nullptr;
        }

    private:
        static constexpr const char* GROUP = "ForestTest/Rtss";
        Ogre::RTShader::ShaderGenerator* mGenerator = nullptr;
        Ogre::RTShader::IntegratedPSSM3* mPssm = nullptr;
    };

    // The application's set-up, not TreeLod's: an RTSS-drawn ground receives the trees' shadows
    // (integrated PSSM through the RTSS; Ogre's modulative texture shadows), and an application
    // object, cast with TreeLod/BarkCaster as the scene's caster material, shadows the trees.
    TEST(Forest, shadowsInAnRtssApplication)
    {
        const ForestTree& tree = oak();
        OffscreenRenderer& r = OgreEnvironment::renderer();
        Ogre::SceneManager& sm = r.getSceneManager();
        const float h = treeHeight(tree.model);
        RtssApplication application;
        Ogre::MaterialManager& materials = Ogre::MaterialManager::getSingleton();
        for (const auto& [name, colour] : {std::make_pair("ForestTest/AppGround", Ogre::ColourValue(0.45f, 0.5f, 0.3f)),
                                           std::make_pair("ForestTest/AppBox", Ogre::ColourValue(0.6f, 0.6f, 0.6f))})
            if (!materials.resourceExists(name, "TreeLod"))
            {
                Ogre::MaterialPtr material = materials.create(name, "TreeLod");
                Ogre::Pass* pass = material->getTechnique(0)->getPass(0);
                pass->setAmbient(colour);
                pass->setDiffuse(colour);
                material->setReceiveShadows(std::string(name) == "ForestTest/AppGround");
            }
        const LightingSpec lighting;
        const glm::vec3 treeAt(0.0f, 0.0f, 0.0f);
        const glm::vec3 boxAt = treeAt + glm::vec3(0.0f, 0.6f * h, 0.0f) + lighting.sunDirection * (0.9f * h);
        Ogre::MovableObject* forest = nullptr;
        Ogre::MovableObject* box = nullptr;
        auto place = [&](bool trees) {
            r.clearContent();
            Ogre::ManualObject* ground = sm.createManualObject();
            ground->setCastShadows(false);
            ground->begin("ForestTest/AppGround", Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float s = 6.0f * h;
            for (const glm::vec2 c : {glm::vec2(-s, -s), glm::vec2(s, -s), glm::vec2(s, s), glm::vec2(-s, s)})
            {
                ground->position(c.x, 0.0f, c.y);
                ground->normal(0.0f, 1.0f, 0.0f);
            }
            ground->quad(0, 3, 2, 1);
            ground->end();
            r.getContentNode().createChildSceneNode()->attachObject(ground);
            auto* cube = sm.createManualObject();
            cube->begin("ForestTest/AppBox", Ogre::RenderOperation::OT_TRIANGLE_LIST, "TreeLod");
            const float b = 0.2f * h;
            for (int face = 0; face < 6; ++face)
            {
                const int axis = face / 2;
                const float sign = face % 2 ? -1.0f : 1.0f;
                Ogre::Vector3 n(0.0f), u(0.0f), v(0.0f);
                n[axis] = sign;
                u[(axis + 1) % 3] = 1.0f;
                v[(axis + 2) % 3] = sign;
                const Ogre::Vector3 base(boxAt.x, boxAt.y, boxAt.z);
                for (const auto& [du, dv] : {std::make_pair(-1.0f, -1.0f), std::make_pair(1.0f, -1.0f),
                                            std::make_pair(1.0f, 1.0f), std::make_pair(-1.0f, 1.0f)})
                {
                    cube->position(base + b * (n + du * u + dv * v));
                    cube->normal(n);
                }
                cube->quad(Ogre::uint32(4 * face), Ogre::uint32(4 * face + 1), Ogre::uint32(4 * face + 2),
                           Ogre::uint32(4 * face + 3));
            }
            cube->end();
            box = cube;
            r.getContentNode().createChildSceneNode()->attachObject(cube);
            forest = nullptr;
            if (trees)
            {
                static int serial = 0;
                auto* f = static_cast<Forest*>(sm.createMovableObject("rtssForest" + std::to_string(serial++), "Forest"));
                f->addSpecies(tree.asset, {ForestLevel{"mesh", 0, false, 0.0f}});
                f->addInstances({instance(treeAt.x, treeAt.y, treeAt.z, 0.5f), instance(-1.2f * h, 0.0f, -0.8f * h, 2.0f)});
                r.getContentNode().createChildSceneNode()->attachObject(f);
                forest = f;
            }
        };
        const CameraSpec view = look(glm::vec3(0.6f * h, 0.9f * h, 1.7f * h), glm::vec3(-0.4f * h, 0.3f * h, -0.3f * h), 50.0f);
        auto render = [&](bool treesCast, bool boxCasts) {
            if (forest)
                forest->setCastShadows(treesCast);
            box->setCastShadows(boxCasts);
            r.render(view, 192, 144, 1); // shadow cameras framed by this view's receivers
            return toImage(r.render(view, 192, 144, 1));
        };
        // Which pixels are trees: they differ from the scene without trees (both unshadowed).
        r.setShadows(false);
        place(false);
        const Image noTrees = render(false, false);
        place(true);
        const Image unshadowed = render(false, false);
        std::vector<bool> treePixel(unshadowed.pixels.size());
        for (std::size_t i = 0; i < treePixel.size(); ++i)
            treePixel[i] = glm::length(glm::vec3(unshadowed.pixels[i] - noTrees.pixels[i])) > 0.02f;
        auto meanOver = [&](const Image& image, bool trees) {
            double sum = 0.0;
            std::size_t n = 0;
            for (std::size_t i = 0; i < treePixel.size(); ++i)
                if (treePixel[i] == trees)
                {
                    const glm::vec4& p = image.pixels[i];
                    sum += pixelLuminance(p);
                    ++n;
                }
            return n ? sum / double(n) : 0.0;
        };
        sm.setShadowTextureCasterMaterial(materials.getByName("TreeLod/BarkCaster", "TreeLod"));
        // Integrated PSSM: TreeLod's receivers and the RTSS's read the same depth textures.
        SunShadowSettings settings;
        settings.camera = ShadowCamera::PSSM;
        settings.textureSize = 1024;
        settings.farDistance = 12.0f * h;
        r.setShadows(settings);
        r.render(view, 192, 144, 1); // the view's near clip sets the split points
        application.receivePssm();
        const Image pssmNoCasters = render(false, false);
        const Image pssmTrees = render(true, false);
        const Image pssmBox = render(true, true);
        // Ogre's modulative texture shadows: the RTSS draws Ogre's receiver pass on the ground.
        settings.technique = Ogre::SHADOWTYPE_TEXTURE_MODULATIVE;
        settings.camera = ShadowCamera::Focused;
        r.setShadows(settings);
        const Image modulativeNoCasters = render(false, false);
        const Image modulativeTrees = render(true, false);
        sm.setShadowTextureCasterMaterial(Ogre::MaterialPtr());
        r.setShadows(false);
        r.clearContent();
        const double groundDrop = meanOver(pssmNoCasters, false) - meanOver(pssmTrees, false);
        const double treeDrop = meanOver(pssmTrees, true) - meanOver(pssmBox, true);
        const double modulativeDrop = meanOver(modulativeNoCasters, false) - meanOver(modulativeTrees, false);
        std::printf("RTSS application: ground darkened by the trees' PSSM shadows %.4f, trees by the box's %.4f; "
                    "modulative: ground %.4f, trees FLIP against unshadowed %.5f\n", groundDrop, treeDrop,
                    modulativeDrop, flipMean(modulativeTrees, unshadowed));
        writePng(OgreEnvironment::outDir() + "/forest-shadows-rtss-strip.png",
                 sideBySide({unshadowed, pssmNoCasters, pssmTrees, pssmBox, modulativeTrees}));
        EXPECT_GT(groundDrop, 0.005) << "the RTSS ground receives the trees' depth shadows";
        EXPECT_GT(treeDrop, 0.005) << "the trees receive the application's caster";
        EXPECT_GT(modulativeDrop, 0.005) << "the RTSS ground receives the trees' modulative shadows";
        compareWithGolden(pssmBox, "forest-shadows-rtss-pssm", 0.02);
        compareWithGolden(modulativeTrees, "forest-shadows-rtss-modulative", 0.02);
    }
}
