// ForestInstances: packed instances, frustum culling, LoD selection and bucketing (see the header).
#include "TreeLod/ForestInstances.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t INVALID_SLOT = std::numeric_limits<std::uint32_t>::max();

        bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

        std::string text(const glm::vec3& v)
        {
            std::ostringstream out;
            out << "(" << v.x << ", " << v.y << ", " << v.z << ")";
            return out.str();
        }

        std::string text(float v)
        {
            std::ostringstream out;
            out << v;
            return out.str();
        }

        /// The per-frame constants of the LoD value (the header's formula).
        struct LodConstants
        {
            float pixelFactor; // pi * W * H * P00 * P11 * bias
            float bias;
            bool orthographic;
        };

        LodConstants lodConstants(const CullCamera& camera, float lodBias)
        {
            return {glm::pi<float>() * camera.lodPixelScale * lodBias, lodBias, camera.lodOrthographic};
        }

        /// The key compared with a kind's table: the pixel value, or -d^2 / bias for distance kinds.
        inline float lodKey(float d2, float radius, bool distance, const LodConstants& c)
        {
            if (distance)
                return -(d2 / c.bias);
            if (c.orthographic)
                return c.pixelFactor * radius * radius;
            return d2 > FLT_EPSILON ? c.pixelFactor * radius * radius / d2 : FLT_MAX;
        }

        /// Number of table entries the key is below: the level (the tables are monotone).
        inline std::uint32_t levelForKey(const float* table, float key)
        {
            std::uint32_t level = 0;
            for (std::size_t i = 0; i < ForestInstances::MAX_THRESHOLDS; ++i)
                level += key < table[i] ? 1u : 0u;
            return level;
        }
    }

    // ---- CullCamera ------------------------------------------------------------------------------

    std::array<glm::vec4, 6> CullCamera::frustumPlanes(const glm::dmat4& m)
    {
        auto row = [&](int i) { return glm::dvec4(m[0][i], m[1][i], m[2][i], m[3][i]); };
        const glm::dvec4 r0 = row(0), r1 = row(1), r2 = row(2), r3 = row(3);
        const glm::dvec4 raw[6] = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
        const double scale = std::max(glm::length(glm::dvec3(r3)), 1e-300);
        std::array<glm::vec4, 6> planes;
        for (int p = 0; p < 6; ++p)
        {
            const double length = glm::length(glm::dvec3(raw[p]));
            if (length <= 1e-6 * scale)
                // Degenerate (an infinite far plane): all inside or all outside.
                planes[p] = glm::vec4(0.0f, 0.0f, 0.0f, raw[p].w >= 0.0 ? 0.0f : -FLT_MAX);
            else
                planes[p] = glm::vec4(raw[p] / length);
        }
        return planes;
    }

    CullCamera CullCamera::fromMatrices(const glm::mat4& view, const glm::mat4& projection, float viewportWidth,
                                        float viewportHeight)
    {
        CullCamera camera;
        camera.planes = frustumPlanes(glm::dmat4(projection) * glm::dmat4(view));
        camera.lodPosition = glm::vec3(glm::inverse(glm::dmat4(view))[3]);
        camera.lodPixelScale =
            float(double(viewportWidth) * double(viewportHeight) * std::abs(projection[0][0] * projection[1][1]));
        camera.lodOrthographic = projection[3][3] != 0.0f;
        camera.viewProjection = projection * view;
        camera.projectionScale = glm::vec2(projection[0][0], projection[1][1]);
        camera.viewportHeight = viewportHeight;
        return camera;
    }

    CullCamera CullCamera::fromSpec(const CameraSpec& spec, float viewportWidth, float viewportHeight)
    {
        return fromMatrices(spec.viewMatrix(), spec.projectionMatrix(viewportWidth / viewportHeight), viewportWidth,
                            viewportHeight);
    }

    // ---- ForestVisibility ------------------------------------------------------------------------

    std::size_t ForestVisibility::getCapacityBytes() const
    {
        return mBuckets.capacity() * sizeof(ForestBucket) +
               (mIndices.capacity() + mVisible.capacity() + mVisibleBucket.capacity() + mCursor.capacity() +
                mNearFirst.capacity()) *
                   sizeof(std::uint32_t) +
               mVisibleClass.capacity() + mLastLevel.capacity() + mDrawInstance.capacity() * sizeof(std::uint32_t) +
               (mTransforms.capacity() + mCodes.capacity() + mVisibleCode.capacity() + mBandEnds.capacity() +
                mVisibleKey.capacity() + mVisibility.capacity()) *
                   sizeof(float);
    }

    std::size_t ForestInstances::getMemoryBytes() const
    {
        std::size_t bytes = 0;
        for (const std::vector<float>* a : {&mX, &mY, &mZ, &mCosScale, &mSinScale})
            bytes += a->capacity() * sizeof(float);
        return bytes + mKind.capacity() * sizeof(std::uint16_t) + mBlockBounds.capacity() * sizeof(float) +
               (mHandleOfSlot.capacity() + mSlotOfHandle.capacity() + mFreeHandles.capacity()) * sizeof(std::uint32_t);
    }

    // ---- kinds -----------------------------------------------------------------------------------

    Result<void> ForestInstances::checkThresholds(const ForestKind& kind, const std::string& element) const
    {
        if (kind.thresholds.size() > MAX_THRESHOLDS)
            return fail("", element, std::to_string(kind.thresholds.size()) + " LoD thresholds (at most " +
                                         std::to_string(MAX_THRESHOLDS) + ")");
        const bool distance = kind.lodMode == ForestLodMode::Distance;
        for (std::size_t i = 0; i < kind.thresholds.size(); ++i)
        {
            const float t = kind.thresholds[i];
            if (!std::isfinite(t) || t < 0.0f)
                return fail("", element, "LoD threshold " + std::to_string(i) + " (" + text(t) +
                                             ") is not finite and >= 0");
            if (i > 0 && (distance ? t < kind.thresholds[i - 1] : t > kind.thresholds[i - 1]))
                return fail("", element, "LoD threshold " + std::to_string(i) + " (" + text(t) + ") is " +
                                             (distance ? "below" : "above") + " the previous one (" +
                                             text(kind.thresholds[i - 1]) + "); " +
                                             (distance ? "distance thresholds increase" :
                                                         "pixel-count thresholds decrease"));
        }
        for (std::size_t c = 0; c < OCCLUSION_CLASSES; ++c)
            if (!(kind.occlusionHeightScales[c] > 0.0f && kind.occlusionHeightScales[c] <= 1.0f))
                return fail("", element, "occlusion height scale " + std::to_string(c) + " (" +
                                             text(kind.occlusionHeightScales[c]) + ") is not in (0, 1]");
        return {};
    }

    void ForestInstances::writeKindTable(std::uint32_t index)
    {
        const ForestKind& kind = mKinds[index];
        const bool distance = kind.lodMode == ForestLodMode::Distance;
        mKindDistance[index] = distance ? 1 : 0;
        float* table = mKindTable.data() + std::size_t(index) * MAX_THRESHOLDS;
        for (std::size_t i = 0; i < MAX_THRESHOLDS; ++i)
            table[i] = i >= kind.thresholds.size() ? -std::numeric_limits<float>::infinity() // never above the key
                                                   : distance ? -kind.thresholds[i] : kind.thresholds[i];
        for (std::size_t c = 0; c < OCCLUSION_CLASSES; ++c)
            mKindOcclusionLog2[std::size_t(index) * OCCLUSION_CLASSES + c] =
                (distance ? -2.0f : 2.0f) * std::log2(kind.occlusionHeightScales[c]);
        ++mTableGeneration; // levels remembered for hysteresis may mean others now
        // Buckets are kind-major: a kind's level count moves the buckets of the kinds after it.
        mBucketCount = 0;
        for (std::uint32_t k = 0; k < mKinds.size(); ++k)
        {
            mKindFirstBucket[k] = mBucketCount;
            mBucketCount += getLevelCount(k);
        }
    }

    Result<std::uint32_t> ForestInstances::addKind(const ForestKind& kind)
    {
        const std::string element = "kind " + std::to_string(mKinds.size()) + " '" + kind.name + "'";
        if (!finite(kind.boundsCentre))
            return fail("", element, "bounding sphere centre " + text(kind.boundsCentre) + " is not finite");
        if (!std::isfinite(kind.boundsRadius) || !(kind.boundsRadius > 0.0f))
            return fail("", element, "bounding radius " + text(kind.boundsRadius) + " is not finite and > 0");
        if (mKinds.size() >= MAX_KINDS)
            return fail("", element, "more than " + std::to_string(MAX_KINDS) + " kinds");
        if (Result<void> valid = checkThresholds(kind, element); !valid)
            return valid.error();

        const std::uint32_t index = std::uint32_t(mKinds.size());
        mKinds.push_back(kind);
        mKindFirstBucket.push_back(0);
        mKindDistance.push_back(0);
        mKindTable.resize(mKindTable.size() + MAX_THRESHOLDS);
        mKindOcclusionLog2.resize(mKindOcclusionLog2.size() + OCCLUSION_CLASSES);
        writeKindTable(index);
        // Instances already placed keep their kinds; their spheres do not depend on new kinds.
        return index;
    }

    Result<void> ForestInstances::setKindThresholds(std::uint32_t kind, const std::vector<float>& thresholds,
                                                    std::uint16_t hardSwitches)
    {
        if (kind >= mKinds.size())
            return fail("", "kind " + std::to_string(kind), "no such kind (" + std::to_string(mKinds.size()) + " kinds)");
        ForestKind changed = mKinds[kind];
        changed.thresholds = thresholds;
        changed.hardSwitches = hardSwitches;
        if (Result<void> valid = checkThresholds(changed, "kind " + std::to_string(kind) + " '" + changed.name + "'");
            !valid)
            return valid;
        mKinds[kind] = std::move(changed);
        writeKindTable(kind);
        return {};
    }

    Result<void> ForestInstances::setKindOcclusion(std::uint32_t kind, std::shared_ptr<const OcclusionMask> mask,
                                                   const std::array<float, OCCLUSION_CLASSES>& heightScales)
    {
        if (kind >= mKinds.size())
            return fail("", "kind " + std::to_string(kind), "no such kind (" + std::to_string(mKinds.size()) + " kinds)");
        ForestKind changed = mKinds[kind];
        changed.occlusionMask = std::move(mask);
        changed.occlusionHeightScales = heightScales;
        if (Result<void> valid = checkThresholds(changed, "kind " + std::to_string(kind) + " '" + changed.name + "'");
            !valid)
            return valid;
        const bool scalesChanged = changed.occlusionHeightScales != mKinds[kind].occlusionHeightScales;
        mKinds[kind] = std::move(changed);
        if (scalesChanged) // the table's key factors; a new mask alone keeps the remembered levels
            writeKindTable(kind);
        return {};
    }

    // ---- instances -------------------------------------------------------------------------------

    std::string ForestInstances::check(const ForestInstance& instance) const
    {
        if (!finite(instance.position))
            return "position " + text(instance.position) + " is not finite";
        if (!std::isfinite(instance.rotationY))
            return "rotation " + text(instance.rotationY) + " is not finite";
        if (!std::isfinite(instance.scale) || !(instance.scale > 0.0f))
            return "scale " + text(instance.scale) + " is not finite and > 0";
        if (instance.kind >= mKinds.size())
            return "kind " + std::to_string(instance.kind) + " does not exist (" + std::to_string(mKinds.size()) +
                   " kinds)";
        const ForestKind& kind = mKinds[instance.kind];
        const float radius = kind.boundsRadius * instance.scale;
        const glm::vec3 centre = instance.position + instance.scale * kind.boundsCentre;
        if (!std::isfinite(radius * radius) || !finite(centre))
            return "scale " + text(instance.scale) + " makes the bounding sphere overflow";
        return {};
    }

    void ForestInstances::write(std::size_t slot, const ForestInstance& instance)
    {
        const ForestKind& kind = mKinds[instance.kind];
        const float s = instance.scale;
        const float cs = s * std::cos(instance.rotationY), ss = s * std::sin(instance.rotationY);
        const glm::vec3& c = kind.boundsCentre;
        mX[slot] = instance.position.x;
        mY[slot] = instance.position.y;
        mZ[slot] = instance.position.z;
        mCosScale[slot] = cs;
        mSinScale[slot] = ss;
        mKind[slot] = std::uint16_t(instance.kind);
        (void)kind;
        (void)c;
        growBlock(slot);
    }

    std::array<std::vector<float>*, 5> ForestInstances::floatArrays()
    {
        return {&mX, &mY, &mZ, &mCosScale, &mSinScale};
    }

    ForestHandle ForestInstances::takeHandle()
    {
        if (mFreeHandles.empty())
            return ForestHandle(mSlotOfHandle.size());
        const ForestHandle handle = mFreeHandles.back();
        mFreeHandles.pop_back();
        return handle;
    }

    void ForestInstances::push(const ForestInstance& instance, ForestHandle handle)
    {
        const std::size_t slot = size();
        for (std::vector<float>* a : floatArrays())
            a->push_back(0.0f);
        mKind.push_back(0);
        if (slot % BLOCK_SIZE == 0) // a new block, empty
            mBlockBounds.insert(mBlockBounds.end(), {FLT_MAX, FLT_MAX, FLT_MAX, -FLT_MAX, -FLT_MAX, -FLT_MAX});
        mHandleOfSlot.push_back(handle);
        if (handle >= mSlotOfHandle.size())
            mSlotOfHandle.resize(std::size_t(handle) + 1, INVALID_SLOT);
        mSlotOfHandle[handle] = std::uint32_t(slot);
        write(slot, instance);
    }

    Result<ForestHandle> ForestInstances::add(const ForestInstance& instance)
    {
        const std::string reason = check(instance);
        if (!reason.empty())
            return fail("", "instance " + std::to_string(size()), reason);
        const ForestHandle handle = takeHandle();
        push(instance, handle);
        return handle;
    }

    Result<void> ForestInstances::validate(const std::vector<ForestInstance>& instances) const
    {
        for (std::size_t i = 0; i < instances.size(); ++i)
        {
            const std::string reason = check(instances[i]);
            if (!reason.empty())
                return fail("", "instance " + std::to_string(i), reason);
        }
        return {};
    }

    Result<std::vector<ForestHandle>> ForestInstances::add(const std::vector<ForestInstance>& instances)
    {
        if (Result<void> valid = validate(instances); !valid)
            return valid.error();
        reserve(size() + instances.size());
        std::vector<ForestHandle> handles;
        handles.reserve(instances.size());
        for (const ForestInstance& instance : instances)
        {
            handles.push_back(takeHandle());
            push(instance, handles.back());
        }
        return handles;
    }

    Result<void> ForestInstances::update(ForestHandle handle, const ForestInstance& instance)
    {
        const std::string element = "instance handle " + std::to_string(handle);
        if (!contains(handle))
            return fail("", element, "no such instance");
        const std::string reason = check(instance);
        if (!reason.empty())
            return fail("", element, reason);
        write(mSlotOfHandle[handle], instance);
        return {};
    }

    Result<void> ForestInstances::remove(ForestHandle handle)
    {
        if (!contains(handle))
            return fail("", "instance handle " + std::to_string(handle), "no such instance");
        const std::uint32_t slot = mSlotOfHandle[handle];
        const std::uint32_t last = std::uint32_t(size() - 1);
        for (std::vector<float>* a : floatArrays())
        {
            (*a)[slot] = (*a)[last];
            a->pop_back();
        }
        mKind[slot] = mKind[last];
        mKind.pop_back();
        // Block bounds only grow (still conservative); the emptied last block goes.
        if (slot != last)
            growBlock(slot);
        if (last % BLOCK_SIZE == 0)
            mBlockBounds.resize(mBlockBounds.size() - 6);
        const ForestHandle moved = mHandleOfSlot[last];
        mHandleOfSlot[slot] = moved;
        mHandleOfSlot.pop_back();
        mSlotOfHandle[moved] = slot;
        mSlotOfHandle[handle] = INVALID_SLOT;
        mFreeHandles.push_back(handle);
        return {};
    }

    void ForestInstances::clear()
    {
        for (std::vector<float>* a : floatArrays())
            a->clear();
        mKind.clear();
        mBlockBounds.clear();
        mHandleOfSlot.clear();
        mSlotOfHandle.clear();
        mFreeHandles.clear();
    }

    void ForestInstances::reserve(std::size_t count)
    {
        for (std::vector<float>* a : floatArrays())
            a->reserve(count);
        mKind.reserve(count);
        mBlockBounds.reserve(6 * ((count + BLOCK_SIZE - 1) / BLOCK_SIZE));
        mHandleOfSlot.reserve(count);
        mSlotOfHandle.reserve(std::max(count, mSlotOfHandle.size()));
    }

    bool ForestInstances::contains(ForestHandle handle) const
    {
        return handle < mSlotOfHandle.size() && mSlotOfHandle[handle] != INVALID_SLOT;
    }

    ForestInstance ForestInstances::getAt(std::size_t index) const
    {
        ForestInstance instance;
        instance.position = glm::vec3(mX[index], mY[index], mZ[index]);
        // Derived from scale * (cos, sin): the rotation comes back in (-pi, pi], both to float rounding.
        instance.rotationY = std::atan2(mSinScale[index], mCosScale[index]);
        instance.scale = std::hypot(mCosScale[index], mSinScale[index]);
        instance.kind = mKind[index];
        return instance;
    }

    void ForestInstances::growBlock(std::size_t slot)
    {
        const glm::vec4 sphere = getWorldSphere(slot);
        float* b = mBlockBounds.data() + 6 * (slot / BLOCK_SIZE);
        for (int k = 0; k < 3; ++k)
        {
            b[k] = std::min(b[k], sphere[k] - sphere.w);
            b[3 + k] = std::max(b[3 + k], sphere[k] + sphere.w);
        }
    }

    std::vector<std::uint32_t> ForestInstances::spatialOrder(const std::vector<ForestInstance>& instances)
    {
        // Z-order (Morton) of a 1024 x 1024 grid over the instances' x-z extent.
        glm::vec2 lo(FLT_MAX), hi(-FLT_MAX);
        for (const ForestInstance& i : instances)
            if (std::isfinite(i.position.x) && std::isfinite(i.position.z))
            {
                lo = glm::min(lo, glm::vec2(i.position.x, i.position.z));
                hi = glm::max(hi, glm::vec2(i.position.x, i.position.z));
            }
        const glm::vec2 scale = 1023.0f / glm::max(hi - lo, glm::vec2(1e-6f));
        auto spread = [](std::uint32_t v) {
            v &= 0x3FF;
            v = (v | (v << 8)) & 0x00FF00FF;
            v = (v | (v << 4)) & 0x0F0F0F0F;
            v = (v | (v << 2)) & 0x33333333;
            return (v | (v << 1)) & 0x55555555;
        };
        std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed(instances.size());
        for (std::size_t i = 0; i < instances.size(); ++i)
        {
            const glm::vec2 p(instances[i].position.x, instances[i].position.z);
            const glm::vec2 g = glm::clamp((p - lo) * scale, glm::vec2(0.0f), glm::vec2(1023.0f));
            const bool finiteXz = std::isfinite(g.x) && std::isfinite(g.y);
            keyed[i] = {finiteXz ? spread(std::uint32_t(g.x)) | (spread(std::uint32_t(g.y)) << 1) : 0u,
                        std::uint32_t(i)};
        }
        std::sort(keyed.begin(), keyed.end());
        std::vector<std::uint32_t> order(instances.size());
        for (std::size_t i = 0; i < keyed.size(); ++i)
            order[i] = keyed[i].second;
        return order;
    }

    glm::vec4 ForestInstances::getWorldSphere(std::size_t index) const
    {
        // World centre = position + (R * s) * local centre, R about +Y (see the transform rows).
        const ForestKind& kind = mKinds[mKind[index]];
        const glm::vec3& c = kind.boundsCentre;
        const float cs = mCosScale[index], ss = mSinScale[index], s = std::sqrt(cs * cs + ss * ss);
        return glm::vec4(mX[index] + cs * c.x + ss * c.z, mY[index] + s * c.y, mZ[index] - ss * c.x + cs * c.z,
                         s * kind.boundsRadius);
    }

    // ---- level of detail -------------------------------------------------------------------------

    float ForestInstances::lodValue(std::size_t index, const CullCamera& camera, float lodBias) const
    {
        const LodConstants c = lodConstants(camera, lodBias);
        const float dx = mX[index] - camera.lodPosition.x, dy = mY[index] - camera.lodPosition.y,
                    dz = mZ[index] - camera.lodPosition.z;
        const bool distance = mKindDistance[mKind[index]] != 0;
        const float key = lodKey(dx * dx + dy * dy + dz * dz, getWorldSphere(index).w, distance, c);
        return distance ? -key : key;
    }

    std::uint32_t ForestInstances::levelForValue(std::uint32_t kind, float value) const
    {
        const float key = mKindDistance[kind] ? -value : value;
        return levelForKey(mKindTable.data() + kind * MAX_THRESHOLDS, key);
    }

    // ---- the per-frame loop ----------------------------------------------------------------------

    void ForestInstances::writeBandEnds(float transition, ForestVisibility& out) const
    {
        // Screen-size ratio where threshold i's band ends: 1 + t, at most the square root of level
        // i's own range of screen sizes (its lower half in ratio; level 0's range is unbounded).
        out.mBandEnds.assign(mKinds.size() * MAX_THRESHOLDS, 1.0f);
        for (std::size_t k = 0; k < mKinds.size(); ++k)
        {
            const std::vector<float>& t = mKinds[k].thresholds;
            const bool distance = mKindDistance[k] != 0;
            for (std::size_t i = 0; i < t.size(); ++i)
            {
                if (!(t[i] > 0.0f) || (mKinds[k].hardSwitches >> i & 1u))
                    continue; // hard; or at value 0 (or distance 0): never crossed from above
                // Level i's range of screen sizes: the square root of its range of values.
                const float range = i == 0 ? std::numeric_limits<float>::infinity()
                                           : std::sqrt(distance ? t[i] / t[i - 1] : t[i - 1] / t[i]);
                out.mBandEnds[k * MAX_THRESHOLDS + i] = transitionBandEnd(transition, range);
            }
        }
        out.mBandTransition = transition;
        out.mBandTables = mTableGeneration;
    }

    Result<void> ForestInstances::cull(const CullCamera& camera, float lodBias, ForestVisibility& out,
                                       float hysteresis, float transition) const
    {
        if (!std::isfinite(lodBias) || !(lodBias > 0.0f))
            return fail("", "LoD bias", text(lodBias) + " is not finite and > 0");
        if (!(hysteresis >= 0.0f && hysteresis <= 1.0f))
            return fail("", "LoD hysteresis", text(hysteresis) + " is not in [0, 1]");
        if (!(transition >= 0.0f && transition <= MAX_TRANSITION))
            return fail("", "LoD transition", text(transition) + " is not in [0, " + text(MAX_TRANSITION) + "]");
        for (std::size_t p = 0; p < 6; ++p)
            if (!finite(glm::vec3(camera.planes[p])) || !std::isfinite(camera.planes[p].w))
                return fail("", "camera", "frustum plane " + std::to_string(p) + " is not finite");
        if (!finite(camera.lodPosition) || !std::isfinite(camera.lodPixelScale) || camera.lodPixelScale < 0.0f)
            return fail("", "camera", "LoD position or pixel scale is not finite");

        // Warm-up: arrays grow to the instance and bucket counts (draws: twice the instances with
        // transitions, a tree may be drawn at two levels), never shrink.
        const std::size_t n = size();
        const bool transitions = transition > 0.0f;
        const std::size_t entries = transitions ? 2 * n : n;
        if (out.mVisible.size() < n)
        {
            out.mVisible.resize(n);
            out.mVisibleClass.resize(n);
            out.mVisibleKey.resize(n);
            out.mNearFirst.resize(n);
        }
        if (out.mVisibleBucket.size() < entries)
        {
            out.mVisibleBucket.resize(entries);
            out.mVisibleCode.resize(entries);
            out.mDrawInstance.resize(entries);
        }
        if (transitions && (out.mBandTransition != transition || out.mBandTables != mTableGeneration ||
                            out.mBandEnds.size() != mKinds.size() * MAX_THRESHOLDS))
            writeBandEnds(transition, out);
        const float* bandEnds = out.mBandEnds.data();
        out.mBuckets.resize(mBucketCount);
        out.mCursor.assign(mBucketCount, 0u);
        constexpr std::uint8_t LEVEL_NONE = 0xFF;
        if (out.mLastLevelInstances != n || out.mLastLevel.size() < n || out.mLastLevelTables != mTableGeneration)
        {
            out.mLastLevel.assign(std::max(n, out.mLastLevel.size()), LEVEL_NONE);
            out.mLastLevelInstances = n;
            out.mLastLevelTables = mTableGeneration;
        }
        std::uint8_t* lastLevel = out.mLastLevel.data();
        const float nearFactor = 1.0f + hysteresis, farFactor = 1.0f / (1.0f + hysteresis);

        // Pass 1: cull; each visible instance's LoD key and distance class. Planes copied out for
        // the compiler.
        float pl[6][4];
        for (int p = 0; p < 6; ++p)
            for (int k = 0; k < 4; ++k)
                pl[p][k] = camera.planes[p][k];
        const LodConstants c = lodConstants(camera, lodBias);
        const glm::vec3 eye = camera.lodPosition;
        // Kinds' local spheres, copied out: the world sphere is made per instance (4 floats less stored).
        std::array<glm::vec4, 64> localSpheres;
        const bool fewKinds = mKinds.size() <= localSpheres.size();
        if (fewKinds)
            for (std::size_t k = 0; k < mKinds.size(); ++k)
                localSpheres[k] = glm::vec4(mKinds[k].boundsCentre, mKinds[k].boundsRadius);
        const float* cosScale = mCosScale.data();
        const float* sinScale = mSinScale.data();
        const float* px = mX.data();
        const float* py = mY.data();
        const float* pz = mZ.data();
        const std::uint16_t* kinds = mKind.data();
        const std::uint8_t* kindDistance = mKindDistance.data();
        const std::uint32_t* kindFirst = mKindFirstBucket.data();
        const float* tables = mKindTable.data();
        std::uint32_t* visible = out.mVisible.data();
        std::uint8_t* visibleClass = out.mVisibleClass.data();
        float* visibleKey = out.mVisibleKey.data();
        std::array<std::uint32_t, ForestVisibility::DISTANCE_CLASSES> classCounts{};
        std::uint32_t visibleCount = 0;
        const float* blocks = mBlockBounds.data();
        for (std::size_t block = 0, begin = 0; begin < n; ++block, begin += BLOCK_SIZE)
        {
            // A block whose box is outside one plane is skipped whole; one inside every plane needs
            // no per-instance test (its spheres' centres are all inside).
            const float* b = blocks + 6 * block;
            bool outside = false, inside = true;
            for (int p = 0; p < 6; ++p)
            {
                const float farthest = pl[p][3] + pl[p][0] * b[pl[p][0] >= 0.0f ? 3 : 0] +
                                       pl[p][1] * b[pl[p][1] >= 0.0f ? 4 : 1] + pl[p][2] * b[pl[p][2] >= 0.0f ? 5 : 2];
                const float nearest = pl[p][3] + pl[p][0] * b[pl[p][0] >= 0.0f ? 0 : 3] +
                                      pl[p][1] * b[pl[p][1] >= 0.0f ? 1 : 4] + pl[p][2] * b[pl[p][2] >= 0.0f ? 2 : 5];
                outside |= farthest < 0.0f;
                inside &= nearest >= 0.0f;
            }
            if (outside)
                continue;
            const std::size_t end = std::min(n, begin + BLOCK_SIZE);
            for (std::size_t i = begin; i < end; ++i)
            {
                const std::uint32_t kind = kinds[i];
                const glm::vec4 local = fewKinds ? localSpheres[kind]
                                                 : glm::vec4(mKinds[kind].boundsCentre, mKinds[kind].boundsRadius);
                const float cs = cosScale[i], ss = sinScale[i], s = std::sqrt(cs * cs + ss * ss);
                const float x = px[i] + cs * local.x + ss * local.z, y = py[i] + s * local.y,
                            z = pz[i] - ss * local.x + cs * local.z, r = s * local.w, negR = -r;
                bool visibleSphere = true;
                if (!inside)
                    for (int p = 0; p < 6; ++p)
                        visibleSphere &= pl[p][0] * x + pl[p][1] * y + pl[p][2] * z + pl[p][3] >= negR;
                if (!visibleSphere)
                    continue;
                const float dx = px[i] - eye.x, dy = py[i] - eye.y, dz = pz[i] - eye.z;
                const float d2 = dx * dx + dy * dy + dz * dz;
                // Distance class: the exponent and top two mantissa bits of d^2 (monotonic for d^2 >= 0).
                std::uint32_t bits;
                std::memcpy(&bits, &d2, sizeof bits);
                const std::uint8_t distanceClass = std::uint8_t(
                    std::clamp(int(bits >> 21) - 127 * 4, 0, ForestVisibility::DISTANCE_CLASSES - 1));
                visible[visibleCount] = std::uint32_t(i);
                visibleKey[visibleCount] = lodKey(d2, r, kindDistance[kind] != 0, c);
                visibleClass[visibleCount] = distanceClass;
                ++classCounts[distanceClass];
                ++visibleCount;
            }
        }

        // Near first: the visible instances counting-sorted by distance class (stable).
        std::uint32_t* nearFirst = out.mNearFirst.data();
        std::uint32_t at = 0;
        for (std::uint32_t& count : classCounts)
        {
            const std::uint32_t size = count;
            count = at;
            at += size;
        }
        for (std::uint32_t j = 0; j < visibleCount; ++j)
            nearFirst[classCounts[visibleClass[j]]++] = j;

        // Pass 2, near first: occlusion, the level (hysteresis, transitions), the draws and their
        // count per bucket.
        const bool occlusion = camera.occlusion;
        out.mVisibilityValid = occlusion;
        if (occlusion)
        {
            const float aspect = std::abs(camera.projectionScale.y / camera.projectionScale.x);
            out.mGrid.clear(OCCLUSION_GRID_COLUMNS,
                            std::isfinite(aspect) && aspect > 0.0f
                                ? std::clamp(int(std::lround(OCCLUSION_GRID_COLUMNS / aspect)), 8, 4 * OCCLUSION_GRID_COLUMNS)
                                : OCCLUSION_GRID_COLUMNS);
            out.mVisibility.assign(std::max(n, out.mVisibility.size()), -1.0f);
        }
        const glm::mat4& vp = camera.viewProjection;
        const float* occlusionLog2 = mKindOcclusionLog2.data();
        std::uint32_t* drawInstance = out.mDrawInstance.data();
        std::uint32_t* drawBucket = out.mVisibleBucket.data();
        float* drawCode = out.mVisibleCode.data();
        std::uint32_t* counts = out.mCursor.data();
        std::uint32_t drawnCount = 0, occludedCount = 0, switchCount = 0, transitionCount = 0, drawCount = 0;
        for (std::uint32_t k = 0; k < visibleCount; ++k)
        {
            const std::uint32_t j = nearFirst[k];
            const std::uint32_t i = visible[j];
            const std::uint32_t kind = kinds[i];
            float key = visibleKey[j];
            if (occlusion)
            {
                const glm::vec4 sphere = getWorldSphere(i);
                const glm::vec4 clip = vp * glm::vec4(glm::vec3(sphere), 1.0f);
                OcclusionShare visibleShare;
                if (clip.w > sphere.w) // in front of the camera's plane
                {
                    const float cx = clip.x / clip.w, cy = clip.y / clip.w;
                    const float rx = sphere.w * std::abs(camera.projectionScale.x) / clip.w;
                    const float ry = sphere.w * std::abs(camera.projectionScale.y) / clip.w;
                    visibleShare = out.mGrid.addTree(mKinds[kind].occlusionMask.get(), cx - rx, cy - ry, cx + rx, cy + ry,
                                              ry * camera.viewportHeight >= OCCLUSION_MIN_OCCLUDER_PX);
                }
                const float share = visibleShare.estimate;
                out.mVisibility[i] = share;
                if (visibleShare.conservative < OCCLUSION_HIDDEN)
                {
                    ++occludedCount;
                    continue;
                }
                // The kind's factor, interpolated in log2 between its classes (v = 2^-c).
                const float* factors = occlusionLog2 + std::size_t(kind) * OCCLUSION_CLASSES;
                const float t = std::min(-std::log2(share), float(OCCLUSION_CLASSES - 1));
                const int c0 = std::min(int(t), int(OCCLUSION_CLASSES) - 2);
                const float f = t - float(c0);
                const float log2Factor = factors[c0] * (1.0f - f) + factors[c0 + 1] * f;
                if (log2Factor != 0.0f)
                    key *= std::exp2(log2Factor);
            }
            const float* table = tables + kind * MAX_THRESHOLDS;
            std::uint32_t level = levelForKey(table, key);
            // Hysteresis holds hard switches only: a switch through a fading threshold has a band.
            auto fades = [&](std::uint32_t from, std::uint32_t to) {
                for (std::uint32_t t = std::min(from, to); transitions && t < std::max(from, to) && t < MAX_THRESHOLDS; ++t)
                    if (bandEnds[kind * MAX_THRESHOLDS + t] > 1.0f)
                        return true;
                return false;
            };
            if (hysteresis > 0.0f && lastLevel[i] != LEVEL_NONE && lastLevel[i] != level && !fades(lastLevel[i], level))
            {
                // Keys grow toward finer levels (distance keys are negated, so scaling a negative
                // key by more than 1 makes it coarser): the band [finest, coarsest] of key * (1 +- h).
                const float a = key * nearFactor, b = key * farFactor;
                const std::uint32_t finest = levelForKey(table, std::max(a, b));
                const std::uint32_t coarsest = levelForKey(table, std::min(a, b));
                if (lastLevel[i] >= finest && lastLevel[i] <= coarsest)
                    level = lastLevel[i];
            }
            switchCount += lastLevel[i] != LEVEL_NONE && lastLevel[i] != level;
            lastLevel[i] = std::uint8_t(level);
            const std::uint32_t bucket = kindFirst[kind] + level;
            // In a transition band (the file comment): the coarse level's share f of the pixels.
            float coarseShare = 0.0f;
            if (transitions && level < MAX_THRESHOLDS)
            {
                const float end = bandEnds[kind * MAX_THRESHOLDS + level];
                const float threshold = table[level];
                const float ratio = kindDistance[kind] != 0 ? threshold / key : key / threshold; // >= 1 (or NaN)
                if (end > 1.0f && ratio < end * end)
                    coarseShare = transitionCoarseShare(std::sqrt(ratio), end);
            }
            drawInstance[drawCount] = i;
            drawBucket[drawCount] = bucket;
            drawCode[drawCount] = coarseShare > 0.0f ? -coarseShare : 0.0f;
            ++counts[bucket];
            ++drawCount;
            ++drawnCount;
            if (coarseShare > 0.0f)
            {
                drawInstance[drawCount] = i;
                drawBucket[drawCount] = bucket + 1;
                drawCode[drawCount] = coarseShare;
                ++counts[bucket + 1];
                ++drawCount;
                ++transitionCount;
            }
        }

        // Prefix sums: bucket ranges; counts become fill cursors.
        std::uint32_t first = 0;
        for (std::uint32_t k = 0, b = 0; k < mKinds.size(); ++k)
            for (std::uint32_t l = 0, levels = getLevelCount(k); l < levels; ++l, ++b)
            {
                out.mBuckets[b] = ForestBucket{k, l, first, counts[b]};
                first += counts[b];
                counts[b] = out.mBuckets[b].first;
            }

        // Pass 3: fill indices, world matrices and transition codes, bucket by bucket, near first.
        if (out.mIndices.size() < drawCount)
        {
            out.mIndices.resize(drawCount);
            out.mCodes.resize(drawCount);
            out.mTransforms.resize(ForestVisibility::TRANSFORM_FLOATS * drawCount);
        }
        std::uint32_t* indices = out.mIndices.data();
        float* codes = out.mCodes.data();
        float* transforms = out.mTransforms.data();
        for (std::uint32_t k = 0; k < drawCount; ++k)
        {
            const std::uint32_t i = drawInstance[k];
            const std::uint32_t slot = counts[drawBucket[k]]++;
            indices[slot] = i;
            codes[slot] = drawCode[k];
            float* m = transforms + ForestVisibility::TRANSFORM_FLOATS * slot;
            const float cs = cosScale[i], ss = sinScale[i];
            m[0] = cs, m[1] = 0.0f, m[2] = ss, m[3] = px[i];
            m[4] = 0.0f, m[5] = std::sqrt(cs * cs + ss * ss), m[6] = 0.0f, m[7] = py[i];
            m[8] = -ss, m[9] = 0.0f, m[10] = cs, m[11] = pz[i];
        }
        out.mOccludedCount = occludedCount;
        out.mVisibleCount = drawnCount;
        out.mCulledCount = std::uint32_t(n - visibleCount);
        out.mSwitchCount = switchCount;
        out.mTransitionCount = transitionCount;
        return {};
    }
}
