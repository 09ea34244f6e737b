#include "TreeLod/LodPolicy.h"

#include "TreeLod/ForestInstances.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace TreeLod
{
    LodPolicy LodPolicy::automatic(float errorBudget, float frameBudgetMs)
    {
        LodPolicy policy;
        policy.mode = Mode::Auto;
        policy.errorBudget = errorBudget;
        policy.frameBudgetMs = frameBudgetMs;
        return policy;
    }

    LodPolicy LodPolicy::fixed(std::string technique)
    {
        LodPolicy policy;
        policy.mode = Mode::Fixed;
        policy.technique = std::move(technique);
        return policy;
    }

    Result<LodPolicy> LodPolicy::parse(const std::string& text, const std::string& element)
    {
        // The last suffix first: "+fadeT", "+memMB", "+occB".
        struct Suffix
        {
            const char* key;
            double lo, hi;
            const char* what;
        };
        static const Suffix suffixes[] = {
            {"+fade", 0.0, ForestInstances::MAX_TRANSITION, "the transition after '+fade' must be in [0, 1] (0: hard switches)"},
            {"+mem", 0.0, 1e9, "the memory budget after '+mem' must be megabytes in [0, 1e9] (0: none)"},
            {"+occ", 0.0, 1.0, "occlusion after '+occ' must be 0 (off) or 1 (on)"}};
        const Suffix* last = nullptr;
        std::size_t at = 0;
        for (const Suffix& suffix : suffixes)
            if (const std::size_t found = text.rfind(suffix.key); found != std::string::npos && (!last || found > at))
            {
                last = &suffix;
                at = found;
            }
        if (last)
        {
            const std::string number = text.substr(at + std::strlen(last->key));
            char* end = nullptr;
            const double value = std::strtod(number.c_str(), &end);
            const bool occlusion = last == &suffixes[2];
            if (number.empty() || *end != '\0' || !(value >= last->lo && value <= last->hi) ||
                (occlusion && value != 0.0 && value != 1.0))
                return fail("", element, "'" + text + "': " + last->what);
            Result<LodPolicy> base = parse(text.substr(0, at), element);
            if (base)
                (last == &suffixes[0] ? base->transition : last == &suffixes[1] ? base->memoryBudgetMB : base->occlusion) =
                    float(value);
            return base;
        }
        if (text.empty())
            return scriptChoice();
        if (text == "auto")
            return automatic();
        const bool frame = text.rfind("auto~", 0) == 0;
        if (!frame && text.rfind("auto@", 0) != 0)
            return fixed(text);
        const std::string number = text.substr(5);
        char* end = nullptr;
        const double value = std::strtod(number.c_str(), &end);
        const bool isNumber = !number.empty() && *end == '\0';
        if (frame)
        {
            if (!isNumber || !(value > 0.0 && value <= 1e6))
                return fail("", element, "'" + text + "': the frame budget after 'auto~' must be milliseconds in (0, 1e6]");
            return automatic(std::numeric_limits<float>::quiet_NaN(), float(value));
        }
        if (!isNumber || !(value >= 0.0 && value <= 1.0))
            return fail("", element, "'" + text + "': the error budget after 'auto@' must be a mean FLIP in [0, 1]");
        return automatic(float(value));
    }

    std::string LodPolicy::toString() const
    {
        if (!std::isnan(transition))
        {
            LodPolicy base = *this;
            base.transition = std::numeric_limits<float>::quiet_NaN();
            char fade[32];
            std::snprintf(fade, sizeof fade, "+fade%g", double(transition));
            return base.toString() + fade;
        }
        if (!std::isnan(memoryBudgetMB))
        {
            LodPolicy base = *this;
            base.memoryBudgetMB = std::numeric_limits<float>::quiet_NaN();
            char memory[32];
            std::snprintf(memory, sizeof memory, "+mem%g", double(memoryBudgetMB));
            return base.toString() + memory;
        }
        if (!std::isnan(occlusion))
        {
            LodPolicy base = *this;
            base.occlusion = std::numeric_limits<float>::quiet_NaN();
            return base.toString() + (occlusion != 0.0f ? "+occ1" : "+occ0");
        }
        char text[48];
        switch (mode)
        {
        case Mode::Script:
            return "";
        case Mode::Fixed:
            return technique;
        case Mode::Auto:
            if (std::isfinite(frameBudgetMs))
                std::snprintf(text, sizeof text, "auto~%g", double(frameBudgetMs));
            else if (std::isfinite(errorBudget))
                std::snprintf(text, sizeof text, "auto@%g", double(errorBudget));
            else
                return "auto";
            return text;
        }
        return "";
    }

    bool LodPolicy::operator==(const LodPolicy& other) const
    {
        const auto same = [](float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); };
        return mode == other.mode && technique == other.technique && same(errorBudget, other.errorBudget) &&
               same(frameBudgetMs, other.frameBudgetMs) && same(transition, other.transition) &&
               same(memoryBudgetMB, other.memoryBudgetMB) && same(occlusion, other.occlusion);
    }
}
