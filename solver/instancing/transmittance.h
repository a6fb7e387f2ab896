// A structure's directional transmittance (Soler 2003 §4.2.1): τ(ω), the mean unoccluded
// fraction of the parallel rays along ω that cross its box, at the directions of a set.
// The paper rendered the structure with graphics hardware; here every ray is traced
// exactly with Embree, entry points uniform over the box's projection.
// τ(ω) = τ(−ω), for they are the same lines; the tetrahedral sets hold few opposite pairs,
// so each direction is traced.
#pragma once

#include <cstdint>

#include "solver/instancing/directional.h"
#include "solver/instancing/structure.h"

namespace leaflux {

struct TransmittanceOptions {
    int level = 3;  // of the direction set: 3 → 130 directions
    int raysPerDirection = 4096;
    std::uint64_t seed = 1;
};

struct TransmittanceEstimate {
    SphereFunction tau;            // one channel
    SphereFunction standardError;  // of each value: √(τ(1 − τ) / rays)
    std::int64_t rays = 0;
    double seconds = 0.0;
};

TransmittanceEstimate ComputeTransmittance(const StructureAlone& structure,
                                           const TransmittanceOptions& options);

}  // namespace leaflux
