// leaflux: the one-shot command line. `solve` lights a scene file, `generate` writes a
// procedural tree or plantation as a scene file, `policy check` shows the groups an
// instantiation policy makes, `phase-db` inspects the phase-function database.
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
#include "server/generate_cli.h"
#include "server/instanced_cli.h"
#include "server/phase_db_cli.h"
#include "server/policy_cli.h"
#include "server/policy_proto.h"
#include "server/progress.h"
#include "server/scene_proto.h"
#include "solver/generate/generator.h"
#include "solver/results/export.h"
#include "solver/solve.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

constexpr const char* kStrictHelp =
    "Refuse imported files holding geometry that carries no light (zero-area faces, "
    "zero-length organs, NaN diameters) instead of skipping it with a warning";

struct SolveCommand {
    std::string scene, solver = "hrc", out, structures, ply;
    int samples = 1024, replicates = 16, threads = 0;
    double epsilon = 1e-4;
    HrcOptions hrc;  // subdivision, rays and directions; ε and threads are set apart
    std::uint64_t seed = 1;
    bool directOnly = false, quiet = false, strict = false;
    InstancedCommand instanced;
};

// HRC's settings besides ε, as options named `prefix` + name, their help after `label`.
void AddHrcSettings(CLI::App& app, HrcOptions& hrc, const std::string& prefix,
                    const std::string& label) {
    app.add_option(prefix + "subdivision", hrc.maxSubdivision,
                   label + "times a triangle may be split in four")
        ->check(CLI::Range(0, 8));
    app.add_option(prefix + "visibility-rays", hrc.visibilityRays,
                   label + "rays estimating each link's visibility")
        ->check(CLI::Range(1, 1024));
    app.add_option(prefix + "source-rays", hrc.sourceRays,
                   label + "rays estimating the visibility of each link from a sun or sky cone")
        ->check(CLI::Range(1, 1024));
    app.add_option(
           prefix + "cluster-tolerance", hrc.clusterTolerance,
           label +
               "error a link from a surface into a cluster of organs may carry, as a fraction of ε")
        ->check(CLI::Range(1e-3, 1.0));
    app.add_option(prefix + "direction-level", hrc.directionLevel,
                   label + "direction set of cluster light, 0..4 (4, 10, 34, 130, 514 directions)")
        ->check(CLI::Range(0, 4));
    app.add_option(prefix + "exposure-rays", hrc.exposureRays,
                   label +
                       "rays per child of a cluster and direction finding how open it is towards "
                       "the light the cluster hands down (0: evenly by area)")
        ->check(CLI::Range(0, 1024));
}

int RunSolve(const SolveCommand& command) {
    // Before any work: a solve that cannot write its results fails now, not after it.
    CheckWritable(command.out, "--out");
    if (!command.structures.empty()) CheckWritable(command.structures, "--structures");
    if (!command.ply.empty()) CheckWritable(command.ply, "--ply");
    if (!command.instanced.problems.empty())
        CheckWritable(command.instanced.problems, "--problems");
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = LoadSceneFile(command.scene, ImportOptions{command.strict});
    // The instanced solver with shadows by transmittance never flattens the scene whole.
    const bool instanced = command.solver == "instanced";
    const bool whole = !instanced || ShadowsByGeometry(command.instanced);
    std::optional<PreparedScene> prepared;
    if (whole) prepared.emplace(scene);
    const FlatScene receivers = whole ? FlatScene{} : ReceiversOf(scene);
    const FlatScene& flat = whole ? prepared->Flat() : receivers;
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = command.samples;
    settings.monteCarlo.replicates = command.replicates;
    settings.monteCarlo.seed = command.seed;
    settings.monteCarlo.threads = command.threads;
    settings.kind = command.solver == "hrc" ? SolverKind::kHrc : SolverKind::kMonteCarlo;
    settings.hrc = command.hrc;
    settings.hrc.epsilon = command.epsilon;
    settings.hrc.threads = command.threads;
    settings.monteCarlo.directOnly = settings.hrc.directOnly = command.directOnly;
    if (!command.quiet) {
        spdlog::info(
            "{}: {} receivers, {} triangles, {} bands; loaded in {:.2f} s", command.scene,
            flat.receivers.size(), flat.triangles.size(), scene.bands.size(),
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        settings.monteCarlo.progress = ProgressBar("Monte Carlo");
        if (settings.kind == SolverKind::kHrc) settings.hrc.progress = ProgressBar("HRC");
    }
    const Solution solution = instanced
                                  ? RunInstanced(scene, flat, whole ? &prepared->Rays() : nullptr,
                                                 settings.hrc, command.instanced)
                                  : Solve(*prepared, settings);
    std::ofstream leaves(command.out);
    if (!leaves) throw InputError(ErrorCode::kIo, command.out, "cannot write");
    WriteLeafCsv(leaves, scene, flat, solution);
    if (!command.structures.empty()) {
        std::ofstream structures(command.structures);
        if (!structures) throw InputError(ErrorCode::kIo, command.structures, "cannot write");
        WriteStructureCsv(structures, scene, AggregateStructures(scene, flat, solution));
    }
    if (!command.ply.empty()) {
        std::ofstream ply(command.ply);
        if (!ply) throw InputError(ErrorCode::kIo, command.ply, "cannot write");
        WritePly(ply, flat, solution, 0);
    }
    std::cout << Summary(command.solver, scene, flat, solution) << std::endl;
    for (const LinkAudit& audit : solution.linkAudit) {
        if (audit.links == 0) {  // the partition's check: rays where no link or two cover
            std::printf("points %-41s: rays find %.6g ± %.2g W\n", audit.kind.c_str(), audit.foundW,
                        audit.foundStderrW);
        } else if (audit.foundW > 0.0) {
            std::printf(
                "links %-42s %9lld: hand on %.6g W, rays from their receivers find %.6g ± %.2g W"
                " (ratio %.4f)\n",
                audit.kind.c_str(), static_cast<long long>(audit.links), audit.handedW,
                audit.foundW, audit.foundStderrW, audit.handedW / audit.foundW);
        }
    }
    return 0;
}

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
    CLI::App* solveApp =
        app.add_subcommand("solve", "Light a scene file and write per-organ results");
    solveApp
        ->add_option("--scene", solve.scene, "Scene file (protobuf text format, leaflux.v1.Scene)")
        ->required()
        ->check(CLI::ExistingFile);
    solveApp
        ->add_option(
            "--solver", solve.solver,
            "Solver: mc (Monte Carlo reference), hrc (hierarchical radiosity with clustering) "
            "or instanced (hierarchical instantiation: structures the policy names solved as "
            "instances of shared phase functions, one at a time)")
        ->check(CLI::IsMember({"mc", "hrc", "instanced"}));
    solveApp
        ->add_option("--epsilon", solve.epsilon,
                     "hrc, instanced: largest error of a link, as a fraction of the power the suns "
                     "and sky bring "
                     "onto the organs (plus the lamps' power); surfaces far from the organs are "
                     "allowed more by the square of their distance")
        ->check(CLI::Range(1e-9, 1.0));
    AddHrcSettings(*solveApp, solve.hrc, "--", "hrc, instanced: ");
    AddInstancedOptions(*solveApp, solve.instanced);
    solveApp->add_flag("--audit-links", solve.hrc.auditLinks,
                       "hrc: after the solve, set each kind of link against 64 rays from each "
                       "side of every leaf patch (the power handed on, with the solution's "
                       "radiosity), and check that the links cover every exchange once");
    solveApp
        ->add_option("--samples", solve.samples, "mc: paths per receiver (standard error ~ 1/sqrt)")
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1 << 26));
    solveApp
        ->add_option("--replicates", solve.replicates,
                     "mc: independent groups for the standard error")
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1024));
    solveApp->add_option("--seed", solve.seed, "mc: random seed (same seed, same result)")
        ->transform(WholeNumber());
    solveApp->add_flag("--direct-only", solve.directOnly,
                       "Light straight from the suns, the sky and the lamps only (no scattering)");
    solveApp->add_option("--threads", solve.threads, "Worker threads (0: every core)")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1024));
    solveApp
        ->add_option("--out", solve.out,
                     "Per-organ CSV (its folder is made): organ,band,area_m2,"
                     "irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w,light_x,light_y,"
                     "light_z,stderr_upper_wm2,stderr_lower_wm2, then PAR in photons: "
                     "photon_irradiance_upper_umol_m2_s,photon_irradiance_lower_umol_m2_s,"
                     "absorbed_umol_s (the W columns times the band's photon_umol_per_j, "
                     "4.57 for PAR; empty for a band without one)")
        ->required();
    solveApp->add_option("--structures", solve.structures,
                         "Per-structure CSV (plants, axes, phytomers)");
    solveApp->add_option("--ply", solve.ply,
                         "PLY of the triangles with the first band's irradiance");
    solveApp->add_flag("--quiet", solve.quiet, "No progress or log lines, only the summary");
    solveApp->add_flag("--strict", solve.strict, kStrictHelp);

    GenerateCommand generate;
    CLI::App* generateApp = AddGenerateCommand(app, generate);

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
                     "phase-function database, the middle one also with the single value, "
                     "with shadows by transmittance and with light per branch "
                     "(--output-level axis)")
        ->delimiter(',')
        ->check(CLI::Range(1e-9, 1.0));
    errorApp
        ->add_option("--instanced-depth", errorBench.instancedDepths,
                     "Instanced runs at the middle ε opened down to each of these depths only "
                     "(--max-depth), compared per structure solved whole")
        ->delimiter(',')
        ->check(CLI::Range(1, 64));
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
        if (generateApp->parsed()) return RunGenerate(generate, AvailableMemoryBytes());
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
