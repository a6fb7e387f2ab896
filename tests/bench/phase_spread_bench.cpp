// How alike the functions of the structures that share a signature are (Soler 2003 §4.1,
// Fig. 8). Instancing computes one original from a group's representative and lends it to
// every member; the spread of the members' own functions around it is the approximation it
// makes, and it is worth little unless the functions of different groups differ more.
//
// Four generated trees (2,000 and 5,000 leaves, two seeds) in one scene, grouped by the
// policy fitted to them. For each group of two or more, up to K members (the representative
// and others spread over the group's leaf counts) are solved alone: τ at 130 directions and
// f by radiosity (bi-directional, 130² by default). Per group and band:
//   - the spread of τ and of f: the RMS over directions (pairs) of the members' standard
//     deviation, in % of their mean;
//   - the error of lending the representative's f to every other sampled member: the RMS of
//     f_member − f_representative in % of the members' mean f, the same for the scattered
//     power per incoming direction and for the intercepted area (1 − τ)·A_box (τ alone
//     depends on the box, the intercepted area does not), and for f per unit leaf area
//     (its shape, whatever the size);
//   - the same errors with the representative of the nearest other group of the same type;
//   - the part of τ's spread and of the intercepted area's error that the rays' noise alone
//     would give (f by radiosity is deterministic but for its escape rays).
// Directions are weighted by their hats' solid angles. Also writes the Fig. 8 slices of the
// sampled members: f per unit leaf area from a lateral direction (θ = φ = π/2 in the
// structure's frame) towards lateral outputs (θ = π/2, φ from 0 to 2π).
// Run: build/release/tests/leaflux_bench_phase_spread [out dir, out/bench]
//      [policy, proto/policies/generated_tree.txtpb] [members per group, 8] [f level, 3]
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "server/policy_proto.h"
#include "solver/instancing/phase_radiosity.h"
#include "solver/instancing/signature.h"
#include "solver/instancing/structure.h"
#include "solver/instancing/transmittance.h"
#include "tests/bench/bench_trees.h"

#ifndef LEAFLUX_DEFAULT_POLICY
#define LEAFLUX_DEFAULT_POLICY "proto/policies/generated_tree.txtpb"
#endif

namespace leaflux {
namespace {

constexpr int kTauLevel = 3;
// Rays per τ direction: at 4,096 the noise of a sparse crown's (1 − τ) is several percent,
// as large as the spread to be measured.
constexpr int kTauRays = 65536;
constexpr int kSliceAngles = 72;

struct TreeSpec {
    int leaves;
    std::uint64_t seed;
};
const TreeSpec kTrees[] = {{2000, 1}, {2000, 2}, {5000, 1}, {5000, 2}};

Scene Trees() {
    Scene scene;
    SetBenchOptics(scene);
    NodeId next = 1;
    double x = 0.0;
    for (const TreeSpec& spec : kTrees) {
        TreeParameters tree;
        tree.leafCount = spec.leaves;
        tree.seed = spec.seed;
        next = AddTree(scene, tree, {x, 0.0, 0.0}, next);
        x += 20.0;
    }
    return scene;
}

// One structure's functions, each in its own frame.
struct Member {
    NodeId id = 0;
    std::int64_t leaves = 0;
    double leafAreaM2 = 0.0;
    SphereFunction tau, tauError;       // τ and its standard error
    std::vector<double> interceptedM2;  // per τ direction: (1 − τ)·A_box
    std::vector<double> interceptedErrorM2;
    PhaseFunction f;
    std::vector<double> scatteredW;  // per incoming direction and band
    double seconds = 0.0;
};

Member Solve(const Scene& scene, NodeId id, int level) {
    const StructureAlone alone(scene, id);
    Member m;
    m.id = id;
    m.leaves = alone.LeafCount();
    m.leafAreaM2 = alone.LeafAreaM2();
    const TransmittanceEstimate t = ComputeTransmittance(alone, {kTauLevel, kTauRays, 1});
    m.tau = t.tau;
    m.tauError = t.standardError;
    const DirectionSet& set = m.tau.Directions();
    for (int d = 0; d < set.Size(); ++d) {
        const double boxM2 = alone.ProjectedArea(set.Direction(d));
        m.interceptedM2.push_back((1.0 - double(m.tau.At(d, 0))) * boxM2);
        m.interceptedErrorM2.push_back(double(m.tauError.At(d, 0)) * boxM2);
    }
    RadiosityPhaseOptions options;
    options.level = level;
    RadiosityPhase f = PhaseFromRadiosity(alone, options);
    m.f = std::move(f.phase);
    m.scatteredW = std::move(f.scatteredW);
    m.seconds = t.seconds + f.seconds;
    return m;
}

// One quantity sampled at weighted points (directions or pairs of them), one row a member.
struct Samples {
    std::vector<double> weights;
    std::vector<std::vector<double>> rows;
};

double Mean(const Samples& s) {
    double sum = 0.0, weights = 0.0;
    for (const auto& row : s.rows)
        for (std::size_t k = 0; k < row.size(); ++k) {
            sum += s.weights[k] * row[k];
            weights += s.weights[k];
        }
    return sum / weights;
}

// RMS over the points of the members' standard deviation (n − 1), in % of their mean.
double SpreadPct(const Samples& s) {
    const std::size_t n = s.rows.size();
    double sum = 0.0, weights = 0.0;
    for (std::size_t k = 0; k < s.weights.size(); ++k) {
        double mean = 0.0;
        for (const auto& row : s.rows) mean += row[k] / n;
        double variance = 0.0;
        for (const auto& row : s.rows) variance += (row[k] - mean) * (row[k] - mean) / (n - 1);
        sum += s.weights[k] * variance;
        weights += s.weights[k];
    }
    return 100.0 * std::sqrt(sum / weights) / Mean(s);
}

// RMS over the members but `skip` and the points of row − reference, in % of the members'
// mean.
double ErrorPct(const Samples& s, const std::vector<double>& reference, std::size_t skip) {
    double sum = 0.0, weights = 0.0;
    for (std::size_t m = 0; m < s.rows.size(); ++m) {
        if (m == skip) continue;
        for (std::size_t k = 0; k < reference.size(); ++k) {
            const double d = s.rows[m][k] - reference[k];
            sum += s.weights[k] * d * d;
            weights += s.weights[k];
        }
    }
    return 100.0 * std::sqrt(sum / weights) / Mean(s);
}

// What the rays' noise alone makes of SpreadPct (`difference` false) or of ErrorPct with
// the first member as reference (true): the RMS of the standard errors `errors`, of a
// member's or of its difference with the reference, in % of the mean of `values`.
double NoisePct(const Samples& errors, const Samples& values, bool difference) {
    double sum = 0.0, weights = 0.0;
    for (std::size_t m = difference ? 1 : 0; m < errors.rows.size(); ++m) {
        for (std::size_t k = 0; k < errors.weights.size(); ++k) {
            const double e = errors.rows[m][k], e0 = difference ? errors.rows[0][k] : 0.0;
            sum += errors.weights[k] * (e * e + e0 * e0);
            weights += errors.weights[k];
        }
    }
    return 100.0 * std::sqrt(sum / weights) / Mean(values);
}

// The values of one quantity of a member.
enum class Quantity {
    kTau,
    kTauError,
    kIntercepted,
    kInterceptedError,
    kF,
    kFPerLeafArea,
    kScattered
};

std::vector<double> Values(const Member& m, Quantity q, int band) {
    std::vector<double> v;
    const int bands = m.f.Bands();
    switch (q) {
        case Quantity::kTau:
        case Quantity::kTauError:
            for (float t : (q == Quantity::kTau ? m.tau : m.tauError).Values()) v.push_back(t);
            break;
        case Quantity::kIntercepted:
            v = m.interceptedM2;
            break;
        case Quantity::kInterceptedError:
            v = m.interceptedErrorM2;
            break;
        case Quantity::kF:
        case Quantity::kFPerLeafArea: {
            const double scale = q == Quantity::kF ? 1.0 : 1.0 / m.leafAreaM2;
            for (std::size_t k = band; k < m.f.Values().size(); k += bands)
                v.push_back(double(m.f.Values()[k]) * scale);
            break;
        }
        case Quantity::kScattered:
            for (std::size_t k = band; k < m.scatteredW.size(); k += bands)
                v.push_back(m.scatteredW[k]);
            break;
    }
    return v;
}

std::vector<double> Weights(const Member& m, Quantity q) {
    const bool tau = q == Quantity::kTau || q == Quantity::kTauError ||
                     q == Quantity::kIntercepted || q == Quantity::kInterceptedError;
    const DirectionSet& set = tau ? m.tau.Directions() : m.f.Directions();
    std::vector<double> w;
    if (q == Quantity::kF || q == Quantity::kFPerLeafArea) {
        for (int i = 0; i < set.Size(); ++i)
            for (int o = 0; o < set.Size(); ++o)
                w.push_back(set.HatIntegralSr(i) * set.HatIntegralSr(o));
    } else {
        for (int i = 0; i < set.Size(); ++i) w.push_back(set.HatIntegralSr(i));
    }
    return w;
}

Samples Gather(const std::vector<Member>& members, Quantity q, int band) {
    Samples s{Weights(members.front(), q), {}};
    for (const Member& m : members) s.rows.push_back(Values(m, q, band));
    return s;
}

struct Group {
    const SignatureGroup* signature = nullptr;
    std::int64_t minLeaves = 0, maxLeaves = 0;
    NodeType type = NodeType::kOther;
    std::vector<Member> members;  // the representative first
};

// The representative, then up to k − 1 others at even steps over the members sorted by
// leaf count: the group's smallest and largest are always among them.
std::vector<NodeId> Sample(const SignatureGroup& group, const SceneSignatures& signatures,
                           std::size_t k) {
    std::vector<NodeId> others;
    for (NodeId id : group.members)
        if (id != group.representative) others.push_back(id);
    std::stable_sort(others.begin(), others.end(), [&](NodeId a, NodeId b) {
        return signatures.Find(a)->leafCount < signatures.Find(b)->leafCount;
    });
    std::vector<NodeId> chosen{group.representative};
    if (others.size() + 1 <= k) {
        chosen.insert(chosen.end(), others.begin(), others.end());
        return chosen;
    }
    const std::size_t steps = std::max<std::size_t>(k - 2, 1);
    for (std::size_t j = 0; j + 1 < k; ++j)
        chosen.push_back(others[j * (others.size() - 1) / steps]);
    return chosen;
}

struct Row {
    double tauSpread, tauNoise, interceptedNoise, fSpread, fRep, shapeRep, scatteredRep,
        interceptedRep;
    std::string other;  // the nearest other group of the same type; empty: none
    double fOther = 0.0, shapeOther = 0.0, scatteredOther = 0.0;
};

Row Measure(const Group& g, const std::vector<Group>& groups, int band) {
    const std::vector<Member>& ms = g.members;
    Row r{};
    const Samples tau = Gather(ms, Quantity::kTau, band), f = Gather(ms, Quantity::kF, band),
                  shape = Gather(ms, Quantity::kFPerLeafArea, band),
                  scattered = Gather(ms, Quantity::kScattered, band),
                  intercepted = Gather(ms, Quantity::kIntercepted, band);
    r.tauSpread = SpreadPct(tau);
    r.tauNoise = NoisePct(Gather(ms, Quantity::kTauError, band), tau, false);
    r.interceptedNoise = NoisePct(Gather(ms, Quantity::kInterceptedError, band), intercepted, true);
    r.fSpread = SpreadPct(f);
    r.fRep = ErrorPct(f, f.rows[0], 0);
    r.shapeRep = ErrorPct(shape, shape.rows[0], 0);
    r.scatteredRep = ErrorPct(scattered, scattered.rows[0], 0);
    r.interceptedRep = ErrorPct(intercepted, intercepted.rows[0], 0);
    // Every member, this time: none of them is the lent function's structure.
    const std::size_t none = ms.size();
    double best = 0.0;
    for (const Group& h : groups) {
        if (&h == &g || h.type != g.type) continue;
        const Member& rep = h.members.front();
        const double e = ErrorPct(f, Values(rep, Quantity::kF, band), none);
        if (!r.other.empty() && e >= best) continue;
        best = e;
        r.other = h.signature->signature;
        r.fOther = e;
        r.shapeOther = ErrorPct(shape, Values(rep, Quantity::kFPerLeafArea, band), none);
        r.scatteredOther = ErrorPct(scattered, Values(rep, Quantity::kScattered, band), none);
    }
    return r;
}

// A signature as a CSV field: its bins hold commas ("leaves[11,50)").
std::string Quoted(const std::string& text) { return '"' + text + '"'; }

void WriteSlices(const std::string& csv, const std::vector<Group>& groups,
                 const std::vector<Band>& bands) {
    std::FILE* out = std::fopen(csv.c_str(), "w");
    std::fprintf(out,
                 "signature,node,representative,leaves,leaf_area_m2,band,phi_out_deg,"
                 "f_per_leaf_area_per_sr\n");
    const glm::dvec3 towardSource{0.0, 1.0, 0.0};  // θin = φin = π/2
    for (const Group& g : groups) {
        for (const Member& m : g.members) {
            for (int b = 0; b < static_cast<int>(bands.size()); ++b) {
                for (int a = 0; a <= kSliceAngles; ++a) {
                    const double phi = 2.0 * std::numbers::pi * a / kSliceAngles;
                    const glm::dvec3 outgoing{std::cos(phi), std::sin(phi), 0.0};
                    std::fprintf(out, "%s,%lld,%d,%lld,%.6g,%s,%.1f,%.6g\n",
                                 Quoted(g.signature->signature).c_str(),
                                 static_cast<long long>(m.id), m.id == g.members.front().id ? 1 : 0,
                                 static_cast<long long>(m.leaves), m.leafAreaM2,
                                 bands[b].name.c_str(), 360.0 * a / kSliceAngles,
                                 m.f.Value(b, towardSource, outgoing) / m.leafAreaM2);
                }
            }
        }
    }
    std::fclose(out);
}

void Run(const std::string& dir, const std::string& policyPath, std::size_t k, int level) {
    const auto start = std::chrono::steady_clock::now();
    const InstancingPolicy policy = LoadPolicyFile(policyPath);
    const Scene scene = Trees();
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    std::vector<Group> groups;
    for (const SignatureGroup& sg : signatures.groups) {
        if (sg.members.size() < 2) continue;
        Group g;
        g.signature = &sg;
        g.type = signatures.Find(sg.representative)->type;
        g.minLeaves = g.maxLeaves = signatures.Find(sg.representative)->leafCount;
        for (NodeId id : sg.members) {
            g.minLeaves = std::min(g.minLeaves, signatures.Find(id)->leafCount);
            g.maxLeaves = std::max(g.maxLeaves, signatures.Find(id)->leafCount);
        }
        for (NodeId id : Sample(sg, signatures, k)) g.members.push_back(Solve(scene, id, level));
        double seconds = 0.0;
        for (const Member& m : g.members) seconds += m.seconds;
        std::fprintf(stderr, "%s: %zu of %zu members solved in %.1f s\n", sg.signature.c_str(),
                     g.members.size(), sg.members.size(), seconds);
        groups.push_back(std::move(g));
    }

    const int directions = DirectionSet::OfLevel(level).Size();
    std::printf(
        "\nFunctions within a signature: %zu trees (%zu structures, %zu groups, %zu of "
        "two or more), policy %s;\nτ at %d directions (%d rays each), f by radiosity at %d², "
        "up to %zu members a group; errors in %% of the members' mean\n",
        std::size(kTrees), signatures.structures.size(), signatures.groups.size(), groups.size(),
        policy.species.c_str(), DirectionSet::OfLevel(kTauLevel).Size(), kTauRays, directions, k);
    std::FILE* out = std::fopen((dir + "/phase_spread.csv").c_str(), "w");
    std::fprintf(out,
                 "signature,members,sampled,min_leaves,max_leaves,representative,rep_leaves,"
                 "band,tau_spread_pct,tau_noise_pct,f_spread_pct,f_rep_error_pct,"
                 "f_shape_rep_error_pct,scattered_rep_error_pct,intercepted_rep_error_pct,"
                 "intercepted_noise_pct,nearest_other,"
                 "f_other_error_pct,f_shape_other_error_pct,scattered_other_error_pct\n");
    std::printf("%-34s %9s %11s %7s %6s %6s %6s %6s %6s %6s %6s  %-34s %6s %6s\n", "signature",
                "members", "leaves", "τ spr", "noise", "f spr", "f rep", "shape", "S rep", "A rep",
                "noise", "nearest other", "f oth", "shape");
    for (int band = 0; band < static_cast<int>(scene.bands.size()); ++band) {
        std::printf("%s\n", scene.bands[band].name.c_str());
        for (const Group& g : groups) {
            const Row r = Measure(g, groups, band);
            const std::string members = std::to_string(g.members.size()) + "/" +
                                        std::to_string(g.signature->members.size());
            const std::string leaves =
                std::to_string(g.minLeaves) + "-" + std::to_string(g.maxLeaves);
            std::printf(
                "%-34s %9s %11s %6.2f %6.2f %6.2f %6.2f %6.2f %6.2f %6.2f %6.2f  %-34s %6.1f "
                "%6.1f\n",
                g.signature->signature.c_str(), members.c_str(), leaves.c_str(), r.tauSpread,
                r.tauNoise, r.fSpread, r.fRep, r.shapeRep, r.scatteredRep, r.interceptedRep,
                r.interceptedNoise, r.other.empty() ? "–" : r.other.c_str(), r.fOther,
                r.shapeOther);
            std::fprintf(
                out,
                "%s,%zu,%zu,%lld,%lld,%lld,%lld,%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,"
                "%s,",
                Quoted(g.signature->signature).c_str(), g.signature->members.size(),
                g.members.size(), static_cast<long long>(g.minLeaves),
                static_cast<long long>(g.maxLeaves), static_cast<long long>(g.members.front().id),
                static_cast<long long>(g.members.front().leaves), scene.bands[band].name.c_str(),
                r.tauSpread, r.tauNoise, r.fSpread, r.fRep, r.shapeRep, r.scatteredRep,
                r.interceptedRep, r.interceptedNoise, Quoted(r.other).c_str());
            if (r.other.empty())
                std::fprintf(out, ",,\n");
            else
                std::fprintf(out, "%.4f,%.4f,%.4f\n", r.fOther, r.shapeOther, r.scatteredOther);
        }
    }
    std::fclose(out);
    WriteSlices(dir + "/phase_slices.csv", groups, scene.bands);
    std::printf("%.0f s in all\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    spdlog::set_level(spdlog::level::warn);
    const std::string dir = argc > 1 ? argv[1] : "out/bench";
    const std::string policy = argc > 2 ? argv[2] : LEAFLUX_DEFAULT_POLICY;
    const int k = argc > 3 ? std::atoi(argv[3]) : 8;
    const int level = argc > 4 ? std::atoi(argv[4]) : 3;
    if (k < 2 || level < 0 || level > 4) {
        std::fprintf(stderr, "members per group must be ≥ 2 and the level 0..4\n");
        return 2;
    }
    std::filesystem::create_directories(dir);
    try {
        leaflux::Run(dir, policy, static_cast<std::size_t>(k), level);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
