#include "server/scene_file_cli.h"

#include "server/cli_checks.h"

namespace leaflux {

void AddSceneFileOptions(CLI::App& app, SceneFileOptions& options) {
    app.add_flag("--strict", options.strict,
                 "Refuse imported files holding geometry that carries no light (zero-area "
                 "faces, zero-length organs, NaN diameters) instead of skipping it with a "
                 "warning");
    app.add_option("--max-nodes", options.maxNodes,
                   "Largest scene file taken, in nodes (a generated tree of 10^6 leaves has "
                   "2.3 million); a larger one is refused before it is built")
        ->capture_default_str()
        ->transform(WholeNumber())
        ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 31));
}

Scene LoadSceneFile(const std::string& path, const SceneFileOptions& options) {
    SceneLimits limits;
    limits.maxNodes = options.maxNodes;
    return LoadSceneFile(path, ImportOptions{options.strict}, limits);
}

}  // namespace leaflux
