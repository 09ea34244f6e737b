// treelod_volume_study: the volumetric octree tree's bake measured as Linz et al. 2006 measure it,
// on one tree (a .glb, or generated:PRESET:LEAVES), on the CPU (no X server needed):
//   - bake time per step: photographs (the reference renderer), reconstruction, quantisation;
//   - per level the cells, billboards and the share pruned (Fig. 4), hidden and empty apart;
//   - texture memory (§6): the octree's raw 4x4 RGBA8 billboards unpruned and pruned, VQ (the
//     codebook atlas in RGBA8 plus the slot table) and VQ + DXT5;
//   - PSNR of the quantised billboards against the raw ones, colour and alpha, against the
//     codebook size (Fig. 6);
//   - the back-to-front order's CPU time per frame: the paper's octree traversal every frame
//     against VolumeOctreeTree's per-octant orders (§6);
//   - at one codebook size, the colour RMS of RGB GLA, CIELab GLA and the modified GLA in CIELab
//     (Fig. 5): over the billboards' covered texels, and over images of the tree drawn by the CPU
//     twin from between the input cameras, against the same octree uncompressed.
// Output in --out: summary.md and summary.json.
#include "TreeLod/PackageWriter.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/VolumeOctreeBaker.h"
#include "TreeLod/VolumeOctreeTree.h"

#include <OgreEntity.h>
#include <OgreSceneManager.h>

#include "StudySupport.h"

#include <CLI/CLI.hpp>

#include <unordered_map>

namespace TreeLod
{
    namespace
    {
        /// RMS of the colour channels (0..255, R, G, B averaged) over pixels either image covers.
        double imageColourRms(const Image& reference, const Image& test)
        {
            double sum[3] = {0, 0, 0};
            std::size_t n = 0;
            for (std::size_t i = 0; i < reference.pixels.size(); ++i)
            {
                if (reference.pixels[i].a <= 0.0f && test.pixels[i].a <= 0.0f)
                    continue;
                ++n;
                for (int c = 0; c < 3; ++c)
                {
                    const double d = 255.0 * (double(reference.pixels[i][c]) - double(test.pixels[i][c]));
                    sum[c] += d * d;
                }
            }
            if (n == 0)
                return 0.0;
            return (std::sqrt(sum[0] / n) + std::sqrt(sum[1] / n) + std::sqrt(sum[2] / n)) / 3.0;
        }

        int run(int argc, char** argv)
        {
            std::string tree = "generated:oak:20000", out = "out/volume-study";
            CaptureSynthesisOptions capture;
            VolumeOctreeOptions options;
            std::vector<std::uint32_t> codebooks{16, 64, 256, 512, 1024, 2048};
            std::uint32_t compareAt = 512; // 0: no Fig. 5
            int frames = 0;                // 0: no frame times (no X server needed)
            CLI::App app{"The volumetric octree tree's bake, memory and compression (Linz et al. 2006)"};
            app.add_option("--tree", tree, "a .glb or generated:PRESET:LEAVES");
            app.add_option("--cameras", capture.cameraCount, "synthetic photographs")->check(CLI::Range(1, 64));
            app.add_option("--resolution", capture.resolution, "pixels a side of each photograph");
            app.add_option("--levels", options.levelCount, "octree levels")->check(CLI::Range(1, 10));
            app.add_option("--codebooks", codebooks, "codebook sizes for the PSNR curve");
            app.add_option("--compare-at", compareAt,
                           "codebook size of the RGB / CIELab / modified comparison (0: none)");
            app.add_option("--frames", frames,
                           "frames timed per view for pruned against unpruned (needs an X server; 0: none)");
            app.add_option("--out", out, "output folder");
            CLI11_PARSE(app, argc, argv);
            std::filesystem::create_directories(out);

            const StudyTree loaded = loadStudyTree(tree);
            const TreeModel& model = loaded.model;
            const auto t0 = std::chrono::steady_clock::now();
            Result<CaptureSet> set = synthesiseCaptureSet(model, capture, tree);
            const double captureSeconds = secondsSince(t0);
            if (!set)
                throw StudyError(set.error().message());
            const auto t1 = std::chrono::steady_clock::now();
            Result<VolumeOctreeReconstruction> built = reconstructVolumeOctree(set.value(), options, tree);
            const double reconstructSeconds = secondsSince(t1);
            if (!built)
                throw StudyError(built.error().message());
            const VolumeOctreeReconstruction& r = built.value();
            const auto t2 = std::chrono::steady_clock::now();
            Result<VolumeOctreeData> baked = compressVolumeOctree(r, options, tree);
            const double compressSeconds = secondsSince(t2);
            if (!baked)
                throw StudyError(baked.error().message());

            std::string md = "# Volumetric octree tree: " + tree + "\n\n";
            md += format("Command: `%s`\n\n", studyCommandLine("treelod_volume_study", argc, argv).c_str());
            md += format("Bake: photographs %.1f s (%d cameras, %d px), reconstruction %.1f s, quantisation and DXT5 "
                         "%.1f s.\n\n",
                         captureSeconds, capture.cameraCount, capture.resolution, reconstructSeconds, compressSeconds);
            nlohmann::json json = {{"tree", tree},
                                   {"seconds", {{"capture", captureSeconds},
                                                {"reconstruction", reconstructSeconds},
                                                {"compression", compressSeconds}}}};

            // Fig. 4: the share pruned per level.
            md += "## Cells and pruning per level (Fig. 4)\n\n| level | candidates | cells | dropped | slots | "
                  "billboards | hidden | empty | pruned |\n|---|---|---|---|---|---|---|---|---|\n";
            std::uint64_t slots = 0, unprunedSlots = 0;
            for (std::size_t l = 0; l < r.levels.size(); ++l)
            {
                const auto& s = r.levels[l];
                md += format("| %zu | %llu | %llu | %llu | %llu | %llu | %llu | %llu | %.1f %% |\n", l,
                             (unsigned long long)s.candidates, (unsigned long long)s.cells,
                             (unsigned long long)s.dropped, (unsigned long long)s.slots,
                             (unsigned long long)s.billboards, (unsigned long long)s.hidden,
                             (unsigned long long)s.empty,
                             100.0 * double(s.hidden + s.empty) / double(std::max<std::uint64_t>(s.slots, 1)));
                json["levels"].push_back({{"candidates", s.candidates}, {"cells", s.cells}, {"dropped", s.dropped},
                                          {"slots", s.slots}, {"billboards", s.billboards}, {"hidden", s.hidden},
                                          {"empty", s.empty}});
                slots += s.cells * set->cameras.size();
                unprunedSlots += s.slots;
            }

            // §6: texture memory.
            const double raw = double(unprunedSlots) * 64.0, pruned = double(r.billboards.size()) * 64.0;
            const double slotTable = double(slots) * 4.0;
            const std::uint32_t blocks = std::max(baked->colourCodewords, baked->alphaCodewords);
            const double atlasRgba = double(baked->atlas.width) * baked->atlas.height * 4.0;
            const double atlasDxt = baked->atlas.format == GpuTextureFormat::DXT5 ? double(baked->atlas.data.size())
                                                                                 : atlasRgba / 4.0;
            md += "\n## Texture memory (§6)\n\n| representation | bytes | against the raw pruned octree |\n|---|---|---|\n";
            const auto row = [&](const char* name, double bytes) {
                md += format("| %s | %.0f | %.1f : 1 |\n", name, bytes, pruned / bytes);
                json["memory"][name] = bytes;
            };
            row("octree, 4x4 RGBA8 billboards, unpruned", raw);
            row("octree, 4x4 RGBA8 billboards, pruned", pruned);
            row("VQ: RGBA8 codebook atlas + slot table", atlasRgba + slotTable);
            row("VQ + DXT5: DXT5 codebook atlas + slot table", atlasDxt + slotTable);
            md += format("\nThe atlas holds %u blocks (%u colour, %u alpha codewords) in %ux%u texels; the slot table "
                         "is 4 bytes (two 16-bit indices) for each of %llu slots.\n",
                         blocks, baked->colourCodewords, baked->alphaCodewords, baked->atlas.width,
                         baked->atlas.height, (unsigned long long)slots);

            // §6: back-to-front order. The paper traverses the octree on the CPU every frame (its stated
            // bottleneck); VolumeOctreeTree sorts each level once per view octant and rewrites its
            // indices only when the octant or the active level changes.
            {
                const VolumeOctreeData& d = baked.value();
                std::unordered_map<std::uint64_t, std::uint32_t> indexOf;
                std::vector<std::uint32_t> levelOf(d.cells.size());
                for (std::uint32_t l = 0, at = 0; l < d.levelCount; ++l)
                    for (std::uint32_t i = 0; i < d.levelCellCounts[l]; ++i, ++at)
                    {
                        indexOf[(std::uint64_t(l) << 32) | d.cells[at]] = at;
                        levelOf[at] = l;
                    }
                std::vector<std::array<std::int32_t, 8>> children(d.cells.size());
                for (auto& c : children)
                    c.fill(-1);
                for (std::uint32_t at = d.levelCellCounts[0]; at < d.cells.size(); ++at)
                {
                    const glm::uvec3 c = volumeCellCoords(d.cells[at]);
                    const auto parent = indexOf.find((std::uint64_t(levelOf[at] - 1) << 32) |
                                                     volumeCellCode(c.x / 2, c.y / 2, c.z / 2));
                    if (parent != indexOf.end())
                        children[parent->second][(c.x & 1) | ((c.y & 1) << 1) | ((c.z & 1) << 2)] = std::int32_t(at);
                }
                const glm::vec3 centre = d.origin + 0.5f * d.size;
                const float focal = 540.0f / std::tan(glm::radians(22.5f)), lodPixels = 4.0f; // 1080 px, 45 degrees
                std::vector<std::uint32_t> indices;
                std::size_t emitted = 0, rebuilds = 0;
                double paperSeconds = 0.0, oursSeconds = 0.0;
                const auto pre = std::chrono::steady_clock::now();
                std::vector<std::array<std::vector<std::uint32_t>, 8>> orders(d.levelCount);
                for (std::uint32_t l = 0; l < d.levelCount; ++l)
                    for (std::uint32_t o = 0; o < 8; ++o)
                        orders[l][o] = volumeOctreeOctantOrder(d, l, o);
                const double sortSeconds = secondsSince(pre);
                std::uint32_t lastOctant = 8, lastActive = ~0u;
                int frames = 0;
                for (float distance : {1.5f, 4.0f, 12.0f})
                    for (int step = 0; step < 360; ++step, ++frames)
                    {
                        const float a = glm::radians(float(step));
                        const glm::vec3 eye = centre + distance * d.size *
                                                           glm::vec3(std::sin(a), 0.2f, std::cos(a));
                        const glm::vec3 forward = glm::normalize(centre - eye);
                        float nearest = std::numeric_limits<float>::max();
                        for (int k = 0; k < 8; ++k)
                            nearest = std::min(nearest, glm::dot(d.origin + d.size * glm::vec3(k & 1, (k >> 1) & 1, k >> 2) - eye,
                                                                 forward));
                        const std::uint32_t active = volumeOctreeActiveLevel(d, std::max(nearest, 1e-3f), focal, lodPixels);
                        const float plane = volumeOctreePlaneDepth(d.cellEdge(active), focal, lodPixels);
                        const auto depthOf = [&](std::uint32_t at) {
                            return glm::dot(d.cellCentre(d.cells[at], levelOf[at]) - eye, forward);
                        };
                        // The paper: descend from the root every frame, children far to near.
                        const auto t0 = std::chrono::steady_clock::now();
                        indices.clear();
                        std::vector<std::uint32_t> stack{0};
                        while (!stack.empty())
                        {
                            const std::uint32_t at = stack.back();
                            stack.pop_back();
                            const std::uint32_t level = levelOf[at];
                            const float depth = depthOf(at);
                            if (level == active || (level + 1 == active && depth >= plane))
                            {
                                indices.insert(indices.end(), {4 * at, 4 * at + 1, 4 * at + 2, 4 * at, 4 * at + 2, 4 * at + 3});
                                continue;
                            }
                            std::array<std::pair<float, std::uint32_t>, 8> near{};
                            int n = 0;
                            for (std::int32_t child : children[at])
                                if (child >= 0)
                                    near[std::size_t(n++)] = {depthOf(std::uint32_t(child)), std::uint32_t(child)};
                            std::sort(near.begin(), near.begin() + n); // nearest first: pushed first, popped last
                            for (int k = 0; k < n; ++k)
                                stack.push_back(near[std::size_t(k)].second);
                        }
                        emitted += indices.size();
                        paperSeconds += secondsSince(t0);
                        // Ours: a new index list only when the octant or the active level changes.
                        const auto t1 = std::chrono::steady_clock::now();
                        const std::uint32_t octant = volumeOctreeOctant(forward);
                        if (octant != lastOctant || active != lastActive)
                        {
                            ++rebuilds;
                            lastOctant = octant;
                            lastActive = active;
                            indices.clear();
                            for (std::uint32_t l = active == 0 ? 0 : active - 1; l <= active; ++l)
                                for (std::uint32_t i : orders[l][octant])
                                {
                                    const std::uint32_t v = 4 * (d.firstCell(l) + i);
                                    indices.insert(indices.end(), {v, v + 1, v + 2, v, v + 2, v + 3});
                                }
                            emitted += indices.size();
                        }
                        oursSeconds += secondsSince(t1);
                    }
                md += format("\n## Back-to-front order (§6)\n\n%d frames orbiting the tree at 1.5, 4 and 12 times its "
                             "size (1080 px, 45 degrees):\n\n| order | CPU per frame |\n|---|---|\n"
                             "| the paper's traversal, every frame | %.1f us |\n"
                             "| per-octant orders, rewritten on a change (%zu of %d frames) | %.1f us |\n\n"
                             "Sorting every level for the 8 octants once at load: %.1f ms. (%zu indices written in all.)\n",
                             frames, 1e6 * paperSeconds / frames, rebuilds, frames, 1e6 * oursSeconds / frames,
                             1e3 * sortSeconds, emitted);
                json["order"] = {{"frames", frames}, {"paperMicroseconds", 1e6 * paperSeconds / frames},
                                 {"oursMicroseconds", 1e6 * oursSeconds / frames}, {"rebuilds", rebuilds},
                                 {"sortMilliseconds", 1e3 * sortSeconds}};
            }

            // §6: frame time, pruned against unpruned (and the mesh), through the plugin.
            if (frames > 0)
            {
                VolumeOctreeOptions unprunedOptions = options;
                unprunedOptions.prune = false;
                Result<VolumeOctreeData> unpruned = bakeVolumeOctree(set.value(), unprunedOptions, tree);
                if (!unpruned)
                    throw StudyError(unpruned.error().message());
                OffscreenRenderer renderer;
                renderer.setLighting(LightingSpec());
                const auto package = [&](const VolumeOctreeData& data, const std::string& name) {
                    PackageWriter writer;
                    if (Result<void> ok = addReferenceChunkIfMissing(writer, model, name, {}); !ok)
                        throw StudyError(ok.error().message());
                    if (Result<void> ok = writer.addChunk(VOLUME_OCTREE_CHUNK, 0, VOLUME_OCTREE_CHUNK_FORMAT_VERSION,
                                                          encodeVolumeOctreeChunk(data));
                        !ok)
                        throw StudyError(ok.error().message());
                    return TreeAssetManager::getSingleton().loadFromBytes(name, Ogre::RGN_DEFAULT, writer.toBytes());
                };
                const TreeAssetPtr prunedAsset = package(baked.value(), "volume-study-pruned");
                const TreeAssetPtr unprunedAsset = package(unpruned.value(), "volume-study-unpruned");
                std::vector<CameraSpec> orbit;
                for (float azimuth : {0.0f, 45.0f, 90.0f, 135.0f, 180.0f, 225.0f, 270.0f, 315.0f})
                    orbit.push_back(CameraSpec::framing(model.boundsMin, model.boundsMax, azimuth, 10.0f, 1.2f));
                const auto time = [&](const TreeAssetPtr& asset) {
                    renderer.clearContent();
                    Ogre::NameValuePairList params;
                    if (asset)
                        params = {{"asset", asset->getName()}, {"group", asset->getGroup()}};
                    Ogre::MovableObject* object =
                        asset ? renderer.getSceneManager().createMovableObject(
                                    "volume-study", VolumeOctreeTreeFactory::FACTORY_TYPE_NAME, &params)
                              : static_cast<Ogre::MovableObject*>(
                                    renderer.getSceneManager().createEntity(prunedAsset->getReferenceMesh()));
                    renderer.getContentNode().attachObject(object);
                    std::vector<double> ms;
                    for (const CameraSpec& view : orbit)
                        ms.push_back(median(renderer.timeFrames(view, 1024, 768, frames)));
                    renderer.clearContent();
                    return median(ms);
                };
                const double meshMs = time(nullptr), prunedMs = time(prunedAsset), unprunedMs = time(unprunedAsset);
                md += format("\n## Frame time, pruned against unpruned (§6)\n\n1024x768, the tree 1/1.2 of the view "
                             "height, 8 views around it, the median of %d frames each, then of the views:\n\n"
                             "| draw | billboards stored | ms per frame | against the mesh |\n|---|---|---|---|\n"
                             "| mesh | | %.1f | 1.00 |\n| octree, pruned | %zu | %.1f | %.2f |\n"
                             "| octree, unpruned | %zu | %.1f | %.2f |\n",
                             frames, meshMs, r.billboards.size(), prunedMs, prunedMs / meshMs,
                             std::size_t(std::count_if(unpruned->slots.begin(), unpruned->slots.end(),
                                                       [](const VolumeOctreeSlot& slot) { return !slot.pruned(); })),
                             unprunedMs, unprunedMs / meshMs);
                json["frames"] = {{"meshMs", meshMs}, {"prunedMs", prunedMs}, {"unprunedMs", unprunedMs}};
            }

            // Fig. 6: PSNR against the codebook size, against the billboards as the codebooks are made
            // from them (transparent texels filled by the black-pixel heuristic, VectorQuantiser.h):
            // the colour of a transparent texel is never seen.
            std::vector<BillboardTexture> filled = r.billboards;
            for (BillboardTexture& b : filled)
                fillTransparentTexels(b);
            md += "\n## PSNR of the quantised billboards against the codebook size (Fig. 6)\n\n| codewords | colour + "
                  "alpha PSNR (dB) | alpha PSNR (dB) | seconds |\n|---|---|---|---|\n";
            for (std::uint32_t k : codebooks)
            {
                BillboardQuantisationOptions q = options.quantisation;
                q.colourCodebookSize = q.alphaCodebookSize = k;
                const auto start = std::chrono::steady_clock::now();
                const QuantisedBillboards quantised = quantiseBillboards(r.billboards, q);
                const double seconds = secondsSince(start);
                std::fprintf(stderr, "volume-study: %u codewords quantised in %.1f s\n", k, seconds);
                std::vector<BillboardTexture> decoded(r.billboards.size());
                for (std::size_t i = 0; i < decoded.size(); ++i)
                    decoded[i] = dequantise(quantised, i);
                const double all = billboardPsnr(filled, decoded), alpha = billboardPsnr(filled, decoded, true);
                md += format("| %u | %.2f | %.2f | %.1f |\n", k, all, alpha, seconds);
                json["psnr"].push_back({{"codewords", k}, {"all", all}, {"alpha", alpha}, {"seconds", seconds}});
            }

            // Fig. 5: RGB GLA, CIELab GLA, modified GLA in CIELab.
            if (compareAt == 0)
            {
                writeSummary(out, md, json, studyCommandLine("treelod_volume_study", argc, argv));
                return 0;
            }
            std::vector<CameraSpec> views;
            const glm::dvec3 lo = set->volumeMin, hi = set->volumeMax;
            for (float azimuth : {15.0f, 105.0f, 195.0f, 285.0f})
                views.push_back(CameraSpec::framing(glm::vec3(lo), glm::vec3(hi), azimuth, 10.0f, 1.0f, 30.0f));
            VolumeOctreeRenderOptions render;
            render.width = render.height = 256;
            render.transparentBackground = true;
            render.activeLevel = int(options.levelCount) - 1;
            VolumeOctreeRenderOptions opaque = render;
            opaque.transparentBackground = false;
            std::vector<Image> uncompressed, uncompressedOpaque;
            for (const CameraSpec& view : views)
            {
                uncompressed.push_back(renderVolumeOctree(r.octree, volumeOctreeRawSource(r), view, render));
                uncompressedOpaque.push_back(renderVolumeOctree(r.octree, volumeOctreeRawSource(r), view, opaque));
            }
            md += format("\n## Colour error at %u codewords (Fig. 5)\n\n| quantisation | billboard RMS | image RMS | "
                         "image FLIP (tree box) |\n|---|---|---|---|\n",
                         compareAt);
            for (int mode = 0; mode < 3; ++mode)
            {
                VolumeOctreeOptions o = options;
                o.compress = false;
                o.quantisation.colourCodebookSize = o.quantisation.alphaCodebookSize = compareAt;
                o.quantisation.space = mode == 0 ? QuantisationSpace::Rgb : QuantisationSpace::Lab;
                o.quantisation.nearestInput = mode == 2;
                const QuantisedBillboards quantised = quantiseBillboards(r.billboards, o.quantisation);
                std::vector<BillboardTexture> decoded(r.billboards.size());
                for (std::size_t i = 0; i < decoded.size(); ++i)
                    decoded[i] = dequantise(quantised, i);
                Result<VolumeOctreeData> data = compressVolumeOctree(r, o, tree);
                if (!data)
                    throw StudyError(data.error().message());
                double imageRms = 0.0, imageFlip = 0.0;
                const VolumeBillboardSource source = volumeOctreeAtlasSource(data.value());
                for (std::size_t v = 0; v < views.size(); ++v)
                {
                    imageRms += imageColourRms(uncompressed[v], renderVolumeOctree(data.value(), source, views[v], render));
                    const Image test = renderVolumeOctree(data.value(), source, views[v], opaque);
                    const Crop crop = cropAround(treeExtent(uncompressedOpaque[v]), opaque.width, opaque.height);
                    imageFlip += flipMean(cropImage(uncompressedOpaque[v], crop), cropImage(test, crop));
                }
                imageRms /= double(views.size());
                imageFlip /= double(views.size());
                const char* name = mode == 0 ? "RGB, GLA" : mode == 1 ? "CIELab, GLA" : "CIELab, modified GLA";
                const double billboardRms = billboardColourRms(r.billboards, decoded);
                md += format("| %s | %.2f | %.2f | %.4f |\n", name, billboardRms, imageRms, imageFlip);
                json["fig5"].push_back(
                    {{"mode", name}, {"billboardRms", billboardRms}, {"imageRms", imageRms}, {"imageFlip", imageFlip}});
            }
            writeSummary(out, md, json, studyCommandLine("treelod_volume_study", argc, argv));
            return 0;
        }
    }
}

int main(int argc, char** argv)
{
    return TreeLod::runStudy("treelod_volume_study", [&] { return TreeLod::run(argc, argv); });
}
