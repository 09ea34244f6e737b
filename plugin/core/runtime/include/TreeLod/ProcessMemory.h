// This process's resident memory, as the bench and the browser report it.
#pragma once

namespace TreeLod
{
    struct ResidentMemory
    {
        double currentMiB; ///< VmRSS
        double peakMiB;    ///< VmHWM: the most resident at any time so far
    };

    /// From /proc/self/status; NaN where it cannot be read (not Linux).
    ResidentMemory residentMemory();
}
