// The request handlers of leafluxd, apart from any transport: bytes in, bytes out.
//
// Every request is decoded, dispatched by type to one handler and answered with a Reply;
// each handler runs inside one try/catch, so a bad request gets a typed Error and never
// takes the daemon down. A session changes only when a request succeeds: a delta is checked
// whole before it is applied, and taken back if its solve fails.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "leaflux.pb.h"
#include "server/scene_proto.h"
#include "solver/scene/scene_store.h"
#include "solver/solve.h"

namespace leaflux {

// One growth model's scene and solver settings.
class Session {
  public:
    Session(Scene scene, MeshLibrary meshes, SolverSettings settings);

    // Checks a cycle's delta and suns against the scene they make, applies them and solves
    // that scene for what the cycle's outputs ask; the checks and the geometry cost what
    // the delta touches (SceneStore). Throws InputError (naming the field or node), and
    // then the session is as it was: a delta whose solve fails is taken back. A cycle that
    // changes nothing and asks what the last one asked gets the last one's light again.
    v1::CycleResult Run(const v1::Cycle& cycle);

    // What Status reports; readable while the session solves.
    std::int64_t Cycles() const { return cycles_; }
    int Nodes() const { return nodes_; }
    int Organs() const { return organs_; }

  private:
    SceneChange Change(const v1::Cycle& cycle) const;
    v1::CycleResult Solve(const v1::OutputRequest& outputs) const;

    void Count();

    SceneStore store_;
    MeshLibrary meshes_;
    SolverSettings settings_;
    // The last cycle's result and the outputs it answered (serialised), for a cycle that
    // changes nothing: the solvers are deterministic, so it would get the same light.
    std::string lastOutputs_;
    std::optional<v1::CycleResult> last_;
    std::atomic<std::int64_t> cycles_{0};
    std::atomic<int> nodes_{0}, organs_{0};
};

struct DaemonLimits {
    std::size_t maxSessions = 64;
    int solverThreads = 0;  // cores one solve may use; 0: all
};

class Daemon {
  public:
    explicit Daemon(DaemonLimits limits = {});

    // Answers one encoded Request with one encoded Reply.
    std::string Handle(const std::string& request);
    // Thread-safe, provided the requests of one session come one at a time (KeyOf).
    v1::Reply Handle(const v1::Request& request);
    // The session a request must be ordered with ("" for none: Open, Status, Shutdown).
    static std::string KeyOf(const v1::Request& request);

    bool ShutdownRequested() const { return shutdown_; }

  private:
    v1::Reply Open(const v1::OpenSession& request);
    v1::Reply RunCycle(const v1::Cycle& request);
    v1::Reply Resynchronise(const v1::Resync& request);
    v1::Reply Status(const v1::StatusRequest& request);
    v1::Reply Close(const v1::CloseSession& request);
    std::shared_ptr<Session> Find(const std::string& id);
    // A session's solver settings, its threads within the daemon's limit.
    SolverSettings Settings(const v1::SolverSettings& in) const;

    DaemonLimits limits_;
    std::mutex mutex_;  // guards the map and the id counter, never held while solving
    std::map<std::string, std::shared_ptr<Session>> sessions_;
    std::uint64_t nextSession_ = 1;
    std::atomic<std::int64_t> requests_{0};
    std::atomic<bool> shutdown_{false};
};

class KeyedExecutor;
// Decodes each message, runs it on `executor` in its session's order and answers through
// the transport; garbage is answered at once.
std::function<void(std::string, std::function<void(std::string)>)> DaemonDispatch(
    Daemon& daemon, KeyedExecutor& executor);

// An Error reply.
v1::Reply ErrorReply(v1::ErrorCode code, const std::string& message, const std::string& field = "",
                     std::uint64_t node = 0);

}  // namespace leaflux
