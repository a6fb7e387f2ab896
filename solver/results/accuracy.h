// How far one solution is from a reference on the same scene: the figures users weigh
// against run time (Soler 2003, Fig. 14), per band, over the leaves.
#pragma once

#include <unordered_set>
#include <vector>

#include "solver/results/light.h"
#include "solver/scene/scene.h"

namespace leaflux {

// A leaf's value is its irradiance summed over both sides (W/m²). Lit leaves are those
// the reference gives at least kLitFraction of its brightest leaf: relative errors on
// leaves in deep shade say nothing a user acts on and divide by numbers near zero.
struct BandAccuracy {
    static constexpr double kLitFraction = 0.05;

    int leaves = 0;
    int litLeaves = 0;
    double referenceMaxWm2 = 0.0;
    double l2PctOfMax = 0.0;       // RMS of value − reference over the leaves, % of the max
    double meanRelativePct = 0.0;  // mean |value − reference| / reference over lit leaves
    double p95RelativePct = 0.0;   // its 95th percentile
    // The reference's own standard error in the L2 metric (% of the max), the sides taken
    // as independent: errors below it cannot be told from the reference's noise. 0 when
    // the reference gives no standard error.
    double referenceFloorPct = 0.0;
};

// One entry per band of the scene. Both solutions must come from `flat`; a band without a
// lit leaf (an empty or dark scene) gets zeros. `within`, when given: only the leaves under
// these nodes (themselves included) count, those a reference was solved for
// (ReferenceOptions::only), e.g. a sample of a plantation's trees.
std::vector<BandAccuracy> CompareLeaves(const Scene& scene, const FlatScene& flat,
                                        const Solution& reference, const Solution& value,
                                        const std::unordered_set<NodeId>* within = nullptr);
// The same over the structures `value` solved whole (Solution::wholeStructures), on their
// absorbed power per organ area (W/m²) against the reference's over the same organs;
// `leaves` counts those structures (under `within`, when given).
std::vector<BandAccuracy> CompareWholeStructures(
    const Scene& scene, const FlatScene& flat, const Solution& reference, const Solution& value,
    const std::unordered_set<NodeId>* within = nullptr);

}  // namespace leaflux
