// `leaflux solve`: the solver's options on the command line, a scene file loaded and solved,
// and the per-organ results written. `leaflux render` takes the same options.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include "server/instanced_cli.h"
#include "server/scene_file_cli.h"
#include "solver/radiosity/hrc.h"
#include "solver/solve.h"

namespace leaflux {

struct SolveCommand {
    std::string scene, solver = "hrc", out, structures, ply;
    std::string warmStart;  // a per-organ CSV of an earlier solve: where the iteration starts
    int samples = 1024, replicates = 16, threads = 0;
    double epsilon = 1e-4;
    HrcOptions hrc;  // subdivision, rays and directions; ε and threads are set apart
    std::uint64_t seed = 1;
    bool directOnly = false, quiet = false;
    SceneFileOptions file;  // --strict, --max-nodes
    InstancedCommand instanced;
};

// HRC's settings besides ε, as options named `prefix` + name, their help after `label`.
void AddHrcSettings(CLI::App& app, HrcOptions& hrc, const std::string& prefix,
                    const std::string& label);
// The scene, the solver and its settings, as `solve` and `render` take them.
void AddSolverOptions(CLI::App& app, SolveCommand& command);
CLI::App* AddSolveCommand(CLI::App& app, SolveCommand& command);

// A scene file loaded and solved. `prepared` holds the whole scene's rays, but for the
// instanced solver: then `receivers` are the results' receivers, and `shadows` its organs'
// rays when it casts shadows by geometry.
struct SolvedScene {
    Scene scene;
    std::optional<PreparedScene> prepared;
    FlatScene receivers;
    std::unique_ptr<RayScene> shadows;  // refers to `receivers`, declared before it
    Solution solution;

    const FlatScene& Flat() const { return prepared ? prepared->Flat() : receivers; }
};
// `check`, when given, sees the scene once loaded, before the solve (what a picture's
// settings need of it). `leaves`, when given, gets the per-organ CSV: the instanced solver
// writes it as it reaches the organs (LeafCsvStream), its solution's light table left
// empty; the other solvers, after the solve.
std::unique_ptr<SolvedScene> SolveScene(const SolveCommand& command,
                                        const std::function<void(const Scene&)>& check = {},
                                        std::ostream* leaves = nullptr);

int RunSolve(const SolveCommand& command);

}  // namespace leaflux
