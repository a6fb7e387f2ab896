// Where every node of a scene is in the world: worldFromLocal, the product of the
// parentFromLocal frames from its root down.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <vector>

#include "solver/scene/scene.h"
#include "solver/scene/topology.h"

namespace leaflux {

// The frames are kept in the order of the nodes' ids, found by binary search: 136 bytes a
// node, made without an allocation per node. A hash map of frames by id, built with a
// second map of the nodes by id, took about 200 bytes a node at its peak (the 543,000 nodes
// of a plantation of 233 trees: 113 MB, one of the largest things an instanced solve
// held).
class WorldFrames {
  public:
    // A node whose parent links loop, or lead to an id no node has, gets no frame
    // (Scene::Validate reports both).
    explicit WorldFrames(const Scene& scene);

    // The frame of the node with this id; throws std::out_of_range when it has none.
    glm::dmat4 at(NodeId id) const;
    std::size_t size() const { return ids_.size(); }

  private:
    std::vector<NodeId> ids_;  // rising
    std::vector<glm::dmat4> frames_;
};

// Each node with its frame in the world, parents before children (depth first from the
// roots, each node's children in the nodes' order), the frames not kept: about 30 bytes a
// node for the walk (Topology), where WorldFrames keeps 136, and none when the nodes are in
// that order already, their ids rising (as a generated or placed scene has them). Nodes
// whose parent links loop or lead to no node are not visited.
void ForEachWorldFrame(const Scene& scene,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit);
// The same over the scene's topology, when the caller has it; null for a scene InWalkOrder.
void ForEachWorldFrame(const Scene& scene, const Topology& topology,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit);
void ForEachWorldFrame(const Scene& scene, const Topology* topology,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit);
// Each node of the subtree under node `root` (its index in Scene::nodes), in the same
// order, with its frame in the one `rootFrame` is given in: the root's is rootFrame, each
// node's below it its parent's times its parentFromLocal. The identity gives the frames
// in the root's own frame (an instance's).
void ForEachFrameUnder(const Scene& scene, const Topology& topology, std::size_t root,
                       const glm::dmat4& rootFrame,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit);
// `topology` null for a scene InWalkOrder: the subtree is the nodes from `root` on while
// they lie under it.
void ForEachFrameUnder(const Scene& scene, const Topology* topology, std::size_t root,
                       const glm::dmat4& rootFrame,
                       const std::function<void(const Node&, const glm::dmat4&)>& visit);

// worldFromLocal of every node, by id. Requires a validated scene (no cycles).
inline WorldFrames WorldFromLocal(const Scene& scene) { return WorldFrames(scene); }

}  // namespace leaflux
