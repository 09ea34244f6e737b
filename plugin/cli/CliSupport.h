// Shared plumbing of the CLI: exit codes, error printing, progress display.
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/Result.h"
#include "TreeLod/WindModel.h"
#include "TreeLod/SceneScript.h"

#include <functional>
#include <string>
#include <vector>

namespace TreeLod
{
    enum ExitCode
    {
        EXIT_OK = 0,
        EXIT_FAILURE_RUN = 1, ///< could not do the work (e.g. no GL context)
        EXIT_BAD_INPUT = 2    ///< the input or arguments are wrong; nothing was written
    };

    /// Print "treelod: file: element: reason" to stderr and return EXIT_BAD_INPUT.
    int printError(const Error& error);

    /// A progress callback that draws a bar on a terminal (stderr) and prints one plain
    /// line per step otherwise. `quiet` gives an empty callback.
    ProgressCallback makeProgress(bool quiet = false);

    /// Comma-separated items, empty ones dropped.
    std::vector<std::string> splitList(const std::string& text);

    /// `--size WxH` (each 1..16384) into width and height; "" leaves them as they are.
    Result<void> parseSize(const std::string& text, int& width, int& height);

    /// `--lod-bias`: comma-separated finite numbers > 0, at least one.
    Result<std::vector<float>> parseLodBiases(const std::string& text);
    /// --motion-frames: the motion frames among `frames` frames, "all" of them or a count spread
    /// evenly along the path (0: none); an error naming the option for anything else.
    Result<std::vector<std::uint32_t>> parseMotionFrames(const std::string& text, std::uint32_t frames);

    /// `--shadow-size N` and `--shadow-lod-bias B` over a script's shadows. Size: -1 keeps the
    /// script's, 0 turns them off, else a power of two in 256..16384 (scaled-down llvmpipe runs:
    /// the map's fill does not scale with the tree count). Bias: 0 keeps the script's, else
    /// finite and > 0 (Forest::setShadowLodBias).
    Result<void> applyShadowOptions(int size, double lodBias, SceneShadows& shadows);
    /// `--wind S`: the script's wind strength replaced by S (-1: the script's, 0: calm); an error
    /// names the option.
    Result<void> applyWindOption(double strength, WindParameters& wind);

    /// Set the exit code a subcommand callback produced (CLI11 callbacks return void).
    void setExitCode(int code);
    int exitCode();
}
