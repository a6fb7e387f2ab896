// The element and cluster hierarchy of hierarchical radiosity with clustering (Smits 1994,
// Sillion 1995; Soler 2003 §3.1, §4.1).
//
// Leaves of the hierarchy are patches: triangles of the flat scene, subdivided into four
// on demand. Clusters follow the botanical topology (plant → axis → … → organ), with
// extra spatial levels inserted wherever a cluster would have more than kMaxChildren
// children (a constrained clusterer, §4.1 last paragraph); environment surfaces and lamps
// are grouped spatially. Closed instances (closed_node.h) are nodes without children or
// triangles, under the scene node they hang from. Invariant: a node's children partition its
// patches and closed instances; `first` and `count` index the node's original triangles and
// closed instances in `triangleOrder`, contiguous.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <unordered_map>
#include <vector>

#include "solver/radiosity/closed_node.h"
#include "solver/scene/geometry.h"
#include "solver/util/sampling.h"

namespace leaflux {

inline constexpr int kMaxChildren = 8;
inline constexpr std::uint32_t kNoNode = 0xFFFFFFFFu;

struct HrcNode {
    std::uint32_t parent = kNoNode;
    std::vector<std::uint32_t> children;
    bool patch = false;
    // Every patch under the node lies in one plane with one normal, `normal` (a patch's
    // always does): a flat leaf of several triangles, a wall.
    bool flat = false;
    // Patches: the triangle (FlatScene local frame), its flat triangle and receiver.
    glm::dvec3 a{0.0}, b{0.0}, c{0.0}, normal{0.0};
    std::uint32_t triangle = 0;
    std::uint32_t receiver = 0;
    int depth = 0;             // subdivision depth of a patch (0: a flat triangle)
    std::int32_t closed = -1;  // a closed instance: its index among Hierarchy::Closed()
    // Every node: area (m²), bounding sphere, area centroid and the RMS distance of its
    // area from that centroid (m), and its original triangles.
    double areaM2 = 0.0;
    glm::dvec3 centre{0.0};
    double radius = 0.0;
    glm::dvec3 centroid{0.0};
    double spread = 0.0;
    std::uint32_t first = 0, count = 0;
};

class Hierarchy {
  public:
    Hierarchy(const Scene& scene, const FlatScene& flat, std::span<const ClosedNode> closed = {});

    std::uint32_t Root() const { return root_; }
    HrcNode& operator[](std::uint32_t i) { return nodes_[i]; }
    const HrcNode& operator[](std::uint32_t i) const { return nodes_[i]; }
    std::size_t Size() const { return nodes_.size(); }
    const FlatScene& Flat() const { return flat_; }

    // Splits a patch into four (midpoint subdivision); returns false when it is already
    // split or its children would be smaller than minAreaM2.
    bool Subdivide(std::uint32_t patch, double minAreaM2);

    const std::vector<ClosedNode>& Closed() const { return closed_; }
    std::uint32_t NodeOfClosed(std::int32_t closed) const { return closedNode_[closed]; }
    // The node a scene node became (the botanical structure's cluster), or kNoNode.
    std::uint32_t NodeOf(NodeId id) const {
        const auto it = ofScene_.find(id);
        return it == ofScene_.end() ? kNoNode : it->second;
    }

    // The nodes under `root`, parents before children, children in their order.
    std::vector<std::uint32_t> PreOrder(std::uint32_t root) const;

    // Releases the nodes made since the hierarchy had `size` (patches a local problem split):
    // the patches they were split from are whole again.
    void Truncate(std::size_t size);

    // A point on the node's surfaces, area-weighted, from two uniform numbers; with the
    // flat triangle it lies on (for rays to leave it). A point of a closed instance lies in
    // its box, of no triangle and no normal (it takes and sends light in every direction).
    struct Point {
        glm::dvec3 position, normal;
        std::uint32_t triangle;
        std::int32_t closed = -1;
    };
    Point Sample(std::uint32_t node, double u, double v) const;
    Point SampleClosed(std::int32_t closed, double u, double v) const;

    // The patch a flat triangle was made (before any subdivision), or kNoNode: its radiosity
    // is the mean of its parts'.
    std::uint32_t PatchOf(std::uint32_t triangle) const { return patchOf_[triangle]; }

    // By flat triangle, its place in hierarchy order: a node's original triangles are
    // those placed in [first, first + count).
    const std::uint32_t* Ranks() const { return orderOf_.data(); }
    // The flat triangle in place `place` of hierarchy order, or kNoTriangle for a closed
    // instance there.
    std::uint32_t TriangleAt(std::uint32_t place) const {
        const std::uint32_t entry = triangleOrder_[place];
        return entry & kClosedEntry ? kNoTriangle : entry;
    }

    // Whether the point x of flat triangle `triangle` lies on the node's surfaces.
    bool Covers(std::uint32_t node, std::uint32_t triangle, const glm::dvec3& x) const;

  private:
    std::uint32_t AddPatch(std::uint32_t triangle);
    std::uint32_t AddCluster(std::vector<std::uint32_t> children);
    std::uint32_t AddClosed(std::uint32_t index);
    // Groups children into at most kMaxChildren subtrees by median splits in space of
    // their area centroids.
    std::uint32_t Constrain(std::vector<std::uint32_t> children);
    using CentredIterator = std::vector<std::pair<glm::dvec3, std::uint32_t>>::iterator;
    std::uint32_t Constrain(CentredIterator from, CentredIterator to);
    void Finish(std::uint32_t node);
    // Sets a cluster's `flat` and `normal` from its children's.
    void FindPlane(HrcNode& cluster) const;

    const FlatScene& flat_;
    std::vector<HrcNode> nodes_;
    std::vector<glm::dvec4> moments_;  // while building, by node: Σ area × centroid, Σ area
    std::vector<ClosedNode> closed_;
    std::vector<std::uint32_t> closedNode_;              // by closed instance: its node
    std::unordered_map<NodeId, std::uint32_t> ofScene_;  // NodeOf
    // Flat triangles in hierarchy order, and closed instances as kClosedEntry | index.
    static constexpr std::uint32_t kClosedEntry = 0x80000000u;
    std::vector<std::uint32_t> triangleOrder_;
    std::vector<double> cumulativeArea_;  // over triangleOrder_, starting at 0
    // Their corners and normals in that order, so that sampling a cluster reads contiguous
    // memory rather than the flat scene's triangles scattered.
    struct Corners {
        glm::dvec3 a, b, c, normal;
    };
    std::vector<Corners> ordered_;
    std::vector<std::uint32_t> orderOf_;  // by flat triangle: its place in triangleOrder_
    std::vector<std::uint32_t> patchOf_;  // by flat triangle: PatchOf
    std::uint32_t root_ = kNoNode;
};

}  // namespace leaflux
