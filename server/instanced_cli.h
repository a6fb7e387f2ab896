// The instanced solver from the command line (`leaflux solve --solver instanced`): its
// options, and its statistics printed after the summary.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "solver/instancing/instanced.h"

namespace leaflux {

struct InstancedCommand {
    std::string policy;  // a policy file; empty: the built-in default policy
    std::string phaseDb;
    bool noPhaseDb = false;
    double phaseDbMb = 256.0;
    std::string shadows = "geometry";
    bool singleValue = false;
    bool perBin = false;   // InstancedOptions::holdOutside off
    std::string problems;  // CSV of the local problems solved
    int maxDepth = 0;
    std::int64_t mergeTriangles = InstancedOptions{}.mergeTriangles;
    bool pushDown = false;    // InstancedOptions::pushDown
    std::string outputLevel;  // "", "plant", "axis" or "phytomer"
    // Set by leaflux render --open-in-view (InstancedOptions::inView).
    std::function<bool(const glm::dvec3&, const glm::dvec3&)> inView;
};

// Adds the instanced solver's options to `solve`.
void AddInstancedOptions(CLI::App& solve, InstancedCommand& command);

// Whether direct light meets the whole scene's triangles (then the scene is flattened
// whole).
inline bool ShadowsByGeometry(const InstancedCommand& command) {
    return command.shadows != "transmittance";
}
// Whether those triangles are in the ray engine's compact hierarchy (SceneRays).
inline bool CompactShadows(const InstancedCommand& command) {
    return command.shadows == "geometry-compact";
}

// Solves with the instanced solver and prints its statistics; `shadows` the flat scene's
// rays when ShadowsByGeometry, else null and `flat` the receivers alone.
// `organSink`, when given, gets each organ's light as it is solved (InstancedOptions).
Solution RunInstanced(const Scene& scene, const FlatScene& flat, const RayScene* shadows,
                      const HrcOptions& hrc, const InstancedCommand& command,
                      OrganSink* organSink = nullptr);

}  // namespace leaflux
