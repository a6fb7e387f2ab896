// How leaflux's commands read a scene file (`solve`, `render`, `convert`): imported geometry
// that carries no light refused or skipped, and the largest file taken.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <string>

#include "server/scene_proto.h"

namespace leaflux {

struct SceneFileOptions {
    bool strict = false;
    std::size_t maxNodes = SceneLimits{}.maxNodes;
};

// --strict and --max-nodes on `app`, bound to `options`.
void AddSceneFileOptions(CLI::App& app, SceneFileOptions& options);

// The scene file at `path`, read as `options` ask; throws InputError naming the file or
// field at fault.
Scene LoadSceneFile(const std::string& path, const SceneFileOptions& options);

}  // namespace leaflux
