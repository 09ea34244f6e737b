// treelod_corpus_study: every technique against the polygonal tree, on a corpus of trees (ours, our
// generator's atlas and multi-material variants, and third-party trees when present), measured
// headless through the plugin.
//
// Per tree, the package is baked with every technique asked for (their default options; a paper's
// baseline technique, TechniqueRoles::paperBaseline, at its technique's memory). Per
// view the reference ("mesh") and each technique are rendered by the same Ogre pipeline at S x S
// supersampling, from azimuth 30 degrees at the crown's height (--azimuths N: from N azimuths 360/N
// apart starting there, the metrics averaged; one 30 px view moves by a few thousandths of FLIP
// with the azimuth alone):
//   near: the tree 90 % of the view height; mid: a quarter of it; far: 30 px tall; above: as mid,
//   from 60 degrees above the crown's height (where flat billboards and leaves are seen edge-on).
// Image error is taken over the square around the reference tree (its box with a 15 % margin, the
// same pixels for every technique and run): FLIP (mean), multi-scale RMSE, and the coverage (the
// technique's tree pixels over the reference's, whole frame); and each technique's chunk bytes.
// Techniques
// with an ambient occlusion term draw without it (TechniqueRoles::referenceShadingParams), since the
// polygonal reference has none.
// Output in --out: summary.md (per tree and technique: near / mid / far), summary.json,
// error.csv, and worst-<technique>.png: reference | technique | FLIP of the technique's worst case
// (magnified crops).
//
// Tree specs: a .glb/.gltf path, or generated:PRESET[:LEAVES[:IMAGES[:MATERIALS[:FOLD]]]] (TreeGenerator:
// leaf count, leaf images in an atlas, leaf materials, leaf fold in degrees). Without --trees: the
// bundled trees, the generated oak with a 2x2 leaf atlas under six leaf materials, the generated
// oak with leaves folded 45 degrees (one mesh of two quads each), and every .glb in
// media/third-party/ (docs/measurements.md says how to make them).
//
// Needs an X server: xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" treelod_corpus_study [options]
// Errors print one line and exit 2.
#include "TreeLod/BakeTechniques.h"
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
#include <iterator>
#include <map>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        struct StudyArgs
        {
            std::vector<std::string> trees;
            std::vector<std::string> techniques; ///< default: budgeted auto's candidates but the reference
            std::vector<std::string> options; ///< TECHNIQUE.NAME=VALUE, as `treelod bake --option`
            std::vector<std::string> params;  ///< TECHNIQUE.NAME=VALUE, the object's createMovableObject parameters
            int size = 512;
            int supersample = 2;
            int azimuths = 1;
            std::string out = "out/corpus-study";
        };

        void progressLine(const std::string& line) { std::fprintf(stderr, "corpus-study: %s\n", line.c_str()); }

        /// TECHNIQUE.NAME=VALUE assignments (`flag` --option or --param) by technique; each
        /// technique among --techniques (or "mesh", for --param).
        std::map<std::string, BakeOptions> assignmentsByTechnique(const std::vector<std::string>& texts,
                                                                  const StudyArgs& args, const std::string& flag)
        {
            std::map<std::string, BakeOptions> byTechnique;
            for (const std::string& text : texts)
            {
                Result<BakeOptionAssignment> parsed = parseBakeOptionAssignment(text);
                if (!parsed)
                    throw StudyError(flag + " '" + text + "': " + parsed.error().reason);
                if (!(flag == "--param" && parsed->technique == "mesh") &&
                    !std::count(args.techniques.begin(), args.techniques.end(), parsed->technique))
                    throw StudyError(flag + " '" + text + "': '" + parsed->technique + "' is not among --techniques");
                byTechnique[parsed->technique][parsed->name] = parsed->value;
            }
            return byTechnique;
        }

        /// Every --technique is a baker and every --option names one of its options; --param is
        /// well formed. Before any work, so a typo costs nothing.
        void checkArguments(const StudyArgs& args)
        {
            std::map<std::string, BakeOptions> options = assignmentsByTechnique(args.options, args, "--option");
            assignmentsByTechnique(args.params, args, "--param");
            for (const std::string& name : args.techniques)
            {
                const BakeTechnique* technique = findBakeTechnique(name);
                if (!technique)
                    throw StudyError("technique '" + name + "': not a baker (" + knownBakeTechniques() + ")");
                if (Result<void> checked = checkBakeOptions(*technique, options[name], "--option"); !checked)
                    throw StudyError(checked.error().message());
            }
        }

        /// The package of every technique; `chunkBytes` gets each technique's chunk size (level 0).
        std::vector<std::uint8_t> bakePackage(const StudyTree& tree, const StudyArgs& args,
                                              std::map<std::string, std::uint64_t>& chunkBytes)
        {
            std::map<std::string, BakeOptions> options = assignmentsByTechnique(args.options, args, "--option");
            PackageWriter writer;
            for (const std::string& name : args.techniques)
            {
                const BakeTechnique* technique = findBakeTechnique(name);
                progressLine("baking " + name + " of " + tree.label);
                Result<void> baked = technique->bake(writer, tree.model, options[name], tree.label,
                                                     [](const std::string& step, float) {
                    if (step.rfind("warning: ", 0) == 0)
                        progressLine(step);
                });
                if (!baked)
                    throw StudyError(baked.error().message());
                const std::vector<std::uint8_t>* chunk = writer.chunkBytes(name, 0);
                chunkBytes[name] = chunk ? chunk->size() : 0;
            }
            return writer.toBytes();
        }

        struct View
        {
            const char* name;
            double fraction;  ///< tree height / view height; 0: `px`
            double px;
            double elevation; ///< degrees above the crown's height
        };
        const View VIEWS[] = {
            {"near", 0.9, 0.0, 0.0}, {"mid", 0.25, 0.0, 0.0}, {"far", 0.0, 30.0, 0.0}, {"above", 0.25, 0.0, 60.0}};

        struct Row
        {
            std::string tree, technique, view;
            int treePx = 0;
            double flip = 0.0, rmse = 0.0;
            double coverage = 0.0; ///< tree pixels of the technique / tree pixels of the reference
            std::uint64_t bytes = 0; ///< the technique's chunk in the package
        };

        struct Worst
        {
            double flip = -1.0;
            std::string where;
            Image reference, image, heat;
        };

        void measureTree(OffscreenRenderer& renderer, const StudyTree& tree, const TreeAssetPtr& asset,
                         const std::map<std::string, std::uint64_t>& chunkBytes, const StudyArgs& args,
                         std::vector<Row>& rows, std::map<std::string, Worst>& worst)
        {
            renderer.clearContent();
            Ogre::SceneNode* node = renderer.getContentNode().createChildSceneNode();
            std::vector<std::pair<std::string, Ogre::MovableObject*>> objects;
            TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
            for (const std::string& technique : [&] {
                     std::vector<std::string> all{"mesh"};
                     all.insert(all.end(), args.techniques.begin(), args.techniques.end());
                     return all;
                 }())
            {
                Ogre::NameValuePairList params = registry.get(technique).roles.referenceShadingParams;
                std::map<std::string, BakeOptions> assigned = assignmentsByTechnique(args.params, args, "--param");
                for (const auto& [name, value] : assigned[technique])
                    params[name] = value;
                Ogre::MovableObject* object = registry.createInstance(technique, renderer.getSceneManager(),
                                                                      "corpus-" + technique, *asset, params);
                node->attachObject(object);
                objects.emplace_back(technique, object);
            }
            auto show = [&](std::size_t only) {
                for (std::size_t i = 0; i < objects.size(); ++i)
                    objects[i].second->setVisible(i == only);
            };

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
            const glm::vec3 crown = 0.5f * (lo + hi);
            const double height = tree.model.boundsMax.y - tree.model.boundsMin.y;
            for (const View& view : VIEWS)
            {
                const double px = view.fraction > 0.0 ? view.fraction * args.size : view.px;
                const double distance = distanceForHeight(height, px, args.size, STUDY_FOV_Y_DEGREES);
                progressLine(format("%s, %s: tree %.0f px tall at %.1f m", tree.label.c_str(), view.name, px, distance));
                const std::size_t firstRow = rows.size();
                for (int k = 0; k < args.azimuths; ++k)
                {
                    const double azimuth = STUDY_PI / 6.0 + 2.0 * STUDY_PI * k / args.azimuths;
                    const double elevation = view.elevation * STUDY_PI / 180.0;
                    CameraSpec camera;
                    camera.position = crown + float(distance) * glm::vec3(float(std::cos(elevation) * std::sin(azimuth)),
                                                                          float(std::sin(elevation)),
                                                                          float(std::cos(elevation) * std::cos(azimuth)));
                    camera.target = crown;
                    camera.fovYDegrees = STUDY_FOV_Y_DEGREES;
                    camera.farClip = float(4.0 * distance + 2.0 * height);
                    std::vector<Image> images(objects.size());
                    for (std::size_t i = 0; i < objects.size(); ++i)
                    {
                        show(i);
                        images[i] = toImage(renderer.render(camera, args.size, args.size, args.supersample));
                    }
                    const Crop crop = cropAround(treeExtent(images[0]), args.size, args.size);
                    const Image reference = cropImage(images[0], crop);
                    for (std::size_t i = 1; i < objects.size(); ++i)
                    {
                        if (k == 0)
                        {
                            Row row;
                            row.tree = tree.label;
                            row.technique = objects[i].first;
                            row.view = view.name;
                            row.treePx = treeExtent(images[0]).heightPx();
                            row.bytes = chunkBytes.at(row.technique);
                            rows.push_back(row);
                        }
                        Row& row = rows[firstRow + i - 1];
                        const Image test = cropImage(images[i], crop);
                        FlipOptions keep;
                        keep.keepErrorMap = true;
                        Result<FlipResult> flipped = flip(reference, test, keep);
                        if (!flipped)
                            throw StudyError("FLIP: " + flipped.error().message());
                        row.flip += flipped->mean / args.azimuths;
                        row.rmse += multiScaleRmseOf(reference, test) / args.azimuths;
                        row.coverage +=
                            treeCoverage(images[i]) / std::max(treeCoverage(images[0]), 1e-9) / args.azimuths;
                        Worst& w = worst[row.technique];
                        if (flipped->mean > w.flip)
                        {
                            w.flip = flipped->mean;
                            w.where = tree.label + ", " + view.name +
                                      (args.azimuths > 1 ? format(", azimuth %.0f", azimuth * 180.0 / STUDY_PI) : "");
                            w.reference = reference;
                            w.image = test;
                            w.heat = flipHeatmap(flipped.value());
                        }
                    }
                }
            }
            renderer.clearContent();
        }

        const Row* findRow(const std::vector<Row>& rows, const std::string& tree, const std::string& technique,
                           const std::string& view)
        {
            for (const Row& r : rows)
                if (r.tree == tree && r.technique == technique && r.view == view)
                    return &r;
            return nullptr;
        }

        int run(StudyArgs args, const std::string& commandLine)
        {
            checkArguments(args);
            if (args.trees.empty())
            {
                args.trees = {"media/oak.glb", "media/conifer.glb", "media/birch.glb", "generated:oak:3000:4:6",
                              "generated:oak:3000:1:1:45"};
                std::vector<std::string> thirdParty;
                if (std::filesystem::is_directory("media/third-party"))
                    for (const auto& entry : std::filesystem::directory_iterator("media/third-party"))
                        if (entry.path().extension() == ".glb")
                            thirdParty.push_back(entry.path().string());
                std::sort(thirdParty.begin(), thirdParty.end());
                if (thirdParty.empty())
                    progressLine("no third-party trees in media/third-party/ (docs/measurements.md: how to make them)");
                args.trees.insert(args.trees.end(), thirdParty.begin(), thirdParty.end());
            }
            std::filesystem::create_directories(args.out);
            OffscreenRenderer renderer;
            renderer.setLighting(LightingSpec());
            std::vector<Row> rows;
            std::map<std::string, Worst> worst;
            std::vector<std::string> labels;
            for (std::size_t t = 0; t < args.trees.size(); ++t)
            {
                const StudyTree tree = loadStudyTree(args.trees[t]);
                labels.push_back(tree.label);
                std::map<std::string, std::uint64_t> chunkBytes;
                TreeAssetPtr asset = TreeAssetManager::getSingleton().loadFromBytes(
                    format("corpus-%zu.treelod", t), Ogre::RGN_DEFAULT, bakePackage(tree, args, chunkBytes));
                measureTree(renderer, tree, asset, chunkBytes, args, rows, worst);
                TreeAssetManager::getSingleton().remove(asset);
            }

            std::ostringstream md;
            nlohmann::json json;
            md << "# Every technique against the polygonal tree, over a corpus\n\n";
            md << "Command: `" << commandLine << "`\n\n";
            md << "FLIP (mean) over the square around the tree, " << args.size << "x" << args.size << ", "
               << args.supersample << "x" << args.supersample
               << " supersampled; near: the tree fills 90 % of the view, mid: a quarter, far: 30 px tall, all "
                  "at the crown's height; above: as mid, from 60 degrees up; "
               << (args.azimuths > 1 ? format("the mean over %d azimuths from 30 degrees.\n\n", args.azimuths)
                                     : std::string("from azimuth 30 degrees.\n\n"));
            md << "Coverage: the technique's tree pixels over the reference's (1 = as covered).\n\n";
            md << "| tree | technique";
            for (const char* metric : {"FLIP", "ms-RMSE", "coverage"})
                for (const View& view : VIEWS)
                    md << " | " << metric << " " << view.name;
            md << " | chunk KB |\n|---|---|";
            for (std::size_t i = 0; i < 3 * std::size(VIEWS) + 1; ++i)
                md << "---|";
            md << "\n";
            std::string csv = "tree,technique,view,treePx,flip,rmse,coverage,bytes\n";
            for (const std::string& tree : labels)
                for (const std::string& technique : args.techniques)
                {
                    md << "| " << tree << " | " << technique;
                    for (double Row::*metric : {&Row::flip, &Row::rmse, &Row::coverage})
                        for (const View& view : VIEWS)
                            if (const Row* r = findRow(rows, tree, technique, view.name))
                                md << format(metric == &Row::coverage ? " | %.3f" : " | %.4f", r->*metric);
                    if (const Row* r = findRow(rows, tree, technique, VIEWS[0].name))
                        md << format(" | %.0f", double(r->bytes) / 1024.0);
                    md << " |\n";
                }
            for (const Row& r : rows)
            {
                csv += format("\"%s\",%s,%s,%d,%.6f,%.6f,%.4f,%llu\n", r.tree.c_str(), r.technique.c_str(),
                              r.view.c_str(), r.treePx, r.flip, r.rmse, r.coverage, (unsigned long long)r.bytes);
                json["rows"].push_back({{"tree", r.tree},
                                        {"technique", r.technique},
                                        {"view", r.view},
                                        {"treePx", r.treePx},
                                        {"flip", r.flip},
                                        {"rmse", r.rmse},
                                        {"coverage", r.coverage},
                                        {"bytes", r.bytes}});
            }

            // Each technique against its paper's baseline (TechniqueRoles::paperBaseline), where both ran.
            const auto studied = [&](const std::string& t) {
                return std::count(args.techniques.begin(), args.techniques.end(), t) > 0;
            };
            for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            {
                const std::string technique = info.name, baseline = info.roles.paperBaseline;
                if (baseline.empty() || !studied(technique) || !studied(baseline))
                    continue;
                md << "\n## " << technique << " against " << baseline << " at equal memory (FLIP)\n\n| tree";
                for (const View& view : VIEWS)
                    md << " | " << view.name;
                md << " |\n|---|";
                for (std::size_t i = 0; i < std::size(VIEWS); ++i)
                    md << "---|";
                md << "\n";
                int wins = 0, cases = 0;
                for (const std::string& tree : labels)
                {
                    md << "| " << tree;
                    for (const View& view : VIEWS)
                    {
                        const Row* l = findRow(rows, tree, technique, view.name);
                        const Row* c = findRow(rows, tree, baseline, view.name);
                        if (!l || !c)
                            continue;
                        ++cases;
                        wins += l->flip <= c->flip;
                        md << format(" | %.4f vs %.4f %s", l->flip, c->flip,
                                     l->flip <= c->flip ? ("(" + technique + ")").c_str() : ("(" + baseline + ")").c_str());
                    }
                    md << " |\n";
                }
                md << format("\n%s is at or below %s in %d of %d cases.\n", technique.c_str(), baseline.c_str(), wins, cases);
                json["againstPaperBaseline"][technique] = {{"baseline", baseline}, {"wins", wins}, {"cases", cases}};
            }

            md << "\n## Worst case of each technique\n\n";
            for (auto& [technique, w] : worst)
            {
                const int panel = 256;
                const Crop whole{0, 0, w.reference.width};
                const Image p0 = magnify(w.reference, whole, panel), p1 = magnify(w.image, whole, panel),
                            p2 = magnify(w.heat, whole, panel);
                const std::string file = "worst-" + technique + ".png";
                writeImage(args.out + "/" + file, composePanels({{&p0, &p1, &p2}}));
                md << format("- %s: FLIP %.4f (%s), `%s` (reference | %s | FLIP)\n", technique.c_str(), w.flip,
                             w.where.c_str(), file.c_str(), technique.c_str());
                json["worst"][technique] = {{"flip", w.flip}, {"where", w.where}, {"picture", file}};
            }
            writeText(args.out + "/error.csv", csv);
            writeSummary(args.out, md.str(), json, commandLine);
            return 0;
        }
    }
}

int main(int argc, char** argv)
{
    TreeLod::StudyArgs args;
    for (const TreeLod::TechniqueInfo& info : TreeLod::TechniqueRegistry::getSingleton().getTechniques())
        if (info.roles.autoCandidate && info.name != TreeLod::REFERENCE_TECHNIQUE)
            args.techniques.push_back(info.name);
    CLI::App app{"Every technique against the polygonal tree over a corpus of trees: tree-box FLIP and multi-scale "
                 "RMSE near, mid and far. Needs an X server (xvfb-run)."};
    app.add_option("--trees", args.trees,
                   "trees: .glb/.gltf paths or generated:PRESET[:LEAVES[:IMAGES[:MATERIALS[:FOLD]]]] (default: the bundled "
                   "trees, generated:oak:3000:4:6, generated:oak:3000:1:1:45 and media/third-party/*.glb)");
    app.add_option("--techniques", args.techniques,
                   "techniques to bake and compare (default: those budgeted auto chooses among, as `treelod info "
                   "--techniques` lists them)")
        ->capture_default_str();
    app.add_option("--option", args.options, "a baker's option, TECHNIQUE.NAME=VALUE (as treelod bake --option)");
    app.add_option("--param", args.params,
                   "an object parameter, TECHNIQUE.NAME=VALUE (as createMovableObject's, e.g. billboard-cloud.level=1)");
    app.add_option("--size", args.size, "image size")->capture_default_str()->check(CLI::Range(64, 4096));
    app.add_option("--supersample", args.supersample, "samples per pixel per axis")
        ->capture_default_str()
        ->check(CLI::Range(1, 8));
    app.add_option("--azimuths", args.azimuths, "views per distance, 360/N degrees apart from 30 (metrics averaged)")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    app.add_option("--out", args.out, "output directory")->capture_default_str();
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        return app.exit(e);
    }
    const std::string commandLine = TreeLod::studyCommandLine("treelod_corpus_study", argc, argv);
    return TreeLod::runStudy("treelod_corpus_study", [&] { return TreeLod::run(args, commandLine); });
}
