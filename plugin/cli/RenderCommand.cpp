// treelod render INPUT --technique mesh --camera ... --size WxH -o out.png
// Renders a tree headless through the real plugin (Ogre, default) or through the CPU
// reference renderer (--renderer cpu). `--technique mesh` is the polygonal reference,
// supersampled (--supersample N per axis, default 3).
#include "CliSupport.h"
#include "Commands.h"
#include "TreeInput.h"

#include "TreeLod/Image.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/ReferenceRenderer.h"

#include <algorithm>
#include <vector>
#include <chrono>
#include <cstdio>
#include <map>

#ifdef TREELOD_WITH_OGRE
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/OgreMeshImporter.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#endif

namespace TreeLod
{
    namespace
    {
        struct RenderArgs
        {
            std::string input;
            std::string output;
            std::string technique = "mesh";
            std::string camera = "orbit:30,10,1.05";
            std::string size = "512x512";
            std::string renderer = "ogre";
            int supersample = 3;
            float lodBias = 1.0f;
            bool shadows = false;
            std::string shadowCamera = "focused";
            /// The techniques' object parameters (TechniqueRoles::parameters) by option flag; "" = not given.
            std::map<std::string, std::string> techniqueParams;
            std::vector<std::string> leafMaterials;
            bool verbose = false;
        };

        int runRender(const RenderArgs& args)
        {
            int width = 0, height = 0;
            if (Result<void> size = parseSize(args.size.empty() ? "x" : args.size, width, height); !size)
                return printError(size.error());
            if (args.supersample < 1 || args.supersample > 8)
                return printError(fail("", "--supersample", "must be 1..8 samples per axis"));
            if (!(args.lodBias > 0.0f))
                return printError(fail("", "--lod-bias", "must be a positive number"));
            if (args.shadowCamera != "focused" && args.shadowCamera != "lispsm" && args.shadowCamera != "pssm")
                return printError(
                    fail("", "--shadow-camera", "'" + args.shadowCamera + "' is not focused, lispsm or pssm"));
            if (args.renderer != "cpu" && args.renderer != "ogre")
                return printError(fail("", "--renderer", "'" + args.renderer + "' is not ogre or cpu"));
            ProgressCallback progress = makeProgress();
            auto start = std::chrono::steady_clock::now();
            if (args.renderer == "cpu")
            {
                Result<TreeInput> input = loadTreeInput(args.input, args.leafMaterials, progress);
                if (!input)
                    return printError(input.error());
                const TreeModel& model = input->model;
                CameraSpec camera;
                std::string cameraError;
                if (!CameraSpec::parse(args.camera, model.boundsMin, model.boundsMax, camera, cameraError))
                    return printError(fail("", "--camera", cameraError));
                if (args.technique != "mesh")
                    return printError(fail("", "--technique", "the CPU renderer draws the polygonal reference only (mesh)"));
                if (Result<void> polygons = requirePolygons(model, args.input, "the CPU renderer"); !polygons)
                    return printError(polygons.error());
                ReferenceRenderer renderer(model);
                RenderOptions options;
                options.width = width;
                options.height = height;
                options.samplesPerPixel = args.supersample * args.supersample;
                RenderImages images = renderer.render(camera, options);
                Result<void> written = writePng(args.output, images.colour);
                if (!written)
                    return printError(written.error());
            }
            else
            {
#ifdef TREELOD_WITH_OGRE
                try
                {
                    OffscreenOptions options;
                    options.verbose = args.verbose;
                    OffscreenRenderer renderer(options);
                    OgreMeshImportOptions meshOptions;
                    meshOptions.leafMaterials = args.leafMaterials;
                    const TechniqueInfo* technique = TechniqueRegistry::getSingleton().find(args.technique);
                    if (!technique)
                        return printError(fail("", "--technique", "'" + args.technique + "' is not a known technique (known: " +
                                                                      TechniqueRegistry::getSingleton().describe() + ")"));
                    Result<TreeInput> input = loadTreeInput(args.input, args.leafMaterials, progress,
                                                            [&](const std::string& path) { return importOgreMesh(path, meshOptions); },
                                                            {technique->chunkTechnique});
                    if (!input)
                        return printError(input.error());
                    CameraSpec camera;
                    std::string cameraError;
                    if (!CameraSpec::parse(args.camera, input->model.boundsMin, input->model.boundsMax, camera, cameraError))
                        return printError(fail("", "--camera", cameraError));
                    TreeAssetPtr asset = TreeAssetManager::getSingleton().loadFromBytes(
                        input->name, Ogre::RGN_DEFAULT, input->packageBytes);
                    Ogre::NameValuePairList params;
                    for (const auto& flagValue : args.techniqueParams)
                    {
                        const std::string& flag = flagValue.first;
                        const std::string& value = flagValue.second;
                        if (value.empty())
                            continue;
                        const auto& declared = technique->roles.parameters;
                        const auto it = std::find_if(declared.begin(), declared.end(),
                                                     [&](const TechniqueParameter& p) { return p.flag == flag; });
                        if (it == declared.end())
                        {
                            std::string owners;
                            for (const TechniqueInfo& t : TechniqueRegistry::getSingleton().getTechniques())
                                for (const TechniqueParameter& p : t.roles.parameters)
                                    if (p.flag == flag)
                                        owners += (owners.empty() ? "" : ", ") + t.name;
                            return printError(fail("", "--" + flag, "technique '" + args.technique +
                                                                        "' has no such parameter (techniques that take it: " +
                                                                        owners + ")"));
                        }
                        params[it->name] = value;
                    }
                    renderer.setShadows(args.shadows, 2048, parseShadowCamera(args.shadowCamera, "--shadow-camera"));
                    renderer.setLodBias(args.lodBias);
                    Ogre::MovableObject* object = TechniqueRegistry::getSingleton().createInstance(
                        args.technique, renderer.getSceneManager(), "tree", *asset, params);
                    renderer.getContentNode().attachObject(object);
                    RgbaImage image = renderer.render(camera, width, height, args.supersample);
                    OffscreenRenderer::savePng(image, args.output);
                }
                catch (const Ogre::Exception& e)
                {
                    return printError(fail(args.input, "ogre", e.getDescription()));
                }
#else
                return printError(fail("", "--renderer", "this build has no Ogre plugin"));
#endif
            }
            double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            std::printf("wrote %s (%dx%d, technique %s, renderer %s, %d samples per pixel, %.0f ms)\n",
                        args.output.c_str(), width, height, args.technique.c_str(), args.renderer.c_str(),
                        args.supersample * args.supersample, ms);
            return EXIT_OK;
        }
    }

    void addRenderCommand(CLI::App& app)
    {
        auto args = std::make_shared<RenderArgs>();
        CLI::App* cmd = app.add_subcommand("render", "render a tree (.glb, .gltf, .mesh or .treelod) to a PNG, headless");
        cmd->add_option("input", args->input, "tree file")->required();
        cmd->add_option("-o,--output", args->output, "PNG to write")->required();
#ifdef TREELOD_WITH_OGRE
        const std::string techniques = TechniqueRegistry::getSingleton().describe();
#else
        const std::string techniques = "mesh";
#endif
        cmd->add_option("--technique", args->technique,
                        "LoD technique: " + techniques + " (mesh: the polygonal reference); a .glb is baked in memory");
#ifdef TREELOD_WITH_OGRE
        // Each technique's object parameters (TechniqueRoles::parameters), one option per flag; the
        // techniques that describe it alike share one description.
        std::map<std::string, std::vector<std::pair<std::string, std::string>>> help; // flag: (description, names)
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            for (const TechniqueParameter& p : info.roles.parameters)
            {
                auto& described = help[p.flag];
                auto same = std::find_if(described.begin(), described.end(),
                                         [&](const auto& d) { return d.first == p.description; });
                if (same == described.end())
                    described.push_back({p.description, info.name});
                else
                    same->second += ", " + info.name;
            }
        for (const auto& [flag, described] : help)
        {
            std::string text;
            for (const auto& [description, names] : described)
                text += (text.empty() ? "" : "; ") + names + ": " + description;
            cmd->add_option("--" + flag, args->techniqueParams[flag], text)->type_name("VALUE");
        }
#endif
        cmd->add_option("--lod-bias", args->lodBias, "camera LoD bias (> 1 = more detail)");
        cmd->add_flag("--shadows", args->shadows, "texture shadows from the sun (2048^2 float depth)");
        cmd->add_option("--shadow-camera", args->shadowCamera,
                        "with --shadows: focused (orthographic, Ogre's FocusedShadowCameraSetup), lispsm "
                        "(LiSPSMShadowCameraSetup, García et al. 2007 §5.2) or pssm (PSSMShadowCameraSetup, 3 splits)");
        cmd->add_option("--camera", args->camera,
                        "orbit:AZIMUTH,ELEVATION,DISTANCE (degrees; distance 1 = tree fills the view), "
                        "ortho:AZ,EL,DIST, or PX,PY,PZ,TX,TY,TZ[,FOV]");
        cmd->add_option("--size", args->size, "WxH pixels");
        cmd->add_option("--supersample", args->supersample, "samples per pixel per axis (1..8)");
        cmd->add_option("--renderer", args->renderer, "ogre (through Plugin_TreeLod) or cpu (Embree reference)");
        cmd->add_option("--leaf-material", args->leafMaterials, "material names that are leaves (glTF/.mesh input)");
        cmd->add_flag("--verbose", args->verbose, "echo Ogre's log");
        cmd->callback([args]() { setExitCode(runRender(*args)); });
    }
}
