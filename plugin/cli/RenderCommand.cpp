// placeholder: being written
#include "Commands.h"

namespace TreeLod
{
    void addRenderCommand(CLI::App& app) { app.add_subcommand("render", "(not yet implemented)"); }
}
