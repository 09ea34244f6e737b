// BrowserOptions: the sample browser's command line (treelod_browser --help prints it).
#pragma once

#include <string>

namespace TreeLod
{
    struct BrowserOptions
    {
        bool headless = false;     ///< no interaction: render the screenshots and exit
        std::string scene;         ///< scene script of the forest sample (resolved path)
        std::string tree;          ///< source of the single-tree samples: a tree file or "preset:NAME?..."
        std::string terrainScene;  ///< scene script of the terrain sample (a heightfield ground); "" = no terrain sample
        std::string screenshots;   ///< headless: folder for the PNGs (created)
        unsigned frames = 4;       ///< headless: forest frames along the scene's camera path, >= 1
        unsigned shadowSize = 0;   ///< > 0: every sample's shadow map side (else the script's; 2048 single trees)
        unsigned soak = 0;         ///< headless: > 0 = that many sample and technique switches, then memory
        int width = 1280;          ///< window (or headless image) size in pixels
        int height = 720;
        std::string cacheDirectory; ///< bake cache; "" = defaultBakeCacheDirectory()
        bool grabInput = true;     ///< windowed: grab the mouse and draw the trays' cursor (Ogre's browser does)
        bool verbose = false;      ///< echo Ogre's log to stdout
    };

    /// Outcome of parseBrowserOptions: run, or exit with `exitCode` (0 after --help, 2 on a
    /// bad argument, with `message` naming the argument and the reason).
    struct BrowserOptionsResult
    {
        BrowserOptions options;
        bool run = false;
        int exitCode = 0;
        std::string message; ///< for stderr when exitCode != 0; the help text when it is 0
    };

    /// Parse argv. Defaults resolve against `sourceDir` (the TreeLod source tree):
    /// scene samples/scenes/single-tree.json, tree media/oak.glb, terrain scene
    /// samples/scenes/terrain-pssm.json (--no-terrain: none). Checks that the scenes and a
    /// tree file exist and that --headless has --screenshots or --soak; the scene's content is checked
    /// when it loads.
    BrowserOptionsResult parseBrowserOptions(int argc, char** argv, const std::string& sourceDir);
}
