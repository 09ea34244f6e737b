#include "CliSupport.h"

#include <cstdio>
#include <memory>

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
}
