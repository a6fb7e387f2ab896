// A scene's topology by position in Scene::nodes: each node's parent and children and the
// roots, in flat arrays (12 bytes a node; 16 more while it is made, when the nodes are not
// in id order). Hash maps of the nodes by id and a vector of children for each node, as the
// instanced solver's setup had them, took about 100 bytes a node and left the heap
// scattered once freed: 14 MiB of a plantation's peak.
#pragma once

#include <cstdint>
#include <span>
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

}  // namespace leaflux
