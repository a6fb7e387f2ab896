// Where a solver hands each organ's light as it reaches it, instead of holding every
// organ's in Solution::light (InstancedOptions::organSink): a plantation's leaves written
// as they are solved, not a table of all of them held to the end.
#pragma once

#include <cstddef>
#include <span>

#include "solver/results/light.h"

namespace leaflux {

class OrganSink {
  public:
    virtual ~OrganSink() = default;
    // Receiver `receiver`'s light by band: once for each receiver solved, from any thread.
    virtual void Put(std::size_t receiver, std::span<const BandLight> bands) = 0;
    // Receiver `receiver` is not solved (Solution::unsolved): once, from any thread.
    virtual void Skip(std::size_t receiver) = 0;
};

}  // namespace leaflux
