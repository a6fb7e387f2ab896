#include "solver/scene/organ_receivers.h"

#include <algorithm>

#include "solver/util/check.h"

namespace leaflux {

OrganReceivers::OrganReceivers(const FlatScene& flat) : receivers_(flat.receivers) {
    bool inNodeOrder = true;
    for (std::size_t r = 0; r < receivers_.size(); ++r) {
        const Receiver& receiver = receivers_[r];
        if (receiver.kind != ReceiverKind::kOrgan) continue;
        LEAFLUX_CHECK_EQ(r, organs_);  // organs first
        LEAFLUX_CHECK_EQ(receiver.firstTriangle, triangles_);
        triangles_ += receiver.triangleCount;
        inNodeOrder = inNodeOrder && (organs_ == 0 || receivers_[organs_ - 1].node < receiver.node);
        ++organs_;
    }
    if (inNodeOrder) return;
    byNode_.reserve(organs_);
    for (std::uint32_t r = 0; r < organs_; ++r) byNode_.emplace_back(receivers_[r].node, r);
    std::sort(byNode_.begin(), byNode_.end());
}

std::uint32_t OrganReceivers::Of(NodeId node) const {
    if (byNode_.empty()) {
        const auto organs = receivers_.begin() + organs_;
        const auto at = std::partition_point(receivers_.begin(), organs,
                                             [node](const Receiver& r) { return r.node < node; });
        return at != organs && at->node == node
                   ? static_cast<std::uint32_t>(at - receivers_.begin())
                   : kNone;
    }
    const auto at =
        std::lower_bound(byNode_.begin(), byNode_.end(), std::pair<NodeId, std::uint32_t>{node, 0});
    return at != byNode_.end() && at->first == node ? at->second : kNone;
}

}  // namespace leaflux
