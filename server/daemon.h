// The request handlers of leafluxd, apart from any transport: bytes in, bytes out.
//
// Every request is decoded, dispatched by type to one handler and answered with a Reply;
// each handler runs inside one try/catch, so a bad request gets a typed Error and never
// takes the daemon down. A session changes only when a request succeeds: deltas are applied
// to a copy of its scene, validated whole, then swapped in.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "leaflux.pb.h"
#include "server/scene_proto.h"
#include "solver/solve.h"

namespace leaflux {

// One growth model's scene and solver settings.
class Session {
  public:
    Session(Scene scene, MeshLibrary meshes, SolverSettings settings);

    // Applies a cycle's delta and suns to a copy of the scene, validates it whole, solves
    // it for what the cycle's outputs ask, and only then keeps it. Throws InputError
    // (naming the field or node) and leaves the session as it was otherwise.
    v1::CycleResult Run(const v1::Cycle& cycle);

    const Scene& Current() const { return scene_; }
    std::int64_t Cycles() const { return cycles_; }

  private:
    Scene Next(const v1::Cycle& cycle) const;
    v1::CycleResult Solve(const Scene& scene, const v1::OutputRequest& outputs) const;

    Scene scene_;
    MeshLibrary meshes_;
    SolverSettings settings_;
    std::int64_t cycles_ = 0;
};

struct DaemonLimits {
    std::size_t maxSessions = 64;
};

class Daemon {
  public:
    explicit Daemon(DaemonLimits limits = {});

    // Answers one encoded Request with one encoded Reply.
    std::string Handle(const std::string& request);
    v1::Reply Handle(const v1::Request& request);

    bool ShutdownRequested() const { return shutdown_; }

  private:
    v1::Reply Open(const v1::OpenSession& request);
    v1::Reply RunCycle(const v1::Cycle& request);
    v1::Reply Resynchronise(const v1::Resync& request);
    v1::Reply Status(const v1::StatusRequest& request);
    v1::Reply Close(const v1::CloseSession& request);
    Session& Find(const std::string& id);

    DaemonLimits limits_;
    std::mutex mutex_;  // one request at a time, for now
    std::map<std::string, std::unique_ptr<Session>> sessions_;
    std::uint64_t nextSession_ = 1;
    std::int64_t requests_ = 0;
    std::atomic<bool> shutdown_{false};
};

// An Error reply.
v1::Reply ErrorReply(v1::ErrorCode code, const std::string& message, const std::string& field = "",
                     std::uint64_t node = 0);

}  // namespace leaflux
