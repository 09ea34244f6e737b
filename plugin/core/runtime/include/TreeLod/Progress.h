// Progress of long work (import, bake, render). Core code calls it; the CLI draws a
// bar on a terminal or prints a plain line per step otherwise.
#pragma once

#include <functional>
#include <string>

namespace TreeLod
{
    /// fraction in [0, 1] of the named step. May be empty: call through report(). A step named
    /// "warning: ..." is a message for the user (the CLI prints it whole, even when quiet).
    using ProgressCallback = std::function<void(const std::string& step, float fraction)>;

    inline void report(const ProgressCallback& cb, const std::string& step, float fraction)
    {
        if (cb)
            cb(step, fraction);
    }
}
