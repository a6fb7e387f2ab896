// The light closed instances send: what each one's phase function makes of the light that
// arrived on it (Soler 2003 §3.2): I(ωo) = Σ over arrivals E(ωi) f(ωi, ωo), kept per
// direction of the cluster light's set, so that links read it as a cluster's intensity.
// Light from the directional sources is taken at their own directions, the rest per bin.
#pragma once

#include <vector>

#include "solver/radiosity/light_state.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/node_model.h"

namespace leaflux {

// Writes every closed instance's intensity and emitted power into the field; returns the
// largest change of an intensity over the largest intensity. Not `directional`: each sends
// its power alike in every direction (the single value of Soler 2003).
double ScatterClosed(const NodeModel& model, const std::vector<DirectionalSource>& sources,
                     const ClosedLight& arrived, bool directional, Field& field);

}  // namespace leaflux
