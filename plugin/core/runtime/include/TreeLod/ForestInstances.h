// ForestInstances: the Forest's packed instance data (docs/forest.md), and its per-frame
// culling and level-of-detail selection in one tight loop, without Ogre.
//
// Storage is structure-of-arrays: per instance its position, scale * (cos, sin) of its rotation
// about +Y and kind (16 bits), 30 bytes with the handle maps, plus a box per block of 256
// instances (at most 32 B per instance); scale,
// rotation and the world bounding sphere are derived from them (get() returns the rotation in
// (-pi, pi] and both to float rounding). A kind is one (asset, technique) pair with its local
// bounding sphere and LoD table.
// Each frame `cull` tests every instance's world bounding sphere against the six frustum
// planes, picks the visible ones' level from their kind's table, and counting-sorts them into
// buckets (kind, level) with one packed 3x4 world matrix per instance, ready to be copied into
// an instance vertex buffer (Ogre's hardware instancing reads three float4 rows). Within a
// bucket, instances come near first: counting-sorted by distance class (ForestVisibility::
// DISTANCE_CLASSES), so a bucket drawn in order lets the depth test reject
// what nearer trees hide before the fragment shader runs, alpha-tested levels included (their
// depth test can still come first; only the write waits for the alpha test).
//
// LoD value (the units of Ogre's AbsolutePixelCountLodStrategy, as in BillboardCloudTree):
//   perspective:  value = pi * R^2 * (W * H * P00 * P11) / d^2 * bias
//   orthographic: value = pi * R^2 * (W * H * P00 * P11) * bias
// R = local radius * scale, W x H the LoD camera's viewport in pixels, P00, P11 its
// projection's diagonal, d the distance from the LoD camera to the instance's position (its
// origin, as Ogre's Node::getSquaredViewDepth). For a sphere seen at distance d the projected
// radius is r_px = R * P11 * H / (2 d) (and R * P00 * W / (2 d) across), so value = 4 pi r_px^2:
// four times the projected disc's area in pixels. An orthographic projection has P00 = 2 / w,
// P11 = 2 / h for a view window w x h, which gives the same units (4 pi r_px^2). At d^2 <=
// FLT_EPSILON the value is FLT_MAX (Ogre's base value: finest level).
// Distance tables instead compare d^2 / bias (DistanceLodStrategy's squared distance).
//
// Transitions (cull's `transition` t > 0): a tree whose screen size s is within (1, 1 + t) times
// that of its level's switch to the next coarser one is drawn at both levels, by complementary
// screen-door masks: the coarse one keeps the fraction f = (1 + t - s) / t of the pixels, the fine
// one the rest (ForestVisibility::getTransitionCodes; LevelTransition.h; TreeLodTransition.glsl
// draws the masks). Screen size grows as the
// square root of the pixel value and falls as the distance, so s = sqrt(value / threshold) or
// sqrt(threshold / d^2) for distance tables. A band takes at most the lower half of its level's
// own range of s (in ratio), so bands never meet and each level is drawn whole somewhere.
//
// Occlusion (a CullCamera with `occlusion` set; ForestOcclusion.h): the visible instances, near
// first, are added to the camera's OcclusionGrid with their kind's mask, which gives the share v of
// each that the trees in front leave visible, estimated and conservative. An instance whose
// conservative share is below OCCLUSION_HIDDEN is not drawn (getOccludedCount). Its kind's occlusionHeightScales (s_c for v = 2^-c, LevelSelection.h's
// occlusionHeightScale; 1 for none) scale its screen size before its level is picked: s
// interpolated in log2 between the classes (so that v moving smoothly moves no level by a jump),
// its value times s^2 (a distance table: its squared distance over s^2).
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/ForestOcclusion.h"
#include "TreeLod/LevelTransition.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace TreeLod
{
    /// How a kind's LoD table is read.
    enum class ForestLodMode : std::uint8_t
    {
        PixelCount, ///< thresholds in decreasing order; level i while value >= thresholds[i]
        Distance    ///< squared metres, increasing; level i while d^2 / bias <= thresholds[i]
    };

    /// One (asset, technique) pair: what the Forest draws with one instanced batch per level.
    struct ForestKind
    {
        std::string name;                  ///< for errors and stats, e.g. "oak.treelod/<technique>"
        glm::vec3 boundsCentre{0.0f};      ///< local bounding sphere (metres, unscaled)
        float boundsRadius = 1.0f;         ///< > 0
        ForestLodMode lodMode = ForestLodMode::PixelCount;
        /// Level switch values; the kind has thresholds.size() + 1 levels (the last one may be a
        /// camera-facing quad; the Ogre side decides what a level draws). Finite, >= 0, at most
        /// MAX_THRESHOLDS, non-increasing (PixelCount) or non-decreasing (Distance).
        std::vector<float> thresholds;
        /// Bit i: threshold i switches hard, also while cull draws transitions.
        std::uint16_t hardSwitches = 0;
        /// The tree's silhouette, for occlusion (the file comment); null: it hides nothing.
        std::shared_ptr<const OcclusionMask> occlusionMask;
        /// Screen-size factor per visibility class (the file comment): finite, in (0, 1]; all 1: the
        /// levels do not depend on what is hidden (hidden instances are still not drawn).
        std::array<float, OCCLUSION_CLASSES> occlusionHeightScales{1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    };

    /// One tree. Rotation in radians about +Y (right-handed), uniform scale > 0.
    struct ForestInstance
    {
        glm::vec3 position{0.0f};
        float rotationY = 0.0f;
        float scale = 1.0f;
        std::uint32_t kind = 0;
    };

    /// Stable name of an instance: valid from add to remove. Ids of removed instances are reused.
    using ForestHandle = std::uint32_t;

    /// The camera `cull` sees: the frustum that culls and the LoD camera that picks levels. They
    /// differ for shadow cameras (Ogre: cull with the light's camera, pick levels with
    /// Camera::getLodCamera()), so the Ogre side may overwrite `planes` from its own frustum.
    struct CullCamera
    {
        /// World-space planes (normal xyz, unit length, pointing inside; offset w): a point p is
        /// inside where dot(n, p) + w >= 0. Order: left, right, bottom, top, near, far. A plane
        /// with a zero normal (an infinite far plane) passes everything when w >= 0.
        std::array<glm::vec4, 6> planes{};
        glm::vec3 lodPosition{0.0f};  ///< LoD camera position, world space
        float lodPixelScale = 0.0f;   ///< W * H * P00 * P11 of the LoD camera (pixels)
        bool lodOrthographic = false; ///< value does not fall with distance
        /// Occlusion (the file comment): the culling camera's world-to-clip matrix and its
        /// projection's P00, P11 (times the scale from the instances' space to the view's, where
        /// the world matrix scales) place each tree's square on its OcclusionGrid. Off by default
        /// (fromMatrices fills the matrices, not the flag); shadow cameras keep it off: what the
        /// viewer does not see still casts shadows it sees.
        bool occlusion = false;
        glm::mat4 viewProjection{1.0f};
        glm::vec2 projectionScale{1.0f};
        float viewportHeight = 0.0f; ///< pixels (OCCLUSION_MIN_OCCLUDER_PX)

        /// Planes of an OpenGL-convention clip space (clip = viewProjection * world, inside where
        /// -w <= x, y, z <= w), normalised (Gribb & Hartmann's extraction, in double). The far
        /// plane is the difference of two nearly equal rows: a product taken in float moves it by
        /// decimetres at 8 km, so fromMatrices multiplies in double.
        static std::array<glm::vec4, 6> frustumPlanes(const glm::dmat4& viewProjection);

        /// Culling and LoD from one camera: view and projection as GLM (column-major, OpenGL
        /// clip), viewport in pixels. Orthographic when projection[3][3] != 0.
        static CullCamera fromMatrices(const glm::mat4& view, const glm::mat4& projection, float viewportWidth,
                                       float viewportHeight);

        /// From a CameraSpec (aspect = width / height).
        static CullCamera fromSpec(const CameraSpec& spec, float viewportWidth, float viewportHeight);
    };

    /// Instances of one (kind, level), in ForestVisibility's packed arrays at [first, first + count).
    struct ForestBucket
    {
        std::uint32_t kind = 0;
        std::uint32_t level = 0;
        std::uint32_t first = 0;
        std::uint32_t count = 0;
    };

    /// What `cull` produced. Reuse one per camera: its arrays only grow, so `cull` allocates only
    /// when the instance, bucket or visible count exceeds that of every earlier frame.
    class ForestVisibility
    {
    public:
        static constexpr std::size_t TRANSFORM_FLOATS = 12; ///< 3x4 world matrix, row-major
        /// Near-first order within a bucket: classes of the squared distance, 4 per octave (its
        /// float exponent and top two mantissa bits: a class spans at most 12 % of its distance),
        /// the first up to 1 m, the last from 2^32 m; instances of one class keep their input order.
        static constexpr int DISTANCE_CLASSES = 256;

        /// One bucket per (kind, level), kind-major, including empty ones.
        const std::vector<ForestBucket>& getBuckets() const { return mBuckets; }
        std::size_t getBucketCount() const { return mBuckets.size(); }
        const ForestBucket& getBucket(std::size_t bucket) const { return mBuckets[bucket]; }

        /// Instance indices (ForestInstances' dense indices), grouped by bucket, near first within
        /// a bucket: getDrawCount() of them (a tree in a transition is in two buckets).
        const std::uint32_t* getIndices() const { return mIndices.data(); }
        /// 12 floats per visible instance, same order as getIndices(): rows of the world matrix
        /// [R*s | t]: (m00 m01 m02 tx) (m10 m11 m12 ty) (m20 m21 m22 tz).
        const float* getTransforms() const { return mTransforms.data(); }
        const std::uint32_t* getBucketIndices(std::size_t bucket) const
        {
            return mIndices.data() + mBuckets[bucket].first;
        }
        const float* getBucketTransforms(std::size_t bucket) const
        {
            return mTransforms.data() + TRANSFORM_FLOATS * mBuckets[bucket].first;
        }
        /// Transition code per draw, same order as getIndices() (transitionCode): 0 draws the whole
        /// tree; f in (0, 1] the coarse level's share f of a transition, -f the fine level's rest.
        const float* getTransitionCodes() const { return mCodes.data(); }
        const float* getBucketTransitionCodes(std::size_t bucket) const { return mCodes.data() + mBuckets[bucket].first; }

        /// Visible trees (each once, also when in a transition).
        std::uint32_t getVisibleCount() const { return mVisibleCount; }
        /// Draws: the visible trees and once more each tree in a transition.
        std::uint32_t getDrawCount() const { return mVisibleCount + mTransitionCount; }
        /// Visible trees drawn at two levels (in a transition band).
        std::uint32_t getTransitionCount() const { return mTransitionCount; }
        std::uint32_t getCulledCount() const { return mCulledCount; }
        /// Level switches of the last cull: visible instances given another level than this
        /// visibility's previous cull gave them (instances never seen before do not count; one
        /// that comes back into view at another level does).
        std::uint32_t getSwitchCount() const { return mSwitchCount; }

        /// Visible instances not drawn because occlusion found less than OCCLUSION_HIDDEN of them
        /// visible (0 without occlusion). Not counted in getVisibleCount.
        std::uint32_t getOccludedCount() const { return mOccludedCount; }
        /// The visible share occlusion estimated for the instance at a dense index in the last cull
        /// (OcclusionShare::estimate), in [0, 1]; -1 where it was not estimated (outside the
        /// frustum, occlusion off).
        float getVisibility(std::size_t index) const
        {
            return index < mVisibility.size() && mVisibilityValid ? mVisibility[index] : -1.0f;
        }
        /// The last cull's grid (empty without occlusion).
        const OcclusionGrid& getOcclusionGrid() const { return mGrid; }

        /// Bytes reserved by the arrays (to check that a second cull allocates nothing).
        std::size_t getCapacityBytes() const;

    private:
        friend class ForestInstances;
        std::vector<ForestBucket> mBuckets;
        std::vector<std::uint32_t> mIndices;     // grown to the largest visible count so far
        std::vector<float> mTransforms;          // grown to 12 x the largest visible count so far
        std::vector<float> mCodes;               // transition code per draw
        std::vector<float> mVisibleCode;         // scratch: per draw, near first (transition code)
        std::vector<std::uint32_t> mDrawInstance; // scratch: per draw, near first (dense index)
        std::vector<float> mVisibleKey;          // scratch: per entry of mVisible, its LoD key
        std::vector<float> mBandEnds;            // per kind and threshold: 1 + the band's length (1: none)
        float mBandTransition = -1.0f;           // the transition mBandEnds were made for
        std::uint32_t mBandTables = 0;           // and the table generation
        std::vector<std::uint32_t> mVisible;     // scratch: visible instances in input order
        std::vector<std::uint32_t> mVisibleBucket; // scratch: per draw, near first (bucket)
        std::vector<std::uint8_t> mVisibleClass;   // scratch: their distance classes
        std::vector<std::uint32_t> mNearFirst;     // scratch: positions in mVisible, near first
        std::vector<std::uint32_t> mCursor;      // scratch: fill position per bucket
        std::vector<std::uint8_t> mLastLevel;    // per dense instance: its level last time it was seen (LEVEL_NONE)
        std::size_t mLastLevelInstances = 0;     // the instance count mLastLevel was made for
        std::uint32_t mLastLevelTables = 0;      // the ForestInstances table generation it was made for
        std::uint32_t mVisibleCount = 0;
        std::uint32_t mCulledCount = 0;
        std::uint32_t mSwitchCount = 0;
        std::uint32_t mTransitionCount = 0;
        std::uint32_t mOccludedCount = 0;
        OcclusionGrid mGrid;
        std::vector<float> mVisibility;          // per dense instance (getVisibility)
        bool mVisibilityValid = false;
    };

    /// The instance store. Removal swaps the last instance into the hole, so dense indices
    /// change on remove; handles do not. Not thread-safe for writes; `cull` is const and may run
    /// for several cameras at once, each into its own ForestVisibility.
    class ForestInstances
    {
    public:
        static constexpr std::size_t MAX_THRESHOLDS = 15; ///< at most 16 levels per kind
        static constexpr std::size_t MAX_KINDS = 65535;   ///< kinds are stored in 16 bits
        /// Dense instances [k * BLOCK_SIZE, (k + 1) * BLOCK_SIZE) share a conservative world box;
        /// cull skips a block outside the frustum whole and tests no instance of a block inside it.
        static constexpr std::size_t BLOCK_SIZE = 256;
        /// The longest transition: a screen size doubling.
        static constexpr float MAX_TRANSITION = 1.0f;
        /// The transition the Forest and scene scripts use unless told: hard switches. Measured
        /// (docs/measurements.md, "Transitions: pops faded"), masks in a dense forest flicker more
        /// than its hard switches pop; scenes of large trees seen one by one set about 0.2.
        static constexpr float DEFAULT_TRANSITION = 0.0f;

        /// An order of `instances` (indices) along a Z-order curve over their x-z extent: added in
        /// that order, blocks are compact patches and culling skips what is out of view (the
        /// Forest adds in this order). Non-finite positions go first (add() refuses them).
        static std::vector<std::uint32_t> spatialOrder(const std::vector<ForestInstance>& instances);

        /// Add a kind; returns its index. Kinds are never removed.
        Result<std::uint32_t> addKind(const ForestKind& kind);
        /// Replace a kind's LoD table (same checks as addKind; the kind is unchanged on error). When
        /// its level count changes, the bucket indices of the kinds after it move (getBucketIndex);
        /// a ForestVisibility culled before holds the old buckets until its next cull, which forgets
        /// the levels it remembered for hysteresis (a level index may mean another level now).
        Result<void> setKindThresholds(std::uint32_t kind, const std::vector<float>& thresholds,
                                       std::uint16_t hardSwitches = 0);
        /// Replace a kind's occlusion mask and height scales (ForestKind; checked as addKind does).
        Result<void> setKindOcclusion(std::uint32_t kind, std::shared_ptr<const OcclusionMask> mask,
                                      const std::array<float, OCCLUSION_CLASSES>& heightScales);
        std::uint32_t getKindCount() const { return std::uint32_t(mKinds.size()); }
        const ForestKind& getKind(std::uint32_t kind) const { return mKinds[kind]; }
        std::uint32_t getLevelCount(std::uint32_t kind) const
        {
            return std::uint32_t(mKinds[kind].thresholds.size() + 1);
        }
        /// Bucket of (kind, level) in ForestVisibility::getBuckets().
        std::uint32_t getBucketIndex(std::uint32_t kind, std::uint32_t level) const
        {
            return mKindFirstBucket[kind] + level;
        }
        std::uint32_t getBucketCount() const { return mBucketCount; }

        /// Add one instance. Error (element "instance N", N the index it would get) on a
        /// non-finite value, scale <= 0 or an unknown kind; nothing is added then.
        Result<ForestHandle> add(const ForestInstance& instance);
        /// The check add() makes, without adding: the error names the instance by its index.
        Result<void> validate(const std::vector<ForestInstance>& instances) const;
        /// Add many: all or nothing; the error names the instance by its index in `instances`.
        Result<std::vector<ForestHandle>> add(const std::vector<ForestInstance>& instances);
        /// Replace an instance's data; same checks as add.
        Result<void> update(ForestHandle handle, const ForestInstance& instance);
        /// Remove an instance: the last one moves into its dense index.
        Result<void> remove(ForestHandle handle);
        void clear();
        void reserve(std::size_t count);
        /// Bytes the store holds for its instances (every per-instance array's capacity, handle maps
        /// included; kinds not counted): what grows with the instance count.
        std::size_t getMemoryBytes() const;

        std::size_t size() const { return mKind.size(); }
        bool contains(ForestHandle handle) const;
        /// The instance (handle must be valid).
        ForestInstance get(ForestHandle handle) const { return getAt(mSlotOfHandle[handle]); }
        /// By dense index (< size()), as `cull` reports them.
        ForestInstance getAt(std::size_t index) const;
        ForestHandle getHandleAt(std::size_t index) const { return mHandleOfSlot[index]; }
        std::uint32_t getIndexOf(ForestHandle handle) const { return mSlotOfHandle[handle]; }

        /// World bounding sphere (centre xyz, radius w) of the instance at a dense index.
        glm::vec4 getWorldSphere(std::size_t index) const;

        /// LoD value of the instance at a dense index for a LoD camera and bias (the formula above;
        /// for Distance kinds the squared distance divided by the bias).
        float lodValue(std::size_t index, const CullCamera& camera, float lodBias) const;
        /// Level a kind's table gives for a value from lodValue.
        std::uint32_t levelForValue(std::uint32_t kind, float value) const;

        /// Cull and select levels for every instance (see the file comment). Error if the bias is
        /// not finite and > 0, the hysteresis not in [0, 1], the transition not in [0,
        /// MAX_TRANSITION] or the camera has a non-finite value; `out` is untouched then.
        /// Hysteresis h: an instance keeps the level it had in `out`'s last cull while that level is
        /// one its LoD value times or divided by (1 + h) would give, so trees near a switch do not
        /// flicker between two levels under camera jitter (0: none). `out` remembers the levels
        /// per instance; after instances are added or removed, or a kind's table changes, it
        /// starts afresh. Occlusion as the file comment says, where `camera.occlusion` is set. Transition t (file comment): trees near a switch are drawn at both levels;
        /// hysteresis holds only the switches that do not fade (a fade has nothing to flicker).
        Result<void> cull(const CullCamera& camera, float lodBias, ForestVisibility& out, float hysteresis = 0.0f,
                          float transition = 0.0f) const;

    private:
        std::string check(const ForestInstance& instance) const; ///< "" or the reason it is refused
        Result<void> checkThresholds(const ForestKind& kind, const std::string& element) const;
        void writeKindTable(std::uint32_t kind); ///< its table row and every kind's first bucket
        ForestHandle takeHandle();
        std::array<std::vector<float>*, 5> floatArrays(); ///< every per-instance float array
        void write(std::size_t slot, const ForestInstance& instance);
        void push(const ForestInstance& instance, ForestHandle handle);
        void growBlock(std::size_t slot); ///< merge the instance's world sphere into its block's box
        void writeBandEnds(float transition, ForestVisibility& out) const; ///< out.mBandEnds for t

        // kinds
        std::vector<ForestKind> mKinds;
        std::vector<std::uint32_t> mKindFirstBucket;
        std::vector<std::uint8_t> mKindDistance;  // 1 for ForestLodMode::Distance
        /// Per kind MAX_THRESHOLDS keys, compared as key >= table[i]: pixel thresholds as they
        /// are, distance thresholds negated (value = -d^2 / bias), padding never reached.
        std::vector<float> mKindTable;
        /// Per kind OCCLUSION_CLASSES factors on the key, log2 (0: none): 2 log2 s for pixel tables,
        /// -2 log2 s for distance tables (keys negated).
        std::vector<float> mKindOcclusionLog2;
        std::uint32_t mBucketCount = 0;
        std::uint32_t mTableGeneration = 0; ///< counts table changes (addKind, setKindThresholds)

        // instances (structure of arrays, dense): 32 bytes each with the handle maps;
        // scale, rotation and the world sphere are derived from these where needed
        std::vector<float> mX, mY, mZ;             // position
        std::vector<float> mCosScale, mSinScale;   // scale * cos / sin of the rotation
        std::vector<std::uint16_t> mKind;
        std::vector<float> mBlockBounds;           // per block: min xyz, max xyz (only grow until clear)
        std::vector<ForestHandle> mHandleOfSlot;

        // handles
        std::vector<std::uint32_t> mSlotOfHandle; // INVALID for free ids
        std::vector<ForestHandle> mFreeHandles;
    };
}
