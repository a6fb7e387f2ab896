#include "solver/scene/geometry.h"

#include <limits>

#include "solver/scene/world_frames.h"

namespace leaflux {
namespace {
// Flatten's receivers as their triangles are added: each one's area and triangle range, the
// bounds, and the triangles themselves when `keep` is set.
struct Flattening {
    FlatScene flat;
    bool keep = true;
    std::vector<Triangle> triangles;
    std::uint32_t count = 0;
    glm::dvec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};

    void Add(const std::vector<Triangle>& placed, Receiver receiver) {
        receiver.firstTriangle = count;
        const auto receiverIndex = static_cast<std::uint32_t>(flat.receivers.size());
        for (Triangle t : placed) {
            t.receiver = receiverIndex;
            receiver.areaM2 += t.areaM2;
            lo = glm::min(lo, glm::min(t.a, glm::min(t.b, t.c)));
            hi = glm::max(hi, glm::max(t.a, glm::max(t.b, t.c)));
            if (keep) triangles.push_back(t);
        }
        count += static_cast<std::uint32_t>(placed.size());
        receiver.triangleCount = count - receiver.firstTriangle;
        flat.receivers.push_back(std::move(receiver));
    }
};

// Each receiver of the scene in the flat scene's order — the organs, the environment's
// surfaces, the emitters — as visit(its triangles placed in the world, a function making
// its Receiver).
template <class Visit>
void ForEachReceiver(const Scene& scene, const PlacedOrgans& placed, const Visit& visit) {
    for (const Node& node : scene.nodes) {
        if (!node.organ) continue;
        visit(placed(node), [&] {
            return Receiver{scene.NodeName(node), ReceiverKind::kOrgan, node.id,
                            scene.OpticsIndex(node.organ->opticsId)};
        });
    }
    for (const Surface& surface : scene.environment) {
        visit(PlaceMesh(*surface.mesh, glm::dmat4(1.0)), [&] {
            return Receiver{surface.name, ReceiverKind::kEnvironment, 0,
                            scene.OpticsIndex(surface.opticsId)};
        });
    }
    for (std::size_t e = 0; e < scene.sources.emitters.size(); ++e) {
        const Emitter& emitter = scene.sources.emitters[e];
        visit(PlaceMesh(*emitter.mesh, glm::dmat4(1.0)), [&] {
            return Receiver{emitter.name,
                            emitter.held ? ReceiverKind::kHeld : ReceiverKind::kEmitter, 0,
                            emitter.opticsId.empty() ? -1 : scene.OpticsIndex(emitter.opticsId),
                            static_cast<int>(e)};
        });
    }
}

// Flatten, with or without the triangles.
FlatScene FlattenScene(const Scene& scene, const PlacedOrgans& placed, bool keep) {
    Flattening out;
    out.keep = keep;
    ForEachReceiver(scene, placed,
                    [&](const std::vector<Triangle>& triangles, const auto& receiver) {
                        out.Add(triangles, receiver());
                    });
    FlatScene& flat = out.flat;
    if (out.count == 0) return flat;
    flat.origin = 0.5 * (out.lo + out.hi);
    for (Triangle& t : out.triangles) {
        t.a -= flat.origin;
        t.b -= flat.origin;
        t.c -= flat.origin;
    }
    flat.boundsMin = out.lo - flat.origin;
    flat.boundsMax = out.hi - flat.origin;
    flat.triangles = std::move(out.triangles);
    return flat;
}

PlacedOrgans PlacedByFrame(const Scene& scene, std::vector<Triangle>& placed) {
    return [&placed, worldFromLocal =
                         WorldFromLocal(scene)](const Node& organ) -> const std::vector<Triangle>& {
        placed = PlaceMesh(*organ.organ->mesh, worldFromLocal.at(organ.id));
        return placed;
    };
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
    std::vector<Triangle> placed;
    return FlattenScene(scene, PlacedByFrame(scene, placed), true);
}

FlatScene ReceiversOf(const Scene& scene) {
    std::vector<Triangle> placed;
    return FlattenScene(scene, PlacedByFrame(scene, placed), false);
}

FlatScene Flatten(const Scene& scene, const PlacedOrgans& placed) {
    return FlattenScene(scene, placed, true);
}

void PlaceTriangles(const Scene& scene, const FlatScene& receivers, float* xyz) {
    std::vector<Triangle> placed;
    ForEachReceiver(scene, PlacedByFrame(scene, placed),
                    [&](const std::vector<Triangle>& triangles, const auto&) {
                        for (const Triangle& t : triangles) {
                            for (const glm::dvec3& corner : {t.a, t.b, t.c}) {
                                const glm::dvec3 local = corner - receivers.origin;
                                *xyz++ = static_cast<float>(local.x);
                                *xyz++ = static_cast<float>(local.y);
                                *xyz++ = static_cast<float>(local.z);
                            }
                        }
                    });
}

}  // namespace leaflux
