// ForestLevelProvider: how a technique draws its levels in a Forest (Forest.h). A technique that
// can be a Forest level registers one with its TechniqueInfo (TechniqueRegistry.h); the Forest
// plans, checks and builds levels through it and never names a technique.
//
// Units: LoD values are Ogre's absolute pixel count (4 pi r_px^2) of the asset's reference
// sphere (Forest.h, "Units"). A level's parts are drawn instanced: the Forest clones each part's
// material with every vertex program swapped for its INSTANCED variant (Forest.h, "Materials"),
// unless the part says its material reads the instance data already.
#pragma once

#include <OgreAxisAlignedBox.h>
#include <OgreHardwareIndexBuffer.h>
#include <OgreMesh.h>
#include <OgreVector.h>

#include <cstdint>
#include <limits>
#include <map>
#include <vector>

namespace Ogre
{
    class VertexData;
}

namespace TreeLod
{
    class TreeAsset;

    /// One level of a species: what its trees draw while their LoD value is >= minPixelCount.
    struct ForestLevel
    {
        Ogre::String technique;            ///< a registered technique with a ForestLevelProvider
        std::uint32_t techniqueLevel = 0;  ///< the technique's own level (its README says what it
                                           ///< counts; one-level techniques: 0)
        bool lowRes = false;               ///< the level's second material technique (a low-res
                                           ///< material of the same level, where one is baked)
        Ogre::Real minPixelCount = 0.0f;   ///< Ogre pixel-count units; the last level's is 0
    };

    /// A technique over a band of screen sizes, near to far (scene scripts' "techniques").
    struct ForestBand
    {
        Ogre::String technique;
        /// The band draws trees whose height on screen is >= this many pixels (at LoD bias 1);
        /// the last band's is 0.
        Ogre::Real minHeightPixels = 0.0f;
    };

    /// A technique's level with the LoD values it is drawn at: [level.minPixelCount, upper).
    struct ForestLevelSpan
    {
        static constexpr Ogre::Real NO_UPPER = std::numeric_limits<Ogre::Real>::max();
        ForestLevel level;
        Ogre::Real upper = NO_UPPER;
    };

    /// How one part of a level is drawn.
    struct ForestPartOptions
    {
        unsigned short techniqueLod = 0; ///< the material technique's LoD index to draw
        /// The material's vertex programs read the Forest's instance data already (uv4, uv5;
        /// Forest.h): used as it is, not cloned.
        bool instancedMaterial = false;
        /// > 0: custom parameter 0 of the part is (lengthFactor * sqrt(camera LoD bias), 1, 0, 0),
        /// a screen-length factor that follows the LoD bias (billboard clouds' list factor).
        float lengthFactor = 0.0f;
        /// Custom parameters set on every draw of the part (index -> value); index 0 is the length
        /// factor's when lengthFactor > 0.
        std::map<std::size_t, Ogre::Vector4> customParameters;
        /// The part blends: each draw lists its trees far to near from the camera (instances are
        /// drawn in order), and the Forest queues it at the depth of its farthest tree.
        bool backToFront = false;
    };

    /// What a provider adds a level's parts through (implemented by the Forest).
    class ForestPartBuilder
    {
    public:
        virtual ~ForestPartBuilder() = default;
        /// `count` indices of `buffer` from `start` over `vertices` (the asset's, alive as long as the
        /// asset); nothing when count is 0 or vertices null. `shadowed` ("" for none) receives
        /// integrated texture shadows.
        virtual void addRange(Ogre::VertexData* vertices, const Ogre::HardwareIndexBufferSharedPtr& buffer,
                              std::size_t start, std::size_t count, const Ogre::String& material,
                              const Ogre::String& shadowed, const ForestPartOptions& options = {}) = 0;
        /// Every non-empty submesh of `mesh` at the LoD level its strategy gives for the level's
        /// largest value; a submesh whose material is plain[i] receives shadows with shadowed[i].
        virtual void addMesh(const Ogre::MeshPtr& mesh, const std::vector<Ogre::String>& plain,
                             const std::vector<Ogre::String>& shadowed) = 0;
    };

    class ForestLevelProvider
    {
    public:
        virtual ~ForestLevelProvider() = default;
        /// Every level of `technique` (the registered name) for `asset` over all LoD values, near to
        /// far, from decoded data (uploading at most the bark mesh); empty when the asset has the
        /// technique's chunk but nothing it can draw (a reference without polygons). Throws
        /// Ogre::InvalidParametersException naming what the asset lacks.
        virtual std::vector<ForestLevelSpan> getSpans(TreeAsset& asset, const Ogre::String& technique) = 0;
        /// Whether the levels draw the asset's bark mesh (or a mesh with its LoD levels): the Forest
        /// then splits spans where the bark mesh's LoD switches (Forest.h, "Bark").
        virtual bool drawsBarkMesh() const { return true; }
        /// The bark mesh the levels draw (where drawsBarkMesh): its LoD levels split the spans. By
        /// default the asset's plain bark mesh (TreeAsset::getBarkMesh); a technique that draws its
        /// own copy returns that one, so that planning uploads no mesh its levels do not draw.
        virtual Ogre::MeshPtr getBarkMesh(TreeAsset& asset);
        /// Check `level` when a species is added, from decoded data only; throw
        /// Ogre::InvalidParametersException with the reason. Merge into `drawnBounds` (local metres)
        /// what the level draws outside the reference's box.
        virtual void checkLevel(TreeAsset& asset, const ForestLevel& level, Ogre::AxisAlignedBox& drawnBounds) = 0;
        /// Build what `level` draws (uploading the asset's resources on first use).
        virtual void buildParts(TreeAsset& asset, const ForestLevel& level, ForestPartBuilder& parts) = 0;
        /// A few words naming `level` for people ("<technique> 1200", "<technique> 1 low"); by default the
        /// technique's name.
        virtual Ogre::String describeLevel(const ForestLevel& level) const { return level.technique; }
        /// Whether a switch from `finer` to `coarser` (one of this technique's levels) is one step of
        /// a continuous simplification, whose pop is small: the Forest switches it hard, also with
        /// transitions (a cross-fade of two nearly equal levels is pixel noise). By default only
        /// the same drawable again (bark LoD splits, Forest.h "Bark").
        virtual bool isContinuousStep(const ForestLevel& finer, const ForestLevel& coarser) const
        {
            return finer.technique == coarser.technique && finer.techniqueLevel == coarser.techniqueLevel &&
                   finer.lowRes == coarser.lowRes;
        }
    };
}
