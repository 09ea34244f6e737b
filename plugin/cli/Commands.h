// The `treelod` subcommands. Each add*Command registers one subcommand on the app;
// its callback returns the process exit code through CliSupport's runCommand().
#pragma once

#include <CLI/CLI.hpp>

namespace TreeLod
{
    void addGenerateCommand(CLI::App& app);
    void addCompareCommand(CLI::App& app);
    void addInfoCommand(CLI::App& app);
    void addBakeCommand(CLI::App& app);
    void addRenderCommand(CLI::App& app);
    void addBenchCommand(CLI::App& app);
    void addCalibrateCommand(CLI::App& app);
}
