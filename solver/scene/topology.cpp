#include "solver/scene/topology.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace leaflux {

Topology::Topology(const Scene& scene) {
    const std::size_t n = scene.nodes.size();
    parent_.assign(n, kNone);
    first_.assign(n + 1, 0);
    {
        std::vector<std::pair<NodeId, std::uint32_t>> byId(n);
        for (std::uint32_t i = 0; i < n; ++i) byId[i] = {scene.nodes[i].id, i};
        // Often in id order already (ExpandPlacements leaves them so): no sort then.
        if (!std::is_sorted(byId.begin(), byId.end())) std::sort(byId.begin(), byId.end());
        for (std::uint32_t i = 0; i < n; ++i) {
            const NodeId parent = scene.nodes[i].parent;
            if (parent == kNoParent) {
                roots_.push_back(i);
                continue;
            }
            const auto it = std::lower_bound(byId.begin(), byId.end(), std::pair{parent, 0u});
            if (it == byId.end() || it->first != parent) continue;
            parent_[i] = it->second;
            ++first_[it->second + 1];
        }
    }
    std::partial_sum(first_.begin(), first_.end(), first_.begin());
    children_.resize(first_[n]);
    std::vector<std::uint32_t> filled(first_.begin(), first_.end() - 1);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (parent_[i] != kNone) children_[filled[parent_[i]]++] = i;
    }
}

}  // namespace leaflux
