// leafluxd: the lighting daemon. Growth models connect over ZeroMQ and speak leaflux.v1
// (proto/leaflux.proto): OpenSession, then a Cycle per growth step, and CloseSession.
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <csignal>

#include "server/daemon.h"
#include "server/executor.h"
#include "server/transport.h"

namespace {
std::atomic<bool> stopRequested{false};
void OnSignal(int) { stopRequested = true; }
}  // namespace

int main(int argc, char** argv) {
    using namespace leaflux;
    CLI::App app{"leafluxd: the leaflux lighting daemon (ZeroMQ + protobuf, leaflux.v1)"};
    std::string bind = "tcp://127.0.0.1:5555", level = "info", logFile;
    DaemonLimits limits;
    TransportLimits transport;
    std::size_t maxMegabytes = 256;
    int workers = 2;
    std::string curveKeyFile;
    app.add_option("--bind", bind, "ZeroMQ endpoint to serve (loopback by default)");
    app.add_option("--log-level", level, "trace, debug, info, warn, error")
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
    app.add_option("--log-file", logFile,
                   "Also append the log to this file (every request with its timing at info)");
    app.add_option("--solver-threads", limits.solverThreads,
                   "Cores one solve may use (0: all); a session asking fewer gets fewer")
        ->check(CLI::Range(0, 1024));
    app.add_option("--max-sessions", limits.maxSessions, "Sessions served at once")
        ->check(CLI::Range(1, 100000));
    app.add_option("--workers", workers,
                   "Requests handled at once (different sessions solve in parallel)")
        ->check(CLI::Range(1, 256));
    app.add_option("--curve-secret-key", curveKeyFile,
                   "File with the server's CurveZMQ secret key (leaflux keygen): encrypts every "
                   "connection; required to bind anywhere but loopback")
        ->check(CLI::ExistingFile);
    app.add_option("--max-message-mb", maxMegabytes, "Largest request accepted (MiB)")
        ->check(CLI::Range(1, 4096));
    CLI11_PARSE(app, argc, argv);
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
    std::string curveSecretKey;
    if (!curveKeyFile.empty()) {
        const auto key = ReadCurveKey(curveKeyFile);
        if (!key) {
            spdlog::error("{}: not a Z85 CurveZMQ secret key (40 characters)", curveKeyFile);
            return 2;
        }
        curveSecretKey = *key;
    }
    const bool loopback = bind.rfind("tcp://127.", 0) == 0 ||
                          bind.rfind("tcp://localhost", 0) == 0 || bind.rfind("ipc://", 0) == 0 ||
                          bind.rfind("inproc://", 0) == 0;
    if (!loopback && curveSecretKey.empty()) {
        spdlog::error("{}: binding beyond loopback needs --curve-secret-key", bind);
        return 2;
    }
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    try {
        zmq::context_t context;
        Daemon daemon(limits);
        RouterServer server(context, bind, transport, curveSecretKey);
        // Declared after the daemon: on the way out, in-flight requests finish first.
        KeyedExecutor executor(workers);
        spdlog::info("leafluxd serving {} with {} workers", server.Endpoint(), workers);
        server.Serve(
            DaemonDispatch(daemon, executor),
            [] {
                std::string out;
                ErrorReply(v1::ERROR_CODE_TOO_LARGE, "the message exceeds the daemon's limits")
                    .SerializeToString(&out);
                return out;
            },
            [&] { return daemon.ShutdownRequested(); }, stopRequested);
        spdlog::info("leafluxd stopped");
    } catch (const std::exception& e) {
        spdlog::error("leafluxd: {}", e.what());
        return 1;
    }
    return 0;
}
