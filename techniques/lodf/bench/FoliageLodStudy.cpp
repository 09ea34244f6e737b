// treelod_lodf_study: what LoDF (Rebollo et al. 2006) buys on one tree, measured headless through the
// plugin against the polygonal reference ("mesh") rendered by the same Ogre pipeline.
//
// 1. Continuity (zoom): F frames with the camera log-spaced from --near to --far metres
//    (horizontal distance from the crown's axis), eye at 1.5 m above the tree's base, fixed
//    azimuth, looking at the crown centre (leaf bounding box). Each frame renders the
//    reference, "lodf" continuous and "lodf" quantised to --levels geometric levels (the
//    discrete, popping baseline) at S x S supersampled. Per frame: leaf counts, FLIP against
//    the reference, and the popping excess: FLIP between a technique's consecutive frames
//    minus the reference's own consecutive-frame FLIP at the same step (what the technique
//    changes beyond what the camera motion changes; raw in the CSV, clamped at 0 in the
//    summary).
// 2. Trade-off: at distances where the tree is about 400, 150, 50 px tall at 512 x 512, for
//    each pixelsPerLeaf: FLIP against the supersampled reference and the median frame time
//    (OffscreenRenderer::timeFrames, 1 sample per pixel) of lodf and of the reference in the
//    same run, their ratio, and the cheapest setting that keeps FLIP within --flip-bound.
// FLIP is reported over the whole frame (as asked) and over the square around the tree (the
// whole-frame mean of a small tree is mostly sky). Unless --no-cpu-reference, every image is
// also compared with the CPU ray-traced reference (ReferenceRenderer: leaf alpha from the
// full-resolution texture), because the Ogre reference's alpha-tested, mip-mapped leaves thin
// out on small trees and a technique that keeps them can be closer to the truth than to it.
// Output in --out: zoom.csv, tradeoff.csv, summary.md, summary.json, zoom.svg, zoom-*.png
// (reference | lodf | discrete, full frame above, the tree magnified below) and
// pop-worst.png (the discrete baseline's largest pop next to lodf at the same step).
//
// Needs an X server: xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" treelod_lodf_study [options]
// Errors print one line and exit 2. Timings on llvmpipe are CPU timings (docs/architecture.md,
// "Measuring"): compare ratios, not milliseconds, across machines.
#include "TreeLod/AtomicFile.h"
#include "TreeLod/FoliageLodBaker.h"
#include "TreeLod/FoliageLodTree.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeGenerator.h"

#include "StudySupport.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace TreeLod
{
    namespace
    {
        struct StudyArgs
        {
            std::string tree;
            std::uint32_t leaves = 0;
            std::uint32_t seed = 1;
            int frames = 48;
            int size = 256;
            int supersample = 3;
            double nearDistance = 1.0;
            double farDistance = 2000.0;
            double eyeHeight = 1.5;
            double azimuth = 30.0;
            std::uint32_t levels = 4;
            int timingSize = 512;
            int timingFrames = 15;
            std::vector<double> heights{400.0, 150.0, 50.0};
            std::vector<double> pixelsPerLeaf{1.0, 2.0, 4.0, 8.0, 16.0, 32.0};
            double flipBound = 0.05;
            bool cpuReference = true;
            std::string out = "out/lodf-study";
        };

        constexpr float FOV_Y_DEGREES = STUDY_FOV_Y_DEGREES;
        constexpr double PI = STUDY_PI;

        void progressLine(const std::string& line) { std::fprintf(stderr, "lodf-study: %s\n", line.c_str()); }

        // ---- the tree and its three objects ------------------------------------------------

        struct StudyTree
        {
            std::string label;
            TreeModel model;
            glm::vec3 crownCentre{0.0f}; ///< centre of the leaves' bounding box
            std::uint32_t clusters = 0;
        };

        StudyTree loadTree(const StudyArgs& args)
        {
            StudyTree tree;
            if (args.leaves > 0)
            {
                GeneratorOptions options;
                options.preset = TreePreset::Oak;
                options.seed = args.seed;
                options.leafCount = args.leaves;
                Result<TreeModel> model = generateTree(options);
                if (!model)
                    throw StudyError(model.error().message());
                tree.model = std::move(model.value());
                tree.label = format("generated oak, seed %u, %u leaves", args.seed, args.leaves);
            }
            else
            {
                Result<TreeModel> model = importGltf(args.tree);
                if (!model)
                    throw StudyError(model.error().message());
                tree.model = std::move(model.value());
                tree.label = std::filesystem::path(args.tree).filename().string();
            }
            if (tree.model.leaves.empty())
                throw StudyError(tree.label + ": the tree has no leaves; LoDF has nothing to simplify");
            glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            for (const Vertex& v : tree.model.leafVertices)
            {
                lo = glm::min(lo, v.position);
                hi = glm::max(hi, v.position);
            }
            tree.crownCentre = 0.5f * (lo + hi);
            return tree;
        }

        /// The reference, continuous LoDF and quantised LoDF of one asset, one drawn at a time.
        class Techniques
        {
        public:
            Techniques(OffscreenRenderer& renderer, StudyTree& tree, std::uint32_t levels) : mRenderer(renderer)
            {
                PackageWriter writer;
                Result<void> added = addFoliageLodChunk(writer, tree.model, tree.label);
                if (!added)
                    throw StudyError(added.error().message());
                TreeAssetPtr asset =
                    TreeAssetManager::getSingleton().loadFromBytes("lodf-study.treelod", Ogre::RGN_DEFAULT, writer.toBytes());
                Ogre::SceneManager& sm = renderer.getSceneManager();
                TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
                renderer.clearContent();
                mMesh = registry.createInstance("mesh", sm, "study-mesh", *asset);
                mLodf = asLodf(registry.createInstance("lodf", sm, "study-lodf", *asset));
                mDiscrete = asLodf(registry.createInstance("lodf", sm, "study-discrete", *asset,
                                                           {{"quantise", std::to_string(levels)}}));
                for (Ogre::MovableObject* object : {mMesh, static_cast<Ogre::MovableObject*>(mLodf),
                                                    static_cast<Ogre::MovableObject*>(mDiscrete)})
                    renderer.getContentNode().createChildSceneNode()->attachObject(object);
                tree.clusters = mLodf->getMinLeafCount();
            }

            Ogre::MovableObject* mesh() { return mMesh; }
            /// Bark LoD level the reference Entity drew last (0 = full); compare getBarkLodIndex().
            unsigned meshLodIndex() const
            {
                auto* entity = dynamic_cast<Ogre::Entity*>(mMesh);
                return entity ? entity->getCurrentLodIndex() : 0;
            }
            FoliageLodTree* lodf() { return mLodf; }
            FoliageLodTree* discrete() { return mDiscrete; }

            Image render(Ogre::MovableObject* object, const CameraSpec& camera, int size, int supersample)
            {
                show(object);
                return toImage(mRenderer.render(camera, size, size, supersample));
            }

            double medianFrameMs(Ogre::MovableObject* object, const CameraSpec& camera, int size, int frames)
            {
                show(object);
                return median(mRenderer.timeFrames(camera, size, size, frames));
            }

        private:
            static FoliageLodTree* asLodf(Ogre::MovableObject* object)
            {
                auto* tree = dynamic_cast<FoliageLodTree*>(object);
                if (!tree)
                    throw StudyError("technique 'lodf' did not create a FoliageLodTree");
                return tree;
            }

            void show(Ogre::MovableObject* only)
            {
                for (Ogre::MovableObject* object : {mMesh, static_cast<Ogre::MovableObject*>(mLodf),
                                                    static_cast<Ogre::MovableObject*>(mDiscrete)})
                    object->setVisible(object == only);
            }

            OffscreenRenderer& mRenderer;
            Ogre::MovableObject* mMesh = nullptr;
            FoliageLodTree* mLodf = nullptr;
            FoliageLodTree* mDiscrete = nullptr;
        };

        /// Eye `eyeHeight` above the tree's base, `distance` metres from the crown's vertical
        /// axis at `azimuth`, looking at the crown centre; as an explicit camera string.
        std::string cameraText(const StudyTree& tree, const StudyArgs& args, double distance)
        {
            const double az = args.azimuth * PI / 180.0;
            const glm::vec3& c = tree.crownCentre;
            return format("%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%g", c.x + distance * std::sin(az),
                          tree.model.boundsMin.y + args.eyeHeight, c.z + distance * std::cos(az), c.x, c.y, c.z,
                          double(FOV_Y_DEGREES));
        }

        CameraSpec parseCamera(const StudyTree& tree, const std::string& text)
        {
            CameraSpec camera;
            std::string error;
            if (!CameraSpec::parse(text, tree.model.boundsMin, tree.model.boundsMax, camera, error))
                throw StudyError("camera '" + text + "': " + error);
            return camera;
        }

        double distanceForHeight(const StudyTree& tree, double px, int size)
        {
            return TreeLod::distanceForHeight(tree.model.boundsMax.y - tree.model.boundsMin.y, px, size);
        }

        // ---- 1. continuity ------------------------------------------------------------------

        struct ZoomFrame
        {
            double distance = 0.0;
            std::string camera;
            int treePx = 0;
            std::uint32_t leavesLodf = 0, leavesDiscrete = 0;
            unsigned barkLodMesh = 0, barkLodLodf = 0; ///< bark LoD level drawn (0 = full)
            double uploadedKibLodf = 0.0, uploadedKibDiscrete = 0.0;
            double flipLodf = 0.0, flipDiscrete = 0.0;
            /// Against the CPU ray-traced reference (no mip-mapping), when it is rendered.
            std::optional<double> cpuMesh, cpuLodf, cpuDiscrete;
            std::optional<double> stepReference, stepLodf, stepDiscrete; ///< none for frame 0
            /// The same over the square around the tree (cropAround the reference's extent; for
            /// steps, of both frames' extents), when that square is at least MIN_TREE_SQUARE.
            std::optional<double> treeFlipLodf, treeFlipDiscrete;
            std::optional<double> treeStepReference, treeStepLodf, treeStepDiscrete;
            double excessLodf() const { return *stepLodf - *stepReference; }
            double excessDiscrete() const { return *stepDiscrete - *stepReference; }
            double treeExcessLodf() const { return *treeStepLodf - *treeStepReference; }
            double treeExcessDiscrete() const { return *treeStepDiscrete - *treeStepReference; }
        };

        struct ZoomImages
        {
            Image reference, lodf, discrete;
            Extent extent; ///< of the reference
        };

        /// Smallest square (pixels) compared "over the tree": below it FLIP's filters see
        /// mostly the square's edges.
        constexpr int MIN_TREE_SQUARE = 16;

        struct TechniqueSummary
        {
            double meanFlip = 0.0, maxFlip = 0.0;
            std::optional<double> meanFlipCpu;        ///< against the CPU reference
            double meanExcess = 0.0, maxExcess = 0.0; ///< clamped at 0
            double maxExcessDistance = 0.0;           ///< where the largest excess happened
            int worstStep = 0;                         ///< frame index ending that step
            int leafChanges = 0;                       ///< frames whose leaf count differs from the previous
            // Over the square around the tree (frames / steps where it was measured).
            double treeMeanFlip = 0.0, treeMaxFlip = 0.0, treeMeanExcess = 0.0, treeMaxExcess = 0.0;
            double treeMaxExcessDistance = 0.0;
            int treeFrames = 0, treeSteps = 0;
            double meanLeaves = 0.0;
            double uploadedKib = 0.0;
        };

        TechniqueSummary summarise(const std::vector<ZoomFrame>& frames, bool discrete)
        {
            TechniqueSummary s;
            int steps = 0;
            for (std::size_t i = 0; i < frames.size(); ++i)
            {
                const ZoomFrame& f = frames[i];
                const double flipValue = discrete ? f.flipDiscrete : f.flipLodf;
                s.meanFlip += flipValue;
                s.maxFlip = std::max(s.maxFlip, flipValue);
                s.meanLeaves += discrete ? f.leavesDiscrete : f.leavesLodf;
                s.uploadedKib += discrete ? f.uploadedKibDiscrete : f.uploadedKibLodf;
                if (f.treeFlipLodf)
                {
                    const double v = discrete ? *f.treeFlipDiscrete : *f.treeFlipLodf;
                    s.treeMeanFlip += v;
                    s.treeMaxFlip = std::max(s.treeMaxFlip, v);
                    ++s.treeFrames;
                }
                if (f.treeStepReference)
                {
                    const double v = std::max(0.0, discrete ? f.treeExcessDiscrete() : f.treeExcessLodf());
                    s.treeMeanExcess += v;
                    if (v > s.treeMaxExcess || s.treeSteps == 0)
                    {
                        s.treeMaxExcess = v;
                        s.treeMaxExcessDistance = f.distance;
                    }
                    ++s.treeSteps;
                }
                if (f.cpuLodf)
                    s.meanFlipCpu = s.meanFlipCpu.value_or(0.0) + (discrete ? *f.cpuDiscrete : *f.cpuLodf);
                if (i == 0)
                    continue;
                const double excess = std::max(0.0, discrete ? f.excessDiscrete() : f.excessLodf());
                s.meanExcess += excess;
                if (excess > s.maxExcess || steps == 0)
                {
                    s.maxExcess = excess;
                    s.maxExcessDistance = f.distance;
                    s.worstStep = int(i);
                }
                ++steps;
                const ZoomFrame& p = frames[i - 1];
                s.leafChanges += discrete ? f.leavesDiscrete != p.leavesDiscrete : f.leavesLodf != p.leavesLodf;
            }
            s.meanFlip /= double(frames.size());
            if (s.meanFlipCpu)
                *s.meanFlipCpu /= double(frames.size());
            s.meanLeaves /= double(frames.size());
            s.meanExcess /= double(std::max(steps, 1));
            s.treeMeanFlip /= double(std::max(s.treeFrames, 1));
            s.treeMeanExcess /= double(std::max(s.treeSteps, 1));
            return s;
        }

        struct ZoomResult
        {
            std::vector<ZoomFrame> frames;
            TechniqueSummary lodf, discrete;
            std::optional<double> meanMeshCpu, maxMeshCpu; ///< the Ogre reference against the CPU one
            std::vector<std::string> pictures;
            double seconds = 0.0;
        };

        ZoomResult runZoom(Techniques& techniques, const StudyTree& tree, const StudyArgs& args,
                           const ReferenceRenderer* cpu)
        {
            const auto start = std::chrono::steady_clock::now();
            ZoomResult result;
            std::vector<ZoomImages> images;
            const int n = args.frames;
            std::uint64_t uploadedLodf = techniques.lodf()->getUpdateStats().totalBytesUploaded;
            std::uint64_t uploadedDiscrete = techniques.discrete()->getUpdateStats().totalBytesUploaded;
            for (int i = 0; i < n; ++i)
            {
                ZoomFrame f;
                f.distance = args.nearDistance * std::pow(args.farDistance / args.nearDistance, double(i) / (n - 1));
                f.camera = cameraText(tree, args, f.distance);
                const CameraSpec camera = parseCamera(tree, f.camera);
                ZoomImages frame;
                frame.reference = techniques.render(techniques.mesh(), camera, args.size, args.supersample);
                frame.lodf = techniques.render(techniques.lodf(), camera, args.size, args.supersample);
                frame.discrete = techniques.render(techniques.discrete(), camera, args.size, args.supersample);
                frame.extent = treeExtent(frame.reference);
                f.treePx = frame.extent.heightPx();
                f.leavesLodf = techniques.lodf()->getLeafCount();
                f.barkLodMesh = techniques.meshLodIndex();
                f.barkLodLodf = techniques.lodf()->getBarkLodIndex();
                f.leavesDiscrete = techniques.discrete()->getLeafCount();
                const std::uint64_t totalLodf = techniques.lodf()->getUpdateStats().totalBytesUploaded;
                const std::uint64_t totalDiscrete = techniques.discrete()->getUpdateStats().totalBytesUploaded;
                f.uploadedKibLodf = double(totalLodf - uploadedLodf) / 1024.0;
                f.uploadedKibDiscrete = double(totalDiscrete - uploadedDiscrete) / 1024.0;
                uploadedLodf = totalLodf;
                uploadedDiscrete = totalDiscrete;
                f.flipLodf = flipMean(frame.reference, frame.lodf);
                f.flipDiscrete = flipMean(frame.reference, frame.discrete);
                if (i > 0)
                {
                    const ZoomImages& prev = images.back();
                    f.stepReference = flipMean(prev.reference, frame.reference);
                    f.stepLodf = flipMean(prev.lodf, frame.lodf);
                    f.stepDiscrete = flipMean(prev.discrete, frame.discrete);
                }
                if (frame.extent.any())
                {
                    const Crop crop = cropAround(frame.extent, args.size, args.size);
                    if (crop.side >= MIN_TREE_SQUARE)
                    {
                        const Image reference = magnify(frame.reference, crop, crop.side);
                        f.treeFlipLodf = flipMean(reference, magnify(frame.lodf, crop, crop.side));
                        f.treeFlipDiscrete = flipMean(reference, magnify(frame.discrete, crop, crop.side));
                    }
                }
                if (i > 0 && frame.extent.any() && images.back().extent.any())
                {
                    const ZoomImages& prev = images.back();
                    const Crop crop = cropAround(unite(prev.extent, frame.extent), args.size, args.size);
                    if (crop.side >= MIN_TREE_SQUARE)
                    {
                        auto step = [&](const Image& a, const Image& b) {
                            return flipMean(magnify(a, crop, crop.side), magnify(b, crop, crop.side));
                        };
                        f.treeStepReference = step(prev.reference, frame.reference);
                        f.treeStepLodf = step(prev.lodf, frame.lodf);
                        f.treeStepDiscrete = step(prev.discrete, frame.discrete);
                    }
                }
                if (cpu)
                {
                    const Image traced = traceReference(*cpu, camera, args.size, args.supersample);
                    f.cpuMesh = flipMean(traced, frame.reference);
                    f.cpuLodf = flipMean(traced, frame.lodf);
                    f.cpuDiscrete = flipMean(traced, frame.discrete);
                    result.meanMeshCpu = result.meanMeshCpu.value_or(0.0) + *f.cpuMesh / n;
                    result.maxMeshCpu = std::max(result.maxMeshCpu.value_or(0.0), *f.cpuMesh);
                }
                progressLine(format("zoom %d/%d: %.4g m, tree %d px; lodf %u leaves FLIP %.4f; discrete %u leaves FLIP %.4f%s",
                                    i + 1, n, f.distance, f.treePx, f.leavesLodf, f.flipLodf, f.leavesDiscrete,
                                    f.flipDiscrete,
                                    i > 0 ? format("; pop excess lodf %+.4f discrete %+.4f", f.excessLodf(),
                                                   f.excessDiscrete()).c_str()
                                          : ""));
                result.frames.push_back(f);
                images.push_back(std::move(frame));
            }
            result.lodf = summarise(result.frames, false);
            result.discrete = summarise(result.frames, true);

            // Pictures: the frames nearest to four tree heights (fractions of the frame height).
            std::vector<int> picked;
            for (double fraction : {0.6, 0.2, 0.06, 0.02})
            {
                const double d = distanceForHeight(tree, fraction * args.size, args.size);
                int best = 0;
                for (int i = 1; i < n; ++i)
                    if (std::abs(std::log(result.frames[i].distance / d)) <
                        std::abs(std::log(result.frames[best].distance / d)))
                        best = i;
                if (std::find(picked.begin(), picked.end(), best) == picked.end())
                    picked.push_back(best);
            }
            for (int i : picked)
            {
                const ZoomImages& f = images[i];
                const Crop crop = cropAround(treeExtent(f.reference), args.size, args.size);
                const Image mr = magnify(f.reference, crop, args.size), ml = magnify(f.lodf, crop, args.size),
                            md = magnify(f.discrete, crop, args.size);
                const std::string name = format("zoom-%03d-%gm.png", i, std::round(result.frames[i].distance * 10.0) / 10.0);
                writeImage(args.out + "/" + name, composePanels({{&f.reference, &f.lodf, &f.discrete}, {&mr, &ml, &md}}));
                result.pictures.push_back(name);
            }
            // The discrete baseline's worst pop next to lodf across the same step.
            if (n > 1)
            {
                const int i = result.discrete.worstStep;
                const Crop crop = cropAround(treeExtent(images[i - 1].reference), args.size, args.size);
                std::vector<Image> panels;
                for (const Image* image : {&images[i - 1].discrete, &images[i].discrete, &images[i - 1].lodf,
                                           &images[i].lodf, &images[i - 1].reference, &images[i].reference})
                    panels.push_back(magnify(*image, crop, args.size));
                writeImage(args.out + "/pop-worst.png", composePanels({{&panels[0], &panels[1]},
                                                                       {&panels[2], &panels[3]},
                                                                       {&panels[4], &panels[5]}}));
                result.pictures.push_back("pop-worst.png");
            }
            result.seconds = secondsSince(start);
            return result;
        }

        std::string zoomCsv(const std::vector<ZoomFrame>& frames)
        {
            // Differences below the printed precision print as 0, not "-0.000000".
            auto fixed6 = [](double v) { return format("%.6f", std::abs(v) < 5e-7 ? 0.0 : v); };
            std::ostringstream csv;
            csv << "frame,distance_m,tree_px,camera,leaves_lodf,leaves_discrete,uploaded_kib_lodf,uploaded_kib_discrete,"
                   "flip_lodf,flip_discrete,step_flip_reference,step_flip_lodf,step_flip_discrete,"
                   "pop_excess_lodf,pop_excess_discrete,cpu_flip_mesh,cpu_flip_lodf,cpu_flip_discrete,"
                   "tree_flip_lodf,tree_flip_discrete,tree_step_flip_reference,tree_step_flip_lodf,"
                   "tree_step_flip_discrete,tree_pop_excess_lodf,tree_pop_excess_discrete,bark_lod_mesh,bark_lod_lodf\n";
            for (std::size_t i = 0; i < frames.size(); ++i)
            {
                const ZoomFrame& f = frames[i];
                csv << i << ',' << format("%.6g", f.distance) << ',' << f.treePx << ",\"" << f.camera << "\","
                    << f.leavesLodf << ',' << f.leavesDiscrete << ',' << format("%.3f", f.uploadedKibLodf) << ','
                    << format("%.3f", f.uploadedKibDiscrete) << ',' << format("%.6f", f.flipLodf) << ','
                    << format("%.6f", f.flipDiscrete);
                if (f.stepReference)
                {
                    csv << ',' << format("%.6f,%.6f,%.6f", *f.stepReference, *f.stepLodf, *f.stepDiscrete) << ','
                        << fixed6(f.excessLodf()) << ',' << fixed6(f.excessDiscrete());
                }
                else
                    csv << ",,,,,";
                if (f.cpuMesh)
                    csv << format(",%.6f,%.6f,%.6f", *f.cpuMesh, *f.cpuLodf, *f.cpuDiscrete);
                else
                    csv << ",,,";
                if (f.treeFlipLodf)
                    csv << format(",%.6f,%.6f", *f.treeFlipLodf, *f.treeFlipDiscrete);
                else
                    csv << ",,";
                if (f.treeStepReference)
                    csv << format(",%.6f,%.6f,%.6f,", *f.treeStepReference, *f.treeStepLodf, *f.treeStepDiscrete)
                        << fixed6(f.treeExcessLodf()) << ',' << fixed6(f.treeExcessDiscrete());
                else
                    csv << ",,,,,";
                csv << ',' << f.barkLodMesh << ',' << f.barkLodLodf << '\n';
            }
            return csv.str();
        }

        /// Two panels over x = log10(distance): FLIP against the reference (top) and the raw
        /// popping excess (bottom), continuous and discrete.
        std::string zoomSvg(const std::vector<ZoomFrame>& frames, const StudyArgs& args, const std::string& title)
        {
            const double W = 820, left = 70, right = 20, panelH = 150, top = 40, gap = 56;
            const double plotW = W - left - right, H = top + 20 + 4 * panelH + 3 * gap + 46;
            const double x0 = std::log10(args.nearDistance), x1 = std::log10(args.farDistance);
            auto px = [&](double d) { return left + (std::log10(d) - x0) / (x1 - x0) * plotW; };
            std::ostringstream svg;
            svg << format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
                          "viewBox=\"0 0 %g %g\" font-family=\"sans-serif\" font-size=\"12\">\n",
                          W, H, W, H);
            svg << format("<rect width=\"%g\" height=\"%g\" fill=\"white\"/>\n", W, H);
            svg << format("<text x=\"%g\" y=\"20\" font-size=\"14\">%s</text>\n", left, title.c_str());

            struct Series
            {
                std::string name;
                const char* colour;
                const char* dash; ///< stroke-dasharray, "" = solid
                std::vector<std::pair<double, double>> points;
            };
            auto dash = [](const char* pattern) {
                return *pattern ? format(" stroke-dasharray=\"%s\"", pattern) : std::string();
            };
            auto panel = [&](double y0, const char* label, std::vector<Series> series) {
                double lo = 0.0, hi = 0.0;
                for (const Series& s : series)
                    for (const auto& p : s.points)
                    {
                        lo = std::min(lo, p.second);
                        hi = std::max(hi, p.second);
                    }
                // A round upper bound: 1, 2 or 5 x 10^k.
                const double span = std::max(hi - lo, 1e-4);
                const double step = std::pow(10.0, std::floor(std::log10(span / 4.0)));
                const double tick = span / step > 20 ? 5 * step : (span / step > 8 ? 2 * step : step);
                lo = std::floor(lo / tick) * tick;
                hi = std::ceil(hi / tick) * tick;
                if (hi <= lo)
                    hi = lo + tick;
                auto py = [&](double v) { return y0 + panelH - (v - lo) / (hi - lo) * panelH; };
                svg << format("<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"#888\"/>\n",
                              left, y0, plotW, panelH);
                for (double v = lo; v <= hi + 0.5 * tick; v += tick)
                {
                    svg << format("<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"%s\"/>\n", left, py(v),
                                  left + plotW, py(v), std::abs(v) < 0.5 * tick ? "#444" : "#e4e4e4");
                    svg << format("<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">%.3g</text>\n", left - 6, py(v) + 4,
                                  std::abs(v) < 0.5 * tick ? 0.0 : v);
                }
                for (double d = std::pow(10.0, std::ceil(x0)); d <= args.farDistance * 1.0001; d *= 10.0)
                {
                    svg << format("<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"#e4e4e4\"/>\n", px(d), y0,
                                  px(d), y0 + panelH);
                    svg << format("<text x=\"%.1f\" y=\"%g\" text-anchor=\"middle\">%g m</text>\n", px(d),
                                  y0 + panelH + 16, d);
                }
                svg << format("<text x=\"%g\" y=\"%g\">%s</text>\n", left, y0 - 6, label);
                double legendX = left + plotW - 10;
                for (auto it = series.rbegin(); it != series.rend(); ++it)
                {
                    std::ostringstream path;
                    for (std::size_t i = 0; i < it->points.size(); ++i)
                        path << (i ? " L" : "M") << format("%.1f,%.1f", px(it->points[i].first), py(it->points[i].second));
                    svg << "<path d=\"" << path.str() << "\" fill=\"none\" stroke=\"" << it->colour
                        << "\" stroke-width=\"1.8\"" << dash(it->dash) << "/>\n";
                    legendX -= 6.5 * double(it->name.size()) + 34;
                    svg << format("<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"%s\" stroke-width=\"2.5\"%s/>",
                                  legendX, y0 - 10, legendX + 22, y0 - 10, it->colour, dash(it->dash).c_str());
                    svg << format("<text x=\"%g\" y=\"%g\">%s</text>\n", legendX + 26, y0 - 6, it->name.c_str());
                }
            };

            Series flipLodf{"lodf (continuous)", "#1f77b4", "", {}};
            Series flipDiscrete{format("%u discrete levels", args.levels), "#d62728", "6,3", {}};
            Series popLodf = flipLodf, popDiscrete = flipDiscrete;
            Series treeFlipLodf = flipLodf, treeFlipDiscrete = flipDiscrete;
            Series treePopLodf = treeFlipLodf, treePopDiscrete = treeFlipDiscrete;
            for (const ZoomFrame& f : frames)
            {
                flipLodf.points.emplace_back(f.distance, f.flipLodf);
                flipDiscrete.points.emplace_back(f.distance, f.flipDiscrete);
                if (f.stepReference)
                {
                    popLodf.points.emplace_back(f.distance, f.excessLodf());
                    popDiscrete.points.emplace_back(f.distance, f.excessDiscrete());
                }
                if (f.treeFlipLodf)
                {
                    treeFlipLodf.points.emplace_back(f.distance, *f.treeFlipLodf);
                    treeFlipDiscrete.points.emplace_back(f.distance, *f.treeFlipDiscrete);
                }
                if (f.treeStepReference)
                {
                    treePopLodf.points.emplace_back(f.distance, f.treeExcessLodf());
                    treePopDiscrete.points.emplace_back(f.distance, f.treeExcessDiscrete());
                }
            }
            const double y0 = top + 20, dy = panelH + gap;
            panel(y0, "FLIP against the reference, whole frame", {flipLodf, flipDiscrete});
            panel(y0 + dy, "FLIP against the reference, square around the tree", {treeFlipLodf, treeFlipDiscrete});
            panel(y0 + 2 * dy, "popping excess (step FLIP minus the reference's), whole frame", {popLodf, popDiscrete});
            panel(y0 + 3 * dy, "popping excess, square around the tree", {treePopLodf, treePopDiscrete});
            svg << format("<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">camera distance (log scale); "
                          "square around the tree: frames where it is at least %d px</text>\n",
                          left + plotW / 2, H - 8, MIN_TREE_SQUARE);
            svg << "</svg>\n";
            return svg.str();
        }

        // ---- 2. frame time at equal FLIP ----------------------------------------------------

        struct TradeoffSetting
        {
            double pixelsPerLeaf = 0.0;
            std::uint32_t leaves = 0;
            double flip = 0.0;     ///< whole frame
            double flipTree = 0.0; ///< the square around the tree only
            std::optional<double> cpuTree; ///< the square around the tree against the CPU reference
            unsigned barkLod = 0;          ///< bark LoD level lodf drew
            double lodfMs = 0.0;
            double ratio = 0.0;
        };

        struct TradeoffDistance
        {
            double targetPx = 0.0, distance = 0.0;
            int treePx = 0;
            int cropPx = 0; ///< side of the square around the tree that flipTree compares
            std::string camera;
            std::optional<double> meshCpuTree; ///< the reference itself against the CPU reference (tree square)
            unsigned meshBarkLod = 0;          ///< bark LoD level the reference drew
            double meshMsBefore = 0.0, meshMsAfter = 0.0;
            double meshMs() const { return 0.5 * (meshMsBefore + meshMsAfter); }
            std::vector<TradeoffSetting> settings;
            int best = -1;     ///< the largest pixelsPerLeaf within the FLIP bound (whole frame), or -1
            int bestTree = -1; ///< the same with the FLIP of the square around the tree
            /// The largest pixelsPerLeaf whose tree-square FLIP against the CPU reference is no
            /// worse than the reference's own, or -1.
            int bestCpu = -1;
        };

        struct TradeoffResult
        {
            std::vector<TradeoffDistance> distances;
            double seconds = 0.0;
        };

        TradeoffResult runTradeoff(Techniques& techniques, const StudyTree& tree, const StudyArgs& args,
                                   const ReferenceRenderer* cpu)
        {
            const auto start = std::chrono::steady_clock::now();
            TradeoffResult result;
            FoliageLodTree* lodf = techniques.lodf();
            const int t = args.timingSize;
            for (double target : args.heights)
            {
                TradeoffDistance d;
                d.targetPx = target;
                d.distance = distanceForHeight(tree, target, t);
                d.camera = cameraText(tree, args, d.distance);
                const CameraSpec camera = parseCamera(tree, d.camera);
                const Image reference = techniques.render(techniques.mesh(), camera, t, args.supersample);
                d.meshBarkLod = techniques.meshLodIndex();
                const Extent extent = treeExtent(reference);
                d.treePx = extent.heightPx();
                const Crop crop = cropAround(extent, t, t);
                d.cropPx = crop.side;
                const Image referenceTree = magnify(reference, crop, crop.side);
                std::optional<Image> tracedTree;
                if (cpu)
                {
                    tracedTree = magnify(traceReference(*cpu, camera, t, args.supersample), crop, crop.side);
                    d.meshCpuTree = flipMean(*tracedTree, referenceTree);
                }
                // Reference timed before and after the sweep; the ratio uses their mean.
                d.meshMsBefore = techniques.medianFrameMs(techniques.mesh(), camera, t, args.timingFrames);
                for (double ppl : args.pixelsPerLeaf)
                {
                    TradeoffSetting s;
                    s.pixelsPerLeaf = ppl;
                    lodf->setPixelsPerLeaf(float(ppl));
                    const Image image = techniques.render(lodf, camera, t, args.supersample);
                    s.leaves = lodf->getLeafCount();
                    s.barkLod = lodf->getBarkLodIndex();
                    s.flip = flipMean(reference, image);
                    const Image imageTree = magnify(image, crop, crop.side);
                    s.flipTree = flipMean(referenceTree, imageTree);
                    if (tracedTree)
                        s.cpuTree = flipMean(*tracedTree, imageTree);
                    s.lodfMs = techniques.medianFrameMs(lodf, camera, t, args.timingFrames);
                    if (lodf->getLeafCount() != s.leaves)
                        throw StudyError(format("leaf count changed between the supersampled render (%u) and the "
                                                "timed frames (%u): LoD must follow output pixels",
                                                s.leaves, lodf->getLeafCount()));
                    d.settings.push_back(s);
                    progressLine(format("trade-off %g px (%.4g m, measured %d px): pixelsPerLeaf %g, %u leaves, "
                                        "FLIP %.4f (tree %.4f%s), %.2f ms",
                                        target, d.distance, d.treePx, ppl, s.leaves, s.flip, s.flipTree,
                                        s.cpuTree ? format(", vs CPU %.4f", *s.cpuTree).c_str() : "", s.lodfMs));
                }
                d.meshMsAfter = techniques.medianFrameMs(techniques.mesh(), camera, t, args.timingFrames);
                for (std::size_t i = 0; i < d.settings.size(); ++i)
                {
                    TradeoffSetting& s = d.settings[i];
                    s.ratio = s.lodfMs / d.meshMs();
                    auto larger = [&](int other) {
                        return other < 0 || s.pixelsPerLeaf > d.settings[std::size_t(other)].pixelsPerLeaf;
                    };
                    if (s.flip <= args.flipBound && larger(d.best))
                        d.best = int(i);
                    if (s.flipTree <= args.flipBound && larger(d.bestTree))
                        d.bestTree = int(i);
                    if (s.cpuTree && *s.cpuTree <= *d.meshCpuTree && larger(d.bestCpu))
                        d.bestCpu = int(i);
                }
                progressLine(format("trade-off %g px: mesh %.2f ms (before %.2f, after %.2f)%s", target, d.meshMs(),
                                    d.meshMsBefore, d.meshMsAfter,
                                    d.meshCpuTree ? format(", mesh vs CPU (tree) FLIP %.4f", *d.meshCpuTree).c_str()
                                                  : ""));
                result.distances.push_back(std::move(d));
            }
            lodf->setPixelsPerLeaf(4.0f);
            result.seconds = secondsSince(start);
            return result;
        }

        std::string tradeoffCsv(const TradeoffResult& result, std::uint32_t maxLeaves, double bound)
        {
            std::ostringstream csv;
            csv << "target_px,distance_m,tree_px,crop_px,camera,pixels_per_leaf,leaves,max_leaves,flip,flip_tree,lodf_ms,"
                   "mesh_ms,mesh_ms_before,mesh_ms_after,ratio,within_bound,tree_within_bound,cpu_flip_tree,cpu_flip_tree_mesh,"
                   "bark_lod_mesh,bark_lod_lodf\n";
            for (const TradeoffDistance& d : result.distances)
                for (const TradeoffSetting& s : d.settings)
                    csv << format("%g,%.6g,%d,%d,\"%s\",%g,%u,%u,%.6f,%.6f,%.3f,%.3f,%.3f,%.3f,%.4f,%d,%d", d.targetPx,
                                  d.distance, d.treePx, d.cropPx, d.camera.c_str(), s.pixelsPerLeaf, s.leaves, maxLeaves,
                                  s.flip, s.flipTree, s.lodfMs, d.meshMs(), d.meshMsBefore, d.meshMsAfter, s.ratio,
                                  s.flip <= bound, s.flipTree <= bound)
                        << (s.cpuTree ? format(",%.6f,%.6f", *s.cpuTree, *d.meshCpuTree) : std::string(",,"))
                        << ',' << d.meshBarkLod << ',' << s.barkLod << '\n';
            return csv.str();
        }

        // ---- reports ------------------------------------------------------------------------

        struct Study
        {
            StudyArgs args;
            StudyTree* tree = nullptr;
            ZoomResult zoom;
            TradeoffResult tradeoff;
            double setupSeconds = 0.0, totalSeconds = 0.0;
        };

        std::string summaryMarkdown(const Study& s)
        {
            const StudyArgs& a = s.args;
            const TreeModel& m = s.tree->model;
            const bool cpu = s.zoom.meanMeshCpu.has_value();
            std::ostringstream md;
            md << "## LoDF study: " << s.tree->label << "\n\n";
            md << format("Tree: %zu leaves in %u clusters (coarsest level %u leaves), %zu bark triangles, %.1f m tall. "
                         "Rendered headless by the plugin (Mesa llvmpipe); reference = `mesh` (every leaf), same "
                         "pipeline, supersampled. FLIP is the mean over the whole frame.\n\n",
                         m.leaves.size(), s.tree->clusters, s.tree->clusters, m.barkIndices.size() / 3,
                         double(m.boundsMax.y - m.boundsMin.y));
            md << "### Continuity: zoom from " << format("%g m to %g m", a.nearDistance, a.farDistance) << "\n\n";
            md << format("%d frames, log-spaced, eye %.1f m above the base, azimuth %g°, looking at the crown centre; "
                         "%dx%d, %dx%d supersampled. *Popping excess* = FLIP between a technique's consecutive "
                         "frames minus the reference's own consecutive-frame FLIP (clamped at 0). Discrete = `lodf` "
                         "with `quantise=%u` (%u geometric levels).%s\n\n",
                         a.frames, a.eyeHeight, a.azimuth, a.size, a.size, a.supersample, a.supersample, a.levels,
                         a.levels,
                         cpu ? " *vs CPU* = mean FLIP against the CPU ray-traced reference (leaf alpha from the "
                               "full-resolution texture, no mip-mapping)."
                             : "");
            md << "| technique | mean FLIP vs reference | max FLIP vs reference | mean popping excess | "
                  "max popping excess (at) | leaf-count changes | mean leaves | uploaded |"
               << (cpu ? " mean FLIP vs CPU |\n" : "\n");
            md << "|---|---:|---:|---:|---:|---:|---:|---:|" << (cpu ? "---:|\n" : "\n");
            auto row = [&](const char* name, const TechniqueSummary& t) {
                md << format("| %s | %.4f | %.4f | %.4f | %.4f (%.3g m) | %d | %.0f | %.0f KiB |", name, t.meanFlip,
                             t.maxFlip, t.meanExcess, t.maxExcess, t.maxExcessDistance, t.leafChanges, t.meanLeaves,
                             t.uploadedKib);
                md << (t.meanFlipCpu ? format(" %.4f |\n", *t.meanFlipCpu) : std::string("\n"));
            };
            row("lodf (continuous)", s.zoom.lodf);
            row(format("lodf, %u discrete levels", a.levels).c_str(), s.zoom.discrete);
            if (cpu)
                md << format("| mesh (the reference itself) | | | | | | %zu | | %.4f (max %.4f) |\n", m.leaves.size(),
                             *s.zoom.meanMeshCpu, *s.zoom.maxMeshCpu);
            md << format("\nThe same over the square around the tree (frames where it is at least %d px: %d of %d; "
                         "steps: %d of %d), where the sky does not dilute the error:\n\n",
                         MIN_TREE_SQUARE, s.zoom.lodf.treeFrames, a.frames, s.zoom.lodf.treeSteps, a.frames - 1);
            md << "| technique | mean FLIP vs reference | max FLIP vs reference | mean popping excess | "
                  "max popping excess (at) |\n|---|---:|---:|---:|---:|\n";
            auto treeRow = [&](const char* name, const TechniqueSummary& t) {
                md << format("| %s | %.4f | %.4f | %.4f | %.4f (%.3g m) |\n", name, t.treeMeanFlip, t.treeMaxFlip,
                             t.treeMeanExcess, t.treeMaxExcess, t.treeMaxExcessDistance);
            };
            treeRow("lodf (continuous)", s.zoom.lodf);
            treeRow(format("lodf, %u discrete levels", a.levels).c_str(), s.zoom.discrete);
            md << "\nPlot: `zoom.svg`. Frames (reference | lodf | discrete; the tree magnified below): ";
            for (std::size_t i = 0; i + 1 < s.zoom.pictures.size(); ++i)
                md << (i ? ", " : "") << '`' << s.zoom.pictures[i] << '`';
            if (!s.zoom.pictures.empty())
                md << ". `pop-worst.png`: the discrete baseline's largest step, rows discrete / lodf / reference, "
                      "before | after, magnified.";
            md << "\n\n";

            md << format("### Frame time at equal FLIP (%dx%d)\n\n", a.timingSize, a.timingSize);
            const bool cpuTrade = !s.tradeoff.distances.empty() && s.tradeoff.distances[0].meshCpuTree.has_value();
            md << format("FLIP against the reference rendered %dx%d supersampled, over the whole frame and over the "
                         "square around the tree (*tree*: the whole-frame mean is diluted by the sky)%s; frame time = "
                         "median of %d frames (1 sample per pixel), reference timed in the same run before and after "
                         "the sweep (mean of both medians). Ratio = lodf / reference.\n\n",
                         a.supersample, a.supersample,
                         cpuTrade ? "; *tree vs CPU*: the square around the tree against the CPU ray-traced reference, "
                                    "the reference's own value in its row"
                                  : "",
                         a.timingFrames);
            md << "| tree height (px) | distance | pixelsPerLeaf | leaves | FLIP | FLIP tree |"
               << (cpuTrade ? " tree vs CPU |" : "") << " lodf ms | reference ms | ratio |\n";
            md << "|---:|---:|---:|---:|---:|---:|" << (cpuTrade ? "---:|" : "") << "---:|---:|---:|\n";
            auto mark = [&](double v) { return format("%.4f%s", v, v <= a.flipBound ? "" : " ✗"); };
            for (const TradeoffDistance& d : s.tradeoff.distances)
            {
                if (cpuTrade)
                    md << format("| %d | %.3g m | reference | %zu | | | %.4f | | %.2f | |\n", d.treePx, d.distance,
                                 m.leaves.size(), *d.meshCpuTree, d.meshMs());
                for (const TradeoffSetting& t : d.settings)
                {
                    md << format("| %d | %.3g m | %g | %u | %s | %s |", d.treePx, d.distance, t.pixelsPerLeaf, t.leaves,
                                 mark(t.flip).c_str(), mark(t.flipTree).c_str());
                    if (cpuTrade)
                        md << format(" %.4f |", *t.cpuTree);
                    md << format(" %.2f | %.2f | %.2f |\n", t.lodfMs, d.meshMs(), t.ratio);
                }
            }
            md << format("\nCheapest setting (largest pixelsPerLeaf) meeting each criterion: FLIP against the reference "
                         "≤ %g over the whole frame, or over the square around the tree (✗ above: over the bound)%s.\n\n",
                         a.flipBound,
                         cpuTrade ? "; or tree-square FLIP against the CPU reference no worse than the reference's own"
                                  : "");
            md << "| tree height (px) | distance | criterion | pixelsPerLeaf | leaves | FLIP | ratio lodf / reference |\n";
            md << "|---:|---:|---|---:|---:|---:|---:|\n";
            for (const TradeoffDistance& d : s.tradeoff.distances)
                for (int criterion = 0; criterion < (cpuTrade ? 3 : 2); ++criterion)
                {
                    const int best = criterion == 0 ? d.best : (criterion == 1 ? d.bestTree : d.bestCpu);
                    const char* name = criterion == 0   ? "whole frame ≤ bound"
                                       : criterion == 1 ? "tree square ≤ bound"
                                                        : "tree vs CPU ≤ reference's";
                    if (best < 0)
                    {
                        md << format("| %d | %.3g m | %s | none | | | |\n", d.treePx, d.distance, name);
                        continue;
                    }
                    const TradeoffSetting& t = d.settings[std::size_t(best)];
                    const double value = criterion == 0 ? t.flip : (criterion == 1 ? t.flipTree : *t.cpuTree);
                    md << format("| %d | %.3g m | %s | %g | %u | %.4f | %.2f |\n", d.treePx, d.distance, name,
                                 t.pixelsPerLeaf, t.leaves, value, t.ratio);
                }
            md << format("\nWall time: %.0f s (setup %.0f s, zoom %.0f s, trade-off %.0f s).\n", s.totalSeconds,
                         s.setupSeconds, s.zoom.seconds, s.tradeoff.seconds);
            return md.str();
        }

        nlohmann::json summaryJson(const Study& s)
        {
            using nlohmann::json;
            const StudyArgs& a = s.args;
            auto technique = [](const TechniqueSummary& t) {
                return json{{"mean_flip", t.meanFlip},       {"max_flip", t.maxFlip},
                            {"mean_flip_cpu", t.meanFlipCpu ? json(*t.meanFlipCpu) : json(nullptr)},
                            {"mean_pop_excess", t.meanExcess}, {"max_pop_excess", t.maxExcess},
                            {"max_pop_excess_distance_m", t.maxExcessDistance},
                            {"leaf_count_changes", t.leafChanges}, {"mean_leaves", t.meanLeaves},
                            {"uploaded_kib", t.uploadedKib},
                            {"tree_square",
                             {{"mean_flip", t.treeMeanFlip}, {"max_flip", t.treeMaxFlip},
                              {"mean_pop_excess", t.treeMeanExcess}, {"max_pop_excess", t.treeMaxExcess},
                              {"max_pop_excess_distance_m", t.treeMaxExcessDistance},
                              {"frames", t.treeFrames}, {"steps", t.treeSteps}}}};
            };
            json frames = json::array();
            for (const ZoomFrame& f : s.zoom.frames)
            {
                json j{{"distance_m", f.distance}, {"tree_px", f.treePx}, {"camera", f.camera},
                       {"leaves_lodf", f.leavesLodf}, {"leaves_discrete", f.leavesDiscrete},
                       {"bark_lod_mesh", f.barkLodMesh}, {"bark_lod_lodf", f.barkLodLodf},
                       {"flip_lodf", f.flipLodf}, {"flip_discrete", f.flipDiscrete}};
                if (f.cpuMesh)
                {
                    j["cpu_flip_mesh"] = *f.cpuMesh;
                    j["cpu_flip_lodf"] = *f.cpuLodf;
                    j["cpu_flip_discrete"] = *f.cpuDiscrete;
                }
                if (f.treeFlipLodf)
                {
                    j["tree_flip_lodf"] = *f.treeFlipLodf;
                    j["tree_flip_discrete"] = *f.treeFlipDiscrete;
                }
                if (f.treeStepReference)
                {
                    j["tree_pop_excess_lodf"] = f.treeExcessLodf();
                    j["tree_pop_excess_discrete"] = f.treeExcessDiscrete();
                }
                if (f.stepReference)
                {
                    j["step_flip_reference"] = *f.stepReference;
                    j["pop_excess_lodf"] = f.excessLodf();
                    j["pop_excess_discrete"] = f.excessDiscrete();
                }
                frames.push_back(j);
            }
            json distances = json::array();
            for (const TradeoffDistance& d : s.tradeoff.distances)
            {
                json settings = json::array();
                for (const TradeoffSetting& t : d.settings)
                    settings.push_back({{"pixels_per_leaf", t.pixelsPerLeaf}, {"leaves", t.leaves}, {"flip", t.flip},
                                        {"flip_tree", t.flipTree},
                                        {"cpu_flip_tree", t.cpuTree ? json(*t.cpuTree) : json(nullptr)},
                                        {"bark_lod", t.barkLod}, {"lodf_ms", t.lodfMs}, {"ratio", t.ratio}});
                distances.push_back({{"target_px", d.targetPx},
                                     {"distance_m", d.distance},
                                     {"tree_px", d.treePx},
                                     {"crop_px", d.cropPx},
                                     {"camera", d.camera},
                                     {"mesh_ms", d.meshMs()},
                                     {"mesh_bark_lod", d.meshBarkLod},
                                     {"mesh_cpu_flip_tree", d.meshCpuTree ? json(*d.meshCpuTree) : json(nullptr)},
                                     {"mesh_ms_before", d.meshMsBefore},
                                     {"mesh_ms_after", d.meshMsAfter},
                                     {"settings", settings},
                                     {"best_pixels_per_leaf",
                                      d.best < 0 ? json(nullptr) : json(d.settings[std::size_t(d.best)].pixelsPerLeaf)},
                                     {"best_pixels_per_leaf_tree",
                                      d.bestTree < 0 ? json(nullptr)
                                                     : json(d.settings[std::size_t(d.bestTree)].pixelsPerLeaf)},
                                     {"best_pixels_per_leaf_cpu",
                                      d.bestCpu < 0 ? json(nullptr)
                                                    : json(d.settings[std::size_t(d.bestCpu)].pixelsPerLeaf)}});
            }
            return json{
                {"tree",
                 {{"label", s.tree->label},
                  {"leaves", s.tree->model.leaves.size()},
                  {"clusters", s.tree->clusters},
                  {"height_m", s.tree->model.boundsMax.y - s.tree->model.boundsMin.y}}},
                {"settings",
                 {{"frames", a.frames}, {"size", a.size}, {"supersample", a.supersample},
                  {"near_m", a.nearDistance}, {"far_m", a.farDistance}, {"eye_height_m", a.eyeHeight},
                  {"azimuth_deg", a.azimuth}, {"discrete_levels", a.levels}, {"timing_size", a.timingSize},
                  {"timing_frames", a.timingFrames}, {"flip_bound", a.flipBound}}},
                {"zoom",
                 {{"lodf", technique(s.zoom.lodf)},
                  {"discrete", technique(s.zoom.discrete)},
                  {"mesh_vs_cpu_mean_flip", s.zoom.meanMeshCpu ? json(*s.zoom.meanMeshCpu) : json(nullptr)},
                  {"mesh_vs_cpu_max_flip", s.zoom.maxMeshCpu ? json(*s.zoom.maxMeshCpu) : json(nullptr)},
                  {"frames", frames},
                  {"pictures", s.zoom.pictures}}},
                {"tradeoff", distances},
                {"seconds", {{"total", s.totalSeconds}, {"setup", s.setupSeconds}, {"zoom", s.zoom.seconds},
                             {"tradeoff", s.tradeoff.seconds}}}};
        }

        void validate(const StudyArgs& a)
        {
            auto require = [](bool ok, const std::string& what) {
                if (!ok)
                    throw StudyError(what);
            };
            require(a.leaves == 0 || a.tree.empty(), "--tree and --leaves exclude each other");
            require(a.frames >= 2 && a.frames <= 10000, "--frames must be 2..10000");
            require(a.size >= 16 && a.size <= 4096, "--size must be 16..4096");
            require(a.supersample >= 1 && a.supersample <= 8, "--supersample must be 1..8");
            require(a.nearDistance > 0.0 && a.farDistance > a.nearDistance, "--near must be > 0 and below --far");
            require(a.levels >= 2, "--levels must be at least 2 (1 would be continuous)");
            require(a.timingSize >= 16 && a.timingSize <= 4096, "--timing-size must be 16..4096");
            require(a.timingFrames >= 1 && a.timingFrames <= 1000, "--timing-frames must be 1..1000");
            require(!a.heights.empty(), "--heights needs at least one tree height in pixels");
            for (double h : a.heights)
                require(h > 0.0, "--heights must be positive pixel counts");
            for (double p : a.pixelsPerLeaf)
                require(p > 0.0, "--pixels-per-leaf values must be positive");
            require(a.flipBound > 0.0, "--flip-bound must be positive");
        }

        int run(StudyArgs args)
        {
            const auto start = std::chrono::steady_clock::now();
            validate(args);
            if (args.leaves == 0 && args.tree.empty())
                args.tree = std::string(TREELOD_SOURCE_DIR) + "/media/oak.glb";
            StudyTree tree = loadTree(args);
            std::error_code ec;
            std::filesystem::create_directories(args.out, ec);
            if (ec)
                throw StudyError(args.out + ": cannot create the output folder: " + ec.message());

            Study study;
            study.args = args;
            study.tree = &tree;
            progressLine(format("%s: %zu leaves; building LoDF", tree.label.c_str(), tree.model.leaves.size()));
            OffscreenRenderer renderer;
            Techniques techniques(renderer, tree, args.levels);
            study.setupSeconds = secondsSince(start);
            progressLine(format("%u clusters; bounding radius (drives pixel-count LoD): mesh %.3f m, lodf %.3f m; "
                                "setup %.1f s",
                                tree.clusters, double(techniques.mesh()->getBoundingRadius()),
                                double(techniques.lodf()->getBoundingRadius()), study.setupSeconds));

            std::optional<ReferenceRenderer> cpu;
            if (args.cpuReference)
                cpu.emplace(tree.model);
            study.zoom = runZoom(techniques, tree, args, cpu ? &*cpu : nullptr);
            writeText(args.out + "/zoom.csv", zoomCsv(study.zoom.frames));
            writeText(args.out + "/zoom.svg",
                      zoomSvg(study.zoom.frames, args,
                              format("LoDF zoom, %s: continuous vs %u discrete levels", tree.label.c_str(), args.levels)));
            progressLine(format("zoom done in %.0f s", study.zoom.seconds));

            study.tradeoff = runTradeoff(techniques, tree, args, cpu ? &*cpu : nullptr);
            writeText(args.out + "/tradeoff.csv",
                      tradeoffCsv(study.tradeoff, techniques.lodf()->getMaxLeafCount(), args.flipBound));
            progressLine(format("trade-off done in %.0f s", study.tradeoff.seconds));

            study.totalSeconds = secondsSince(start);
            const std::string md = summaryMarkdown(study);
            writeText(args.out + "/summary.md", md);
            writeText(args.out + "/summary.json", summaryJson(study).dump(2) + "\n");
            renderer.clearContent();
            std::fputs(md.c_str(), stdout);
            progressLine("wrote " + args.out + "/{summary.md,summary.json,zoom.csv,tradeoff.csv,zoom.svg,*.png}");
            return 0;
        }
    }
}

int main(int argc, char** argv)
{
    using TreeLod::StudyArgs;
    StudyArgs args;
    CLI::App app{"LoDF study (Rebollo et al. 2006): popping along a zoom, and frame time against the reference at equal FLIP. "
                 "Run under xvfb-run -a -s \"-screen 0 1280x1024x24 -noreset\"."};
    app.add_option("--tree", args.tree, "glTF tree (default: media/oak.glb of the source tree)");
    app.add_option("--leaves", args.leaves, "generate an oak preset with this many leaves instead (100..200000)");
    app.add_option("--seed", args.seed, "generator seed with --leaves")->capture_default_str();
    app.add_option("--frames", args.frames, "zoom frames")->capture_default_str();
    app.add_option("--size", args.size, "zoom frame size in pixels (square)")->capture_default_str();
    app.add_option("--supersample", args.supersample, "samples per axis of every image compared")->capture_default_str();
    app.add_option("--near", args.nearDistance, "nearest camera distance (m)")->capture_default_str();
    app.add_option("--far", args.farDistance, "farthest camera distance (m)")->capture_default_str();
    app.add_option("--azimuth", args.azimuth, "camera azimuth (degrees, 0 = from +Z)")->capture_default_str();
    app.add_option("--levels", args.levels, "levels of the discrete baseline (lodf quantise)")->capture_default_str();
    app.add_option("--timing-size", args.timingSize, "trade-off frame size (square)")->capture_default_str();
    app.add_option("--timing-frames", args.timingFrames, "timed frames per measurement")->capture_default_str();
    app.add_option("--heights", args.heights, "trade-off tree heights in pixels at --timing-size")
        ->delimiter(',')
        ->capture_default_str();
    app.add_option("--pixels-per-leaf", args.pixelsPerLeaf, "trade-off pixelsPerLeaf values")
        ->delimiter(',')
        ->capture_default_str();
    app.add_option("--flip-bound", args.flipBound, "FLIP bound of the equal-quality choice")->capture_default_str();
    app.add_flag("!--no-cpu-reference", args.cpuReference,
                 "skip the CPU ray-traced reference (a second, mip-free reference for every comparison)");
    app.add_option("--out", args.out, "output folder")->capture_default_str();
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        return app.exit(e) == 0 ? 0 : 2;
    }
    return TreeLod::runStudy("treelod_lodf_study", [&] { return TreeLod::run(args); });
}
