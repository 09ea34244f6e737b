// placeholder: being written
#include "Commands.h"

namespace TreeLod
{
    void addGenerateCommand(CLI::App& app) { app.add_subcommand("generate", "(not yet implemented)"); }
}
