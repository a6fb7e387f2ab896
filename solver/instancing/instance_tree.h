// The parts of a scene that hierarchical instantiation solves one at a time (Soler 2003
// §3.2–3.4, Fig. 5): the top — everything that lies in no instance, and the largest
// instances closed — and, for each instance, its contents: the nodes under it that lie in
// no smaller instance, and its largest smaller instances closed. Each node belongs to one
// part; an instance is the root of its own part and a closed member of its parent's.
//
// Instances are the structures whose signature the policy gives (signature.h). Everything
// is in scene order, so it depends on nothing but the scene and the signatures.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "solver/instancing/signature.h"
#include "solver/radiosity/closed_node.h"
#include "solver/scene/scene.h"

namespace leaflux {

class InstanceTree {
  public:
    static constexpr std::uint32_t kTop = 0;

    struct Part {
        NodeId root = kNoParent;               // the instance (kNoParent: the top)
        std::size_t rootIndex = 0;             // its index into Scene::nodes
        std::uint32_t parent = kTop;           // the part it is closed in
        int depth = 0;                         // 0: the top, 1: its largest instances, …
        std::string signature;                 // the instance's
        std::vector<std::uint32_t> nodes;      // indices into Scene::nodes, in scene order
        std::vector<std::uint32_t> instances;  // the parts closed in it, in scene order
        // The instance's box in its own frame (its root's local frame) and its organs' area
        // (one side, as an original's), over its whole subtree.
        glm::dvec3 boxMin{0.0}, boxMax{0.0};
        double leafAreaM2 = 0.0;
        std::shared_ptr<const AreaGrid> area;  // where in the box that area lies
        std::int64_t triangles = 0;            // of its own nodes' organs
        // Solved as a part of the instance holding it, its nodes among that part's (Merge);
        // `nodes` and `instances` are then empty.
        bool merged = false;
    };

    // `signatures` of a validated scene (ComputeSignatures).
    InstanceTree(const Scene& scene, const SceneSignatures& signatures);

    // Each instance of at most `triangles` organ triangles in all, whose smaller instances
    // all open (`opens`), is made one part with them: their nodes join its own, and they
    // are marked merged; the largest such instances first, so that the parts are as large
    // as `triangles` allows. 0: none.
    void Merge(std::int64_t triangles, const std::function<bool(std::uint32_t)>& opens);

    // The parts reached from the top through the instances that `opens` (the top first),
    // each placed by its root's frame in `world` when given (else the identity).
    std::vector<std::uint32_t> Opened(
        const std::function<bool(std::uint32_t, const glm::dmat4& worldFromRoot)>& opens,
        const Scene* world = nullptr) const;

    // Whether part q holds an instance of `type`, in it or in its instances (`scene`: the
    // tree's).
    bool HoldsInstanceOf(const Scene& scene, std::uint32_t q, NodeType type) const;
    // Whether a node of `type` lies in part q under its root, in it or in its instances.
    bool HoldsNodeOf(const Scene& scene, std::uint32_t q, NodeType type) const;

    const std::vector<Part>& Parts() const { return parts_; }
    const Part& operator[](std::uint32_t part) const { return parts_[part]; }
    int Depth() const { return depth_; }  // of the deepest instance (0: none)

  private:
    std::vector<Part> parts_;
    int depth_ = 0;
};

}  // namespace leaflux
