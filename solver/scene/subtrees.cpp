#include "solver/scene/subtrees.h"

#include <unordered_map>

namespace leaflux {

std::unordered_set<NodeId> NodesUnder(const Scene& scene, const std::vector<NodeId>& roots) {
    std::unordered_map<NodeId, std::vector<NodeId>> children;
    for (const Node& node : scene.nodes) {
        if (node.parent != kNoParent) children[node.parent].push_back(node.id);
    }
    std::unordered_set<NodeId> under;
    std::vector<NodeId> stack(roots.begin(), roots.end());
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (!under.insert(id).second) continue;
        if (const auto it = children.find(id); it != children.end())
            stack.insert(stack.end(), it->second.begin(), it->second.end());
    }
    return under;
}

}  // namespace leaflux
