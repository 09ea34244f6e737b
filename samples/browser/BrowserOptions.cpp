#include "BrowserOptions.h"

#include <CLI/CLI.hpp>

#include <filesystem>

namespace TreeLod
{
    namespace
    {
        const char* const FOOTER = R"(Windowed (the default): a menu of samples, each with a thumbnail and a description:
one per LoD technique on a single tree, shown as a split view (polygonal reference |
technique | FLIP difference image), the forest of the scene script, and the terrain sample: the
--terrain-scene script's forest on Ogre's Terrain under PSSM shadows.
  keys: Up/Down choose a sample, Enter start it, Esc back to the menu (quits from the menu);
        N next technique, [ and ] LoD bias / 2 and x 2, H shadows, R wireframe, L freeze LoD,
        Space play/pause the forest's camera path; WASD/QE + mouse move the camera
        (orbit: left drag turns, right drag or wheel zooms; forest: drag to look);
        OgreBites' AdvancedRenderControls: F6 screenshot, G camera details, T filtering.

--headless writes into the --screenshots folder, with the trays visible:
  menu.png                  the sample menu
  forest-NNN.png            the forest sample at --frames frames spread evenly along the
                            scene's camera path (NNN = 000, 001, ...)
  terrain-NNN.png           the terrain sample, the same way along its script's camera path
  split-TECHNIQUE.png       each technique sample's split view (every registered technique:
                            treelod render --help lists them), the tree framed whole
--headless --soak N switches N times between samples and techniques as a user does (the menu,
the technique menu), each drawn until it has settled, and prints resident memory and the heap in
use after each pass over every sample and technique; then after the warm-up (two passes), at the
end, and the peak; --screenshots may be left out.
Layout: a 270-pixel column of controls and stats on the left; the split view divides the rest
into three equal panels.
Needs an X server (xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" treelod_browser --headless ...).
Bad arguments exit 2; a failure while running exits 1.)";

        bool parseSize(const std::string& text, int& w, int& h)
        {
            const std::size_t x = text.find('x');
            if (x == std::string::npos)
                return false;
            try
            {
                std::size_t a = 0, b = 0;
                w = std::stoi(text.substr(0, x), &a);
                h = std::stoi(text.substr(x + 1), &b);
                if (a != x || b != text.size() - x - 1)
                    return false;
            }
            catch (const std::exception&)
            {
                return false;
            }
            return w >= 320 && h >= 240 && w <= 8192 && h <= 8192;
        }

        BrowserOptionsResult bad(const std::string& message)
        {
            BrowserOptionsResult r;
            r.exitCode = 2;
            r.message = "treelod_browser: " + message;
            return r;
        }
    }

    BrowserOptionsResult parseBrowserOptions(int argc, char** argv, const std::string& sourceDir)
    {
        BrowserOptions o;
        o.scene = sourceDir + "/samples/scenes/single-tree.json";
        o.tree = sourceDir + "/media/oak.glb";
        o.terrainScene = sourceDir + "/samples/scenes/terrain-pssm.json";
        bool noTerrain = false;
        std::string size = "1280x720";

        CLI::App app{"treelod_browser: TreeLod's sample browser (OgreBites + trays)", "treelod_browser"};
        app.footer(FOOTER);
        app.add_flag("--headless", o.headless, "no window and no interaction: write the screenshots and exit");
        app.add_option("--scene", o.scene, "scene script of the forest sample (default samples/scenes/single-tree.json)");
        app.add_option("--tree", o.tree,
                       "tree of the single-tree samples: a .glb/.gltf file or preset:NAME?seed=S&leaves=N "
                       "(default media/oak.glb)");
        app.add_option("--terrain-scene", o.terrainScene,
                       "scene script of the terrain sample, with a heightfield ground (default "
                       "samples/scenes/terrain-pssm.json)");
        app.add_flag("--no-terrain", noTerrain, "no terrain sample");
        app.add_option("--screenshots", o.screenshots, "with --headless: folder for the PNGs (created)");
        app.add_option("--frames", o.frames, "with --headless: forest frames along the camera path (default 4)");
        app.add_option("--soak", o.soak,
                       "with --headless: N switches between samples and techniques, then report resident memory");
        app.add_option("--shadow-size", o.shadowSize,
                       "shadow map side of every sample, a power of two 256 .. 16384 (default: the scene's, "
                       "2048 for the single tree)");
        app.add_option("--size", size, "WxH window or image size, 320x240 .. 8192x8192 (default 1280x720)");
        app.add_option("--cache", o.cacheDirectory, "bake cache folder (default $XDG_CACHE_HOME/treelod)");
        bool noGrab = false;
        app.add_flag("--no-grab", noGrab, "windowed: leave the mouse free (the trays then take keys only)");
        app.add_flag("--verbose", o.verbose, "echo Ogre's log to stdout");
        try
        {
            app.parse(argc, argv);
        }
        catch (const CLI::CallForHelp&)
        {
            BrowserOptionsResult r;
            r.message = app.help();
            return r;
        }
        catch (const CLI::ParseError& e)
        {
            return bad(e.what());
        }
        o.grabInput = !noGrab;
        if (!parseSize(size, o.width, o.height))
            return bad("--size: '" + size + "' is not WxH with 320x240 .. 8192x8192");
        if (o.frames < 1)
            return bad("--frames: must be at least 1");
        if (o.headless && o.screenshots.empty() && o.soak == 0)
            return bad("--headless needs --screenshots DIR or --soak N");
        if (o.shadowSize != 0 && (o.shadowSize < 256 || o.shadowSize > 16384 || (o.shadowSize & (o.shadowSize - 1))))
            return bad("--shadow-size: " + std::to_string(o.shadowSize) + " is not a power of two in 256 .. 16384");
        if (!o.headless && o.soak > 0)
            return bad("--soak needs --headless");
        if (!o.headless && !o.screenshots.empty())
            return bad("--screenshots needs --headless");
        std::error_code ec;
        if (!std::filesystem::is_regular_file(o.scene, ec))
            return bad("--scene: " + o.scene + ": no such file");
        if (noTerrain)
            o.terrainScene.clear();
        else if (!std::filesystem::is_regular_file(o.terrainScene, ec))
            return bad("--terrain-scene: " + o.terrainScene + ": no such file");
        if (o.tree.rfind("preset:", 0) != 0 && !std::filesystem::is_regular_file(o.tree, ec))
            return bad("--tree: " + o.tree + ": no such file");
        BrowserOptionsResult r;
        r.options = o;
        r.run = true;
        return r;
    }
}
