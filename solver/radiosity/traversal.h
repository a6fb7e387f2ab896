// The orders in which the sweeps visit a hierarchy: pre-order (parents before children),
// the leaf patches, the nodes that receive links, and a partition of the pre-order into
// subtrees that the sweeps run in parallel (with the few nodes above them run alone).
// Made anew after refinement changed the hierarchy (Index); owns only its index vectors.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "solver/radiosity/hierarchy.h"
#include "solver/radiosity/links.h"

namespace leaflux {

class Traversal {
  public:
    // Indexes the hierarchy under `root` as it stands, with the links it holds: at the cost
    // of the nodes under it, whatever the hierarchy's size (a local problem's few).
    void Index(const Hierarchy& hierarchy, std::uint32_t root, const Links& links);

    std::uint32_t Root() const { return root_; }
    const std::vector<std::uint32_t>& PreOrder() const { return preOrder_; }
    const std::vector<std::uint32_t>& Leaves() const { return leaves_; }        // leaf patches
    const std::vector<std::uint32_t>& Receivers() const { return receivers_; }  // with links
    // Ranges of PreOrder, each a subtree, and the nodes above them, in pre-order.
    const std::vector<std::pair<std::size_t, std::size_t>>& Subtrees() const { return subtrees_; }
    const std::vector<std::uint32_t>& Above() const { return above_; }
    // Levels from the root to the deepest node with a link.
    std::size_t Depth(const Hierarchy& hierarchy, const Links& links) const;

  private:
    void Share(const Hierarchy& hierarchy);

    std::uint32_t root_ = kNoNode;
    std::vector<std::uint32_t> preOrder_, leaves_, receivers_, above_;
    std::vector<std::pair<std::size_t, std::size_t>> subtrees_;
};

}  // namespace leaflux
