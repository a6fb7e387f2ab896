// Where a solve's iteration may start: the light its organs had at the end of an earlier
// solve of much the same scene (a growth cycle's, the last one's). Jacobi from the emission
// spends its first sweeps bringing the scattered light up from nothing; from the last
// cycle's light, where little changed, the change still to come is small from the start.
// The iteration alone reaches the same fixed point from wherever it starts; the links,
// judged in the light it has reached, may be chosen otherwise, each within ε, so the
// answer is a cold start's within a small part of what ε costs (HrcOptions::warmStart,
// tests/warm_start_test.cpp).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/hierarchy.h"
#include "solver/results/light.h"
#include "solver/scene/geometry.h"

namespace leaflux {

class WarmStart {
  public:
    // The organs' irradiance on each side in every band of `solution`, solved on
    // `receivers` (a flat scene's, or ReceiversOf's): by organ node, so that a scene whose
    // organs were added, removed or moved since takes what is still there. Organs solved
    // whole in a structure (Solution::unsolved) have no light of their own and are left out.
    WarmStart(const std::vector<Receiver>& receivers, const Solution& solution);

    int Bands() const { return bands_; }
    // W/m² on the upper and lower side of organ `node` in band b: [2b], [2b + 1]; null when
    // the earlier solve had no such organ.
    const float* Of(NodeId node) const {
        const auto it = row_.find(node);
        return it == row_.end() ? nullptr : &irradiance_[it->second * 2 * bands_];
    }

    // On the first arrival `irradiance` holds on the leaf patches `leaves` (one channel per
    // band, by `receivers`), the light scattered onto each organ it has: the organ's light
    // less its patches' mean first arrival, alike on its patches. The first arrival stays
    // each patch's own (sun and shade on a leaf); the scattered light is spread evenly, and
    // the first sweeps still even it out where a neighbour leaf lies close (the
    // 10,000-leaf tree, warm from its own solution: the first change 13 % of the largest
    // radiosity, against 26 % from the direct light). Returns the organs it had.
    std::int64_t Apply(const Hierarchy& hierarchy, const std::vector<Receiver>& receivers,
                       const std::vector<std::uint32_t>& leaves, SideTable& irradiance) const;

  private:
    int bands_ = 0;
    std::unordered_map<NodeId, std::uint32_t> row_;
    std::vector<float> irradiance_;
};

}  // namespace leaflux
