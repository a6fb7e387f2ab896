#include "solver/instancing/structure.h"

#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "solver/scene/geometry.h"
#include "solver/scene/subtrees.h"
#include "solver/scene/topology.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {
// The box's pad: a thousandth of its diagonal, at least a micrometre.
constexpr double kPadFraction = 1e-3;
constexpr double kMinPadM = 1e-6;
}  // namespace

StructureAlone::StructureAlone(const Scene& scene, NodeId root) {
    std::optional<std::size_t> rootIndex;
    for (std::size_t i = 0; i < scene.nodes.size() && !rootIndex; ++i) {
        if (scene.nodes[i].id == root) rootIndex = i;
    }
    if (!rootIndex) throw InputError(ErrorCode::kNotFound, "root", "names no node", root);
    name_ = scene.NodeName(scene.nodes[*rootIndex]);
    alone_.bands = scene.bands;
    alone_.optics = scene.optics;
    // The subtree in scene order (so that receivers keep the scene's order), its root at
    // the origin of its own frame.
    const Topology topology(scene);
    std::vector<std::uint8_t> inside(scene.nodes.size(), 0);
    std::vector<std::size_t> stack{*rootIndex};
    while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        inside[i] = 1;
        const std::span<const std::uint32_t> children = topology.Children(i);
        stack.insert(stack.end(), children.begin(), children.end());
    }
    std::vector<std::uint32_t> indices;
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        if (inside[i]) indices.push_back(static_cast<std::uint32_t>(i));
    }
    alone_.nodes = Rerooted(scene, indices, root, glm::dmat4(1.0));
    flat_ = Flatten(alone_);
    if (flat_.Empty())
        throw InputError(ErrorCode::kDegenerate, "root", "has no organ under it", root);
    for (const Receiver& receiver : flat_.receivers) leafAreaM2_ += receiver.areaM2;
    for (const Node& node : alone_.nodes)
        leafCount_ += node.organ() && node.type() == NodeType::kLeaf;
    const double pad =
        std::max(kMinPadM, kPadFraction * glm::length(flat_.boundsMax - flat_.boundsMin));
    boxMin_ = flat_.boundsMin - pad;
    boxMax_ = flat_.boundsMax + pad;
    rays_ = std::make_unique<RayScene>(flat_, std::nullopt);
}

double StructureAlone::ProjectedArea(const glm::dvec3& d) const {
    const glm::dvec3 size = boxMax_ - boxMin_;
    return std::abs(d.x) * size.y * size.z + std::abs(d.y) * size.z * size.x +
           std::abs(d.z) * size.x * size.y;
}

glm::dvec3 StructureAlone::Entry(const glm::dvec3& d, double u1, double u2, double u3) const {
    const glm::dvec3 size = boxMax_ - boxMin_;
    const std::array<double, 3> seen = {std::abs(d.x) * size.y * size.z,
                                        std::abs(d.y) * size.z * size.x,
                                        std::abs(d.z) * size.x * size.y};
    // The face crossed, by its share of the projection; the entering face of that axis is
    // the one the ray meets first.
    double pick = u1 * (seen[0] + seen[1] + seen[2]);
    int axis = 0;
    while (axis < 2 && pick >= seen[axis]) pick -= seen[axis++];
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    glm::dvec3 p;
    p[axis] = d[axis] > 0.0 ? boxMin_[axis] : boxMax_[axis];
    p[a] = boxMin_[a] + u2 * size[a];
    p[b] = boxMin_[b] + u3 * size[b];
    return p;
}

}  // namespace leaflux
