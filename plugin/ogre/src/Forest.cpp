// Forest: many trees in one MovableObject, culled and LoD-selected in one loop
// (ForestInstances::cull) and drawn with hardware instancing. See Forest.h.
#include "TreeLod/Forest.h"

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/LevelSelection.h"
#include "TreeLod/ObjectParams.h"
#include "TreeLod/ScreenSizeLodStrategy.h"
#include "TreeLod/ShadowSetup.h"

#include "TreeLod/TechniqueRegistry.h"

#include <OgreCamera.h>
#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreHighLevelGpuProgram.h>
#include <OgreHighLevelGpuProgramManager.h>
#include <OgreLogManager.h>
#include <OgreMaterialManager.h>
#include <OgrePixelCountLodStrategy.h>
#include <OgrePass.h>
#include <OgreRenderQueue.h>
#include <OgreRoot.h>
#include <OgreSceneManager.h>
#include <OgreSceneNode.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>
#include <OgreUnifiedHighLevelGpuProgram.h>
#include <OgreViewport.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cfloat>
#include <cmath>
#include <limits>
#include <set>

namespace TreeLod
{
    namespace
    {
        /// Per instance: uv4 = position xyz + uniform scale, uv5 = cos, sin of the rotation (Forest.h).
        constexpr std::size_t INSTANCE_FLOATS = 6;
        constexpr std::size_t INSTANCE_BYTES = INSTANCE_FLOATS * sizeof(float);
        static_assert(INSTANCE_BYTES == 24, "the instance layout of Forest.h");
        constexpr std::size_t MIN_INSTANCE_CAPACITY = 16;
        constexpr std::size_t MAX_LEVELS = ForestInstances::MAX_THRESHOLDS + 1;
        constexpr Ogre::Real NO_UPPER = ForestLevelSpan::NO_UPPER;
        constexpr std::uint32_t NO_LEVEL = std::numeric_limits<std::uint32_t>::max();

        [[noreturn]] void invalid(const Ogre::String& text, const char* source)
        {
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, text, source);
        }

        /// The Forest levels of technique `name`; throws "<element>unknown technique ..." or
        /// "<element>technique '...' cannot be a Forest level" from `source`.
        ForestLevelProvider& levelProvider(const Ogre::String& name, const Ogre::String& element, const char* source)
        {
            const TechniqueRegistry& registry = TechniqueRegistry::getSingleton();
            const TechniqueInfo& technique = registry.get(name, element, source);
            if (!technique.forestLevels)
            {
                Ogre::String known;
                for (const TechniqueInfo& t : registry.getTechniques())
                    if (t.forestLevels)
                        known += (known.empty() ? "" : ", ") + t.name;
                invalid(element + "technique '" + name + "' cannot be a Forest level (those that can: " + known + ")",
                        source);
            }
            return *technique.forestLevels;
        }

        /// Radius of the asset's reference sphere: the units of ForestLevel::minPixelCount (Forest.h).
        Ogre::Real referenceRadius(TreeAsset& asset) { return Ogre::Math::boundingRadiusFromAABB(asset.getBounds()); }

        /// Ogre (row-major) to GLM (column-major), in double for the frustum planes.
        glm::dmat4 toGlm(const Ogre::Matrix4& m)
        {
            glm::dmat4 g;
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c)
                    g[c][r] = double(m[r][c]);
            return g;
        }

        using Span = ForestLevelSpan;

        /// The LoD value (reference-sphere units) of `asset` drawn `heightPixels` tall: a tree h
        /// metres tall drawn h_px pixels tall has r_px = h_px * R / h, value = 4 pi r_px^2.
        Ogre::Real valueForHeight(TreeAsset& asset, Ogre::Real heightPixels, const Ogre::String& label,
                                       const char* source)
        {
            const Ogre::AxisAlignedBox bounds = asset.getBounds();
            const Ogre::Real height = bounds.getMaximum().y - bounds.getMinimum().y;
            const Ogre::Real radius = referenceRadius(asset);
            if (!(height > 0.0f) || !(radius > 0.0f))
                invalid(label + "the tree has no height: no screen size to choose levels by", source);
            const double rPx = double(heightPixels) * double(radius) / double(height);
            return Ogre::Real(std::min(4.0 * Ogre::Math::PI * rPx * rPx, double(FLT_MAX)));
        }

        /// Every level of `technique` over all LoD values, near to far (reference-sphere units).
        std::vector<Span> techniqueSpans(TreeAsset& asset, ForestLevelProvider& technique, const Ogre::String& name)
        {
            std::vector<Span> spans = technique.getSpans(asset, name);

            // Bark: split where the drawn mesh's own LoD levels switch (MeshLodGenerator levels,
            // pixel-count values), so that a level's bark level (the one of its largest value,
            // Forest::buildParts) is the one each of its trees would pick alone. The reference,
            // bark and bark-AO meshes share those levels (the generator runs on the bark alone,
            // with the same options: TreeMeshBuilder.h), so the plain bark mesh plans them all.
            Ogre::MeshPtr bark;
            if (technique.drawsBarkMesh() && !asset.getReference().model.barkIndices.empty())
                bark = asset.getBarkMesh();
            if (!bark || bark->getLodStrategy() != Ogre::AbsolutePixelCountLodStrategy::getSingletonPtr())
                return spans;
            std::vector<Span> split;
            for (const Span& span : spans)
            {
                Ogre::Real upper = span.upper;
                for (unsigned short l = 1; l < bark->getNumLodLevels(); ++l)
                {
                    const Ogre::Real value = bark->getLodLevel(l).value;
                    if (value > span.level.minPixelCount && value < upper)
                    {
                        split.push_back(Span{span.level, upper});
                        split.back().level.minPixelCount = value;
                        upper = value;
                    }
                }
                split.push_back(Span{span.level, upper});
            }
            return split;
        }

        /// The asset's error curves, only the levels of Forest::getAutoTechniques (budgeted auto's).
        ErrorCurves autoCurves(TreeAsset& asset, const Ogre::String& label, const char* source)
        {
            if (!asset.hasChunk(ERROR_CURVES_CHUNK))
                invalid(label + "no error curves (bake them: treelod bake, or the bench's cache)", source);
            Result<ErrorCurves> curves = decodeErrorCurves(asset.readChunk(ERROR_CURVES_CHUNK), asset.getName());
            if (!curves)
                invalid(curves.error().message(), source);
            const std::vector<Ogre::String> autoTechniques = Forest::getAutoTechniques();
            std::vector<ErrorCurveLevel> kept;
            for (ErrorCurveLevel& level : curves->levels)
                if (std::find(autoTechniques.begin(), autoTechniques.end(), level.technique) != autoTechniques.end())
                    kept.push_back(std::move(level));
            curves->levels = std::move(kept);
            return std::move(*curves);
        }

        /// The Forest level a curve names, drawn down to `minPixelCount`.
        ForestLevel levelOfCurve(const ErrorCurveLevel& curve, Ogre::Real minPixelCount)
        {
            return ForestLevel{curve.technique, curve.techniqueLevel, curve.lowRes, minPixelCount};
        }

        /// The Forest levels of a selection (LevelSelection.h): its runs' heights as LoD values.
        std::vector<ForestLevel> levelsForChoices(TreeAsset& asset, const ErrorCurves& curves,
                                                  const std::vector<LevelChoice>& choices, const Ogre::String& label,
                                                  const char* source)
        {
            std::vector<ForestLevel> levels;
            for (const LevelChoice& choice : choices)
                levels.push_back(levelOfCurve(
                    curves.levels[choice.curveLevel],
                    choice.minHeightPx > 0.0f ? valueForHeight(asset, choice.minHeightPx, label, source) : 0.0f));
            return levels;
        }

        bool sameDrawable(const ForestLevel& a, const ForestLevel& b)
        {
            return a.technique == b.technique && a.techniqueLevel == b.techniqueLevel && a.lowRes == b.lowRes;
        }

        /// Check `levels` as addSpecies takes them (throws naming `label`, the level and the reason);
        /// `drawn` grows by what they draw outside the asset's box.
        void checkLevels(TreeAsset& asset, const std::vector<ForestLevel>& levels, const Ogre::String& label,
                         const char* source, Ogre::AxisAlignedBox& drawn)
        {
            if (levels.empty() || levels.size() > MAX_LEVELS)
                invalid(label + std::to_string(levels.size()) + " levels (1 to " + std::to_string(MAX_LEVELS) + ")",
                        source);
            for (std::size_t l = 0; l < levels.size(); ++l)
            {
                const ForestLevel& level = levels[l];
                const Ogre::String element = label + "level " + std::to_string(l) + " '" + level.technique + "': ";
                ForestLevelProvider& technique = levelProvider(level.technique, element, source);
                const bool last = l + 1 == levels.size();
                if (!std::isfinite(level.minPixelCount) || level.minPixelCount < 0.0f ||
                    (l > 0 && !(level.minPixelCount < levels[l - 1].minPixelCount)) ||
                    (last && level.minPixelCount != 0.0f))
                    invalid(element + "minPixelCount " + std::to_string(level.minPixelCount) +
                                " (finite, >= 0, below the previous level's, 0 for the last level)",
                            source);
                try
                {
                    technique.checkLevel(asset, level, drawn);
                }
                catch (const Ogre::Exception& e)
                {
                    invalid(element + e.getDescription(), source);
                }
            }
        }

        /// The largest LoD value level `l` of `levels` is drawn at (reference-sphere units).
        Ogre::Real upperValue(const std::vector<ForestLevel>& levels, std::size_t l)
        {
            return l == 0 ? NO_UPPER : levels[l - 1].minPixelCount;
        }

        std::uint64_t textureBytes(const Ogre::Texture& texture)
        {
            std::uint64_t bytes = 0;
            for (std::uint32_t mip = 0; mip <= texture.getNumMipmaps(); ++mip)
                bytes += Ogre::PixelUtil::getMemorySize(std::max<std::uint32_t>(texture.getWidth() >> mip, 1),
                                                        std::max<std::uint32_t>(texture.getHeight() >> mip, 1),
                                                        std::max<std::uint32_t>(texture.getDepth() >> mip, 1),
                                                        texture.getFormat());
            return bytes * texture.getNumFaces();
        }

        /// The INSTANCED variant of vertex program `plain`: "<name>/Instanced", same source and
        /// entry point and target, defines + INSTANCED=1, made once in the plain program's group. A unified program
        /// (materials/TreeLod.program) is varied through the delegate the render system chose.
        Ogre::String instancedProgram(const Ogre::GpuProgramPtr& plain)
        {
            const Ogre::String name = plain->getName() + "/Instanced";
            Ogre::HighLevelGpuProgramManager& programs = Ogre::HighLevelGpuProgramManager::getSingleton();
            if (programs.resourceExists(name, plain->getGroup()))
                return name;
            const Ogre::GpuProgram* source = plain.get();
            if (const auto* unified = dynamic_cast<const Ogre::UnifiedHighLevelGpuProgram*>(source))
                source = unified->_getDelegate().get();
            if (!source)
                OGRE_EXCEPT(Ogre::Exception::ERR_INVALID_STATE,
                            "vertex program '" + plain->getName() + "' has no variant that " +
                                Ogre::Root::getSingleton().getRenderSystem()->getName() + " supports",
                            "Forest");
            Ogre::HighLevelGpuProgramPtr program =
                programs.createProgram(name, plain->getGroup(), source->getLanguage(), Ogre::GPT_VERTEX_PROGRAM);
            program->setSourceFile(source->getSourceFile());
            // HLSL's and Cg's compile parameters (GLSL has none; the rest are the language's defaults).
            for (const char* parameter : {"entry_point", "target", "profiles"})
                if (!source->getParameter(parameter).empty())
                    program->setParameter(parameter, source->getParameter(parameter));
            const Ogre::String defines = source->getParameter("preprocessor_defines");
            program->setParameter("preprocessor_defines", defines.empty() ? "INSTANCED=1" : defines + ",INSTANCED=1");
            program->load();
            if (plain->hasDefaultParameters() && program->isSupported())
                program->getDefaultParameters()->copyMatchingNamedConstantsFrom(*plain->getDefaultParameters());
            return name;
        }
    }

    // ---- parts, batches, per-camera state --------------------------------------------------------

    /// One draw of a level: an index range over the asset's vertices with an instanced material.
    struct Forest::Part
    {
        Ogre::VertexData* vertexData = nullptr; ///< the asset's
        Ogre::IndexData* indexData = nullptr;   ///< the asset's, or &ownIndexData
        Ogre::IndexData ownIndexData;
        Ogre::MaterialPtr material;
        Ogre::MaterialPtr shadowedMaterial; ///< may be null
        unsigned short techniqueLod = 0;    ///< ForestPartOptions::techniqueLod
        float lengthFactor = 0.0f;          ///< ForestPartOptions::lengthFactor (custom parameter 0 when > 0)
        std::map<std::size_t, Ogre::Vector4> customParameters; ///< ForestPartOptions::customParameters
        bool backToFront = false;           ///< ForestPartOptions::backToFront
    };

    /// Where a level's drawables are (Forest.h, "Residency").
    enum class Forest::Residency : std::uint8_t
    {
        Absent,   ///< not built; its trees draw the next resident level
        Queued,   ///< asked for, waiting in mUploadQueue
        Resident, ///< parts built and uploaded
        Failed    ///< building threw (logged); its trees keep drawing the fallback
    };

    /// What a budgeted species is planned from (Forest.h, "Budgeted species").
    struct Forest::BudgetPlan
    {
        ErrorCurves curves;                  ///< the auto techniques' levels
        std::vector<LevelCost> costs;        ///< this machine's
        std::vector<LevelChoice> choices;    ///< the plan in use
        /// Per frameBudgetLadder() step: its plan's cost per tree at each selection sample height.
        std::vector<std::vector<float>> ladderMsPerTree;
        HeightHistogram visible; ///< the viewer's trees at the frame budget's last measurement
    };

    struct Forest::Species
    {
        TreeAssetPtr asset;
        std::vector<ForestLevel> levels;
        std::vector<std::vector<std::unique_ptr<Part>>> parts; ///< per level; empty until resident
        std::vector<Residency> residency;                     ///< per level
        std::vector<std::uint32_t> shadowLevels;              ///< per level: what its shadow casters draw
        std::unique_ptr<BudgetPlan> budget;                   ///< budgeted species only
        /// (kind radius / reference radius)^2: the kind's LoD values per reference-sphere value.
        double kindUnit = 1.0;
        /// Tree height on screen (px) per square root of the kind's LoD value.
        double heightPerRootValue = 0.0;

        /// A level's switch value in the kind's units (Forest.h, "Units").
        float kindValue(Ogre::Real minPixelCount) const
        {
            return float(std::min(double(minPixelCount) * kindUnit, double(FLT_MAX)));
        }
    };

    /// One instanced draw of one camera: a Part with that camera's instance buffer of its bucket.
    class Forest::Batch : public Ogre::Renderable
    {
    public:
        Batch(const Forest& forest, const Part& part) : mForest(forest), mPart(part)
        {
            // The part's declaration and binding (not its buffers), plus the instance source.
            mVertexData = part.vertexData->clone(false);
            Ogre::VertexDeclaration* decl = mVertexData->vertexDeclaration;
            mSource = static_cast<unsigned short>(decl->getMaxSource() + 1);
            decl->addElement(mSource, 0, Ogre::VET_FLOAT4, Ogre::VES_TEXTURE_COORDINATES, 4);
            decl->addElement(mSource, 4 * sizeof(float), Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 5);
            for (const auto& [index, value] : part.customParameters)
                setCustomParameter(index, value);
        }
        ~Batch() override { delete mVertexData; }

        void setInstanceBuffer(const Ogre::HardwareVertexBufferSharedPtr& buffer)
        {
            mVertexData->vertexBufferBinding->setBinding(mSource, buffer);
        }
        const Part& getPart() const { return mPart; }

        std::uint32_t mInstanceCount = 0;
        /// Queued at this squared depth (world units) when >= 0, else at the Forest's node's.
        Ogre::Real mSquaredViewDepth = -1.0f;

        const Ogre::MaterialPtr& getMaterial() const override
        {
            return mPart.shadowedMaterial && mForest.useShadowedMaterials() ? mPart.shadowedMaterial : mPart.material;
        }
        Ogre::Technique* getTechnique() const override
        {
            return getMaterial()->getBestTechnique(mPart.techniqueLod, this);
        }
        void getRenderOperation(Ogre::RenderOperation& op) override
        {
            op.operationType = Ogre::RenderOperation::OT_TRIANGLE_LIST;
            op.useIndexes = true;
            op.vertexData = mVertexData;
            op.indexData = mPart.indexData;
            op.numberOfInstances = mInstanceCount;
            op.srcRenderable = this;
        }
        void getWorldTransforms(Ogre::Matrix4* xform) const override
        {
            *xform = mForest._getParentNodeFullTransform();
        }
        Ogre::Real getSquaredViewDepth(const Ogre::Camera* camera) const override
        {
            if (mSquaredViewDepth >= 0.0f)
                return mSquaredViewDepth;
            return mForest.getParentNode() ? mForest.getParentNode()->getSquaredViewDepth(camera) : 0.0f;
        }
        const Ogre::LightList& getLights() const override { return mForest.queryLights(); }
        bool getCastsShadows() const override { return mForest.getCastShadows(); }

    private:
        const Forest& mForest;
        const Part& mPart;
        Ogre::VertexData* mVertexData = nullptr;
        unsigned short mSource = 0;
    };

    struct Forest::BucketState
    {
        Ogre::HardwareVertexBufferSharedPtr buffer;
        std::size_t capacity = 0; ///< instances
        std::uint32_t drawnLevel = NO_LEVEL; ///< the level whose parts `batches` draw
        std::vector<std::unique_ptr<Batch>> batches; ///< one per part of the drawn level
        bool backToFront = false; ///< a part of the drawn level blends (ForestPartOptions::backToFront)
        /// Squared distance (local) of the farthest instance of the last fill when backToFront.
        float farthestSquared = 0.0f;
    };

    struct Forest::CameraState
    {
        ForestVisibility visibility;
        CullCamera camera;  ///< planes of this frame; LoD data kept while the LoD is frozen
        float lodBias = 1.0f;
        bool hasLod = false;
        std::vector<std::unique_ptr<BucketState>> buckets; ///< by ForestInstances bucket index
        glm::vec3 eye{0.0f};  ///< this camera's position in the Forest's local space
        std::vector<std::pair<float, std::uint32_t>> depthOrder; ///< scratch of back-to-front fills
    };

    /// Clears the viewer's stats before each visibility pass of a viewport (not of shadow textures).
    class Forest::ViewerListener : public Ogre::SceneManager::Listener
    {
    public:
        explicit ViewerListener(Forest& forest) : mForest(forest) {}
        void preFindVisibleObjects(Ogre::SceneManager*, Ogre::SceneManager::IlluminationRenderStage stage,
                                   Ogre::Viewport*) override
        {
            if (stage != Ogre::SceneManager::IRS_RENDER_TO_TEXTURE)
                mForest.clearFrameStats();
        }

    private:
        Forest& mForest;
    };

    /// Drops a camera's state when the camera is destroyed (Forest.h, "Per-camera state").
    class Forest::CameraListener : public Ogre::Camera::Listener
    {
    public:
        explicit CameraListener(Forest& forest) : mForest(forest) {}
        void cameraDestroyed(Ogre::Camera* camera) override { mForest.dropCamera(camera); }

    private:
        Forest& mForest;
    };

    // ---- Forest ----------------------------------------------------------------------------------

    const Ogre::String ForestFactory::FACTORY_TYPE_NAME = "Forest";

    Forest::Forest(const Ogre::String& name) : Ogre::MovableObject(name)
    {
        static std::atomic<std::uint32_t> serial{0};
        mMaterialPrefix = "TreeLod/Forest" + std::to_string(serial++) + "/";
        mBounds.setNull();
        mCameraListener = std::make_unique<CameraListener>(*this);
    }

    Forest::~Forest()
    {
        if (mManager && mViewerListener)
            mManager->removeListener(mViewerListener.get());
        for (const auto& camera : mCameras)
            camera.first->removeListener(mCameraListener.get());
        mCameras.clear();
        mSpecies.clear();
        if (Ogre::MaterialManager* materials = Ogre::MaterialManager::getSingletonPtr())
            for (const auto& entry : mInstancedMaterials)
                materials->remove(entry.second);
    }

    const Ogre::String& Forest::getMovableType() const { return ForestFactory::FACTORY_TYPE_NAME; }

    std::vector<ForestBand> Forest::getAutoBands()
    {
        return {ForestBand{"lodf", 160.0f}, ForestBand{"billboard-cloud", 24.0f}, ForestBand{FLOOR_TECHNIQUE, 0.0f}};
    }

    std::vector<ForestLevel> Forest::getCandidateLevels(TreeAsset& asset, const std::vector<Ogre::String>& techniques)
    {
        std::vector<ForestLevel> levels;
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
        {
            if (!info.forestLevels || !asset.hasChunk(info.chunkTechnique) ||
                (!techniques.empty() && std::find(techniques.begin(), techniques.end(), info.name) == techniques.end()))
                continue;
            for (const Span& span : info.forestLevels->getSpans(asset, info.name))
            {
                ForestLevel level = span.level;
                level.minPixelCount = 0.0f;
                const bool seen = std::any_of(levels.begin(), levels.end(), [&](const ForestLevel& l) {
                    return l.technique == level.technique && l.techniqueLevel == level.techniqueLevel &&
                           l.lowRes == level.lowRes;
                });
                if (!seen)
                    levels.push_back(level);
            }
        }
        return levels;
    }

    Ogre::String Forest::describeLevel(const ForestLevel& level)
    {
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(level.technique);
        return info && info->forestLevels ? info->forestLevels->describeLevel(level) : level.technique;
    }

    Ogre::Real Forest::pixelCountForHeight(TreeAsset& asset, Ogre::Real heightPixels)
    {
        return valueForHeight(asset, heightPixels, "asset '" + asset.getName() + "': ",
                                            "Forest::pixelCountForHeight");
    }

    Ogre::Real Forest::heightForPixelCount(TreeAsset& asset, Ogre::Real pixelCount)
    {
        const Ogre::Real perPixel = valueForHeight(asset, 1.0f, "asset '" + asset.getName() + "': ",
                                                        "Forest::heightForPixelCount");
        return std::sqrt(std::max(pixelCount, 0.0f) / perPixel);
    }

    std::vector<Ogre::String> Forest::getAutoTechniques()
    {
        return {REFERENCE_TECHNIQUE, "lodf", "billboard-cloud", "classic-billboard-cloud", "ellipsoids",
                "octahedral-impostor", FLOOR_TECHNIQUE};
    }

    std::vector<ForestLevel> Forest::levelsForErrorBudget(TreeAsset& asset, const std::vector<LevelCost>& costs,
                                                          float errorBudget)
    {
        const char* source = "Forest::levelsForErrorBudget";
        const Ogre::String label = "asset '" + asset.getName() + "': ";
        const ErrorCurves curves = autoCurves(asset, label, source);
        Result<std::vector<LevelChoice>> choices = chooseLevels(curves, costs, errorBudget, MAX_LEVELS);
        if (!choices)
            invalid(label + choices.error().message(), source);
        return levelsForChoices(asset, curves, *choices, label, source);
    }

    std::vector<ForestLevel> Forest::levelsForBands(TreeAsset& asset, const std::vector<ForestBand>& bands)
    {
        const char* source = "Forest::levelsForBands";
        const Ogre::String label = "asset '" + asset.getName() + "': ";
        if (bands.empty())
            invalid(label + "no technique bands", source);
        valueForHeight(asset, 1.0f, label, source); // a tree without height has no screen size: refused here
        auto pixelCount = [&](Ogre::Real heightPixels) { return valueForHeight(asset, heightPixels, label, source); };

        std::vector<ForestLevel> levels;
        Ogre::Real upper = NO_UPPER;
        Ogre::Real previousHeight = std::numeric_limits<Ogre::Real>::infinity();
        for (std::size_t b = 0; b < bands.size(); ++b)
        {
            const ForestBand& band = bands[b];
            const Ogre::String element = label + "band " + std::to_string(b) + " '" + band.technique + "': ";
            ForestLevelProvider& technique = levelProvider(band.technique, element, source);
            const bool last = b + 1 == bands.size();
            if (last && band.minHeightPixels != 0.0f)
                invalid(element + "the last band must reach 0 pixels, not " + std::to_string(band.minHeightPixels),
                        source);
            if (!last && !(std::isfinite(band.minHeightPixels) && band.minHeightPixels > 0.0f &&
                           band.minHeightPixels < previousHeight))
                invalid(element + "minHeightPixels " + std::to_string(band.minHeightPixels) +
                            " is not finite, > 0 and below the previous band's",
                        source);
            previousHeight = band.minHeightPixels;
            const Ogre::Real lower = last ? 0.0f : pixelCount(band.minHeightPixels);
            std::vector<Span> spans;
            try
            {
                spans = techniqueSpans(asset, technique, band.technique);
            }
            catch (const Ogre::Exception& e)
            {
                invalid(element + e.getDescription(), source);
            }
            if (spans.empty())
                invalid(element + "the asset has nothing this technique draws (a tree baked from photographs has "
                                  "volume-octree levels only)",
                        source);
            // The technique's levels clipped to the band's values [lower, upper).
            for (const Span& span : spans)
                if (span.level.minPixelCount < upper && span.upper > lower)
                {
                    levels.push_back(span.level);
                    levels.back().minPixelCount = std::max(span.level.minPixelCount, lower);
                }
            upper = lower;
        }
        if (levels.size() > MAX_LEVELS)
            invalid(label + "the bands give " + std::to_string(levels.size()) + " levels (at most " +
                        std::to_string(MAX_LEVELS) + ")",
                    source);
        return levels;
    }

    Ogre::MaterialPtr Forest::instancedMaterial(const Ogre::String& name, const Ogre::String& group)
    {
        auto found = mInstancedMaterials.find(name);
        if (found != mInstancedMaterials.end())
            return found->second;
        Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(name, group);
        if (!material)
            OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "material '" + name + "' not found",
                        "Forest '" + mName + "'");
        material->load();
        Ogre::MaterialPtr clone = material->clone(mMaterialPrefix + name, true, material->getGroup());
        for (Ogre::Technique* technique : clone->getTechniques())
        {
            for (Ogre::Pass* pass : technique->getPasses())
            {
                if (!pass->hasVertexProgram())
                    OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                                "material '" + name + "' technique '" + technique->getName() + "' pass '" +
                                    pass->getName() + "' has no vertex program to draw instanced",
                                "Forest '" + mName + "'");
                const Ogre::GpuProgramParametersSharedPtr plain = pass->getVertexProgramParameters();
                pass->setVertexProgram(instancedProgram(pass->getVertexProgram()), true);
                pass->getVertexProgramParameters()->copyMatchingNamedConstantsFrom(*plain);
            }
            if (Ogre::MaterialPtr caster = technique->getShadowCasterMaterial())
                technique->setShadowCasterMaterial(instancedMaterial(caster->getName(), caster->getGroup()));
        }
        clone->compile();
        clone->load();
        mInstancedMaterials.emplace(name, clone);
        return clone;
    }

    /// The ForestPartBuilder a level's provider adds its parts through.
    class Forest::PartBuilder : public ForestPartBuilder
    {
    public:
        PartBuilder(Forest& forest, TreeAsset& asset, Ogre::Real upperPixelCount)
            : mForest(forest), mAsset(asset), mUpperPixelCount(upperPixelCount)
        {
        }

        void addRange(Ogre::VertexData* vertices, const Ogre::HardwareIndexBufferSharedPtr& buffer, std::size_t start,
                      std::size_t count, const Ogre::String& material, const Ogre::String& shadowed,
                      const ForestPartOptions& options) override
        {
            if (count == 0 || !vertices)
                return;
            Part& part = add(vertices, material, shadowed, options);
            part.ownIndexData.indexBuffer = buffer;
            part.ownIndexData.indexStart = start;
            part.ownIndexData.indexCount = count;
            part.indexData = &part.ownIndexData;
        }

        void addMesh(const Ogre::MeshPtr& mesh, const std::vector<Ogre::String>& plain,
                     const std::vector<Ogre::String>& shadowed) override
        {
            // The submeshes at the LoD level the mesh's strategy gives for the level's largest value.
            const unsigned short lod = mUpperPixelCount == NO_UPPER ? 0 : mesh->getLodIndex(mUpperPixelCount);
            for (Ogre::SubMesh* sub : mesh->getSubMeshes())
            {
                Ogre::IndexData* indices =
                    lod == 0 || sub->mLodFaceList.empty()
                        ? sub->indexData
                        : sub->mLodFaceList[std::min<std::size_t>(lod, sub->mLodFaceList.size()) - 1];
                if (indices->indexCount == 0)
                    continue;
                const auto it = std::find(plain.begin(), plain.end(), sub->getMaterialName());
                const Ogre::String receiver = it == plain.end() ? "" : shadowed[std::size_t(it - plain.begin())];
                add(sub->vertexData, sub->getMaterialName(), receiver, {}).indexData = indices;
            }
        }

        std::vector<std::unique_ptr<Part>> mParts;

    private:
        Part& add(Ogre::VertexData* vertices, const Ogre::String& material, const Ogre::String& shadowed,
                  const ForestPartOptions& options)
        {
            const Ogre::String& group = mAsset.getGroup();
            auto part = std::make_unique<Part>();
            part->vertexData = vertices;
            part->techniqueLod = options.techniqueLod;
            part->lengthFactor = options.lengthFactor;
            part->customParameters = options.customParameters;
            part->backToFront = options.backToFront;
            if (options.instancedMaterial)
            {
                for (auto [name, slot] : {std::make_pair(&material, &part->material),
                                          std::make_pair(&shadowed, &part->shadowedMaterial)})
                {
                    if (name->empty())
                        continue;
                    // The asset's own (cloned per asset), else a shared one wherever it is.
                    *slot = Ogre::MaterialManager::getSingleton().getByName(*name, group);
                    if (!*slot)
                        *slot = Ogre::MaterialManager::getSingleton().getByName(*name, Ogre::RGN_AUTODETECT);
                    if (!*slot)
                        OGRE_EXCEPT(Ogre::Exception::ERR_ITEM_NOT_FOUND, "material '" + *name + "' not found",
                                    "Forest '" + mForest.mName + "'");
                    (*slot)->load();
                }
            }
            else
            {
                part->material = mForest.instancedMaterial(material, group);
                if (!shadowed.empty())
                    part->shadowedMaterial = mForest.instancedMaterial(shadowed, group);
            }
            mParts.push_back(std::move(part));
            return *mParts.back();
        }

        Forest& mForest;
        TreeAsset& mAsset;
        const Ogre::Real mUpperPixelCount;
    };

    std::vector<std::unique_ptr<Forest::Part>> Forest::buildParts(TreeAsset& asset, const ForestLevel& level,
                                                                  Ogre::Real upperPixelCount)
    {
        PartBuilder builder(*this, asset, upperPixelCount);
        levelProvider(level.technique, "", "Forest").buildParts(asset, level, builder);
        return std::move(builder.mParts);
    }

    std::uint32_t Forest::addSpecies(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels)
    {
        return addSpeciesImpl(asset, levels, nullptr);
    }

    std::uint32_t Forest::addBudgetedSpecies(const TreeAssetPtr& asset, const std::vector<LevelCost>& costs)
    {
        const char* source = "Forest::addBudgetedSpecies";
        const Ogre::String label = speciesLabel(std::uint32_t(mSpecies.size()), asset.get());
        if (!asset)
            invalid(label + "no asset", source);
        auto plan = std::make_unique<BudgetPlan>();
        plan->curves = autoCurves(*asset, label, source);
        plan->costs = costs;
        for (const float step : frameBudgetLadder())
        {
            Result<std::vector<LevelChoice>> choices = chooseLevels(plan->curves, costs, step, MAX_LEVELS);
            if (!choices)
                invalid(label + choices.error().message(), source);
            plan->ladderMsPerTree.push_back(planCostPerTree(plan->curves, costs, *choices));
        }
        Result<std::vector<LevelChoice>> choices = chooseLevels(plan->curves, costs, mErrorBudget, MAX_LEVELS);
        if (!choices)
            invalid(label + choices.error().message(), source);
        plan->choices = *choices;
        const std::vector<ForestLevel> levels = levelsForChoices(*asset, plan->curves, plan->choices, label, source);
        return addSpeciesImpl(asset, levels, std::move(plan));
    }

    std::uint32_t Forest::addSpeciesImpl(const TreeAssetPtr& asset, const std::vector<ForestLevel>& levels,
                                         std::unique_ptr<BudgetPlan> budget)
    {
        const char* source = "Forest::addSpecies";
        const Ogre::String label = speciesLabel(std::uint32_t(mSpecies.size()), asset.get());
        if (!asset)
            invalid(label + "no asset", source);
        // Planned from decoded chunks only (nothing uploaded but the bark mesh levelsForBands
        // plans with); each level's drawables are built when its trees first need them.
        Ogre::AxisAlignedBox drawn = asset->getBounds();
        checkLevels(*asset, levels, label, source, drawn);
        if (budget)
        {
            // The kind's sphere holds every level a budget may choose: re-plans keep it.
            for (const ErrorCurveLevel& c : budget->curves.levels)
                if (findLevelCost(budget->costs, c.technique, c.techniqueLevel, c.lowRes) >= 0)
                {
                    Ogre::AxisAlignedBox box = asset->getBounds();
                    checkLevels(*asset, {levelOfCurve(c, 0.0f)}, label + "candidate ", source, box);
                    drawn.merge(box);
                }
        }
        auto species = std::make_unique<Species>();
        species->asset = asset;
        species->levels = levels;
        species->parts.resize(levels.size());
        species->residency.assign(levels.size(), Residency::Absent);
        species->budget = std::move(budget);
        try
        {
            // The last level is the fallback of every other: resident from the start.
            species->parts.back() = buildParts(*asset, levels.back(), upperValue(levels, levels.size() - 1));
            species->residency.back() = Residency::Resident;
        }
        catch (const Ogre::Exception& e)
        {
            invalid(label + "level " + std::to_string(levels.size() - 1) + " '" + levels.back().technique +
                        "': " + e.getDescription(),
                    source);
        }

        // The kind: a tight sphere about what is drawn; thresholds in its units (Forest.h).
        const Ogre::Real referenceR = referenceRadius(*asset);
        const Ogre::Vector3 centre = drawn.getCenter();
        const Ogre::Real radius = std::max(0.5f * drawn.getSize().length(), 1e-6f);
        if (!(referenceR > 0.0f))
            invalid(label + "the tree has no extent", source);
        const double unit = double(radius) * double(radius) / (double(referenceR) * double(referenceR));
        const Ogre::AxisAlignedBox bounds = asset->getBounds();
        const double height = double(bounds.getMaximum().y - bounds.getMinimum().y);
        // valueForHeight inverted: value = 4 pi (h_px R / height)^2 in reference units, x unit here.
        species->kindUnit = unit;
        species->heightPerRootValue = height / (double(referenceR) * std::sqrt(4.0 * Ogre::Math::PI * unit));
        ForestKind kind;
        kind.name = asset->getName() + " species " + std::to_string(mSpecies.size());
        kind.boundsCentre = glm::vec3(centre.x, centre.y, centre.z);
        kind.boundsRadius = radius;
        kind.thresholds = kindThresholds(*species, levels);
        Result<std::uint32_t> added = mInstances.addKind(kind);
        if (!added)
            invalid(label + added.error().message(), source);
        OgreAssert(added.value() == mSpecies.size(), "kinds and species share indices");
        mSpecies.push_back(std::move(species));
        mStats.levelCounts.emplace_back(levels.size(), 0u);
        updateShadowLevels(added.value());
        return added.value();
    }

    Ogre::String Forest::speciesLabel(std::uint32_t species, const TreeAsset* asset) const
    {
        return "Forest '" + mName + "' species " + std::to_string(species) + " ('" +
               (asset ? asset->getName() : Ogre::String("null")) + "'): ";
    }

    bool Forest::isBudgeted(std::uint32_t species) const { return mSpecies.at(species)->budget != nullptr; }

    const std::vector<std::uint32_t>& Forest::getShadowLevels(std::uint32_t species) const
    {
        return mSpecies.at(species)->shadowLevels;
    }

    void Forest::updateShadowLevels(std::uint32_t s)
    {
        Species& species = *mSpecies[s];
        species.shadowLevels.resize(species.levels.size());
        for (std::uint32_t l = 0; l < species.shadowLevels.size(); ++l)
            species.shadowLevels[l] = l;
        if (!species.budget)
            return;
        const BudgetPlan& plan = *species.budget;
        Result<std::vector<std::size_t>> shadow =
            chooseShadowLevels(plan.curves, plan.costs, plan.choices, mShadowErrorBudget);
        if (shadow && shadow->size() == species.levels.size())
            for (std::size_t l = 0; l < shadow->size(); ++l)
                species.shadowLevels[l] = std::uint32_t((*shadow)[l]);
    }

    void Forest::replan(std::uint32_t s, const std::vector<LevelChoice>& choices)
    {
        const char* source = "Forest::replan";
        Species& species = *mSpecies[s];
        BudgetPlan& plan = *species.budget;
        TreeAsset& asset = *species.asset;
        const Ogre::String label = speciesLabel(s, &asset);
        const std::vector<ForestLevel> levels = levelsForChoices(asset, plan.curves, choices, label, source);
        const bool same = levels.size() == species.levels.size() &&
                          std::equal(levels.begin(), levels.end(), species.levels.begin(),
                                     [](const ForestLevel& a, const ForestLevel& b) {
                                         return sameDrawable(a, b) && a.minPixelCount == b.minPixelCount;
                                     });
        if (same)
        {
            plan.choices = choices;
            updateShadowLevels(s);
            return;
        }
        Ogre::AxisAlignedBox drawn = asset.getBounds();
        checkLevels(asset, levels, label, source, drawn);

        // Parts: the last level first (its failure changes nothing); then kept, rebuilt or absent.
        const std::size_t count = levels.size();
        std::vector<std::vector<std::unique_ptr<Part>>> parts(count);
        std::vector<Residency> residency(count, Residency::Absent);
        std::vector<bool> moved(species.levels.size(), false);
        // An old resident level drawing what level l draws: with the same switch value and parts not
        // taken yet (they are kept), or any (its drawables are uploaded).
        auto findOld = [&](std::size_t l, bool sameUpper) -> int {
            for (std::size_t k = 0; k < species.levels.size(); ++k)
                if (!(sameUpper && moved[k]) && species.residency[k] == Residency::Resident &&
                    sameDrawable(species.levels[k], levels[l]) &&
                    (!sameUpper || upperValue(species.levels, k) == upperValue(levels, l)))
                    return int(k);
            return -1;
        };
        if (findOld(count - 1, true) < 0)
        {
            try
            {
                parts[count - 1] = buildParts(asset, levels[count - 1], upperValue(levels, count - 1));
            }
            catch (const Ogre::Exception& e)
            {
                invalid(label + "level " + std::to_string(count - 1) + " '" + levels[count - 1].technique +
                            "': " + e.getDescription() + " (the levels stay as they were)",
                        source);
            }
            residency[count - 1] = Residency::Resident;
        }
        for (std::size_t l = 0; l < count; ++l)
        {
            if (residency[l] == Residency::Resident)
                continue;
            if (const int k = findOld(l, true); k >= 0)
            {
                parts[l] = std::move(species.parts[std::size_t(k)]);
                moved[std::size_t(k)] = true;
                residency[l] = Residency::Resident;
            }
            else if (findOld(l, false) >= 0)
            {
                // Its drawables are uploaded: the parts at the new switch value cost no upload.
                try
                {
                    parts[l] = buildParts(asset, levels[l], upperValue(levels, l));
                    residency[l] = Residency::Resident;
                }
                catch (const Ogre::Exception&)
                {
                    residency[l] = Residency::Absent; // built on demand, where a failure is logged
                }
            }
        }

        // The kind's table; each camera's buckets of this species reset (their batches draw the
        // old parts), the buckets of later species moved with their indices.
        const std::uint32_t first = mInstances.getBucketIndex(s, 0);
        const std::size_t oldCount = species.levels.size();
        if (Result<void> set = mInstances.setKindThresholds(s, kindThresholds(species, levels)); !set)
            invalid(label + set.error().message(), source);
        for (auto& [camera, state] : mCameras)
        {
            std::vector<std::unique_ptr<BucketState>>& buckets = state->buckets;
            if (buckets.size() <= first)
                continue; // has not seen this species yet
            const std::size_t end = std::min(buckets.size(), first + oldCount);
            std::vector<std::unique_ptr<BucketState>> slots;
            for (std::size_t b = first; b < end; ++b)
                slots.push_back(std::move(buckets[b]));
            for (std::unique_ptr<BucketState>& slot : slots)
            {
                slot->batches.clear();
                slot->drawnLevel = NO_LEVEL;
            }
            while (slots.size() > count)
            {
                mInstanceBufferBytes -= slots.back()->capacity * INSTANCE_BYTES;
                slots.pop_back();
            }
            while (slots.size() < count)
                slots.push_back(std::make_unique<BucketState>());
            buckets.erase(buckets.begin() + std::ptrdiff_t(first), buckets.begin() + std::ptrdiff_t(end));
            buckets.insert(buckets.begin() + std::ptrdiff_t(first), std::make_move_iterator(slots.begin()),
                           std::make_move_iterator(slots.end()));
        }
        mUploadQueue.erase(std::remove_if(mUploadQueue.begin(), mUploadQueue.end(),
                                          [s](const auto& entry) { return entry.first == s; }),
                           mUploadQueue.end());
        species.levels = levels;
        species.parts = std::move(parts);
        species.residency = std::move(residency);
        plan.choices = choices;
        mStats.levelCounts[s].assign(count, 0u);
        mStats.instanceBufferBytes = mInstanceBufferBytes;
        updateShadowLevels(s);
    }

    void Forest::applyErrorBudget(float budget)
    {
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
        {
            Species& species = *mSpecies[s];
            if (!species.budget)
                continue;
            Result<std::vector<LevelChoice>> choices =
                chooseLevels(species.budget->curves, species.budget->costs, budget, MAX_LEVELS);
            if (!choices)
                invalid("Forest '" + mName + "' species " + std::to_string(s) + ": " + choices.error().message(),
                        "Forest::setErrorBudget");
            replan(s, *choices);
        }
        mErrorBudget = budget;
    }

    void Forest::setErrorBudget(float budget)
    {
        if (!(std::isfinite(budget) && budget >= 0.0f && budget <= 1.0f))
            invalid("Forest '" + mName + "': error budget " + std::to_string(budget) + " is not a number in [0, 1]",
                    "Forest::setErrorBudget");
        applyErrorBudget(budget);
        mUserErrorBudget = budget;
        mFrameBudgetStep = mWantedBudgetStep = ladderStepOf(budget);
    }

    std::size_t Forest::ladderStepOf(float budget)
    {
        const std::vector<float>& ladder = frameBudgetLadder();
        const auto step = std::find(ladder.begin(), ladder.end(), budget);
        return step == ladder.end() ? OFF_LADDER : std::size_t(step - ladder.begin());
    }

    void Forest::setShadowErrorBudget(float budget)
    {
        if (!(std::isfinite(budget) && budget >= 0.0f && budget <= 1.0f))
            invalid("Forest '" + mName + "': shadow error budget " + std::to_string(budget) +
                        " is not a number in [0, 1]",
                    "Forest::setShadowErrorBudget");
        mShadowErrorBudget = budget;
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            updateShadowLevels(s);
    }

    void Forest::setFrameBudgetMs(float milliseconds)
    {
        if (!(std::isfinite(milliseconds) && milliseconds >= 0.0f))
            invalid("Forest '" + mName + "': frame budget " + std::to_string(milliseconds) +
                        " ms is not finite and >= 0 (0: none)",
                    "Forest::setFrameBudgetMs");
        const bool off = milliseconds == 0.0f && mFrameBudgetMs > 0.0f;
        mFrameBudgetMs = milliseconds;
        mFrameBudgetStep = mWantedBudgetStep = ladderStepOf(mErrorBudget);
        mFrameBudgetFrames = 0;
        mStats.predictedMilliseconds = 0.0;
        mFrameTimeRatio = 1.0;
        mReportedMs = 0.0;
        mReportedFrames = 0;
        mPlanPredictedMs = 0.0;
        if (off)
            setErrorBudget(mUserErrorBudget);
    }

    void Forest::measureFrameBudget(const CameraState& state)
    {
        // Every visible tree of a budgeted species, counted at its height on screen.
        bool anyBudgeted = false;
        for (const std::unique_ptr<Species>& species : mSpecies)
            if (species->budget)
            {
                species->budget->visible.clear();
                anyBudgeted = true;
            }
        if (!anyBudgeted)
            return; // nothing to plan: the error budget stays
        const ForestVisibility& visibility = state.visibility;
        for (std::uint32_t b = 0; b < visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = visibility.getBucket(b);
            Species& species = *mSpecies[bucket.kind];
            if (!species.budget || bucket.count == 0)
                continue;
            const std::uint32_t* indices = visibility.getBucketIndices(b);
            for (std::uint32_t i = 0; i < bucket.count; ++i)
            {
                const float value = mInstances.lodValue(indices[i], state.camera, state.lodBias);
                species.budget->visible.add(float(species.heightPerRootValue * std::sqrt(double(value))));
            }
        }
        const std::size_t steps = frameBudgetLadder().size();
        std::vector<double> predicted(steps, 0.0);
        for (const std::unique_ptr<Species>& species : mSpecies)
            if (species->budget)
                for (std::size_t step = 0; step < steps; ++step)
                    predicted[step] += species->budget->visible.milliseconds(species->budget->ladderMsPerTree[step]);
        // Reported frame times since the last measurement against what was predicted for their plan:
        // the running ratio, within [0.1, 10]; it rises at once (frames over the model go coarser
        // in the next plan) and falls a quarter of the way to each lower ratio (finer slowly).
        if (mReportedFrames > 0 && mPlanPredictedMs > 0.0)
        {
            const double ratio = std::clamp(mReportedMs / mReportedFrames / mPlanPredictedMs, 0.1, 10.0);
            mFrameTimeRatio = ratio > mFrameTimeRatio ? ratio : mFrameTimeRatio + 0.25 * (ratio - mFrameTimeRatio);
        }
        mReportedMs = 0.0;
        mReportedFrames = 0;
        for (double& ms : predicted)
            ms *= mFrameTimeRatio;
        mStats.predictedMilliseconds = predicted[std::min(mFrameBudgetStep, steps - 1)];
        mWantedBudgetStep = chooseFrameBudgetStep(predicted, double(mFrameBudgetMs), mFrameBudgetStep);
        mPlanPredictedMs = predicted[mWantedBudgetStep] / mFrameTimeRatio;
    }

    void Forest::notifyFrameTime(float milliseconds)
    {
        if (mFrameBudgetMs > 0.0f && std::isfinite(milliseconds) && milliseconds > 0.0f)
        {
            mReportedMs += double(milliseconds);
            ++mReportedFrames;
        }
    }

    std::uint32_t Forest::getSpeciesCount() const { return std::uint32_t(mSpecies.size()); }
    const std::vector<ForestLevel>& Forest::getLevels(std::uint32_t species) const
    {
        return mSpecies.at(species)->levels;
    }
    const TreeAssetPtr& Forest::getAsset(std::uint32_t species) const { return mSpecies.at(species)->asset; }

    std::vector<ForestHandle> Forest::addInstances(const std::vector<ForestInstance>& instances)
    {
        // Added along a Z-order curve so that culling skips whole blocks (ForestInstances.h); the
        // handles come back in the caller's order, and errors name the caller's index.
        if (Result<void> valid = mInstances.validate(instances); !valid)
            invalid("Forest '" + mName + "': " + valid.error().message(), "Forest::addInstances");
        const std::vector<std::uint32_t> order = ForestInstances::spatialOrder(instances);
        std::vector<ForestInstance> sorted(instances.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            sorted[i] = instances[order[i]];
        Result<std::vector<ForestHandle>> handles = mInstances.add(sorted);
        if (!handles)
            invalid("Forest '" + mName + "': " + handles.error().message(), "Forest::addInstances");
        std::vector<ForestHandle> out(instances.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            out[order[i]] = (*handles)[i];
        updateBounds();
        return out;
    }

    void Forest::updateBounds()
    {
        glm::vec3 lo(FLT_MAX), hi(-FLT_MAX);
        for (std::size_t i = 0; i < mInstances.size(); ++i)
        {
            const glm::vec4 sphere = mInstances.getWorldSphere(i);
            lo = glm::min(lo, glm::vec3(sphere) - sphere.w);
            hi = glm::max(hi, glm::vec3(sphere) + sphere.w);
        }
        if (mInstances.size() == 0)
            mBounds.setNull();
        else
            mBounds.setExtents(lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        mRadius = mBounds.isNull() ? 0.0f : Ogre::Math::boundingRadiusFromAABB(mBounds);
        if (mParentNode)
            mParentNode->needUpdate();
    }

    std::vector<float> Forest::kindThresholds(const Species& species, const std::vector<ForestLevel>& levels) const
    {
        // Level l is drawn while the value is at least thresholds[l]: setMeshLodBias's limits make
        // the levels finer than maxDetailIndex unreachable and stop at minDetailIndex.
        std::vector<float> thresholds;
        for (std::size_t l = 0; l + 1 < levels.size(); ++l)
            thresholds.push_back(l < mLodBias.maxMeshIndex    ? FLT_MAX
                                 : l >= mLodBias.minMeshIndex ? 0.0f
                                                              : species.kindValue(levels[l].minPixelCount));
        return thresholds;
    }

    void Forest::setMeshLodBias(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)
    {
        const bool limits = maxDetailIndex != mLodBias.maxMeshIndex || minDetailIndex != mLodBias.minMeshIndex;
        mLodBias.setMesh(factor, maxDetailIndex, minDetailIndex, "Forest '" + mName + "'");
        if (!limits)
            return;
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            if (Result<void> set = mInstances.setKindThresholds(s, kindThresholds(*mSpecies[s], mSpecies[s]->levels));
                !set)
                invalid("Forest '" + mName + "': " + set.error().message(), "Forest::setMeshLodBias");
    }

    void Forest::setLodBias(Ogre::Real bias)
    {
        setMeshLodBias(bias, mLodBias.maxMeshIndex, mLodBias.minMeshIndex);
    }

    void Forest::setLodHysteresis(Ogre::Real hysteresis)
    {
        if (!(hysteresis >= 0.0f && hysteresis <= 1.0f))
            invalid("Forest '" + mName + "': LoD hysteresis " + std::to_string(hysteresis) + " is not in [0, 1]",
                    "Forest::setLodHysteresis");
        mLodHysteresis = hysteresis;
    }

    void Forest::setShadowLodBias(Ogre::Real bias)
    {
        if (!std::isfinite(bias) || !(bias > 0.0f))
            invalid("Forest '" + mName + "': shadow LoD bias " + std::to_string(bias) + " is not finite and > 0",
                    "Forest::setShadowLodBias");
        mShadowLodBias = bias;
    }

    void Forest::setLodFrozen(bool frozen) { mLodFrozen = frozen; }

    bool Forest::useShadowedMaterials() const
    {
        return receivesDepthShadows(mManager);
    }

    std::uint64_t Forest::getGpuBytes() const { return drawableBytes() + mInstanceBufferBytes; }

    std::uint64_t Forest::drawableBytes() const
    {
        std::set<const void*> seen;
        std::uint64_t bytes = 0;
        auto once = [&](const void* what, std::uint64_t size) {
            if (what && seen.insert(what).second)
                bytes += size;
        };
        for (const std::unique_ptr<Species>& species : mSpecies)
            for (const auto& level : species->parts)
                for (const std::unique_ptr<Part>& part : level)
                {
                    for (const auto& binding : part->vertexData->vertexBufferBinding->getBindings())
                        once(binding.second.get(), binding.second->getSizeInBytes());
                    once(part->indexData->indexBuffer.get(), part->indexData->indexBuffer->getSizeInBytes());
                    for (const Ogre::MaterialPtr* material : {&part->material, &part->shadowedMaterial})
                        if (*material)
                            for (Ogre::Technique* technique : (*material)->getTechniques())
                                for (Ogre::Pass* pass : technique->getPasses())
                                    for (Ogre::TextureUnitState* unit : pass->getTextureUnitStates())
                                        if (unit->getContentType() == Ogre::TextureUnitState::CONTENT_NAMED)
                                            if (const Ogre::TexturePtr& texture = unit->_getTexturePtr())
                                                once(texture.get(), textureBytes(*texture));
                }
        return bytes;
    }

    // ---- residency (Forest.h) ---------------------------------------------------------------------

    void Forest::setUploadBudget(std::uint64_t bytesPerFrame) { mUploadBudget = bytesPerFrame; }

    bool Forest::isResident(std::uint32_t species, std::uint32_t level) const
    {
        return mSpecies.at(species)->residency.at(level) == Residency::Resident;
    }

    std::uint32_t Forest::getDrawnLevel(std::uint32_t species, std::uint32_t level) const
    {
        // The nearest resident level, coarser first: the last level always is (addSpecies).
        const std::vector<Residency>& residency = mSpecies.at(species)->residency;
        for (std::size_t l = level; l < residency.size(); ++l)
            if (residency[l] == Residency::Resident)
                return std::uint32_t(l);
        for (std::size_t l = std::min<std::size_t>(level, residency.size()); l-- > 0;)
            if (residency[l] == Residency::Resident)
                return std::uint32_t(l);
        return level;
    }

    std::uint64_t Forest::makeResident(std::uint32_t s, std::uint32_t l)
    {
        Species& species = *mSpecies[s];
        if (species.residency[l] == Residency::Resident || species.residency[l] == Residency::Failed)
            return 0;
        const std::uint64_t before = drawableBytes();
        try
        {
            species.parts[l] =
                buildParts(*species.asset, species.levels[l], l == 0 ? NO_UPPER : species.levels[l - 1].minPixelCount);
            species.residency[l] = Residency::Resident;
        }
        catch (const Ogre::Exception& e)
        {
            // Not fatal mid-frame: the level's trees keep drawing their fallback.
            species.parts[l].clear();
            species.residency[l] = Residency::Failed;
            Ogre::LogManager::getSingleton().logError(
                "Forest '" + mName + "' species " + std::to_string(s) + " level " + std::to_string(l) + " '" +
                species.levels[l].technique + "': " + e.getDescription() + " (its trees draw level " +
                std::to_string(getDrawnLevel(s, l)) + ")");
        }
        return drawableBytes() - before;
    }

    void Forest::makeAllResident()
    {
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            for (std::uint32_t l = 0; l < mSpecies[s]->levels.size(); ++l)
                makeResident(s, l);
        mUploadQueue.clear();
        mStats.pendingLevels = 0;
    }

    unsigned long Forest::currentFrame()
    {
        return Ogre::Root::getSingletonPtr() ? Ogre::Root::getSingleton().getNextFrameNumber() : 0;
    }

    void Forest::serviceUploads()
    {
        const unsigned long frame = currentFrame();
        if (frame != mUploadFrame)
        {
            mUploadFrame = frame;
            mStats.uploadedBytes = 0;
            mStats.uploadedLevels = 0;
        }
        // In the order asked for, until this frame's bytes reach the budget (a level larger than
        // the whole budget goes alone in its frame: a level is not split).
        while (!mUploadQueue.empty() && (mUploadBudget == 0 || mStats.uploadedBytes < mUploadBudget))
        {
            const auto [s, l] = mUploadQueue.front();
            mUploadQueue.pop_front();
            mStats.uploadedBytes += makeResident(s, l);
            ++mStats.uploadedLevels;
        }
        mStats.pendingLevels = std::uint32_t(mUploadQueue.size());
    }

    void Forest::_notifyManager(Ogre::SceneManager* manager)
    {
        if (mManager && mViewerListener)
            mManager->removeListener(mViewerListener.get());
        Ogre::MovableObject::_notifyManager(manager);
        if (!mViewerListener)
            mViewerListener = std::make_unique<ViewerListener>(*this);
        if (mManager)
            mManager->addListener(mViewerListener.get());
    }

    void Forest::clearFrameStats()
    {
        if (currentFrame() != mUploadFrame)
        {
            mStats.uploadedBytes = 0;
            mStats.uploadedLevels = 0;
        }
        mStats.fallbackInstances = 0;
        mStats.instances = std::uint32_t(mInstances.size());
        mStats.visibleInstances = 0;
        mStats.batches = 0;
        mStats.triangles = 0;
        mStats.cullMilliseconds = 0.0;
        for (std::vector<std::uint32_t>& counts : mStats.levelCounts)
            std::fill(counts.begin(), counts.end(), 0u);
    }

    void Forest::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        mCurrentCamera = camera;
    }

    void Forest::fillBucket(CameraState& state, std::uint32_t b, std::uint32_t level)
    {
        const ForestBucket& bucket = state.visibility.getBucket(b);
        BucketState& slot = *state.buckets[b];
        const std::uint32_t drawn = getDrawnLevel(bucket.kind, level);
        if (slot.drawnLevel != drawn)
        {
            // First use, or the bucket's own level (or a nearer fallback) became resident.
            slot.batches.clear();
            for (const std::unique_ptr<Part>& part : mSpecies[bucket.kind]->parts[drawn])
            {
                slot.batches.push_back(std::make_unique<Batch>(*this, *part));
                if (slot.buffer)
                    slot.batches.back()->setInstanceBuffer(slot.buffer);
            }
            slot.drawnLevel = drawn;
            slot.backToFront = std::any_of(mSpecies[bucket.kind]->parts[drawn].begin(),
                                           mSpecies[bucket.kind]->parts[drawn].end(),
                                           [](const std::unique_ptr<Part>& part) { return part->backToFront; });
        }
        if (bucket.count > slot.capacity)
        {
            // Grown by doubling, never shrunk: steady frames allocate nothing.
            const std::size_t capacity =
                std::max({std::size_t(bucket.count), 2 * slot.capacity, MIN_INSTANCE_CAPACITY});
            slot.buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                INSTANCE_BYTES, capacity, Ogre::HardwareBuffer::HBU_DYNAMIC_WRITE_ONLY_DISCARDABLE);
            slot.buffer->setIsInstanceData(true);
            slot.buffer->setInstanceDataStepRate(1);
            mInstanceBufferBytes += (capacity - slot.capacity) * INSTANCE_BYTES;
            slot.capacity = capacity;
            for (const std::unique_ptr<Batch>& batch : slot.batches)
                batch->setInstanceBuffer(slot.buffer);
        }
        // The cull's rows [R*s | t] (ForestInstances.h): t, s = m11, cos = m00 / s, sin = m02 / s.
        const float* transforms = state.visibility.getBucketTransforms(b);
        constexpr std::size_t STRIDE = ForestVisibility::TRANSFORM_FLOATS;
        if (slot.backToFront)
        {
            // Far to near: instances of one draw rasterise in order, so the blending is right
            // between the bucket's trees.
            state.depthOrder.clear();
            for (std::uint32_t i = 0; i < bucket.count; ++i)
            {
                const float* m = transforms + i * STRIDE;
                const glm::vec3 d = glm::vec3(m[3], m[7], m[11]) - state.eye;
                state.depthOrder.emplace_back(glm::dot(d, d), i);
            }
            std::sort(state.depthOrder.begin(), state.depthOrder.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
            slot.farthestSquared = state.depthOrder.empty() ? 0.0f : state.depthOrder.front().first;
        }
        float* out = static_cast<float*>(
            slot.buffer->lock(0, std::size_t(bucket.count) * INSTANCE_BYTES, Ogre::HardwareBuffer::HBL_DISCARD));
        for (std::uint32_t i = 0; i < bucket.count; ++i, out += INSTANCE_FLOATS)
        {
            const float* m = transforms + (slot.backToFront ? state.depthOrder[i].second : i) * STRIDE;
            const float scale = m[5], inverse = 1.0f / scale;
            out[0] = m[3];
            out[1] = m[7];
            out[2] = m[11];
            out[3] = scale;
            out[4] = m[0] * inverse;
            out[5] = m[2] * inverse;
        }
        slot.buffer->unlock();
    }

    void Forest::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        Ogre::Camera* camera = mCurrentCamera;
        if (!camera || mSpecies.empty())
            return;
        const bool shadowTexture =
            mManager && mManager->_getCurrentRenderStage() == Ogre::SceneManager::IRS_RENDER_TO_TEXTURE;
        const bool viewer = camera->getLodCamera() == camera && !shadowTexture;
        if (viewer && mFrameBudgetMs > 0.0f && mWantedBudgetStep != mFrameBudgetStep &&
            mWantedBudgetStep != OFF_LADDER)
        {
            // The frame budget's choice of the last measurement, before this camera culls.
            try
            {
                applyErrorBudget(frameBudgetLadder()[mWantedBudgetStep]);
                mFrameBudgetStep = mWantedBudgetStep;
            }
            catch (const Ogre::Exception& e)
            {
                Ogre::LogManager::getSingleton().logError(e.getDescription());
                mWantedBudgetStep = mFrameBudgetStep;
            }
        }
        std::unique_ptr<CameraState>& entry = mCameras[camera];
        if (!entry)
        {
            entry = std::make_unique<CameraState>();
            camera->addListener(mCameraListener.get());
        }
        CameraState& state = *entry;
        while (state.buckets.size() < mInstances.getBucketCount()) // species added since
            state.buckets.push_back(std::make_unique<BucketState>());

        // Culling: this camera's frustum in the Forest's local space (instances are local).
        const Ogre::Affine3& world = _getParentNodeFullTransform();
        state.camera.planes = CullCamera::frustumPlanes(toGlm(camera->getProjectionMatrix()) *
                                                        toGlm(camera->getViewMatrix()) * toGlm(world));
        // LoD: the LoD camera (the viewer's, for shadow cameras), unless frozen.
        if (!mLodFrozen || !state.hasLod)
        {
            const Ogre::Camera* lod = camera->getLodCamera();
            const Ogre::Vector3 eye = world.inverse() * lod->getDerivedPosition();
            state.camera.lodPosition = glm::vec3(eye.x, eye.y, eye.z);
            state.camera.lodPixelScale = ScreenSizeLodStrategy::pixelScale(*lod); // treelod_screen_size's
            state.camera.lodOrthographic = lod->getProjectionType() == Ogre::PT_ORTHOGRAPHIC;
            state.lodBias = lod->getLodBias() * mLodBias.meshFactor * (shadowTexture ? mShadowLodBias : 1.0f);
            state.hasLod = true;
        }
        const Ogre::Vector3 eye = world.inverse() * camera->getDerivedPosition();
        state.eye = glm::vec3(eye.x, eye.y, eye.z);

        const auto start = std::chrono::steady_clock::now();
        const Result<void> culled = mInstances.cull(state.camera, state.lodBias, state.visibility, mLodHysteresis);
        const double cullMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (!culled)
        {
            Ogre::LogManager::getSingleton().logError("Forest '" + mName + "': " + culled.error().message());
            return;
        }
        if (viewer && mFrameBudgetMs > 0.0f && !mLodFrozen && mFrameBudgetFrames++ % FRAME_BUDGET_INTERVAL == 0)
            measureFrameBudget(state);

        // The level each bucket draws: shadow casters their species' shadow level.
        auto wantedLevel = [&](const ForestBucket& bucket) {
            return shadowTexture ? mSpecies[bucket.kind]->shadowLevels[bucket.level] : bucket.level;
        };

        // Residency: ask for the levels this camera needs, then build within this frame's budget;
        // until built, a level's trees draw the nearest resident level (getDrawnLevel).
        for (std::uint32_t b = 0; b < state.visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = state.visibility.getBucket(b);
            const std::uint32_t level = wantedLevel(bucket);
            Residency& residency = mSpecies[bucket.kind]->residency[level];
            if (bucket.count > 0 && residency == Residency::Absent)
            {
                residency = Residency::Queued;
                mUploadQueue.emplace_back(bucket.kind, level);
            }
        }
        serviceUploads();

        std::uint32_t batches = 0;
        std::uint64_t triangles = 0;
        std::uint32_t fallbacks = 0;
        const Ogre::Vector4 lengthParams(0.0f, 1.0f, 0.0f, 0.0f);
        for (std::uint32_t b = 0; b < state.visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = state.visibility.getBucket(b);
            if (viewer)
                mStats.levelCounts[bucket.kind][bucket.level] = bucket.count;
            if (bucket.count == 0)
                continue;
            fillBucket(state, b, wantedLevel(bucket));
            if (state.buckets[b]->drawnLevel != wantedLevel(bucket))
                fallbacks += bucket.count;
            for (const std::unique_ptr<Batch>& batch : state.buckets[b]->batches)
            {
                batch->mInstanceCount = bucket.count;
                if (batch->getPart().lengthFactor > 0.0f)
                {
                    // x: the length factor, the bias applied to lengths; y: 1 (ForestLevelProvider.h).
                    Ogre::Vector4 params = lengthParams;
                    params.x = batch->getPart().lengthFactor * std::sqrt(state.lodBias);
                    batch->setCustomParameter(0, params);
                }
                // Blending draws queue at their farthest tree's depth (world units: times the
                // node's scale squared), so that Ogre sorts them back to front among transparents.
                batch->mSquaredViewDepth =
                    batch->getPart().backToFront
                        ? state.buckets[b]->farthestSquared *
                              (mParentNode ? mParentNode->_getDerivedScale().squaredLength() / 3.0f : 1.0f)
                        : -1.0f;
                queue->addRenderable(batch.get(), mRenderQueueID, mRenderQueuePriority);
                ++batches;
                triangles += std::uint64_t(batch->getPart().indexData->indexCount / 3) * bucket.count;
            }
        }
        if (viewer)
        {
            mStats.instances = std::uint32_t(mInstances.size());
            mStats.visibleInstances = state.visibility.getVisibleCount();
            mStats.batches = batches;
            mStats.triangles = triangles;
            mStats.cullMilliseconds = cullMs;
            mStats.fallbackInstances = fallbacks;
        }
        mStats.instanceBufferBytes = mInstanceBufferBytes;
    }

    void Forest::dropCamera(Ogre::Camera* camera)
    {
        const auto found = mCameras.find(camera);
        if (found == mCameras.end())
            return;
        for (const std::unique_ptr<BucketState>& bucket : found->second->buckets)
            mInstanceBufferBytes -= bucket->capacity * INSTANCE_BYTES;
        mStats.instanceBufferBytes = mInstanceBufferBytes;
        if (mCurrentCamera == camera)
            mCurrentCamera = nullptr;
        mCameras.erase(found);
    }

    void Forest::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (const auto& camera : mCameras)
            for (const std::unique_ptr<BucketState>& bucket : camera.second->buckets)
                for (const std::unique_ptr<Batch>& batch : bucket->batches)
                    visitor->visit(batch.get(), 0, false);
    }

    Ogre::MovableObject* ForestFactory::createInstanceImpl(const Ogre::String& name,
                                                           const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "ForestFactory::createInstanceImpl");
        double bias = 1.0;
        p.number("lodBias", 1e-6, 1e6, bias);
        auto forest = std::make_unique<Forest>(name);
        forest->setLodBias(Ogre::Real(bias));
        return forest.release();
    }
}
