#include "server/instanced_cli.h"

#include <cstdio>
#include <fstream>
#include <utility>

#include "server/policy_proto.h"
#include "solver/instancing/phase_db.h"
#include "solver/util/error.h"

namespace leaflux {

void AddInstancedOptions(CLI::App& solve, InstancedCommand& command) {
    command.phaseDb = DefaultPhaseDatabasePath();
    solve.add_option("--policy", command.policy,
                     "instanced: instantiation policy file (protobuf text format, "
                     "leaflux.v1.InstancingPolicy); default: the built-in general policy, "
                     "plants and axes of more than 10 leaves by their leaf count, in steps of "
                     "√2 up to 1,000 leaves");
    solve
        .add_option("--phase-db", command.phaseDb,
                    "instanced: phase-function database file, read and extended")
        ->capture_default_str();
    solve.add_flag("--no-phase-db", command.noPhaseDb,
                   "instanced: keep the phase functions in memory only");
    solve
        .add_option("--phase-db-mb", command.phaseDbMb,
                    "instanced: the database's buffer in memory (MB)")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 1e6));
    solve
        .add_option("--shadows", command.shadows,
                    "instanced: what direct light from the suns and sky meets: geometry (every "
                    "triangle of the scene, exact shadows, the scene's triangles in memory), "
                    "geometry-compact (the same in a compact ray-engine hierarchy: about 30 % "
                    "less memory for the triangles, and the plants that are exact copies of "
                    "another held once, nearly none for theirs; up to 45 % slower) or "
                    "transmittance (the "
                    "closed instances' τ, the paper's; memory follows the depth of instances)")
        ->capture_default_str()
        ->check(CLI::IsMember({"geometry", "geometry-compact", "transmittance"}));
    solve.add_flag("--single-value", command.singleValue,
                   "instanced: a closed instance sends its power alike in every direction (the "
                   "paper's single value) instead of by direction");
    solve.add_flag("--per-bin", command.perBin,
                   "instanced: an opened instance takes the light of the level it was closed in "
                   "per direction bin, the same at each of its points, instead of holding that "
                   "level's patches and closed instances fixed and linking them into its "
                   "contents (the paper's link copies); cheaper, less accurate in scattered light");
    auto* depth = solve
                      .add_option("--max-depth", command.maxDepth,
                                  "instanced: open instances down to this depth only (1: the "
                                  "largest); deeper ones are solved whole, each as one structure "
                                  "(--structures), their leaves left out of --out; 0: every depth")
                      ->capture_default_str()
                      ->check(CLI::Range(0, 64));
    auto* outputLevel =
        solve
            .add_option("--output-level", command.outputLevel,
                        "instanced: light per structure of this type: an instance is opened only "
                        "while it holds instances of the type (or, of another type, structures "
                        "of the type that are not instances), the others are solved whole "
                        "(--structures) and their leaves never built; e.g. axis for light per "
                        "branch")
            ->check(CLI::IsMember({"plant", "axis", "phytomer"}))
            ->excludes(depth);
    solve.add_flag("--push-down", command.pushDown,
                   "instanced: with --max-depth or --output-level, the leaves of the structures "
                   "solved whole get light handed down from the structure's (straight light "
                   "from its box's sides through its transmittance, what it absorbs beyond that "
                   "evenly), in --out: approximate, for a little more time");
    solve
        .add_option("--merge-triangles", command.mergeTriangles,
                    "instanced: an opened instance of at most this many organ triangles in all "
                    "is solved as one local problem with the smaller instances it holds, rather "
                    "than each of them closed and opened in turn; 0: never")
        ->capture_default_str()
        ->check(CLI::Range(std::int64_t{0}, std::int64_t{1} << 40))
        ->excludes(outputLevel);
    solve.add_option("--problems", command.problems,
                     "instanced: CSV of every local problem solved: depth, triangles, closed "
                     "instances, elements, links, seconds");
}

Solution RunInstanced(const Scene& scene, const FlatScene& flat, const RayScene* shadows,
                      const HrcOptions& hrc, const InstancedCommand& command,
                      OrganSink* organSink) {
    if (command.pushDown && command.maxDepth == 0 && command.outputLevel.empty()) {
        throw InputError(ErrorCode::kInvalidArgument, "--push-down",
                         "needs --max-depth or --output-level: without them no structure is "
                         "solved whole");
    }
    const InstancingPolicy policy =
        command.policy.empty() ? DefaultPolicy() : LoadPolicyFile(command.policy);
    PhaseDatabase database(
        {command.noPhaseDb ? "" : command.phaseDb, command.phaseDbMb, 0.0, true});
    if (!database.Health().empty())
        std::fprintf(stderr, "phase-function database: %s; going on in memory\n",
                     database.Health().c_str());
    InstancedOptions options;
    options.hrc = hrc;
    options.hrc.directionalInstances = !command.singleValue;
    options.holdOutside = !command.perBin;
    options.maxDepth = command.maxDepth;
    options.mergeTriangles = command.mergeTriangles;
    options.pushDown = command.pushDown;
    options.inView = command.inView;
    options.organSink = organSink;
    if (!command.outputLevel.empty()) {
        options.outputLevel = command.outputLevel == "plant"  ? NodeType::kPlant
                              : command.outputLevel == "axis" ? NodeType::kAxis
                                                              : NodeType::kPhytomer;
    }
    InstancedSolution solved = SolveInstanced(scene, flat, shadows, policy, database, options);
    const InstancedStats& stats = solved.stats;
    std::printf("instances by depth (opened):");
    for (std::size_t d = 1; d < stats.depths.size(); ++d) {
        std::printf(" %zu: %d (%d", d, stats.depths[d].instances, stats.depths[d].opened);
        if (stats.depths[d].merged > 0) std::printf(", %d merged", stats.depths[d].merged);
        std::printf(")");
    }
    int whole = 0;
    for (const InstancedStats::Depth& d : stats.depths) whole += d.whole;
    if (whole > 0) std::printf("; %d solved whole", whole);
    std::printf(
        "\nphase functions: %d computed in %.2f s, %d reused; solving %.2f s; peak %.1f MiB\n",
        stats.originalsComputed, stats.originalSeconds, stats.originalsReused, stats.solveSeconds,
        stats.peakRssBytes / 1048576.0);
    if (!command.problems.empty()) {
        std::ofstream out(command.problems);
        if (!out) throw InputError(ErrorCode::kIo, command.problems, "cannot write");
        out << "depth,triangles,closed,elements,links,seconds\n";
        for (const InstancedStats::Problem& p : stats.problems)
            out << p.depth << ',' << p.triangles << ',' << p.closed << ',' << p.elements << ','
                << p.links << ',' << p.seconds << '\n';
    }
    return std::move(solved.solution);  // a copy was a second light table at the peak
}

}  // namespace leaflux
