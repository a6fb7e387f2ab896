#include "solver/instancing/instance_tree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <unordered_map>

#include "solver/scene/topology.h"
#include "solver/scene/world_frames.h"

namespace leaflux {
namespace {
// The box's pad, as a structure alone has it (structure.cpp): a thousandth of its diagonal,
// at least a micrometre.
constexpr double kPadFraction = 1e-3;
constexpr double kMinPadM = 1e-6;
}  // namespace

InstanceTree::InstanceTree(const Scene& scene, const SceneSignatures& signatures) {
    const std::optional<Topology> topology = TopologyUnlessInWalkOrder(scene);
    const Topology* walk = topology ? &*topology : nullptr;
    // Each node's part, depth first from the roots; an instance opens a part of its own,
    // placed in the world by its root's frame, up its parents (the frames of every node
    // would be 136 bytes each). Each node goes straight into its part, which is put in
    // scene order after: the part of every node first took 4 bytes a node more at the
    // setup's peak.
    parts_.push_back(Part{});
    std::vector<glm::dmat4> worldFromRoot{glm::dmat4(1.0)};  // by part
    std::vector<std::uint32_t> partAbove;                    // of the nodes above, by depth
    ForEachNodeDown(scene, walk, [&](std::uint32_t i, std::span<const std::uint32_t> above) {
        partAbove.resize(above.size());
        std::uint32_t part = above.empty() ? kTop : partAbove.back();
        const Node& node = scene.nodes[i];
        if (const StructureSignature* s = signatures.Find(node.id); s && !s->signature.empty()) {
            Part instance;
            instance.root = node.id;
            instance.rootIndex = i;
            instance.parent = part;
            instance.depth = parts_[part].depth + 1;
            instance.signature = s->signature;
            depth_ = std::max(depth_, instance.depth);
            part = static_cast<std::uint32_t>(parts_.size());
            parts_[instance.parent].instances.push_back(part);
            parts_.push_back(std::move(instance));
            glm::dmat4 frame(node.parentFromLocal());
            for (auto up = above.rbegin(); up != above.rend(); ++up)
                frame = glm::dmat4(scene.nodes[*up].parentFromLocal()) * frame;
            worldFromRoot.push_back(frame);
        }
        partAbove.push_back(part);
        parts_[part].nodes.push_back(i);
        if (node.organ()) {
            parts_[part].triangles +=
                static_cast<std::int64_t>(node.organ()->mesh->triangles.size());
        }
    });
    for (Part& part : parts_) {
        std::sort(part.nodes.begin(), part.nodes.end());
        part.nodes.shrink_to_fit();
        std::sort(part.instances.begin(), part.instances.end(),
                  [&](std::uint32_t a, std::uint32_t b) {
                      return parts_[a].rootIndex < parts_[b].rootIndex;
                  });
    }
    // Boxes, areas and where the areas lie over each instance's whole subtree, in its own
    // frame: the box first, then each triangle's area into its cell (two walks, so that
    // nothing the size of the subtree is kept).
    const auto walkOrgans = [&](const Part& part, const auto& visit) {
        ForEachFrameUnder(scene, walk, part.rootIndex, glm::dmat4(1.0),
                          [&](const Node& node, const glm::dmat4& instanceFromNode) {
                              if (node.organ()) visit(*node.organ()->mesh, instanceFromNode);
                          });
    };
    // Copies of a structure get the same grid, to the bit: held once (a plantation of 233
    // copies of 4 trees held 21 k of them, 18 MB, where 360 differ).
    std::map<std::array<float, AreaGrid::kCount>, std::shared_ptr<const AreaGrid>> grids;
    std::mutex gridsMutex;
    // Each part walks its own subtree, the parts at once: every level of them walks the
    // whole scene again.
    tbb::parallel_for(std::size_t{1}, parts_.size(), [&](std::size_t p) {
        Part& part = parts_[p];
        std::array<double, AreaGrid::kCount> cells;
        glm::dvec3 lo(std::numeric_limits<double>::max()), hi = -lo;
        walkOrgans(part, [&](const Mesh& mesh, const glm::dmat4& instanceFromNode) {
            for (const glm::dvec3& v : mesh.positions) {
                const glm::dvec3 q(instanceFromNode * glm::dvec4(v, 1.0));
                lo = glm::min(lo, q);
                hi = glm::max(hi, q);
            }
        });
        if (lo.x > hi.x) lo = hi = glm::dvec3(0.0);  // no organ (signatures need a leaf)
        const double pad = std::max(kMinPadM, kPadFraction * glm::length(hi - lo));
        part.boxMin = lo - pad;
        part.boxMax = hi + pad;
        const glm::dmat4& worldFromInstance = worldFromRoot[p];
        cells.fill(0.0);
        walkOrgans(part, [&](const Mesh& mesh, const glm::dmat4& instanceFromNode) {
            const glm::dmat4 worldFromNode = worldFromInstance * instanceFromNode;
            for (const glm::uvec3& t : mesh.triangles) {
                const glm::dvec3 centroid(
                    instanceFromNode *
                    glm::dvec4(
                        (mesh.positions[t.x] + mesh.positions[t.y] + mesh.positions[t.z]) / 3.0,
                        1.0));
                const double area = TriangleArea(worldFromNode, mesh, t);
                cells[AreaGrid::CellOf(centroid, part.boxMin, part.boxMax)] += area;
                part.leafAreaM2 += area;
            }
        });
        if (!(part.leafAreaM2 > 0.0)) return;
        AreaGrid grid;
        for (int c = 0; c < AreaGrid::kCount; ++c)
            grid.share[c] = static_cast<float>(cells[c] / part.leafAreaM2);
        const std::lock_guard lock(gridsMutex);
        std::shared_ptr<const AreaGrid>& held = grids[grid.share];
        if (!held) held = std::make_shared<const AreaGrid>(grid);
        part.area = held;
    });
}

void InstanceTree::Merge(std::int64_t triangles, const std::function<bool(std::uint32_t)>& opens) {
    if (triangles <= 0) return;
    // A part's instances come after it: its whole count from the last part up, and whether
    // every instance in it opens.
    std::vector<std::int64_t> whole(parts_.size());
    std::vector<std::uint8_t> allOpen(parts_.size(), 1);
    for (std::size_t p = parts_.size(); p-- > 0;) {
        whole[p] = parts_[p].triangles;
        for (std::uint32_t q : parts_[p].instances) {
            whole[p] += whole[q];
            allOpen[p] &= allOpen[q] && opens(q);
        }
    }
    for (std::size_t p = 1; p < parts_.size(); ++p) {
        Part& part = parts_[p];
        if (part.merged || part.instances.empty() || whole[p] > triangles || !allOpen[p]) continue;
        std::vector<std::uint32_t> inner = part.instances;
        for (std::size_t k = 0; k < inner.size(); ++k) {
            Part& q = parts_[inner[k]];
            q.merged = true;
            part.nodes.insert(part.nodes.end(), q.nodes.begin(), q.nodes.end());
            inner.insert(inner.end(), q.instances.begin(), q.instances.end());
            std::vector<std::uint32_t>().swap(q.nodes);  // held once, by the part solving them
            std::vector<std::uint32_t>().swap(q.instances);
        }
        std::sort(part.nodes.begin(), part.nodes.end());  // scene order
        part.instances.clear();
        part.triangles = whole[p];
    }
}

std::vector<std::uint32_t> InstanceTree::Opened(
    const std::function<bool(std::uint32_t, const glm::dmat4& worldFromRoot)>& opens,
    const Scene* world) const {
    std::vector<glm::dmat4> worldFromRoot(parts_.size(), glm::dmat4(1.0));
    if (world != nullptr) {
        std::unordered_map<NodeId, std::uint32_t> partOf;
        for (std::uint32_t q = 0; q < parts_.size(); ++q) {
            if (q != kTop && !parts_[q].merged) partOf.emplace(parts_[q].root, q);
        }
        ForEachWorldFrame(*world, [&](const Node& node, const glm::dmat4& worldFromLocal) {
            if (const auto found = partOf.find(node.id); found != partOf.end())
                worldFromRoot[found->second] = worldFromLocal;
        });
    }
    std::vector<std::uint32_t> opened = {kTop};
    for (std::size_t k = 0; k < opened.size(); ++k) {
        for (std::uint32_t q : parts_[opened[k]].instances) {
            if (opens(q, worldFromRoot[q])) opened.push_back(q);
        }
    }
    return opened;
}

bool InstanceTree::HoldsInstanceOf(const Scene& scene, std::uint32_t q, NodeType type) const {
    for (std::uint32_t inner : parts_[q].instances) {
        if (scene.nodes[parts_[inner].rootIndex].type() == type ||
            HoldsInstanceOf(scene, inner, type))
            return true;
    }
    return false;
}

bool InstanceTree::HoldsNodeOf(const Scene& scene, std::uint32_t q, NodeType type) const {
    for (std::size_t i : parts_[q].nodes) {
        if (i != parts_[q].rootIndex && scene.nodes[i].type() == type) return true;
    }
    for (std::uint32_t inner : parts_[q].instances) {
        if (scene.nodes[parts_[inner].rootIndex].type() == type || HoldsNodeOf(scene, inner, type))
            return true;
    }
    return false;
}

}  // namespace leaflux
