#include "solver/instancing/compute_original.h"

#include <chrono>
#include <cmath>

#include "solver/instancing/phase_photons.h"
#include "solver/instancing/transmittance.h"

namespace leaflux {

Original ComputeOriginal(const StructureAlone& structure, const OriginalSettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    const TransmittanceEstimate tau = ComputeTransmittance(
        structure, {settings.transmittanceLevel, settings.raysPerDirection, settings.seed});
    PhotonOptions photons;
    photons.kind = settings.kind;
    photons.level = settings.phaseLevel;
    photons.photonsPerBeam = settings.photonsPerBeam;
    photons.seed = settings.seed;
    PhaseEstimate phase = PhaseFromPhotons(structure, photons);

    Original original;
    original.boxMin = structure.BoxMin() + structure.Origin();
    original.boxMax = structure.BoxMax() + structure.Origin();
    original.transmittance = tau.tau;
    original.phase = std::move(phase.phase);
    OriginalProvenance& p = original.provenance;
    p.representative = structure.Name();
    p.leafCount = structure.LeafCount();
    p.leafAreaM2 = structure.LeafAreaM2();
    p.method = "mc";
    p.accuracy = settings.photonsPerBeam;
    // RMS of the relative standard errors: of τ over the directions, of the scattered
    // power over the beams (first band).
    double tauError = 0.0, tauMean = 0.0;
    for (int i = 0; i < tau.tau.Directions().Size(); ++i) {
        tauError += std::pow(double(tau.standardError.At(i, 0)), 2);
        tauMean += double(tau.tau.At(i, 0));
    }
    const int directions = tau.tau.Directions().Size();
    p.transmittanceRelativeError =
        tauMean > 0.0 ? std::sqrt(tauError / directions) / (tauMean / directions) : 0.0;
    double phaseError = 0.0;
    int lit = 0;
    for (const BeamBalance& beam : phase.beams) {
        if (beam.scatteredW[0] <= 0.0) continue;
        phaseError += std::pow(beam.scatteredErrorW[0] / beam.scatteredW[0], 2);
        ++lit;
    }
    p.phaseRelativeError = lit > 0 ? std::sqrt(phaseError / lit) : 0.0;
    p.computeSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return original;
}

}  // namespace leaflux
