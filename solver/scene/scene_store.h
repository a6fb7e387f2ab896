// A scene that changes cycle by cycle, kept with what a change leaves as it was: each
// node's world frame and each organ's triangles placed in world coordinates. A change is
// checked and applied at the cost of what it touches — the nodes it removes, updates and
// adds, and the organs those move (a branch's new frame moves every organ above it) —
// not of the whole scene.
//
// Invariant: the scene is valid; every node has its world frame, every organ its
// triangles as PlaceMesh(mesh, world frame) placed them, every organ name its node.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

// What a growth cycle changes; fields named as in the protocol's TopologyDelta.
struct SceneChange {
    std::vector<NodeId> removed;           // each with its whole subtree
    std::vector<Node> updated;             // each replaces the node of its id
    std::vector<Node> added;               // new ids
    std::optional<std::vector<Sun>> suns;  // when given, the suns from now on
};

class SceneStore {
  public:
    // Validates the scene whole; throws InputError naming the field or node.
    explicit SceneStore(Scene scene);

    const Scene& Get() const { return scene_; }

    // Checks `change` against the scene it would make — as Scene::Validate would, but
    // only where it touches — and applies it: a removal takes its subtree, an id re-added
    // after its removal is a new node, added nodes come last. Throws InputError naming
    // the field ("delta.removed", …) or the node, and then the store is as it was.
    void Apply(SceneChange change);
    // Takes the last Apply back (a cycle whose solve failed): the scene is again what it
    // was, node order included.
    void Undo();

    // Flatten(Get()), the same bit for bit, from the placed triangles.
    FlatScene Flat() const;

  private:
    struct Kept {
        std::size_t at = 0;  // index in scene_.nodes
        glm::dmat4 worldFromLocal{1.0};
        std::vector<NodeId> children;
        // Organs: the mesh (kept alive, so no other mesh takes its address) and its
        // triangles placed by worldFromLocal.
        std::shared_ptr<const Mesh> mesh;
        std::shared_ptr<const std::vector<Triangle>> placed;
    };
    struct Plan;
    // What Apply changes, to take it back.
    struct Log {
        std::vector<std::pair<std::size_t, Node>> updated, removed;  // by index before
        std::size_t added = 0;
        std::optional<std::vector<Sun>> suns;
        std::vector<std::pair<NodeId, std::optional<Kept>>> kept;  // first values
        std::vector<std::pair<std::string, std::optional<NodeId>>> names;
    };

    Plan Check(const SceneChange& change) const;
    void Commit(Plan& plan, SceneChange& change);
    void SetKept(NodeId id, std::optional<Kept> value);
    void SetName(const std::string& name, std::optional<NodeId> owner);
    void Reindex();

    Scene scene_;
    std::unordered_map<NodeId, Kept> kept_;
    std::unordered_map<std::string, NodeId> names_;  // organ names
    std::unordered_set<std::string> fixedNames_;     // environment surfaces and emitters
    std::optional<Log> log_;
};

}  // namespace leaflux
