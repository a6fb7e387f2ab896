// Subtrees of a scene's topology: the nodes under some of its nodes, e.g. a sample of a
// plantation's plants whose organs a reference is solved for (ReferenceOptions::only) and
// whose leaves the errors are taken over (CompareLeaves).
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <span>
#include <unordered_set>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

// The nodes under any of `roots`, themselves included; ids the scene does not hold are
// returned as they are, with nothing under them.
std::unordered_set<NodeId> NodesUnder(const Scene& scene, const std::vector<NodeId>& roots);

// The nodes of `scene` at `indices` (in scene order, parents first), the one whose id is
// `root` made a root of its own placed by `rootFrame`: a structure taken out of its scene,
// in its own frame (identity) or where it lies in the world.
std::vector<Node> Rerooted(const Scene& scene, std::span<const std::uint32_t> indices, NodeId root,
                           const glm::dmat4& rootFrame);

}  // namespace leaflux
