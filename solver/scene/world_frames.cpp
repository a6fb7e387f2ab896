#include "solver/scene/world_frames.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace leaflux {

WorldFrames::WorldFrames(const Scene& scene) {
    ids_.reserve(scene.nodes.size());
    for (const Node& node : scene.nodes) ids_.push_back(node.id);
    std::sort(ids_.begin(), ids_.end());
    frames_.assign(ids_.size(), glm::dmat4(1.0));
    std::vector<std::uint8_t> framed(ids_.size(), 0);
    ForEachWorldFrame(scene, [&](const Node& node, const glm::dmat4& frame) {
        const std::size_t slot = std::lower_bound(ids_.begin(), ids_.end(), node.id) - ids_.begin();
        frames_[slot] = frame;
        framed[slot] = 1;
    });
    // Nodes the walk did not reach (their parent links loop or lead nowhere) have no frame.
    std::size_t kept = 0;
    for (std::size_t k = 0; k < ids_.size(); ++k) {
        if (!framed[k]) continue;
        ids_[kept] = ids_[k];
        frames_[kept++] = frames_[k];
    }
    ids_.resize(kept);
    frames_.resize(kept);
}

glm::dmat4 WorldFrames::at(NodeId id) const {
    const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
    if (it == ids_.end() || *it != id)
        throw std::out_of_range("no frame for node " + std::to_string(id));
    return frames_[it - ids_.begin()];
}

void ForEachWorldFrame(const Scene& scene,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit) {
    const std::size_t n = scene.nodes.size();
    std::vector<std::pair<NodeId, std::uint32_t>> byId(n);
    for (std::uint32_t i = 0; i < n; ++i) byId[i] = {scene.nodes[i].id, i};
    std::sort(byId.begin(), byId.end());
    const auto indexOf = [&](NodeId id) -> std::int64_t {
        const auto it = std::lower_bound(byId.begin(), byId.end(), std::pair{id, 0u});
        return it != byId.end() && it->first == id ? static_cast<std::int64_t>(it->second) : -1;
    };
    // Each node's children, in the nodes' order: first[i] .. first[i + 1] of `children`.
    std::vector<std::uint32_t> first(n + 1, 0), children(n), parentOf(n);
    std::vector<std::uint32_t> roots;
    for (std::uint32_t i = 0; i < n; ++i) {
        const NodeId parent = scene.nodes[i].parent;
        const std::int64_t p = parent == kNoParent ? -1 : indexOf(parent);
        parentOf[i] = p < 0 ? static_cast<std::uint32_t>(n) : static_cast<std::uint32_t>(p);
        if (parent == kNoParent) roots.push_back(i);
        if (p >= 0) ++first[p + 1];
    }
    std::partial_sum(first.begin(), first.end(), first.begin());
    std::vector<std::uint32_t> filled(first.begin(), first.end() - 1);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (parentOf[i] < n) children[filled[parentOf[i]]++] = i;
    }
    std::vector<std::pair<std::uint32_t, glm::dmat4>> stack;
    for (auto r = roots.rbegin(); r != roots.rend(); ++r)
        stack.push_back({*r, glm::dmat4(scene.nodes[*r].parentFromLocal)});
    while (!stack.empty()) {
        const auto [i, frame] = stack.back();
        stack.pop_back();
        visit(scene.nodes[i], frame);
        for (std::uint32_t k = first[i + 1]; k-- > first[i];)
            stack.push_back(
                {children[k], frame * glm::dmat4(scene.nodes[children[k]].parentFromLocal)});
    }
}

}  // namespace leaflux
