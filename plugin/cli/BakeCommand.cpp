// placeholder: being written
#include "Commands.h"

namespace TreeLod
{
    void addBakeCommand(CLI::App& app) { app.add_subcommand("bake", "(not yet implemented)"); }
}
