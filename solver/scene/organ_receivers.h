// Which of a flat scene's receivers an organ is, by its node's id. ReceiversOf lists the
// organs first, in their nodes' order: when that is the ids' (a scene read from a file with
// placements, whose nodes are then in id order), they are searched in place; else through
// an index of (id, receiver), 16 bytes an organ, 33 MB of the paper's plantation.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "solver/scene/geometry.h"

namespace leaflux {

class OrganReceivers {
  public:
    static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

    // `flat` must outlive this; its organs come first (checked).
    explicit OrganReceivers(const FlatScene& flat);

    // The receiver of node `node`'s organ; kNone for a node that has none.
    std::uint32_t Of(NodeId node) const;
    std::uint32_t Count() const { return organs_; }         // the organ receivers, the first ones
    std::uint32_t Triangles() const { return triangles_; }  // theirs, the first ones

  private:
    const std::vector<Receiver>& receivers_;
    std::uint32_t organs_ = 0, triangles_ = 0;
    std::vector<std::pair<NodeId, std::uint32_t>> byNode_;  // empty: in node order already
};

}  // namespace leaflux
