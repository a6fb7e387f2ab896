// leafluxd over loopback TCP: the protocol's own cost (Status round trips, a cycle with an
// empty delta, answered with the last cycle's light — with the organs' results or none —
// or solved again when it asks other outputs) and the latency of cycles of a plant growing to
// 1,000 leaves (ε = 1e-4, 3e-4, 1e-3 and 3e-3) and 10,000 leaves (ε = 1e-4 and 3e-4), one
// tenth of the plant added per cycle, each grown twice: from the direct light, and from the
// last cycle's light (SolverSettings.warm_start); and the same plants with the instanced
// solver, first on a new daemon's empty phase-function database (cold: the functions
// computed as the plant's structures appear), then as a second session on the database the
// first filled (warm: none computed), then a third on it with the warm start, and, given
// --merge-triangles=N, a fourth with its instances of at most N triangles merged into the
// problems of those holding them.
// Run: build/release/tests/leaflux_bench_daemon [out.csv [--merge-triangles=N]
// [LEAVES:EPSILON ...]] (default out/bench/daemon_bench.csv); each LEAVES:EPSILON grows one
// more tree of LEAVES leaves at that ε, as those above but for the protocol's cost.
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <thread>
#include <utility>

#include "server/daemon.h"
#include "server/executor.h"
#include "server/transport.h"
#include "solver/generate/generator.h"

namespace leaflux {
namespace {

using Clock = std::chrono::steady_clock;

class Loopback {
  public:
    Loopback() : server_(context_, "tcp://127.0.0.1:*") {
        thread_ = std::thread([this] {
            server_.Serve(
                DaemonDispatch(daemon_, executor_),
                [](const OversizedMessage&) { return std::string(); }, [] { return false; }, stop_);
        });
        client_ = std::make_unique<ClientConnection>(context_, server_.Endpoint());
    }
    ~Loopback() {
        stop_ = true;
        thread_.join();
    }
    v1::Reply Call(v1::Request request) {
        request.set_version(v1::PROTOCOL_VERSION_CURRENT);
        std::string bytes, reply;
        request.SerializeToString(&bytes);
        client_->Call(bytes, reply);
        v1::Reply decoded;
        decoded.ParseFromString(reply);
        return decoded;
    }

  private:
    zmq::context_t context_;
    Daemon daemon_;
    KeyedExecutor executor_{2};
    RouterServer server_;
    std::unique_ptr<ClientConnection> client_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

double Seconds(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
}

// The scene of a generated tree, without its nodes, and the nodes in parent-first order.
v1::Scene TreeScene(int leaves, std::vector<v1::Node>& nodes) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}, {0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0, 0}, {0.4, 0.4, 0, 0}}}};
    TreeParameters tree;
    tree.leafCount = leaves;
    AddTree(scene, tree, {0, 0, 0});
    scene.sources.suns.push_back({glm::normalize(glm::dvec3(0.3, -0.4, 0.8)), {400.0, 350.0}, 0.0});
    scene.sources.skies.push_back(
        {SkyModel::kCieOvercast, {100.0, 60.0}, SkyDiscretization::kTurtle46});
    v1::Scene message = ToProto(scene);
    nodes.assign(message.nodes().begin(), message.nodes().end());
    message.clear_nodes();
    return message;
}

struct Row {
    std::string what;
    int leaves;
    double epsilon;
    int cycle, organs;
    double roundTripMs, solveMs;
    int phaseComputed = 0;
    int iterations = 0;
    std::int64_t warmOrgans = 0;
};

}  // namespace
}  // namespace leaflux

// The growing plants and the ε of their sessions, and the protocol's cost measured on each;
// examples/bench_report.py adds, on the command line, the coarsest ε at which each solver's
// cycles stay within 2 % L2 of the reference (docs/results_daemon.md).
constexpr std::pair<int, double> kGrowths[] = {{1000, 1e-4}, {1000, 3e-4},  {1000, 1e-3},
                                               {1000, 3e-3}, {10000, 1e-4}, {10000, 3e-4}};

int main(int argc, char** argv) {
    using namespace leaflux;
    // Every request is logged at info level: SPDLOG_LEVEL=info shows them, debug the phases
    // of each cycle and of the solver.
    spdlog::set_level(spdlog::level::warn);
    spdlog::cfg::load_env_levels();
    std::vector<std::pair<int, double>> growths(std::begin(kGrowths), std::end(kGrowths));
    long long mergeTriangles = 0;  // the "instanced_merged" sessions' bound; 0: none run
    for (int a = 2; a < argc; ++a) {
        if (std::string_view(argv[a]).starts_with("--merge-triangles=")) {
            char rest = 0;
            if (std::sscanf(argv[a], "--merge-triangles=%lld%c", &mergeTriangles, &rest) == 1 &&
                mergeTriangles > 0)
                continue;
            std::fprintf(stderr, "%s: expected a positive triangle count\n", argv[a]);
            return 2;
        }
        int leaves = 0;
        double epsilon = 0.0;
        if (std::sscanf(argv[a], "%d:%lf", &leaves, &epsilon) != 2 || leaves <= 0 ||
            !(epsilon > 0.0)) {
            std::fprintf(stderr, "growth %s: expected LEAVES:EPSILON, e.g. 1000:6e-3\n", argv[a]);
            return 2;
        }
        if (std::find(growths.begin(), growths.end(), std::pair{leaves, epsilon}) == growths.end())
            growths.emplace_back(leaves, epsilon);
    }
    std::sort(growths.begin(), growths.end());
    std::vector<Row> rows;
    Loopback daemon;
    {
        v1::Request status;
        status.mutable_status();
        constexpr int kCalls = 2000;
        const auto start = Clock::now();
        for (int i = 0; i < kCalls; ++i) daemon.Call(status);
        rows.push_back({"status", 0, 0.0, 0, 0, 1e3 * Seconds(start) / kCalls, 0.0});
    }
    // Grows the tree of `leaves` in a session of `settings` over kCycles cycles; returns
    // the session.
    constexpr int kCycles = 10;
    auto grow = [&](Loopback& to, const char* what, int leaves,
                    const v1::SolverSettings& settings) {
        std::vector<v1::Node> nodes;
        v1::Request open;
        *open.mutable_open_session()->mutable_scene() = TreeScene(leaves, nodes);
        *open.mutable_open_session()->mutable_settings() = settings;
        open.mutable_open_session()->set_species("generated-tree");
        const std::string session = to.Call(open).opened().session();
        std::size_t next = 0;
        for (int c = 1; c <= kCycles; ++c) {
            v1::Request request;
            v1::Cycle* cycle = request.mutable_cycle();
            cycle->set_session(session);
            cycle->set_number(c);
            cycle->mutable_outputs()->set_leaves(true);
            const std::size_t until = nodes.size() * c / kCycles;
            for (; next < until; ++next) *cycle->mutable_delta()->add_added() = nodes[next];
            const auto start = Clock::now();
            const v1::Reply reply = to.Call(request);
            const v1::SolveStatistics& stats = reply.cycle().statistics();
            rows.push_back({what, leaves, settings.epsilon(), c, reply.cycle().organs_size(),
                            1e3 * Seconds(start), 1e3 * stats.wall_seconds(),
                            stats.phase_functions_computed(), stats.iterations(),
                            stats.warm_organs()});
        }
        return session;
    };
    for (const auto& [leaves, epsilon] : growths) {
        v1::SolverSettings settings;
        settings.set_epsilon(epsilon);
        settings.set_warm_start(true);
        grow(daemon, "growing_tree_warm_start", leaves, settings);
        settings.set_warm_start(false);
        const std::string session = grow(daemon, "growing_tree", leaves, settings);
        if (std::find(std::begin(kGrowths), std::end(kGrowths), std::pair{leaves, epsilon}) ==
            std::end(kGrowths))
            continue;
        // The same plant again with nothing changed. Asking what the last cycle asked, its
        // light comes back unsolved: the protocol alone and the organs' results (median of
        // kRepeats calls). Asking other outputs (none), it is solved again: validation,
        // flattening, ray engine and solve, without growth. Asking none again, it comes
        // back unsolved with no organs: the protocol alone.
        constexpr int kRepeats = 200;
        int number = kCycles;
        auto unchanged = [&](bool leavesWanted, int repeats, const char* what) {
            std::vector<double> times;
            v1::Reply reply;
            for (int i = 0; i < repeats; ++i) {
                v1::Request same;
                same.mutable_cycle()->set_session(session);
                same.mutable_cycle()->set_number(++number);
                same.mutable_cycle()->mutable_outputs()->set_leaves(leavesWanted);
                const auto start = Clock::now();
                reply = daemon.Call(same);
                times.push_back(1e3 * Seconds(start));
            }
            std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
            rows.push_back({what, leaves, epsilon, number, reply.cycle().organs_size(),
                            times[times.size() / 2],
                            1e3 * reply.cycle().statistics().wall_seconds()});
        };
        unchanged(true, kRepeats, "empty_delta");
        unchanged(false, 1, "empty_resolve");
        unchanged(false, kRepeats, "empty_nothing");
    }
    for (const auto& [leaves, epsilon] : growths) {
        v1::SolverSettings settings;
        settings.set_solver(v1::SOLVER_KIND_INSTANCED);
        settings.set_epsilon(epsilon);
        Loopback fresh;  // its database empty
        grow(fresh, "instanced_cold", leaves, settings);
        grow(fresh, "instanced_warm", leaves, settings);
        settings.set_warm_start(true);
        grow(fresh, "instanced_warm_start", leaves, settings);
        // Its small instances solved with those that hold them (merge_triangles).
        if (mergeTriangles > 0) {
            settings.set_warm_start(false);
            settings.mutable_instanced()->set_merge_triangles(mergeTriangles);
            grow(fresh, "instanced_merged", leaves, settings);
        }
    }
    const char* path = argc > 1 ? argv[1] : "out/bench/daemon_bench.csv";
    if (const auto folder = std::filesystem::path(path).parent_path(); !folder.empty())
        std::filesystem::create_directories(folder);  // out/ from the checkout root
    std::ofstream csv(path);
    csv << "what,leaves,epsilon,cycle,organs,round_trip_ms,solve_ms,overhead_ms,phase_computed,"
           "iterations,warm_organs\n";
    std::printf("%-26s %7s %8s %6s %7s %14s %10s %12s %6s %6s %7s\n", "what", "leaves", "epsilon",
                "cycle", "organs", "round_trip_ms", "solve_ms", "overhead_ms", "phases", "sweeps",
                "warm");
    for (const Row& r : rows) {
        csv << r.what << ',' << r.leaves << ',' << r.epsilon << ',' << r.cycle << ',' << r.organs
            << ',' << r.roundTripMs << ',' << r.solveMs << ',' << r.roundTripMs - r.solveMs << ','
            << r.phaseComputed << ',' << r.iterations << ',' << r.warmOrgans << '\n';
        std::printf("%-26s %7d %8.0e %6d %7d %14.3f %10.3f %12.3f %6d %6d %7lld\n", r.what.c_str(),
                    r.leaves, r.epsilon, r.cycle, r.organs, r.roundTripMs, r.solveMs,
                    r.roundTripMs - r.solveMs, r.phaseComputed, r.iterations,
                    static_cast<long long>(r.warmOrgans));
    }
    std::printf("wrote %s\n", path);
    return 0;
}
