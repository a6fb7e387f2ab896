// `leaflux render`: a picture of a scene's light, solved now with the solve command's
// options or read from a per-organ CSV already written (--from).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "server/solve_cli.h"

namespace leaflux {

struct RenderCommand {
    SolveCommand solve;
    std::string camera, size = "1024x768", out, from, quantity = "irradiance", side = "seen", band,
                        range, palette = "viridis", rgb = "R,G,B";
    int pixelSamples = 4;
    bool photons = false, openInView = false, scaleBar = false, northArrow = false;
};

CLI::App* AddRenderCommand(CLI::App& app, RenderCommand& command);
int RunRender(const RenderCommand& command);

}  // namespace leaflux
