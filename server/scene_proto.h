// Conversion between the wire/file schema (leaflux.v1.Scene) and the solver's Scene.
//
// FromProto checks what only the schema can get wrong (an unknown band name in a map, a
// frame of 7 numbers, a dangling mesh_ref, a file that cannot be imported) and then runs
// Scene::Validate: a Scene it returns is valid. Errors are InputError naming the field.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "leaflux.pb.h"
#include "solver/io/importers.h"
#include "solver/scene/scene.h"

namespace leaflux {

// Shared meshes by name (Scene.meshes), which later organs may reference.
using MeshLibrary = std::map<std::string, std::shared_ptr<const Mesh>>;
MeshLibrary MeshesFromProto(const v1::Scene& message);

// One node; its mesh_ref resolved in `meshes`. Not validated: Scene::Validate does that.
Node NodeFromProto(const v1::Node& node, const MeshLibrary& meshes);

// A sun for `scene`'s bands; `field` names it in errors.
Sun SunFromProto(const Scene& scene, const v1::Sun& sun, const std::string& field);

// `baseDirectory` resolves relative import paths (the scene file's folder); `options` say
// what imports do with geometry that carries no light.
Scene FromProto(const v1::Scene& message, const std::string& baseDirectory,
                const ImportOptions& options = {});

// Shared meshes stay shared: each distinct mesh is written once in `meshes`.
v1::Scene ToProto(const Scene& scene);
v1::NodeType TypeToProto(NodeType type);

// Reads a scene file in protobuf text format; parse errors name line and column.
Scene LoadSceneFile(const std::string& path, const ImportOptions& options = {});
void SaveSceneFile(const Scene& scene, const std::string& path);

}  // namespace leaflux
