// ForestDetail: what the Forest's source files share (Forest.cpp: the object, its species and
// instances; ForestLevelPlan.cpp: levels, budgets and shadow levels; ForestInstancing.cpp: instanced
// materials and parts; ForestResidency.cpp: GPU residency and uploads; ForestRenderQueue.cpp: the
// per-camera cull and queue). Private to the plugin.
#pragma once

#include "TreeLod/Forest.h"

#include "TreeLod/ErrorCurves.h"
#include "TreeLod/LevelSelection.h"
#include "TreeLod/ObjectParams.h"
#include "TreeLod/ObjectTransition.h"
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
    namespace ForestDetail
    {
        /// Per draw of a tree: uv4 = position xyz + uniform scale, uv5 = cos, sin of the rotation and
        /// the transition code (Forest.h, TreeLodInstance.glsl).
        constexpr std::size_t INSTANCE_FLOATS = 7;
        constexpr std::size_t INSTANCE_BYTES = INSTANCE_FLOATS * sizeof(float);
        static_assert(INSTANCE_BYTES == 28, "the instance layout of Forest.h");
        constexpr std::size_t MIN_INSTANCE_CAPACITY = 16;
        constexpr std::size_t MAX_LEVELS = ForestInstances::MAX_THRESHOLDS + 1;
        constexpr Ogre::Real NO_UPPER = ForestLevelSpan::NO_UPPER;
        constexpr std::uint32_t NO_LEVEL = std::numeric_limits<std::uint32_t>::max();

        [[noreturn]] inline void invalid(const Ogre::String& text, const char* source)
        {
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, text, source);
        }

        /// The Forest levels of technique `name`; throws "<element>unknown technique ..." or
        /// "<element>technique '...' cannot be a Forest level" from `source`.
        inline ForestLevelProvider& levelProvider(const Ogre::String& name, const Ogre::String& element, const char* source)
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
        inline Ogre::Real referenceRadius(TreeAsset& asset) { return Ogre::Math::boundingRadiusFromAABB(asset.getBounds()); }

        /// Ogre (row-major) to GLM (column-major), in double for the frustum planes.
        inline glm::dmat4 toGlm(const Ogre::Matrix4& m)
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
        inline Ogre::Real valueForHeight(TreeAsset& asset, Ogre::Real heightPixels, const Ogre::String& label,
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
        inline std::vector<Span> techniqueSpans(TreeAsset& asset, ForestLevelProvider& technique, const Ogre::String& name)
        {
            std::vector<Span> spans = technique.getSpans(asset, name);

            // Bark: split where the drawn mesh's own LoD levels switch (MeshLodGenerator levels,
            // pixel-count values), so that a level's bark level (the one of its largest value,
            // Forest::buildParts) is the one each of its trees would pick alone. The reference,
            // bark and bark-AO meshes share those levels (the generator runs on the bark alone,
            // with the same options: TreeMeshBuilder.h), so the one the technique draws plans them.
            Ogre::MeshPtr bark;
            if (technique.drawsBarkMesh() && !asset.getReference().model.barkIndices.empty())
                bark = technique.getBarkMesh(asset);
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
        inline ErrorCurves autoCurves(TreeAsset& asset, const Ogre::String& label, const char* source)
        {
            if (!asset.hasChunk(ERROR_CURVES_CHUNK))
                invalid(label + "no error curves (bake them: treelod bake, or the bench's cache)", source);
            Result<ErrorCurves> curves = decodeErrorCurves(asset.readChunk(ERROR_CURVES_CHUNK), asset.getName(),
                                                          asset.getChunkFormatVersion(ERROR_CURVES_CHUNK));
            if (!curves)
                invalid(curves.error().message(), source);
            const std::vector<Ogre::String> autoTechniques = Forest::getAutoTechniques();
            std::vector<bool> keep;
            for (const ErrorCurveLevel& level : curves->levels)
                keep.push_back(std::find(autoTechniques.begin(), autoTechniques.end(), level.technique) !=
                               autoTechniques.end());
            curves->keepLevels(keep);
            return std::move(*curves);
        }

        /// The Forest level a curve names, drawn down to `minPixelCount`.
        inline ForestLevel levelOfCurve(const ErrorCurveLevel& curve, Ogre::Real minPixelCount)
        {
            return ForestLevel{curve.technique, curve.techniqueLevel, curve.lowRes, minPixelCount};
        }

        /// The Forest levels of a selection (LevelSelection.h): its runs' heights as LoD values.
        inline std::vector<ForestLevel> levelsForChoices(TreeAsset& asset, const ErrorCurves& curves,
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

        inline bool sameDrawable(const ForestLevel& a, const ForestLevel& b)
        {
            return a.technique == b.technique && a.techniqueLevel == b.techniqueLevel && a.lowRes == b.lowRes;
        }

        /// Check `levels` as addSpecies takes them (throws naming `label`, the level and the reason);
        /// `drawn` grows by what they draw outside the asset's box.
        inline void checkLevels(TreeAsset& asset, const std::vector<ForestLevel>& levels, const Ogre::String& label,
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
        inline Ogre::Real upperValue(const std::vector<ForestLevel>& levels, std::size_t l)
        {
            return l == 0 ? NO_UPPER : levels[l - 1].minPixelCount;
        }

        inline std::uint64_t textureBytes(const Ogre::Texture& texture)
        {
            std::uint64_t bytes = 0;
            for (std::uint32_t mip = 0; mip <= texture.getNumMipmaps(); ++mip)
                bytes += Ogre::PixelUtil::getMemorySize(std::max<std::uint32_t>(texture.getWidth() >> mip, 1),
                                                        std::max<std::uint32_t>(texture.getHeight() >> mip, 1),
                                                        std::max<std::uint32_t>(texture.getDepth() >> mip, 1),
                                                        texture.getFormat());
            return bytes * texture.getNumFaces();
        }

        /// The INSTANCED variant of vertex program `plain`: "<name>/Instanced", same source, entry
        /// point and target, defines + INSTANCED=1, the same default and shared parameters, made
        /// once in the plain program's group. A unified program (materials/TreeLod.program) is
        /// varied through the delegate the render system chose.
        inline Ogre::String instancedProgram(const Ogre::GpuProgramPtr& plain)
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
            {
                const Ogre::GpuProgramParametersSharedPtr& defaults = plain->getDefaultParameters();
                program->getDefaultParameters()->copyMatchingNamedConstantsFrom(*defaults);
                for (const Ogre::GpuSharedParametersUsage& shared : defaults->getSharedParameters())
                    program->getDefaultParameters()->addSharedParameters(shared.getName());
            }
            return name;
        }
    }

    using namespace ForestDetail; // the Forest's own sources only: this header is private

    // ---- parts, batches, per-camera state --------------------------------------------------------

    /// One draw of a level: an index range over the asset's vertices with an instanced material.
    struct Forest::Part
    {
        Ogre::VertexData* vertexData = nullptr; ///< the asset's
        Ogre::IndexData* indexData = nullptr;   ///< the asset's, or &ownIndexData
        Ogre::IndexData ownIndexData;
        Ogre::MaterialPtr material;
        Ogre::MaterialPtr shadowedMaterial; ///< may be null
        /// The mesh a submesh part draws from (ForestPartBuilder::addMesh): it holds all of its LoD
        /// levels' index buffers on the GPU, whichever one the part draws. Null for ranges.
        Ogre::MeshPtr mesh;
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
        float errorBudget = 0.0f;            ///< the error budget `choices` were planned for
        /// Per curve level: taken out by the memory budget (Forest::setMemoryBudget); empty: none.
        std::vector<bool> excluded;
        /// Per frameBudgetLadder() step: its plan (costed at each measurement, with the transition then).
        std::vector<std::vector<LevelChoice>> ladderChoices;
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
        bool occlusionMaskMade = false; ///< Forest::makeOcclusionMasks
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
            decl->addElement(mSource, 4 * sizeof(float), Ogre::VET_FLOAT3, Ogre::VES_TEXTURE_COORDINATES, 5);
            ObjectTransition::apply(*this, 0.0f, Ogre::Vector3::ZERO); // the code comes per instance
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
}
