// treelod_browser: TreeLod's sample browser (see TreeLodBrowser.h and --help).
#include "BrowserOptions.h"
#include "TreeLodBrowser.h"

#include "TreeLod/Image.h" // readGreyImage: heightfields
#include "TreeLod/SceneScript.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

int main(int argc, char** argv)
{
    using namespace TreeLod;
    const char* source = std::getenv("TREELOD_SOURCE_DIR");
    BrowserOptionsResult parsed = parseBrowserOptions(argc, argv, source && *source ? source : TREELOD_SOURCE_DIR);
    if (!parsed.run)
    {
        (parsed.exitCode == 0 ? std::cout : std::cerr) << parsed.message << std::endl;
        return parsed.exitCode;
    }
    const BrowserOptions& options = parsed.options;
    Result<SceneScript> script = loadSceneScript(options.scene, readGreyImage);
    if (!script)
    {
        std::cerr << "treelod_browser: " << script.error().message() << std::endl;
        return 2;
    }
    std::optional<SceneScript> terrainScript;
    if (!options.terrainScene.empty())
    {
        Result<SceneScript> terrain = loadSceneScript(options.terrainScene, readGreyImage);
        if (!terrain)
        {
            std::cerr << "treelod_browser: " << terrain.error().message() << std::endl;
            return 2;
        }
        if (terrain->ground.kind != SceneGround::Kind::Heightfield)
        {
            std::cerr << "treelod_browser: --terrain-scene: " << options.terrainScene
                      << ": the ground is not a heightfield" << std::endl;
            return 2;
        }
        terrainScript = std::move(*terrain);
    }
    // Debian's OGRE is GLX only: say so before Ogre half-starts.
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
    {
        std::cerr << "treelod_browser: no X display (DISPLAY is not set): run under "
                     "xvfb-run -a -s \"-screen 0 1280x1024x24 -noreset\" treelod_browser --headless ..."
                  << std::endl;
        return 1;
    }
    TreeLodBrowser browser(options, *script, std::move(terrainScript));
    int code = 0;
    try
    {
        browser.initApp();
        if (!options.headless)
            browser.getRoot()->startRendering();
        if (options.headless && !options.screenshots.empty())
            browser.writeScreenshots();
        if (options.headless && options.soak > 0)
            browser.soak(options.soak);
    }
    catch (const Ogre::Exception& e)
    {
        std::cerr << "treelod_browser: " << e.getDescription() << std::endl;
        code = 1;
    }
    catch (const std::exception& e)
    {
        std::cerr << "treelod_browser: " << e.what() << std::endl;
        code = 1;
    }
    browser.closeApp();
    return code;
}
