// Subtrees of a scene's topology: the nodes under some of its nodes, e.g. a sample of a
// plantation's plants whose organs a reference is solved for (ReferenceOptions::only) and
// whose leaves the errors are taken over (CompareLeaves).
#pragma once

#include <unordered_set>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

// The nodes under any of `roots`, themselves included; ids the scene does not hold are
// returned as they are, with nothing under them.
std::unordered_set<NodeId> NodesUnder(const Scene& scene, const std::vector<NodeId>& roots);

}  // namespace leaflux
