#include "solver/scene/geometry.h"

#include <limits>

namespace leaflux {
namespace {
void AddReceiver(const std::vector<Triangle>& placed, Receiver receiver,
                 std::vector<Triangle>& worldTriangles, FlatScene& flat) {
    receiver.firstTriangle = static_cast<std::uint32_t>(worldTriangles.size());
    const auto receiverIndex = static_cast<std::uint32_t>(flat.receivers.size());
    for (Triangle t : placed) {
        t.receiver = receiverIndex;
        receiver.areaM2 += t.areaM2;
        worldTriangles.push_back(t);
    }
    receiver.triangleCount =
        static_cast<std::uint32_t>(worldTriangles.size()) - receiver.firstTriangle;
    flat.receivers.push_back(std::move(receiver));
}
}  // namespace

std::vector<Triangle> PlaceMesh(const Mesh& mesh, const glm::dmat4& worldFromLocal) {
    std::vector<Triangle> placed;
    placed.reserve(mesh.triangles.size());
    for (const glm::uvec3& tri : mesh.triangles) {
        Triangle t;
        t.a = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.x], 1.0));
        t.b = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.y], 1.0));
        t.c = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.z], 1.0));
        const glm::dvec3 cross = glm::cross(t.b - t.a, t.c - t.a);
        t.areaM2 = 0.5 * glm::length(cross);
        t.normal = cross / (2.0 * t.areaM2);
        t.receiver = 0;
        placed.push_back(t);
    }
    return placed;
}

FlatScene Flatten(const Scene& scene) {
    const auto worldFromLocal = WorldFromLocal(scene);
    std::vector<Triangle> placed;
    return Flatten(scene, [&](const Node& organ) -> const std::vector<Triangle>& {
        placed = PlaceMesh(*organ.organ->mesh, worldFromLocal.at(organ.id));
        return placed;
    });
}

FlatScene ReceiversOf(const Scene& scene) {
    FlatScene flat;
    const auto worldFromLocal = WorldFromLocal(scene);
    for (const Node& node : scene.nodes) {
        if (!node.organ) continue;
        flat.receivers.push_back({scene.NodeName(node), ReceiverKind::kOrgan, node.id,
                                  scene.OpticsIndex(node.organ->opticsId)});
        flat.receivers.back().areaM2 = MeshArea(*node.organ->mesh, worldFromLocal.at(node.id));
    }
    for (const Surface& surface : scene.environment) {
        flat.receivers.push_back(
            {surface.name, ReceiverKind::kEnvironment, 0, scene.OpticsIndex(surface.opticsId)});
        flat.receivers.back().areaM2 = MeshArea(*surface.mesh, glm::dmat4(1.0));
    }
    for (std::size_t e = 0; e < scene.sources.emitters.size(); ++e) {
        const Emitter& emitter = scene.sources.emitters[e];
        flat.receivers.push_back(
            {emitter.name, emitter.held ? ReceiverKind::kHeld : ReceiverKind::kEmitter, 0,
             emitter.opticsId.empty() ? -1 : scene.OpticsIndex(emitter.opticsId),
             static_cast<int>(e)});
        flat.receivers.back().areaM2 = MeshArea(*emitter.mesh, glm::dmat4(1.0));
    }
    return flat;
}

FlatScene Flatten(const Scene& scene, const PlacedOrgans& placed) {
    FlatScene flat;
    std::vector<Triangle> triangles;
    for (const Node& node : scene.nodes) {
        if (!node.organ) continue;
        Receiver receiver{scene.NodeName(node), ReceiverKind::kOrgan, node.id,
                          scene.OpticsIndex(node.organ->opticsId)};
        AddReceiver(placed(node), std::move(receiver), triangles, flat);
    }
    for (const Surface& surface : scene.environment) {
        Receiver receiver{surface.name, ReceiverKind::kEnvironment, 0,
                          scene.OpticsIndex(surface.opticsId)};
        AddReceiver(PlaceMesh(*surface.mesh, glm::dmat4(1.0)), std::move(receiver), triangles,
                    flat);
    }
    for (std::size_t e = 0; e < scene.sources.emitters.size(); ++e) {
        const Emitter& emitter = scene.sources.emitters[e];
        Receiver receiver{emitter.name, emitter.held ? ReceiverKind::kHeld : ReceiverKind::kEmitter,
                          0, emitter.opticsId.empty() ? -1 : scene.OpticsIndex(emitter.opticsId),
                          static_cast<int>(e)};
        AddReceiver(PlaceMesh(*emitter.mesh, glm::dmat4(1.0)), std::move(receiver), triangles,
                    flat);
    }
    if (triangles.empty()) return flat;

    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const Triangle& t : triangles) {
        lo = glm::min(lo, glm::min(t.a, glm::min(t.b, t.c)));
        hi = glm::max(hi, glm::max(t.a, glm::max(t.b, t.c)));
    }
    flat.origin = 0.5 * (lo + hi);
    for (Triangle& t : triangles) {
        t.a -= flat.origin;
        t.b -= flat.origin;
        t.c -= flat.origin;
    }
    flat.boundsMin = lo - flat.origin;
    flat.boundsMax = hi - flat.origin;
    flat.triangles = std::move(triangles);
    return flat;
}

}  // namespace leaflux
