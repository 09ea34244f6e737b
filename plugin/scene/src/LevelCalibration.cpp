#include "TreeLod/LevelCalibration.h"

#include "TreeLod/Forest.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TechniqueSupport.h"
#include "TreeLod/TreeAssetManager.h"

#include <OgreHighLevelGpuProgram.h>
#include <OgreManualObject.h>
#include <OgreRenderSystem.h>
#include <OgreRenderSystemCapabilities.h>
#include <OgreRoot.h>
#include <OgreSceneManager.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <tuple>

namespace TreeLod
{
    namespace
    {
        constexpr float FOV_Y_DEGREES = 45.0f;

        double median(std::vector<double> v)
        {
            std::sort(v.begin(), v.end());
            return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
        }

        float boxHeight(const Ogre::AxisAlignedBox& box) { return std::max(box.getMaximum().y - box.getMinimum().y, 1e-6f); }

        /// A grid of `count` trees `distance` metres in front of the camera (looking along -Z from
        /// the origin), each `heightPx` tall, `spacingPx` apart.
        std::vector<ForestInstance> grid(const Ogre::AxisAlignedBox& box, float heightPx, float spacingPx,
                                         float distance, std::uint32_t count)
        {
            const float metresPerPx = boxHeight(box) / heightPx;
            const int columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
            std::vector<ForestInstance> instances;
            for (std::uint32_t i = 0; i < count; ++i)
            {
                const int cx = int(i) % columns, cy = int(i) / columns;
                ForestInstance instance;
                instance.position = glm::vec3((float(cx) - 0.5f * float(columns - 1)) * spacingPx * metresPerPx,
                                              (float(cy) - 0.5f * float(columns - 1)) * spacingPx * metresPerPx -
                                                  0.5f * (box.getMinimum().y + box.getMaximum().y),
                                              -distance);
                instances.push_back(instance);
            }
            return instances;
        }
    }

    namespace
    {
        // The sampling draw of measureTextureSampling: clip-space quads, four trilinear reads a fragment.
        constexpr const char* SAMPLING_VERTEX = R"(
in vec4 vertex;
in vec2 uv0;
out vec2 uv;
void main()
{
    gl_Position = vec4(vertex.xy, 0.0, 1.0);
    uv = uv0;
}
)";
        constexpr const char* SAMPLING_FRAGMENT = R"(
uniform sampler2D tex;
in vec2 uv;
out vec4 fragColour;
void main()
{
    fragColour = 0.25 * (texture(tex, uv) + texture(tex, uv * 0.93 + 0.03) + texture(tex, uv * 1.07 + 0.11) +
                         texture(tex, uv.yx));
}
)";
        constexpr std::uint32_t SAMPLING_TEXELS = 1024;
        constexpr int SAMPLING_LAYERS = 4;
        constexpr int SAMPLING_VIEWPORT = 256;

        /// A DXT5 texture of SAMPLING_TEXELS² with every mip level, of pseudo-random blocks (every
        /// byte string is a valid BC3 block; what the texels hold does not change the cost).
        GpuTexture samplingTexture()
        {
            GpuTexture t;
            t.name = "sampling";
            t.format = GpuTextureFormat::DXT5;
            t.width = t.height = SAMPLING_TEXELS;
            t.mipCount = fullMipCount(t.width, t.height);
            t.data.resize(gpuTextureBytes(t.format, t.width, t.height, t.mipCount));
            std::uint64_t state = 0x9E3779B97F4A7C15ull;
            for (std::uint8_t& b : t.data)
            {
                state = state * 6364136223846793005ull + 1442695040888963407ull;
                b = std::uint8_t(state >> 56);
            }
            return t;
        }

        /// Makes the sampling programs, textures and materials in RGN_INTERNAL; removes them when destroyed.
        class SamplingScene
        {
        public:
            SamplingScene()
            {
                auto& programs = Ogre::HighLevelGpuProgramManager::getSingleton();
                const bool es = programsAreGlslEs();
                const std::string header = es ? "#version 300 es\nprecision highp float;\n" : "#version 330\n";
                for (const auto& [name, source, type] :
                     {std::make_tuple(VERTEX, SAMPLING_VERTEX, Ogre::GPT_VERTEX_PROGRAM),
                      std::make_tuple(FRAGMENT, SAMPLING_FRAGMENT, Ogre::GPT_FRAGMENT_PROGRAM)})
                {
                    Ogre::HighLevelGpuProgramPtr program =
                        programs.createProgram(name, Ogre::RGN_INTERNAL, es ? "glsles" : "glsl", type);
                    program->setSource(header + source);
                    program->load();
                }
                const GpuTexture compressed = samplingTexture();
                const GpuTexture decoded = decodeGpuTexture(compressed);
                for (const GpuTexture* t : {&compressed, &decoded})
                {
                    const Ogre::String name = t == &compressed ? COMPRESSED : DECODED;
                    uploadTexture(name, Ogre::RGN_INTERNAL, t->data.data(), t->width, t->height, ogreFormat(t->format),
                                  t->mipCount);
                    Ogre::MaterialPtr m = Ogre::MaterialManager::getSingleton().create(name, Ogre::RGN_INTERNAL);
                    Ogre::Pass* pass = m->getTechnique(0)->getPass(0);
                    pass->setVertexProgram(VERTEX);
                    pass->setFragmentProgram(FRAGMENT);
                    pass->setDepthCheckEnabled(false);
                    pass->setDepthWriteEnabled(false);
                    pass->setCullingMode(Ogre::CULL_NONE);
                    pass->setLightingEnabled(false);
                    pass->createTextureUnitState(name)->setTextureFiltering(Ogre::TFO_TRILINEAR);
                    pass->getFragmentProgramParameters()->setNamedConstant("tex", 0);
                    m->load();
                }
            }
            ~SamplingScene()
            {
                for (const char* name : {COMPRESSED, DECODED})
                {
                    Ogre::MaterialManager::getSingleton().remove(name, Ogre::RGN_INTERNAL);
                    Ogre::TextureManager::getSingleton().remove(name, Ogre::RGN_INTERNAL);
                }
                for (const char* name : {VERTEX, FRAGMENT})
                    Ogre::HighLevelGpuProgramManager::getSingleton().remove(name, Ogre::RGN_INTERNAL);
            }
            /// SAMPLING_LAYERS quads covering the viewport, drawn with `material`.
            static void attach(OffscreenRenderer& renderer, const char* material)
            {
                Ogre::ManualObject* quads = renderer.getSceneManager().createManualObject();
                quads->begin(material, Ogre::RenderOperation::OT_TRIANGLE_LIST, Ogre::RGN_INTERNAL);
                for (int layer = 0; layer < SAMPLING_LAYERS; ++layer)
                {
                    const float shift = 0.25f * float(layer);
                    for (const auto& [x, y] : {std::make_pair(-1.0f, -1.0f), std::make_pair(1.0f, -1.0f),
                                               std::make_pair(1.0f, 1.0f), std::make_pair(-1.0f, 1.0f)})
                    {
                        quads->position(x, y, 0.0f);
                        quads->textureCoord(0.5f * (x + 1.0f) + shift, 0.5f * (1.0f - y));
                    }
                    const Ogre::uint32 first = Ogre::uint32(4 * layer);
                    quads->quad(first, first + 1, first + 2, first + 3);
                }
                quads->end();
                quads->setBoundingBox(Ogre::AxisAlignedBox::BOX_INFINITE);
                renderer.getContentNode().attachObject(quads);
            }
            static constexpr const char* VERTEX = "TreeLod/Calibration/SamplingVertex";
            static constexpr const char* FRAGMENT = "TreeLod/Calibration/SamplingFragment";
            static constexpr const char* COMPRESSED = "TreeLod/Calibration/Compressed";
            static constexpr const char* DECODED = "TreeLod/Calibration/Decoded";
        };

        /// The calibration file at `path` for `renderer`, or an empty one (a warning when the file
        /// is there but unreadable: it is calibrated again).
        CostCalibration heldCalibration(const std::string& path, const std::string& renderer,
                                        const ProgressCallback& progress)
        {
            CostCalibration calibration;
            calibration.renderer = renderer;
            std::error_code ec;
            if (!std::filesystem::exists(path, ec))
                return calibration;
            Result<CostCalibration> read = readCostCalibration(path, renderer);
            if (read)
                return std::move(read.value());
            report(progress, "warning: " + read.error().message() + "; calibrating again", 0.0f);
            return calibration;
        }
    }

    Result<TextureSamplingCost> measureTextureSampling(OffscreenRenderer& renderer, const CalibrationOptions& options)
    {
        const Ogre::HighLevelGpuProgramManager& programs = Ogre::HighLevelGpuProgramManager::getSingleton();
        if (!programs.isLanguageSupported("glsl") && !programs.isLanguageSupported("glsles"))
            return fail("", "texture sampling", "the render system runs no GLSL or GLSL ES programs");
        if (options.viewport < 16 || options.frames < 1)
            return fail("", "texture sampling", "needs a viewport of 16 px or more and frames");
        renderer.setShadows(false);
        renderer.clearContent();
        const CameraSpec camera; // the quads are in clip space
        const int viewport = std::min(options.viewport, SAMPLING_VIEWPORT);
        auto time = [&]() { return median(renderer.timeFrames(camera, viewport, viewport, options.frames)); };
        TextureSamplingCost cost;
        try
        {
            SamplingScene scene;
            const double emptyMs = time();
            // Twice each, alternating, so that a drift of the machine's load falls on both.
            std::vector<double> compressed, decoded;
            for (int round = 0; round < 2; ++round)
                for (const char* material : {SamplingScene::COMPRESSED, SamplingScene::DECODED})
                {
                    SamplingScene::attach(renderer, material);
                    (material == SamplingScene::COMPRESSED ? compressed : decoded).push_back(time());
                    renderer.clearContent();
                }
            cost.compressedMs = std::max(0.0, median(compressed) - emptyMs);
            cost.decodedMs = std::max(0.0, median(decoded) - emptyMs);
        }
        catch (const Ogre::Exception& e)
        {
            renderer.clearContent();
            return fail("", "texture sampling", e.getDescription());
        }
        return cost;
    }

    Result<TextureSamplingCost> requireTextureUpload(OffscreenRenderer& renderer, const std::string& directory,
                                                     const CalibrationOptions& options, const ProgressCallback& progress)
    {
        const std::string renderString = rendererString(renderer.getRoot());
        const std::string path = costCalibrationPath(directory, renderString);
        CostCalibration calibration = heldCalibration(path, renderString, progress);
        std::error_code ec;
        if (!calibration.hasTextureSampling)
        {
            report(progress, "calibrate texture sampling (block-compressed against RGBA8)", 0.0f);
            Result<TextureSamplingCost> measured = measureTextureSampling(renderer, options);
            if (!measured)
                return measured.error();
            calibration.hasTextureSampling = true;
            calibration.textureSampling = measured.value();
            std::filesystem::create_directories(directory, ec);
            if (Result<void> written = writeCostCalibration(path, calibration); !written)
                return written.error();
        }
        adoptCalibratedTextureUpload(calibration);
        return calibration.textureSampling;
    }

    bool adoptCalibratedTextureUpload(const CostCalibration& calibration)
    {
        if (!calibration.hasTextureSampling)
            return false;
        TreeAssetManager::getSingleton().adoptMeasuredTextureUpload(calibration.textureSampling.decodeAtLoad()
                                                                        ? CompressedTextureUpload::Decoded
                                                                        : CompressedTextureUpload::AsStored);
        return true;
    }

    std::string rendererString(Ogre::Root& root)
    {
        Ogre::RenderSystem* system = root.getRenderSystem();
        if (!system)
            return "no render system";
        const Ogre::RenderSystemCapabilities* caps = system->getCapabilities();
        return system->getName() + " | " + (caps ? caps->getDeviceName() : Ogre::String("?")) + " | " +
               (caps ? caps->getDriverVersion().toString() : Ogre::String("?"));
    }

    std::string levelCostKey(TreeAsset& asset)
    {
        std::vector<std::string> chunks;
        for (const ForestLevel& level : Forest::getCandidateLevels(asset, Forest::getAutoTechniques()))
        {
            const TechniqueInfo& info = TechniqueRegistry::getSingleton().get(level.technique);
            if (std::find(chunks.begin(), chunks.end(), info.chunkTechnique) == chunks.end())
                chunks.push_back(info.chunkTechnique);
        }
        if (std::find(chunks.begin(), chunks.end(), REFERENCE_CHUNK) == chunks.end())
            chunks.push_back(REFERENCE_CHUNK); // the bark every level draws
        return assetCostKey(asset.getPackage(), chunks);
    }

    Forest* createLevelForest(Ogre::SceneManager& sceneManager, Ogre::SceneNode& node, TreeAsset& asset,
                              const ForestLevel& level, const std::vector<ForestInstance>& instances,
                              const std::string& name, float heightPx)
    {
        const TreeAssetPtr pointer = TreeAssetManager::getSingleton().getByName(asset.getName(), asset.getGroup());
        if (!pointer)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "asset '" + asset.getName() + "' is not TreeAssetManager's",
                        "createLevelForest");
        auto* forest = static_cast<Forest*>(sceneManager.createMovableObject(name, ForestFactory::FACTORY_TYPE_NAME));
        forest->setOcclusion(false); // a level's cost and error are measured on every tree
        try
        {
            ForestLevel only = level;
            only.minPixelCount = 0.0f;
            std::vector<ForestLevel> levels = {only};
            if (heightPx > 0.0f)
            {
                ForestLevel above = level; // built only if a tree is taller than 1.05 heightPx: never here
                above.minPixelCount = Forest::pixelCountForHeight(asset, 1.05f * heightPx);
                levels.insert(levels.begin(), above);
            }
            forest->addSpecies(pointer, levels);
            forest->addInstances(instances);
        }
        catch (...)
        {
            sceneManager.destroyMovableObject(forest);
            throw;
        }
        node.attachObject(forest);
        return forest;
    }

    Result<std::vector<LevelCost>> calibrateLevels(OffscreenRenderer& renderer, TreeAsset& asset,
                                                   const CalibrationOptions& options, const ProgressCallback& progress)
    {
        const std::string label = "asset '" + asset.getName() + "'";
        if (options.heightsPx.empty() || options.viewport < 16 || options.frames < 1 || options.maxTrees == 0)
            return fail(label, "calibration", "needs heights, a viewport of 16 px or more, frames and trees");
        std::vector<ForestLevel> levels;
        try
        {
            levels = Forest::getCandidateLevels(asset, Forest::getAutoTechniques());
        }
        catch (const Ogre::Exception& e)
        {
            return fail(label, "calibration", e.getDescription());
        }
        const Ogre::AxisAlignedBox box = asset.getBounds();
        const Ogre::Vector3 size = box.getSize();
        const float aspect = std::max(1.0f, std::max(size.x, size.z) / std::max(size.y, 1e-6f));
        renderer.setShadows(false);
        renderer.setLodBias(1.0f);
        renderer.clearContent();

        // The camera of each height (trees `heightPx` tall in the viewport) and its empty frame's time.
        struct Setup
        {
            float heightPx = 0.0f, spacingPx = 0.0f, distance = 0.0f; ///< distance: of the grid
            std::uint32_t count = 0;
            CameraSpec camera;
            double emptyMs = 0.0;
        };
        std::vector<Setup> setups;
        for (const float heightPx : options.heightsPx)
        {
            Setup setup;
            setup.heightPx = heightPx;
            setup.spacingPx = 1.2f * heightPx * aspect;
            const int columns = std::max(1, int(float(options.viewport) / setup.spacingPx));
            setup.count = std::min(options.maxTrees, std::uint32_t(columns * columns));
            setup.distance = float(distanceForHeight(boxHeight(box), heightPx, options.viewport, FOV_Y_DEGREES));
            setup.camera.position = glm::vec3(0.0f);
            setup.camera.target = glm::vec3(0.0f, 0.0f, -1.0f);
            setup.camera.fovYDegrees = FOV_Y_DEGREES;
            setup.camera.nearClip = std::max(0.01f, 0.25f * setup.distance);
            setup.camera.farClip = 4.0f * setup.distance;
            setup.emptyMs = median(renderer.timeFrames(setup.camera, options.viewport, options.viewport, options.frames));
            setups.push_back(setup);
        }

        std::vector<LevelCost> costs;
        const std::size_t total = levels.size() * setups.size();
        std::size_t done = 0;
        for (const ForestLevel& level : levels)
        {
            LevelCost cost;
            cost.technique = level.technique;
            cost.techniqueLevel = level.techniqueLevel;
            cost.lowRes = level.lowRes;
            for (const Setup& setup : setups)
            {
                report(progress,
                       "calibrate " + Forest::describeLevel(level) + " at " + std::to_string(int(setup.heightPx)) + " px",
                       float(done++) / float(total));
                double perTree = 0.0;
                try
                {
                    auto timeGrid = [&](std::uint32_t count, int frames) {
                        createLevelForest(renderer.getSceneManager(), renderer.getContentNode(), asset, level,
                                          grid(box, setup.heightPx, setup.spacingPx, setup.distance, count),
                                          "TreeLod/Calibration", setup.heightPx);
                        // timeFrames draws one untimed frame first (programs linked, levels built)
                        const double ms = median(renderer.timeFrames(setup.camera, options.viewport, options.viewport,
                                                                     frames));
                        renderer.clearContent();
                        return std::max(0.0, ms - setup.emptyMs);
                    };
                    const std::uint32_t probe = std::min(options.probeTrees, setup.count);
                    const double probeMs = timeGrid(probe, 1) / double(probe);
                    const std::uint32_t count = std::clamp<std::uint32_t>(
                        std::uint32_t(options.targetFrameMs / std::max(probeMs, 1e-4)), 1, setup.count);
                    perTree = timeGrid(count, options.frames) / double(count);
                }
                catch (const Ogre::Exception& e)
                {
                    renderer.clearContent();
                    return fail(label, "level " + Forest::describeLevel(level), e.getDescription());
                }
                cost.heightsPx.push_back(setup.heightPx);
                cost.msPerTree.push_back(float(perTree));
            }
            costs.push_back(std::move(cost));
        }
        report(progress, "calibrate", 1.0f);
        return costs;
    }

    Result<std::vector<LevelCost>> requireLevelCosts(OffscreenRenderer& renderer, TreeAsset& asset,
                                                     const std::string& directory, const CalibrationOptions& options,
                                                     const ProgressCallback& progress, bool* calibrated)
    {
        if (calibrated)
            *calibrated = false;
        if (Result<TextureSamplingCost> sampling = requireTextureUpload(renderer, directory, options, progress); !sampling)
            report(progress, "warning: " + sampling.error().message() + "; textures uploaded as stored", 0.0f);
        const std::string renderString = rendererString(renderer.getRoot());
        const std::string path = costCalibrationPath(directory, renderString);
        const std::string key = levelCostKey(asset);
        CostCalibration calibration = heldCalibration(path, renderString, progress);
        std::error_code ec;
        if (const std::vector<LevelCost>* held = calibration.find(key))
        {
            bool all = true;
            for (const ForestLevel& level : Forest::getCandidateLevels(asset, Forest::getAutoTechniques()))
                all = all && findLevelCost(*held, level.technique, level.techniqueLevel, level.lowRes) >= 0;
            if (all)
                return *held;
        }
        Result<std::vector<LevelCost>> costs = calibrateLevels(renderer, asset, options, progress);
        if (!costs)
            return costs.error();
        calibration.assets[key] = costs.value();
        std::filesystem::create_directories(directory, ec);
        if (Result<void> written = writeCostCalibration(path, calibration); !written)
            return written.error();
        if (calibrated)
            *calibrated = true;
        return costs;
    }
}
