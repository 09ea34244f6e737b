#include "TreeLod/ErrorCurveMeasurer.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/Forest.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/LevelCalibration.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/Package.h"
#include "TreeLod/PackageWriter.h"
#include "TreeLod/RgbaImageConversion.h"
#include "TreeLod/TreeAssetManager.h"
#include "TreeLod/TreeViews.h"

#include <OgreException.h>
#include <OgreSceneManager.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <memory>
#include <map>
#include <optional>
#include <set>

namespace TreeLod
{
    namespace
    {
        constexpr float FOV_Y_DEGREES = 45.0f;

        /// One view of the tree at one screen height: the camera and the square image size.
        struct View
        {
            CameraSpec camera;
            int size = 0;
        };

        /// The tree's box height spans `heightPx` pixels at the view's distance (ForestBand's
        /// units); the image holds the box's bounding sphere.
        View makeView(const glm::vec3& lo, const glm::vec3& hi, float heightPx, const glm::vec2& view)
        {
            const glm::vec3 centre = 0.5f * (lo + hi);
            const float boxHeight = std::max(hi.y - lo.y, 1e-6f);
            const float radius = 0.5f * glm::length(hi - lo);
            View v;
            v.size = std::max(8, int(std::ceil(2.1f * heightPx * radius / boxHeight)) + 2);
            const float distance = float(distanceForHeight(boxHeight, heightPx, v.size, FOV_Y_DEGREES));
            const float az = glm::radians(view.x), el = glm::radians(view.y);
            const glm::vec3 dir(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
            v.camera.position = centre + distance * dir;
            v.camera.target = centre;
            v.camera.up = std::abs(dir.y) > 0.99f ? glm::vec3(0.0f, 0.0f, -1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
            v.camera.fovYDegrees = FOV_Y_DEGREES;
            v.camera.nearClip = std::max(distance - 1.5f * radius, 0.01f * distance);
            v.camera.farClip = distance + 1.5f * radius;
            return v;
        }

        struct Scores
        {
            double flip = 0.0, rmse = 0.0;
        };

        /// One view's images: the CPU reference and each level's frame (same size).
        struct ViewShots
        {
            Image reference;
            std::vector<RgbaImage> levels;
        };

        /// One view's scores: each level's against the reference, and (where the view counts in the
        /// mean) each pair's FLIP, at ErrorCurves::switchPair.
        struct ViewScores
        {
            std::vector<Scores> levels;
            std::vector<double> switches;
        };

        /// Every level's scores against the reference over one square crop around the tree: the
        /// union of the reference's and every level's tree pixels, so the levels of a view are
        /// compared on the same pixels. FLIP is the mean over the tree's own pixels (meanOverTree),
        /// multi-scale RMSE the crop's. With `switches`, the FLIP between every two levels too,
        /// over the pixels that are tree in either. Each image is filtered for FLIP once
        /// (FlipReference), so a pair costs only the per-pixel comparison; a level drawn byte for
        /// byte as an earlier one gets its scores. Errors name the level.
        Result<ViewScores> scoreView(const ViewShots& shots, const std::vector<ForestLevel>& levels, bool switches)
        {
            Extent extent = treeExtent(shots.reference);
            for (const RgbaImage& shot : shots.levels)
                extent = unite(extent, treeExtent(toImage(shot)));
            const Crop crop = cropAround(extent, shots.reference.width, shots.reference.height);
            const Image reference = cropImage(shots.reference, crop);
            Result<FlipReference> prepared = FlipReference::make(reference);
            if (!prepared)
                return fail("", "reference", "FLIP: " + prepared.error().message());
            const std::size_t n = shots.levels.size();
            const std::vector<std::uint8_t> referenceTree = treeMask(reference);
            std::vector<std::size_t> first(n); // the first level drawn byte for byte as this one
            std::vector<std::vector<std::uint8_t>> trees(n); // each level's tree pixels
            std::vector<FlipReference> analysed(n);
            ViewScores scores;
            scores.levels.resize(n);
            for (std::size_t l = 0; l < n; ++l)
            {
                first[l] = std::size_t(std::find_if(shots.levels.begin(), shots.levels.begin() + std::ptrdiff_t(l),
                                                    [&](const RgbaImage& earlier) {
                                                        return earlier.pixels == shots.levels[l].pixels;
                                                    }) -
                                       shots.levels.begin());
                if (first[l] != l)
                {
                    scores.levels[l] = scores.levels[first[l]];
                    continue;
                }
                const std::string element = "level " + Forest::describeLevel(levels[l]);
                const Image test = cropImage(toImage(shots.levels[l]), crop);
                trees[l] = treeMask(test);
                Result<FlipReference> image = FlipReference::make(test);
                Result<FlipResult> f = image ? flip(*prepared, *image, true) : Result<FlipResult>(image.error());
                if (!f)
                    return fail("", element, "FLIP: " + f.error().message());
                analysed[l] = std::move(*image);
                Result<MultiScaleRmseResult> m = multiScaleRmse(reference, test);
                if (!m)
                    return fail("", element, "multi-scale RMSE: " + m.error().message());
                scores.levels[l] = Scores{meanOverTree(*f, referenceTree, trees[l]), m->combined};
            }
            if (!switches)
                return scores;
            for (std::size_t a = 0; a < n; ++a)
                for (std::size_t b = a + 1; b < n; ++b)
                {
                    const std::size_t i = first[a], j = first[b];
                    if (i == j)
                    {
                        scores.switches.push_back(0.0);
                        continue;
                    }
                    Result<FlipResult> f = flip(analysed[i], analysed[j], true);
                    if (!f)
                        return fail("", "levels " + Forest::describeLevel(levels[a]) + " and " +
                                            Forest::describeLevel(levels[b]),
                                    "FLIP: " + f.error().message());
                    scores.switches.push_back(meanOverTree(*f, trees[i], trees[j]));
                }
            return scores;
        }
    }

    Result<ErrorCurves> measureErrorCurves(OffscreenRenderer& renderer, TreeAsset& asset,
                                           const ErrorCurveOptions& options, const ProgressCallback& progress)
    {
        const std::string label = "asset '" + asset.getName() + "'";
        if (options.heightsPx.empty() || options.views.empty() || options.referenceSupersample < 1)
            return fail(label, "error curves", "no heights, no views or a supersampling below 1");
        std::vector<ForestLevel> levels;
        try
        {
            levels = Forest::getCandidateLevels(asset);
        }
        catch (const Ogre::Exception& e)
        {
            return fail(label, "error curves", e.getDescription());
        }
        if (levels.empty())
            return fail(label, "error curves", "no technique can draw this asset as a Forest level");

        const TreeModel& model = asset.getReference().model;
        if (Result<void> polygons = requirePolygons(model, label, "error curves (measured against it)"); !polygons)
            return polygons.error();
        const ReferenceRenderer cpu(model);
        const glm::vec3 lo = model.boundsMin, hi = model.boundsMax;

        ErrorCurves curves;
        curves.heightsPx = options.heightsPx;
        curves.views = std::uint32_t(options.views.size());
        curves.referenceSamples = std::uint32_t(options.referenceSupersample * options.referenceSupersample);
        curves.levels.resize(levels.size());
        for (std::size_t l = 0; l < levels.size(); ++l)
        {
            ErrorCurveLevel& c = curves.levels[l];
            c.technique = levels[l].technique;
            c.techniqueLevel = levels[l].techniqueLevel;
            c.lowRes = levels[l].lowRes;
            c.flip.assign(options.heightsPx.size(), 0.0f);
            c.flipMax.assign(options.heightsPx.size(), 0.0f);
            c.rmse.assign(options.heightsPx.size(), 0.0f);
        }
        curves.switchFlip.assign(ErrorCurves::switchPairs(levels.size()),
                                 std::vector<float>(options.heightsPx.size(), 0.0f));

        renderer.setLighting(LightingSpec()); // the CPU reference's (RenderOptions' default)
        renderer.setShadows(false);
        renderer.setLodBias(1.0f);
        renderer.clearContent();
        Ogre::SceneManager& sceneManager = renderer.getSceneManager();
        // The mean is over the views a camera near the ground sees; the worst view includes them all.
        const bool anySide = std::any_of(options.views.begin(), options.views.end(),
                                         [&](const glm::vec2& v) { return v.y <= options.meanMaxElevation; });
        auto meanView = [&](const glm::vec2& view) { return !anySide || view.y <= options.meanMaxElevation; };
        const std::size_t meanViews = std::size_t(std::count_if(options.views.begin(), options.views.end(), meanView));
        const std::size_t total = options.heightsPx.size() * options.views.size();
        std::size_t done = 0;
        // A view's scores are computed on another thread while Ogre (this thread, which owns the
        // GL context) draws the next view: FLIP on the CPU overlaps the renderer's work. The
        // scores do not depend on the thread count (ImageMetrics.h).
        struct Pending
        {
            std::future<Result<ViewScores>> scores;
            std::size_t height = 0;
            bool inMean = false;
        };
        std::optional<Pending> pending;
        auto collect = [&]() -> Result<void> {
            if (!pending)
                return {};
            Result<ViewScores> s = pending->scores.get();
            const Pending view = std::move(*pending);
            pending.reset();
            if (!s)
                return s.error();
            for (std::size_t p = 0; p < s->switches.size(); ++p)
                curves.switchFlip[p][view.height] += float(s->switches[p]) / float(meanViews);
            for (std::size_t l = 0; l < levels.size(); ++l)
            {
                ErrorCurveLevel& c = curves.levels[l];
                const Scores& score = s->levels[l];
                if (view.inMean)
                {
                    c.flip[view.height] += float(score.flip) / float(meanViews);
                    c.rmse[view.height] += float(score.rmse) / float(meanViews);
                }
                c.flipMax[view.height] = std::max(c.flipMax[view.height], float(score.flip));
            }
            return {};
        };
        auto abandon = [&](const Error& error) -> Error {
            if (pending)
                pending->scores.wait(); // it reads only its own images
            pending.reset();
            renderer.clearContent();
            return fail(label, error.element, error.reason);
        };
        // The GPU resources each level draws from at any height (the bark at its LoD level there):
        // each once, by identity, held to the end so that no address is reused.
        std::vector<std::shared_ptr<const void>> held;
        std::map<const void*, std::uint32_t> resourceIndex;
        std::vector<std::set<std::uint32_t>> levelResources(levels.size());
        auto addResources = [&](std::size_t l, const Forest& forest) {
            const std::uint32_t drawn = std::uint32_t(forest.getLevels(0).size() - 1); // built with the species
            for (const ForestGpuResource& resource : forest.getGpuResources(0, drawn))
            {
                auto [at, added] = resourceIndex.emplace(resource.handle.get(), std::uint32_t(held.size()));
                if (added)
                {
                    held.push_back(resource.handle);
                    curves.resourceBytes.push_back(resource.bytes);
                }
                levelResources[l].insert(at->second);
            }
        };
        for (std::size_t h = 0; h < options.heightsPx.size(); ++h)
        {
            // One Forest per level, its bark at the mesh LoD level a Forest draws at this height.
            std::vector<Forest*> forests;
            try
            {
                renderer.clearContent();
                for (std::size_t l = 0; l < levels.size(); ++l)
                {
                    Forest* forest =
                        createLevelForest(sceneManager, renderer.getContentNode(), asset, levels[l], {ForestInstance{}},
                                          "TreeLod/ErrorCurves/" + std::to_string(l), options.heightsPx[h]);
                    forest->setVisible(false);
                    forests.push_back(forest);
                    addResources(l, *forest);
                }
            }
            catch (const Ogre::Exception& e)
            {
                return abandon(Error{"", "level " + Forest::describeLevel(levels[forests.size()]), e.getDescription()});
            }
            for (const glm::vec2& viewAngles : options.views)
            {
                report(progress, "error curves", float(done++) / float(total));
                const View view = makeView(lo, hi, options.heightsPx[h], viewAngles);
                auto shots = std::make_shared<ViewShots>();
                shots->reference = traceReference(cpu, view.camera, view.size, options.referenceSupersample);
                for (std::size_t l = 0; l < levels.size(); ++l)
                {
                    forests[l]->setVisible(true);
                    try
                    {
                        shots->levels.push_back(renderer.render(view.camera, view.size, view.size, 1));
                    }
                    catch (const Ogre::Exception& e)
                    {
                        return abandon(Error{"", "level " + Forest::describeLevel(levels[l]), e.getDescription()});
                    }
                    forests[l]->setVisible(false);
                }
                if (Result<void> collected = collect(); !collected)
                    return abandon(collected.error());
                const bool inMean = meanView(viewAngles);
                pending = Pending{std::async(std::launch::async,
                                             [shots, &levels, inMean] { return scoreView(*shots, levels, inMean); }),
                                  h, inMean};
            }
        }
        if (Result<void> collected = collect(); !collected)
            return abandon(collected.error());
        renderer.clearContent();
        report(progress, "error curves", 1.0f);
        for (std::size_t l = 0; l < levels.size(); ++l)
            curves.levels[l].resources.assign(levelResources[l].begin(), levelResources[l].end());
        for (ErrorCurveLevel& c : curves.levels)
            for (std::size_t h = 0; h < c.flip.size(); ++h)
            {
                c.flip[h] = std::clamp(c.flip[h], 0.0f, 1.0f);
                c.rmse[h] = std::clamp(c.rmse[h], 0.0f, 1.0f);
                c.flipMax[h] = std::max(c.flipMax[h], c.flip[h]);
            }
        for (std::vector<float>& pair : curves.switchFlip)
            for (float& v : pair)
                v = std::clamp(v, 0.0f, 1.0f);
        if (Result<void> valid = validateErrorCurves(curves, label); !valid)
            return valid.error();
        return curves;
    }

    bool coversCandidateLevels(const ErrorCurves& curves, TreeAsset& asset, const ErrorCurveOptions& options)
    {
        if (curves.heightsPx != options.heightsPx || curves.views != options.views.size() || !curves.hasSwitchFlip() ||
            !curves.hasGpuBytes())
            return false;
        for (const ForestLevel& level : Forest::getCandidateLevels(asset))
            if (curves.find(level.technique, level.techniqueLevel, level.lowRes) < 0)
                return false;
        return true;
    }

    namespace
    {
        /// `bytes` loaded as a TreeAsset of TreeAssetManager's for as long as it lives.
        class TemporaryAsset
        {
        public:
            TemporaryAsset(std::vector<std::uint8_t> bytes, const std::string& label)
            {
                static int counter = 0;
                mAsset = TreeAssetManager::getSingleton().loadFromBytes(
                    "TreeLod/ErrorCurves/" + std::to_string(counter++) + "/" + label, Ogre::RGN_DEFAULT,
                    std::move(bytes));
            }
            ~TemporaryAsset() { TreeAssetManager::getSingleton().remove(mAsset); }
            TreeAsset& get() { return *mAsset; }

        private:
            TreeAssetPtr mAsset;
        };

        /// The package of `asset` with its error curves measured and added, the other chunks copied.
        Result<std::vector<std::uint8_t>> withCurves(OffscreenRenderer& renderer, TreeAsset& asset,
                                                     const ErrorCurveOptions& options, const ProgressCallback& progress,
                                                     const std::string& label)
        {
            Result<ErrorCurves> curves = measureErrorCurves(renderer, asset, options, progress);
            if (!curves)
                return fail(label, "error curves", curves.error().message());
            const PackageReader& reader = asset.getPackage();
            PackageWriter writer;
            for (std::size_t i = 0; i < reader.chunks().size(); ++i)
            {
                const ChunkInfo& info = reader.chunks()[i];
                if (info.technique == ERROR_CURVES_CHUNK)
                    continue;
                Result<std::vector<std::uint8_t>> chunk = reader.readChunk(i);
                if (!chunk)
                    return chunk.error();
                if (Result<void> added = writer.addChunk(info.technique, info.level, info.formatVersion,
                                                         std::move(chunk.value()));
                    !added)
                    return fail(label, info.element(), added.error().message());
            }
            if (Result<void> added = writer.addChunk(ERROR_CURVES_CHUNK, 0, ERROR_CURVES_FORMAT_VERSION,
                                                     encodeErrorCurves(*curves));
                !added)
                return fail(label, ERROR_CURVES_CHUNK, added.error().message());
            return writer.toBytes();
        }
    }

    Result<std::vector<std::uint8_t>> addErrorCurves(OffscreenRenderer& renderer, const std::vector<std::uint8_t>& bytes,
                                                     const std::string& label, const ErrorCurveOptions& options,
                                                     const ProgressCallback& progress)
    {
        try
        {
            TemporaryAsset asset(bytes, label);
            return withCurves(renderer, asset.get(), options, progress, label);
        }
        catch (const Ogre::Exception& e)
        {
            return fail(label, "", e.getDescription());
        }
    }

    Result<bool> ensureErrorCurves(OffscreenRenderer& renderer, const std::string& path,
                                   const ErrorCurveOptions& options, const ProgressCallback& progress)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        try
        {
            TemporaryAsset asset(std::move(bytes.value()), path);
            if (asset.get().hasChunk(ERROR_CURVES_CHUNK))
            {
                Result<ErrorCurves> held = decodeErrorCurves(asset.get().readChunk(ERROR_CURVES_CHUNK), path,
                                                             asset.get().getChunkFormatVersion(ERROR_CURVES_CHUNK));
                if (held && coversCandidateLevels(*held, asset.get(), options))
                    return false;
            }
            Result<std::vector<std::uint8_t>> updated = withCurves(renderer, asset.get(), options, progress, path);
            if (!updated)
                return updated.error();
            if (Result<void> written = writeFileAtomic(path, *updated); !written)
                return written.error();
            return true;
        }
        catch (const Ogre::Exception& e)
        {
            return fail(path, "", e.getDescription());
        }
    }
}
