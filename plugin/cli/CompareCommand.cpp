// placeholder: being written
#include "Commands.h"

namespace TreeLod
{
    void addCompareCommand(CLI::App& app) { app.add_subcommand("compare", "(not yet implemented)"); }
}
