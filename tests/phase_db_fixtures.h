// Synthetic originals and keys for the phase-function database's tests, kill test and
// benchmark: random values of the right shape, no lighting computed.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "solver/instancing/original.h"
#include "solver/instancing/phase_key.h"

namespace leaflux::testing {

inline PhaseKey SyntheticKey(const std::string& signature,
                             PhaseKind kind = PhaseKind::kBiDirectional, int level = 2) {
    PhaseKey key;
    key.species = "poplar";
    key.policyHash = "00112233445566aa";
    key.signature = signature;
    key.opticsHash = "ffeeddccbbaa9988";
    key.bands = {"PAR", "NIR"};
    key.kind = kind;
    key.directionLevel = kind == PhaseKind::kConstant ? 0 : level;
    return key;
}

// Values drawn uniformly from [0, 1) with `seed`; τ at `level`, f of `kind` at `level`.
inline Original SyntheticOriginal(PhaseKind kind, int level, int bands, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const auto fill = [&](std::span<float> values) {
        for (float& v : values) v = uniform(random);
    };
    Original original;
    original.boxMin = {-0.5, -0.25 * seed, 0.0};
    original.boxMax = {0.5, 0.75, 1.0 + seed};
    original.transmittance = SphereFunction(level, 1);
    for (int d = 0; d < original.transmittance.Directions().Size(); ++d) {
        original.transmittance.At(d, 0) = uniform(random);
    }
    original.phase = PhaseFunction(kind, level, bands);
    fill(original.phase.MutableValues());
    original.absorption = SphereFunction(level, bands);
    for (int d = 0; d < original.absorption.Directions().Size(); ++d) {
        for (int b = 0; b < bands; ++b) original.absorption.At(d, b) = uniform(random);
    }
    original.provenance.representative = "plant " + std::to_string(seed) + " / axis 1";
    original.provenance.leafCount = 10 + seed;
    original.provenance.leafAreaM2 = 0.01 * seed;
    original.provenance.method = "mc";
    original.provenance.accuracy = 4096;
    original.provenance.computeSeconds = 1.5;
    original.provenance.transmittanceRelativeError = 0.01;
    original.provenance.phaseRelativeError = 0.02;
    return original;
}

}  // namespace leaflux::testing
