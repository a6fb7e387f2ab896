#include "server/convert_cli.h"

#include <chrono>
#include <filesystem>
#include <iostream>

#include "server/cli_checks.h"
#include "server/scene_proto.h"
#include "solver/util/error.h"

namespace leaflux {

CLI::App* AddConvertCommand(CLI::App& app, ConvertCommand& command) {
    CLI::App* convert = app.add_subcommand(
        "convert",
        "Write a scene file again: as binary protobuf if --out ends in .binpb (read faster, "
        "in less memory), else as text; imported OBJ, Caribu and OPF geometry taken in");
    convert->add_option("--scene", command.scene, "Scene file to read (text, or .binpb)")
        ->required()
        ->check(CLI::ExistingFile);
    convert->add_option("--out", command.out, "Scene file to write (its folder is made)")
        ->required();
    convert->add_flag("--instanced", command.instanced,
                      "Write subtrees that are exact copies once, as shared structures placed "
                      "by a frame (Scene.structures, Scene.placements)");
    AddSceneFileOptions(*convert, command.file);
    return convert;
}

int RunConvert(const ConvertCommand& command) {
    CheckWritable(command.out, "--out");  // and its folder made
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = LoadSceneFile(command.scene, command.file);
    SaveSceneFile(scene, command.out,
                  command.instanced ? SceneWriting::kInstanced : SceneWriting::kFlat);
    std::cout << "wrote " << command.out << ": " << scene.nodes.size() << " nodes, "
              << (IsBinarySceneFile(command.out) ? "binary" : "text")
              << (command.instanced ? ", instanced" : "") << ", "
              << std::filesystem::file_size(command.out) << " bytes in "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s" << std::endl;
    return 0;
}

}  // namespace leaflux
