// treelod: generate, inspect, bake, render and compare trees (docs/architecture.md, "CLI").
#include "CliSupport.h"
#include "Commands.h"

int main(int argc, char** argv)
{
    CLI::App app{"TreeLod: level-of-detail trees for OGRE 1.12"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "treelod 0.1.0");
    TreeLod::addGenerateCommand(app);
    TreeLod::addInfoCommand(app);
    TreeLod::addBakeCommand(app);
    TreeLod::addRenderCommand(app);
    TreeLod::addBenchCommand(app);
    TreeLod::addCalibrateCommand(app);
    TreeLod::addCompareCommand(app);
    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        int rc = app.exit(e);
        return rc == 0 ? 0 : TreeLod::EXIT_BAD_INPUT;
    }
    return TreeLod::exitCode();
}
