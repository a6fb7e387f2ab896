// Outputs of a radiosity solve: per receiver and band, the light of its leaf patches
// (irradiance per side, absorbed power, the radiance integral and moment), area-weighted;
// and per band the energy balance, whose escaped power is estimated by rays from every
// leaf patch side towards the sky (its standard error reported). Reads the solve's state.
#pragma once

#include <cstdint>
#include <vector>

#include "solver/radiosity/gathering.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/node_model.h"
#include "solver/raytrace/raytrace.h"
#include "solver/results/light.h"

namespace leaflux {

// Fills solution.light and solution.balance (sized by the caller) from the leaf patches
// `leaves`; returns the rays it traced. A scene's solve: one channel per band.
std::int64_t WriteOutputs(const NodeModel& model, const RayScene& rays,
                          const std::vector<std::uint32_t>& leaves, const ReceiverOptics& optics,
                          const Field& field, const LeafLight& leafLight, Solution& solution);

}  // namespace leaflux
