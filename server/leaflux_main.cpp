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
#include "server/client.h"
#include "server/instanced_cli.h"
#include "server/phase_db_cli.h"
#include "server/policy_cli.h"
#include "server/policy_proto.h"
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
    std::string scene, solver = "mc", out, structures, ply;
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
        settings.monteCarlo.progress = [last = -1](double done) mutable {
            const int tenth = static_cast<int>(done * 10.0);
            if (tenth > last) {
                last = tenth;
                std::fprintf(stderr, "\r  %3d %%", 10 * tenth);
                if (tenth == 10) std::fprintf(stderr, "\n");
            }
        };
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

struct GenerateCommand {
    TreeParameters tree;
    int rows = 1, columns = 1, trees = 0;
    double spacing = 6.0, rowSpacing = 0.0, rowAzimuth = 0.0, sunElevation = 50.0,
           sunAzimuth = 160.0;
    double sunPar = 400.0, sunNir = 350.0, skyPar = 100.0, skyNir = 60.0;
    bool noSky = false, noGround = false;
    CanopyParameters canopy;
    bool randomCanopy = false;
    bool greenhouse = false;
    double lampPar = 1500.0, lampNir = 150.0;
    std::string skyCones = "continuous";
    int prototypes = 4;
    bool instanced = false;
    std::string out;
};

SkyDiscretization SkyDiscretizationNamed(const std::string& name) {
    if (name == "turtle46") return SkyDiscretization::kTurtle46;
    if (name == "tetra34") return SkyDiscretization::kTetra34;
    if (name == "tetra130") return SkyDiscretization::kTetra130;
    if (name == "tetra514") return SkyDiscretization::kTetra514;
    return SkyDiscretization::kContinuous;
}

// PAR- and NIR-like optics (leaf ρ, τ), a sun and a CIE overcast sky: a scene ready to solve.
int RunGenerate(const GenerateCommand& command) {
    Scene scene;
    scene.bands = {{"PAR", 400, 700}, {"NIR", 700, 2500}};
    scene.optics = {{"leaf", {{0.10, 0.10, 0.05, 0.05}, {0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.10, 0.10, 0.0, 0.0}, {0.40, 0.40, 0.0, 0.0}}},
                    {"ground", {{0.10, 0.10, 0.0, 0.0}, {0.30, 0.30, 0.0, 0.0}}}};
    PlantationParameters plantation;
    plantation.tree = command.tree;
    plantation.rows = command.rows;
    plantation.columns = command.columns;
    plantation.trees = command.trees;
    plantation.columnSpacingM = command.spacing;
    plantation.rowSpacingM = command.rowSpacing > 0.0 ? command.rowSpacing : command.spacing;
    plantation.rowAzimuthDeg = command.rowAzimuth;
    plantation.jitterM = 0.1 * command.spacing;
    plantation.prototypes = command.prototypes;
    if (command.randomCanopy) {
        CanopyParameters canopy = command.canopy;
        canopy.seed = command.tree.seed;
        AddRandomCanopy(scene, canopy);
    } else if (command.greenhouse) {
        scene.optics.push_back({"wall", {{0.80, 0.80, 0.0, 0.0}, {0.85, 0.85, 0.0, 0.0}}});
        scene.optics.push_back({"floor", {{0.60, 0.60, 0.0, 0.0}, {0.70, 0.70, 0.0, 0.0}}});
        GreenhouseParameters greenhouse;
        greenhouse.plantation = plantation;
        greenhouse.lampExitanceWm2 = {command.lampPar, command.lampNir};
        AddGreenhouse(scene, greenhouse);
    } else {
        AddPlantation(scene, plantation, command.noGround ? "" : "ground");
    }
    const double h = glm::radians(command.sunElevation), a = glm::radians(command.sunAzimuth);
    if (!command.greenhouse) {
        scene.sources.suns.push_back(
            {{std::cos(h) * std::sin(a), std::cos(h) * std::cos(a), std::sin(h)},
             {command.sunPar, command.sunNir},
             0.0});
    }
    if (!command.noSky && !command.greenhouse) {
        scene.sources.skies.push_back({SkyModel::kCieOvercast,
                                       {command.skyPar, command.skyNir},
                                       SkyDiscretizationNamed(command.skyCones)});
    }
    scene.Validate();
    SaveSceneFile(scene, command.out,
                  command.instanced ? SceneWriting::kInstanced : SceneWriting::kFlat);
    std::size_t leaves = 0, triangles = 0;
    for (const Node& node : scene.nodes) {
        leaves += node.type == NodeType::kLeaf;
        if (node.organ) triangles += node.organ->mesh->triangles.size();
    }
    std::cout << "wrote " << command.out << ": " << leaves << " leaves, " << scene.nodes.size()
              << " nodes, " << triangles << " organ triangles ("
              << std::filesystem::file_size(command.out) << " bytes"
              << (command.instanced ? ", instanced" : "") << ")" << std::endl;
    return 0;
}

struct ClientCommand {
    std::string endpoint = "tcp://127.0.0.1:5555", scene, session, delta, solver = "hrc";
    std::string curveServerKeyFile;
    std::int64_t number = 1;
    bool leaves = true, structures = false, strict = false;
    double epsilon = 1e-4;
    ClientTimeouts timeouts;
    double timeoutS = 0.0;  // 0: the defaults of ClientTimeouts
};

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

// Sends one request to leafluxd and prints the reply in protobuf text format.
int RunClient(const ClientCommand& command, const v1::Request& request) {
    std::string serverKey;
    if (!command.curveServerKeyFile.empty()) {
        const auto key = ReadCurveKey(command.curveServerKeyFile);
        if (!key) {
            throw InputError(ErrorCode::kParse, command.curveServerKeyFile,
                             "not a Z85 CurveZMQ public key");
        }
        serverKey = *key;
    }
    ClientTimeouts timeouts = command.timeouts;
    if (command.timeoutS > 0.0)
        timeouts = ClientTimeouts::All(static_cast<int>(1000 * command.timeoutS));
    v1::Reply reply;
    try {
        Client client(command.endpoint, serverKey, timeouts);
        reply = client.Call(request);
    } catch (const ClientError& e) {
        spdlog::error("{}", e.what());  // names the endpoint
        return 4;
    }
    std::string text;
    google::protobuf::TextFormat::PrintToString(reply, &text);
    std::cout << text;
    return reply.has_error() ? 2 : 0;
}

v1::Request OpenFromFile(const ClientCommand& command) {
    // The scene file's imports are read here: the daemon reads no files.
    v1::Request request;
    *request.mutable_open_session()->mutable_scene() =
        ToProto(LoadSceneFile(command.scene, ImportOptions{command.strict}));
    v1::SolverSettings* settings = request.mutable_open_session()->mutable_settings();
    settings->set_solver(command.solver == "mc" ? v1::SOLVER_KIND_MONTE_CARLO
                                                : v1::SOLVER_KIND_HRC);
    settings->set_epsilon(command.epsilon);
    return request;
}

v1::Request CycleFromFile(const ClientCommand& command) {
    v1::Request request;
    v1::Cycle* cycle = request.mutable_cycle();
    cycle->set_session(command.session);
    cycle->set_number(command.number);
    cycle->mutable_outputs()->set_leaves(command.leaves);
    cycle->mutable_outputs()->set_structures(command.structures);
    if (!command.delta.empty()) {
        std::ifstream in(command.delta);
        std::stringstream text;
        text << in.rdbuf();
        if (!in ||
            !google::protobuf::TextFormat::ParseFromString(text.str(), cycle->mutable_delta())) {
            throw InputError(ErrorCode::kParse, command.delta,
                             "not a leaflux.v1.TopologyDelta in text format");
        }
    }
    return request;
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    using namespace leaflux;
    CLI::App app{
        "leaflux: light on plants by hierarchical radiosity, with a Monte Carlo reference"};
    app.require_subcommand(1);

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
        ->check(CLI::Range(2, 1 << 26));
    solveApp
        ->add_option("--replicates", solve.replicates,
                     "mc: independent groups for the standard error")
        ->check(CLI::Range(2, 1024));
    solveApp->add_option("--seed", solve.seed, "mc: random seed (same seed, same result)");
    solveApp->add_flag("--direct-only", solve.directOnly,
                       "Light straight from the suns, the sky and the lamps only (no scattering)");
    solveApp->add_option("--threads", solve.threads, "Worker threads (0: every core)")
        ->check(CLI::Range(0, 1024));
    solveApp
        ->add_option("--out", solve.out,
                     "Per-organ CSV: organ,band,area_m2,irradiance_upper_wm2,"
                     "irradiance_lower_wm2,absorbed_w,light_x,light_y,light_z,"
                     "stderr_upper_wm2,stderr_lower_wm2")
        ->required();
    solveApp->add_option("--structures", solve.structures,
                         "Per-structure CSV (plants, axes, phytomers)");
    solveApp->add_option("--ply", solve.ply,
                         "PLY of the triangles with the first band's irradiance");
    solveApp->add_flag("--quiet", solve.quiet, "No progress or log lines, only the summary");
    solveApp->add_flag("--strict", solve.strict, kStrictHelp);

    GenerateCommand generate;
    CLI::App* generateApp =
        app.add_subcommand("generate", "Write a procedural poplar-like tree or plantation");
    generateApp->add_option("--leaves", generate.tree.leafCount, "Leaves per tree")
        ->check(CLI::Range(1, 10'000'000));
    generateApp->add_option("--seed", generate.tree.seed, "Random seed");
    generateApp->add_option("--leaf-length", generate.tree.leafLengthM, "Mean leaf length (m)")
        ->check(CLI::PositiveNumber);
    generateApp->add_option("--rows", generate.rows, "Rows of trees")->check(CLI::Range(1, 1000));
    generateApp->add_option("--columns", generate.columns, "Trees per row")
        ->check(CLI::Range(1, 1000));
    generateApp
        ->add_option("--trees", generate.trees,
                     "Only this many trees of the rows x columns grid, row by row (0: all)")
        ->check(CLI::Range(0, 1'000'000));
    generateApp->add_option("--spacing", generate.spacing, "Distance between trees (m)")
        ->check(CLI::PositiveNumber);
    generateApp
        ->add_option("--row-spacing", generate.rowSpacing,
                     "Distance between rows (m; default: --spacing, the distance along a row)")
        ->check(CLI::PositiveNumber);
    generateApp->add_option("--row-azimuth", generate.rowAzimuth,
                            "Row direction from north, clockwise (deg)");
    generateApp->add_option("--sun-elevation", generate.sunElevation, "Sun elevation (deg)")
        ->check(CLI::Range(0.0, 90.0));
    generateApp->add_option("--sun-azimuth", generate.sunAzimuth,
                            "Sun azimuth from north, clockwise (deg)");
    generateApp->add_flag("--no-sky", generate.noSky, "Sun only, no diffuse sky");
    generateApp->add_flag("--no-ground", generate.noGround,
                          "Trees without the ground under them (as a growth model sends a plant)");
    generateApp->add_flag("--random-canopy", generate.randomCanopy,
                          "A random canopy of square leaves (spherical angles) instead of trees");
    generateApp->add_flag(
        "--greenhouse", generate.greenhouse,
        "A greenhouse at night instead: the rows of trees (small plants, see --leaves, "
        "--leaf-length, --spacing) on a white floor, white walls, no roof, a bar of lamps "
        "2.4 m above each row; no sun, no sky");
    generateApp->add_option("--lamp-par", generate.lampPar, "Greenhouse: lamp exitance, PAR (W/m²)")
        ->check(CLI::NonNegativeNumber);
    generateApp->add_option("--lamp-nir", generate.lampNir, "Greenhouse: lamp exitance, NIR (W/m²)")
        ->check(CLI::NonNegativeNumber);
    generateApp->add_option("--canopy-leaves", generate.canopy.leaves, "Random canopy: leaves")
        ->check(CLI::Range(1, 10'000'000));
    generateApp
        ->add_option("--lai", generate.canopy.leafAreaIndex, "Random canopy: leaf area index")
        ->check(CLI::PositiveNumber);
    generateApp
        ->add_option("--canopy-width", generate.canopy.widthM,
                     "Random canopy: side of its square (m)")
        ->check(CLI::PositiveNumber);
    generateApp
        ->add_option(
            "--sky-cones", generate.skyCones,
            "Sky as continuous radiance or as cones (every solver then sees the same cones)")
        ->check(CLI::IsMember({"continuous", "turtle46", "tetra34", "tetra130", "tetra514"}));
    generateApp->add_flag("!--internodes", generate.tree.internodes,
                          "No internode geometry (leaves only)");
    generateApp->add_flag(
        "--copies", generate.tree.copies,
        "Exact self-similarity: the lateral axes of one order and leaf count are copies of one "
        "prototype (the same organs in the axis's frame), and the trees copies of "
        "--prototypes trees, each turned about z; for instancing tests, and with --instanced "
        "for files that grow with the placements, not the polygons");
    generateApp
        ->add_option("--prototypes", generate.prototypes,
                     "With --copies: prototype trees of a plantation (tree i is a copy of "
                     "prototype i mod N)")
        ->check(CLI::Range(1, 1'000'000));
    generateApp->add_flag(
        "--instanced", generate.instanced,
        "Write subtrees that are exact copies once, as shared structures placed by a frame and "
        "an id offset (Scene.structures, Scene.placements); leaflux solve reads the same scene "
        "as from the flat file");
    generateApp->add_option("--out", generate.out, "Scene file to write")->required();

    ClientCommand client;
    CLI::App* clientApp = app.add_subcommand("client", "Talk to a running leafluxd by hand");
    clientApp->require_subcommand(1);
    clientApp->add_option("--endpoint", client.endpoint, "leafluxd's endpoint");
    clientApp->add_option("--timeout", client.timeoutS,
                          "Seconds to wait for any reply (default: as the next three say)");
    clientApp
        ->add_option("--status-timeout-ms", client.timeouts.statusMs,
                     "Status, close, shutdown: milliseconds to wait for the reply")
        ->capture_default_str();
    clientApp
        ->add_option("--scene-timeout-ms", client.timeouts.sceneMs,
                     "open, cycle: milliseconds to wait for the reply, plus --per-organ-ms for "
                     "each organ of the scene")
        ->capture_default_str();
    clientApp->add_option("--per-organ-ms", client.timeouts.perOrganMs)->capture_default_str();
    clientApp
        ->add_option("--curve-server-key", client.curveServerKeyFile,
                     "File with the daemon's CurveZMQ public key, when it uses one")
        ->check(CLI::ExistingFile);
    std::string keyPrefix;
    CLI::App* keygenApp = app.add_subcommand("keygen", "Write a CurveZMQ key pair for leafluxd");
    keygenApp
        ->add_option("--out", keyPrefix,
                     "Writes PREFIX.secret (for leafluxd) and PREFIX.public (for clients)")
        ->required();
    CLI::App* openApp = clientApp->add_subcommand("open", "Open a session from a scene file");
    openApp->add_option("--scene", client.scene, "Scene file")
        ->required()
        ->check(CLI::ExistingFile);
    openApp->add_option("--solver", client.solver, "hrc or mc")
        ->check(CLI::IsMember({"mc", "hrc"}));
    openApp->add_flag("--strict", client.strict, kStrictHelp);
    openApp
        ->add_option("--epsilon", client.epsilon,
                     "hrc: link error bound, a fraction of the power reaching the organs")
        ->check(CLI::Range(1e-9, 1.0));
    CLI::App* cycleApp = clientApp->add_subcommand("cycle", "Send a cycle, with a delta file");
    cycleApp->add_option("--session", client.session, "Session id")->required();
    cycleApp->add_option("--number", client.number, "Cycle number");
    cycleApp->add_option("--delta", client.delta, "leaflux.v1.TopologyDelta in text format")
        ->check(CLI::ExistingFile);
    cycleApp->add_flag("!--no-leaves", client.leaves, "No per-organ results");
    cycleApp->add_flag("--structures", client.structures, "Per-structure results");
    CLI::App* statusApp = clientApp->add_subcommand("status", "The daemon's or a session's status");
    statusApp->add_option("--session", client.session, "Session id (default: all)");
    CLI::App* closeApp = clientApp->add_subcommand("close", "Close a session");
    closeApp->add_option("--session", client.session, "Session id")->required();
    CLI::App* shutdownApp = clientApp->add_subcommand("shutdown", "Stop the daemon");

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
    errorApp->add_option("--out", errorBenchOut, "Directory of the CSV and the plot");
    errorApp->add_option("--cache", errorBench.cacheDirectory,
                         "Directory of cached references (default: " + DefaultCacheDirectory() +
                             "); delete a file there to solve it again");
    errorApp
        ->add_option("--reference-samples", errorBench.referenceSamples,
                     "Reference: Monte Carlo paths per receiver")
        ->check(CLI::Range(2, 1 << 26));
    errorApp->add_option("--reference-seed", errorBench.referenceSeed, "Reference: random seed");
    errorApp
        ->add_option("--mc-samples", errorBench.monteCarloSamples,
                     "Monte Carlo runs: paths per receiver of each")
        ->delimiter(',')
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
        ->check(CLI::Range(0, 1024));

    PolicyCheckCommand policyCheck;
    CLI::App* policyCheckApp = AddPolicyCommand(app, policyCheck);
    PhaseDbCli phaseDb(app);

    CLI11_PARSE(app, argc, argv);
    spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug shows the solvers' phases
    try {
        if (solveApp->parsed()) return RunSolve(solve);
        if (generateApp->parsed()) return RunGenerate(generate);
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
            const CurveKeyPair keys = CurveKeyPair::Generate();
            WriteSecret(keyPrefix + ".secret", keys.secretKey + "\n");
            std::ofstream(keyPrefix + ".public") << keys.publicKey << '\n';
            std::cout << "wrote " << keyPrefix << ".secret and " << keyPrefix << ".public"
                      << std::endl;
            return 0;
        }
        if (phaseDb.Parsed()) return phaseDb.Run();
        if (openApp->parsed()) return RunClient(client, OpenFromFile(client));
        if (cycleApp->parsed()) return RunClient(client, CycleFromFile(client));
        v1::Request request;
        if (statusApp->parsed()) request.mutable_status()->set_session(client.session);
        if (closeApp->parsed()) request.mutable_close_session()->set_session(client.session);
        if (shutdownApp->parsed()) request.mutable_shutdown();
        if (clientApp->parsed()) return RunClient(client, request);
    } catch (const InputError& e) {
        spdlog::error("{}", e.what());
        return 2;
    } catch (const TooLarge& e) {  // a scene over the limits a solve accepts
        spdlog::error("{}: {}", e.Field(), e.what());
        return 2;
    } catch (const std::exception& e) {
        spdlog::error("internal error: {}", e.what());
        return 3;
    }
    return 1;
}
