// A scene's topology by position in Scene::nodes: each node's parent and children and the
// roots, in flat arrays (12 bytes a node; 16 more while it is made, when the nodes are not
// in id order). Hash maps of the nodes by id and a vector of children for each node, as the
// instanced solver's setup had them, took about 100 bytes a node and left the heap
// scattered once freed: 14 MiB of a plantation's peak.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

class Topology {
  public:
    static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

    // Any scene: a node whose parent id no node has is neither a root nor anyone's child
    // (Scene::Validate reports it).
    explicit Topology(const Scene& scene);

    // Node i's parent, kNone for a root or a parent no node has.
    std::uint32_t Parent(std::size_t i) const { return parent_[i]; }
    // Node i's children, in the nodes' order.
    std::span<const std::uint32_t> Children(std::size_t i) const {
        return {children_.data() + first_[i], first_[i + 1] - first_[i]};
    }
    // The nodes without a parent, in the nodes' order.
    const std::vector<std::uint32_t>& Roots() const { return roots_; }

  private:
    std::vector<std::uint32_t> parent_, first_, children_, roots_;
};

// Whether the nodes are in the order a walk from the roots visits them (depth first, the
// roots and each node's children in the nodes' order), their ids rising (none twice), as a
// generated or a placed scene has them. Such a scene is walked without a Topology, with
// the nodes on the way down to the one at hand only: on the paper's plantation a topology
// took 52 MB (12 bytes a node) at the instanced solve's peak.
bool InWalkOrder(const Scene& scene);
// The scene's Topology when its nodes are not InWalkOrder; none when they are.
std::optional<Topology> TopologyUnlessInWalkOrder(const Scene& scene);

// Each node in that walk's order as visit(i, above): its index in Scene::nodes and those
// of the nodes above it, its root first. `topology`: the scene's, or null when the scene
// is InWalkOrder. Nodes whose parent links loop or lead to no node are not visited.
template <class Visit>
void ForEachNodeDown(const Scene& scene, const Topology* topology, const Visit& visit) {
    std::vector<std::uint32_t> above;
    if (topology == nullptr) {
        for (std::uint32_t i = 0; i < scene.nodes.size(); ++i) {
            const NodeId parent = scene.nodes[i].parent;
            if (parent == kNoParent) {
                above.clear();
            } else {
                while (scene.nodes[above.back()].id != parent) above.pop_back();
            }
            visit(i, std::span<const std::uint32_t>(above));
            above.push_back(i);
        }
        return;
    }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack;  // a node, its depth
    for (auto it = topology->Roots().rbegin(); it != topology->Roots().rend(); ++it)
        stack.push_back({*it, 0});
    while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        above.resize(depth);
        visit(i, std::span<const std::uint32_t>(above));
        above.push_back(i);
        const std::span<const std::uint32_t> children = topology->Children(i);
        for (auto c = children.rbegin(); c != children.rend(); ++c)
            stack.push_back({*c, depth + 1});
    }
}

}  // namespace leaflux
