// placeholder: being written
#include "Commands.h"

namespace TreeLod
{
    void addInfoCommand(CLI::App& app) { app.add_subcommand("info", "(not yet implemented)"); }
}
