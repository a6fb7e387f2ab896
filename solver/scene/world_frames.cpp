#include "solver/scene/world_frames.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "solver/scene/topology.h"

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
    const Topology topology(scene);
    std::vector<std::pair<std::uint32_t, glm::dmat4>> stack;
    for (auto r = topology.Roots().rbegin(); r != topology.Roots().rend(); ++r)
        stack.push_back({*r, glm::dmat4(scene.nodes[*r].parentFromLocal)});
    while (!stack.empty()) {
        const auto [i, frame] = stack.back();
        stack.pop_back();
        visit(scene.nodes[i], frame);
        const std::span<const std::uint32_t> children = topology.Children(i);
        for (auto c = children.rbegin(); c != children.rend(); ++c)
            stack.push_back({*c, frame * glm::dmat4(scene.nodes[*c].parentFromLocal)});
    }
}

}  // namespace leaflux
