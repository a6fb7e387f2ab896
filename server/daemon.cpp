#include "server/daemon.h"

#include <google/protobuf/io/coded_stream.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <random>

#include "server/executor.h"
#include "server/session_render.h"
#include "solver/scene/light_units.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

v1::ErrorCode ToProto(ErrorCode code) {
    switch (code) {
        case ErrorCode::kInvalidArgument:
            return v1::ERROR_CODE_INVALID_ARGUMENT;
        case ErrorCode::kNotFound:
            return v1::ERROR_CODE_NOT_FOUND;
        case ErrorCode::kAlreadyExists:
            return v1::ERROR_CODE_ALREADY_EXISTS;
        case ErrorCode::kDegenerate:
            return v1::ERROR_CODE_DEGENERATE;
        case ErrorCode::kCycle:
            return v1::ERROR_CODE_CYCLE;
        case ErrorCode::kParse:
            return v1::ERROR_CODE_PARSE;
        case ErrorCode::kIo:
            return v1::ERROR_CODE_IO;
        case ErrorCode::kUnsupported:
            return v1::ERROR_CODE_UNSUPPORTED;
    }
    return v1::ERROR_CODE_INTERNAL;
}

using Clock = std::chrono::steady_clock;

double Milliseconds(Clock::time_point since) {
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

// The request's kind and the session it concerns, for the log.
std::string Describe(const v1::Request& request) {
    switch (request.body_case()) {
        case v1::Request::kOpenSession:
            return "open_session";
        case v1::Request::kCycle:
            return "cycle " + std::to_string(request.cycle().number()) + " of session " +
                   request.cycle().session();
        case v1::Request::kResync:
            return "resync of session " + request.resync().session();
        case v1::Request::kStatus:
            return "status";
        case v1::Request::kCloseSession:
            return "close_session " + request.close_session().session();
        case v1::Request::kShutdown:
            return "shutdown";
        case v1::Request::kRender:
            return "render of session " + request.render().session();
        default:
            return "request without a known body";
    }
}

// How a session solves, for the log: "" for HRC and Monte Carlo, else the instanced
// solver's species and where its policy came from.
std::string DescribeSolver(const SessionSolver& solver) {
    if (!solver.instanced) return "";
    return ": instanced, species " + solver.instanced->policy.species + ", policy " +
           solver.instanced->policySource;
}

// A session-level unknown id: its own code, so a client knows to resync.
class UnknownSession : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

SolverSettings SettingsFromProto(const v1::SolverSettings& in) {
    SolverSettings settings;
    settings.kind =
        in.solver() == v1::SOLVER_KIND_MONTE_CARLO ? SolverKind::kMonteCarlo : SolverKind::kHrc;
    if (in.epsilon() != 0.0) {
        if (!(in.epsilon() > 0.0 && in.epsilon() < 1.0)) {
            throw InputError(ErrorCode::kInvalidArgument, "settings.epsilon", "must be in (0, 1)");
        }
        settings.hrc.epsilon = in.epsilon();
    }
    if (in.samples() < 0 || in.samples() > (1 << 24)) {
        throw InputError(ErrorCode::kInvalidArgument, "settings.samples", "must be in [0, 2^24]");
    }
    if (in.samples() > 0) settings.monteCarlo.samplesPerReceiver = in.samples();
    if (in.threads() < 0 || in.threads() > 1024) {
        throw InputError(ErrorCode::kInvalidArgument, "settings.threads", "must be in [0, 1024]");
    }
    if (in.subdivision() < 0 || in.subdivision() > 8) {
        throw InputError(ErrorCode::kInvalidArgument, "settings.subdivision", "must be in [0, 8]");
    }
    if (in.subdivision() > 0) settings.hrc.maxSubdivision = in.subdivision();
    settings.monteCarlo.seed = in.seed() == 0 ? 1 : in.seed();
    settings.monteCarlo.threads = settings.hrc.threads = in.threads();
    settings.monteCarlo.directOnly = settings.hrc.directOnly = in.direct_only();
    return settings;
}

// `errors`: the bands' standard errors, or none (-1 in the reply).
void BandsToProto(const Scene& scene, std::span<const BandLight> bands,
                  std::span<const BandError> errors, const std::vector<int>& wanted,
                  bool lightVectors, google::protobuf::RepeatedPtrField<v1::BandLight>* out) {
    for (int b : wanted) {
        const BandLight& light = bands[b];
        v1::BandLight* band = out->Add();
        band->set_band(scene.bands[b].name);
        band->set_irradiance_upper_wm2(light.irradianceUpperWm2);
        band->set_irradiance_lower_wm2(light.irradianceLowerWm2);
        band->set_absorbed_w(light.absorbedW);
        if (lightVectors) {
            const glm::dvec3 v = light.LightVector();
            band->mutable_light_vector()->set_x(v.x);
            band->mutable_light_vector()->set_y(v.y);
            band->mutable_light_vector()->set_z(v.z);
        }
        band->set_stderr_upper_wm2(errors.empty() ? -1.0 : errors[b].upperWm2);
        band->set_stderr_lower_wm2(errors.empty() ? -1.0 : errors[b].lowerWm2);
        if (const std::optional<double> photons = PhotonUmolPerJ(scene.bands[b])) {
            band->set_photon_irradiance_upper_umol_m2_s(*photons * light.irradianceUpperWm2);
            band->set_photon_irradiance_lower_umol_m2_s(*photons * light.irradianceLowerWm2);
            band->set_absorbed_umol_s(*photons * light.absorbedW);
        }
    }
}

}  // namespace

v1::Reply ErrorReply(v1::ErrorCode code, const std::string& message, const std::string& field,
                     std::uint64_t node) {
    v1::Reply reply;
    reply.set_version(v1::PROTOCOL_VERSION_CURRENT);
    v1::Error* error = reply.mutable_error();
    error->set_code(code);
    error->set_message(message);
    error->set_field(field);
    error->set_node(node);
    return reply;
}

Session::Session(Scene scene, MeshLibrary meshes, SessionSolver solver, SceneLimits limits,
                 std::int64_t lastCycle)
    : store_(std::move(scene)),
      meshes_(std::move(meshes)),
      solver_(std::move(solver)),
      limits_(limits),
      lastCycle_(lastCycle) {
    if (solver_.instanced && store_.Get().periodic) {
        throw InputError(ErrorCode::kUnsupported, "settings.solver",
                         "the instanced solver does not repeat a periodic tile; use hrc or mc");
    }
    if (store_.Get().periodic) CheckPeriodicTile(store_.Get(), store_.Flat(), limits_);
    Count();
}

void Session::Count() {
    const Scene& scene = store_.Get();
    nodes_ = static_cast<int>(scene.nodes.size());
    organs_ = static_cast<int>(std::count_if(scene.nodes.begin(), scene.nodes.end(),
                                             [](const Node& n) { return n.organ().has_value(); }));
}

v1::CycleResult Session::Run(const v1::Cycle& cycle) {
    const v1::TopologyDelta& delta = cycle.delta();
    // Counts before any work they multiply, then the number.
    if (cycle.outputs().bands_size() > kMaxBands) {
        throw TooLarge("outputs.bands", "at most " + std::to_string(kMaxBands) + " bands, got " +
                                            std::to_string(cycle.outputs().bands_size()));
    }
    if (static_cast<std::size_t>(cycle.suns_size()) > limits_.maxSuns) {
        throw TooLarge("suns", "at most " + std::to_string(limits_.maxSuns) + " suns, got " +
                                   std::to_string(cycle.suns_size()));
    }
    if (static_cast<std::size_t>(delta.added_size()) > limits_.maxNodes) {
        // Removals take subtrees: the total is checked exactly once the delta is applied.
        throw TooLarge("delta.added", "at most " + std::to_string(limits_.maxNodes) +
                                          " nodes a session, got " +
                                          std::to_string(delta.added_size()) + " added");
    }
    if (cycle.number() <= lastCycle_) {
        throw InputError(ErrorCode::kInvalidArgument, "number",
                         "cycle numbers are positive and increase: " +
                             std::to_string(cycle.number()) + " does not follow the session's " +
                             (lastCycle_ == 0 ? std::string("start")
                                              : "last cycle, " + std::to_string(lastCycle_)));
    }
    const bool unchanged = delta.added_size() == 0 && delta.updated_size() == 0 &&
                           delta.removed_size() == 0 && cycle.suns_size() == 0;
    std::string outputs;
    cycle.outputs().SerializeToString(&outputs);
    if (unchanged && last_ && outputs == lastOutputs_) {
        v1::CycleResult result = *last_;
        result.mutable_statistics()->set_reused(true);
        result.mutable_statistics()->set_wall_seconds(0.0);
        result.mutable_statistics()->set_cpu_seconds(0.0);
        ++cycles_;
        lastCycle_ = cycle.number();
        return result;
    }
    const Clock::time_point start = Clock::now();
    store_.Apply(Change(cycle));  // checked against the scene it makes, then applied
    spdlog::debug("cycle {}: delta applied and the scene validated in {:.1f} ms", cycle.number(),
                  Milliseconds(start));
    v1::CycleResult result;
    try {
        if (store_.Get().nodes.size() > limits_.maxNodes) {
            throw TooLarge("delta.added",
                           "the session would hold " + std::to_string(store_.Get().nodes.size()) +
                               " nodes; at most " + std::to_string(limits_.maxNodes));
        }
        Solved solved = Solve(cycle.outputs());
        result = std::move(solved.result);
        if (solved.warm) warm_ = std::move(solved.warm);
    } catch (...) {
        store_.Undo();
        throw;
    }
    Count();
    ++cycles_;
    lastCycle_ = cycle.number();
    last_ = result;
    lastOutputs_ = std::move(outputs);
    return result;
}

v1::Picture Session::Render(const v1::RenderRequest& request) const {
    return RenderSession(store_.Get(), store_.Flat(), last_ ? &*last_ : nullptr, request);
}

SceneChange Session::Change(const v1::Cycle& cycle) const {
    const v1::TopologyDelta& delta = cycle.delta();
    SceneChange change;
    change.removed.assign(delta.removed().begin(), delta.removed().end());
    for (const v1::Node& in : delta.updated()) change.updated.push_back(NodeFromProto(in, meshes_));
    for (const v1::Node& in : delta.added()) change.added.push_back(NodeFromProto(in, meshes_));
    if (cycle.suns_size() > 0) {
        change.suns.emplace();
        for (int i = 0; i < cycle.suns_size(); ++i) {
            change.suns->push_back(
                SunFromProto(store_.Get(), cycle.suns(i), "suns[" + std::to_string(i) + "]"));
        }
    }
    return change;
}

Session::Solved Session::Solve(const v1::OutputRequest& outputs) const {
    const Scene& scene = store_.Get();
    std::vector<int> wanted;
    for (const std::string& band : outputs.bands()) {
        const int b = scene.BandIndex(band);
        if (b < 0)
            throw InputError(ErrorCode::kNotFound, "outputs.bands[" + band + "]",
                             "names no declared band");
        if (std::find(wanted.begin(), wanted.end(), b) != wanted.end()) {
            throw InputError(ErrorCode::kAlreadyExists, "outputs.bands[" + band + "]",
                             "is asked twice");
        }
        wanted.push_back(b);
    }
    if (wanted.empty()) {
        for (std::size_t b = 0; b < scene.bands.size(); ++b) wanted.push_back(static_cast<int>(b));
    }
    // Only the bands asked for are solved: the solver sees a scene of those alone.
    const bool allBands = wanted.size() == scene.bands.size();
    std::vector<int> order(wanted.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    const Scene subset = allBands ? Scene{} : WithBands(scene, wanted);
    const Scene& solved = allBands ? scene : subset;
    if (!allBands) wanted = order;
    const bool lightVectors = !outputs.has_light_vectors() || outputs.light_vectors();
    SolverSettings settings = solver_.settings;
    settings.hrc.lightVectors = lightVectors;
    // Its bands as the last cycle's: the iteration starts from their light.
    const bool warm = solver_.warmStart && allBands && settings.kind != SolverKind::kMonteCarlo;
    if (warm) settings.hrc.warmStart = warm_;
    Clock::time_point start = Clock::now();
    FlatScene flat = store_.Flat();
    CheckPeriodicTile(scene, flat, limits_);
    const PreparedScene prepared(solved, std::move(flat));  // the bands do not change the geometry
    spdlog::debug("scene flattened and its ray engine built in {:.1f} ms", Milliseconds(start));
    start = Clock::now();
    std::optional<InstancedStats> instanced;
    Solution solution;
    if (solver_.instanced) {
        InstancedOptions options = solver_.instanced->options;
        options.hrc = settings.hrc;
        options.hrc.directionalInstances = !solver_.instanced->singleValue;
        InstancedSolution run =
            SolveInstanced(solved, prepared.Flat(),
                           solver_.instanced->shadowsByGeometry ? &prepared.Rays() : nullptr,
                           solver_.instanced->policy, *solver_.database, options);
        solution = std::move(run.solution);
        instanced = std::move(run.stats);
    } else {
        solution = leaflux::Solve(prepared, settings);
    }
    spdlog::debug("solved in {:.1f} ms ({} organs from the last cycle's light)",
                  Milliseconds(start), solution.stats.warmOrgans);
    Solved out;
    if (warm) out.warm = std::make_shared<const WarmStart>(prepared.Flat().receivers, solution);
    v1::CycleResult& result = out.result;
    if (outputs.leaves()) {
        for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
            // Organs inside a structure solved whole have no light of their own.
            if (!solution.unsolved.empty() && solution.unsolved[r]) continue;
            const Receiver& receiver = prepared.Flat().receivers[r];
            v1::OrganLight* organ = result.add_organs();
            organ->set_node(receiver.node);
            organ->set_name(ReceiverName(solved, receiver));
            organ->set_area_m2(receiver.areaM2);
            BandsToProto(solved, solution.light[r], solution.ErrorOf(r), wanted, lightVectors,
                         organ->mutable_bands());
        }
    }
    if (outputs.structures()) {
        for (const StructureLight& s : AggregateStructures(solved, prepared.Flat(), solution)) {
            v1::StructureLight* structure = result.add_structures();
            structure->set_node(s.node);
            structure->set_name(s.name);
            structure->set_type(TypeToProto(s.type));
            structure->set_organs(s.organCount);
            structure->set_area_m2(s.areaM2);
            BandsToProto(solved, s.bands, s.errors, wanted, lightVectors,
                         structure->mutable_bands());
        }
    }
    v1::SolveStatistics* stats = result.mutable_statistics();
    stats->set_wall_seconds(solution.stats.wallSeconds);
    stats->set_cpu_seconds(solution.stats.cpuSeconds);
    stats->set_peak_rss_bytes(solution.stats.peakRssBytes);
    stats->set_rays(solution.stats.rays);
    stats->set_links(solution.stats.links);
    stats->set_elements(solution.stats.elements);
    stats->set_iterations(solution.stats.iterations);
    stats->set_residual(solution.stats.residual);
    stats->set_warm_organs(solution.stats.warmOrgans);
    stats->set_threads(solution.stats.threads);
    if (instanced) {
        int opened = 0;
        for (const InstancedStats::Depth& d : instanced->depths) opened += d.opened;
        stats->set_instances_opened(opened);
        stats->set_phase_functions_computed(instanced->originalsComputed);
        stats->set_phase_functions_reused(instanced->originalsReused);
        stats->set_phase_compute_seconds(instanced->originalSeconds);
        stats->set_phase_reuse_seconds(instanced->reuseSeconds);
        stats->set_solving_seconds(instanced->solveSeconds);
        stats->set_phase_db_health(solver_.database->Health());
    }
    for (int b : wanted) {
        v1::EnergyBalance* balance = stats->add_balance();
        balance->set_band(solved.bands[b].name);
        balance->set_incident_w(solution.balance[b].incidentW);
        balance->set_absorbed_w(solution.balance[b].absorbedW);
        balance->set_escaped_w(solution.balance[b].escapedW);
    }
    return out;
}

Daemon::Daemon(DaemonLimits limits, DaemonPhaseFunctions phase)
    : limits_(limits), phase_(std::move(phase)) {
    PhaseDatabaseOptions options = phase_.database;
    options.degradeToMemory = true;  // a daemon serves on without its file
    phaseDb_ = std::make_shared<PhaseDatabase>(options);
    if (phaseDb_->Persistent()) {  // else the database has logged why not
        spdlog::info("phase-function database {}", options.path);
    }
}

std::string Daemon::Handle(const std::string& bytes) {
    v1::Request request;
    v1::Reply reply;
    if (!request.ParseFromString(bytes)) {
        reply = ErrorReply(v1::ERROR_CODE_PARSE, "the message is not a leaflux.v1.Request");
    } else {
        reply = Handle(request);
    }
    std::string out;
    reply.SerializeToString(&out);
    return out;
}

std::string Daemon::KeyOf(const v1::Request& request) {
    switch (request.body_case()) {
        case v1::Request::kCycle:
            return request.cycle().session();
        case v1::Request::kResync:
            return request.resync().session();
        case v1::Request::kCloseSession:
            return request.close_session().session();
        case v1::Request::kRender:
            return request.render().session();
        default:
            return "";
    }
}

v1::Reply Daemon::Handle(const v1::Request& request) {
    ++requests_;
    const Clock::time_point start = Clock::now();
    v1::Reply reply;
    try {  // the one place a request's failure is caught
        if (request.version() > v1::PROTOCOL_VERSION_CURRENT) {
            throw InputError(ErrorCode::kUnsupported, "version",
                             "is newer than this daemon understands");
        }
        if (request.version() < v1::PROTOCOL_VERSION_CURRENT) {
            throw InputError(
                ErrorCode::kInvalidArgument, "version",
                "must be PROTOCOL_VERSION_CURRENT (1), got " + std::to_string(request.version()));
        }
        switch (request.body_case()) {
            case v1::Request::kOpenSession:
                reply = Open(request.open_session());
                break;
            case v1::Request::kCycle:
                reply = RunCycle(request.cycle());
                break;
            case v1::Request::kResync:
                reply = Resynchronise(request.resync());
                break;
            case v1::Request::kStatus:
                reply = Status(request.status());
                break;
            case v1::Request::kCloseSession:
                reply = Close(request.close_session());
                break;
            case v1::Request::kShutdown:
                shutdown_ = true;
                reply.mutable_done();
                break;
            case v1::Request::kRender:
                reply = Draw(request.render());
                break;
            default:
                reply =
                    ErrorReply(v1::ERROR_CODE_UNSUPPORTED, "the request has no known body", "body");
        }
    } catch (const InputError& e) {
        reply = ErrorReply(ToProto(e.Code()), e.what(), e.Field(), e.Node().value_or(0));
    } catch (const TooLarge& e) {
        reply = ErrorReply(v1::ERROR_CODE_TOO_LARGE, e.what(), e.Field());
    } catch (const UnknownSession& e) {
        reply = ErrorReply(v1::ERROR_CODE_UNKNOWN_SESSION, e.what(), "session");
    } catch (const std::exception& e) {
        spdlog::error("request {}: internal error: {}", request.request_id(), e.what());
        reply = ErrorReply(v1::ERROR_CODE_INTERNAL, e.what());
    }
    reply.set_version(v1::PROTOCOL_VERSION_CURRENT);
    reply.set_request_id(request.request_id());
    // Status is polled: its timing only at debug level.
    const auto level = reply.has_error()                             ? spdlog::level::warn
                       : request.body_case() == v1::Request::kStatus ? spdlog::level::debug
                                                                     : spdlog::level::info;
    if (spdlog::should_log(level)) {
        const std::string outcome =
            reply.has_error()
                ? fmt::format(
                      "{} ({}{})", v1::ErrorCode_Name(reply.error().code()), reply.error().field(),
                      reply.error().node() ? ", node " + std::to_string(reply.error().node()) : "")
                : "done";
        spdlog::log(level, "request {}: {}: {} in {:.2f} ms", request.request_id(),
                    Describe(request), outcome, Milliseconds(start));
    }
    return reply;
}

SessionSolver Daemon::Settings(const v1::SolverSettings& in, const std::string& species) const {
    SessionSolver solver;
    SolverSettings& settings = solver.settings;
    settings = SettingsFromProto(in);
    if (limits_.solverThreads > 0) {
        int& threads = settings.hrc.threads;
        threads = threads == 0 ? limits_.solverThreads : std::min(threads, limits_.solverThreads);
        settings.monteCarlo.threads = threads;
    }
    solver.warmStart = in.warm_start();
    if (in.solver() == v1::SOLVER_KIND_INSTANCED) {
        solver.instanced = InstancedRunFromProto(in.instanced(), species, phase_.policyDir);
        solver.database = phaseDb_;
    } else if (in.has_instanced()) {
        throw InputError(ErrorCode::kInvalidArgument, "settings.instanced",
                         "is for SOLVER_KIND_INSTANCED alone");
    }
    return solver;
}

std::shared_ptr<Session> Daemon::Find(const std::string& id) {
    std::lock_guard lock(mutex_);
    const auto it = sessions_.find(id);
    if (it == sessions_.end())
        throw UnknownSession("unknown session '" + id + "': open or resync it");
    return it->second;
}

v1::Reply Daemon::Open(const v1::OpenSession& request) {
    if (request.scene().imports_size() > 0 || request.scene().can_lights_size() > 0) {
        throw InputError(ErrorCode::kUnsupported, "scene.imports",
                         "the daemon reads no files: send the geometry");
    }
    Scene scene = FromProto(request.scene(), "", limits_.scene);
    SessionSolver solver = Settings(request.settings(), request.species());
    const std::string described = DescribeSolver(solver);
    auto session = std::make_shared<Session>(std::move(scene), MeshesFromProto(request.scene()),
                                             std::move(solver), limits_.scene);
    std::string id;
    {
        std::lock_guard lock(mutex_);
        if (sessions_.size() >= limits_.maxSessions) {
            throw InputError(
                ErrorCode::kInvalidArgument, "open_session",
                "the daemon serves at most " + std::to_string(limits_.maxSessions) + " sessions");
        }
        // Never an id in use (one a Resync brought back, say): an open never replaces.
        do {
            id = NewSessionId();
        } while (sessions_.count(id));
        sessions_.emplace(id, std::move(session));
    }
    spdlog::info("session {} opened{}", id, described);
    v1::Reply reply;
    reply.mutable_opened()->set_session(id);
    return reply;
}

v1::Reply Daemon::RunCycle(const v1::Cycle& request) {
    const std::shared_ptr<Session> session = Find(request.session());
    v1::Reply reply;
    *reply.mutable_cycle() = session->Run(request);
    reply.mutable_cycle()->set_session(request.session());
    reply.mutable_cycle()->set_number(request.number());
    return reply;
}

v1::Reply Daemon::Draw(const v1::RenderRequest& request) {
    const std::shared_ptr<Session> session = Find(request.session());
    v1::Reply reply;
    *reply.mutable_picture() = session->Render(request);
    return reply;
}

v1::Reply Daemon::Resynchronise(const v1::Resync& request) {
    if (request.session().empty())
        throw InputError(ErrorCode::kInvalidArgument, "session", "is empty");
    if (!IsSessionId(request.session())) {
        throw InputError(ErrorCode::kInvalidArgument, "session",
                         "is not an id this daemon issues (32 lowercase hexadecimal digits)");
    }
    if (request.last_cycle() < 0)
        throw InputError(ErrorCode::kInvalidArgument, "last_cycle", "is negative");
    if (request.scene().imports_size() > 0 || request.scene().can_lights_size() > 0) {
        throw InputError(ErrorCode::kUnsupported, "scene.imports",
                         "the daemon reads no files: send the geometry");
    }
    Scene scene = FromProto(request.scene(), "", limits_.scene);
    SessionSolver solver = Settings(request.settings(), request.species());
    auto session =
        std::make_shared<Session>(std::move(scene), MeshesFromProto(request.scene()),
                                  std::move(solver), limits_.scene, request.last_cycle());
    {
        std::lock_guard lock(mutex_);
        if (!sessions_.count(request.session()) && sessions_.size() >= limits_.maxSessions) {
            throw InputError(
                ErrorCode::kInvalidArgument, "resync",
                "the daemon serves at most " + std::to_string(limits_.maxSessions) + " sessions");
        }
        sessions_[request.session()] = std::move(session);
    }
    spdlog::info("session {} resynchronised", request.session());
    v1::Reply reply;
    reply.mutable_opened()->set_session(request.session());
    return reply;
}

v1::Reply Daemon::Status(const v1::StatusRequest& request) {
    v1::Reply reply;
    v1::StatusReply* status = reply.mutable_status();
    status->set_requests(requests_);
    status->set_max_message_bytes(static_cast<std::int64_t>(limits_.maxMessageBytes));
    {
        const PhaseDatabaseStats db = phaseDb_->Stats();
        v1::PhaseDatabaseStatus* out = status->mutable_phase_db();
        out->set_path(phase_.database.path);
        out->set_persistent(db.persistent);
        out->set_health(db.health);
        out->set_memory_entries(db.memoryEntries);
        out->set_memory_bytes(db.memoryBytes);
        out->set_memory_cap_mb(phase_.database.memoryCapMb);
        out->set_computed(db.computed);
        out->set_reused(db.memoryHits + db.diskHits + db.awaited);
        out->set_stored(db.stored);
    }
    std::lock_guard lock(mutex_);  // counts only: never waits for a solve
    status->set_session_count(static_cast<int>(sessions_.size()));
    if (request.session().empty()) return reply;  // ids are credentials: none is listed
    const auto it = sessions_.find(request.session());
    if (it == sessions_.end()) {
        throw UnknownSession("unknown session '" + request.session() + "': open or resync it");
    }
    v1::SessionStatus* s = status->add_sessions();
    s->set_session(it->first);
    s->set_cycles(it->second->Cycles());
    s->set_last_cycle(it->second->LastCycle());
    s->set_nodes(it->second->Nodes());
    s->set_organs(it->second->Organs());
    return reply;
}

v1::Reply Daemon::Close(const v1::CloseSession& request) {
    std::lock_guard lock(mutex_);
    if (!sessions_.erase(request.session())) {
        throw UnknownSession("unknown session '" + request.session() + "': nothing to close");
    }
    v1::Reply reply;
    reply.mutable_done();
    return reply;
}

std::string NewSessionId() {
    // std::random_device reads the kernel's generator (/dev/urandom, getrandom).
    thread_local std::random_device device;
    std::string id;
    for (int i = 0; i < 4; ++i) id += fmt::format("{:08x}", static_cast<std::uint32_t>(device()));
    return id;
}

bool IsSessionId(const std::string& id) {
    return id.size() == 32 && std::all_of(id.begin(), id.end(), [](char c) {
               return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
           });
}

std::string TooLargeReply(std::size_t bytes, std::size_t frames, const std::string& head,
                          std::size_t limitBytes) {
    // Fields 1 (version) and 2 (request_id) come first in a serialised Request.
    std::uint64_t requestId = 0;
    google::protobuf::io::CodedInputStream in(reinterpret_cast<const std::uint8_t*>(head.data()),
                                              static_cast<int>(head.size()));
    for (std::uint32_t tag; (tag = in.ReadTag()) != 0;) {
        std::uint64_t value = 0;
        if ((tag & 7) != 0 || !in.ReadVarint64(&value)) break;  // not a varint
        if (tag >> 3 == 2) {
            requestId = value;
            break;
        }
        if (tag >> 3 != 1) break;
    }
    v1::Reply reply = ErrorReply(
        v1::ERROR_CODE_TOO_LARGE,
        fmt::format("the message of {} bytes in {} frames exceeds the daemon's limit of {} bytes "
                    "(--max-message-mb) or of frames",
                    bytes, frames, limitBytes));
    reply.set_request_id(requestId);
    return reply.SerializeAsString();
}

struct DaemonDispatcher::Pending {
    Respond respond;
    std::uint64_t requestId = 0;
    std::atomic<bool> answered{false};  // whoever sets it first answers
};

struct DaemonDispatcher::InFlight {
    void Finish(const std::shared_ptr<Pending>& request, std::string reply) {
        if (!request->answered.exchange(true)) request->respond(std::move(reply));
        std::lock_guard lock(mutex);
        pending.erase(request);
    }

    std::mutex mutex;
    std::set<std::shared_ptr<Pending>> pending;
};

DaemonDispatcher::DaemonDispatcher(Daemon& daemon, KeyedExecutor& executor)
    : daemon_(daemon), executor_(executor), inFlight_(std::make_shared<InFlight>()) {}

namespace {

std::string ShuttingDown(std::uint64_t requestId, const std::string& why) {
    v1::Reply reply = ErrorReply(v1::ERROR_CODE_SHUTTING_DOWN, why);
    reply.set_request_id(requestId);
    return reply.SerializeAsString();
}

}  // namespace

void DaemonDispatcher::operator()(std::string payload, Respond respond) {
    auto request = std::make_shared<v1::Request>();
    if (!request->ParseFromString(payload)) {
        std::string out;
        ErrorReply(v1::ERROR_CODE_PARSE, "the message is not a leaflux.v1.Request")
            .SerializeToString(&out);
        respond(std::move(out));
        return;
    }
    if (stopping_) {
        respond(ShuttingDown(request->request_id(), "the daemon is stopping: not run"));
        return;
    }
    if (request->body_case() == v1::Request::kStatus) {  // counts only: never behind a solve
        respond(daemon_.Handle(*request).SerializeAsString());
        return;
    }
    auto pending = std::make_shared<Pending>();
    pending->respond = std::move(respond);
    pending->requestId = request->request_id();
    {
        std::lock_guard lock(inFlight_->mutex);
        inFlight_->pending.insert(pending);
    }
    executor_.Submit(
        Daemon::KeyOf(*request),
        [&daemon = daemon_, inFlight = inFlight_, request, pending] {
            inFlight->Finish(pending, daemon.Handle(*request).SerializeAsString());
        },
        [inFlight = inFlight_, pending] {
            inFlight->Finish(pending,
                             ShuttingDown(pending->requestId, "the daemon is stopping: not run"));
        });
}

void DaemonDispatcher::StopTaking() {
    stopping_ = true;
    executor_.CancelQueued();
}

std::size_t DaemonDispatcher::Running() const {
    std::lock_guard lock(inFlight_->mutex);
    return inFlight_->pending.size();
}

void DaemonDispatcher::AbandonRunning() {
    std::set<std::shared_ptr<Pending>> running;
    {
        std::lock_guard lock(inFlight_->mutex);
        running = inFlight_->pending;
    }
    for (const std::shared_ptr<Pending>& pending : running) {
        if (!pending->answered.exchange(true)) {
            pending->respond(ShuttingDown(
                pending->requestId,
                "the daemon stopped before this request's solve ended (--grace-seconds): "
                "nothing of it was kept"));
        }
    }
}

std::function<void(std::string, std::function<void(std::string)>)> DaemonDispatch(
    Daemon& daemon, KeyedExecutor& executor) {
    auto dispatcher = std::make_shared<DaemonDispatcher>(daemon, executor);
    return [dispatcher](std::string payload, std::function<void(std::string)> respond) {
        (*dispatcher)(std::move(payload), std::move(respond));
    };
}

}  // namespace leaflux
