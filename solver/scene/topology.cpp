#include "solver/scene/topology.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace leaflux {

Topology::Topology(const Scene& scene) {
    const std::size_t n = scene.nodes.size();
    parent_.assign(n, kNone);
    first_.assign(n + 1, 0);
    // Each parent's index by its id: found among the nodes themselves when they are in id
    // order (as ExpandPlacements leaves them), else in a sorted copy of (id, index), 16
    // bytes a node: on the paper's plantation, 70 MB at the instanced solve's peak.
    const auto byNodeId = [](const Node& a, const Node& b) { return a.id < b.id; };
    std::vector<std::pair<NodeId, std::uint32_t>> byId;
    const bool inIdOrder = std::is_sorted(scene.nodes.begin(), scene.nodes.end(), byNodeId);
    if (!inIdOrder) {
        byId.resize(n);
        for (std::uint32_t i = 0; i < n; ++i) byId[i] = {scene.nodes[i].id, i};
        std::sort(byId.begin(), byId.end());
    }
    const auto indexOf = [&](NodeId id) -> std::uint32_t {
        if (inIdOrder) {
            const auto it = std::partition_point(scene.nodes.begin(), scene.nodes.end(),
                                                 [id](const Node& node) { return node.id < id; });
            return it != scene.nodes.end() && it->id == id
                       ? static_cast<std::uint32_t>(it - scene.nodes.begin())
                       : kNone;
        }
        const auto it = std::lower_bound(byId.begin(), byId.end(), std::pair{id, 0u});
        return it != byId.end() && it->first == id ? it->second : kNone;
    };
    for (std::uint32_t i = 0; i < n; ++i) {
        const NodeId parent = scene.nodes[i].parent;
        if (parent == kNoParent) {
            roots_.push_back(i);
            continue;
        }
        const std::uint32_t p = indexOf(parent);
        if (p == kNone) continue;
        parent_[i] = p;
        ++first_[p + 1];
    }
    byId = {};
    std::partial_sum(first_.begin(), first_.end(), first_.begin());
    children_.resize(first_[n]);
    // Filled through first_ itself, each parent's start moved on as a child is placed, then
    // moved back: a copy of the starts took 4 bytes a node more.
    for (std::uint32_t i = 0; i < n; ++i) {
        if (parent_[i] != kNone) children_[first_[parent_[i]]++] = i;
    }
    for (std::size_t k = n; k > 0; --k) first_[k] = first_[k - 1];
    first_[0] = 0;
}

bool InWalkOrder(const Scene& scene) {
    std::vector<NodeId> down;  // the ids on the way down to the node before
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        const Node& node = scene.nodes[i];
        if (i > 0 && node.id <= scene.nodes[i - 1].id) return false;
        if (node.parent == kNoParent) {
            down.clear();
        } else {
            while (!down.empty() && down.back() != node.parent) down.pop_back();
            if (down.empty()) return false;
        }
        down.push_back(node.id);
    }
    return true;
}

std::optional<Topology> TopologyUnlessInWalkOrder(const Scene& scene) {
    if (InWalkOrder(scene)) return std::nullopt;
    return Topology(scene);
}

}  // namespace leaflux
