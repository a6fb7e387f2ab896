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

// f(ωi, ωo) of every closed instance between the directions a solve knows — from each bin
// of the cluster light's set and each directional source, towards each bin — in its own
// frame, per band: looked up once, for those directions do not change within a solve.
class ClosedResponse {
  public:
    ClosedResponse(const NodeModel& model, const std::vector<DirectionalSource>& sources);
    // f of closed instance c in band b towards bin o, from input i: bins first, then sources.
    // Only for instances that scatter: a held one sends what it was given.
    const double* Row(std::size_t c, int band, int o) const {
        return values_.data() + ((slot_[c] * bands_ + band) * bins_ + o) * inputs_;
    }

  private:
    std::size_t bands_, bins_, inputs_;
    // Each closed instance's place in values_; held ones have none (kHeld). Sized for
    // every one, an instance opened among a plantation's 232 held trees took 10 MB.
    static constexpr std::size_t kHeld = ~std::size_t{0};
    std::vector<std::size_t> slot_;
    std::vector<double> values_;
};

// Writes every closed instance's intensity and emitted power into the field; returns the
// largest change of an intensity over the largest intensity. Not `directional`: each sends
// its power alike in every direction (the single value of Soler 2003).
double ScatterClosed(const NodeModel& model, const std::vector<DirectionalSource>& sources,
                     const ClosedResponse& response, const ClosedLight& arrived, bool directional,
                     Field& field);

// Writes the intensity and emitted power of every closed instance held from outside a local
// problem (ClosedNode::held) into the field: they send what they were given, from the start.
void HoldClosed(const NodeModel& model, Field& field);

// Sets the intensity and emitted power of every closed instance that scatters (not held)
// to nothing: the field before any light arrived.
void DarkenClosed(const NodeModel& model, Field& field);

// Per channel, the power the closed instances intercept of the light that arrived on them
// per bin (`arrived`): each bin's irradiance times the box's section less τ that way.
std::vector<double> InterceptedByClosed(const NodeModel& model, const ClosedLight& arrived);

}  // namespace leaflux
