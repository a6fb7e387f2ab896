// `leaflux generate`: a procedural poplar-like tree, a plantation, a random canopy or a
// greenhouse written as a scene file. Options that the chosen kind of scene would ignore
// are refused, and a scene that cannot fit in memory is refused before it is built.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "solver/generate/generator.h"

namespace leaflux {

struct GenerateCommand {
    TreeParameters tree;
    int rows = 1, columns = 1, trees = 0;
    double spacing = 6.0, rowSpacing = 0.0, rowAzimuth = 0.0, sunElevation = 50.0,
           sunAzimuth = 160.0;
    double sunPar = 400.0, sunNir = 350.0, skyPar = 100.0, skyNir = 60.0;
    bool noSky = false, noGround = false;
    CanopyParameters canopy;
    bool randomCanopy = false;
    bool greenhouse = false;
    double lampPar = 1500.0, lampNir = 150.0;
    std::string skyCones = "continuous";
    int prototypes = 4;
    bool instanced = false, quiet = false, colourBands = false;
    std::string out;
};

// The `generate` subcommand of `app`, its options bound to `command`.
CLI::App* AddGenerateCommand(CLI::App& app, GenerateCommand& command);

// Memory (bytes) building and writing the scene of `command` takes, about: its leaves
// times what a leaf costs (measured, see generate_cli.cpp).
double GenerateMemoryEstimate(const GenerateCommand& command);

// Writes the scene; throws InputError when it would need more than `availableBytes`
// (0: unknown, no check), with the estimate.
int RunGenerate(const GenerateCommand& command, std::uint64_t availableBytes);

}  // namespace leaflux
