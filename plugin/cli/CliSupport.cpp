#include "CliSupport.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>

#include <unistd.h>

namespace TreeLod
{
    namespace
    {
        int gExitCode = EXIT_OK;
    }

    int printError(const Error& error)
    {
        std::fprintf(stderr, "treelod: %s\n", error.message().c_str());
        return EXIT_BAD_INPUT;
    }

    void setExitCode(int code) { gExitCode = code; }
    int exitCode() { return gExitCode; }

    ProgressCallback makeProgress(bool quiet)
    {
        // Steps named "warning: ..." are messages, printed whole even with -q.
        auto isWarning = [](const std::string& step) { return step.rfind("warning: ", 0) == 0; };
        if (quiet)
            return [isWarning](const std::string& step, float) {
                if (isWarning(step))
                    std::fprintf(stderr, "%s\n", step.c_str());
            };
        struct State
        {
            std::string step;
            int shown = -1;
        };
        auto state = std::make_shared<State>();
        const bool tty = isatty(fileno(stderr));
        return [state, tty, isWarning](const std::string& step, float fraction) {
            if (isWarning(step))
            {
                const bool midBar = tty && state->shown >= 0 && state->shown < 100;
                std::fprintf(stderr, "%s%s\n", midBar ? "\n" : "", step.c_str());
                return;
            }
            int percent = int(fraction * 100.0f + 0.5f);
            percent = percent < 0 ? 0 : (percent > 100 ? 100 : percent);
            if (tty)
            {
                if (step == state->step && percent == state->shown)
                    return;
                const int width = 30, filled = percent * width / 100;
                std::fprintf(stderr, "\r%-28.28s [%.*s%*s] %3d%%", step.c_str(), filled,
                             "##############################", width - filled, "", percent);
                if (percent == 100)
                    std::fputc('\n', stderr);
                std::fflush(stderr);
            }
            else if (step != state->step || (percent == 100 && state->shown != 100))
            {
                // Plain log: one line when a step starts and one when it completes.
                std::fprintf(stderr, "%s: %d%%\n", step.c_str(), percent);
            }
            state->step = step;
            state->shown = percent;
        };
    }

    std::vector<std::string> splitList(const std::string& text)
    {
        std::vector<std::string> out;
        std::stringstream in(text);
        std::string item;
        while (std::getline(in, item, ','))
            if (!item.empty())
                out.push_back(item);
        return out;
    }

    Result<void> parseSize(const std::string& text, int& width, int& height)
    {
        if (text.empty())
            return {};
        int w = 0, h = 0;
        char tail = 0;
        if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w <= 0 || h <= 0 || w > 16384 || h > 16384)
            return fail("", "--size", "'" + text + "' is not WxH with 1..16384");
        width = w;
        height = h;
        return {};
    }

    Result<std::vector<float>> parseLodBiases(const std::string& text)
    {
        std::vector<float> biases;
        for (const std::string& b : splitList(text))
        {
            char* end = nullptr;
            const double v = std::strtod(b.c_str(), &end);
            if (*end != '\0' || !(v > 0.0) || !std::isfinite(v))
                return fail("", "--lod-bias", "'" + b + "' is not a positive number");
            biases.push_back(float(v));
        }
        if (biases.empty())
            return fail("", "--lod-bias", "needs at least one value");
        return biases;
    }

    Result<std::vector<std::uint32_t>> parseMotionFrames(const std::string& text, std::uint32_t frames)
    {
        std::vector<std::uint32_t> motion;
        if (text == "all")
        {
            for (std::uint32_t f = 0; f < frames; ++f)
                motion.push_back(f);
            return motion;
        }
        char* end = nullptr;
        const unsigned long count = std::strtoul(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0' || !std::isdigit(static_cast<unsigned char>(text[0])))
            return fail("", "--motion-frames", "'" + text + "' is not 'all' or a frame count >= 0");
        const std::uint32_t n = std::uint32_t(std::min<unsigned long>(count, frames));
        for (std::uint32_t i = 0; i < n; ++i)
            motion.push_back(std::uint32_t((std::uint64_t(i) * 2 + 1) * frames / (2 * n)));
        return motion;
    }

    Result<void> applyShadowOptions(int size, double lodBias, SceneShadows& shadows)
    {
        if (!(lodBias >= 0.0) || !std::isfinite(lodBias))
            return fail("", "--shadow-lod-bias", std::to_string(lodBias) + " is not 0 (the script's) or finite and > 0");
        if (size != -1 && size != 0 && (size < 256 || size > 16384 || (size & (size - 1)) != 0))
            return fail("", "--shadow-size",
                        std::to_string(size) + " is not -1 (the script's), 0 (off) or a power of two in 256..16384");
        if (lodBias > 0.0)
            shadows.lodBias = float(lodBias);
        if (size == 0)
            shadows.enabled = false;
        else if (size > 0)
            shadows.textureSize = size;
        return {};
    }

    Result<void> applyWindOption(double strength, WindParameters& wind)
    {
        if (strength == -1.0)
            return {};
        if (!(strength >= 0.0 && strength <= 100.0))
            return fail("", "--wind", std::to_string(strength) + " is not -1 (the script's) or a strength in 0..100");
        wind.strength = float(strength);
        return {};
    }
}
