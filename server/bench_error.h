// `leaflux bench error`: error against run time on one scene. The Monte Carlo reference at
// a high sample count (cached on disk, keyed by the scene and its settings), then every
// solver at a list of settings, each compared with the reference per band (accuracy.h),
// with its wall time, CPU time and peak memory. Writes a CSV, prints the table and plots
// error against time with matplotlib when Python has it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "server/scene_file_cli.h"
#include "solver/instancing/policy.h"
#include "solver/radiosity/hrc.h"

namespace leaflux {

struct ErrorBenchOptions {
    std::string scene;       // scene file
    SceneFileOptions file;   // --strict, --max-nodes
    std::string name;        // the scene's name in the CSV and the log
    std::string csv;         // where to write the rows
    std::string png;         // where to plot them (none when empty)
    std::string plotScript;  // the Python script that plots (examples/plot_error.py)
    std::string cacheDirectory;
    int referenceSamples = 8192;
    // > 0: the reference solved for the organs of this many plants alone, spread evenly
    // through the scene's, and every error taken over their leaves; the solvers still
    // solve the whole scene. A plantation's reference in minutes rather than hours.
    int samplePlants = 0;
    std::uint64_t referenceSeed = 99;
    std::vector<int> monteCarloSamples{64, 256, 1024};
    std::vector<double> hrcEpsilons{1e-3, 1e-4, 1e-5};
    HrcOptions hrc;          // the HRC runs' other settings (subdivision, rays, directions)
    bool directOnly = true;  // also direct light only (HRC, the finest ε)
    // Instanced runs under `policy`, its originals in one database in memory: the first ε
    // from an empty database ("cold", computing them), then every ε from the full one; at
    // the middle ε also directional instance light against the paper's single value (with
    // the phase function made bi-directional when the policy's is not: "phase=bi", first
    // "cold", computing its originals), the outside light per bin (per-bin), shadows by
    // transmittance, light per branch (output=axis) and opening down to each of
    // `instancedDepths` only; at every ε also with small instances merged (instancedMerge)
    // when asked. A run that solved structures whole is compared on those structures'
    // absorbed power per organ area (CompareWholeStructures), not on leaves.
    std::vector<double> instancedEpsilons;
    std::vector<int> instancedDepths;
    // > 0: also at every ε with instances of at most this many organ triangles solved as
    // one local problem with the instances they hold (InstancedOptions::mergeTriangles).
    std::int64_t instancedMerge = 0;
    InstancingPolicy policy;
    int threads = 0;
};

// The directory references are cached in when none is given: $XDG_CACHE_HOME/leaflux,
// else ~/.cache/leaflux, else ./.leaflux-cache.
std::string DefaultCacheDirectory();

// Runs the benchmark; returns the process exit code.
int RunErrorBench(const ErrorBenchOptions& options);

}  // namespace leaflux
