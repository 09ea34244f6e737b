// The baker registry of BakeTechniques.h.
#include "TreeLod/BakeTechniques.h"

#include "TreeLod/Package.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace TreeLod
{
    namespace
    {
        Result<void> bakeReference(PackageWriter& writer, const TreeModel& model, const BakeOptions&,
                                   const std::string& label, const ProgressCallback& progress)
        {
            return addReferenceChunk(writer, model, label, progress);
        }

        std::vector<BakeTechnique>& registry()
        {
            static std::vector<BakeTechnique> techniques = {
                {REFERENCE_CHUNK, "the polygonal tree with GPU-ready mip-mapped textures", &bakeReference, {}}};
            return techniques;
        }

        std::string formatNumber(double value)
        {
            char text[32];
            std::snprintf(text, sizeof text, "%g", value);
            return text;
        }

        std::string optionElement(const std::string& technique, const std::string& name)
        {
            return "option '" + technique + "." + name + "'";
        }
    }

    Result<void> checkBakeOptions(const BakeTechnique& technique, const BakeOptions& options, const std::string& label)
    {
        for (const auto& given : options)
        {
            bool known = false;
            std::string list;
            for (const BakeOptionInfo& option : technique.options)
            {
                known = known || option.name == given.first;
                list += (list.empty() ? "" : ", ") + option.name;
            }
            if (!known)
                return fail(label, optionElement(technique.name, given.first),
                            "not an option of " + std::string(technique.name) +
                                (list.empty() ? " (it has none)" : " (known: " + list + ")"));
        }
        return {};
    }

    Result<double> bakeOptionNumber(const BakeOptions& options, const std::string& technique, const std::string& name,
                                    double fallback, double lo, double hi, const std::string& label)
    {
        auto it = options.find(name);
        if (it == options.end())
            return fallback;
        char* end = nullptr;
        const double value = std::strtod(it->second.c_str(), &end);
        if (it->second.empty() || *end != '\0' || !(value >= lo && value <= hi))
            return fail(label, optionElement(technique, name),
                        "'" + it->second + "' is not a number in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]");
        return value;
    }

    Result<bool> bakeOptionFlag(const BakeOptions& options, const std::string& technique, const std::string& name,
                                bool fallback, const std::string& label)
    {
        auto it = options.find(name);
        if (it == options.end())
            return fallback;
        if (it->second != "true" && it->second != "false")
            return fail(label, optionElement(technique, name), "'" + it->second + "' is not true or false");
        return it->second == "true";
    }

    void registerBakeTechnique(const BakeTechnique& technique)
    {
        std::vector<BakeTechnique>& all = registry();
        const std::string name = technique.name;
        auto same = std::find_if(all.begin(), all.end(), [&](const BakeTechnique& t) { return name == t.name; });
        if (same != all.end())
        {
            *same = technique;
            return;
        }
        auto at = std::find_if(all.begin() + 1, all.end(), [&](const BakeTechnique& t) { return name < t.name; });
        all.insert(at, technique);
    }

    const std::vector<BakeTechnique>& bakeTechniques() { return registry(); }

    const BakeTechnique* findBakeTechnique(const std::string& name)
    {
        for (const BakeTechnique& t : registry())
            if (name == t.name)
                return &t;
        return nullptr;
    }

    Result<BakeOptionAssignment> parseBakeOptionAssignment(const std::string& text)
    {
        const std::size_t dot = text.find('.'), equals = text.find('=');
        if (dot == std::string::npos || equals == std::string::npos || dot > equals)
            return fail("", "option --option '" + text + "'", "expected TECHNIQUE.NAME=VALUE");
        return BakeOptionAssignment{text.substr(0, dot), text.substr(dot + 1, equals - dot - 1), text.substr(equals + 1)};
    }

    std::string knownBakeTechniques()
    {
        std::string list;
        for (const BakeTechnique& t : registry())
            list += (list.empty() ? "" : ", ") + std::string(t.name);
        return list;
    }
}
