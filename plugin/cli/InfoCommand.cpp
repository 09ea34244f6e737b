// treelod info FILE [--json] | treelod info --techniques [--json]
// What a .treelod package holds (version, size, chunks with their checksums, the reference
// model's counts, what each technique's descriptor says of its chunk) or what a .glb/.gltf imports
// to (the same counts plus texture sizes). --techniques: the techniques this build registers, with
// their roles in the trade (TechniqueRoles), the measurement baselines and the default bands.
// The kind is told by content (the "TRLD" magic), not by extension. A package with a damaged
// chunk is still listed (crc "BAD"), then the command exits 2.
#include "CliSupport.h"
#include "Commands.h"

#include "TreeLod/GltfImporter.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#ifdef TREELOD_WITH_OGRE
#include "TreeLod/Forest.h"
#include "TreeLod/TechniqueRegistry.h"
#endif

#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>

namespace TreeLod
{
    namespace
    {
        using nlohmann::json;

        struct InfoArgs
        {
            std::string input;
            std::vector<std::string> leafMaterials;
            bool json = false;
            bool techniques = false;
        };

        /// One row per texture: what the model holds and, for packages, the GPU copy.
        struct TextureRow
        {
            std::string name;
            std::uint32_t width = 0, height = 0, mipCount = 0;
            std::uint64_t bytes = 0;
        };

        json vec3Json(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }

        json modelJson(const TreeModel& m, const std::vector<TextureRow>& textures)
        {
            json j;
            j["name"] = m.name;
            j["leaves"] = m.leaves.size();
            j["leafTriangles"] = m.leafTriangleCount();
            j["barkTriangles"] = m.barkTriangleCount();
            j["vertices"] = m.barkVertices.size() + m.leafVertices.size();
            j["barkVertices"] = m.barkVertices.size();
            j["leafVertices"] = m.leafVertices.size();
            j["materials"] = m.materials.size();
            j["skeletonNodes"] = m.skeleton.size();
            j["polygons"] = hasPolygons(m); // false: baked from photographs, bounds only
            j["bounds"] = {{"min", vec3Json(m.boundsMin)}, {"max", vec3Json(m.boundsMax)}};
            json tex = json::array();
            for (const TextureRow& t : textures)
            {
                json row = {{"name", t.name}, {"width", t.width}, {"height", t.height}, {"bytes", t.bytes}};
                if (t.mipCount > 0)
                    row["mipCount"] = t.mipCount;
                tex.push_back(row);
            }
            j["textures"] = tex;
            return j;
        }

        void printModel(const TreeModel& m, const std::vector<TextureRow>& textures)
        {
            std::printf("model '%s':\n", m.name.c_str());
            std::printf("  leaves %zu, leaf triangles %zu, bark triangles %zu\n", m.leaves.size(),
                        m.leafTriangleCount(), m.barkTriangleCount());
            std::printf("  vertices %zu (bark %zu, leaf %zu), materials %zu, skeleton nodes %zu\n",
                        m.barkVertices.size() + m.leafVertices.size(), m.barkVertices.size(), m.leafVertices.size(),
                        m.materials.size(), m.skeleton.size());
            const glm::vec3 size = m.boundsMax - m.boundsMin;
            std::printf("  bounds (%.3f, %.3f, %.3f) .. (%.3f, %.3f, %.3f), %.3f x %.3f x %.3f m\n", m.boundsMin.x,
                        m.boundsMin.y, m.boundsMin.z, m.boundsMax.x, m.boundsMax.y, m.boundsMax.z, size.x, size.y,
                        size.z);
            if (!hasPolygons(m))
                std::printf("  no polygons: baked from photographs, the bounds are the capture's volume (only "
                            "techniques that bake from photographs draw it)\n");
            std::printf("  textures %zu\n", textures.size());
            for (std::size_t i = 0; i < textures.size(); ++i)
            {
                const TextureRow& t = textures[i];
                if (t.mipCount > 0)
                    std::printf("    %zu '%s' %ux%u RGBA8, %u mip levels, %llu bytes\n", i, t.name.c_str(), t.width,
                                t.height, t.mipCount, (unsigned long long)t.bytes);
                else
                    std::printf("    %zu '%s' %ux%u RGBA8, %llu bytes\n", i, t.name.c_str(), t.width, t.height,
                                (unsigned long long)t.bytes);
            }
        }

        bool isPackage(const std::string& path)
        {
            std::ifstream in(path, std::ios::binary);
            char magic[4] = {};
            return in.read(magic, 4) && std::memcmp(magic, PACKAGE_MAGIC, 4) == 0;
        }

        int infoPackage(const InfoArgs& args)
        {
            Result<PackageReader> opened = PackageReader::open(args.input);
            if (!opened)
                return printError(opened.error());
            const PackageReader& reader = opened.value();

            std::optional<Error> firstError;
            json chunks = json::array();
            std::vector<bool> crcOk(reader.chunks().size(), false);
            std::optional<ReferenceChunk> reference;
            /// (chunk index, summary) of every chunk a registered technique decoded.
            std::vector<std::pair<std::size_t, ChunkSummary>> summaries;
            json meta;
            for (std::size_t i = 0; i < reader.chunks().size(); ++i)
            {
                const ChunkInfo& c = reader.chunks()[i];
                Result<std::vector<std::uint8_t>> bytes = reader.readChunk(i);
                crcOk[i] = bytes.ok();
                char crc[16];
                std::snprintf(crc, sizeof(crc), "%08x", c.crc32);
                chunks.push_back({{"technique", c.technique}, {"level", c.level},
                                  {"formatVersion", c.formatVersion}, {"offset", c.offset}, {"bytes", c.size},
                                  {"crc32", crc}, {"crcOk", bytes.ok()}});
                if (!bytes)
                {
                    if (!firstError)
                        firstError = bytes.error();
                    continue;
                }
                if (c.technique == META_CHUNK && c.level == 0)
                {
                    const std::string text(bytes->begin(), bytes->end());
                    meta = json::parse(text, nullptr, false);
                    if (meta.is_discarded())
                        meta = text;
                    continue;
                }
                const TechniqueDescriptor* technique = findTechniqueDescriptor(c.technique);
                if (!technique)
                    continue; // a chunk of a technique this build does not know: listed only
                if (!readsFormatVersion(*technique, c.formatVersion))
                {
                    if (!firstError)
                        firstError = fail(reader.label(), c.element(),
                                          "unsupported format version " + std::to_string(c.formatVersion) +
                                              ", this build reads " + readFormatVersions(*technique));
                    continue;
                }
                Result<ChunkSummary> summary = inspectChunk(*technique, bytes.value(), reader.label(), c.formatVersion);
                if (!summary)
                {
                    if (!firstError)
                        firstError = summary.error();
                    continue;
                }
                summaries.emplace_back(i, std::move(summary.value()));
                // The model, printed as for glTF input.
                if (c.technique == REFERENCE_CHUNK && c.level == 0)
                {
                    Result<ReferenceChunk> decoded = decodeReferenceChunk(bytes.value(), reader.label());
                    if (decoded)
                        reference = std::move(decoded.value());
                }
            }

            std::vector<TextureRow> textures;
            if (reference)
                for (const GpuTexture& t : reference->textures)
                    textures.push_back({t.name, t.width, t.height, t.mipCount, t.data.size()});

            if (args.json)
            {
                json j;
                j["file"] = args.input;
                j["kind"] = "package";
                j["version"] = reader.version();
                j["fileSize"] = reader.fileSize();
                j["chunks"] = chunks;
                if (!meta.is_null())
                    j["meta"] = meta;
                if (reference)
                    j["model"] = modelJson(reference->model, textures); // same key as for glTF input
                for (const auto& [index, summary] : summaries)
                {
                    const ChunkInfo& c = reader.chunks()[index];
                    const std::string key = c.level == 0 ? c.technique : c.technique + "/" + std::to_string(c.level);
                    if (c.technique != REFERENCE_CHUNK) // the model above says more
                        j[key] = json::parse(summary.json, nullptr, false);
                }
                if (firstError)
                    j["error"] = firstError->message();
                std::printf("%s\n", j.dump(2, ' ', false, json::error_handler_t::replace).c_str());
            }
            else
            {
                std::printf("%s: TreeLod package version %u, %llu bytes, %zu chunks\n", args.input.c_str(),
                            reader.version(), (unsigned long long)reader.fileSize(), reader.chunks().size());
                std::printf("  %-20s %5s %6s %12s %12s  %s\n", "technique", "level", "format", "offset", "bytes",
                            "crc32");
                for (std::size_t i = 0; i < reader.chunks().size(); ++i)
                {
                    const ChunkInfo& c = reader.chunks()[i];
                    std::printf("  %-20s %5u %6u %12llu %12llu  %08x %s\n", c.technique.c_str(), c.level,
                                c.formatVersion, (unsigned long long)c.offset, (unsigned long long)c.size, c.crc32,
                                crcOk[i] ? "ok" : "BAD");
                }
                if (meta.is_object())
                {
                    const std::string source = meta.value("source", std::string());
                    const std::string hash = meta.value("sourceHash", std::string());
                    if (!source.empty() || !hash.empty())
                        std::printf("source %s%s%s\n", source.c_str(), hash.empty() ? "" : ", ", hash.c_str());
                }
                if (reference)
                    printModel(reference->model, textures);
                for (const auto& [index, summary] : summaries)
                {
                    const ChunkInfo& c = reader.chunks()[index];
                    if (c.technique == REFERENCE_CHUNK)
                        continue; // printModel above
                    std::printf("%s%s: %s\n", c.technique.c_str(),
                                c.level == 0 ? "" : (" level " + std::to_string(c.level)).c_str(), summary.text.c_str());
                }
            }
            if (firstError)
                return printError(*firstError);
            return EXIT_OK;
        }

        int infoGltf(const InfoArgs& args)
        {
            ImportOptions options;
            options.leafMaterials = args.leafMaterials;
            ImportReport report;
            Result<TreeModel> model = importGltf(args.input, options, &report);
            if (!model)
                return printError(model.error());
            std::vector<TextureRow> textures;
            for (const TextureImage& t : model->textures)
                textures.push_back({t.name, std::uint32_t(t.width), std::uint32_t(t.height), 0, t.rgba.size()});
            if (args.json)
            {
                json j;
                j["file"] = args.input;
                j["kind"] = "gltf";
                j["model"] = modelJson(model.value(), textures);
                j["import"] = {{"droppedDegenerateLeaves", report.droppedDegenerateLeaves},
                               {"duplicateLeaves", report.duplicateLeaves},
                               {"skippedPrimitives", report.skippedPrimitives},
                               {"warnings", report.warnings}};
                std::printf("%s\n", j.dump(2, ' ', false, json::error_handler_t::replace).c_str());
            }
            else
            {
                std::printf("%s: glTF\n", args.input.c_str());
                printModel(model.value(), textures);
                std::printf("import: %zu degenerate leaves dropped, %zu duplicate leaves, %zu primitives skipped\n",
                            report.droppedDegenerateLeaves, report.duplicateLeaves, report.skippedPrimitives);
                for (const std::string& w : report.warnings)
                    std::printf("warning: %s\n", w.c_str());
            }
            return EXIT_OK;
        }

#ifdef TREELOD_WITH_OGRE
        /// `treelod info --techniques`: every registered technique with its roles, the baselines and
        /// the default bands; what the Forest, the bench and `treelod render` read from the registry.
        int infoTechniques(const InfoArgs& args)
        {
            const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
            const std::vector<ForestBand> bands = Forest::getAutoBands();
            json techniques = json::array();
            for (const TechniqueInfo& t : registry.getTechniques())
            {
                json options = json::array();
                for (const TechniqueParameter& p : t.roles.parameters)
                    options.push_back({{"option", "--" + p.flag}, {"parameter", p.name}, {"description", p.description}});
                techniques.push_back(
                    {{"name", t.name},
                     {"description", t.description},
                     {"chunk", t.chunkTechnique},
                     {"movableType", t.movableType},
                     {"forestLevel", bool(t.forestLevels)},
                     {"floor", t.roles.floor},
                     {"autoCandidate", t.roles.autoCandidate},
                     {"defaultBandMinHeightPx",
                      t.roles.defaultBandMinHeight >= 0.0f ? json(t.roles.defaultBandMinHeight) : json(nullptr)},
                     {"benchDefault", t.roles.benchDefault},
                     {"comparison", t.roles.comparisonLabel.empty() ? json(nullptr) : json(t.roles.comparisonLabel)},
                     {"renderOptions", options}});
            }
            json baselines = json::array();
            for (const BaselineInfo& b : registry.getBaselines())
                baselines.push_back({{"name", b.name}, {"comparison", b.comparisonLabel}, {"chunk", b.chunkTechnique}});
            json defaultBands = json::array();
            for (const ForestBand& b : bands)
                defaultBands.push_back({{"technique", b.technique}, {"minHeightPx", b.minHeightPixels}});
            if (args.json)
            {
                const json j = {{"techniques", techniques}, {"baselines", baselines}, {"defaultBands", defaultBands}};
                std::printf("%s\n", j.dump(2).c_str());
                return EXIT_OK;
            }
            std::printf("techniques (name: roles; chunk; MovableObject type):\n");
            for (const json& t : techniques)
            {
                std::string roles;
                auto add = [&](const std::string& role) { roles += (roles.empty() ? "" : ", ") + role; };
                if (t["autoCandidate"].get<bool>())
                    add("auto candidate");
                if (!t["defaultBandMinHeightPx"].is_null())
                    add("default band from " + std::to_string(int(t["defaultBandMinHeightPx"].get<float>())) + " px");
                if (t["floor"].get<bool>())
                    add("floor");
                if (t["benchDefault"].get<bool>())
                    add("bench default");
                if (!t["comparison"].is_null())
                    add("compared with every bench run");
                if (!t["forestLevel"].get<bool>())
                    add("no Forest level");
                for (const json& o : t["renderOptions"])
                    add("render " + o["option"].get<std::string>());
                std::printf("  %s: %s; chunk %s; %s\n    %s\n", t["name"].get<std::string>().c_str(),
                            roles.empty() ? "-" : roles.c_str(), t["chunk"].get<std::string>().c_str(),
                            t["movableType"].get<std::string>().c_str(), t["description"].get<std::string>().c_str());
            }
            std::printf("baselines (drawn without the Forest, compared with every bench run):\n");
            for (const BaselineInfo& b : registry.getBaselines())
                std::printf("  %s: %s; chunk %s\n", b.name.c_str(), b.comparisonLabel.c_str(), b.chunkTechnique.c_str());
            std::printf("default bands (\"auto\" without a budget):");
            for (std::size_t i = 0; i < bands.size(); ++i)
                std::printf("%s %s from %g px", i ? "," : "", bands[i].technique.c_str(), double(bands[i].minHeightPixels));
            std::printf("\n");
            return EXIT_OK;
        }
#endif

        int runInfo(const InfoArgs& args)
        {
            if (args.techniques)
            {
#ifdef TREELOD_WITH_OGRE
                if (!args.input.empty())
                    return printError(fail(args.input, "--techniques", "takes no file"));
                return infoTechniques(args);
#else
                return printError(fail("", "--techniques", "this build has no Ogre plugin, which registers the techniques"));
#endif
            }
            if (args.input.empty())
                return printError(fail("", "info", "a file to describe, or --techniques"));
            return isPackage(args.input) ? infoPackage(args) : infoGltf(args);
        }
    }

    void addInfoCommand(CLI::App& app)
    {
        auto args = std::make_shared<InfoArgs>();
        CLI::App* cmd = app.add_subcommand("info", "list what a .treelod package or a .glb/.gltf holds");
        cmd->add_option("file", args->input, ".treelod, .glb or .gltf file");
        cmd->add_flag("--techniques", args->techniques,
                      "list the registered techniques with their roles (auto candidate, default band, floor, "
                      "render options), the measurement baselines and the default bands");
        cmd->add_option("--leaf-material", args->leafMaterials,
                        "glTF only: materials with this name are leaves (repeatable; default: alphaMode MASK/BLEND)")
            ->allow_extra_args(false);
        cmd->add_flag("--json", args->json, "print one JSON object");
        cmd->callback([args]() { setExitCode(runInfo(*args)); });
    }
}
