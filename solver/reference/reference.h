// The Monte Carlo reference solver (`mc`): unbiased light transport with two-sided diffuse
// reflection and transmission, the ground truth of every accuracy figure in leaflux.
//
// Method: for each receiver, paths are gathered from points spread over its area —
// next-event estimation towards suns and lamps, a direction drawn over the whole sphere
// for everything else, continued by cosine-weighted bounces with unbiased Russian
// roulette. Lamps combine both strategies by multiple importance sampling (power
// heuristic). The samples of a receiver form `replicates` independent stratified groups;
// the spread of the group means gives the standard error.
//
// Determinism: a receiver's random stream is keyed by (seed, receiver, replicate), so the
// result is the same for a given seed whatever the thread count; threads only change the
// order of the final sums (the energy balance), within floating-point rounding.
#pragma once

#include <cstdint>
#include <functional>

#include "solver/raytrace/raytrace.h"
#include "solver/results/light.h"
#include "solver/scene/scene.h"

namespace leaflux {

struct ReferenceOptions {
    int samplesPerReceiver = 1024;  // paths per receiver, rounded up to replicates · m²
    int replicates = 16;            // independent groups for the standard error (≥ 2)
    std::uint64_t seed = 1;
    int threads = 0;        // 0: every core of the calling task arena (all, outside one)
    int maxDepth = 100000;  // a safety net: with Russian roulette at ≤ 0.995,
                            // a path reaches it with probability < 1e-200
    // Direct light only: light straight from the suns, the sky and the lamps; what leaves
    // and surfaces scatter is dropped (and shows as missing in the energy balance).
    bool directOnly = false;
    // The receivers to solve (empty: every one); the others are left dark, with zero error,
    // and out of the energy balance. A plantation's reference on a sample of its trees takes
    // minutes where all of it would take hours.
    std::vector<std::uint32_t> only;
    // Called with the fraction done, from any thread, at most every 1 %.
    std::function<void(double)> progress;
};

Solution SolveReference(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                        const ReferenceOptions& options);

}  // namespace leaflux
