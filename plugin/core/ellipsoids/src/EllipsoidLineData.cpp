// EllipsoidLineData: the "ellipsoid-lines" chunk (layout and meaning in EllipsoidLineData.h).
#include "TreeLod/EllipsoidLineData.h"

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
        /// flags, box, unit, height and the three counts.
        constexpr std::size_t HEADER_BYTES = 4 + 24 + 4 + 4 + 4 + 4 + 4;
        constexpr std::size_t PALETTE_ENTRY_BYTES = 4;

        using EllipsoidQuantisation::finite;
        using EllipsoidQuantisation::text;

        std::uint16_t quantiseUnit(float t) { return EllipsoidQuantisation::unit(t); }

        std::uint16_t quantiseRadius(float radius, float unit)
        {
            return EllipsoidQuantisation::logLength(radius, unit, ELLIPSOID_LINE_RADIUS_LOG2_MIN,
                                                    ELLIPSOID_LINE_RADIUS_LOG2_SPAN);
        }

        float radiusFromCode(std::uint16_t q, float unit)
        {
            return EllipsoidQuantisation::lengthFromCode(q, unit, ELLIPSOID_LINE_RADIUS_LOG2_MIN,
                                                         ELLIPSOID_LINE_RADIUS_LOG2_SPAN);
        }

        std::string text(const glm::vec3& v) { return "(" + text(v.x) + ", " + text(v.y) + ", " + text(v.z) + ")"; }
    }

    std::size_t EllipsoidLineData::encodedBytes() const
    {
        return HEADER_BYTES + palette.size() * PALETTE_ENTRY_BYTES + levels.size() * ELLIPSOID_LINE_LEVEL_BYTES +
               lines.size() * ELLIPSOID_LINE_RECORD_BYTES;
    }

    float ellipsoidLineEndStep(const EllipsoidLineData& data, int axis)
    {
        return (data.boundsMax[axis] - data.boundsMin[axis]) / 65535.0f * 0.5f;
    }

    Result<void> EllipsoidLineData::validate(const std::string& label) const
    {
        const std::string name = chunkElement(ELLIPSOID_LINES_CHUNK, 0);
        if (!finite(boundsMin) || !finite(boundsMax) || !finite(boundsMax - boundsMin) ||
            glm::any(glm::lessThan(boundsMax, boundsMin)))
            return fail(label, name + ", bounds",
                        "line box " + text(boundsMin) + " .. " + text(boundsMax) + " is not finite with max >= min");
        if (!std::isfinite(radiusUnit) || !(radiusUnit > 0.0f))
            return fail(label, name + ", bounds", "radius unit " + text(radiusUnit) + " is not finite and > 0");
        if (!std::isfinite(heightMetres) || !(heightMetres > 0.0f))
            return fail(label, name + ", bounds", "tree height " + text(heightMetres) + " m is not finite and > 0");
        if (palette.empty() || palette.size() > ELLIPSOID_LINE_MAX_PALETTE)
            return fail(label, name + ", palette",
                        std::to_string(palette.size()) + " colours (1 to " +
                            std::to_string(ELLIPSOID_LINE_MAX_PALETTE) + " needed)");
        for (std::size_t c = 0; c < palette.size(); ++c)
            if (palette[c][3] != 255)
                return fail(label, name + ", palette entry " + std::to_string(c),
                            "alpha " + std::to_string(palette[c][3]) + " (255 needed)");
        if (levels.empty() || levels.size() > ELLIPSOID_LINE_MAX_LEVELS)
            return fail(label, name + ", levels",
                        std::to_string(levels.size()) + " levels (1 to " + std::to_string(ELLIPSOID_LINE_MAX_LEVELS) +
                            " needed)");
        std::uint64_t next = 0;
        for (std::size_t k = 0; k < levels.size(); ++k)
        {
            const EllipsoidLineLevel& l = levels[k];
            const std::string element = name + ", level " + std::to_string(k);
            if (l.first != next)
                return fail(label, element,
                            "starts at line " + std::to_string(l.first) + ", the previous level ends at " +
                                std::to_string(next) + " (levels must be contiguous, finest first)");
            if (l.count == 0)
                return fail(label, element, "has no lines");
            next += l.count;
            if (next > lines.size())
                return fail(label, element,
                            "lines " + std::to_string(l.first) + " + " + std::to_string(l.count) + " run past the " +
                                std::to_string(lines.size()) + " stored");
            if (!std::isfinite(l.targetHeightPx) || !(l.targetHeightPx > 0.0f))
                return fail(label, element, "target height " + text(l.targetHeightPx) + " px is not finite and > 0");
            if (!std::isfinite(l.imageError) || l.imageError < 0.0f || l.imageError > 1.0f)
                return fail(label, element, "image error " + text(l.imageError) + " is outside [0, 1]");
        }
        if (next != lines.size())
            return fail(label, name + ", levels",
                        "the levels cover " + std::to_string(next) + " of the " + std::to_string(lines.size()) +
                            " lines");
        // The box holds every end up to the rounding of its own corners.
        const glm::vec3 slack =
            1e-5f * (boundsMax - boundsMin) + 1e-6f * glm::max(glm::abs(boundsMin), glm::abs(boundsMax));
        for (std::size_t i = 0; i < lines.size(); ++i)
        {
            const EllipsoidLine& l = lines[i];
            const std::string element = name + ", line " + std::to_string(i);
            for (const glm::vec3* p : {&l.start, &l.end})
                if (!finite(*p) || glm::any(glm::lessThan(*p, boundsMin - slack)) ||
                    glm::any(glm::greaterThan(*p, boundsMax + slack)))
                    return fail(label, element,
                                std::string(p == &l.start ? "start " : "end ") + text(*p) +
                                    " is not finite inside the line box");
            if (!std::isfinite(l.radius) || !(l.radius > 0.0f))
                return fail(label, element, "radius " + text(l.radius) + " is not finite and > 0");
            if (l.colour >= palette.size())
                return fail(label, element,
                            "colour index " + std::to_string(l.colour) + " past the " + std::to_string(palette.size()) +
                                " palette entries");
        }
        return {};
    }

    std::vector<std::uint8_t> encodeEllipsoidLineChunk(const EllipsoidLineData& data)
    {
        ByteWriter w;
        w.reserve(data.encodedBytes());
        w.u32(KNOWN_FLAGS);
        w.vec3(data.boundsMin);
        w.vec3(data.boundsMax);
        w.f32(data.radiusUnit);
        w.f32(data.heightMetres);
        w.u32(std::uint32_t(data.palette.size()));
        for (const std::array<std::uint8_t, 4>& c : data.palette)
            for (std::uint8_t v : c)
                w.u8(v);
        w.u32(std::uint32_t(data.levels.size()));
        for (const EllipsoidLineLevel& l : data.levels)
        {
            w.u32(l.first);
            w.u32(l.count);
            w.f32(l.targetHeightPx);
            w.f32(l.imageError);
        }
        w.u32(std::uint32_t(data.lines.size()));
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        for (const EllipsoidLine& l : data.lines)
        {
            for (const glm::vec3& p : {l.start, l.end})
                for (int a = 0; a < 3; ++a)
                    w.u16(extent[a] > 0.0f ? quantiseUnit((p[a] - data.boundsMin[a]) / extent[a]) : 0);
            w.u16(quantiseRadius(l.radius, data.radiusUnit));
            w.u8(l.colour);
            w.u8(l.ambientOcclusion);
        }
        return w.take();
    }

    Result<EllipsoidLineData> decodeEllipsoidLineChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(ELLIPSOID_LINES_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        EllipsoidLineData data;
        const std::uint32_t flags = r.u32();
        if (r.ok() && (flags & ~KNOWN_FLAGS) != 0)
            r.failHere("unknown flags " + std::to_string(flags));
        r.setElement(name + ", bounds");
        data.boundsMin = r.vec3();
        data.boundsMax = r.vec3();
        data.radiusUnit = r.f32();
        data.heightMetres = r.f32();
        r.setElement(name + ", palette");
        const std::uint32_t paletteCount = r.count(PALETTE_ENTRY_BYTES);
        if (r.ok() && (paletteCount == 0 || paletteCount > ELLIPSOID_LINE_MAX_PALETTE))
            r.failHere(std::to_string(paletteCount) + " colours (1 to " + std::to_string(ELLIPSOID_LINE_MAX_PALETTE) +
                       " needed)");
        if (!r.ok())
            return r.error();
        data.palette.resize(paletteCount);
        for (std::array<std::uint8_t, 4>& c : data.palette)
            for (std::uint8_t& v : c)
                v = r.u8();
        r.setElement(name + ", levels");
        const std::uint32_t levelCount = r.count(ELLIPSOID_LINE_LEVEL_BYTES);
        if (r.ok() && (levelCount == 0 || levelCount > ELLIPSOID_LINE_MAX_LEVELS))
            r.failHere(std::to_string(levelCount) + " levels (1 to " + std::to_string(ELLIPSOID_LINE_MAX_LEVELS) +
                       " needed)");
        if (!r.ok())
            return r.error();
        data.levels.resize(levelCount);
        for (std::uint32_t k = 0; k < levelCount; ++k)
        {
            r.setElement(name + ", level " + std::to_string(k));
            EllipsoidLineLevel& l = data.levels[k];
            l.first = r.u32();
            l.count = r.u32();
            l.targetHeightPx = r.f32();
            l.imageError = r.f32();
        }
        r.setElement(name + ", lines");
        const std::uint32_t count = r.count(ELLIPSOID_LINE_RECORD_BYTES);
        if (!r.ok())
            return r.error();
        data.lines.resize(count);
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        for (std::uint32_t i = 0; i < count; ++i)
        {
            EllipsoidLine& l = data.lines[i];
            for (glm::vec3* p : {&l.start, &l.end})
                for (int a = 0; a < 3; ++a)
                    (*p)[a] = data.boundsMin[a] + extent[a] * (float(r.u16()) / 65535.0f);
            l.radius = radiusFromCode(r.u16(), data.radiusUnit);
            l.colour = r.u8();
            l.ambientOcclusion = r.u8();
        }
        return finishDecode(r, label, name, std::move(data));
    }
}
