// Outputs of a radiosity solve: per receiver and band, the light of its leaf patches
// (irradiance per side, absorbed power, the radiance integral and moment), area-weighted;
// and per band the energy balance, whose escaped power is estimated by rays from every
// leaf patch side towards the sky (its standard error reported). Reads the solve's state.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "solver/radiosity/gathering.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/node_model.h"
#include "solver/raytrace/occlusion.h"
#include "solver/raytrace/raytrace.h"
#include "solver/results/light.h"

namespace leaflux {

// Where a solve's light goes as its receivers are reached, so that a local problem hands on
// its organs' light without holding the scene's.
class LightSink {
  public:
    virtual ~LightSink() = default;
    // Receiver `receiver` (a FlatScene index), per band, once all its leaf patches are in.
    virtual void Receiver(std::size_t receiver, const std::vector<BandLight>& light) = 0;
};

// Into a Solution's light, sized by its owner.
class SolutionSink : public LightSink {
  public:
    explicit SolutionSink(Solution& solution) : solution_(solution) {}
    void Receiver(std::size_t receiver, const std::vector<BandLight>& light) override {
        std::ranges::copy(light, solution_.light[receiver].begin());
    }

  private:
    Solution& solution_;
};

// Hands each receiver of the leaf patches `leaves` to the sink and adds their energy
// balance to `balances` (one per band); returns the rays it traced. A scene's solve: one
// channel per band. With `occlusion` (a level holding closed instances, or within levels
// further out), the escape rays meet the whole scene's triangles where it has them
// (Occlusion::Shadows), else they pass its closed instances by their transmittance and
// the levels further out; without, they meet `rays`' triangles alone.
std::int64_t WriteOutputs(const NodeModel& model, const RayScene& rays,
                          const std::vector<std::uint32_t>& leaves, const ReceiverOptics& optics,
                          const Field& field, const LeafLight& leafLight, LightSink& sink,
                          std::vector<EnergyBalance>& balances,
                          const Occlusion* occlusion = nullptr);

// Adds to `balances` the power the closed instances send out of the scene: per instance and
// bin of the cluster light's set, what it sends that way (its intensity times the bin's
// solid angle) times the fraction of rays from points of its box, along the bin's
// direction, that pass the rest of the scene (triangles block them, other closed instances
// pass them by their transmittance). Its standard error goes into stderrW. Held instances
// and those opened later (ClosedNode::opens) are left out. Returns the rays traced.
std::int64_t AddClosedEscape(const NodeModel& model, const Occlusion& occlusion, const Field& field,
                             std::vector<EnergyBalance>& balances);

}  // namespace leaflux
