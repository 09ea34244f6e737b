// minimal_app PLUGINS_CFG RESOURCES_CFG ASSET OUT_PNG
//
// One tree drawn by TreeLod in a plain Ogre application: plugins from PLUGINS_CFG (a render system,
// Codec_STBI, Plugin_TreeLod), resource locations from RESOURCES_CFG (TreeLod's materials and the
// folder holding ASSET), a FoliageLodTree made by its factory, rendered into a texture and saved as
// OUT_PNG. Needs an X server (Debian's OGRE is GLX only): under xvfb-run when there is no display.
#include "TreeLod/FoliageLodTree.h"

#include <Ogre.h>
#include <OgreConfigFile.h>

#include <cstdio>
#include <memory>

namespace
{
    /// Every section of `path` is a resource group, every `Type=location` line a location in it.
    void addResourceLocations(const Ogre::String& path)
    {
        Ogre::ConfigFile config;
        config.load(path);
        Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
        for (const auto& [group, settings] : config.getSettingsBySection())
            for (const auto& [type, location] : settings)
                rgm.addResourceLocation(location, type, group);
    }

    int run(const Ogre::String& pluginsCfg, const Ogre::String& resourcesCfg, const Ogre::String& asset,
            const Ogre::String& output)
    {
        Ogre::Root root(pluginsCfg, "", ""); // loads the plugins plugins.cfg names; no ogre.cfg
        Ogre::RenderSystem* renderSystem = root.getRenderSystemByName("OpenGL 3+ Rendering Subsystem");
        if (!renderSystem)
        {
            std::fprintf(stderr, "minimal_app: RenderSystem_GL3Plus is not in %s\n", pluginsCfg.c_str());
            return 1;
        }
        root.setRenderSystem(renderSystem);
        root.initialise(false);
        // A hidden 1x1 window owns the GL context; the picture is drawn into a texture.
        Ogre::NameValuePairList windowParams{{"hidden", "true"}, {"vsync", "false"}};
        Ogre::RenderWindow* window = root.createRenderWindow("minimal_app", 1, 1, false, &windowParams);
        window->setAutoUpdated(false);

        addResourceLocations(resourcesCfg);
        Ogre::ResourceGroupManager::getSingleton().initialiseAllResourceGroups();

        Ogre::SceneManager* scene = root.createSceneManager();
        scene->setAmbientLight(Ogre::ColourValue(0.35f, 0.35f, 0.4f));
        Ogre::Light* sun = scene->createLight("sun");
        sun->setType(Ogre::Light::LT_DIRECTIONAL);
        sun->setDiffuseColour(Ogre::ColourValue(1.0f, 0.95f, 0.85f));
        Ogre::SceneNode* sunNode = scene->getRootSceneNode()->createChildSceneNode();
        sunNode->attachObject(sun);
        sunNode->setDirection(Ogre::Vector3(-0.5f, -1.0f, -0.6f), Ogre::Node::TS_WORLD);

        // The tree: made by Plugin_TreeLod's factory, its package found in the resource groups.
        Ogre::NameValuePairList treeParams{{"asset", asset}};
        Ogre::MovableObject* tree = scene->createMovableObject("tree", "FoliageLodTree", &treeParams);
        scene->getRootSceneNode()->createChildSceneNode()->attachObject(tree);

        // A camera framing the tree's bounds from the front, slightly above.
        const Ogre::AxisAlignedBox& bounds = tree->getBoundingBox();
        const Ogre::Vector3 centre = bounds.getCenter();
        const Ogre::Real radius = 0.5f * bounds.getSize().length();
        Ogre::Camera* camera = scene->createCamera("camera");
        camera->setFOVy(Ogre::Degree(45.0f));
        camera->setNearClipDistance(0.01f * radius);
        camera->setFarClipDistance(10.0f * radius);
        Ogre::SceneNode* cameraNode = scene->getRootSceneNode()->createChildSceneNode();
        cameraNode->attachObject(camera);
        cameraNode->setPosition(centre + Ogre::Vector3(0.0f, 0.15f * radius, 1.7f * radius));
        cameraNode->lookAt(centre, Ogre::Node::TS_WORLD);

        Ogre::TexturePtr target = Ogre::TextureManager::getSingleton().createManual(
            "minimal_app/target", Ogre::RGN_DEFAULT, Ogre::TEX_TYPE_2D, 256, 256, 0, Ogre::PF_BYTE_RGBA,
            Ogre::TU_RENDERTARGET);
        Ogre::RenderTarget* rt = target->getBuffer()->getRenderTarget();
        Ogre::Viewport* viewport = rt->addViewport(camera);
        viewport->setBackgroundColour(Ogre::ColourValue(0.6f, 0.75f, 0.9f));
        viewport->setOverlaysEnabled(false);
        root.renderOneFrame(); // the first frame picks the tree's level of detail
        root.renderOneFrame();
        rt->writeContentsToFile(output);

        if (auto* lodf = dynamic_cast<TreeLod::FoliageLodTree*>(tree))
            std::printf("minimal_app: %s, %u of %u leaves, written to %s\n", asset.c_str(), lodf->getLeafCount(),
                        lodf->getMaxLeafCount(), output.c_str());
        // The render texture goes before the scene manager whose camera its viewport uses.
        Ogre::TextureManager::getSingleton().remove(target);
        target.reset();
        root.destroySceneManager(scene);
        return 0;
    }
}

int main(int argc, char** argv)
{
    if (argc != 5)
    {
        std::fprintf(stderr, "usage: minimal_app PLUGINS_CFG RESOURCES_CFG ASSET OUT_PNG\n");
        return 2;
    }
    // Our own log manager before the Root, so that Ogre's log goes to a file, not to stdout.
    auto logManager = std::make_unique<Ogre::LogManager>();
    logManager->createLog("minimal_app.log", true, false, false);
    try
    {
        return run(argv[1], argv[2], argv[3], argv[4]);
    }
    catch (const Ogre::Exception& e)
    {
        std::fprintf(stderr, "minimal_app: %s\n", e.getFullDescription().c_str());
        return 1;
    }
}
