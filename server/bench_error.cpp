#include "server/bench_error.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <unordered_set>

#include "server/cli_checks.h"
#include "server/progress.h"
#include "server/scene_proto.h"
#include "solver/results/accuracy.h"
#include "solver/results/export.h"
#include "solver/scene/subtrees.h"
#include "solver/solve.h"
#include "solver/util/error.h"
#include "solver/util/memory.h"
#include "solver/util/user_directory.h"

namespace leaflux {
namespace {

// Bumped whenever the Monte Carlo solver's answer for a given seed changes, so that old
// cached references are not taken for new ones.
constexpr std::uint64_t kReferenceVersion = 2;
constexpr char kCacheMagic[8] = {'L', 'F', 'X', 'R', 'E', 'F', '0', '1'};

// FNV-1a, 64 bits: stable across compilers and runs, unlike std::hash.
class Fingerprint {
  public:
    void Add(const void* data, std::size_t size) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ bytes[i]) * 0x100000001b3ULL;
    }
    template <typename T>
    void Add(const T& value) {
        Add(&value, sizeof value);
    }
    std::string Hex() const {
        char text[17];
        std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash_));
        return text;
    }

  private:
    std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

// The scene as the solvers see it (imports read, defaults filled) and the reference's
// settings; not the file's bytes, so that a comment or a moved import does not matter.
std::string ReferenceKey(const Scene& scene, const ReferenceOptions& options) {
    std::string bytes;
    {
        google::protobuf::io::StringOutputStream stream(&bytes);
        google::protobuf::io::CodedOutputStream coded(&stream);
        coded.SetSerializationDeterministic(true);
        ToProto(scene).SerializeToCodedStream(&coded);
    }
    Fingerprint key;
    key.Add(bytes.data(), bytes.size());
    key.Add(kReferenceVersion);
    key.Add(options.samplesPerReceiver);
    key.Add(options.replicates);
    key.Add(options.seed);
    for (std::uint32_t r : options.only) key.Add(r);  // a sample's reference is its own
    return key.Hex();
}

void WriteDoubles(std::ostream& out, std::initializer_list<double> values) {
    for (double v : values) out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

void WriteCachedReference(const std::filesystem::path& path, const Solution& solution) {
    std::filesystem::create_directories(path.parent_path());
    const std::filesystem::path partial = path.string() + ".partial";
    {
        std::ofstream out(partial, std::ios::binary);
        out.write(kCacheMagic, sizeof kCacheMagic);
        const std::uint64_t receivers = solution.light.size();
        const std::uint64_t bands = solution.balance.size();
        out.write(reinterpret_cast<const char*>(&receivers), sizeof receivers);
        out.write(reinterpret_cast<const char*>(&bands), sizeof bands);
        const SolveStats& stats = solution.stats;
        WriteDoubles(out,
                     {stats.wallSeconds, stats.cpuSeconds, static_cast<double>(stats.peakRssBytes),
                      static_cast<double>(stats.rays), static_cast<double>(stats.threads)});
        for (const EnergyBalance& e : solution.balance) {
            WriteDoubles(out, {e.incidentW, e.absorbedW, e.escapedW, e.stderrW});
        }
        for (std::size_t r = 0; r < solution.light.size(); ++r) {
            const std::span<const BandError> errors = solution.ErrorOf(r);
            for (std::size_t b = 0; b < solution.light.Bands(); ++b) {
                const BandLight& l = solution.light[r][b];
                const BandError e = errors.empty() ? BandError{-1.0, -1.0, -1.0} : errors[b];
                WriteDoubles(out, {l.irradianceUpperWm2, l.irradianceLowerWm2, l.absorbedW,
                                   l.radianceIntegral, l.radianceMoment.x, l.radianceMoment.y,
                                   l.radianceMoment.z, e.upperWm2, e.lowerWm2, e.absorbedW});
            }
        }
        if (!out) throw InputError(ErrorCode::kIo, partial.string(), "cannot write");
    }
    std::filesystem::rename(partial, path);  // whole or absent, never half written
}

// The cached reference, or nothing when there is none or it does not fit the scene.
std::optional<Solution> ReadCachedReference(const std::filesystem::path& path,
                                            std::size_t receivers, std::size_t bands) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    char magic[sizeof kCacheMagic];
    std::uint64_t storedReceivers = 0, storedBands = 0;
    in.read(magic, sizeof magic);
    in.read(reinterpret_cast<char*>(&storedReceivers), sizeof storedReceivers);
    in.read(reinterpret_cast<char*>(&storedBands), sizeof storedBands);
    if (!in || !std::equal(magic, magic + sizeof magic, kCacheMagic) ||
        storedReceivers != receivers || storedBands != bands) {
        spdlog::warn("{}: not a reference for this scene; solving again", path.string());
        return std::nullopt;
    }
    auto next = [&in] {
        double v = 0.0;
        in.read(reinterpret_cast<char*>(&v), sizeof v);
        return v;
    };
    Solution solution;
    SolveStats& stats = solution.stats;
    stats.wallSeconds = next();
    stats.cpuSeconds = next();
    stats.peakRssBytes = static_cast<std::int64_t>(next());
    stats.rays = static_cast<std::int64_t>(next());
    stats.threads = static_cast<int>(next());
    solution.balance.resize(bands);
    for (EnergyBalance& e : solution.balance) {
        e = {next(), next(), next(), next()};
    }
    solution.light.assign(receivers, bands);
    solution.error.assign(receivers, bands);  // a reference is Monte Carlo's: it has them
    for (std::size_t r = 0; r < receivers; ++r) {
        for (std::size_t b = 0; b < bands; ++b) {
            BandLight& l = solution.light[r][b];
            l.irradianceUpperWm2 = next();
            l.irradianceLowerWm2 = next();
            l.absorbedW = next();
            l.radianceIntegral = next();
            l.radianceMoment = {next(), next(), next()};
            solution.error[r][b] = {next(), next(), next()};
        }
    }
    if (!in || in.peek() != std::char_traits<char>::eof()) {
        spdlog::warn("{}: truncated or overlong; solving again", path.string());
        return std::nullopt;
    }
    return solution;
}

struct Run {
    std::string solver, setting;
    SolverSettings settings;
};

std::vector<Run> Runs(const ErrorBenchOptions& options) {
    std::vector<Run> runs;
    SolverSettings base;
    base.hrc = options.hrc;
    base.monteCarlo.threads = base.hrc.threads = options.threads;
    // HRC settings other than the defaults are named with each run's ε.
    const HrcOptions defaults;
    std::string hrcSetting;
    if (options.hrc.maxSubdivision != defaults.maxSubdivision)
        hrcSetting += " subdivision=" + std::to_string(options.hrc.maxSubdivision);
    if (options.hrc.visibilityRays != defaults.visibilityRays)
        hrcSetting += " rays=" + std::to_string(options.hrc.visibilityRays);
    if (options.hrc.sourceRays != defaults.sourceRays)
        hrcSetting += " source-rays=" + std::to_string(options.hrc.sourceRays);
    if (options.hrc.clusterTolerance != defaults.clusterTolerance)
        hrcSetting += " cluster-tolerance=" + Number(options.hrc.clusterTolerance);
    if (options.hrc.directionLevel != defaults.directionLevel)
        hrcSetting += " directions=" + std::to_string(options.hrc.directionLevel);
    if (options.hrc.exposureRays != defaults.exposureRays)
        hrcSetting += " exposure-rays=" + std::to_string(options.hrc.exposureRays);
    for (int samples : options.monteCarloSamples) {
        Run run{"mc", "samples=" + std::to_string(samples), base};
        run.settings.kind = SolverKind::kMonteCarlo;
        run.settings.monteCarlo.samplesPerReceiver = samples;
        runs.push_back(run);
    }
    for (double epsilon : options.hrcEpsilons) {
        Run run{"hrc", "epsilon=" + Number(epsilon) + hrcSetting, base};
        run.settings.kind = SolverKind::kHrc;
        run.settings.hrc.epsilon = epsilon;
        runs.push_back(run);
    }
    for (std::size_t i = 0; i < options.instancedEpsilons.size(); ++i) {
        const double epsilon = options.instancedEpsilons[i];
        Run run{"instanced", "epsilon=" + Number(epsilon) + hrcSetting, base};
        run.settings.kind = SolverKind::kInstanced;
        run.settings.hrc.epsilon = epsilon;
        run.settings.instanced.policy = options.policy;
        if (i == 0) {
            Run cold = run;
            cold.setting += " cold";
            runs.push_back(cold);
        }
        runs.push_back(run);
        if (options.instancedMerge > 0) {
            Run merged = run;
            merged.setting += " merge-triangles=" + std::to_string(options.instancedMerge);
            merged.settings.instanced.mergeTriangles = options.instancedMerge;
            runs.push_back(merged);
        }
        if (i == options.instancedEpsilons.size() / 2) {
            // Directional instance light against the paper's single value. Under a
            // mono-directional phase function an instance sends alike in every direction
            // already, and the two are one solve: both are then taken with the policy's
            // phase function made bi-directional, on its direction set.
            Run directional = run;
            if (options.policy.phase.kind != PhaseKind::kBiDirectional) {
                directional.setting += " phase=bi";
                directional.settings.instanced.policy.phase.kind = PhaseKind::kBiDirectional;
                Run cold = directional;  // computing the bi-directional originals
                cold.setting += " cold";
                runs.push_back(cold);
                runs.push_back(directional);
            }
            Run single = directional;
            single.setting += " single-value";
            single.settings.hrc.directionalInstances = false;
            runs.push_back(single);
            // The light of the level an instance was closed in per direction bin, the same at
            // each of its points, instead of held and linked into it.
            Run perBin = run;
            perBin.setting += " per-bin";
            perBin.settings.instanced.holdOutside = false;
            runs.push_back(perBin);
            Run tau = run;
            tau.setting += " shadows=tau";
            tau.settings.instanced.shadowsByGeometry = false;
            runs.push_back(tau);
            // Stopping early, compared per structure solved whole (absorbed power).
            Run branches = run;
            branches.setting += " output=axis per-structure";
            branches.settings.instanced.outputLevel = NodeType::kAxis;
            runs.push_back(branches);
            // The same, its leaves' light handed down from the branches solved whole.
            Run pushed = branches;
            pushed.setting = run.setting + " output=axis pushed-down";
            pushed.settings.instanced.pushDown = true;
            runs.push_back(pushed);
            for (int depth : options.instancedDepths) {
                Run shallow = run;
                shallow.setting += " depth=" + std::to_string(depth) + " per-structure";
                shallow.settings.instanced.maxDepth = depth;
                runs.push_back(shallow);
            }
        }
    }
    if (options.directOnly) {
        // Deterministic direct light, as fine as the finest HRC run: what ignoring
        // scattering costs in accuracy, and what it saves in time.
        Run run{"direct", "", base};
        run.settings.kind = SolverKind::kHrc;
        run.settings.hrc.directOnly = true;
        if (!options.hrcEpsilons.empty()) {
            run.settings.hrc.epsilon =
                *std::min_element(options.hrcEpsilons.begin(), options.hrcEpsilons.end());
        }
        run.setting = "epsilon=" + Number(run.settings.hrc.epsilon) + hrcSetting;
        runs.push_back(run);
    }
    return runs;
}

struct Row {
    std::string solver, setting, band;
    SolveStats stats;
    BandAccuracy accuracy;
    double balancePct = 0.0;
};

// The solver's working memory (its peak less the memory before it), or -1 where the kernel
// did not let the peak be reset (and for the reference, measured once in its own run).
std::int64_t WorkingBytes(const SolveStats& stats) {
    return stats.solvingPeakRssBytes > 0
               ? std::max<std::int64_t>(stats.solvingPeakRssBytes - stats.loadedRssBytes, 0)
               : -1;
}

void WriteCsv(const std::string& path, const std::string& scene, int leaves,
              const std::vector<Row>& rows) {
    if (std::filesystem::path(path).has_parent_path()) {
        std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    }
    std::ofstream out(path);
    if (!out) throw InputError(ErrorCode::kIo, path, "cannot write");
    out << "scene,leaves,solver,setting,band,wall_s,cpu_s,peak_mib,working_mib,iterations,links,"
           "l2_pct_of_max,mean_rel_pct,p95_rel_pct,reference_floor_pct,lit_leaves,"
           "balance_residual_pct\n";
    for (const Row& r : rows) {
        const std::int64_t working = WorkingBytes(r.stats);
        out << scene << ',' << leaves << ',' << r.solver << ',' << r.setting << ',' << r.band << ','
            << Number(r.stats.wallSeconds) << ',' << Number(r.stats.cpuSeconds) << ','
            << Number(static_cast<double>(r.stats.peakRssBytes) / (1 << 20)) << ','
            << (working >= 0 ? Number(static_cast<double>(working) / (1 << 20)) : std::string())
            << ',' << r.stats.iterations << ',' << r.stats.links << ','
            << Number(r.accuracy.l2PctOfMax) << ',' << Number(r.accuracy.meanRelativePct) << ','
            << Number(r.accuracy.p95RelativePct) << ',' << Number(r.accuracy.referenceFloorPct)
            << ',' << r.accuracy.litLeaves << ',' << Number(r.balancePct) << '\n';
    }
    if (!out) throw InputError(ErrorCode::kIo, path, "cannot write");
}

void PrintTable(const std::string& scene, const std::vector<Row>& rows) {
    std::printf("%-12s %-6s %-16s %-5s %8s %8s %9s %11s %8s %9s %8s %8s %9s\n", "scene", "solver",
                "setting", "band", "wall_s", "cpu_s", "peak_MiB", "working_MiB", "L2_%max",
                "mean_rel%", "p95_rel%", "floor_%", "balance%");
    for (const Row& r : rows) {
        const std::int64_t working = WorkingBytes(r.stats);
        std::printf("%-12s %-6s %-16s %-5s %8.3f %8.3f %9.0f %11s %8.3f %9.3f %8.3f %8.3f %9.3f\n",
                    scene.c_str(), r.solver.c_str(), r.setting.c_str(), r.band.c_str(),
                    r.stats.wallSeconds, r.stats.cpuSeconds,
                    static_cast<double>(r.stats.peakRssBytes) / (1 << 20),
                    working >= 0 ? std::to_string(working >> 20).c_str() : "-",
                    r.accuracy.l2PctOfMax, r.accuracy.meanRelativePct, r.accuracy.p95RelativePct,
                    r.accuracy.referenceFloorPct, r.balancePct);
    }
}

// `within`: the sample the reference was solved for, or none (every leaf).
std::vector<Row> RowsOf(const Run& run, const Scene& scene, const FlatScene& flat,
                        const Solution& reference, const Solution& solution,
                        const std::unordered_set<NodeId>* within) {
    const std::vector<BandAccuracy> accuracy =
        solution.wholeStructures.empty() || !solution.pushedDown.empty()
            ? CompareLeaves(scene, flat, reference, solution, within)
            : CompareWholeStructures(scene, flat, reference, solution, within);
    std::vector<Row> rows;
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        rows.push_back({run.solver, run.setting, scene.bands[b].name, solution.stats, accuracy[b],
                        100.0 * solution.balance[b].RelativeResidual()});
    }
    return rows;
}

// Plotting is Python's (matplotlib); a missing plot is a warning, the CSV is the result.
void Plot(const ErrorBenchOptions& options) {
    auto quoted = [](const std::string& text) {
        std::string out = "'";
        for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return out + "'";
    };
    // Debian's own Python is the one with python3-matplotlib, whatever else is on the PATH.
    const std::string python =
        std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string command = python + " " + quoted(options.plotScript) + " " +
                                quoted(options.csv) + " " + quoted(options.png);
    if (std::system(command.c_str()) != 0) {
        spdlog::warn("no plot: `{}` failed (python3 with matplotlib is needed)", command);
    }
}

// `count` of the scene's plants spread evenly through them by id (--sample-plants).
std::vector<NodeId> EvenlySpreadPlants(const Scene& scene, int count) {
    std::vector<NodeId> plants;
    for (const Node& node : scene.nodes)
        if (node.type() == NodeType::kPlant) plants.push_back(node.id);
    std::sort(plants.begin(), plants.end());
    if (plants.size() < static_cast<std::size_t>(count)) {
        throw InputError(ErrorCode::kInvalidArgument, "--sample-plants",
                         "the scene has " + std::to_string(plants.size()) + " plants, fewer than " +
                             std::to_string(count));
    }
    std::vector<NodeId> sampled;
    for (int k = 0; k < count; ++k)
        sampled.push_back(plants[(2 * k + 1) * plants.size() / (2 * count)]);
    return sampled;
}

}  // namespace

std::string DefaultCacheDirectory() {
    return LeafluxDirectory("XDG_CACHE_HOME", ".cache", ".leaflux-cache");
}

int RunErrorBench(const ErrorBenchOptions& options) {
    // Before the reference, which may take hours, as solve --out is checked before its solve.
    CheckWritable(options.csv, "--out");
    if (!options.png.empty()) CheckWritable(options.png, "--out");
    const Scene scene = LoadSceneFile(options.scene, options.file);
    const std::string& name = options.name;
    PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    // A sample of the plants: the reference is solved for their organs alone and every
    // error taken over their leaves.
    std::optional<std::unordered_set<NodeId>> sample;
    SolverSettings referenceSettings;
    if (options.samplePlants > 0) {
        sample = NodesUnder(scene, EvenlySpreadPlants(scene, options.samplePlants));
        for (std::uint32_t r = 0; r < flat.receivers.size(); ++r) {
            const Receiver& receiver = flat.receivers[r];
            if (receiver.kind == ReceiverKind::kOrgan && sample->count(receiver.node))
                referenceSettings.monteCarlo.only.push_back(r);
        }
    }
    const std::unordered_set<NodeId>* within = sample ? &*sample : nullptr;
    int leaves = 0;
    for (const Node& node : scene.nodes)
        leaves += node.type() == NodeType::kLeaf && (!within || within->count(node.id));
    if (!ResetPeakRss()) {
        spdlog::warn(
            "the kernel does not let the peak memory be reset: each run's peak is the "
            "process's so far");
    }

    referenceSettings.kind = SolverKind::kMonteCarlo;
    referenceSettings.monteCarlo.samplesPerReceiver = options.referenceSamples;
    referenceSettings.monteCarlo.seed = options.referenceSeed;
    referenceSettings.monteCarlo.threads = options.threads;
    const std::filesystem::path cached =
        std::filesystem::path(options.cacheDirectory.empty() ? DefaultCacheDirectory()
                                                             : options.cacheDirectory) /
        ("reference-" + ReferenceKey(scene, referenceSettings.monteCarlo) + ".bin");
    // A first solve pays the process's one-time start-up (worker threads, first touches of
    // the ray engine): a minimal untimed solve keeps it out of the timings, as a daemon
    // pays it once in its life.
    SolverSettings warmUp = referenceSettings;
    warmUp.monteCarlo.samplesPerReceiver = warmUp.monteCarlo.replicates = 2;
    Solve(prepared, warmUp);

    std::optional<Solution> reference =
        ReadCachedReference(cached, flat.receivers.size(), scene.bands.size());
    if (reference) {
        spdlog::info("{}: {} leaves; reference from {} (solved in {:.1f} s)", name, leaves,
                     cached.string(), reference->stats.wallSeconds);
    } else {
        CheckWritable(cached.string() + ".partial", "--cache");  // before the solve, too
        spdlog::info("{}: {} leaves; solving the reference at {} paths per receiver", name, leaves,
                     options.referenceSamples);
        SolverSettings solving = referenceSettings;  // the same key, with a progress bar
        solving.monteCarlo.progress = ProgressBar("reference");
        reference = Solve(prepared, solving);
        WriteCachedReference(cached, *reference);
        spdlog::info("reference solved in {:.1f} s, cached in {}", reference->stats.wallSeconds,
                     cached.string());
    }

    // The reference against itself: its own error is its standard error (the floor).
    std::vector<Row> rows =
        RowsOf({"mc", "reference samples=" + std::to_string(options.referenceSamples), {}}, scene,
               flat, *reference, *reference, within);
    // A reference of a sample balances no closed part of the scene: what its organs scatter
    // is absorbed and escapes through organs it did not solve.
    if (within != nullptr)
        for (Row& row : rows) row.balancePct = std::nan("");
    PhaseDatabase originals(PhaseDatabaseOptions{});  // the instanced runs'
    for (Run run : Runs(options)) {
        // The solver's working memory: its peak less what the process held before it (the
        // scene, flattened and in the ray engine, the reference, the phase functions the
        // earlier runs put in memory).
        const bool peakReset = ResetPeakRss();
        const std::int64_t before = ResidentBytes();
        run.settings.instanced.database = &originals;
        const std::string label = run.solver + " " + run.setting;
        if (run.solver == "hrc") run.settings.hrc.progress = ProgressBar(label);
        if (run.solver == "mc") run.settings.monteCarlo.progress = ProgressBar(label);
        Solution solution = Solve(prepared, run.settings);
        if (peakReset) {
            solution.stats.loadedRssBytes = before;
            solution.stats.solvingPeakRssBytes = solution.stats.peakRssBytes;
        }
        spdlog::info("{} {}: {:.2f} s", run.solver, run.setting, solution.stats.wallSeconds);
        for (Row& row : RowsOf(run, scene, flat, *reference, solution, within)) rows.push_back(row);
    }
    WriteCsv(options.csv, name, leaves, rows);
    PrintTable(name, rows);
    std::cout << "wrote " << options.csv << std::endl;
    if (!options.png.empty()) Plot(options);
    return 0;
}

}  // namespace leaflux
