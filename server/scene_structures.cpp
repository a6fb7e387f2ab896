#include "server/scene_structures.h"

#include <algorithm>
#include <array>
#include <compare>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "solver/util/error.h"

namespace leaflux {
namespace {

std::string StructureField(const std::string& name) { return "structures[" + name + "]"; }

// ---- Reading --------------------------------------------------------------------------

// A structure's nodes, parsed once and checked against its local ids.
struct ParsedStructure {
    const v1::Structure* message = nullptr;
    std::vector<Node> nodes;
};

ParsedStructure Parse(const std::string& name, const v1::Structure& message,
                      const MeshLibrary& meshes) {
    const std::string field = StructureField(name);
    ParsedStructure parsed;
    parsed.message = &message;
    std::unordered_set<NodeId> ids;
    for (const v1::Node& in : message.nodes()) {
        try {
            parsed.nodes.push_back(NodeFromProto(in, meshes));
        } catch (const InputError& e) {
            throw InputError(e.Code(), field + ".nodes." + e.Field(),
                             e.Message() + " (local id " + std::to_string(in.id()) + ")", e.Node());
        }
        if (in.id() == 0) {
            throw InputError(ErrorCode::kInvalidArgument, field + ".nodes.id",
                             "a structure's node needs a non-zero local id");
        }
        if (!ids.insert(in.id()).second) {
            throw InputError(ErrorCode::kAlreadyExists, field + ".nodes.id",
                             "local id " + std::to_string(in.id()) + " is used by two nodes",
                             in.id());
        }
        // Every copy's name from one pattern (NodeBody::nameHasId), not a string of its own.
        if (in.name().find("{id}") != std::string::npos)
            parsed.nodes.back().Edit().nameHasId = true;
    }
    for (const Node& node : parsed.nodes) {
        if (node.parent != kNoParent && !ids.count(node.parent)) {
            throw InputError(
                ErrorCode::kNotFound, field + ".nodes.parent",
                "names no node of the structure (local id " + std::to_string(node.parent) + ")",
                node.id);
        }
    }
    for (int k = 0; k < message.placements_size(); ++k) {
        const NodeId parent = message.placements(k).parent();
        if (parent != kNoParent && !ids.count(parent)) {
            throw InputError(
                ErrorCode::kNotFound, field + ".placements[" + std::to_string(k) + "].parent",
                "names no node of the structure (local id " + std::to_string(parent) + ")");
        }
    }
    return parsed;
}

// One placement to expand: a structure, the offset of its ids, where its roots hang.
struct Job {
    const std::string* structure;
    const v1::Placement* placement;  // the message placing it
    NodeId offset;
    NodeId rootParent;
    glm::dmat4 rootFrame;
    std::string field;  // the placement, for errors
};

// Every node of the scene's placements, appended to `nodes`. With `used` (the ids taken so
// far), a placed id already taken throws, naming the placement; without, ids are not checked.
void Expand(const v1::Scene& message, const MeshLibrary& meshes, std::vector<Node>& nodes,
            std::unordered_set<NodeId>* used) {
    std::unordered_map<std::string, ParsedStructure> parsed;
    auto structureNamed = [&](const std::string& name) -> const ParsedStructure& {
        auto it = parsed.find(name);
        if (it == parsed.end()) {
            it = parsed.emplace(name, Parse(name, message.structures().at(name), meshes)).first;
        }
        return it->second;
    };
    // The roots a placement made last, by (placement, root): a placement inside a structure
    // makes the same roots, at the same frame, in every copy of that structure (a branch in
    // each of 233 copies of a tree), and they share one body.
    struct Made {
        bool any = false;
        glm::dmat4 frame{1.0};
        Node root;
    };
    std::map<std::pair<const v1::Placement*, std::size_t>, Made> roots;
    std::vector<Job> jobs;
    for (int i = 0; i < message.placements_size(); ++i) {
        const v1::Placement& p = message.placements(i);
        const std::string field = "placements[" + std::to_string(i) + "]";
        jobs.push_back({&p.structure(), &p, p.id_offset(), p.parent(),
                        FrameFromProto(p.frame(), field + ".frame"), field});
    }
    constexpr NodeId kMaxId = std::numeric_limits<NodeId>::max();
    while (!jobs.empty()) {
        const Job job = std::move(jobs.back());
        jobs.pop_back();
        const ParsedStructure& s = structureNamed(*job.structure);
        auto placed = [&](NodeId local) {
            if (local > kMaxId - job.offset) {
                throw InputError(ErrorCode::kInvalidArgument, job.field + ".id_offset",
                                 "places local id " + std::to_string(local) + " of structure '" +
                                     *job.structure + "' past the largest id");
            }
            return local + job.offset;
        };
        for (std::size_t k = 0; k < s.nodes.size(); ++k) {
            Node node = s.nodes[k];
            const NodeId local = node.id, id = placed(local);
            node.id = id;
            if (used && !used->insert(node.id).second) {
                throw InputError(ErrorCode::kAlreadyExists, job.field + ".id_offset",
                                 "places node " + std::to_string(local) + " of structure '" +
                                     *job.structure + "' at id " + std::to_string(node.id) +
                                     ", which another node already has",
                                 node.id);
            }
            if (node.parent != kNoParent) {
                node.parent = placed(node.parent);
                nodes.push_back(std::move(node));
                continue;
            }
            Made& made = roots[{job.placement, k}];
            if (!made.any || made.frame != job.rootFrame) {
                made.any = true;
                made.frame = job.rootFrame;
                made.root = s.nodes[k];
                if (made.root.parentFromLocal() == Frame()) {
                    made.root.Edit().parentFromLocal = job.rootFrame;  // exact: no product
                } else {
                    made.root.Edit().parentFromLocal =
                        job.rootFrame * glm::dmat4(made.root.parentFromLocal());
                }
            }
            node = made.root;
            node.id = id;
            node.parent = job.rootParent;
            nodes.push_back(std::move(node));
        }
        for (int k = 0; k < s.message->placements_size(); ++k) {
            const v1::Placement& q = s.message->placements(k);
            const std::string field =
                StructureField(*job.structure) + ".placements[" + std::to_string(k) + "]";
            const glm::dmat4 frame = FrameFromProto(q.frame(), field + ".frame");
            if (q.id_offset() > kMaxId - job.offset) {
                throw InputError(ErrorCode::kInvalidArgument, field + ".id_offset",
                                 "with the offset of " + job.field + ", passes the largest id");
            }
            const bool atRoot = q.parent() == kNoParent;
            jobs.push_back({&q.structure(), &q, job.offset + q.id_offset(),
                            atRoot ? job.rootParent : placed(q.parent()),
                            atRoot ? job.rootFrame * frame : frame,
                            field + " (in " + job.field + ")"});
        }
    }
}

}  // namespace

std::size_t CountPlacedNodes(const v1::Scene& message, std::size_t topLevelNodes,
                             const SceneLimits& limits) {
    const auto& structures = message.structures();
    constexpr double kCap = 1e18;  // counts saturate here: a nest of placements multiplies
    std::unordered_map<std::string, double> done;  // nodes a structure makes, placements in
    std::vector<std::string> path;                 // structures being counted, outermost first
    struct Visit {
        const v1::Structure* structure;
        int next;
        double total;
    };
    std::vector<Visit> stack;
    auto count = [&](const std::string& name, const std::string& field) -> double {
        if (const auto it = done.find(name); it != done.end()) return it->second;
        const auto it = structures.find(name);
        if (it == structures.end())
            throw InputError(ErrorCode::kNotFound, field, "names no structure '" + name + "'");
        stack.push_back({&it->second, 0, static_cast<double>(it->second.nodes_size())});
        path.push_back(name);
        while (!stack.empty()) {
            Visit& top = stack.back();
            if (top.next < top.structure->placements_size()) {
                const int k = top.next++;
                const std::string& child = top.structure->placements(k).structure();
                const std::string childField = StructureField(path.back()) + ".placements[" +
                                               std::to_string(k) + "].structure";
                if (const auto d = done.find(child); d != done.end()) {
                    top.total = std::min(kCap, top.total + d->second);
                    continue;
                }
                if (const auto on = std::find(path.begin(), path.end(), child); on != path.end()) {
                    std::string loop;
                    for (auto p = on; p != path.end(); ++p) loop += "'" + *p + "' → ";
                    throw InputError(
                        ErrorCode::kCycle, childField,
                        "places a structure inside itself: " + loop + "'" + child + "'");
                }
                const auto c = structures.find(child);
                if (c == structures.end()) {
                    throw InputError(ErrorCode::kNotFound, childField,
                                     "names no structure '" + child + "'");
                }
                stack.push_back({&c->second, 0, static_cast<double>(c->second.nodes_size())});
                path.push_back(child);
                continue;
            }
            const double total = top.total;
            done[path.back()] = total;
            stack.pop_back();
            path.pop_back();
            if (!stack.empty()) stack.back().total = std::min(kCap, stack.back().total + total);
        }
        return done.at(name);
    };
    double total = static_cast<double>(topLevelNodes);
    for (int i = 0; i < message.placements_size(); ++i) {
        total += count(message.placements(i).structure(),
                       "placements[" + std::to_string(i) + "].structure");
        if (total > static_cast<double>(limits.maxNodes)) {
            throw TooLarge("placements", "the nodes and placements make more than " +
                                             std::to_string(limits.maxNodes) +
                                             " nodes; at most that many a scene (--max-nodes)");
        }
    }
    return static_cast<std::size_t>(total) - topLevelNodes;
}

void ExpandPlacements(const v1::Scene& message, const MeshLibrary& meshes,
                      std::vector<Node>& nodes) {
    if (message.placements_size() == 0) return;
    std::vector<NodeId> own;
    own.reserve(nodes.size());
    for (const Node& node : nodes) own.push_back(node.id);
    Expand(message, meshes, nodes, nullptr);
    std::sort(nodes.begin(), nodes.end(), [](const Node& a, const Node& b) { return a.id < b.id; });
    const auto same = [](const Node& a, const Node& b) { return a.id == b.id; };
    if (std::adjacent_find(nodes.begin(), nodes.end(), same) == nodes.end()) return;
    // An id twice: expanded again, each id checked as it is placed, to name the placement that
    // placed it a second time (a hash set of every id while expanding cost 24 bytes a node,
    // freed in pieces among the bodies kept: 100 MB of the paper's plantation stayed
    // resident). Twice among the scene's own nodes instead, Scene::Validate names it.
    std::unordered_set<NodeId> used(own.begin(), own.end());
    std::vector<Node> again;
    Expand(message, meshes, again, &used);
}

// ---- Writing --------------------------------------------------------------------------

namespace {

// Meshes used by more than one organ are written once in Scene.meshes and referenced.
class MeshWriter {
  public:
    MeshWriter(const Scene& scene, v1::Scene& message) : message_(message) {
        for (const Node& node : scene.nodes) {
            if (node.organ()) ++uses_[node.organ()->mesh.get()];
        }
    }

    void Write(const Organ& organ, v1::Organ* out) {
        out->set_optics(organ.opticsId);
        const Mesh* mesh = organ.mesh.get();
        if (uses_[mesh] == 1) {
            MeshToProto(*mesh, out->mutable_mesh());
            return;
        }
        auto [it, added] = names_.emplace(mesh, "mesh" + std::to_string(names_.size()));
        if (added) MeshToProto(*mesh, &(*message_.mutable_meshes())[it->second]);
        out->set_mesh_ref(it->second);
    }

  private:
    v1::Scene& message_;
    std::unordered_map<const Mesh*, int> uses_;
    std::unordered_map<const Mesh*, std::string> names_;
};

void WriteNode(const Node& node, NodeId id, NodeId parent, const std::string& name, bool withFrame,
               MeshWriter& meshes, v1::Node* out) {
    out->set_id(id);
    out->set_parent(parent);
    out->set_type(TypeToProto(node.type()));
    out->set_name(name);
    if (withFrame) FrameToProto(node.parentFromLocal(), out->mutable_frame());
    out->set_age(node.age());
    out->mutable_attributes()->insert(node.attributes().begin(), node.attributes().end());
    if (node.organ()) meshes.Write(*node.organ(), out->mutable_organ());
}

// A node's name as a structure holds it: a name ending in the node's id ("leaf1042", as
// generated) becomes "leaf{id}"; others stay. `shareable` is false for a name that already
// holds "{", which a structure would rewrite.
std::string NameTemplate(const Node& node, bool& shareable) {
    const std::string name = node.name();
    shareable = name.find('{') == std::string::npos;
    const std::string digits = std::to_string(node.id);
    if (name.size() > digits.size() &&
        name.compare(name.size() - digits.size(), digits.size(), digits) == 0) {
        return name.substr(0, name.size() - digits.size()) + "{id}";
    }
    return name;
}

std::uint64_t Bits(double value) {
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    return bits;
}

// What makes two subtrees exact copies: the same node (but its id and own frame), and the
// same children in order, each at the same frame and the same id distance from its parent.
struct ChildKey {
    std::int64_t idDelta;
    std::array<std::uint64_t, 12> frame;
    int cls;
    auto operator<=>(const ChildKey&) const = default;
};

struct ClassKey {
    int type;
    std::uint64_t age;
    std::vector<std::pair<std::string, std::uint64_t>> attributes;
    const Mesh* mesh;
    std::string optics;
    std::string name;
    std::vector<ChildKey> children;
    auto operator<=>(const ClassKey&) const = default;
};

struct ClassInfo {
    std::size_t representative;  // index of its first occurrence
    int uses = 0;                // occurrences once each class is written once
    std::size_t size = 1;        // nodes of the subtree
    std::int64_t minDelta = 0;   // smallest id in the subtree, less the root's
    std::string structure;       // its name in Scene.structures, once written
};

class InstancedWriter {
  public:
    InstancedWriter(const Scene& scene, v1::Scene& message)
        : nodes_(scene.nodes), message_(message), meshes_(scene, message) {}

    void Write() {
        Classify();
        for (std::size_t root : roots_) Emit(root, nullptr, 0);
        while (!pending_.empty()) {
            const int c = pending_.back();
            pending_.pop_back();
            ClassInfo& info = info_[c];
            v1::Structure& s = (*message_.mutable_structures())[info.structure];
            const Node& root = nodes_[info.representative];
            Emit(info.representative, &s, root.id + info.minDelta - 1);
        }
    }

  private:
    // Post-order: each subtree's class from its children's.
    void Classify() {
        std::unordered_map<NodeId, std::size_t> index;
        index.reserve(nodes_.size());
        for (std::size_t i = 0; i < nodes_.size(); ++i) index.emplace(nodes_[i].id, i);
        children_.resize(nodes_.size());
        for (std::size_t i = 0; i < nodes_.size(); ++i) {
            if (nodes_[i].parent == kNoParent) {
                roots_.push_back(i);
            } else {
                children_[index.at(nodes_[i].parent)].push_back(i);
            }
        }
        class_.assign(nodes_.size(), -1);
        std::map<ClassKey, int> classes;
        std::vector<std::pair<std::size_t, bool>> stack;
        for (std::size_t root : roots_) {
            stack.push_back({root, false});
            while (!stack.empty()) {
                auto [i, expanded] = stack.back();
                stack.pop_back();
                if (!expanded) {
                    stack.push_back({i, true});
                    for (std::size_t c : children_[i]) stack.push_back({c, false});
                    continue;
                }
                const int c = ClassOf(i, classes);
                class_[i] = c;
            }
        }
        for (std::size_t root : roots_) ++info_[class_[root]].uses;
        for (const auto& [key, c] : classes) {
            for (const ChildKey& child : key.children) ++info_[child.cls].uses;
        }
    }

    int ClassOf(std::size_t i, std::map<ClassKey, int>& classes) {
        const Node& node = nodes_[i];
        ClassKey key;
        key.type = static_cast<int>(node.type());
        key.age = Bits(node.age());
        for (const auto& [name, value] : node.attributes())
            key.attributes.push_back({name, Bits(value)});
        key.mesh = node.organ() ? node.organ()->mesh.get() : nullptr;
        key.optics = node.organ() ? node.organ()->opticsId.str() : std::string();
        bool shareable = true;
        key.name = NameTemplate(node, shareable);
        if (!shareable) key.name += "\n" + std::to_string(node.id);  // a class of its own
        for (std::size_t c : children_[i]) {
            ChildKey child{static_cast<std::int64_t>(nodes_[c].id - node.id), {}, class_[c]};
            for (int k = 0; k < 12; ++k)
                child.frame[k] = Bits(nodes_[c].parentFromLocal().At(k / 3, k % 3));
            key.children.push_back(child);
        }
        const auto [it, added] = classes.emplace(std::move(key), static_cast<int>(info_.size()));
        if (added) {
            ClassInfo info;
            info.representative = i;
            for (const ChildKey& child : it->first.children) {
                info.size += info_[child.cls].size;
                info.minDelta = std::min(info.minDelta, child.idDelta + info_[child.cls].minDelta);
            }
            info_.push_back(std::move(info));
        }
        return it->second;
    }

    bool Shared(int c) const { return info_[c].uses >= 2 && info_[c].size >= 2; }

    // Writes the subtree at `top` into `structure` (nullptr: the scene's own nodes), ids less
    // `base`; shared subtrees below it become placements.
    void Emit(std::size_t top, v1::Structure* structure, NodeId base) {
        std::vector<std::size_t> stack{top};
        while (!stack.empty()) {
            const std::size_t i = stack.back();
            stack.pop_back();
            const Node& node = nodes_[i];
            const bool root = structure && i == top;
            const NodeId parent = root || node.parent == kNoParent ? kNoParent : node.parent - base;
            const int c = class_[i];
            if (!root && Shared(c)) {
                ClassInfo& info = info_[c];
                if (info.structure.empty()) {
                    info.structure = std::string(NodeTypeName(node.type())) + "_" +
                                     std::to_string(structures_++);
                    pending_.push_back(c);
                }
                v1::Placement* p =
                    structure ? structure->add_placements() : message_.add_placements();
                p->set_structure(info.structure);
                p->set_parent(parent);
                FrameToProto(node.parentFromLocal(), p->mutable_frame());
                p->set_id_offset(node.id - base - static_cast<NodeId>(1 - info.minDelta));
                continue;
            }
            bool shareable = true;
            const std::string name = structure ? NameTemplate(node, shareable) : node.name();
            WriteNode(node, node.id - base, parent, name, !root, meshes_,
                      structure ? structure->add_nodes() : message_.add_nodes());
            for (auto k = children_[i].rbegin(); k != children_[i].rend(); ++k) stack.push_back(*k);
        }
    }

    const std::vector<Node>& nodes_;
    v1::Scene& message_;
    MeshWriter meshes_;
    std::vector<std::size_t> roots_;
    std::vector<std::vector<std::size_t>> children_;
    std::vector<int> class_;
    std::vector<ClassInfo> info_;
    std::vector<int> pending_;  // classes placed but not yet defined
    int structures_ = 0;
};

}  // namespace

void WriteInstancedNodes(const Scene& scene, v1::Scene& message) {
    InstancedWriter(scene, message).Write();
}

void WriteFlatNodes(const Scene& scene, v1::Scene& message) {
    MeshWriter meshes(scene, message);
    for (const Node& node : scene.nodes) {
        WriteNode(node, node.id, node.parent, node.name(), true, meshes, message.add_nodes());
    }
}

}  // namespace leaflux
