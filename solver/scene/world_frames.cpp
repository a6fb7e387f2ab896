#include "solver/scene/world_frames.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace leaflux {
namespace {
enum class State : std::uint8_t { kUnknown, kOnPath, kDone, kNone };
}  // namespace

WorldFrames::WorldFrames(const Scene& scene) {
    const std::size_t n = scene.nodes.size();
    // The nodes in the order of their ids.
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    if (!std::is_sorted(scene.nodes.begin(), scene.nodes.end(),
                        [](const Node& a, const Node& b) { return a.id < b.id; })) {
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            return scene.nodes[a].id < scene.nodes[b].id;
        });
    }
    ids_.resize(n);
    for (std::size_t k = 0; k < n; ++k) ids_[k] = scene.nodes[order[k]].id;
    const auto slotOf = [&](NodeId id) -> std::int64_t {
        const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
        return it != ids_.end() && *it == id ? it - ids_.begin() : -1;
    };
    frames_.assign(n, glm::dmat4(1.0));
    std::vector<State> state(n, State::kUnknown);
    std::vector<std::uint32_t> path;  // slots from a node up to the first one known
    for (std::uint32_t start = 0; start < n; ++start) {
        path.clear();
        State above = State::kDone;  // a root's parent: the world
        std::int64_t known = -1;     // the slot the walk stopped at, if any
        for (std::int64_t slot = start; slot >= 0;) {
            if (state[slot] != State::kUnknown) {
                above = state[slot] == State::kOnPath ? State::kNone : state[slot];
                known = slot;
                break;
            }
            state[slot] = State::kOnPath;
            path.push_back(static_cast<std::uint32_t>(slot));
            const NodeId parent = scene.nodes[order[slot]].parent;
            if (parent == kNoParent) break;
            slot = slotOf(parent);
            if (slot < 0) above = State::kNone;
        }
        // Down the path, each frame from its parent's.
        for (auto it = path.rbegin(); it != path.rend(); ++it) {
            state[*it] = above;
            if (above == State::kNone) continue;
            const glm::dmat4& parentFromLocal = scene.nodes[order[*it]].parentFromLocal;
            frames_[*it] = known < 0 ? parentFromLocal : frames_[known] * parentFromLocal;
            known = *it;
        }
    }
    // Nodes without a frame are taken out of the lookup.
    std::size_t kept = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (state[k] != State::kDone) continue;
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
        stack.push_back({*r, scene.nodes[*r].parentFromLocal});
    while (!stack.empty()) {
        const auto [i, frame] = stack.back();
        stack.pop_back();
        visit(scene.nodes[i], frame);
        for (std::uint32_t k = first[i + 1]; k-- > first[i];)
            stack.push_back({children[k], frame * scene.nodes[children[k]].parentFromLocal});
    }
}

}  // namespace leaflux
