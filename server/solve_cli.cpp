#include "server/solve_cli.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "server/cli_checks.h"
#include "server/progress.h"
#include "server/scene_proto.h"
#include "solver/results/export.h"
#include "solver/results/leaf_csv_stream.h"
#include "solver/results/read_leaf_csv.h"
#include "solver/util/error.h"
#include "solver/util/memory.h"

namespace leaflux {

void AddHrcSettings(CLI::App& app, HrcOptions& hrc, const std::string& prefix,
                    const std::string& label) {
    app.add_option(prefix + "subdivision", hrc.maxSubdivision,
                   label + "times a triangle may be split in four")
        ->check(CLI::Range(0, 8));
    app.add_option(prefix + "visibility-rays", hrc.visibilityRays,
                   label + "rays estimating each link's visibility")
        ->check(CLI::Range(1, 1024));
    app.add_option(prefix + "source-rays", hrc.sourceRays,
                   label +
                       "rays estimating the visibility of each link from a sun or sky cone; "
                       "up to twice as many from one bringing most of the light")
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

void AddSolverOptions(CLI::App& app, SolveCommand& command) {
    app.add_option("--scene", command.scene,
                   "Scene file (leaflux.v1.Scene in protobuf text format, or binary if its name "
                   "ends in .binpb)")
        ->required()
        ->check(CLI::ExistingFile);
    app.add_option("--solver", command.solver,
                   "Solver: mc (Monte Carlo reference), hrc (hierarchical radiosity with "
                   "clustering) or instanced (hierarchical instantiation: structures the policy "
                   "names solved as instances of shared phase functions, one at a time)")
        ->check(CLI::IsMember({"mc", "hrc", "instanced"}));
    app.add_option("--epsilon", command.epsilon,
                   "hrc, instanced: largest error of a link, as a fraction of the power the suns "
                   "and sky bring onto the organs (plus the lamps' power); surfaces far from the "
                   "organs are allowed more by the square of their distance")
        ->check(CLI::Range(1e-9, 1.0));
    AddHrcSettings(app, command.hrc, "--", "hrc, instanced: ");
    AddInstancedOptions(app, command.instanced);
    app.add_option("--samples", command.samples, "mc: paths per receiver (standard error ~ 1/sqrt)")
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1 << 26));
    app.add_option("--replicates", command.replicates,
                   "mc: independent groups for the standard error")
        ->transform(WholeNumber())
        ->check(CLI::Range(2, 1024));
    app.add_option("--seed", command.seed, "mc: random seed (same seed, same result)")
        ->transform(WholeNumber());
    app.add_flag("--direct-only", command.directOnly,
                 "Light straight from the suns, the sky and the lamps only (no scattering)");
    app.add_option("--threads", command.threads, "Worker threads (0: every core)")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1024));
    app.add_flag("--quiet", command.quiet, "No progress or log lines, only the summary");
    AddSceneFileOptions(app, command.file);
}

CLI::App* AddSolveCommand(CLI::App& app, SolveCommand& command) {
    CLI::App* solve = app.add_subcommand("solve", "Light a scene file and write per-organ results");
    AddSolverOptions(*solve, command);
    solve->add_flag("--audit-links", command.hrc.auditLinks,
                    "hrc: after the solve, set each kind of link against 64 rays from each "
                    "side of every leaf patch (the power handed on, with the solution's "
                    "radiosity), and check that the links cover every exchange once");
    solve
        ->add_option("--out", command.out,
                     "Per-organ CSV (its folder is made; written to OUT.partial, renamed once "
                     "whole; the instanced solver writes each organ as it solves it): "
                     "organ,band,area_m2,"
                     "irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w,light_x,light_y,"
                     "light_z,stderr_upper_wm2,stderr_lower_wm2, then PAR in photons: "
                     "photon_irradiance_upper_umol_m2_s,photon_irradiance_lower_umol_m2_s,"
                     "absorbed_umol_s (the W columns times the band's photon_umol_per_j, "
                     "4.57 for PAR; empty for a band without one)")
        ->required();
    solve->add_option("--structures", command.structures,
                      "Per-structure CSV (plants, axes, phytomers)");
    solve->add_option("--ply", command.ply,
                      "PLY of the triangles with the first band's irradiance");
    solve
        ->add_option("--warm-start", command.warmStart,
                     "hrc, instanced: start the iteration from the organs' light in this "
                     "per-organ CSV of an earlier solve (by organ name, as --out writes it; "
                     "the last growth cycle's): the same light within the iteration's "
                     "tolerance and the links' epsilon, in fewer sweeps where little changed")
        ->check(CLI::ExistingFile);
    return solve;
}

std::unique_ptr<SolvedScene> SolveScene(const SolveCommand& command,
                                        const std::function<void(const Scene&)>& check,
                                        std::ostream* leaves) {
    const auto start = std::chrono::steady_clock::now();
    auto solved = std::make_unique<SolvedScene>();
    solved->scene = LoadSceneFile(command.scene, command.file);
    const Scene& scene = solved->scene;
    if (check) check(scene);
    // The solver's working memory: its peak from here less what the loaded scene holds.
    const std::int64_t loaded = ResidentBytes(), loadingPeak = PeakRssBytes();
    const bool peakReset = ResetPeakRss();
    // The instanced solver never flattens the scene whole: with shadows by geometry, the
    // scene's triangles go straight into the ray engine.
    const bool instanced = command.solver == "instanced";
    if (!instanced) {
        solved->prepared.emplace(scene);
    } else {
        solved->receivers = ReceiversOf(scene);
        if (ShadowsByGeometry(command.instanced))
            solved->shadows =
                SceneRays(scene, solved->receivers, CompactShadows(command.instanced));
    }
    const FlatScene& flat = solved->Flat();
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
    if (!command.warmStart.empty()) {
        if (command.solver == "mc")
            throw InputError(ErrorCode::kInvalidArgument, "--warm-start",
                             "is for the hrc and instanced solvers; mc starts nothing");
        settings.hrc.warmStart = std::make_shared<const WarmStart>(
            flat.receivers, ReadLeafCsv(command.warmStart, scene, flat));
    }
    if (!command.quiet) {
        spdlog::info(
            "{}: {} receivers, {} triangles, {} bands; loaded in {:.2f} s", command.scene,
            flat.receivers.size(), flat.triangles.size(), scene.bands.size(),
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        settings.monteCarlo.progress = ProgressBar("Monte Carlo");
        if (settings.kind == SolverKind::kHrc) settings.hrc.progress = ProgressBar("HRC");
    }
    std::optional<LeafCsvStream> stream;
    if (instanced && leaves != nullptr) stream.emplace(*leaves, scene, flat);
    solved->solution = instanced ? RunInstanced(scene, flat, solved->shadows.get(), settings.hrc,
                                                command.instanced, stream ? &*stream : nullptr)
                                 : Solve(*solved->prepared, settings);
    if (stream) {
        stream->Finish();
    } else if (leaves != nullptr) {
        WriteLeafCsv(*leaves, scene, flat, solved->solution);
    }
    SolveStats& stats = solved->solution.stats;
    if (peakReset) {
        stats.loadedRssBytes = loaded;
        stats.solvingPeakRssBytes = PeakRssBytes();
        stats.peakRssBytes = std::max(stats.solvingPeakRssBytes, loadingPeak);
    }
    return solved;
}

int RunSolve(const SolveCommand& command) {
    // Before any work: a solve that cannot write its results fails now, not after it.
    CheckWritable(command.out, "--out");
    if (!command.structures.empty()) CheckWritable(command.structures, "--structures");
    if (!command.ply.empty()) CheckWritable(command.ply, "--ply");
    if (!command.instanced.problems.empty())
        CheckWritable(command.instanced.problems, "--problems");
    // The per-organ CSV, written during the solve where nothing after it needs the organs'
    // light, into a file beside --out renamed to it once whole: a solve that fails leaves
    // no part of one, and --warm-start may read the --out it replaces. Straight to --out
    // when that is not a file (a pipe, /dev/stdout).
    const bool keepLight = !command.structures.empty() || !command.ply.empty();
    const bool toFile =
        !std::filesystem::exists(command.out) || std::filesystem::is_regular_file(command.out);
    const std::string written = toFile ? command.out + ".partial" : command.out;
    std::ofstream leaves(written);
    if (!leaves) throw InputError(ErrorCode::kIo, written, "cannot write");
    std::unique_ptr<SolvedScene> solved;
    try {
        solved = SolveScene(command, {}, keepLight ? nullptr : &leaves);
        if (keepLight) WriteLeafCsv(leaves, solved->scene, solved->Flat(), solved->solution);
        leaves.close();
        if (!leaves) throw InputError(ErrorCode::kIo, written, "cannot write");
    } catch (...) {
        leaves.close();
        if (toFile) std::filesystem::remove(written);
        throw;
    }
    if (toFile) std::filesystem::rename(written, command.out);
    const Scene& scene = solved->scene;
    const FlatScene& flat = solved->Flat();
    const Solution& solution = solved->solution;
    if (!command.structures.empty()) {
        std::ofstream structures(command.structures);
        if (!structures) throw InputError(ErrorCode::kIo, command.structures, "cannot write");
        WriteStructureCsv(structures, scene, AggregateStructures(scene, flat, solution));
    }
    if (!command.ply.empty()) {
        std::ofstream ply(command.ply);
        if (!ply) throw InputError(ErrorCode::kIo, command.ply, "cannot write");
        // The instanced solver's receivers hold no triangles: the scene flattened for it.
        const FlatScene whole = flat.triangles.empty() ? Flatten(scene) : FlatScene{};
        WritePly(ply, flat.triangles.empty() ? whole : flat, solution, 0);
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

}  // namespace leaflux
