// A structure's phase function by photon tracing (Soler 2003 §4.2.3 computes it by
// hierarchical radiosity; phase_radiosity.h does that, and each checks the other).
//
// For each direction i of the set, photons come from directions ωi drawn by i's
// interpolation weight (its hat), enter the box uniformly over its projection along −ωi,
// each carrying A(ωi)/N of a unit irradiance, and are followed
// through the structure's leaves — two-sided diffuse reflection and transmission, one
// direction for every band with per-band weights, Russian roulette — until they leave.
// What leaves towards ωo is what leaves the structure that way, its self-occlusion
// included; photons that meet no leaf are the transmittance's. Each escaping photon is
// shared among the three directions of the face holding ωo by their interpolation
// weights, and a direction's tally divided by its hat's integral (DirectionSet). So f(i, o)
// is f averaged over the hats of i and of o: the interpolated function integrates to the
// scattered power exactly, and it keeps reciprocity, f(i, o) = f(o, i), where sampling
// ωi at the vertex would smooth one side only.
//
// Determinism: beam i's photons draw from the stream (seed, i), so the function is the
// same for a seed whatever the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "solver/instancing/directional.h"
#include "solver/instancing/structure.h"

namespace leaflux {

struct PhotonOptions {
    PhaseKind kind = PhaseKind::kBiDirectional;
    int level = 3;  // of the incoming (and outgoing) directions; a constant function
                    // averages over the incoming directions of this level
    int photonsPerBeam = 20000;
    int replicates = 8;  // independent groups per beam, for the standard errors (≥ 2)
    // Incoming directions drawn over each direction's hat; false: every photon of beam i
    // comes from direction i itself (as radiosity's beams do, phase_radiosity.h).
    bool hatIncoming = true;
    std::uint64_t seed = 1;
};

// What became of a unit irradiance from one incoming direction's hat, per band (W per W/m²):
// entered = intercepted + transmitted, and intercepted = scattered + absorbed up to the
// photons' sampling error.
struct BeamBalance {
    double enteredW = 0.0;                                    // A(ωi): the box's cross-section
    double transmittedW = 0.0;                                // photons that met no leaf
    std::vector<double> interceptedW, scatteredW, absorbedW;  // per band
    // Standard errors, per band: of the scattered power, and of intercepted − scattered −
    // absorbed, whose expectation is zero.
    std::vector<double> scatteredErrorW, closureErrorW;
};

struct PhaseEstimate {
    PhaseFunction phase;
    PhaseFunction standardError;     // of each value, from the spread of the replicates
    std::vector<BeamBalance> beams;  // per incoming direction of the level
    std::int64_t rays = 0;
    double seconds = 0.0;
};

PhaseEstimate PhaseFromPhotons(const StructureAlone& structure, const PhotonOptions& options);

}  // namespace leaflux
