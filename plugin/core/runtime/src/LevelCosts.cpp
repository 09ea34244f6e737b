#include "TreeLod/LevelCosts.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/Crc32.h"
#include "TreeLod/Package.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>

namespace TreeLod
{
    namespace
    {
        std::string hex16(std::uint64_t value)
        {
            char text[17];
            std::snprintf(text, sizeof(text), "%016" PRIx64, value);
            return text;
        }

        Result<LevelCost> parseLevel(const nlohmann::json& j, const std::string& path, const std::string& element)
        {
            if (!j.is_object() || !j.contains("technique") || !j["technique"].is_string() || !j.contains("level") ||
                !j["level"].is_number_unsigned() || !j.contains("heightsPx") || !j["heightsPx"].is_array() ||
                !j.contains("msPerTree") || !j["msPerTree"].is_array())
                return fail(path, element, "needs technique, level, heightsPx and msPerTree");
            LevelCost cost;
            cost.technique = j["technique"].get<std::string>();
            cost.techniqueLevel = j["level"].get<std::uint32_t>();
            cost.lowRes = j.value("lowRes", false);
            for (const nlohmann::json& v : j["heightsPx"])
                cost.heightsPx.push_back(v.is_number() ? v.get<float>() : NAN);
            for (const nlohmann::json& v : j["msPerTree"])
                cost.msPerTree.push_back(v.is_number() ? v.get<float>() : NAN);
            if (cost.technique.empty() || cost.heightsPx.empty() || cost.heightsPx.size() != cost.msPerTree.size())
                return fail(path, element, "needs a technique name and one msPerTree per height");
            for (std::size_t i = 0; i < cost.heightsPx.size(); ++i)
                if (!(std::isfinite(cost.heightsPx[i]) && cost.heightsPx[i] > 0.0f) ||
                    (i > 0 && !(cost.heightsPx[i] > cost.heightsPx[i - 1])) ||
                    !(std::isfinite(cost.msPerTree[i]) && cost.msPerTree[i] >= 0.0f))
                    return fail(path, element + " value " + std::to_string(i),
                                "heights must be finite, positive and increasing; costs finite and >= 0");
            return cost;
        }
    }

    float LevelCost::msAt(float heightPx) const
    {
        const std::size_t n = std::min(heightsPx.size(), msPerTree.size());
        if (n == 0)
            return 0.0f;
        if (n == 1 || std::isnan(heightPx) || heightPx <= heightsPx.front())
            return msPerTree.front();
        heightPx = std::min(heightPx, 1024.0f * heightsPx[n - 1]); // +inf: far past the last height
        // log(ms) against log(h) on the segment holding heightPx (the last one past the end); a
        // zero cost is floored so that its log exists.
        auto logMs = [&](std::size_t i) { return std::log(std::max(msPerTree[i], 1e-9f)); };
        std::size_t i = 1;
        while (i + 1 < n && heightsPx[i] < heightPx)
            ++i;
        const float t = std::log(heightPx / heightsPx[i - 1]) / std::log(heightsPx[i] / heightsPx[i - 1]);
        const float rise = logMs(i) - logMs(i - 1);
        if (t > 1.0f) // past the last height: from there, never falling
            return std::exp(logMs(i) + (t - 1.0f) * std::max(0.0f, rise));
        return std::exp(logMs(i - 1) + t * rise);
    }

    const std::vector<LevelCost>* CostCalibration::find(const std::string& assetKey) const
    {
        const auto it = assets.find(assetKey);
        return it == assets.end() ? nullptr : &it->second;
    }

    int findLevelCost(const std::vector<LevelCost>& levels, const std::string& technique, std::uint32_t techniqueLevel,
                      bool lowRes)
    {
        for (std::size_t i = 0; i < levels.size(); ++i)
            if (levels[i].technique == technique && levels[i].techniqueLevel == techniqueLevel &&
                levels[i].lowRes == lowRes)
                return int(i);
        return -1;
    }

    std::string costCalibrationPath(const std::string& directory, const std::string& renderer)
    {
        return directory + "/calibration-" + hex16(fnv1a64(renderer.data(), renderer.size())) + ".json";
    }

    Result<CostCalibration> readCostCalibration(const std::string& path, const std::string& renderer)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        const nlohmann::json j = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
        if (j.is_discarded() || !j.is_object() || !j.contains("renderer") || !j["renderer"].is_string() ||
            !j.contains("assets") || !j["assets"].is_object())
            return fail(path, "", "not a cost calibration (JSON with renderer and assets)");
        if (j.value("version", 0) != CostCalibration::VERSION)
            return fail(path, "version", "made by another version of the calibration");
        CostCalibration calibration;
        calibration.renderer = j["renderer"].get<std::string>();
        if (calibration.renderer != renderer)
            return fail(path, "renderer", "made on '" + calibration.renderer + "', not on this renderer '" + renderer + "'");
        for (const auto& [key, levels] : j["assets"].items())
        {
            if (!levels.is_array())
                return fail(path, "assets." + key, "not a list of levels");
            std::vector<LevelCost>& out = calibration.assets[key];
            for (std::size_t i = 0; i < levels.size(); ++i)
            {
                Result<LevelCost> level = parseLevel(levels[i], path, "assets." + key + "[" + std::to_string(i) + "]");
                if (!level)
                    return level.error();
                out.push_back(std::move(level.value()));
            }
        }
        if (j.contains("textureSampling"))
        {
            const nlohmann::json& t = j["textureSampling"];
            auto valid = [&](const char* name) {
                return t.is_object() && t.contains(name) && t[name].is_number() && std::isfinite(t[name].get<double>()) &&
                       t[name].get<double>() >= 0.0;
            };
            if (!valid("compressedMs") || !valid("decodedMs"))
                return fail(path, "textureSampling", "needs compressedMs and decodedMs, finite and >= 0");
            calibration.hasTextureSampling = true;
            calibration.textureSampling.compressedMs = t["compressedMs"].get<double>();
            calibration.textureSampling.decodedMs = t["decodedMs"].get<double>();
        }
        return calibration;
    }

    Result<void> writeCostCalibration(const std::string& path, const CostCalibration& calibration)
    {
        nlohmann::json assets = nlohmann::json::object();
        for (const auto& [key, levels] : calibration.assets)
        {
            nlohmann::json list = nlohmann::json::array();
            for (const LevelCost& level : levels)
                list.push_back({{"technique", level.technique},
                                {"level", level.techniqueLevel},
                                {"lowRes", level.lowRes},
                                {"heightsPx", level.heightsPx},
                                {"msPerTree", level.msPerTree}});
            assets[key] = list;
        }
        nlohmann::json j = {{"renderer", calibration.renderer}, {"version", CostCalibration::VERSION}, {"assets", assets}};
        if (calibration.hasTextureSampling)
            j["textureSampling"] = {{"compressedMs", calibration.textureSampling.compressedMs},
                                    {"decodedMs", calibration.textureSampling.decodedMs}};
        const std::string text = j.dump(1) + "\n";
        return writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
    }

    std::string assetCostKey(const PackageReader& package, const std::vector<std::string>& chunks)
    {
        std::string entries;
        for (const ChunkInfo& info : package.chunks())
            if (std::find(chunks.begin(), chunks.end(), info.technique) != chunks.end())
                entries += info.technique + "/" + std::to_string(info.level) + "/" +
                           std::to_string(info.formatVersion) + "/" + std::to_string(info.crc32) + ";";
        return hex16(fnv1a64(entries.data(), entries.size()));
    }
}
