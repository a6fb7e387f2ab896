// `leaflux convert`: a scene file written again, as protobuf text or binary by its name
// (.binpb), its imported geometry (OBJ, Caribu, OPF) taken in, and exact copies shared if
// asked: what a user does once to a large scene so that each solve reads it quickly.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "server/scene_file_cli.h"

namespace leaflux {

struct ConvertCommand {
    std::string scene, out;
    bool instanced = false;
    SceneFileOptions file;  // --strict, --max-nodes
};

// The `convert` subcommand of `app`, its options bound to `command`.
CLI::App* AddConvertCommand(CLI::App& app, ConvertCommand& command);

// Reads the scene (checked as a solve checks it) and writes it; throws InputError naming
// the file or field at fault.
int RunConvert(const ConvertCommand& command);

}  // namespace leaflux
