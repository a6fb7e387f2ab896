// Conversion between the wire/file schema (leaflux.v1.Scene) and the solver's Scene.
//
// FromProto checks what only the schema can get wrong (an unknown band name in a map, a
// frame of 7 numbers, a dangling mesh_ref, a file that cannot be imported) and then runs
// Scene::Validate: a Scene it returns is valid. Errors are InputError naming the field.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "leaflux.pb.h"
#include "solver/io/importers.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

// Counts that multiply the work a scene makes, capped before any is done. Bands are capped
// at kMaxBands.
struct SceneLimits {
    std::size_t maxSuns = 4096;        // suns of a scene, sun period steps included, or of a cycle
    std::size_t maxNodes = 1'000'000;  // nodes of a scene (a session's, after any cycle)
    // The geometry may span at most this many periodic tiles in x and in y: a ray crosses
    // a tile at each step, so a tile much smaller than the plants multiplies every ray.
    double maxTilesSpanned = 8.0;
};

// A request over a limit (SceneLimits, kMaxBands, a daemon's options); `Field()` names what.
class TooLarge : public std::runtime_error {
  public:
    TooLarge(std::string field, const std::string& message)
        : std::runtime_error(message), field_(std::move(field)) {}
    const std::string& Field() const { return field_; }

  private:
    std::string field_;
};

// Throws TooLarge when the geometry of `flat` spans more than limits.maxTilesSpanned of
// `scene`'s periodic tiles in x or y.
void CheckPeriodicTile(const Scene& scene, const FlatScene& flat, const SceneLimits& limits);

// Shared meshes by name (Scene.meshes), which later organs may reference.
using MeshLibrary = std::map<std::string, std::shared_ptr<const Mesh>>;
MeshLibrary MeshesFromProto(const v1::Scene& message);

// One node; its mesh_ref resolved in `meshes`. Not validated: Scene::Validate does that.
Node NodeFromProto(const v1::Node& node, const MeshLibrary& meshes);

// A sun for `scene`'s bands; `field` names it in errors.
Sun SunFromProto(const Scene& scene, const v1::Sun& sun, const std::string& field);

// `baseDirectory` resolves relative import paths (the scene file's folder). Counts over
// `limits` throw TooLarge before anything is read; `options` say what imports do with
// geometry that carries no light.
Scene FromProto(const v1::Scene& message, const std::string& baseDirectory,
                const SceneLimits& limits = {}, const ImportOptions& options = {});

// How a scene's nodes are written. kFlat: node by node. kInstanced: subtrees that occur
// more than once as exact copies (server/scene_structures.h) are written once, in
// `structures`, and placed by `placements`; reading either gives the same scene (its nodes
// then in id order).
enum class SceneWriting { kFlat, kInstanced };

// Shared meshes stay shared: each distinct mesh is written once in `meshes`.
v1::Scene ToProto(const Scene& scene, SceneWriting writing = SceneWriting::kFlat);
v1::NodeType TypeToProto(NodeType type);

// Frames and meshes as the schema holds them; `field` and `node` name a bad frame.
glm::dmat4 FrameFromProto(const v1::Frame& frame, const std::string& field,
                          std::optional<NodeId> node = std::nullopt);
void FrameToProto(const glm::dmat4& m, v1::Frame* frame);  // nothing for the identity
void MeshToProto(const Mesh& mesh, v1::Mesh* message);

// Reads a scene file in protobuf text format (parse errors name line and column), or in
// protobuf's binary encoding when its name ends in .binpb (kBinarySceneExtension): the
// same message, read faster and in less memory, for scenes of millions of triangles.
inline constexpr const char* kBinarySceneExtension = ".binpb";
bool IsBinarySceneFile(const std::string& path);
Scene LoadSceneFile(const std::string& path, const ImportOptions& options = {},
                    const SceneLimits& limits = {});
void SaveSceneFile(const Scene& scene, const std::string& path,
                   SceneWriting writing = SceneWriting::kFlat);

}  // namespace leaflux
