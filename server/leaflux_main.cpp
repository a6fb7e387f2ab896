// leaflux: the one-shot command line. `solve` lights a scene file, `render` draws its
// light, `generate` writes a procedural tree or plantation as a scene file, `convert` writes
// one again (text or binary), `policy check` shows the groups an instantiation policy makes,
// `phase-db` inspects the phase-function database.
#include <fcntl.h>
#include <google/protobuf/text_format.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>

#include "server/bench_error.h"
#include "server/cli_checks.h"
#include "server/client.h"
#include "server/client_cli.h"
#include "server/convert_cli.h"
#include "server/generate_cli.h"
#include "server/instanced_cli.h"
#include "server/phase_db_cli.h"
#include "server/policy_cli.h"
#include "server/policy_proto.h"
#include "server/progress.h"
#include "server/render_cli.h"
#include "server/scene_proto.h"
#include "server/solve_cli.h"
#include "solver/generate/generator.h"
#include "solver/results/export.h"
#include "solver/solve.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// Writes `text` to `path` readable by its owner alone (0600), whatever the file was before.
void WriteSecret(const std::string& path, const std::string& text) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) throw InputError(ErrorCode::kIo, path, std::strerror(errno));
    const bool written = ::fchmod(fd, 0600) == 0 &&
                         ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    const int error = errno;
    ::close(fd);
    if (!written) throw InputError(ErrorCode::kIo, path, std::strerror(error));
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    using namespace leaflux;
    CLI::App app{
        "leaflux: light on plants by hierarchical radiosity, with a Monte Carlo reference"};
    app.require_subcommand(1);
    // Every option's --help shows its default; subcommands inherit this.
    app.option_defaults()->always_capture_default();

    SolveCommand solve;
    CLI::App* solveApp = AddSolveCommand(app, solve);
    RenderCommand render;
    CLI::App* renderApp = AddRenderCommand(app, render);

    GenerateCommand generate;
    CLI::App* generateApp = AddGenerateCommand(app, generate);
    ConvertCommand convert;
    CLI::App* convertApp = AddConvertCommand(app, convert);

    ClientCommand client;
    const ClientApps clientApps = AddClientCommand(app, client);
    std::string keyPrefix;
    CLI::App* keygenApp = app.add_subcommand("keygen", "Write a CurveZMQ key pair for leafluxd");
    keygenApp
        ->add_option("--out", keyPrefix,
                     "Writes PREFIX.secret (for leafluxd) and PREFIX.public (for clients)")
        ->required();

    ErrorBenchOptions errorBench;
    errorBench.plotScript = LEAFLUX_PLOT_ERROR_SCRIPT;
    std::string errorBenchOut = "out/bench/error";
    bool noPlot = false;
    CLI::App* benchApp = app.add_subcommand("bench", "Measure the solvers");
    benchApp->require_subcommand(1);
    CLI::App* errorApp = benchApp->add_subcommand(
        "error",
        "Error against run time on one scene: a cached Monte Carlo reference, then every "
        "solver at several settings (wall and CPU time, peak memory, L2 error in % of the "
        "reference maximum, mean and 95th-percentile relative error over lit leaves, energy "
        "balance, per band); writes OUT/NAME.csv and OUT/NAME.png");
    errorApp->add_option("--scene", errorBench.scene, "Scene file")
        ->required()
        ->check(CLI::ExistingFile);
    AddSceneFileOptions(*errorApp, errorBench.file);
    errorApp->add_option("--name", errorBench.name, "The scene's name (default: the file's)");
    errorApp->add_option("--out", errorBenchOut,
                         "Directory of the CSV and the plot (made; checked before the "
                         "reference is solved)");
    errorApp->add_option("--cache", errorBench.cacheDirectory,
                         "Directory of cached references (default: " + DefaultCacheDirectory() +
                             "); delete a file there to solve it again");
    errorApp
        ->add_option("--reference-samples", errorBench.referenceSamples,
                     "Reference: Monte Carlo paths per receiver")
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1 << 26));
    errorApp->add_option("--reference-seed", errorBench.referenceSeed, "Reference: random seed");
    errorApp
        ->add_option("--sample-plants", errorBench.samplePlants,
                     "Reference solved for the organs of this many plants alone, spread evenly "
                     "through the scene's, and every error taken over their leaves (0: every "
                     "leaf); the solvers still solve the whole scene")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1 << 20));
    errorApp
        ->add_option("--mc-samples", errorBench.monteCarloSamples,
                     "Monte Carlo runs: paths per receiver of each")
        ->delimiter(',')
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1 << 26));
    errorApp->add_option("--hrc-epsilon", errorBench.hrcEpsilons, "HRC runs: ε of each")
        ->delimiter(',')
        ->check(CLI::Range(1e-9, 1.0));
    AddHrcSettings(*errorApp, errorBench.hrc, "--hrc-", "HRC runs: ");
    std::string benchPolicy;
    errorApp
        ->add_option("--instanced-epsilon", errorBench.instancedEpsilons,
                     "Instanced runs: ε of each (none by default); the first also from an empty "
                     "phase-function database, the middle one also directional against the "
                     "single value (phase functions made bi-directional if the policy's are "
                     "not), with the outside light per bin (--per-bin), with shadows by "
                     "transmittance and with light per branch (--output-level axis)")
        ->delimiter(',')
        ->check(CLI::Range(1e-9, 1.0));
    errorApp
        ->add_option("--instanced-depth", errorBench.instancedDepths,
                     "Instanced runs at the middle ε opened down to each of these depths only "
                     "(--max-depth), compared per structure solved whole")
        ->delimiter(',')
        ->check(CLI::Range(1, 64));
    errorApp
        ->add_option("--instanced-merge", errorBench.instancedMerge,
                     "Instanced runs at every ε also with instances of at most this many "
                     "organ triangles solved as one local problem with those they hold "
                     "(--merge-triangles); 0: no such run")
        ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40));
    errorApp->add_option("--policy", benchPolicy,
                         "Instanced runs: instantiation policy file (default: the built-in one)");
    errorApp->add_flag("!--no-direct", errorBench.directOnly,
                       "No direct-light-only run (HRC at the finest ε)");
    bool noMonteCarlo = false, noHrc = false;
    errorApp->add_flag("--no-mc", noMonteCarlo, "No Monte Carlo run (but the reference)");
    errorApp->add_flag("--no-hrc", noHrc, "No HRC run");
    errorApp->add_flag("--no-plot", noPlot, "CSV and table only");
    errorApp->add_option("--threads", errorBench.threads, "Worker threads (0: every core)")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1024));

    PolicyCheckCommand policyCheck;
    CLI::App* policyCheckApp = AddPolicyCommand(app, policyCheck);
    PhaseDbCli phaseDb(app);

    CLI11_PARSE(app, argc, argv);
    spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug shows the solvers' phases
    try {
        if (solveApp->parsed()) return RunSolve(solve);
        if (renderApp->parsed()) return RunRender(render);
        if (generateApp->parsed()) return RunGenerate(generate, AvailableMemoryBytes());
        if (convertApp->parsed()) return RunConvert(convert);
        if (policyCheckApp->parsed()) return RunPolicyCheck(policyCheck, std::cout);
        if (errorApp->parsed()) {
            if (errorBench.name.empty()) {
                errorBench.name = std::filesystem::path(errorBench.scene).stem().stem().string();
            }
            if (noMonteCarlo) errorBench.monteCarloSamples.clear();
            if (noHrc) errorBench.hrcEpsilons.clear();
            errorBench.csv = errorBenchOut + "/" + errorBench.name + ".csv";
            if (!noPlot) errorBench.png = errorBenchOut + "/" + errorBench.name + ".png";
            errorBench.policy = benchPolicy.empty() ? DefaultPolicy() : LoadPolicyFile(benchPolicy);
            return RunErrorBench(errorBench);
        }
        if (keygenApp->parsed()) {
            CheckWritable(keyPrefix + ".secret", "--out");  // and its folder made
            CheckWritable(keyPrefix + ".public", "--out");
            const CurveKeyPair keys = CurveKeyPair::Generate();
            WriteSecret(keyPrefix + ".secret", keys.secretKey + "\n");
            std::ofstream(keyPrefix + ".public") << keys.publicKey << '\n';
            std::cout << "wrote " << keyPrefix << ".secret and " << keyPrefix << ".public"
                      << std::endl;
            return 0;
        }
        if (phaseDb.Parsed()) return phaseDb.Run();
        if (clientApps.client->parsed()) return RunClientCommand(clientApps, client);
    } catch (const InputError& e) {
        spdlog::error("{}", e.what());
        return 2;
    } catch (const TooLarge& e) {  // a scene over the limits a solve accepts
        spdlog::error("{}: {}", e.Field(), e.what());
        return 2;
    } catch (const std::invalid_argument& e) {  // a command line's check (cli_checks.h)
        spdlog::error("{}", e.what());
        return 2;
    } catch (const std::exception& e) {
        spdlog::error("internal error: {}", e.what());
        return 3;
    }
    return 1;
}
