// OgreBootstrap: the Ogre start-up that OffscreenRenderer (the headless Root of the CLI, tests and
// bench) and the sample browser (OgreBites) share: where OGRE's plugins and media and TreeLod's
// materials are, a log that stays off stdout, the plugins TreeLod renders with, TreeLod's
// resource locations, and the hidden window that owns the GL context when nothing is shown.
//
// Folders: the environment first, else those of the OGRE the build found, and TreeLod's own data
// beside the running executable (bin/../share/TreeLod: installed, and in the build tree, whose
// share/TreeLod links to the sources):
//   $OGRE_PLUGIN_DIR_OVERRIDE  OGRE's plugins (RenderSystem_GL3Plus.so, Codec_STBI.so)
//   $TREELOD_RENDER_SYSTEM     GL3Plus (default), GL or GLES2: the render system loaded
//   $TREELOD_OGRE_MEDIA_DIR    OGRE's media (ShadowVolume, RTShaderLib, packs/SdkTrays.zip)
//   $TREELOD_MATERIALS_DIR     TreeLod's material scripts and shaders (share/TreeLod/media, and its GLSL/)
// Part of TreeLodOffscreen, not of Plugin_TreeLod.
#pragma once

#include <OgreCommon.h>
#include <OgreLogManager.h>
#include <OgreRoot.h>

#include <memory>
#include <string>

namespace TreeLod
{
    /// OGRE's plugin folder: $OGRE_PLUGIN_DIR_OVERRIDE, else the build's.
    std::string ogrePluginDirectory();

    /// OGRE's media folder: $TREELOD_OGRE_MEDIA_DIR, else the build's.
    std::string ogreMediaDirectory();

    /// TreeLod's data folder, `share/TreeLod` beside the running executable's `bin/` (installed:
    /// <prefix>/share/TreeLod; build tree: build/share/TreeLod, linking to the sources).
    std::string dataDirectory();

    /// TreeLod's material scripts and shaders: $TREELOD_MATERIALS_DIR, else dataDirectory()/media.
    std::string materialsDirectory();

    /// An own LogManager, created before the Root (else Ogre logs to stdout, OGRE-NOTES.md), with
    /// one default log written to `logFile` ("" = no file, messages dropped) and echoed to stdout
    /// when `verbose`.
    std::unique_ptr<Ogre::LogManager> createLogManager(const std::string& logFile, bool verbose);

    /// The render system plugin to load: "RenderSystem_" + $TREELOD_RENDER_SYSTEM (GL3Plus, the
    /// default, GL or GLES2); throws Ogre::InvalidParametersException naming any other value.
    std::string renderSystemPlugin();

    /// Load renderSystemPlugin() and Codec_STBI from ogrePluginDirectory() into `root`; returns
    /// that folder (for messages).
    std::string loadRenderPlugins(Ogre::Root& root);

    /// Add `materialsDir` and its GLSL/ folder as FileSystem locations of `group` (not initialised).
    void addMaterialsLocations(const std::string& materialsDir, const std::string& group = "TreeLod");

    /// Add OGRE's ShadowVolume programs (texture shadows load them) to Ogre::RGN_INTERNAL (not
    /// initialised); false, and nothing added, when the media folder has none.
    bool addShadowVolumeLocation();

    /// `params` with what a hidden window that only owns the GL context needs (hidden, no vsync).
    Ogre::NameValuePairList hiddenWindowParams(Ogre::NameValuePairList params = Ogre::NameValuePairList());
}
