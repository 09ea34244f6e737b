// EllipsoidTreeData: the "ellipsoids" chunk (layout and meaning in EllipsoidTreeData.h).
#include "TreeLod/EllipsoidTreeData.h"

#include "EllipsoidQuantisation.h"

#include "TreeLod/ByteReader.h"
#include "TreeLod/ByteWriter.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;
        constexpr std::size_t HEADER_BYTES = 4 + 24 + 4 + 4 + 4; // flags, box, unit, both counts

        using EllipsoidQuantisation::finite;
        using EllipsoidQuantisation::text;

        std::uint16_t quantiseUnit(float t) { return EllipsoidQuantisation::unit(t); }

        std::uint16_t quantiseRadius(float radius, float unit)
        {
            return EllipsoidQuantisation::logLength(radius, unit, ELLIPSOID_RADIUS_LOG2_MIN,
                                                    ELLIPSOID_RADIUS_LOG2_SPAN);
        }

        float radiusFromCode(std::uint16_t q, float unit)
        {
            return EllipsoidQuantisation::lengthFromCode(q, unit, ELLIPSOID_RADIUS_LOG2_MIN,
                                                         ELLIPSOID_RADIUS_LOG2_SPAN);
        }

        std::int16_t quantiseSigned(float v)
        {
            return std::int16_t(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f));
        }
    }

    std::size_t EllipsoidTreeData::encodedBytes() const
    {
        return HEADER_BYTES + levels.size() * ELLIPSOID_LEVEL_BYTES + ellipsoids.size() * ELLIPSOID_RECORD_BYTES;
    }

    float ellipsoidCentreStep(const EllipsoidTreeData& data, int axis)
    {
        return (data.boundsMax[axis] - data.boundsMin[axis]) / 65535.0f * 0.5f;
    }

    Result<void> EllipsoidTreeData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(ELLIPSOID_TREE_CHUNK, 0);
        if (!finite(boundsMin) || !finite(boundsMax) || !finite(boundsMax - boundsMin) ||
            glm::any(glm::lessThan(boundsMax, boundsMin)))
            return fail(label, name + ", bounds",
                        "centre box (" + text(boundsMin.x) + ", " + text(boundsMin.y) + ", " + text(boundsMin.z) +
                            ") .. (" + text(boundsMax.x) + ", " + text(boundsMax.y) + ", " + text(boundsMax.z) +
                            ") is not finite with max >= min");
        if (!std::isfinite(radiusUnit) || !(radiusUnit > 0.0f))
            return fail(label, name + ", bounds", "radius unit " + text(radiusUnit) + " is not finite and > 0");
        if (levels.empty() || levels.size() > ELLIPSOID_MAX_LEVELS)
            return fail(label, name + ", levels",
                        std::to_string(levels.size()) + " levels (1 to " + std::to_string(ELLIPSOID_MAX_LEVELS) +
                            " needed)");
        std::uint64_t next = 0;
        for (std::size_t k = 0; k < levels.size(); ++k)
        {
            const EllipsoidLevel& l = levels[k];
            const std::string element = name + ", level " + std::to_string(k);
            if (l.first != next)
                return fail(label, element,
                            "starts at ellipsoid " + std::to_string(l.first) + ", the previous level ends at " +
                                std::to_string(next) + " (levels must be contiguous, finest first)");
            if (l.count == 0)
                return fail(label, element, "has no ellipsoids");
            next += l.count;
            if (next > ellipsoids.size())
                return fail(label, element,
                            "ellipsoids " + std::to_string(l.first) + " + " + std::to_string(l.count) + " run past the " +
                                std::to_string(ellipsoids.size()) + " stored");
            if (!std::isfinite(l.scale) || !(l.scale > 0.0f) || l.scale > 16.0f)
                return fail(label, element, "scale " + text(l.scale) + " is outside (0, 16]");
            if (!std::isfinite(l.targetHeightPx) || !(l.targetHeightPx > 0.0f))
                return fail(label, element, "target height " + text(l.targetHeightPx) + " px is not finite and > 0");
            if (!std::isfinite(l.imageError) || l.imageError < 0.0f || l.imageError > 1.0f)
                return fail(label, element, "image error " + text(l.imageError) + " is outside [0, 1]");
            if (!(l.noiseThreshold >= 0.0f && l.noiseThreshold < 1.0f))
                return fail(label, element, "noise threshold " + text(l.noiseThreshold) + " is outside [0, 1)");
            if (!(l.normalBlend >= 0.0f && l.normalBlend <= 1.0f))
                return fail(label, element, "normal blend " + text(l.normalBlend) + " is outside [0, 1]");
        }
        if (next != ellipsoids.size())
            return fail(label, name + ", levels",
                        "the levels cover " + std::to_string(next) + " of the " + std::to_string(ellipsoids.size()) +
                            " ellipsoids");
        // The box holds every centre up to the rounding of its own corners.
        const glm::vec3 slack = 1e-5f * (boundsMax - boundsMin) + 1e-6f * glm::max(glm::abs(boundsMin), glm::abs(boundsMax));
        for (std::size_t i = 0; i < ellipsoids.size(); ++i)
        {
            const Ellipsoid& e = ellipsoids[i];
            const std::string element = name + ", ellipsoid " + std::to_string(i);
            if (!finite(e.centre) || glm::any(glm::lessThan(e.centre, boundsMin - slack)) ||
                glm::any(glm::greaterThan(e.centre, boundsMax + slack)))
                return fail(label, element,
                            "centre (" + text(e.centre.x) + ", " + text(e.centre.y) + ", " + text(e.centre.z) +
                                ") is not finite inside the centre box");
            if (!finite(e.radii) || !(glm::min(e.radii.x, glm::min(e.radii.y, e.radii.z)) > 0.0f))
                return fail(label, element,
                            "radii (" + text(e.radii.x) + ", " + text(e.radii.y) + ", " + text(e.radii.z) +
                                ") are not finite and > 0");
            const float length = std::sqrt(e.rotation.x * e.rotation.x + e.rotation.y * e.rotation.y +
                                           e.rotation.z * e.rotation.z + e.rotation.w * e.rotation.w);
            if (!std::isfinite(length) || std::abs(length - 1.0f) > 0.02f)
                return fail(label, element, "rotation quaternion of length " + text(length) + " (1 within 2 % needed)");
            if (!std::isfinite(e.leafWeight) || e.leafWeight < 0.0f)
                return fail(label, element, "leaf weight " + text(e.leafWeight) + " is not finite and >= 0");
        }
        return {};
    }

    std::vector<std::uint8_t> encodeEllipsoidTreeChunk(const EllipsoidTreeData& data)
    {
        ByteWriter w;
        w.reserve(data.encodedBytes());
        w.u32(KNOWN_FLAGS);
        w.vec3(data.boundsMin);
        w.vec3(data.boundsMax);
        w.f32(data.radiusUnit);
        w.u32(std::uint32_t(data.levels.size()));
        for (const EllipsoidLevel& l : data.levels)
        {
            w.u32(l.first);
            w.u32(l.count);
            w.f32(l.scale);
            w.f32(l.targetHeightPx);
            w.f32(l.imageError);
            w.f32(l.noiseThreshold);
            w.f32(l.normalBlend);
        }
        w.u32(std::uint32_t(data.ellipsoids.size()));
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        for (const Ellipsoid& e : data.ellipsoids)
        {
            for (int a = 0; a < 3; ++a)
                w.u16(extent[a] > 0.0f ? quantiseUnit((e.centre[a] - data.boundsMin[a]) / extent[a]) : 0);
            for (int a = 0; a < 3; ++a)
                w.u16(quantiseRadius(e.radii[a], data.radiusUnit));
            glm::quat q = e.rotation;
            const float length = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
            q = length > 0.0f && std::isfinite(length) ? glm::quat(q.w / length, q.x / length, q.y / length, q.z / length)
                                                       : glm::quat(1, 0, 0, 0);
            if (q.w < 0.0f) // q and -q are the same rotation
                q = glm::quat(-q.w, -q.x, -q.y, -q.z);
            for (float c : {q.x, q.y, q.z, q.w})
                w.u16(std::uint16_t(quantiseSigned(c)));
            for (std::uint8_t c : e.colour)
                w.u8(c);
            w.f32(e.leafWeight);
        }
        return w.take();
    }

    Result<EllipsoidTreeData> decodeEllipsoidTreeChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(ELLIPSOID_TREE_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        EllipsoidTreeData data;
        const std::uint32_t flags = r.u32();
        if (r.ok() && (flags & ~KNOWN_FLAGS) != 0)
            r.failHere("unknown flags " + std::to_string(flags));
        r.setElement(name + ", bounds");
        data.boundsMin = r.vec3();
        data.boundsMax = r.vec3();
        data.radiusUnit = r.f32();
        r.setElement(name + ", levels");
        const std::uint32_t levelCount = r.count(ELLIPSOID_LEVEL_BYTES);
        if (r.ok() && (levelCount == 0 || levelCount > ELLIPSOID_MAX_LEVELS))
            r.failHere(std::to_string(levelCount) + " levels (1 to " + std::to_string(ELLIPSOID_MAX_LEVELS) + " needed)");
        if (!r.ok())
            return r.error();
        data.levels.resize(levelCount);
        for (std::uint32_t k = 0; k < levelCount; ++k)
        {
            r.setElement(name + ", level " + std::to_string(k));
            EllipsoidLevel& l = data.levels[k];
            l.first = r.u32();
            l.count = r.u32();
            l.scale = r.f32();
            l.targetHeightPx = r.f32();
            l.imageError = r.f32();
            l.noiseThreshold = r.f32();
            l.normalBlend = r.f32();
        }
        r.setElement(name + ", ellipsoids");
        const std::uint32_t count = r.count(ELLIPSOID_RECORD_BYTES);
        if (!r.ok())
            return r.error();
        data.ellipsoids.resize(count);
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        for (std::uint32_t i = 0; i < count; ++i)
        {
            r.setElement(name + ", ellipsoid " + std::to_string(i));
            Ellipsoid& e = data.ellipsoids[i];
            for (int a = 0; a < 3; ++a)
                e.centre[a] = data.boundsMin[a] + extent[a] * (float(r.u16()) / 65535.0f);
            for (int a = 0; a < 3; ++a)
                e.radii[a] = radiusFromCode(r.u16(), data.radiusUnit);
            float q[4];
            for (float& c : q)
                c = float(std::int16_t(r.u16())) / 32767.0f;
            const float length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
            if (r.ok() && std::abs(length - 1.0f) > 0.02f)
                r.failHere("rotation quaternion of length " + text(length) + " (1 within 2 % needed)");
            if (!r.ok())
                return r.error();
            e.rotation = glm::quat(q[3] / length, q[0] / length, q[1] / length, q[2] / length);
            for (std::uint8_t& c : e.colour)
                c = r.u8();
            e.leafWeight = r.f32();
        }
        return finishDecode(r, label, name, std::move(data));
    }
}
