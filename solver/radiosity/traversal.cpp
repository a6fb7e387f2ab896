#include "solver/radiosity/traversal.h"

#include <algorithm>
#include <queue>

namespace leaflux {

void Traversal::Index(const Hierarchy& hierarchy, std::uint32_t root, const Links& links) {
    root_ = root;
    preOrder_ = hierarchy.PreOrder(root);
    leaves_.clear();
    for (std::uint32_t n : preOrder_) {
        if (hierarchy[n].patch && hierarchy[n].children.empty()) leaves_.push_back(n);
    }
    Share(hierarchy);
    receivers_.clear();
    for (std::uint32_t n : preOrder_) {
        if (!links.node[n].empty()) receivers_.push_back(n);
    }
}

void Traversal::Share(const Hierarchy& hierarchy) {
    // A tree under a one-plant root has one big subtree: the largest subtree is split into
    // its children until there are enough to keep every thread busy.
    constexpr std::size_t kSubtrees = 64;
    const std::size_t size = hierarchy.Size();
    std::vector<std::size_t> position(size, 0), extent(size, 1);  // pre-order index, nodes
    for (std::size_t i = 0; i < preOrder_.size(); ++i) position[preOrder_[i]] = i;
    for (std::size_t i = preOrder_.size(); i-- > 1;) {
        extent[hierarchy[preOrder_[i]].parent] += extent[preOrder_[i]];
    }
    std::priority_queue<std::pair<std::size_t, std::uint32_t>> largest;
    largest.push({extent[preOrder_.front()], preOrder_.front()});
    while (largest.size() < kSubtrees && !hierarchy[largest.top().second].children.empty()) {
        const std::uint32_t n = largest.top().second;
        largest.pop();
        for (std::uint32_t child : hierarchy[n].children) largest.push({extent[child], child});
    }
    subtrees_.clear();
    for (; !largest.empty(); largest.pop()) {
        const std::uint32_t n = largest.top().second;
        subtrees_.push_back({position[n], position[n] + extent[n]});
    }
    std::sort(subtrees_.begin(), subtrees_.end());
    above_.clear();
    std::size_t next = 0;
    for (const auto& [first, last] : subtrees_) {
        for (; next < first; ++next) above_.push_back(preOrder_[next]);
        next = last;
    }
}

std::size_t Traversal::Depth(const Hierarchy& hierarchy, const Links& links) const {
    std::vector<std::size_t> depth(hierarchy.Size(), 0);
    std::size_t deepest = 0;
    for (std::uint32_t n : preOrder_) {
        const std::uint32_t parent = hierarchy[n].parent;
        if (parent != kNoNode) depth[n] = depth[parent] + 1;
        if (!links.node[n].empty() || !links.source[n].empty())
            deepest = std::max(deepest, depth[n]);
    }
    return deepest;
}

}  // namespace leaflux
