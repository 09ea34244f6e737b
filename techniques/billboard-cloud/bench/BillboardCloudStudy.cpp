// treelod_bc_study: what billboard clouds with multi-layered indirect texturing (García et al. 2007)
// cost and how close they come to the polygonal tree, measured headless through the plugin;
// memory, bake time, image error and frame time, in the shape of the paper's Tables 1 and 2.
//
// 1. Memory and bake time (Table 1): per tree, leaves, polygons per leaf, billboards of the
//    three clouds, list entries, GPU bytes of the multi-layered chunk (DXT) and bake seconds
//    (wall clock of bakeBillboardCloud on this machine, AO included), and the classic cloud
//    baked at the same memory.
// 2. Image error: the error tree seen with the tree filling the view (90 % of the height), a
//    quarter of the view height and 32 px tall, and close up (3x the view height: branches and
//    leaves). Reference ("mesh"), classic and multi-layered are rendered by the same Ogre pipeline
//    at S x S supersampling, the clouds without their AO term (the polygonal reference has none);
//    multi-scale RMSE (ellipsoids-and-lines paper §4) and FLIP over the square around the tree.
//    Pictures: reference | classic | multi-layered | FLIP of the multi-layered (magnified crops),
//    one PNG per view.
// 3. Frame time (Table 2): N trees on a square grid (spacing 1.25 tree widths), the camera at
//    a corner of the grid at eye height looking across it, so distances range from a close
//    view to far trees; the median frame time of mesh, classic and multi-layered for each N in
//    the same run, same camera, and their ratios.
// Output in --out: summary.md, summary.json, error.csv, timing.csv, error-<view>.png.
//
// Needs an X server: xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" treelod_bc_study [options]
// Errors print one line and exit 2. Timings on llvmpipe are CPU timings: compare ratios.
#include "TreeLod/BillboardCloudBaker.h"
#include "TreeLod/BillboardCloudTree.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include "StudySupport.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        struct StudyArgs
        {
            std::vector<std::string> trees{"media/oak.glb", "media/conifer.glb", "media/birch.glb"};
            std::vector<std::uint32_t> generatedLeaves{20000};
            std::string errorTree = "generated:20000"; ///< a --trees path or generated:<leaves>
            std::string timingTree = "media/oak.glb";
            int size = 384;
            int supersample = 3;
            std::vector<std::uint32_t> counts{1, 50, 100, 1000};
            int timingWidth = 640, timingHeight = 512;
            int timingFrames = 5;
            bool timing = true;
            bool error = true;
            int level = -1; ///< >= 0: force this cloud level
            int aoRays = BillboardCloudOptions().aoRays;
            double listFactor = -1.0; ///< < 0: the package's
            std::string out = "out/bc-study";
        };

        void progressLine(const std::string& line) { std::fprintf(stderr, "bc-study: %s\n", line.c_str()); }

        struct StudyTree
        {
            std::string label;
            TreeModel model;
            glm::vec3 crownCentre{0.0f};
        };

        StudyTree loadTree(const std::string& spec)
        {
            StudyTree tree;
            if (spec.rfind("generated:", 0) == 0)
            {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.seed = 1;
                options.leafCount = std::uint32_t(std::stoul(spec.substr(10)));
                Result<TreeModel> model = generateTree(options);
                if (!model)
                    throw StudyError(model.error().message());
                tree.model = std::move(model.value());
                tree.label = format("generated oak (%u leaves)", options.leafCount);
            }
            else
            {
                Result<TreeModel> model = importGltf(spec);
                if (!model)
                    throw StudyError(model.error().message());
                tree.model = std::move(model.value());
                tree.label = std::filesystem::path(spec).filename().string();
            }
            glm::vec3 lo = tree.model.boundsMin, hi = tree.model.boundsMax;
            if (!tree.model.leafVertices.empty())
            {
                lo = glm::vec3(std::numeric_limits<float>::max());
                hi = -lo;
                for (const Vertex& v : tree.model.leafVertices)
                {
                    lo = glm::min(lo, v.position);
                    hi = glm::max(hi, v.position);
                }
            }
            tree.crownCentre = 0.5f * (lo + hi);
            return tree;
        }

        /// One tree baked both ways, with what the bake measured.
        struct BakedTree
        {
            std::string spec; ///< as given: a path or generated:<leaves>
            StudyTree tree;
            BillboardCloudStats layered, classic;
            double layeredSeconds = 0.0, classicSeconds = 0.0;
            std::vector<std::uint8_t> package;
        };

        BakedTree bake(const std::string& spec, const StudyArgs& args)
        {
            BakedTree baked;
            baked.spec = spec;
            baked.tree = loadTree(spec);
            progressLine("baking " + baked.tree.label);
            PackageWriter writer;
            Result<void> added = addReferenceChunk(writer, baked.tree.model, baked.tree.label);
            if (!added)
                throw StudyError(added.error().message());

            BillboardCloudOptions options;
            options.aoRays = args.aoRays;
            auto start = std::chrono::steady_clock::now();
            Result<BillboardCloudData> layered =
                bakeBillboardCloud(baked.tree.model, options, baked.tree.label, {}, &baked.layered);
            baked.layeredSeconds = secondsSince(start);
            if (!layered)
                throw StudyError(layered.error().message());

            ClassicBillboardCloudOptions classicOptions;
            classicOptions.cloud = options;
            classicOptions.memoryBytes = layered->gpuBytes();
            start = std::chrono::steady_clock::now();
            Result<BillboardCloudData> classic =
                bakeClassicBillboardCloud(baked.tree.model, classicOptions, baked.tree.label, {}, &baked.classic);
            baked.classicSeconds = secondsSince(start);
            if (!classic)
                throw StudyError(classic.error().message());

            for (auto [name, data] : {std::pair{BILLBOARD_CLOUD_CHUNK, &layered.value()},
                                      std::pair{CLASSIC_BILLBOARD_CLOUD_CHUNK, &classic.value()}})
            {
                Result<void> r =
                    writer.addChunk(name, 0, BILLBOARD_CLOUD_CHUNK_FORMAT_VERSION, encodeBillboardCloudChunk(*data));
                if (!r)
                    throw StudyError(r.error().message());
            }
            baked.package = writer.toBytes();
            return baked;
        }

        // ---- 2. image error ----------------------------------------------------------------

        struct ErrorView
        {
            std::string name;
            double fraction = 0.0; ///< tree height / view height (0 = --fixed px)
            double px = 0.0;
        };

        struct ErrorRow
        {
            std::string view;
            int treePx = 0;
            double flipClassic = 0, flipLayered = 0, rmseClassic = 0, rmseLayered = 0;
            unsigned level = 0;
        };

        struct Scene
        {
            TreeAssetPtr asset;
            std::vector<Ogre::MovableObject*> mesh, classic, layered;

            void show(const std::vector<Ogre::MovableObject*>& only)
            {
                for (auto* set : {&mesh, &classic, &layered})
                    for (Ogre::MovableObject* o : *set)
                        o->setVisible(set == &only);
            }
        };

        /// N instances of each technique on a grid (N = 1: one at the origin).
        void populate(OffscreenRenderer& renderer, Scene& scene, std::uint32_t count, float spacing,
                      const Ogre::NameValuePairList& cloudParams = {})
        {
            renderer.clearContent();
            scene.mesh.clear();
            scene.classic.clear();
            scene.layered.clear();
            Ogre::SceneManager& sm = renderer.getSceneManager();
            TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
            const std::uint32_t columns = std::uint32_t(std::ceil(std::sqrt(double(count))));
            for (std::uint32_t i = 0; i < count; ++i)
            {
                Ogre::SceneNode* node = renderer.getContentNode().createChildSceneNode(
                    Ogre::Vector3(float(i % columns) * spacing, 0.0f, -float(i / columns) * spacing));
                for (auto [technique, set] : {std::pair{"mesh", &scene.mesh},
                                              std::pair{CLASSIC_BILLBOARD_CLOUD_CHUNK, &scene.classic},
                                              std::pair{BILLBOARD_CLOUD_CHUNK, &scene.layered}})
                {
                    Ogre::NameValuePairList params = set == &scene.mesh ? Ogre::NameValuePairList() : cloudParams;
                    if (set == &scene.classic)
                        params.erase("level"); // the classic cloud has one level
                    Ogre::MovableObject* object =
                        registry.createInstance(technique, sm, format("%s-%u", technique, i), *scene.asset, params);
                    node->attachObject(object);
                    set->push_back(object);
                }
            }
        }

        std::vector<ErrorRow> measureError(OffscreenRenderer& renderer, Scene& scene, const StudyTree& tree,
                                           const StudyArgs& args)
        {
            // Without AO: the polygonal reference has none, so AO would count as error.
            Ogre::NameValuePairList params{{"ambientOcclusion", "false"}};
            if (args.listFactor >= 0.0)
                params["listFactor"] = format("%g", args.listFactor);
            if (args.level >= 0)
                params["level"] = std::to_string(args.level);
            populate(renderer, scene, 1, 0.0f, params);
            const double height = tree.model.boundsMax.y - tree.model.boundsMin.y;
            // Three views (the tree filling the view, a quarter of its height, 32 px), and a close-up
            // (the tree 3x the view's height: branches and leaves, where García et al. 2007 §7 says
            // the layers matter most).
            const std::vector<ErrorView> views = {
                {"close", 3.0, 0.0}, {"fill", 0.9, 0.0}, {"quarter", 0.25, 0.0}, {"32px", 0.0, 32.0}};
            std::vector<ErrorRow> rows;
            for (const ErrorView& view : views)
            {
                const double px = view.fraction > 0 ? view.fraction * args.size : view.px;
                const double distance = distanceForHeight(height, px, args.size);
                CameraSpec camera;
                const glm::vec3& c = tree.crownCentre;
                camera.position = glm::vec3(c.x + float(distance * std::sin(0.5)), c.y, c.z + float(distance * std::cos(0.5)));
                camera.target = c;
                camera.fovYDegrees = STUDY_FOV_Y_DEGREES;
                progressLine(format("error view %s: tree %.0f px tall at %.1f m", view.name.c_str(), px, distance));

                Image images[3];
                for (int t = 0; t < 3; ++t)
                {
                    const std::vector<Ogre::MovableObject*>& set = t == 0 ? scene.mesh : t == 1 ? scene.classic : scene.layered;
                    scene.show(set);
                    images[t] = toImage(renderer.render(camera, args.size, args.size, args.supersample));
                }
                const Extent extent = unite(treeExtent(images[0]), treeExtent(images[2]));
                const Crop crop = cropAround(extent, args.size, args.size);
                Image crops[3];
                for (int t = 0; t < 3; ++t)
                    crops[t] = magnify(images[t], crop, crop.side);

                ErrorRow row;
                row.view = view.name;
                if (auto* cloud = dynamic_cast<BillboardCloudTree*>(scene.layered.front()))
                    row.level = cloud->getLevel();
                row.treePx = extent.heightPx();
                row.flipClassic = flipMean(crops[0], crops[1]);
                row.flipLayered = flipMean(crops[0], crops[2]);
                row.rmseClassic = multiScaleRmseOf(crops[0], crops[1]);
                row.rmseLayered = multiScaleRmseOf(crops[0], crops[2]);
                rows.push_back(row);

                // reference | classic | multi-layered | FLIP of the multi-layered, magnified to one size
                FlipOptions keep;
                keep.keepErrorMap = true;
                Result<FlipResult> heat = flip(crops[0], crops[2], keep);
                if (!heat)
                    throw StudyError("FLIP: " + heat.error().message());
                const int panel = args.size;
                const Crop whole{0, 0, crop.side};
                Image p0 = magnify(crops[0], whole, panel), p1 = magnify(crops[1], whole, panel),
                      p2 = magnify(crops[2], whole, panel), p3 = magnify(flipHeatmap(*heat), whole, panel);
                writeImage(args.out + "/error-" + view.name + ".png", composePanels({{&p0, &p1, &p2, &p3}}));
            }
            return rows;
        }

        // ---- 3. frame time -----------------------------------------------------------------

        struct TimingRow
        {
            std::uint32_t trees = 0;
            double meshMs = 0, classicMs = 0, layeredMs = 0;
        };

        std::vector<TimingRow> measureTiming(OffscreenRenderer& renderer, Scene& scene, const StudyTree& tree,
                                             const StudyArgs& args)
        {
            const glm::vec3 size = tree.model.boundsMax - tree.model.boundsMin;
            const float spacing = 1.25f * std::max(size.x, size.z);
            const double height = size.y;
            std::vector<TimingRow> rows;
            for (std::uint32_t count : args.counts)
            {
                Ogre::NameValuePairList params;
                if (args.listFactor >= 0.0)
                    params["listFactor"] = format("%g", args.listFactor);
                if (args.level >= 0)
                    params["level"] = std::to_string(args.level);
                populate(renderer, scene, count, spacing, params);
                const std::uint32_t columns = std::uint32_t(std::ceil(std::sqrt(double(count))));
                const float extent = float(columns - 1) * spacing;
                // At a corner, one tree-height's "fill" distance out, eye at 1.7 m, looking across
                // the grid: the nearest tree fills the view, the farthest is small.
                CameraSpec camera;
                const float back = float(distanceForHeight(height, 0.9 * args.timingHeight, args.timingHeight));
                camera.position = glm::vec3(-0.7f * back, 1.7f, 0.7f * back);
                camera.target = count == 1 ? tree.crownCentre : glm::vec3(0.5f * extent, 0.3f * float(height), -0.5f * extent);
                camera.fovYDegrees = STUDY_FOV_Y_DEGREES;
                camera.farClip = 100000.0f;
                TimingRow row;
                row.trees = count;
                double* out[3] = {&row.meshMs, &row.classicMs, &row.layeredMs};
                const std::vector<Ogre::MovableObject*>* sets[3] = {&scene.mesh, &scene.classic, &scene.layered};
                for (int t = 0; t < 3; ++t)
                {
                    scene.show(*sets[t]);
                    *out[t] = median(renderer.timeFrames(camera, args.timingWidth, args.timingHeight, args.timingFrames));
                }
                if (count == args.counts.front())
                {
                    scene.show(scene.layered);
                    writeImage(args.out + format("/timing-%u.png", count),
                               toImage(renderer.render(camera, args.timingWidth, args.timingHeight, 1)));
                }
                progressLine(format("%u trees: mesh %.1f ms, classic %.1f ms, multi-layered %.1f ms", count, row.meshMs,
                                    row.classicMs, row.layeredMs));
                rows.push_back(row);
            }
            return rows;
        }

        int run(const StudyArgs& args, const std::string& commandLine)
        {
            std::filesystem::create_directories(args.out);
            std::vector<BakedTree> baked;
            for (const std::string& path : args.trees)
                baked.push_back(bake(path, args));
            for (std::uint32_t leaves : args.generatedLeaves)
                baked.push_back(bake("generated:" + std::to_string(leaves), args));

            OffscreenRenderer renderer;
            renderer.setLighting(LightingSpec());
            std::ostringstream md;
            nlohmann::json json;
            md << "# Billboard clouds (García et al. 2007): memory, bake time, image error, frame time\n\n";
            md << "Command: `" << commandLine << "`\n\n";
            md << "## Memory and bake time (Table 1)\n\n";
            md << "| tree | leaves | polys/leaf | billboards (3 clouds) | list entries | multi-layered bytes | "
                  "classic bytes | bake s (multi-layered) | bake s (classic) |\n|---|---|---|---|---|---|---|---|---|\n";
            for (const BakedTree& b : baked)
            {
                const double polys = b.tree.model.leaves.empty()
                                         ? 0.0
                                         : double(b.tree.model.leafTriangleCount()) / double(b.tree.model.leaves.size());
                md << format("| %s | %zu | %.1f | %u / %u / %u | %u | %llu | %llu | %.2f | %.2f |\n",
                             b.tree.label.c_str(), b.tree.model.leaves.size(), polys, b.layered.billboards[0],
                             b.layered.billboards[1], b.layered.billboards[2], b.layered.entries,
                             (unsigned long long)b.layered.gpuBytes, (unsigned long long)b.classic.gpuBytes,
                             b.layeredSeconds, b.classicSeconds);
                json["memory"].push_back({{"tree", b.tree.label},
                                          {"leaves", b.tree.model.leaves.size()},
                                          {"billboards", {b.layered.billboards[0], b.layered.billboards[1],
                                                          b.layered.billboards[2]}},
                                          {"entries", b.layered.entries},
                                          {"longestList", b.layered.longestList},
                                          {"truncatedCells", b.layered.truncatedCells},
                                          {"layeredBytes", b.layered.gpuBytes},
                                          {"classicBytes", b.classic.gpuBytes},
                                          {"bakeSeconds", b.layeredSeconds},
                                          {"classicBakeSeconds", b.classicSeconds}});
            }

            auto find = [&](const std::string& spec) -> BakedTree& {
                for (BakedTree& b : baked)
                    if (b.spec == spec)
                        return b;
                throw StudyError("tree '" + spec + "' is not among --trees / --generated");
            };

            Scene scene;
            if (args.error)
            {
                BakedTree& e = find(args.errorTree);
                scene.asset = TreeAssetManager::getSingleton().loadFromBytes("bc-study-error.treelod", Ogre::RGN_DEFAULT,
                                                                             e.package);
                std::vector<ErrorRow> rows = measureError(renderer, scene, e.tree, args);
                md << "\n## Image error against the polygonal reference (" << e.tree.label << ", " << args.size << "^2, "
                   << args.supersample << "x" << args.supersample << " supersampled, crop around the tree)\n\n";
                md << "| view | tree px | cloud level | FLIP classic | FLIP multi-layered | ms-RMSE classic | "
                      "ms-RMSE multi-layered | winner (FLIP) |\n|---|---|---|---|---|---|---|---|\n";
                std::string csv = "view,treePx,flipClassic,flipLayered,rmseClassic,rmseLayered\n";
                for (const ErrorRow& r : rows)
                {
                    md << format("| %s | %d | %u | %.4f | %.4f | %.4f | %.4f | %s |\n", r.view.c_str(), r.treePx, r.level,
                                 r.flipClassic,
                                 r.flipLayered, r.rmseClassic, r.rmseLayered,
                                 r.flipLayered < r.flipClassic ? "multi-layered" : "classic");
                    csv += format("%s,%d,%.6f,%.6f,%.6f,%.6f\n", r.view.c_str(), r.treePx, r.flipClassic, r.flipLayered,
                                  r.rmseClassic, r.rmseLayered);
                    json["error"].push_back({{"view", r.view},
                                             {"level", r.level},
                                             {"treePx", r.treePx},
                                             {"flipClassic", r.flipClassic},
                                             {"flipLayered", r.flipLayered},
                                             {"rmseClassic", r.rmseClassic},
                                             {"rmseLayered", r.rmseLayered}});
                }
                md << "\nPictures: `error-<view>.png` = reference | classic | multi-layered | FLIP of the multi-layered.\n";
                writeText(args.out + "/error.csv", csv);
                renderer.clearContent();
                scene.asset.reset();
            }

            if (args.timing)
            {
                BakedTree& t = find(args.timingTree);
                scene.asset = TreeAssetManager::getSingleton().loadFromBytes("bc-study-timing.treelod", Ogre::RGN_DEFAULT,
                                                                             t.package);
                std::vector<TimingRow> rows = measureTiming(renderer, scene, t.tree, args);
                md << "\n## Frame time (Table 2 shape; " << t.tree.label << ", " << args.timingWidth << "x"
                   << args.timingHeight << ", median of " << args.timingFrames << " frames, same run and camera)\n\n";
                md << "| trees | mesh ms | classic ms | multi-layered ms | multi-layered / mesh | classic / mesh |\n"
                      "|---|---|---|---|---|---|\n";
                std::string csv = "trees,meshMs,classicMs,layeredMs\n";
                for (const TimingRow& r : rows)
                {
                    md << format("| %u | %.1f | %.1f | %.1f | %.3f | %.3f |\n", r.trees, r.meshMs, r.classicMs, r.layeredMs,
                                 r.layeredMs / r.meshMs, r.classicMs / r.meshMs);
                    csv += format("%u,%.3f,%.3f,%.3f\n", r.trees, r.meshMs, r.classicMs, r.layeredMs);
                    json["timing"].push_back({{"trees", r.trees},
                                              {"meshMs", r.meshMs},
                                              {"classicMs", r.classicMs},
                                              {"layeredMs", r.layeredMs}});
                }
                writeText(args.out + "/timing.csv", csv);
                renderer.clearContent();
                scene.asset.reset();
            }
            writeSummary(args.out, md.str(), json, commandLine);
            return 0;
        }
    }
}

int main(int argc, char** argv)
{
    TreeLod::StudyArgs args;
    CLI::App app{"Billboard clouds (García et al. 2007): memory, bake time, image error and frame time against the polygonal "
                 "reference. Needs an X server (xvfb-run)."};
    app.add_option("--trees", args.trees, "glTF trees for Table 1");
    app.add_option("--generated", args.generatedLeaves, "generated oaks with these leaf counts");
    app.add_option("--error-tree", args.errorTree, "tree for the image error: a --trees path or generated:<leaves>");
    app.add_option("--timing-tree", args.timingTree, "tree for the frame times");
    app.add_option("--size", args.size, "error views: image size");
    app.add_option("--supersample", args.supersample, "error views: samples per axis");
    app.add_option("--counts", args.counts, "frame time: tree counts");
    app.add_option("--timing-width", args.timingWidth);
    app.add_option("--timing-height", args.timingHeight);
    app.add_option("--timing-frames", args.timingFrames, "frames per median");
    app.add_flag("!--no-timing", args.timing, "skip the frame times");
    app.add_flag("!--no-error", args.error, "skip the image error views");
    app.add_option("--level", args.level, "force this cloud level (0 finest) instead of the LoD strategy's");
    app.add_option("--ao-rays", args.aoRays, "AO rays per leaf vertex in the bake");
    app.add_option("--list-factor", args.listFactor, "shader LoD list factor of the clouds (default: the package's)");
    app.add_option("--out", args.out, "output directory");
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        return app.exit(e);
    }
    const std::string commandLine = TreeLod::studyCommandLine("treelod_bc_study", argc, argv);
    return TreeLod::runStudy("treelod_bc_study", [&] { return TreeLod::run(args, commandLine); });
}
