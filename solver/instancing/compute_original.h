// The functions of one structure, computed: its transmittance by parallel rays
// (transmittance.h) and its phase function by photons (phase_photons.h), with how they
// were got. What the phase-function database stores on a miss.
#pragma once

#include <cstdint>

#include "solver/instancing/original.h"
#include "solver/instancing/structure.h"

namespace leaflux {

struct OriginalSettings {
    PhaseKind kind = PhaseKind::kMonoDirectional;
    int phaseLevel = 3;  // 130 directions: the paper's compromise (§4.2.2)
    int transmittanceLevel = 3;
    int photonsPerBeam = 20000;
    int raysPerDirection = 4096;
    std::uint64_t seed = 1;
};

Original ComputeOriginal(const StructureAlone& structure, const OriginalSettings& settings);

}  // namespace leaflux
