#include "TreeLod/OgreBootstrap.h"

#include <OgreException.h>
#include <OgreResourceGroupManager.h>

#include <cstdlib>
#include <filesystem>

namespace TreeLod
{
    namespace
    {
        std::string envOr(const char* name, const std::string& fallback)
        {
            const char* v = std::getenv(name);
            return v && *v ? std::string(v) : fallback;
        }
    }

    std::string ogrePluginDirectory() { return envOr("OGRE_PLUGIN_DIR_OVERRIDE", TREELOD_OGRE_PLUGIN_DIR); }

    std::string ogreMediaDirectory() { return envOr("TREELOD_OGRE_MEDIA_DIR", TREELOD_OGRE_MEDIA_DIR); }

    std::string dataDirectory()
    {
        std::error_code ec;
        const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
        const std::filesystem::path bin = ec ? std::filesystem::current_path(ec) : self.parent_path();
        return (bin / TREELOD_DATADIR_FROM_BINDIR).lexically_normal().string();
    }

    std::string materialsDirectory() { return envOr("TREELOD_MATERIALS_DIR", dataDirectory() + "/media"); }

    std::unique_ptr<Ogre::LogManager> createLogManager(const std::string& logFile, bool verbose)
    {
        auto logManager = std::make_unique<Ogre::LogManager>();
        logManager->createLog(logFile, true, verbose, logFile.empty());
        return logManager;
    }

    std::string renderSystemPlugin()
    {
        const std::string name = envOr("TREELOD_RENDER_SYSTEM", "GL3Plus");
        for (const char* known : {"GL3Plus", "GL", "GLES2"})
            if (name == known)
                return "RenderSystem_" + name;
        OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                    "TREELOD_RENDER_SYSTEM='" + name + "': not a render system TreeLod runs on (GL3Plus, GL or GLES2)",
                    "TreeLod::renderSystemPlugin");
    }

    std::string loadRenderPlugins(Ogre::Root& root)
    {
        const std::string pluginDir = ogrePluginDirectory();
        root.loadPlugin(pluginDir + "/" + renderSystemPlugin() + ".so");
        root.loadPlugin(pluginDir + "/Codec_STBI.so");
        return pluginDir;
    }

    void addMaterialsLocations(const std::string& materialsDir, const std::string& group)
    {
        Ogre::ResourceGroupManager& rgm = Ogre::ResourceGroupManager::getSingleton();
        rgm.addResourceLocation(materialsDir, "FileSystem", group);
        rgm.addResourceLocation(materialsDir + "/GLSL", "FileSystem", group);
    }

    bool addShadowVolumeLocation()
    {
        const std::string shadowVolume = ogreMediaDirectory() + "/ShadowVolume";
        if (!std::filesystem::is_directory(shadowVolume))
            return false;
        Ogre::ResourceGroupManager::getSingleton().addResourceLocation(shadowVolume, "FileSystem",
                                                                       Ogre::RGN_INTERNAL);
        return true;
    }

    Ogre::NameValuePairList hiddenWindowParams(Ogre::NameValuePairList params)
    {
        params["hidden"] = "true";
        params["vsync"] = "false";
        return params;
    }
}
