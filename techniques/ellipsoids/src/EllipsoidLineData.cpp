// EllipsoidLineData: the "ellipsoid-lines" chunk (layout and meaning in EllipsoidLineData.h).
#include "TreeLod/EllipsoidLineData.h"

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
        /// flags, box, unit, height and the three counts.
        constexpr std::size_t HEADER_BYTES = 4 + 24 + 4 + 4 + 4 + 4 + 4;
        constexpr ArrayLayout PALETTE{4, 1, 1, ELLIPSOID_LINE_MAX_PALETTE, "colours"};
        constexpr ArrayLayout LEVELS{ELLIPSOID_LINE_LEVEL_BYTES, 1, 1, ELLIPSOID_LINE_MAX_LEVELS, "levels"};
        constexpr ArrayLayout LINES{ELLIPSOID_LINE_RECORD_BYTES};

        constexpr auto colourFields = [](auto& s, auto& c) { s.fields(c[0], c[1], c[2], c[3]); };
        constexpr auto levelFields = [](auto& s, auto& l) { s.fields(l.first, l.count, l.targetHeightPx, l.imageError); };

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
        return HEADER_BYTES + palette.size() * PALETTE.recordBytes + levels.size() * ELLIPSOID_LINE_LEVEL_BYTES +
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
        if (std::string problem = PALETTE.countProblem(palette.size()); !problem.empty())
            return fail(label, name + ", palette", problem);
        for (std::size_t c = 0; c < palette.size(); ++c)
            if (palette[c][3] != 255)
                return fail(label, name + ", palette entry " + std::to_string(c),
                            "alpha " + std::to_string(palette[c][3]) + " (255 needed)");
        if (std::string problem = LEVELS.countProblem(levels.size()); !problem.empty())
            return fail(label, name + ", levels", problem);
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
        w.fields(data.boundsMin, data.boundsMax, data.radiusUnit, data.heightMetres);
        writeArray(w, data.palette, PALETTE, colourFields);
        writeArray(w, data.levels, LEVELS, levelFields);
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        writeArray(w, data.lines, LINES, [&](ByteWriter& w, const EllipsoidLine& l) {
            for (const glm::vec3& p : {l.start, l.end})
                for (int a = 0; a < 3; ++a)
                    w.u16(extent[a] > 0.0f ? quantiseUnit((p[a] - data.boundsMin[a]) / extent[a]) : 0);
            w.u16(quantiseRadius(l.radius, data.radiusUnit));
            w.fields(l.colour, l.ambientOcclusion);
        });
        return w.take();
    }

    Result<EllipsoidLineData> decodeEllipsoidLineChunk(const std::vector<std::uint8_t>& bytes, const std::string& label)
    {
        const std::string name = chunkElement(ELLIPSOID_LINES_CHUNK, 0);
        ByteReader r(bytes.data(), bytes.size(), label, name);
        EllipsoidLineData data;
        readFlags(r, KNOWN_FLAGS);
        r.setElement(name + ", bounds");
        r.fields(data.boundsMin, data.boundsMax, data.radiusUnit, data.heightMetres);
        r.setElement(name + ", palette");
        readArray(r, data.palette, PALETTE, colourFields);
        r.setElement(name + ", levels");
        readArray(r, data.levels, LEVELS, levelFields);
        r.setElement(name + ", lines");
        const glm::vec3 extent = data.boundsMax - data.boundsMin;
        readArray(r, data.lines, LINES, [&](ByteReader& r, EllipsoidLine& l) {
            for (glm::vec3* p : {&l.start, &l.end})
                for (int a = 0; a < 3; ++a)
                    (*p)[a] = data.boundsMin[a] + extent[a] * (float(r.u16()) / 65535.0f);
            l.radius = radiusFromCode(r.u16(), data.radiusUnit);
            r.fields(l.colour, l.ambientOcclusion);
        });
        return finishDecode(r, label, name, std::move(data));
    }
}
