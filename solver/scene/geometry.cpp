#include "solver/scene/geometry.h"

#include <limits>

#include "solver/scene/world_frames.h"

namespace leaflux {
namespace {
// A mesh position placed by worldFromLocal: the one formula of PlaceMesh's corners and
// PlaceVertices' vertices, so that the ray engine's floats are the flat scene's.
glm::dvec3 Placed(const glm::dmat4& worldFromLocal, const glm::dvec3& position) {
    return glm::dvec3(worldFromLocal * glm::dvec4(position, 1.0));
}

// Flatten's receivers as their triangles are added: each one's area and triangle range, the
// bounds, and the triangles themselves when `keep` is set.
struct Flattening {
    FlatScene flat;
    bool keep = true;
    std::vector<Triangle> triangles;
    std::uint32_t count = 0;
    glm::dvec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};

    // Widens the bounds to the triangles; returns their area.
    double Bound(const std::vector<Triangle>& placed) {
        double area = 0.0;
        for (const Triangle& t : placed) {
            area += t.areaM2;
            lo = glm::min(lo, glm::min(t.a, glm::min(t.b, t.c)));
            hi = glm::max(hi, glm::max(t.a, glm::max(t.b, t.c)));
        }
        return area;
    }
    // The next receiver, of so many triangles (its area set).
    void Append(Receiver receiver, std::size_t triangleCount) {
        receiver.firstTriangle = count;
        receiver.triangleCount = static_cast<std::uint32_t>(triangleCount);
        count += receiver.triangleCount;
        flat.receivers.push_back(receiver);
    }
    void Add(const std::vector<Triangle>& placed, Receiver receiver) {
        receiver.areaM2 = Bound(placed);
        if (keep) {
            for (Triangle t : placed) {
                t.receiver = static_cast<std::uint32_t>(flat.receivers.size());
                triangles.push_back(t);
            }
        }
        Append(receiver, placed.size());
    }
    // The flat scene, in the frame centred on its bounds.
    FlatScene Finish() {
        if (count == 0) return std::move(flat);
        flat.origin = 0.5 * (lo + hi);
        for (Triangle& t : triangles) {
            t.a -= flat.origin;
            t.b -= flat.origin;
            t.c -= flat.origin;
        }
        flat.boundsMin = lo - flat.origin;
        flat.boundsMax = hi - flat.origin;
        flat.triangles = std::move(triangles);
        return std::move(flat);
    }
};

Receiver OrganReceiver(const Scene& scene, std::size_t n) {
    const Node& node = scene.nodes[n];
    return Receiver{ReceiverKind::kOrgan,
                    static_cast<std::int16_t>(scene.OpticsIndex(node.organ()->opticsId)),
                    static_cast<std::uint32_t>(n), node.id};
}

// The receivers after the organs, in the flat scene's order — the environment's surfaces,
// the emitters — as visit(its triangles placed in the world, a function making its
// Receiver).
template <class Visit>
void ForEachSurfaceAndEmitter(const Scene& scene, const Visit& visit) {
    for (std::size_t s = 0; s < scene.environment.size(); ++s) {
        const Surface& surface = scene.environment[s];
        visit(PlaceMesh(*surface.mesh, glm::dmat4(1.0)), [&] {
            return Receiver{ReceiverKind::kEnvironment,
                            static_cast<std::int16_t>(scene.OpticsIndex(surface.opticsId)),
                            static_cast<std::uint32_t>(s), 0};
        });
    }
    for (std::size_t e = 0; e < scene.sources.emitters.size(); ++e) {
        const Emitter& emitter = scene.sources.emitters[e];
        visit(PlaceMesh(*emitter.mesh, glm::dmat4(1.0)), [&] {
            return Receiver{emitter.held ? ReceiverKind::kHeld : ReceiverKind::kEmitter,
                            static_cast<std::int16_t>(emitter.opticsId.empty()
                                                          ? -1
                                                          : scene.OpticsIndex(emitter.opticsId)),
                            static_cast<std::uint32_t>(e), 0};
        });
    }
}

// Each organ's triangles placed by its world frame, as visit(its node's index in
// Scene::nodes, the triangles), parents before children. The frames are not kept
// (ForEachWorldFrame): WorldFrames' 136 bytes a node took 15 MB of the 119k-leaf tree's
// setup.
template <class Visit>
void ForEachPlacedOrgan(const Scene& scene, const Visit& visit) {
    ForEachWorldFrame(scene, [&](const Node& node, const glm::dmat4& worldFromLocal) {
        if (node.organ())
            visit(static_cast<std::size_t>(&node - scene.nodes.data()),
                  PlaceMesh(*node.organ()->mesh, worldFromLocal));
    });
}

}  // namespace

std::string ReceiverName(const Scene& scene, const Receiver& receiver) {
    if (receiver.kind == ReceiverKind::kOrgan)
        return scene.NodeName(scene.nodes.at(receiver.declared));
    if (receiver.kind == ReceiverKind::kEnvironment)
        return scene.environment.at(receiver.declared).name;
    return scene.sources.emitters.at(receiver.declared).name;  // an emitter, held or not
}

std::vector<Triangle> PlaceMesh(const Mesh& mesh, const glm::dmat4& worldFromLocal) {
    std::vector<Triangle> placed;
    placed.reserve(mesh.triangles.size());
    for (const glm::uvec3& tri : mesh.triangles) {
        Triangle t;
        t.a = Placed(worldFromLocal, mesh.positions[tri.x]);
        t.b = Placed(worldFromLocal, mesh.positions[tri.y]);
        t.c = Placed(worldFromLocal, mesh.positions[tri.z]);
        const glm::dvec3 cross = glm::cross(t.b - t.a, t.c - t.a);
        t.areaM2 = 0.5 * glm::length(cross);
        t.normal = cross / (2.0 * t.areaM2);
        t.receiver = 0;
        placed.push_back(t);
    }
    return placed;
}

FlatScene Flatten(const Scene& scene, const PlacedOrgans& placed) {
    Flattening out;
    for (std::size_t n = 0; n < scene.nodes.size(); ++n)
        if (scene.nodes[n].organ()) out.Add(placed(scene.nodes[n]), OrganReceiver(scene, n));
    ForEachSurfaceAndEmitter(scene, [&](const std::vector<Triangle>& triangles,
                                        const auto& receiver) { out.Add(triangles, receiver()); });
    return out.Finish();
}

FlatScene Flatten(const Scene& scene) {
    const WorldFrames worldFromLocal(scene);
    std::vector<Triangle> placed;
    return Flatten(scene, [&](const Node& organ) -> const std::vector<Triangle>& {
        placed = PlaceMesh(*organ.organ()->mesh, worldFromLocal.at(organ.id));
        return placed;
    });
}

FlatScene ReceiversOf(const Scene& scene) {
    Flattening out;
    out.keep = false;
    // The organs' receivers in the nodes' order, as many as there will be, then their areas
    // as the walk places them, each found by its node: an area per node and the receivers
    // grown by doubling took 36 and 33 MB more on the paper's plantation.
    std::size_t organs = 0;
    for (const Node& node : scene.nodes) organs += node.organ() ? 1 : 0;
    out.flat.receivers.reserve(organs + scene.environment.size() + scene.sources.emitters.size());
    for (std::size_t n = 0; n < scene.nodes.size(); ++n) {
        if (scene.nodes[n].organ())
            out.Append(OrganReceiver(scene, n), scene.nodes[n].organ()->mesh->triangles.size());
    }
    ForEachPlacedOrgan(scene, [&](std::size_t n, const std::vector<Triangle>& placed) {
        const auto receiver =
            std::lower_bound(out.flat.receivers.begin(), out.flat.receivers.end(), n,
                             [](const Receiver& r, std::size_t node) { return r.declared < node; });
        receiver->areaM2 = out.Bound(placed);
    });
    ForEachSurfaceAndEmitter(scene, [&](const std::vector<Triangle>& triangles,
                                        const auto& receiver) { out.Add(triangles, receiver()); });
    return out.Finish();
}

std::uint32_t LeadingOrgans(const FlatScene& flat) {
    std::uint32_t organs = 0;
    while (organs < flat.receivers.size() && flat.receivers[organs].kind == ReceiverKind::kOrgan)
        ++organs;
    return organs;
}

std::uint32_t LeadingOrganTriangles(const FlatScene& flat) {
    const std::uint32_t organs = LeadingOrgans(flat);
    if (organs == flat.receivers.size()) return static_cast<std::uint32_t>(flat.triangles.size());
    return flat.receivers[organs].firstTriangle;
}

const Mesh& ReceiverMesh(const Scene& scene, const Receiver& receiver) {
    if (receiver.kind == ReceiverKind::kOrgan)
        return *scene.nodes.at(receiver.declared).organ()->mesh;
    if (receiver.kind == ReceiverKind::kEnvironment)
        return *scene.environment.at(receiver.declared).mesh;
    return *scene.sources.emitters.at(receiver.declared).mesh;  // an emitter, held or not
}

void PlaceVertices(const Scene& scene, const FlatScene& receivers, float* xyz,
                   std::uint32_t* indices) {
    const std::vector<Receiver>& all = receivers.receivers;
    std::vector<std::uint32_t> firstVertex(all.size());  // each receiver's first vertex
    std::uint32_t vertices = 0;
    for (std::uint32_t r = 0; r < all.size(); ++r) {
        firstVertex[r] = vertices;
        vertices += static_cast<std::uint32_t>(ReceiverMesh(scene, all[r]).positions.size());
    }
    PlaceVertices(scene, receivers, [&](std::uint32_t r) {
        return VertexSlot{xyz + 3 * static_cast<std::size_t>(firstVertex[r]),
                          indices + 3 * static_cast<std::size_t>(all[r].firstTriangle),
                          firstVertex[r]};
    });
}

void PlaceVertices(const Scene& scene, const FlatScene& receivers,
                   const std::function<VertexSlot(std::uint32_t receiver)>& slot) {
    const std::vector<Receiver>& all = receivers.receivers;
    std::vector<std::uint32_t> receiverOf(scene.nodes.size(), 0);  // by node index
    for (std::uint32_t r = 0; r < all.size(); ++r) {
        if (all[r].kind == ReceiverKind::kOrgan) receiverOf[all[r].declared] = r;
    }
    const auto put = [&](const Mesh& mesh, const glm::dmat4& worldFromLocal, std::uint32_t r) {
        const VertexSlot to = slot(r);
        if (!to.xyz) return;
        float* at = to.xyz;
        for (const glm::dvec3& position : mesh.positions) {
            const glm::dvec3 local = Placed(worldFromLocal, position) - receivers.origin;
            *at++ = static_cast<float>(local.x);
            *at++ = static_cast<float>(local.y);
            *at++ = static_cast<float>(local.z);
        }
        std::uint32_t* index = to.indices;
        for (const glm::uvec3& triangle : mesh.triangles) {
            for (int k = 0; k < 3; ++k) *index++ = to.firstVertex + triangle[k];
        }
    };
    // The organs by their world frames, not kept (ForEachWorldFrame); the others as declared.
    ForEachWorldFrame(scene, [&](const Node& node, const glm::dmat4& worldFromLocal) {
        if (node.organ())
            put(*node.organ()->mesh, worldFromLocal,
                receiverOf[static_cast<std::size_t>(&node - scene.nodes.data())]);
    });
    for (std::uint32_t r = 0; r < all.size(); ++r) {
        if (all[r].kind != ReceiverKind::kOrgan)
            put(ReceiverMesh(scene, all[r]), glm::dmat4(1.0), r);
    }
}

}  // namespace leaflux
