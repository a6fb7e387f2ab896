// The scene flattened into world-space triangles grouped by receiver — what the ray engine
// traces and what the solvers light. A receiver is one organ, environment surface or
// emitter; it is the unit of every per-leaf output.
//
// Invariant: triangles of receiver r are [firstTriangle, firstTriangle + triangleCount);
// positions are stored relative to `origin` (the centre of the scene's bounds) so that a
// scene 10⁵ m from the world origin keeps its millimetres in single precision.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

// kHeld: a surface outside a local problem whose light is held as it was solved there
// (an emitter with Emitter::held): it sends, receives nothing, is outside the energy
// balance and has no output.
enum class ReceiverKind : std::uint8_t { kOrgan, kEnvironment, kEmitter, kHeld };

// 32 bytes. Its name is the scene's (ReceiverName): kept here, it took 32 bytes more, 8 MB
// on a plantation; with 4-byte kind and optics it took 40, 17 MB of the plantation's 2.07 M.
struct Receiver {
    ReceiverKind kind = ReceiverKind::kOrgan;
    // Index into Scene::optics (at most kMaxOptics of them); -1: black (an emitter without
    // optics).
    std::int16_t optics = -1;
    // Where the scene declares it: its node's index in Scene::nodes, its surface's in
    // Scene::environment, its emitter's in Sources::emitters.
    std::uint32_t declared = 0;
    NodeId node = 0;  // the organ's node; 0 for environment surfaces and emitters
    double areaM2 = 0.0;
    std::uint32_t firstTriangle = 0;
    std::uint32_t triangleCount = 0;
};
static_assert(sizeof(Receiver) == 32);

// The name of a receiver of the scene's flat scene: its node's (Scene::NodeName), its
// surface's or its emitter's.
std::string ReceiverName(const Scene& scene, const Receiver& receiver);

struct Triangle {
    glm::dvec3 a, b, c;  // relative to FlatScene::origin
    glm::dvec3 normal;   // unit, right-hand rule on a, b, c: the upper side
    double areaM2;
    std::uint32_t receiver;
};

struct FlatScene {
    glm::dvec3 origin{0.0};                     // world position of the local frame's origin
    glm::dvec3 boundsMin{0.0}, boundsMax{0.0};  // local frame
    std::vector<Triangle> triangles;
    std::vector<Receiver> receivers;

    bool Empty() const { return triangles.empty(); }
    glm::dvec3 ToLocal(const glm::dvec3& world) const { return world - origin; }
};

// Flattens a validated scene. Receivers come in scene order: organs, environment, emitters.
FlatScene Flatten(const Scene& scene);

// What Flatten makes but the triangles: the receivers in its order, with their areas and
// triangle ranges, and the frame (origin, bounds). What per-receiver results are indexed by
// when the scene is never flattened whole (the instanced solver).
FlatScene ReceiversOf(const Scene& scene);
// The organ receivers a flat scene lists first (ReceiversOf, Flatten and an instanced
// level's scene put them there), and their triangles, the first ones.
std::uint32_t LeadingOrgans(const FlatScene& flat);
std::uint32_t LeadingOrganTriangles(const FlatScene& flat);
// The mesh a receiver of the scene's flat scene has: its organ's, surface's or emitter's.
const Mesh& ReceiverMesh(const Scene& scene, const Receiver& receiver);
// The scene's vertices placed once each: every receiver's mesh's positions as Flatten
// would place them, in the receivers' order, straight into 3 floats each in the frame of
// `receivers` (ReceiversOf the scene); and every triangle, in Flatten's order, as the
// indices of its three. A ray engine's mesh without the flat scene: on a plantation 13 MB
// of vertices, where its triangles' corners one by one took 22. `xyz` holds 3 floats for
// each of ReceiverMesh's positions, `indices` 3 for each triangle.
void PlaceVertices(const Scene& scene, const FlatScene& receivers, float* xyz,
                   std::uint32_t* indices);
// Where PlaceVertices puts a receiver's vertices (3 floats each, from xyz) and its
// triangles' (3 vertex indices each, from indices, counted from firstVertex); nowhere when
// xyz is null.
struct VertexSlot {
    float* xyz = nullptr;
    std::uint32_t* indices = nullptr;
    std::uint32_t firstVertex = 0;
};
// PlaceVertices with each receiver put where `slot` says: several buffers, or some
// receivers not at all (a ray engine's runs, RayScene).
void PlaceVertices(const Scene& scene, const FlatScene& receivers,
                   const std::function<VertexSlot(std::uint32_t receiver)>& slot);

// A mesh's triangles placed by worldFromLocal, in world coordinates (receiver 0).
std::vector<Triangle> PlaceMesh(const Mesh& mesh, const glm::dmat4& worldFromLocal);
// Flatten, with each organ's triangles as PlaceMesh placed them by its world frame (kept
// from an earlier cycle by a SceneStore); the result is the same.
using PlacedOrgans = std::function<const std::vector<Triangle>&(const Node& organ)>;
FlatScene Flatten(const Scene& scene, const PlacedOrgans& placed);

}  // namespace leaflux
