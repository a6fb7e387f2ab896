// The key of an original in the phase-function database (Soler 2003 §5, "Instantiation
// Database"): everything its functions depend on. Two keys that differ in any field name
// different functions, so a change to the policy, the optics, the bands, the resolution or
// the code that computes functions is a miss, never a stale hit.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "solver/instancing/directional.h"

namespace leaflux {

// Bump when the computation of τ or f changes what it gives for the same inputs: every
// stored function of an older version then stops matching.
inline constexpr int kPhaseCodeVersion = 1;

struct PhaseKey {
    std::string species;
    std::string policyHash;  // ContentHash::Hex() of the species' policy file
    std::string signature;   // the policy's signature of the structure ("type=axis;leaves=2")
    std::string opticsHash;  // ContentHash::Hex() of the optical properties the solve used
    std::vector<std::string> bands;  // band names, in the order of the function's bands
    PhaseKind kind = PhaseKind::kBiDirectional;
    int directionLevel = 0;  // DirectionSet level (0..4) of f's directions
    // How the functions are computed (method, accuracy, τ's resolution): "" when a caller
    // keys on nothing more; see OriginalSettings::Describe.
    std::string settings;
    int codeVersion = kPhaseCodeVersion;

    // One line naming every field, unambiguous whatever the strings hold ('|', '=' and ','
    // inside fields are escaped): the database's primary key.
    std::string Canonical() const;
    std::string HashHex() const;  // ContentHash of Canonical()
    bool operator==(const PhaseKey&) const = default;
};

// The bands as Canonical() writes them: "PAR,NIR" with separators escaped.
std::string JoinBands(const std::vector<std::string>& bands);

}  // namespace leaflux
