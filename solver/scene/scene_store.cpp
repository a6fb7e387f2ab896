#include "solver/scene/scene_store.h"

#include <algorithm>

#include "solver/scene/world_frames.h"
#include "solver/util/check.h"
#include "solver/util/error.h"

namespace leaflux {

// A change checked against the scene: the nodes it removes (with their subtrees), the
// nodes it updates or adds (pointing into the change), and every node it touches with its
// new world frame and, for organs, placed triangles.
struct SceneStore::Plan {
    std::unordered_set<NodeId> removed;
    std::unordered_map<NodeId, const Node*> changed;
    std::vector<NodeId> order;  // changed nodes: updated, then added, as the change lists them
    std::unordered_map<NodeId, Kept> touched;
};

SceneStore::SceneStore(Scene scene) : scene_(std::move(scene)) {
    scene_.Validate();
    const auto worldFromLocal = WorldFromLocal(scene_);
    for (std::size_t i = 0; i < scene_.nodes.size(); ++i) {
        const Node& node = scene_.nodes[i];
        Kept& kept = kept_[node.id];
        kept.at = i;
        kept.worldFromLocal = worldFromLocal.at(node.id);
        if (node.organ()) {
            kept.mesh = node.organ()->mesh;
            kept.placed = std::make_shared<const std::vector<Triangle>>(
                PlaceMesh(*kept.mesh, kept.worldFromLocal));
            names_.emplace(scene_.NodeName(node), node.id);
        }
    }
    for (const Node& node : scene_.nodes) {
        if (node.parent != kNoParent) kept_.at(node.parent).children.push_back(node.id);
    }
    for (const Surface& surface : scene_.environment) fixedNames_.insert(surface.name);
    for (const Emitter& emitter : scene_.sources.emitters) fixedNames_.insert(emitter.name);
}

void SceneStore::Apply(SceneChange change) {
    Plan plan = Check(change);
    Commit(plan, change);
}

SceneStore::Plan SceneStore::Check(const SceneChange& change) const {
    Plan plan;
    for (NodeId id : change.removed) {
        if (!kept_.count(id))
            throw InputError(ErrorCode::kNotFound, "delta.removed", "no such node", id);
        plan.removed.insert(id);
    }
    for (std::vector<NodeId> stack(plan.removed.begin(), plan.removed.end()); !stack.empty();) {
        const NodeId id = stack.back();
        stack.pop_back();
        for (NodeId child : kept_.at(id).children) {
            if (plan.removed.insert(child).second) stack.push_back(child);
        }
    }
    for (const Node& node : change.updated) {
        if (!kept_.count(node.id) || plan.removed.count(node.id)) {
            throw InputError(ErrorCode::kNotFound, "delta.updated", "no such node to update",
                             node.id);
        }
        if (!plan.changed.emplace(node.id, &node).second) {
            throw InputError(ErrorCode::kAlreadyExists, "delta.updated",
                             "the node is updated twice", node.id);
        }
        plan.order.push_back(node.id);
    }
    for (const Node& node : change.added) {
        if ((kept_.count(node.id) && !plan.removed.count(node.id)) ||
            !plan.changed.emplace(node.id, &node).second) {
            throw InputError(ErrorCode::kAlreadyExists, "delta.added", "a node with this id exists",
                             node.id);
        }
        plan.order.push_back(node.id);
    }
    // The scene the change makes, node by node.
    const auto after = [&](NodeId id) -> const Node* {
        if (const auto it = plan.changed.find(id); it != plan.changed.end()) return it->second;
        if (plan.removed.count(id)) return nullptr;
        const auto it = kept_.find(id);
        return it == kept_.end() ? nullptr : &scene_.nodes[it->second.at];
    };
    const std::size_t count = scene_.nodes.size() - plan.removed.size() + change.added.size();
    for (NodeId id : plan.order) {
        const Node& node = *plan.changed.at(id);
        ValidateNode(scene_, node);
        if (node.parent != kNoParent && !after(node.parent)) {
            throw InputError(ErrorCode::kNotFound, "parent",
                             "names unknown node " + std::to_string(node.parent), node.id);
        }
    }
    // A loop of parent links goes through a changed node: the scene before had none.
    std::unordered_set<NodeId> rooted;
    for (NodeId id : plan.order) {
        std::vector<NodeId> path;
        for (NodeId at = id; at != kNoParent && !rooted.count(at); at = after(at)->parent) {
            path.push_back(at);
            if (path.size() > count) {
                throw InputError(ErrorCode::kCycle, "parent", "the parent links of this node loop",
                                 id);
            }
        }
        rooted.insert(path.begin(), path.end());
    }
    // The nodes the change moves: changed nodes and everything under them.
    std::unordered_map<NodeId, std::vector<NodeId>> changedChildren;
    for (NodeId id : plan.order) changedChildren[plan.changed.at(id)->parent].push_back(id);
    std::vector<NodeId> stack(plan.order.rbegin(), plan.order.rend());
    std::vector<NodeId> moved;
    std::unordered_set<NodeId> seen;
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (!seen.insert(id).second) continue;
        moved.push_back(id);
        if (const auto it = changedChildren.find(id); it != changedChildren.end())
            stack.insert(stack.end(), it->second.begin(), it->second.end());
        if (const auto it = kept_.find(id); it != kept_.end()) {
            for (NodeId child : it->second.children) {
                if (!plan.removed.count(child) && !plan.changed.count(child))
                    stack.push_back(child);
            }
        }
    }
    // World frames, parents first (a moved node's parent is moved or kept as it was).
    for (NodeId id : moved) {
        std::vector<NodeId> chain;
        for (NodeId at = id; at != kNoParent && seen.count(at) && !plan.touched.count(at);
             at = after(at)->parent) {
            chain.push_back(at);
        }
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const Node& node = *after(*it);
            const glm::dmat4 worldFromParent = node.parent == kNoParent ? glm::dmat4(1.0)
                                               : plan.touched.count(node.parent)
                                                   ? plan.touched.at(node.parent).worldFromLocal
                                                   : kept_.at(node.parent).worldFromLocal;
            plan.touched[*it].worldFromLocal = worldFromParent * glm::dmat4(node.parentFromLocal());
        }
    }
    // Organs: checked and placed again unless mesh and world frame are as they were.
    for (NodeId id : moved) {
        const Node& node = *after(id);
        if (!node.organ()) continue;
        Kept& kept = plan.touched.at(id);
        kept.mesh = node.organ()->mesh;
        const auto before = kept_.find(id);
        if (before != kept_.end() && !plan.removed.count(id) && before->second.mesh == kept.mesh &&
            before->second.worldFromLocal == kept.worldFromLocal) {
            kept.placed = before->second.placed;
        } else {
            ValidateMesh(kept.mesh.get(), kept.worldFromLocal, "organ.mesh", id);
            kept.placed = std::make_shared<const std::vector<Triangle>>(
                PlaceMesh(*kept.mesh, kept.worldFromLocal));
        }
    }
    // Organ names: those the change gives must be free once it is applied.
    std::unordered_set<std::string> claimed;
    for (NodeId id : plan.order) {
        const Node& node = *plan.changed.at(id);
        if (!node.organ()) continue;
        const std::string name = scene_.NodeName(node);
        const auto held = names_.find(name);
        if (fixedNames_.count(name) || !claimed.insert(name).second ||
            (held != names_.end() && held->second != id && !plan.removed.count(held->second) &&
             !plan.changed.count(held->second))) {
            throw InputError(ErrorCode::kAlreadyExists, "name",
                             "organ name '" + name + "' is used twice", id);
        }
    }
    if (change.suns) {
        for (std::size_t i = 0; i < change.suns->size(); ++i)
            ValidateSun(scene_, (*change.suns)[i], "suns[" + std::to_string(i) + "]");
    }
    return plan;
}

void SceneStore::Commit(Plan& plan, SceneChange& change) {
    log_.emplace();
    if (change.suns) {
        log_->suns = std::move(scene_.sources.suns);
        scene_.sources.suns = std::move(*change.suns);
    }
    // The new state of every node whose state changes: the touched ones, and the parents
    // whose children change. Removed nodes give up their names and places; updated ones
    // give up their names, and their places if they change parents.
    std::unordered_map<NodeId, Kept> next = std::move(plan.touched);
    const auto state = [&](NodeId id) -> Kept& {
        const auto [it, inserted] = next.try_emplace(id);
        if (inserted) it->second = kept_.at(id);
        return it->second;
    };
    for (auto& [id, kept] : next) {
        if (const auto it = kept_.find(id); it != kept_.end() && !plan.removed.count(id)) {
            kept.at = it->second.at;
            kept.children = it->second.children;
        }
    }
    const auto release = [&](const Node& node) {
        if (node.organ()) {
            const std::string name = scene_.NodeName(node);
            if (names_.at(name) == node.id) SetName(name, std::nullopt);
        }
    };
    for (NodeId id : plan.removed) {
        const Node& node = scene_.nodes[kept_.at(id).at];
        release(node);
        if (node.parent != kNoParent && !plan.removed.count(node.parent))
            std::erase(state(node.parent).children, id);
    }
    for (Node& node : change.updated) {
        const std::size_t at = kept_.at(node.id).at;
        Node& before = scene_.nodes[at];
        release(before);
        if (before.parent != node.parent) {
            if (before.parent != kNoParent) std::erase(state(before.parent).children, node.id);
            if (node.parent != kNoParent) state(node.parent).children.push_back(node.id);
        }
        log_->updated.emplace_back(at, std::move(before));
        scene_.nodes[at] = std::move(node);
    }
    if (!plan.removed.empty()) {
        for (std::size_t i = 0; i < scene_.nodes.size(); ++i) {
            // Moved into the log: erase_if below reads only the ids, which stay.
            if (plan.removed.count(scene_.nodes[i].id))
                log_->removed.emplace_back(i, std::move(scene_.nodes[i]));
        }
        std::erase_if(scene_.nodes, [&](const Node& n) { return plan.removed.count(n.id) > 0; });
        for (NodeId id : plan.removed) {
            if (!next.count(id)) SetKept(id, std::nullopt);
        }
    }
    for (Node& node : change.added) {
        next.at(node.id).at = scene_.nodes.size();
        if (node.parent != kNoParent) state(node.parent).children.push_back(node.id);
        scene_.nodes.push_back(std::move(node));
    }
    log_->added = change.added.size();
    for (auto& [id, kept] : next) SetKept(id, std::move(kept));
    // Places after the removed nodes moved up: found again before they are read.
    if (!plan.removed.empty()) Reindex();
    for (NodeId id : plan.order) {
        const Node& node = scene_.nodes[kept_.at(id).at];
        if (node.organ()) SetName(scene_.NodeName(node), id);
    }
}

void SceneStore::Undo() {
    LEAFLUX_CHECK(log_.has_value());
    Log log = std::move(*log_);
    log_.reset();
    for (auto it = log.names.rbegin(); it != log.names.rend(); ++it) {
        if (it->second) {
            names_[it->first] = *it->second;
        } else {
            names_.erase(it->first);
        }
    }
    for (auto it = log.kept.rbegin(); it != log.kept.rend(); ++it) {
        if (it->second) {
            kept_[it->first] = std::move(*it->second);
        } else {
            kept_.erase(it->first);
        }
    }
    scene_.nodes.resize(scene_.nodes.size() - log.added);
    for (auto& [at, node] : log.removed)
        scene_.nodes.insert(scene_.nodes.begin() + static_cast<std::ptrdiff_t>(at),
                            std::move(node));
    for (auto& [at, node] : log.updated) scene_.nodes[at] = std::move(node);
    if (log.suns) scene_.sources.suns = std::move(*log.suns);
    Reindex();
}

void SceneStore::SetKept(NodeId id, std::optional<Kept> value) {
    const auto it = kept_.find(id);
    log_->kept.emplace_back(id, it == kept_.end() ? std::nullopt : std::optional<Kept>(it->second));
    if (value) {
        kept_[id] = std::move(*value);
    } else if (it != kept_.end()) {
        kept_.erase(it);
    }
}

void SceneStore::SetName(const std::string& name, std::optional<NodeId> owner) {
    const auto it = names_.find(name);
    log_->names.emplace_back(name,
                             it == names_.end() ? std::nullopt : std::optional<NodeId>(it->second));
    if (owner) {
        names_[name] = *owner;
    } else if (it != names_.end()) {
        names_.erase(it);
    }
}

void SceneStore::Reindex() {
    for (std::size_t i = 0; i < scene_.nodes.size(); ++i) kept_.at(scene_.nodes[i].id).at = i;
}

FlatScene SceneStore::Flat() const {
    return Flatten(scene_, [&](const Node& organ) -> const std::vector<Triangle>& {
        return *kept_.at(organ.id).placed;
    });
}

}  // namespace leaflux
