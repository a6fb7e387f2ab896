// A structure's phase function by hierarchical radiosity (Soler 2003 §4.2.3): the
// structure alone under a unit parallel beam from every incoming direction of the set,
// the beams as channels of one solve (SolveBeams), then the intensity leaving towards each
// outgoing direction read from its leaf patches: f(ωi, ωo) = Σ_p B_p,s(ωi) A_p |cos θo|
// e_p(ωo) / π, s the side of patch p facing ωo and e_p(ωo) the fraction of rays from p
// towards ωo that leave the structure (its self-occlusion on the way out).
//
// Values are at the directions themselves, where photons (phase_photons.h) average over
// the hats around them; each method checks the other (tests/phase_function_test.cpp).
#pragma once

#include <cstdint>

#include "solver/instancing/directional.h"
#include "solver/instancing/structure.h"
#include "solver/radiosity/hrc.h"

namespace leaflux {

struct RadiosityPhaseOptions {
    PhaseKind kind = PhaseKind::kBiDirectional;
    int level = 2;  // of the incoming and outgoing directions
    // ε as a fraction of one beam's power: the paper found about 20 % of the impulse
    // enough for its branches (§4.2.3, Fig. 12); it is the threshold of every link.
    HrcOptions hrc = [] {
        HrcOptions o;
        o.epsilon = 2e-3;
        o.lightVectors = false;
        return o;
    }();
    int escapeRays = 16;  // per patch and outgoing direction
    std::uint64_t seed = 1;
};

struct RadiosityPhase {
    PhaseFunction phase;
    std::vector<double> scatteredW;  // per incoming direction and band: ∫ f dωo
    std::vector<double> absorbedW;   // per incoming direction and band
    SolveStats stats;
    std::int64_t escapeRays = 0;
    double seconds = 0.0;
};

RadiosityPhase PhaseFromRadiosity(const StructureAlone& structure,
                                  const RadiosityPhaseOptions& options);

}  // namespace leaflux
