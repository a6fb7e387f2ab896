// leafluxd: the lighting daemon. Growth models connect over ZeroMQ and speak leaflux.v1
// (proto/leaflux.proto): OpenSession, then a Cycle per growth step, and CloseSession.
//
// Stopping (SIGTERM, SIGINT or a Shutdown request): no new request is taken (each is
// answered ERROR_CODE_SHUTTING_DOWN), the queued ones are refused the same way, the solves
// in flight get --grace-seconds to end and are then answered SHUTTING_DOWN and abandoned:
// the solvers cannot be interrupted, so the process exits without waiting for them.
// The one thing a request writes is the phase-function database, a row per transaction:
// a solve abandoned mid-computation stores nothing, and before exiting the database's
// committed rows are flushed into its file. A second signal ends the process at once.
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdlib>

#include "server/cli_checks.h"
#include "server/daemon.h"
#include "server/executor.h"
#include "server/transport.h"
#include "solver/instancing/phase_db.h"

namespace {
std::atomic<int> signals{0};
void OnSignal(int) {
    if (signals.fetch_add(1) > 0) _exit(1);  // the second: at once (async-signal-safe)
}
}  // namespace

int main(int argc, char** argv) {
    using namespace leaflux;
    CLI::App app{"leafluxd: the leaflux lighting daemon (ZeroMQ + protobuf, leaflux.v1)"};
    app.option_defaults()->always_capture_default();  // --help shows every default
    std::string bind = "tcp://127.0.0.1:5555", level = "info", logFile;
    DaemonLimits limits;
    TransportLimits transport;
    std::size_t maxMegabytes = 256;
    int workers = 2;
    double graceSeconds = 20.0;
    std::string curveKeyFile;
    DaemonPhaseFunctions phase;
    phase.database.path = DefaultPhaseDatabasePath();
    bool noPhaseDb = false;
    app.add_option("--bind", bind,
                   "ZeroMQ endpoint to serve: tcp://HOST:PORT (loopback by default; "
                   "tcp://[::1]:PORT is loopback too), ipc://PATH")
        ->capture_default_str();
    app.add_option("--log-level", level, "trace, debug, info, warn, error")
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
    app.add_option("--log-file", logFile,
                   "Also append the log to this file (every request with its timing at info)");
    app.add_option("--solver-threads", limits.solverThreads,
                   "Cores one solve may use (0: all); a session asking fewer gets fewer")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1024));
    app.add_option("--max-sessions", limits.maxSessions, "Sessions served at once")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    app.add_option("--max-nodes", limits.scene.maxNodes,
                   "Nodes a session may hold; an OpenSession, Resync or cycle beyond is refused "
                   "with ERROR_CODE_TOO_LARGE")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 1'000'000'000))
        ->capture_default_str();
    app.add_option("--max-suns", limits.scene.maxSuns,
                   "Suns a scene or a cycle may hold, sun period steps included (each is a "
                   "light source every solve traces)")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 1'000'000))
        ->capture_default_str();
    app.add_option("--workers", workers,
                   "Requests handled at once (different sessions solve in parallel; Status is "
                   "answered apart, never behind a solve)")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    app.add_option("--grace-seconds", graceSeconds,
                   "On SIGTERM, SIGINT or Shutdown: how long the solves in flight may take to "
                   "end before they are answered ERROR_CODE_SHUTTING_DOWN and abandoned (queued "
                   "requests are refused at once; a second signal exits at once)")
        ->check(CLI::Range(0.0, 86400.0))
        ->capture_default_str();
    app.add_option("--curve-secret-key", curveKeyFile,
                   "File with the server's CurveZMQ secret key (leaflux keygen): encrypts every "
                   "connection; required to bind anywhere but loopback")
        ->check(CLI::ExistingFile);
    app.add_option("--max-message-mb", maxMegabytes,
                   "Largest request accepted (MiB), all its frames together; larger ones get "
                   "ERROR_CODE_TOO_LARGE, and a frame over twice this closes the connection")
        ->check(CLI::Range(1, 4096))
        ->capture_default_str();
    app.add_option("--phase-db", phase.database.path,
                   "Phase-function database file, which every session of the instanced solver "
                   "reads and extends and a restarted daemon reuses; one that cannot be opened "
                   "(corrupt, foreign, read-only) is reported in the log and the replies, and "
                   "the daemon goes on in memory, never writing a file it did not create")
        ->capture_default_str();
    app.add_flag("--no-phase-db", noPhaseDb,
                 "Keep the phase functions in memory only, for this run");
    app.add_option("--phase-db-mb", phase.database.memoryCapMb,
                   "The phase-function database's buffer in memory (MB)")
        ->check(CLI::Range(1.0, 1e6))
        ->capture_default_str();
    app.add_option("--policy-dir", phase.policyDir,
                   "Folder of instantiation policies (DIR/NAME.txtpb): a session names one, "
                   "or gets the one of its species, else the built-in general policy")
        ->check(CLI::ExistingDirectory);
    CLI11_PARSE(app, argc, argv);
    if (noPhaseDb) phase.database.path.clear();
    spdlog::set_default_logger(spdlog::stderr_color_mt("leafluxd"));  // a daemon logs to stderr
    if (!logFile.empty()) {
        try {
            auto logger = std::make_shared<spdlog::logger>(
                "leafluxd", spdlog::sinks_init_list{
                                std::make_shared<spdlog::sinks::stderr_color_sink_mt>(),
                                std::make_shared<spdlog::sinks::basic_file_sink_mt>(logFile)});
            spdlog::set_default_logger(logger);
            spdlog::flush_every(std::chrono::seconds(1));
        } catch (const spdlog::spdlog_ex& e) {
            spdlog::error("--log-file {}: {}", logFile, e.what());
            return 2;
        }
    }
    spdlog::set_level(spdlog::level::from_str(level));
    transport.maxBytes = maxMegabytes << 20;
    limits.maxMessageBytes = transport.maxBytes;
    if (const std::string problem = EndpointProblem(bind); !problem.empty()) {
        spdlog::error("--bind {}", problem);
        return 2;
    }
    std::string curveSecretKey;
    if (!curveKeyFile.empty()) {
        const auto key = ReadCurveKey(curveKeyFile);
        if (!key) {
            spdlog::error("{}: not a Z85 CurveZMQ secret key (40 characters)", curveKeyFile);
            return 2;
        }
        curveSecretKey = *key;
    }
    if (!IsLoopback(bind) && curveSecretKey.empty()) {
        spdlog::error("{}: binding beyond loopback needs --curve-secret-key", bind);
        return 2;
    }
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    zmq::context_t context;
    Daemon daemon(limits, std::move(phase));
    std::unique_ptr<RouterServer> server;
    try {
        server = std::make_unique<RouterServer>(context, bind, transport, curveSecretKey);
    } catch (const std::exception& e) {
        spdlog::error("leafluxd: {}", e.what());
        return 2;
    }
    // Declared after the daemon: destroyed first, once idle.
    KeyedExecutor executor(workers);
    DaemonDispatcher dispatcher(daemon, executor);
    const RouterServer::Dispatch dispatch = [&](std::string payload,
                                                RouterServer::Respond respond) {
        dispatcher(std::move(payload), std::move(respond));
    };
    const RouterServer::TooLarge tooLarge = [&](const OversizedMessage& m) {
        return TooLargeReply(m.bytes, m.frames, m.head, transport.maxBytes);
    };
    std::size_t abandoned = 0;
    try {
        spdlog::info("leafluxd serving {} with {} workers", server->Endpoint(), workers);
        spdlog::default_logger()->flush();
        server->Serve(
            dispatch, tooLarge, [&] { return daemon.ShutdownRequested(); },
            [] { return signals.load() > 0; });
        // Stopping: refuse what is queued, give what runs its grace, then abandon it.
        dispatcher.StopTaking();
        using Clock = std::chrono::steady_clock;
        const Clock::time_point deadline =
            Clock::now() + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(graceSeconds));
        if (dispatcher.Running() > 0) {
            spdlog::info("leafluxd stopping: {} requests in flight, {:g} s of grace",
                         dispatcher.Running(), graceSeconds);
        }
        server->Serve(
            dispatch, tooLarge, [] { return false; },
            [&] { return dispatcher.Running() == 0 || Clock::now() >= deadline; });
        abandoned = dispatcher.Running();
        dispatcher.AbandonRunning();
        server->Close(std::chrono::milliseconds(2000));
        if (abandoned > 0) spdlog::warn("leafluxd abandoned {} requests in flight", abandoned);
        daemon.PhaseFunctions().Flush();
        spdlog::info("leafluxd stopped");
    } catch (const std::exception& e) {
        spdlog::error("leafluxd: {}", e.what());
        spdlog::default_logger()->flush();
        std::_Exit(1);
    }
    spdlog::default_logger()->flush();
    if (abandoned > 0) {
        server.reset();
        context.close();  // delivers the last replies (or gives up after the linger)
        std::_Exit(0);    // the abandoned solves' threads are not waited for
    }
    return 0;
}
