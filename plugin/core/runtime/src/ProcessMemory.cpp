#include "TreeLod/ProcessMemory.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

namespace TreeLod
{
    ResidentMemory residentMemory()
    {
        ResidentMemory memory{NAN, NAN};
        std::ifstream in("/proc/self/status");
        std::string line;
        while (std::getline(in, line))
        {
            if (line.rfind("VmRSS:", 0) == 0)
                memory.currentMiB = std::strtod(line.c_str() + 6, nullptr) / 1024.0;
            else if (line.rfind("VmHWM:", 0) == 0)
                memory.peakMiB = std::strtod(line.c_str() + 6, nullptr) / 1024.0;
        }
        return memory;
    }
}
