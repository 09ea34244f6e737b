// ErrorCurves: the "error-curves" chunk (layout and meaning in ErrorCurves.h) and its descriptor.
#include "TreeLod/ErrorCurves.h"

#include "TreeLod/ByteReader.h"
#include "TreeLod/ByteWriter.h"
#include "TreeLod/Package.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <set>
#include <tuple>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t LOW_RES_FLAG = 1;
        constexpr float FLIP_MAX_TOLERANCE = 1e-6f;
        /// The fewest bytes a level takes: name length, a 1-byte name, level, flags.
        constexpr std::size_t MIN_LEVEL_BYTES = 4 + 1 + 4 + 4;

        std::string number(double v)
        {
            char text[32];
            std::snprintf(text, sizeof(text), "%g", v);
            return text;
        }

        bool validName(const std::string& name)
        {
            if (name.empty() || name.size() > PACKAGE_MAX_TECHNIQUE_NAME)
                return false;
            for (char c : name)
                if (c < 0x20 || c >= 0x7f)
                    return false;
            return true;
        }

        /// "error-curves level 3 '<technique>' 1200 low-res"; the name only when it is valid.
        std::string levelElement(std::size_t index, const ErrorCurveLevel& level)
        {
            std::string element = std::string(ERROR_CURVES_CHUNK) + " level " + std::to_string(index);
            if (validName(level.technique))
                element += " '" + level.technique + "' " + std::to_string(level.techniqueLevel) +
                           (level.lowRes ? " low-res" : "");
            return element;
        }

        std::string element(const std::string& what) { return std::string(ERROR_CURVES_CHUNK) + " " + what; }

        /// "error-curves level 1 'lodf' 0 to level 3 'impostor' 0": the pair of levels (a, b).
        std::string switchElement(const ErrorCurves& curves, std::size_t a, std::size_t b)
        {
            return levelElement(a, curves.levels[a]) + " to" +
                   levelElement(b, curves.levels[b]).substr(std::string(ERROR_CURVES_CHUNK).size());
        }

        /// What is wrong with `values` (one per height, in [0, 1]), "" when nothing; `at` names the value.
        std::string valuesProblem(const char* name, const std::vector<float>& values, std::size_t heights,
                                  std::string& at)
        {
            if (values.size() != heights)
            {
                at = name;
                return std::to_string(values.size()) + " values for " + std::to_string(heights) + " heights";
            }
            for (std::size_t i = 0; i < heights; ++i)
            {
                const float v = values[i];
                if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
                {
                    at = std::string(name) + "[" + std::to_string(i) + "]";
                    return number(v) + " outside [0, 1]";
                }
            }
            return {};
        }

        /// What is wrong with one level, "" when nothing; `at` names the value at fault.
        std::string levelProblem(const ErrorCurveLevel& level, std::size_t heights, std::string& at)
        {
            if (!validName(level.technique))
                return "technique name of " + std::to_string(level.technique.size()) +
                       " bytes (1.." + std::to_string(PACKAGE_MAX_TECHNIQUE_NAME) + " printable ASCII needed)";
            const std::pair<const char*, const std::vector<float>*> curves[] = {
                {"flip", &level.flip}, {"flipMax", &level.flipMax}, {"rmse", &level.rmse}};
            for (const auto& [name, values] : curves)
                if (std::string problem = valuesProblem(name, *values, heights, at); !problem.empty())
                    return problem;
            for (std::size_t i = 0; i < heights; ++i)
                if (level.flipMax[i] < level.flip[i] - FLIP_MAX_TOLERANCE)
                {
                    at = "flipMax[" + std::to_string(i) + "]";
                    return number(level.flipMax[i]) + " below the mean FLIP " + number(level.flip[i]);
                }
            return {};
        }

        /// `v` as the shortest decimal that reads back as the same float, so JSON shows 0.021, not
        /// 0.020999999716877937.
        double shortest(float v)
        {
            char text[32];
            for (int digits = 1; digits <= 9; ++digits)
            {
                std::snprintf(text, sizeof(text), "%.*g", digits, double(v));
                if (std::strtof(text, nullptr) == v)
                    break;
            }
            return std::strtod(text, nullptr);
        }

        nlohmann::json floats(const std::vector<float>& values)
        {
            nlohmann::json out = nlohmann::json::array();
            for (float v : values)
                out.push_back(shortest(v));
            return out;
        }

        Result<ChunkSummary> inspectVersion(const std::vector<std::uint8_t>& bytes, const std::string& label,
                                            std::uint32_t formatVersion)
        {
            Result<ErrorCurves> decoded = decodeErrorCurves(bytes, label, formatVersion);
            if (!decoded)
                return decoded.error();
            const ErrorCurves& c = decoded.value();
            const std::size_t n = c.heightsPx.size();

            // The largest measured height and every second one below it, three at most.
            std::vector<std::size_t> shown;
            for (std::size_t k = 0; k < 3 && 2 * k < n; ++k)
                shown.insert(shown.begin(), n - 1 - 2 * k);
            std::string text = std::to_string(c.levels.size()) + (c.levels.size() == 1 ? " level x " : " levels x ") +
                               std::to_string(n) + (n == 1 ? " height (" : " heights (") + number(c.heightsPx[0]) +
                               (n == 1 ? "" : "-" + number(c.heightsPx.back())) + " px), " + std::to_string(c.views) +
                               (c.views == 1 ? " view" : " views") +
                               (c.switchFlip.empty() ? "" : ", switch FLIP of " + std::to_string(c.switchFlip.size()) +
                                                                (c.switchFlip.size() == 1 ? " pair" : " pairs")) +
                               (c.hasGpuBytes() ? ", GPU bytes of " + std::to_string(c.resourceBytes.size()) + " resources"
                                                : std::string()) +
                               "; FLIP at ";
            for (std::size_t k = 0; k < shown.size(); ++k)
                text += (k ? "/" : "") + number(c.heightsPx[shown[k]]);
            text += " px:";
            constexpr std::size_t LISTED = 8;
            for (std::size_t l = 0; l < c.levels.size() && l < LISTED; ++l)
            {
                const ErrorCurveLevel& level = c.levels[l];
                // The technique's level only where the technique has several.
                const bool several =
                    std::count_if(c.levels.begin(), c.levels.end(), [&](const ErrorCurveLevel& other) {
                        return other.technique == level.technique;
                    }) > 1;
                text += (l ? ", " : " ") + level.technique;
                if (several)
                    text += " " + std::to_string(level.techniqueLevel) + (level.lowRes ? " low-res" : "");
                else if (level.lowRes)
                    text += " low-res";
                for (std::size_t k = 0; k < shown.size(); ++k)
                {
                    char value[16];
                    std::snprintf(value, sizeof(value), "%.3f", double(level.flip[shown[k]]));
                    text += (k ? "/" : " ") + std::string(value);
                }
                if (c.hasGpuBytes())
                {
                    char bytes[32];
                    std::snprintf(bytes, sizeof(bytes), " (%.2f MB)", double(c.gpuBytes({l})) / 1e6);
                    text += bytes;
                }
            }
            if (c.levels.size() > LISTED)
                text += ", ...";

            nlohmann::json curves = nlohmann::json::array();
            for (const ErrorCurveLevel& level : c.levels)
                curves.push_back({{"technique", level.technique},
                                  {"level", level.techniqueLevel},
                                  {"lowRes", level.lowRes},
                                  {"flip", floats(level.flip)},
                                  {"flipMax", floats(level.flipMax)},
                                  {"rmse", floats(level.rmse)},
                                  {"gpuBytes", c.hasGpuBytes() ? nlohmann::json(c.gpuBytes({std::size_t(&level - c.levels.data())}))
                                                               : nlohmann::json(nullptr)}});
            nlohmann::json switches = nlohmann::json::array();
            for (std::size_t a = 0; a < c.levels.size() && !c.switchFlip.empty(); ++a)
                for (std::size_t b = a + 1; b < c.levels.size(); ++b)
                    switches.push_back({{"levels", {a, b}}, {"flip", floats(c.switchFlip[c.switchPair(a, b)])}});
            ChunkSummary summary;
            summary.text = text;
            summary.json = nlohmann::json{{"levels", c.levels.size()},
                                          {"heightsPx", floats(c.heightsPx)},
                                          {"views", c.views},
                                          {"referenceSamples", c.referenceSamples},
                                          {"curves", curves},
                                          {"switchFlip", switches},
                                          {"resourceBytes", c.resourceBytes}}
                               .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
            return summary;
        }

        Result<ChunkSummary> inspect(const std::vector<std::uint8_t>& bytes, const std::string& label)
        {
            return inspectVersion(bytes, label, ERROR_CURVES_FORMAT_VERSION);
        }

        void fuzz(const std::vector<std::uint8_t>& bytes)
        {
            Result<ErrorCurves> decoded = decodeErrorCurves(bytes, "fuzz");
            if (!decoded)
                return;
            const ErrorCurves& c = decoded.value();
            // What a level picker reads: each level found by its name, its FLIP at any height.
            std::vector<float> heights = {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
                                          std::numeric_limits<float>::infinity(), 0.5f, 1e30f, FLT_MAX};
            for (std::size_t i = 0; i < c.heightsPx.size(); ++i)
            {
                heights.push_back(c.heightsPx[i]);
                heights.push_back(std::nextafter(c.heightsPx[i], 0.0f));
                if (i + 1 < c.heightsPx.size())
                    heights.push_back(0.5f * (c.heightsPx[i] + c.heightsPx[i + 1]));
            }
            for (std::size_t l = 0; l < c.levels.size(); ++l)
            {
                const ErrorCurveLevel& level = c.levels[l];
                if (c.find(level.technique, level.techniqueLevel, level.lowRes) != int(l))
                    __builtin_trap();
                for (float h : heights)
                {
                    const float v = c.flipAt(l, h);
                    if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
                        __builtin_trap();
                    // What the selection reads at a switch: a FLIP, or unknown without switch data.
                    for (std::size_t other = 0; other < c.levels.size(); other += 1 + c.levels.size() / 8)
                    {
                        const float s = c.switchFlipAt(l, other, h);
                        if (s != c.switchFlipAt(other, l, h) ||
                            !(c.hasSwitchFlip() || l == other ? s >= 0.0f && s <= 1.0f : s == SWITCH_FLIP_UNKNOWN))
                            __builtin_trap();
                    }
                }
            }
        }
    }

    int ErrorCurves::find(const std::string& technique, std::uint32_t techniqueLevel, bool lowRes) const
    {
        for (std::size_t i = 0; i < levels.size(); ++i)
            if (levels[i].technique == technique && levels[i].techniqueLevel == techniqueLevel &&
                levels[i].lowRes == lowRes)
                return int(i);
        return -1;
    }

    namespace
    {
        /// `values` (one per height) at `heightPx`, as ErrorCurves::flipAt says.
        float interpolateAt(const std::vector<float>& heightsPx, const std::vector<float>& values, float heightPx)
        {
            if (values.empty() || heightsPx.empty())
                return 0.0f;
            const std::size_t n = std::min(values.size(), heightsPx.size());
            if (!std::isfinite(heightPx) || !(heightPx > 0.0f) || heightPx <= heightsPx[0])
                return values[0];
            if (heightPx >= heightsPx[n - 1])
                return values[n - 1];
            // heightsPx[i - 1] <= heightPx < heightsPx[i], 1 <= i <= n - 1.
            const std::size_t i =
                std::size_t(std::upper_bound(heightsPx.begin(), heightsPx.begin() + std::ptrdiff_t(n), heightPx) -
                            heightsPx.begin());
            const double a = std::log2(double(heightsPx[i - 1])), b = std::log2(double(heightsPx[i]));
            const double t = (std::log2(double(heightPx)) - a) / (b - a);
            if (!std::isfinite(t))
                return values[i - 1];
            const double lo = values[i - 1], hi = values[i];
            const double v = lo + std::clamp(t, 0.0, 1.0) * (hi - lo);
            return float(std::clamp(v, std::min(lo, hi), std::max(lo, hi)));
        }
    }

    float ErrorCurves::flipAt(std::size_t level, float heightPx) const
    {
        return level < levels.size() ? interpolateAt(heightsPx, levels[level].flip, heightPx) : 0.0f;
    }

    float ErrorCurves::flipMaxAt(std::size_t level, float heightPx) const
    {
        return level < levels.size() ? interpolateAt(heightsPx, levels[level].flipMax, heightPx) : 0.0f;
    }

    float ErrorCurves::switchFlipAt(std::size_t a, std::size_t b, float heightPx) const
    {
        if (a >= levels.size() || b >= levels.size())
            return SWITCH_FLIP_UNKNOWN;
        if (a == b)
            return 0.0f;
        if (!hasSwitchFlip())
            return SWITCH_FLIP_UNKNOWN;
        return interpolateAt(heightsPx, switchFlip[switchPair(std::min(a, b), std::max(a, b))], heightPx);
    }

    std::uint64_t ErrorCurves::gpuBytes(const std::vector<std::size_t>& levelIndices) const
    {
        std::vector<bool> counted(resourceBytes.size(), false);
        std::uint64_t bytes = 0;
        for (std::size_t l : levelIndices)
            if (l < levels.size())
                for (std::uint32_t r : levels[l].resources)
                    if (r < counted.size() && !counted[r])
                    {
                        counted[r] = true;
                        bytes += resourceBytes[r];
                    }
        return bytes;
    }

    void ErrorCurves::keepLevels(const std::vector<bool>& keep)
    {
        std::vector<std::size_t> kept;
        for (std::size_t l = 0; l < levels.size() && l < keep.size(); ++l)
            if (keep[l])
                kept.push_back(l);
        std::vector<std::vector<float>> switches;
        for (std::size_t a = 0; a < kept.size() && hasSwitchFlip(); ++a)
            for (std::size_t b = a + 1; b < kept.size(); ++b)
                switches.push_back(std::move(switchFlip[switchPair(kept[a], kept[b])]));
        std::vector<ErrorCurveLevel> keptLevels;
        for (std::size_t l : kept)
            keptLevels.push_back(std::move(levels[l]));
        levels = std::move(keptLevels);
        switchFlip = std::move(switches);
    }

    Result<void> validateErrorCurves(const ErrorCurves& curves, const std::string& label)
    {
        const std::size_t n = curves.heightsPx.size();
        if (n < 1 || n > ERROR_CURVES_MAX_HEIGHTS)
            return fail(label, element("heights"),
                        std::to_string(n) + " heights (1.." + std::to_string(ERROR_CURVES_MAX_HEIGHTS) + " allowed)");
        for (std::size_t i = 0; i < n; ++i)
        {
            const float h = curves.heightsPx[i];
            const std::string at = element("heights[" + std::to_string(i) + "]");
            if (!std::isfinite(h) || h < ERROR_CURVES_MIN_HEIGHT_PX || h > ERROR_CURVES_MAX_HEIGHT_PX)
                return fail(label, at,
                            number(h) + " px outside [" + number(ERROR_CURVES_MIN_HEIGHT_PX) + ", " +
                                number(ERROR_CURVES_MAX_HEIGHT_PX) + "]");
            if (i > 0 && !(h > curves.heightsPx[i - 1]))
                return fail(label, at,
                            number(h) + " px after " + number(curves.heightsPx[i - 1]) +
                                " px (strictly increasing needed)");
        }
        if (curves.views < 1)
            return fail(label, element("views"), "0 views (at least 1 needed)");
        if (curves.referenceSamples < 1)
            return fail(label, element("reference samples"), "0 reference samples per pixel (at least 1 needed)");
        if (curves.levels.empty() || curves.levels.size() > ERROR_CURVES_MAX_LEVELS)
            return fail(label, element("levels"),
                        std::to_string(curves.levels.size()) + " levels (1.." +
                            std::to_string(ERROR_CURVES_MAX_LEVELS) + " allowed)");
        std::set<std::tuple<std::string, std::uint32_t, bool>> seen;
        for (std::size_t l = 0; l < curves.levels.size(); ++l)
        {
            const ErrorCurveLevel& level = curves.levels[l];
            std::string at;
            const std::string problem = levelProblem(level, n, at);
            if (!problem.empty())
                return fail(label, levelElement(l, level) + (at.empty() ? "" : " " + at), problem);
            if (!seen.emplace(level.technique, level.techniqueLevel, level.lowRes).second)
                return fail(label, levelElement(l, level),
                            "the same level as level " +
                                std::to_string(curves.find(level.technique, level.techniqueLevel, level.lowRes)));
        }
        const std::size_t pairs = ErrorCurves::switchPairs(curves.levels.size());
        if (!curves.switchFlip.empty() && curves.switchFlip.size() != pairs)
            return fail(label, element("switchFlip"),
                        std::to_string(curves.switchFlip.size()) + " pairs of levels for " +
                            std::to_string(curves.levels.size()) + " levels (0 or " + std::to_string(pairs) +
                            " needed)");
        for (std::size_t a = 0; a < curves.levels.size() && !curves.switchFlip.empty(); ++a)
            for (std::size_t b = a + 1; b < curves.levels.size(); ++b)
            {
                std::string at;
                const std::string problem =
                    valuesProblem("switchFlip", curves.switchFlip[curves.switchPair(a, b)], n, at);
                if (!problem.empty())
                    return fail(label, switchElement(curves, a, b) + " " + at, problem);
            }
        if (curves.resourceBytes.size() > ERROR_CURVES_MAX_RESOURCES)
            return fail(label, element("resources"),
                        std::to_string(curves.resourceBytes.size()) + " GPU resources (at most " +
                            std::to_string(ERROR_CURVES_MAX_RESOURCES) + ")");
        for (std::size_t l = 0; l < curves.levels.size(); ++l)
        {
            const std::vector<std::uint32_t>& resources = curves.levels[l].resources;
            for (std::size_t i = 0; i < resources.size(); ++i)
            {
                const std::string at = levelElement(l, curves.levels[l]) + " resources[" + std::to_string(i) + "]";
                if (resources[i] >= curves.resourceBytes.size())
                    return fail(label, at,
                                "resource " + std::to_string(resources[i]) + " of a table of " +
                                    std::to_string(curves.resourceBytes.size()));
                if (i > 0 && resources[i] <= resources[i - 1])
                    return fail(label, at,
                                "resource " + std::to_string(resources[i]) + " after " +
                                    std::to_string(resources[i - 1]) + " (strictly increasing needed)");
            }
        }
        return {};
    }

    std::vector<std::uint8_t> encodeErrorCurves(const ErrorCurves& curves)
    {
        ByteWriter w;
        const std::size_t n = curves.heightsPx.size();
        w.reserve(20 + 4 * n + curves.levels.size() * (MIN_LEVEL_BYTES + 32 + 12 * n) +
                  curves.switchFlip.size() * 4 * n);
        w.u32(std::uint32_t(n));
        w.u32(std::uint32_t(curves.levels.size()));
        w.u32(curves.views);
        w.u32(curves.referenceSamples);
        for (float h : curves.heightsPx)
            w.f32(h);
        for (const ErrorCurveLevel& level : curves.levels)
        {
            w.string(level.technique);
            w.u32(level.techniqueLevel);
            w.u32(level.lowRes ? LOW_RES_FLAG : 0);
            for (const std::vector<float>* values : {&level.flip, &level.flipMax, &level.rmse})
                for (float v : *values)
                    w.f32(v);
        }
        w.u32(std::uint32_t(curves.switchFlip.size()));
        for (const std::vector<float>& values : curves.switchFlip)
            for (float v : values)
                w.f32(v);
        w.u32(std::uint32_t(curves.resourceBytes.size()));
        if (!curves.resourceBytes.empty())
        {
            for (std::uint64_t bytes : curves.resourceBytes)
                w.u64(bytes);
            for (const ErrorCurveLevel& level : curves.levels)
            {
                w.u32(std::uint32_t(level.resources.size()));
                for (std::uint32_t r : level.resources)
                    w.u32(r);
            }
        }
        return w.take();
    }

    Result<ErrorCurves> decodeErrorCurves(const std::vector<std::uint8_t>& bytes, const std::string& label,
                                          std::uint32_t formatVersion)
    {
        if (formatVersion < ERROR_CURVES_OLDEST_FORMAT_VERSION || formatVersion > ERROR_CURVES_FORMAT_VERSION)
            return fail(label, ERROR_CURVES_CHUNK,
                        "format version " + std::to_string(formatVersion) + ", this build reads " +
                            std::to_string(ERROR_CURVES_OLDEST_FORMAT_VERSION) + ".." +
                            std::to_string(ERROR_CURVES_FORMAT_VERSION));
        ByteReader r(bytes.data(), bytes.size(), label, element("header"));
        const std::uint32_t heightCount = r.u32();
        const std::uint32_t levelCount = r.u32();
        ErrorCurves curves;
        curves.views = r.u32();
        curves.referenceSamples = r.u32();
        if (!r.ok())
            return r.error();
        // The counts, within their limits and the bytes left, before anything is allocated.
        if (heightCount < 1 || heightCount > ERROR_CURVES_MAX_HEIGHTS)
            return fail(label, element("heights"),
                        std::to_string(heightCount) + " heights (1.." + std::to_string(ERROR_CURVES_MAX_HEIGHTS) +
                            " allowed)");
        if (levelCount < 1 || levelCount > ERROR_CURVES_MAX_LEVELS)
            return fail(label, element("levels"),
                        std::to_string(levelCount) + " levels (1.." + std::to_string(ERROR_CURVES_MAX_LEVELS) +
                            " allowed)");
        const std::size_t needed = 4 * std::size_t(heightCount) +
                                   std::size_t(levelCount) * (MIN_LEVEL_BYTES + 12 * std::size_t(heightCount));
        if (needed > r.remaining())
            return fail(label, element("levels"),
                        "truncated: " + std::to_string(levelCount) + " levels of " + std::to_string(heightCount) +
                            " heights need at least " + std::to_string(needed) + " bytes, chunk has " +
                            std::to_string(r.remaining()) + " left");

        r.setElement(element("heights"));
        curves.heightsPx.resize(heightCount);
        for (float& h : curves.heightsPx)
            h = r.f32();
        curves.levels.resize(levelCount);
        for (std::uint32_t l = 0; l < levelCount && r.ok(); ++l)
        {
            ErrorCurveLevel& level = curves.levels[l];
            r.setElement(element("level " + std::to_string(l)));
            level.technique = r.string(PACKAGE_MAX_TECHNIQUE_NAME);
            level.techniqueLevel = r.u32();
            const std::uint32_t flags = r.u32();
            level.lowRes = (flags & LOW_RES_FLAG) != 0;
            r.setElement(levelElement(l, level));
            if (r.ok() && (flags & ~LOW_RES_FLAG) != 0)
                r.failHere("unknown flags " + std::to_string(flags));
            for (std::vector<float>* values : {&level.flip, &level.flipMax, &level.rmse})
            {
                values->resize(heightCount);
                for (float& v : *values)
                    v = r.f32();
            }
        }
        if (!r.ok())
            return r.error();
        if (formatVersion >= 2) // the switch section
        {
            r.setElement(element("switchFlip"));
            const std::uint32_t pairs = r.u32();
            const std::size_t expected = ErrorCurves::switchPairs(levelCount);
            if (r.ok() && pairs != 0 && pairs != expected)
                return fail(label, element("switchFlip"),
                            std::to_string(pairs) + " pairs of levels for " + std::to_string(levelCount) +
                                " levels (0 or " + std::to_string(expected) + " needed)");
            if (r.ok() && 4 * std::size_t(heightCount) * pairs > r.remaining())
                return fail(label, element("switchFlip"),
                            "truncated: " + std::to_string(pairs) + " pairs of " + std::to_string(heightCount) +
                                " heights need " + std::to_string(4 * std::size_t(heightCount) * pairs) +
                                " bytes, chunk has " + std::to_string(r.remaining()) + " left");
            curves.switchFlip.resize(r.ok() ? pairs : 0);
            for (std::vector<float>& values : curves.switchFlip)
            {
                values.resize(heightCount);
                for (float& v : values)
                    v = r.f32();
            }
            if (!r.ok())
                return r.error();
        }
        if (formatVersion >= 3) // the GPU resources
        {
            r.setElement(element("resources"));
            const std::uint32_t count = r.u32();
            if (r.ok() && count > ERROR_CURVES_MAX_RESOURCES)
                return fail(label, element("resources"),
                            std::to_string(count) + " GPU resources (at most " +
                                std::to_string(ERROR_CURVES_MAX_RESOURCES) + ")");
            if (r.ok() && count > 0 && 8 * std::size_t(count) + 4 * std::size_t(levelCount) > r.remaining())
                return fail(label, element("resources"),
                            "truncated: " + std::to_string(count) + " resources and " + std::to_string(levelCount) +
                                " levels' lists need at least " +
                                std::to_string(8 * std::size_t(count) + 4 * std::size_t(levelCount)) +
                                " bytes, chunk has " + std::to_string(r.remaining()) + " left");
            curves.resourceBytes.resize(r.ok() ? count : 0);
            for (std::uint64_t& bytes : curves.resourceBytes)
                bytes = r.u64();
            for (std::uint32_t l = 0; l < levelCount && r.ok() && count > 0; ++l)
            {
                ErrorCurveLevel& level = curves.levels[l];
                r.setElement(levelElement(l, level) + " resources");
                const std::uint32_t k = r.u32();
                if (r.ok() && (k > count || 4 * std::size_t(k) > r.remaining()))
                    return fail(label, levelElement(l, level) + " resources",
                                std::to_string(k) + " resources of a table of " + std::to_string(count) + " with " +
                                    std::to_string(r.remaining()) + " bytes left");
                level.resources.resize(r.ok() ? k : 0);
                for (std::uint32_t& index : level.resources)
                    index = r.u32();
            }
            if (!r.ok())
                return r.error();
        }
        if (r.remaining() != 0)
            return fail(label, ERROR_CURVES_CHUNK, std::to_string(r.remaining()) + " trailing bytes");
        Result<void> valid = validateErrorCurves(curves, label);
        if (!valid)
            return valid.error();
        return curves;
    }

    TechniqueDescriptor errorCurvesDescriptor()
    {
        return {ERROR_CURVES_CHUNK,
                "image error against screen height of every Forest level (FLIP, multi-scale RMSE), measured at bake "
                "time",
                ERROR_CURVES_FORMAT_VERSION, &inspect, &fuzz, ERROR_CURVES_OLDEST_FORMAT_VERSION, &inspectVersion};
    }
}
