// The request handlers of leafluxd, apart from any transport: bytes in, bytes out.
//
// Every request is decoded, dispatched by type to one handler and answered with a Reply;
// each handler runs inside one try/catch, so a bad request gets a typed Error and never
// takes the daemon down. A session changes only when a request succeeds: a delta is checked
// whole before it is applied, and taken back if its solve fails. Counts a request
// multiplies (bands, suns, nodes, periodic tile crossings) are capped before any work.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "leaflux.pb.h"
#include "server/instanced_settings.h"
#include "server/scene_proto.h"
#include "solver/instancing/phase_db.h"
#include "solver/scene/scene_store.h"
#include "solver/solve.h"

namespace leaflux {

struct DaemonLimits {
    std::size_t maxSessions = 64;
    int solverThreads = 0;            // cores one solve may use; 0: all
    SceneLimits scene;                // bands, suns (sun period steps included), nodes of a session
    std::size_t maxMessageBytes = 0;  // the transport's limit, for Status (0: not told)
};

// The daemon's instantiation: its phase-function database, which every session of the
// instanced solver shares, and where it finds policies by name and species.
struct DaemonPhaseFunctions {
    // path "" keeps the functions in memory (--no-phase-db); a file that cannot be opened
    // is reported (Health) and the daemon goes on in memory, whatever degradeToMemory says.
    PhaseDatabaseOptions database;
    std::string policyDir;  // --policy-dir; "" none
};

// How a session solves: the solver's settings and, for the instanced solver, its run and
// the daemon's database.
struct SessionSolver {
    SolverSettings settings;
    bool warmStart = false;  // from the last cycle's light (SolverSettings.warm_start)
    std::optional<InstancedRun> instanced;
    std::shared_ptr<PhaseDatabase> database;  // set with `instanced`
};

// One growth model's scene and solver settings.
class Session {
  public:
    // Throws TooLarge when the scene's periodic tile is too small for its geometry, and
    // InputError (settings.solver) for the instanced solver on a periodic scene.
    Session(Scene scene, MeshLibrary meshes, SessionSolver solver, SceneLimits limits,
            std::int64_t lastCycle = 0);

    // Checks a cycle's number, counts, delta and suns against the scene they make, applies
    // them and solves that scene for what the cycle's outputs ask; the checks and the
    // geometry cost what the delta touches (SceneStore). Throws InputError or TooLarge
    // (naming the field or node), and then the session is as it was: a delta whose solve
    // fails is taken back. A cycle that changes nothing and asks what the last one asked
    // gets the last one's light again.
    v1::CycleResult Run(const v1::Cycle& cycle);

    // What Status reports; readable while the session solves.
    std::int64_t Cycles() const { return cycles_; }
    std::int64_t LastCycle() const { return lastCycle_; }
    int Nodes() const { return nodes_; }
    int Organs() const { return organs_; }

    // A picture of the scene in the light the last cycle returned (RenderSession); changes
    // nothing.
    v1::Picture Render(const v1::RenderRequest& request) const;

  private:
    SceneChange Change(const v1::Cycle& cycle) const;
    struct Solved {
        v1::CycleResult result;
        std::shared_ptr<const WarmStart> warm;  // its organs' light, when every band was solved
    };
    Solved Solve(const v1::OutputRequest& outputs) const;

    void Count();

    SceneStore store_;
    MeshLibrary meshes_;
    SessionSolver solver_;
    SceneLimits limits_;
    // The last cycle's result and the outputs it answered (serialised), for a cycle that
    // changes nothing: the solvers are deterministic, so it would get the same light.
    std::string lastOutputs_;
    std::optional<v1::CycleResult> last_;
    // The organs' light of the last cycle that solved every band: where the next starts.
    std::shared_ptr<const WarmStart> warm_;
    std::atomic<std::int64_t> cycles_{0}, lastCycle_{0};
    std::atomic<int> nodes_{0}, organs_{0};
};

// A session id: 128 random bits as 32 lowercase hexadecimal digits.
std::string NewSessionId();
bool IsSessionId(const std::string& id);

class Daemon {
  public:
    explicit Daemon(DaemonLimits limits = {}, DaemonPhaseFunctions phase = {});

    // Answers one encoded Request with one encoded Reply.
    std::string Handle(const std::string& request);
    // Thread-safe, provided the requests of one session come one at a time (KeyOf).
    v1::Reply Handle(const v1::Request& request);
    // The session a request must be ordered with ("" for none: Open, Status, Shutdown).
    static std::string KeyOf(const v1::Request& request);

    bool ShutdownRequested() const { return shutdown_; }
    // The database every instanced session shares (never null).
    PhaseDatabase& PhaseFunctions() { return *phaseDb_; }

  private:
    v1::Reply Open(const v1::OpenSession& request);
    v1::Reply RunCycle(const v1::Cycle& request);
    v1::Reply Resynchronise(const v1::Resync& request);
    v1::Reply Status(const v1::StatusRequest& request);
    v1::Reply Close(const v1::CloseSession& request);
    v1::Reply Draw(const v1::RenderRequest& request);
    std::shared_ptr<Session> Find(const std::string& id);
    // A session's solver settings, its threads within the daemon's limit; for the
    // instanced solver its run (policy by `species`) on the daemon's database.
    SessionSolver Settings(const v1::SolverSettings& in, const std::string& species) const;

    DaemonLimits limits_;
    DaemonPhaseFunctions phase_;
    std::shared_ptr<PhaseDatabase> phaseDb_;
    std::mutex mutex_;  // guards the map, never held while solving
    std::map<std::string, std::shared_ptr<Session>> sessions_;
    std::atomic<std::int64_t> requests_{0};
    std::atomic<bool> shutdown_{false};
};

class KeyedExecutor;

// Decodes each message and runs it on `executor` in its session's order, answering through
// the transport; garbage is answered at once, and so is Status, on the serving thread:
// it never waits behind a solve. When the daemon stops it refuses what is queued and, after
// a grace, answers what still runs with ERROR_CODE_SHUTTING_DOWN.
class DaemonDispatcher {
  public:
    using Respond = std::function<void(std::string)>;
    DaemonDispatcher(Daemon& daemon, KeyedExecutor& executor);

    void operator()(std::string payload, Respond respond);

    // From now on every request is answered ERROR_CODE_SHUTTING_DOWN; so are the queued
    // ones, at once.
    void StopTaking();
    // Requests still running (after StopTaking: the solves in flight).
    std::size_t Running() const;
    // Answers every running request with ERROR_CODE_SHUTTING_DOWN; their results, if they
    // come, are dropped.
    void AbandonRunning();

  private:
    struct Pending;
    // The requests submitted and not answered; shared with the jobs, which may outlive the
    // dispatcher (an executor joined after it).
    struct InFlight;

    Daemon& daemon_;
    KeyedExecutor& executor_;
    std::shared_ptr<InFlight> inFlight_;
    std::atomic<bool> stopping_{false};
};

// A DaemonDispatcher as a transport's Dispatch.
std::function<void(std::string, std::function<void(std::string)>)> DaemonDispatch(
    Daemon& daemon, KeyedExecutor& executor);

// An Error reply.
v1::Reply ErrorReply(v1::ErrorCode code, const std::string& message, const std::string& field = "",
                     std::uint64_t node = 0);

// The typed reply to a message the transport refused for its size (`head`: its payload's
// first bytes, from which the request id is read when they hold it).
std::string TooLargeReply(std::size_t bytes, std::size_t frames, const std::string& head,
                          std::size_t limitBytes);

}  // namespace leaflux
