// Gathering and convergence: each sweep, every link's receiver gathers the light its
// senders send (Gather), the light is pushed down (PushPull), and every leaf patch's
// radiosity is updated from what arrived, B₁ = E + ρ₁I₁ + τ₂→₁I₂, B₂ = ρ₂I₂ + τ₁→₂I₁
// (Soler 2003 §4.3): a Jacobi iteration, accelerated by extrapolating the geometric series
// of its changes (Convergence). The functions read and write only the tables they are
// handed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/node_model.h"
#include "solver/scene/scene.h"

namespace leaflux {

// Diffuse reflectance and transmittance of each receiver, per side and channel: τ of side
// s is of light arriving on s and leaving through the other side.
struct ReceiverOptics {
    SideTable rho, tau;

    // From the scene's optics: channel c takes band Channels::BandOf(c).
    ReceiverOptics(const Scene& scene, const FlatScene& flat, const Channels& channels);
};

// Per receiver node of `receivers`: what its links bring (Gathered), as W/m² per side for
// a plane and per bin for a cluster; with kDirections also ∫ L dω and ∫ L ω dω.
template <bool kDirections>
void Gather(const NodeModel& model, const Field& field, const Links& links,
            const std::vector<std::uint32_t>& receivers, Gathered& gathered);

// The radiosity of every leaf patch from the light that arrived on it and its emission;
// returns the largest change over the largest radiosity scattered (emission left out).
double UpdateRadiosity(const Hierarchy& hierarchy, const std::vector<std::uint32_t>& leaves,
                       const ReceiverOptics& optics, LeafLight& leafLight, Field& field);
// Adds `factor` times the last change to every leaf patch's radiosity, none below zero.
void Extrapolate(const std::vector<std::uint32_t>& leaves, const LeafLight& leafLight,
                 double factor, Field& field);

// Jacobi iteration converges like λᵏ, λ the spectral radius of the transport (≈ ρ + τ of
// the leaves in a dense canopy or a closed room): at λ = 0.999 thousands of sweeps. The
// ratio of successive changes estimates λ; once it is steady over three sweeps, the
// remaining geometric series Δ·λ/(1 − λ) is added at once (Lyusternik's extrapolation),
// and the change alone no longer says the iteration is done: what remains is Δ·λ/(1 − λ).
class Convergence {
  public:
    // After a sweep that changed the radiosity by `change`: the factor by which to
    // extrapolate that change, or 0.
    double Step(double change) {
        const double ratio = previous_ > 0.0 ? change / previous_ : 0.0;
        previous_ = change;
        steady_ = std::abs(ratio - ratio_) < 0.01 * ratio && ratio < 1.0 ? steady_ + 1 : 0;
        ratio_ = ratio;
        if (steady_ < 3 || ratio_ < 0.5) return 0.0;
        steady_ = 0;
        const double factor = ratio_ / (1.0 - ratio_);
        previous_ = 0.0;  // the next change follows the jump: not a ratio of the series
        return factor;
    }
    // The change still to come, estimated from the last one.
    double Remaining(double change) const {
        return ratio_ > 0.0 && ratio_ < 1.0 ? change * std::max(1.0, ratio_ / (1.0 - ratio_))
                                            : change;
    }

  private:
    double previous_ = 0.0, ratio_ = 0.0;
    int steady_ = 0;
};

}  // namespace leaflux
