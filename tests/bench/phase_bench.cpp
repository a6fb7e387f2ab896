// The cost and accuracy of a structure's functions (Soler 2003 §4.2.2).
//
// 1. The time to compute τ and f for trees of 10, 100 and 1,000 leaves at each kind and
//    resolution: constant, mono-directional (514), bi-directional 34², 130² and 514².
// 2. The paper's §4.2.2 table on a generated branch: each kind against the bi-directional
//    514² function by radiosity (deterministic), L∞ and L2 of the difference over every
//    pair of the 514 directions (in % of the largest value of f, pairs weighted by their
//    hats' solid angles), the size and the time; and the photons' functions against it.
// Prints both tables and writes CSV.
// Run: build/release/tests/leaflux_bench_phase [out dir, out/bench] [photons per beam, 20000]
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

#include "solver/instancing/phase_photons.h"
#include "solver/instancing/phase_radiosity.h"
#include "solver/instancing/structure.h"
#include "solver/instancing/transmittance.h"
#include "tests/bench/bench_trees.h"

namespace leaflux {
namespace {

struct Kind {
    const char* name;
    PhaseKind kind;
    int level;
};
const Kind kKinds[] = {{"constant", PhaseKind::kConstant, 3},
                       {"mono 514", PhaseKind::kMonoDirectional, 4},
                       {"bi 34²", PhaseKind::kBiDirectional, 2},
                       {"bi 130²", PhaseKind::kBiDirectional, 3},
                       {"bi 514²", PhaseKind::kBiDirectional, 4}};

PhaseEstimate Compute(const StructureAlone& structure, const Kind& kind, int photons) {
    PhotonOptions options;
    options.kind = kind.kind;
    options.level = kind.level;
    options.photonsPerBeam = photons;
    return PhaseFromPhotons(structure, options);
}

void Timing(const std::string& csv, int photons) {
    std::FILE* out = std::fopen(csv.c_str(), "w");
    std::fprintf(out, "leaves,triangles,function,directions,rays,seconds,kB\n");
    std::printf(
        "\nTime to compute a structure's functions (%d photons a beam, 4096 rays a τ "
        "direction)\n",
        photons);
    std::printf("%7s %9s  %-20s %10s %11s %9s %10s\n", "leaves", "triangles", "function",
                "directions", "rays", "seconds", "kB");
    for (int leaves : {10, 100, 1000}) {
        const Scene scene = Tree(leaves);
        const StructureAlone tree(scene, scene.nodes.front().id);
        const auto row = [&](const char* function, int directions, std::int64_t rays,
                             double seconds, double kB) {
            std::printf("%7lld %9zu  %-20s %10d %11lld %9.3f %10.3f\n",
                        static_cast<long long>(tree.LeafCount()), tree.Flat().triangles.size(),
                        function, directions, static_cast<long long>(rays), seconds, kB);
            std::fprintf(out, "%lld,%zu,%s,%d,%lld,%.4f,%.3f\n",
                         static_cast<long long>(tree.LeafCount()), tree.Flat().triangles.size(),
                         function, directions, static_cast<long long>(rays), seconds, kB);
        };
        for (int level : {2, 3, 4}) {
            const TransmittanceEstimate t = ComputeTransmittance(tree, {level, 4096, 1});
            row("tau", t.tau.Directions().Size(), t.rays, t.seconds,
                t.tau.Values().size() * sizeof(float) / 1000.0);
        }
        for (const Kind& kind : kKinds) {
            const PhaseEstimate f = Compute(tree, kind, photons);
            row((std::string(kind.name) + " photons").c_str(),
                DirectionSet::OfLevel(kind.level).Size(), f.rays, f.seconds,
                f.phase.Bytes() / 1000.0);
        }
        // By radiosity, every beam a channel of one solve: 514² of 1,000 leaves is 1,028
        // channels on every link, past what this table should wait for.
        for (int level : {2, 3, 4}) {
            if (level == 4 && tree.LeafCount() > 100) continue;
            RadiosityPhaseOptions options;
            options.level = level;
            const RadiosityPhase f = PhaseFromRadiosity(tree, options);
            const char* name = level == 2   ? "bi 34² radiosity"
                               : level == 3 ? "bi 130² radiosity"
                                            : "bi 514² radiosity";
            row(name, DirectionSet::OfLevel(level).Size(), f.stats.rays + f.escapeRays, f.seconds,
                f.phase.Bytes() / 1000.0);
        }
    }
    std::fclose(out);
}

// The axis whose subtree holds the number of leaves nearest `wanted`.
NodeId BranchNear(const Scene& scene, int wanted) {
    std::unordered_map<NodeId, NodeId> parent;
    for (const Node& node : scene.nodes) parent[node.id] = node.parent;
    std::unordered_map<NodeId, int> leaves;
    for (const Node& node : scene.nodes) {
        if (node.type() != NodeType::kLeaf) continue;
        for (NodeId up = node.parent; up != kNoParent; up = parent[up]) ++leaves[up];
    }
    NodeId best = kNoParent;
    for (const Node& node : scene.nodes) {
        if (node.type() != NodeType::kAxis || node.parent == kNoParent) continue;
        if (best == kNoParent ||
            std::abs(leaves[node.id] - wanted) < std::abs(leaves[best] - wanted))
            best = node.id;
    }
    return best;
}

// L∞ and L2 of f − reference over every pair of the 514 directions, in % of the
// reference's largest value, pairs weighted by their hats' solid angles.
struct Difference {
    double linf = 0.0, l2 = 0.0;
};
Difference Compare(const PhaseFunction& f, const PhaseFunction& reference, int band) {
    const DirectionSet& set = DirectionSet::OfLevel(4);
    const int n = set.Size(), bands = reference.Bands();
    double largest = 0.0, worst = 0.0, sum = 0.0, weights = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int o = 0; o < n; ++o) {
            const double r =
                reference.Values()[(static_cast<std::size_t>(i) * n + o) * bands + band];
            const double d = f.Value(band, set.Direction(i), set.Direction(o)) - r;
            const double w = set.HatIntegralSr(i) * set.HatIntegralSr(o);
            largest = std::max(largest, r);
            worst = std::max(worst, std::abs(d));
            sum += w * d * d;
            weights += w;
        }
    }
    return {100.0 * worst / largest, 100.0 * std::sqrt(sum / weights) / largest};
}

void PaperTable(const std::string& csv, int photons) {
    const Scene scene = Tree(2000, 3);
    const StructureAlone branch(scene, BranchNear(scene, 150));
    const int band = 1;  // NIR: the most scattered
    const auto radiosity = [&](int level) {
        RadiosityPhaseOptions options;
        options.level = level;
        return PhaseFromRadiosity(branch, options);
    };
    const RadiosityPhase exact = radiosity(4);
    std::printf(
        "\nThe paper's §4.2.2 table on a generated branch (%s: %lld leaves, %zu "
        "triangles), NIR band,\nagainst bi-directional 514² by radiosity (ε = 2e-3 of "
        "a beam, %lld links, %.1f s)\n",
        branch.Name().c_str(), static_cast<long long>(branch.LeafCount()),
        branch.Flat().triangles.size(), static_cast<long long>(exact.stats.links), exact.seconds);
    std::FILE* out = std::fopen(csv.c_str(), "w");
    std::fprintf(out, "function,method,linf_pct,l2_pct,kB,seconds\n");
    std::printf("%-10s %-9s %8s %8s %11s %9s\n", "function", "method", "L∞ %", "L2 %", "size kB",
                "seconds");
    const auto row = [&](const char* name, const char* method, const PhaseFunction& f,
                         double seconds) {
        const Difference d = Compare(f, exact.phase, band);
        std::printf("%-10s %-9s %8.1f %8.2f %11.3f %9.2f\n", name, method, d.linf, d.l2,
                    f.Bytes() / 1000.0, seconds);
        std::fprintf(out, "%s,%s,%.3f,%.4f,%.3f,%.3f\n", name, method, d.linf, d.l2,
                     f.Bytes() / 1000.0, seconds);
    };
    // The coarser kinds from the 514² function itself (§4.2.1), then the finer
    // resolutions each solved on its own.
    row("constant", "radiosity", exact.phase.Reduced(PhaseKind::kConstant), exact.seconds);
    row("mono 514", "radiosity", exact.phase.Reduced(PhaseKind::kMonoDirectional), exact.seconds);
    for (int level : {2, 3}) {
        const RadiosityPhase f = radiosity(level);
        row(level == 2 ? "bi 34²" : "bi 130²", "radiosity", f.phase, f.seconds);
    }
    row("bi 514²", "radiosity", exact.phase, exact.seconds);
    // The other method on the same structure: photons, averaged over the hats.
    for (const Kind& kind : {kKinds[3], kKinds[4]}) {
        const PhaseEstimate f = Compute(branch, kind, photons);
        row(kind.name, "photons", f.phase, f.seconds);
    }
    std::fclose(out);
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    spdlog::set_level(spdlog::level::warn);
    const std::string dir = argc > 1 ? argv[1] : "out/bench";
    const int photons = argc > 2 ? std::atoi(argv[2]) : 20000;
    std::filesystem::create_directories(dir);
    leaflux::PaperTable(dir + "/phase_table.csv", photons);
    leaflux::Timing(dir + "/phase_functions.csv", photons);
    return 0;
}
