#include "solver/instancing/compute_original.h"

#include <chrono>
#include <cmath>
#include <numbers>

#include "solver/instancing/phase_photons.h"
#include "solver/instancing/phase_radiosity.h"
#include "solver/instancing/transmittance.h"

namespace leaflux {

std::string OriginalSettings::Describe() const {
    std::string text = method == PhaseMethod::kRadiosity
                           ? "radiosity eps=" + std::to_string(epsilon)
                           : "photons n=" + std::to_string(photonsPerBeam);
    return text + " tau=" + PhaseKindName(transmittanceKind) + "/" +
           std::to_string(transmittanceLevel) + " rays=" + std::to_string(raysPerDirection) +
           " seed=" + std::to_string(seed);
}

Original ComputeOriginal(const StructureAlone& structure, const OriginalSettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    const TransmittanceEstimate tau = ComputeTransmittance(
        structure, {settings.transmittanceLevel, settings.raysPerDirection, settings.seed});
    SphereFunction transmittance = tau.tau;
    if (settings.transmittanceKind == PhaseKind::kConstant) {
        // One value: the mean over the sphere.
        const double mean = transmittance.Integral(0) / (4.0 * std::numbers::pi);
        for (int i = 0; i < transmittance.Directions().Size(); ++i)
            transmittance.At(i, 0) = static_cast<float>(mean);
    }
    PhaseFunction f;
    SphereFunction absorption;
    double phaseError = 0.0;
    if (settings.method == PhaseMethod::kPhotons) {
        PhotonOptions photons;
        photons.kind = settings.kind;
        photons.level = settings.phaseLevel;
        photons.photonsPerBeam = settings.photonsPerBeam;
        photons.seed = settings.seed;
        PhaseEstimate phase = PhaseFromPhotons(structure, photons);
        f = std::move(phase.phase);
        absorption = SphereFunction(photons.level, f.Bands());
        for (std::size_t i = 0; i < phase.beams.size(); ++i) {
            for (int b = 0; b < f.Bands(); ++b)
                absorption.At(static_cast<int>(i), b) =
                    static_cast<float>(phase.beams[i].absorbedW[b]);
        }
        // The RMS over the beams of the scattered power's relative standard error.
        int lit = 0;
        for (const BeamBalance& beam : phase.beams) {
            if (beam.scatteredW[0] <= 0.0) continue;
            phaseError += std::pow(beam.scatteredErrorW[0] / beam.scatteredW[0], 2);
            ++lit;
        }
        phaseError = lit > 0 ? std::sqrt(phaseError / lit) : 0.0;
    } else {
        RadiosityPhaseOptions radiosity;
        radiosity.kind = settings.kind;
        // A constant function is the mean over the incoming directions of a set.
        radiosity.level = settings.kind == PhaseKind::kConstant ? 2 : settings.phaseLevel;
        radiosity.hrc.epsilon = settings.epsilon;
        radiosity.seed = settings.seed;
        RadiosityPhase phase = PhaseFromRadiosity(structure, radiosity);
        f = std::move(phase.phase);
        absorption = SphereFunction(radiosity.level, f.Bands());
        for (int i = 0; i < absorption.Directions().Size(); ++i) {
            for (int b = 0; b < f.Bands(); ++b)
                absorption.At(i, b) = static_cast<float>(phase.absorbedW[i * f.Bands() + b]);
        }
    }

    Original original;
    original.boxMin = structure.BoxMin() + structure.Origin();
    original.boxMax = structure.BoxMax() + structure.Origin();
    original.transmittance = std::move(transmittance);
    original.phase = std::move(f);
    original.absorption = std::move(absorption);
    OriginalProvenance& p = original.provenance;
    p.representative = structure.Name();
    p.leafCount = structure.LeafCount();
    p.leafAreaM2 = structure.LeafAreaM2();
    p.method = settings.method == PhaseMethod::kPhotons ? "mc" : "hr";
    p.accuracy =
        settings.method == PhaseMethod::kPhotons ? settings.photonsPerBeam : settings.epsilon;
    // The RMS over the directions of τ's relative standard error.
    double tauError = 0.0, tauMean = 0.0;
    for (int i = 0; i < tau.tau.Directions().Size(); ++i) {
        tauError += std::pow(double(tau.standardError.At(i, 0)), 2);
        tauMean += double(tau.tau.At(i, 0));
    }
    const int directions = tau.tau.Directions().Size();
    p.transmittanceRelativeError =
        tauMean > 0.0 ? std::sqrt(tauError / directions) / (tauMean / directions) : 0.0;
    p.phaseRelativeError = phaseError;
    p.computeSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return original;
}

}  // namespace leaflux
