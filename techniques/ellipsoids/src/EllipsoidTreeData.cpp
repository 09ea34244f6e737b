// EllipsoidTreeData: the "ellipsoids" chunk (layout and meaning in EllipsoidTreeData.h).
#include "TreeLod/EllipsoidTreeData.h"

#include "EllipsoidQuantisation.h"

#include "TreeLod/ChunkCodec.h"
#include "TreeLod/Package.h"

#include <algorithm>
#include <cmath>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t KNOWN_FLAGS = 0;
        constexpr std::size_t HEADER_BYTES = 4 + 24 + 4 + 4 + 4; // flags, box, unit, both counts
        constexpr ArrayLayout LEVELS{ELLIPSOID_LEVEL_BYTES, 1, 1, ELLIPSOID_MAX_LEVELS, "levels"};
        constexpr ArrayLayout ELLIPSOIDS{ELLIPSOID_RECORD_BYTES};

        constexpr auto levelFields = [](auto& s, auto& l) {
            s.fields(l.first, l.count, l.scale, l.targetHeightPx, l.imageError, l.noiseThreshold, l.normalBlend);
        };

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
        if (std::string problem = LEVELS.countProblem(levels.size()); !problem.empty())
            return fail(label, name + ", levels", problem);
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
        w.fields(data.boundsMin, data.boundsMax, data.radiusUnit);
        writeArray(w, data.levels, LEVELS, levelFields);
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        writeArray(w, data.ellipsoids, ELLIPSOIDS, [&](ByteWriter& w, const Ellipsoid& e) {
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
            w.fields(e.colour[0], e.colour[1], e.colour[2], e.colour[3], e.leafWeight);
        });
        return w.take();
    }

    Result<EllipsoidTreeData> decodeEllipsoidTreeChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(ELLIPSOID_TREE_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        EllipsoidTreeData data;
        readFlags(r, KNOWN_FLAGS);
        r.setElement(name + ", bounds");
        r.fields(data.boundsMin, data.boundsMax, data.radiusUnit);
        r.setElement(name + ", levels");
        readArray(r, data.levels, LEVELS, levelFields);
        r.setElement(name + ", ellipsoids");
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        readArray(r, data.ellipsoids, ELLIPSOIDS, [&](ByteReader& r, Ellipsoid& e, std::uint32_t i) {
            for (int a = 0; a < 3; ++a)
                e.centre[a] = data.boundsMin[a] + extent[a] * (float(r.u16()) / 65535.0f);
            for (int a = 0; a < 3; ++a)
                e.radii[a] = radiusFromCode(r.u16(), data.radiusUnit);
            float q[4];
            for (float& c : q)
                c = float(std::int16_t(r.u16())) / 32767.0f;
            const float length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
            if (std::abs(length - 1.0f) > 0.02f)
            {
                r.setElement(name + ", ellipsoid " + std::to_string(i));
                r.failHere("rotation quaternion of length " + text(length) + " (1 within 2 % needed)");
                return;
            }
            e.rotation = glm::quat(q[3] / length, q[0] / length, q[1] / length, q[2] / length);
            r.fields(e.colour[0], e.colour[1], e.colour[2], e.colour[3], e.leafWeight);
        });
        return finishDecode(r, label, name, std::move(data));
    }
}
