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

std::vector<Node> Rerooted(const Scene& scene, std::span<const std::uint32_t> indices, NodeId root,
                           const glm::dmat4& rootFrame) {
    std::vector<Node> nodes;
    nodes.reserve(indices.size());
    for (std::size_t i : indices) {
        Node node = scene.nodes[i];
        if (node.id == root) {
            node.parent = kNoParent;
            node.Edit().parentFromLocal = rootFrame;
        }
        nodes.push_back(std::move(node));
    }
    return nodes;
}

}  // namespace leaflux
