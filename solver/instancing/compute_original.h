// The functions of one structure, computed: its transmittance by parallel rays
// (transmittance.h) and its phase function by radiosity (phase_radiosity.h, the paper's
// method, deterministic) or by photons (phase_photons.h), with how they were got. What the
// phase-function database stores on a miss.
#pragma once

#include <cstdint>
#include <string>

#include "solver/instancing/original.h"
#include "solver/instancing/structure.h"

namespace leaflux {

enum class PhaseMethod { kRadiosity, kPhotons };

struct OriginalSettings {
    PhaseKind kind = PhaseKind::kMonoDirectional;
    int phaseLevel = 3;  // 130 directions: the paper's compromise (§4.2.2)
    PhaseKind transmittanceKind = PhaseKind::kMonoDirectional;  // or constant
    int transmittanceLevel = 3;
    PhaseMethod method = PhaseMethod::kRadiosity;
    // Structures of more leaves are computed by photons even when `method` is radiosity:
    // the beams' solve holds every beam's light on every element (a 10,000-leaf tree took
    // 4.6 GB), the photons' memory is the structure's.
    std::int64_t radiosityLeavesAtMost = 1000;
    double epsilon = 2e-3;  // radiosity: of one beam's power
    int photonsPerBeam = 20000;
    int raysPerDirection = 4096;
    std::uint64_t seed = 1;

    // Everything here but the kind and level of f, which keys hold apart: "radiosity
    // eps=0.002 tau=mono/3 rays=4096 seed=1".
    std::string Describe() const;
};

Original ComputeOriginal(const StructureAlone& structure, const OriginalSettings& settings);

}  // namespace leaflux
