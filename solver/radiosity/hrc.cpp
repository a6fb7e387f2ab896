// The whole-scene driver of the radiosity engine (hrc.h): the scene's hierarchy, the
// directional sources linked to its root, a self-link on the root, then refine–solve
// passes until no link needs refining.
#include "solver/radiosity/hrc.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "solver/radiosity/beams.h"
#include "solver/radiosity/closed_scattering.h"
#include "solver/radiosity/estimate.h"
#include "solver/radiosity/exposure.h"
#include "solver/radiosity/gathering.h"
#include "solver/radiosity/hierarchy.h"
#include "solver/radiosity/link_audit.h"
#include "solver/radiosity/node_model.h"
#include "solver/radiosity/outputs.h"
#include "solver/radiosity/push_pull.h"
#include "solver/radiosity/refinement.h"
#include "solver/radiosity/traversal.h"
#include "solver/radiosity/visibility.h"
#include "solver/util/check.h"
#include "solver/util/cores.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// Refine–solve passes after the first solution, and the Jacobi sweeps of each pass but the
// last.
constexpr int kRefinementPasses = 3;
constexpr int kSweepsBeforeRerefining = 30;
// The largest ρ + τ the scattered light's bound takes (ExposureNeeded): 20 times what one
// gather finds.
constexpr double kMostAlbedo = 0.95;

// The parts of the solve's progress (HrcOptions::progress) its stages take, from their
// times at ε = 1e-4 (`SPDLOG_LEVEL=debug leaflux solve --solver hrc`): on the 10k tree
// (`leaflux generate --leaves 10000`) the hierarchy and exposure take 5 %, the source
// links 15 %, the self refinement 51 %, the passes 25 % and the outputs 4 %; on the
// 500-leaf canopy (`--random-canopy`) 5, 16, 43, 34 and 2 %.
struct Stage {
    double from, to;
};
constexpr Stage kExposureStage{0.0, 0.05}, kSourceStage{0.05, 0.2}, kSelfStage{0.2, 0.67},
    kPassesStage{0.67, 0.97}, kOutputsStage{0.97, 1.0};

class SceneSolve {
  public:
    // The scene's suns and sky cones, a channel per band.
    SceneSolve(const Scene& scene, const FlatScene& flat, const RayScene& rays,
               const HrcOptions& options, std::span<const ClosedNode> closed)
        : SceneSolve(scene, flat, rays, options, closed,
                     {static_cast<int>(scene.bands.size()), 1, ChannelMeasure::kSum},
                     BeamsOf(scene, options.skyCones)) {}
    // Given channels and sources (UnitBeams), and for a level of instantiation its occlusion
    // and threshold (LevelProblem).
    SceneSolve(const Scene& scene, const FlatScene& flat, const RayScene& rays,
               const HrcOptions& options, std::span<const ClosedNode> closed,
               const Channels& channels, std::vector<DirectionalSource> sources,
               const LevelProblem& level = {})
        : scene_(scene),
          flat_(flat),
          rays_(rays),
          options_(options),
          channels_(channels),
          hierarchy_(scene, flat, closed),
          model_(hierarchy_, scene, rays, DirectionSet::OfLevel(options.directionLevel), channels_,
                 options.maxSubdivision),
          field_(channels_, model_.BinCount()),
          gathered_(channels_, model_.BinCount()),
          sourceLight_(channels_),
          leafLight_(channels_),
          optics_(scene, flat, channels_),
          sources_(std::move(sources)),
          closedLight_(channels_, model_.BinCount(), closed.size(), sources_.size()),
          ownOcclusion_(level.occlusion ? nullptr
                                        : std::make_unique<Occlusion>(rays, ProxiesOf(closed))),
          occlusion_(level.occlusion ? *level.occlusion : *ownOcclusion_),
          level_(level),
          // The whole scene's maps; none with closed instances, whose τ no map holds.
          sunMaps_(level.occlusion || !closed.empty() ? SunMaps{} : DrawSuns(flat, rays, sources_)),
          estimator_(model_, field_),
          visibility_(model_, field_, occlusion_, options.visibilityRays, options.sourceRays,
                      sources_, sunMaps_.maps.empty() ? nullptr : &sunMaps_),
          pushPull_(model_, traversal_, exposure_) {
        field_.Resize(hierarchy_.Size());
        field_.intensity.Assign(model_.SlotCount());
        HoldClosed(model_, field_);
        links_.Resize(hierarchy_.Size());
    }

    // The clock started before the hierarchy was built: its time is the solve's.
    Solution Run(const ResourceClock& clock) {
        Solution solution;
        solution.light.assign(flat_.receivers.size(), channels_.bands);
        solution.balance.assign(channels_.bands, EnergyBalance{});
        const int threads = CoresOf(options_.threads);
        if (hierarchy_.Root() != kNoNode) OnCores(threads, [&] { Solve(solution); });
        clock.Stamp(solution.stats);
        solution.stats.threads = threads;
        solution.stats.rays = rays();
        return solution;
    }

    // After Run: the subtree under scene node `root` solved again alone, as a local problem
    // (hrc.h, SolveHrcThenLocal).
    Solution RunLocal(NodeId root);
    // After Run under unit beams: the leaf patches and their radiosity.
    void Patches(BeamSolution& beams) const;
    // After Run: what arrived on each closed instance, and the threshold the links took.
    void Arrived(LevelSolution& level) const;
    // Of that, per closed instance, what the links from surfaces brought.
    std::vector<std::vector<double>> SurfaceBins() const;
    // With LevelProblem::holdLevel: the organs' triangles as solved, into level.surfaces.
    void HandOnOrgans(LevelSolution& level) const;

  private:
    void Solve(Solution& solution);
    // After refinement changed the hierarchy: the traversal and the per-node tables.
    void Index();
    // The parts of a node just split take what it kept of the first arrival and, after the
    // sources were pushed, their light (they have no source links of their own and n's
    // normal).
    void OnSplit(std::uint32_t n);
    // The fraction `done` of a stage, to HrcOptions::progress; never backwards.
    void Report(Stage stage, double done) {
        if (!options_.progress) return;
        const double whole = stage.from + (stage.to - stage.from) * std::clamp(done, 0.0, 1.0);
        if (whole <= progress_) return;
        progress_ = whole;
        options_.progress(whole);
    }
    Refiner::ProgressHook StageHook(Stage stage) {
        if (!options_.progress) return {};
        return [this, stage](double done) { Report(stage, done); };
    }
    template <bool kDirections>
    void Collect() {
        Gather<kDirections>(model_, field_, *active_, traversal_.Receivers(), gathered_);
        pushPull_.PushDown<kDirections>(*active_, gathered_, sourceLight_, leafLight_, Closed());
    }
    // Whether it holds surfaces or closed instances from outside (a local problem's).
    bool HoldsOutside() const {
        return std::any_of(flat_.receivers.begin(), flat_.receivers.end(),
                           [](const Receiver& r) { return r.kind == ReceiverKind::kHeld; }) ||
               std::any_of(hierarchy_.Closed().begin(), hierarchy_.Closed().end(),
                           [](const ClosedNode& c) { return c.Held(); });
    }
    // Direct light first, so that links are refined on what senders will send: the sources
    // pushed down, one update and a pull-up (from a warm start, the light it had).
    void LightFromSources() {
        pushPull_.PushSources(*active_, sources_, sourceLight_, Closed());
        if (!options_.directOnly) {
            pushPull_.PushDown<false>(*active_, gathered_, sourceLight_, leafLight_, Closed());
            WarmLeaves();
            Update();
        }
        pushPull_.PullUp(field_);
    }
    // The leaf patches of the organs HrcOptions::warmStart has: on the first arrival they
    // hold, the light scattered onto their organ there (WarmStart::Apply). Returns how
    // many organs it had.
    std::int64_t WarmLeaves();
    // After refinement, the clusters whose children take their share of the light they hand
    // down by exposure: those that hand down more than a link into them may carry
    // (Refiner::Threshold), as one gather from the direct light's radiosity finds it, times
    // 1 / (1 − a) for the light scattered on, a the largest ρ + τ of the scene's optics.
    std::vector<std::uint8_t> ExposureNeeded();
    // Jacobi from the emission, then refine–solve passes until no link needs refining.
    void Iterate(Refiner& refiner, Solution& solution, Stopwatch& clock);
    // At the scene's top, on the first arrival (the lamps' light: the suns' and sky's reach
    // the closed instances by their own links, counted where those are opened or solved
    // whole): what the closed instances intercept of it.
    void ClosedLampIncident() {
        if (Closed() && !HoldsOutside() && !occlusion_.HasOutside())
            closedLampIncident_ = InterceptedByClosed(model_, closedLight_);
    }
    ClosedLight* Closed() { return hierarchy_.Closed().empty() ? nullptr : &closedLight_; }
    // The radiosity of the leaf patches and the light the closed instances send, from what
    // arrived: the largest change over the largest value.
    double Update() {
        double residual =
            UpdateRadiosity(hierarchy_, traversal_.Leaves(), optics_, leafLight_, field_);
        if (Closed()) {
            if (!closedResponse_) closedResponse_.emplace(model_, sources_);
            residual =
                std::max(residual, ScatterClosed(model_, sources_, *closedResponse_, closedLight_,
                                                 options_.directionalInstances, field_));
        }
        return residual;
    }
    static std::vector<ClosedProxy> ProxiesOf(std::span<const ClosedNode> closed) {
        std::vector<ClosedProxy> proxies;
        for (const ClosedNode& node : closed) proxies.push_back(node.Proxy());
        return proxies;
    }
    void Outputs(Solution& solution);
    // Σ A |n · ω| over the organs' triangles and the closed instances (the whole
    // hierarchy's when there are none), or LevelProblem::organsProjectedArea.
    double OrgansProjectedArea(const glm::dvec3& omega) const {
        if (level_.organsProjectedArea) {
            if (const double area = level_.organsProjectedArea(omega); area > 0.0) return area;
        }
        double area = 0.0;
        bool organs = false;
        for (const Triangle& t : flat_.triangles) {
            if (flat_.receivers[t.receiver].kind != ReceiverKind::kOrgan) continue;
            organs = true;
            area += t.areaM2 * std::abs(glm::dot(t.normal, omega));
        }
        for (std::size_t n = 0; n < hierarchy_.Size(); ++n) {
            if (hierarchy_[n].closed < 0 || model_.Held(static_cast<std::uint32_t>(n))) continue;
            organs = true;
            area += model_.ProjectedArea(static_cast<std::uint32_t>(n), omega);
        }
        return organs ? area : model_.ProjectedArea(hierarchy_.Root(), omega);
    }
    std::int64_t rays() const {
        return rayCount_ + exposure_.Rays() + (refiner_ ? refiner_->Rays() : 0);
    }

    const Scene& scene_;
    const FlatScene& flat_;
    const RayScene& rays_;
    const HrcOptions& options_;
    const Channels channels_;
    Hierarchy hierarchy_;
    NodeModel model_;
    Field field_;
    Gathered gathered_;
    SourceLight sourceLight_;
    LeafLight leafLight_;
    const ReceiverOptics optics_;
    const std::vector<DirectionalSource> sources_;
    ClosedLight closedLight_;
    // At the scene's top: per channel, the lamps' light the closed instances intercepted on
    // its first arrival (ClosedLampIncident), incident light no level counts otherwise.
    std::vector<double> closedLampIncident_;
    std::optional<ClosedResponse> closedResponse_;  // made on the first update
    const std::unique_ptr<const Occlusion> ownOcclusion_;
    const Occlusion& occlusion_;
    const LevelProblem level_;  // its sources moved into sources_
    Links links_;
    Traversal traversal_;
    Exposure exposure_;
    const SunMaps sunMaps_;  // of a whole scene's suns over its triangles (DrawSuns)
    const Estimator estimator_;
    const LinkVisibility visibility_;
    PushPull pushPull_;
    std::optional<Refiner> refiner_;
    Thresholds thresholds_;
    // The links the sweeps take and the root they run under: the scene's, or a local
    // problem's.
    Links* active_ = &links_;
    std::uint32_t activeRoot_ = kNoNode;
    std::int64_t rayCount_ = 0;  // besides exposure's and refinement's
    double progress_ = 0.0;      // reported so far
};

void SceneSolve::Index() {
    traversal_.Index(hierarchy_, activeRoot_, *active_);
    // At the cost of the nodes under the root. Gathering rewrites only nodes with links: a
    // node whose links refinement moved to its children must hand down nothing.
    const std::size_t size = hierarchy_.Size();
    gathered_.bins.Resize(model_.SlotCount());
    gathered_.sides.Resize(size);
    gathered_.integral.Resize(size);
    gathered_.moment.Resize(size);
    leafLight_.Resize(size);
    leafLight_.emission.Resize(size);
    for (std::uint32_t n : traversal_.PreOrder()) {
        gathered_.sides.ClearRow(n);
        gathered_.integral.ClearRow(n);
        gathered_.moment.ClearRow(n);
        const HrcNode& node = hierarchy_[n];
        if (!node.patch) {
            if (model_.Slot(n) != kNoNode) gathered_.bins.ClearRow(model_.Slot(n));
            continue;
        }
        const Receiver& receiver = flat_.receivers[node.receiver];
        if (receiver.kind != ReceiverKind::kEmitter && receiver.kind != ReceiverKind::kHeld)
            continue;
        const Emitter& emitter = scene_.sources.emitters[receiver.declared];
        const std::size_t t = node.triangle - receiver.firstTriangle;
        for (int b = 0; b < channels_.bands; ++b)
            leafLight_.emission[n][b] = emitter.Exitance(t, b);
    }
}

void SceneSolve::OnSplit(std::uint32_t n) {
    const std::size_t size = hierarchy_.Size();
    if (n < leafLight_.direct.Rows()) {  // after the first sweep: the parts keep the first arrival
        leafLight_.direct.Resize(size);
        for (std::uint32_t child : hierarchy_[n].children) leafLight_.direct.CopyRow(child, n);
    }
    if (n < sourceLight_.sides.Rows()) {
        sourceLight_.sides.Resize(size);
        sourceLight_.integral.Resize(size);
        sourceLight_.moment.Resize(size);
        sourceLight_.incident.Resize(size);
        for (std::uint32_t child : hierarchy_[n].children) {
            sourceLight_.sides.CopyRow(child, n);
            sourceLight_.incident.CopyRow(child, n);
            sourceLight_.integral.CopyRow(child, n);
            sourceLight_.moment.CopyRow(child, n);
        }
    }
}

void SceneSolve::Solve(Solution& solution) {
    activeRoot_ = hierarchy_.Root();
    Index();
    Report(kExposureStage, 1.0);
    const auto& preOrder = traversal_.PreOrder();
    for (std::uint32_t n : preOrder)
        std::copy_n(leafLight_.emission[n], channels_.Count(), field_.radiosity(n, kUpper));
    // The scale of every link's error: the power the suns and sky cones bring onto the
    // organs, unoccluded, and the lamps' power. On the organs, not the scene: a leaf's
    // accuracy must not depend on how large a ground or a room is around it (a 200 m
    // ground took 40,000 times the canopy's power, and no link between leaves was ever
    // refined). A scene without organs takes its whole geometry's.
    const bool perBeam = channels_.measure == ChannelMeasure::kWorstBeam && channels_.beams > 1;
    double totalPower = 0.0;
    for (const DirectionalSource& source : sources_) {
        const double power =
            channels_.Measure(source.normalIrradiance.data()) * OrgansProjectedArea(source.toward);
        // Under unit beams each beam is a scene of its own: the scale is the brightest's.
        totalPower = perBeam ? std::max(totalPower, power) : totalPower + power;
    }
    for (std::uint32_t n : preOrder) {
        for (int b = 0; b < channels_.Count(); ++b)
            totalPower += leafLight_.emission[n][b] * hierarchy_[n].areaM2;
    }
    if (totalPower <= 0.0) {
        Outputs(solution);
        return Report(kOutputsStage, 1.0);
    }

    thresholds_ = {options_.epsilon * totalPower, options_.clusterTolerance,
                   perBeam ? std::size_t{1} : sources_.size()};
    if (level_.errorW > 0.0) {  // a level under the top one: the top's threshold
        thresholds_.errorW = level_.errorW;
        thresholds_.sourceCount = std::max<std::size_t>(1, level_.sourceCount);
    }
    refiner_.emplace(model_, field_, links_, estimator_, visibility_, sources_, thresholds_,
                     [this](std::uint32_t n) { OnSplit(n); });
    Refiner& refiner = *refiner_;
    Stopwatch clock;
    std::vector<Task> sourceTasks;
    for (std::uint32_t s = sources_.size(); s-- > 0;) {
        sourceTasks.push_back({Task::kSource, hierarchy_.Root(), s});
    }
    refiner.OnProgress(StageHook(kSourceStage));
    refiner.Refine(std::move(sourceTasks));
    // With direct light only, lamps are the only senders and their links the only ones
    // needed.
    Index();
    LightFromSources();
    const double sourceSeconds = clock.Lap();
    const std::int64_t sourceRays = rays();
    const bool lamps = std::any_of(preOrder.begin(), preOrder.end(), [&](std::uint32_t n) {
        const double* e = leafLight_.emission[n];
        return std::any_of(e, e + channels_.Count(), [](double v) { return v > 0.0; });
    });
    refiner.OnProgress(StageHook(kSelfStage));
    if (!options_.directOnly || lamps)
        refiner.Refine({{Task::kSelf, hierarchy_.Root(), hierarchy_.Root()}});
    Report(kSelfStage, 1.0);
    Index();
    // Under unit beams (a phase function, stored for reuse), every cluster takes it.
    if (channels_.measure == ChannelMeasure::kWorstBeam) {
        exposure_ = Exposure(model_, rays_, options_.exposureRays);
    } else if (options_.exposureRays > 0) {
        const std::vector<std::uint8_t> needed = ExposureNeeded();
        exposure_ = Exposure(model_, rays_, options_.exposureRays, &needed);
    }
    const double refineSeconds = clock.Lap();
    const std::int64_t refineRays = rays() - sourceRays;

    Iterate(refiner, solution, clock);
    if (options_.auditLinks) {
        solution.linkAudit = AuditLinks(model_, rays_, traversal_.Leaves(), field_, links_,
                                        sourceLight_, leafLight_, [this] { Collect<false>(); });
    }
    const std::int64_t passRays = rays() - sourceRays - refineRays;
    Outputs(solution);
    Report(kOutputsStage, 1.0);
    spdlog::debug(
        "hrc: source links {:.3f} s ({} rays), refinement {:.3f} s ({} rays, {} more in the "
        "passes), outputs {:.3f} s ({} rays)",
        sourceSeconds, sourceRays, refineSeconds, refineRays, passRays, clock.Lap(),
        rays() - sourceRays - refineRays - passRays);
}

std::vector<std::uint8_t> SceneSolve::ExposureNeeded() {
    double albedo = 0.0;
    for (const Optics& optics : scene_.optics) {
        for (const BandOptics& b : optics.bands)
            albedo =
                std::max({albedo, b.rhoUpper + b.tauUpperToLower, b.rhoLower + b.tauLowerToUpper});
    }
    Gather<false>(model_, field_, *active_, traversal_.Receivers(), gathered_);
    return ExposedClusters(model_, traversal_.PreOrder(), *active_, gathered_,
                           1.0 / (1.0 - std::min(albedo, kMostAlbedo)), [&](std::uint32_t n) {
                               return model_.Importance(n) * thresholds_.errorW *
                                      thresholds_.clusterTolerance;
                           });
}

std::int64_t SceneSolve::WarmLeaves() {
    const WarmStart* warm = options_.warmStart.get();
    if (warm == nullptr || options_.directOnly || channels_.beams != 1 ||
        warm->Bands() != channels_.bands)
        return 0;
    return warm->Apply(hierarchy_, flat_.receivers, traversal_.Leaves(), leafLight_.irradiance);
}

void SceneSolve::Iterate(Refiner& refiner, Solution& solution, Stopwatch& clock) {
    // Jacobi from the emission: the first sweep's light is the direct light. Then the links
    // are judged again with the light of the solution and the iteration goes on from it,
    // until no link needs refining (a pass or two).
    for (std::uint32_t n : traversal_.PreOrder()) {
        field_.radiosity.ClearRow(n);
        std::copy_n(leafLight_.emission[n], channels_.Count(), field_.radiosity(n, kUpper));
    }
    // A closed instance sends only what it scatters (its light is not pulled up from
    // parts): dark too, or the first sweep's light, the level's incident light in its
    // energy balance, would hold what it scattered of the light from the sources. At the
    // top of the 10,000-leaf tree, instanced, the incident NIR was 2.7 % over HRC's.
    DarkenClosed(model_, field_);
    pushPull_.PullUp(field_);
    double residual = 0.0;
    int iteration = 0;
    const int iterations = options_.directOnly ? 1 : options_.maxIterations;
    bool settled = false;
    Convergence convergence;
    for (int pass = 0;; ++pass) {
        const bool last = options_.directOnly || settled || pass == kRefinementPasses;
        // Light to 10 % is all that judging the links again needs: the 500-leaf canopy and
        // the 10k tree come out as accurate as with 1 %.
        const double tolerance = last ? options_.tolerance : std::max(options_.tolerance, 0.1);
        // The passes' stage in equal parts, the last pass's from where this one starts;
        // of each part, the sweeps the first 60 % and judging the links again the rest.
        const double width = (kPassesStage.to - kPassesStage.from) / (kRefinementPasses + 1);
        const Stage part{std::max(progress_, kPassesStage.from + pass * width),
                         last ? kPassesStage.to : kPassesStage.from + (pass + 1) * width};
        const Stage sweeps{part.from, part.from + (last ? 1.0 : 0.6) * (part.to - part.from)};
        const Stage judging{sweeps.to, part.to};
        convergence = Convergence{};
        int sweep = 0;
        for (; iteration < iterations; ++iteration, ++sweep) {
            if (options_.directOnly) {
                Collect<true>();  // the one sweep: its light is the answer
            } else {
                Collect<false>();
            }
            std::int64_t warmed = 0;
            if (iteration == 0) {
                leafLight_.direct = leafLight_.irradiance;
                // Light that arrived on an opened instance from the rest of the scene, or
                // that what it holds from there sends, was incident there already: its
                // balance counts the suns' and sky's alone.
                if (HoldsOutside() ||
                    std::any_of(sources_.begin(), sources_.end(),
                                [](const DirectionalSource& s) { return !s.incident; }))
                    leafLight_.direct = sourceLight_.incident;
                ClosedLampIncident();
                warmed = WarmLeaves();
                solution.stats.warmOrgans = warmed;
            }
            residual = options_.directOnly ? UpdateRadiosity(hierarchy_, traversal_.Leaves(),
                                                             optics_, leafLight_, field_)
                                           : Update();
            if (warmed > 0) {
                // The jump to the warm start is no step of the geometric series of changes
                // that the convergence extrapolates.
                pushPull_.PullUp(field_);
                continue;
            }
            if (const double factor = convergence.Step(residual); factor > 0.0) {
                Extrapolate(traversal_.Leaves(), leafLight_, factor, field_);
                ++solution.stats.extrapolations;
            }
            pushPull_.PullUp(field_);
            const double remaining = convergence.Remaining(residual);
            if (remaining > 0.0 && remaining < 1.0)  // log of the change's fall to its goal
                Report(sweeps, std::log(remaining) / std::log(tolerance));
            if (remaining <= tolerance || (!last && sweep == kSweepsBeforeRerefining)) break;
        }
        const double sweepSeconds = clock.Lap();
        if (last) {
            spdlog::debug("hrc: pass {}: {} sweeps {:.3f} s", pass, sweep + 1, sweepSeconds);
            break;
        }
        refiner.OnProgress(StageHook(judging));
        settled = !refiner.Rerefine();
        if (!settled) Index();
        spdlog::debug("hrc: pass {}: {} sweeps {:.3f} s, links judged again {:.3f} s", pass,
                      sweep + 1, sweepSeconds, clock.Lap());
        ++iteration;
    }
    // The last light, with its vectors when they are wanted, from the solution's radiosity.
    if (options_.lightVectors && !options_.directOnly) {
        Collect<true>();
    } else if (!options_.directOnly) {
        Collect<false>();
    }
    solution.stats.iterations = std::min(iteration + 1, iterations);
    solution.stats.residual = convergence.Remaining(residual);
}

Solution SceneSolve::RunLocal(NodeId root) {
    const std::uint32_t b = hierarchy_.NodeOf(root);
    if (b == kNoNode)
        throw InputError(ErrorCode::kNotFound, "root", "names no structure with organs", root);
    LEAFLUX_CHECK(refiner_ && hierarchy_.Closed().empty());
    const ResourceClock clock;
    Solution solution;
    solution.light.assign(flat_.receivers.size(), channels_.bands);
    solution.balance.assign(channels_.bands, EnergyBalance{});
    const int threads = CoresOf(options_.threads);
    OnCores(threads, [&] {
        // The light from outside, held fixed: the links from senders outside the subtree
        // into it (their senders never split nor updated), the source links into it, and
        // what b's ancestors hand down.
        const std::vector<std::uint32_t> subtree = hierarchy_.PreOrder(b);
        std::vector<std::uint8_t> inside(hierarchy_.Size(), 0);
        for (std::uint32_t n : subtree) inside[n] = 1;
        Links local;
        local.Resize(hierarchy_.Size());
        for (std::uint32_t n : subtree) {
            for (const NodeLink& link : links_.node[n]) {
                if (!inside[link.sender]) local.node[n].push_back(link);
            }
            local.source[n] = links_.source[n];
        }
        pushPull_.HoldAbove(pushPull_.BinsAbove(b, links_, gathered_),
                            pushPull_.SourcesAbove(b, links_, sources_.size()));
        active_ = &local;
        activeRoot_ = b;
        const std::size_t size = hierarchy_.Size();
        Refiner refiner(model_, field_, local, estimator_, visibility_, sources_, thresholds_,
                        [this](std::uint32_t n) { OnSplit(n); });
        refiner.HoldFixedOutside(b);
        Stopwatch watch;
        // The subtree from its emission, then as a scene of its own: direct light, its own
        // exchanges refined, refine–solve passes.
        Index();
        for (std::uint32_t n : subtree) {
            field_.radiosity.ClearRow(n);
            std::copy_n(leafLight_.emission[n], channels_.Count(), field_.radiosity(n, kUpper));
        }
        pushPull_.PullUp(field_);
        LightFromSources();
        if (!options_.directOnly) refiner.Refine({{Task::kSelf, b, b}});
        Index();
        Iterate(refiner, solution, watch);
        Outputs(solution);
        // The local hierarchy released: the patches it split are whole again.
        active_ = &links_;
        activeRoot_ = hierarchy_.Root();
        pushPull_.HoldAbove({}, {});
        model_.Truncate(size);
        field_.Resize(size);
        links_.Resize(size);
        Index();
    });
    clock.Stamp(solution.stats);
    solution.stats.threads = threads;
    return solution;
}

void SceneSolve::Outputs(Solution& solution) {
    solution.stats.links = static_cast<std::int64_t>(active_->Count());
    solution.stats.elements = static_cast<std::int64_t>(hierarchy_.Size());
    solution.stats.refinementDepth = static_cast<int>(
        traversal_.Subtrees().empty() ? 0 : traversal_.Depth(hierarchy_, *active_));
    if (channels_.beams > 1) return;  // their light is read by Patches
    SolutionSink sink(solution);
    // Holding closed instances, or within levels further out: what escapes passes the whole
    // scene (WriteOutputs), and the closed ones' light by their transmittance.
    const bool closed = !hierarchy_.Closed().empty() || occlusion_.HasOutside();
    rayCount_ += WriteOutputs(model_, rays_, traversal_.Leaves(), optics_, field_, leafLight_, sink,
                              solution.balance, closed ? &occlusion_ : nullptr);
    if (closed) rayCount_ += AddClosedEscape(model_, occlusion_, field_, solution.balance);
    for (std::size_t k = 0; k < closedLampIncident_.size(); ++k)
        solution.balance[k].incidentW += closedLampIncident_[k];
}

void SceneSolve::Arrived(LevelSolution& level) const {
    level.sources = sources_;
    level.errorW = thresholds_.errorW;
    level.sourceCount = thresholds_.sourceCount;
    level.bins = model_.BinCount();
    const std::size_t closed = hierarchy_.Closed().size();
    const std::size_t width = static_cast<std::size_t>(model_.BinCount()) * channels_.Count();
    level.arrivedBins.assign(closed, std::vector<double>(width, 0.0));
    level.sourceVisibility.assign(closed, std::vector<double>(sources_.size(), 0.0));
    if (thresholds_.errorW <= 0.0) return;  // nothing lit it
    for (std::size_t c = 0; c < closed; ++c) {
        std::copy_n(closedLight_.bins[c], width, level.arrivedBins[c].begin());
        std::copy_n(closedLight_.sources[c], sources_.size(), level.sourceVisibility[c].begin());
    }
    if (level_.holdLevel) {
        level.closedIntensity.assign(closed, {});
        for (std::size_t c = 0; c < closed; ++c) {
            if (hierarchy_.Closed()[c].Held()) continue;
            const double* sent =
                field_
                    .intensity[model_.Slot(hierarchy_.NodeOfClosed(static_cast<std::int32_t>(c)))];
            level.closedIntensity[c].assign(sent, sent + width);
        }
    }
    if (!level_.splitSurfaces) return;
    if (closed > 0 && !level_.holdLevel) level.surfaceBins = SurfaceBins();
    if (level_.holdLevel) HandOnOrgans(level);
    for (std::uint32_t n : traversal_.Leaves()) {
        const HrcNode& node = hierarchy_[n];
        if (!node.patch || model_.Held(n) || model_.HoldsOrgans(n)) continue;
        const glm::dvec3 o = flat_.origin;
        const double* upper = field_.radiosity(n, kUpper);
        const double* lower = field_.radiosity(n, kLower);
        level.surfaces.push_back({node.a + o, node.b + o, node.c + o,
                                  std::vector<double>(upper, upper + channels_.Count()),
                                  std::vector<double>(lower, lower + channels_.Count()),
                                  node.receiver, model_.Lamp(n)});
    }
}

void SceneSolve::HandOnOrgans(LevelSolution& level) const {
    // Each organ triangle with the area mean of its patches' radiosity: the instances it
    // holds link it into their contents, where their own organs refine what they take.
    const int count = channels_.Count();
    std::map<std::uint32_t, std::pair<double, std::vector<double>>> organ;  // by triangle
    for (std::uint32_t n : traversal_.Leaves()) {
        const HrcNode& node = hierarchy_[n];
        if (!node.patch || model_.Held(n) || !model_.HoldsOrgans(n)) continue;
        auto& [area, sides] = organ[node.triangle];
        sides.resize(2 * count, 0.0);
        area += node.areaM2;
        for (int side : {kUpper, kLower}) {
            const double* b = field_.radiosity(n, side);
            for (int k = 0; k < count; ++k) sides[side * count + k] += node.areaM2 * b[k];
        }
    }
    const glm::dvec3 o = flat_.origin;
    for (auto& [t, light] : organ) {
        const Triangle& triangle = flat_.triangles[t];
        std::vector<double>& sides = light.second;
        for (double& b : sides) b /= light.first;
        level.surfaces.push_back({triangle.a + o, triangle.b + o, triangle.c + o,
                                  std::vector<double>(sides.begin(), sides.begin() + count),
                                  std::vector<double>(sides.begin() + count, sides.end()),
                                  triangle.receiver});
    }
}

std::vector<std::vector<double>> SceneSolve::SurfaceBins() const {
    // The links from surfaces alone, gathered and pushed down as the sweeps do.
    const std::size_t size = hierarchy_.Size();
    Links plain;
    plain.Resize(size);
    for (std::uint32_t r : traversal_.Receivers()) {
        for (const NodeLink& link : active_->node[r]) {
            if (!model_.HoldsOrgans(link.sender)) plain.node[r].push_back(link);
        }
    }
    Gathered gathered(channels_, model_.BinCount());
    gathered.bins.Assign(model_.SlotCount());
    gathered.sides.Assign(size);
    gathered.integral.Assign(size);
    gathered.moment.Assign(size);
    Gather<false>(model_, field_, plain, traversal_.Receivers(), gathered);
    SourceLight none(channels_);
    none.sides.Assign(size);
    LeafLight leaves(channels_);
    leaves.Resize(size);
    ClosedLight arrived(channels_, model_.BinCount(), hierarchy_.Closed().size(), sources_.size());
    pushPull_.PushDown<false>(plain, gathered, none, leaves, &arrived);
    const std::size_t width = static_cast<std::size_t>(model_.BinCount()) * channels_.Count();
    std::vector<std::vector<double>> bins(hierarchy_.Closed().size());
    for (std::size_t c = 0; c < bins.size(); ++c)
        bins[c].assign(arrived.bins[c], arrived.bins[c] + width);
    return bins;
}

void SceneSolve::Patches(BeamSolution& beams) const {
    beams.channels = channels_;
    beams.absorbedW.assign(channels_.Count(), 0.0);
    const int width = 2 * channels_.Count();
    for (std::uint32_t n : traversal_.Leaves()) {
        const HrcNode& node = hierarchy_[n];
        if (!node.patch || flat_.receivers[node.receiver].kind != ReceiverKind::kOrgan) continue;
        beams.patches.push_back({node.a, node.b, node.c, node.normal, node.areaM2, node.triangle});
        for (int side : {kUpper, kLower}) {
            const double* b = field_.radiosity(n, side);
            beams.radiosity.insert(beams.radiosity.end(), b, b + channels_.Count());
            // What the side takes and neither reflects nor passes on is absorbed.
            const double* e = leafLight_.irradiance(n, side);
            const double* rho = optics_.rho(node.receiver, side);
            const double* tau = optics_.tau(node.receiver, side);
            for (int c = 0; c < channels_.Count(); ++c)
                beams.absorbedW[c] += node.areaM2 * e[c] * (1.0 - rho[c] - tau[c]);
        }
    }
    LEAFLUX_CHECK_EQ(beams.radiosity.size(), beams.patches.size() * width);
}

}  // namespace

BeamSolution SolveBeams(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                        const HrcOptions& options, std::span<const glm::dvec3> towardSource) {
    LEAFLUX_CHECK(options.directionLevel >= 0 && options.directionLevel <= 4);
    LEAFLUX_CHECK(!scene.bands.empty() && !towardSource.empty());
    const ResourceClock clock;
    const Channels channels{static_cast<int>(scene.bands.size()),
                            static_cast<int>(towardSource.size()), ChannelMeasure::kWorstBeam};
    SceneSolve solver(scene, flat, rays, options, {}, channels, UnitBeams(channels, towardSource));
    BeamSolution beams;
    beams.stats = solver.Run(clock).stats;
    solver.Patches(beams);
    return beams;
}

Solution SolveHrc(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                  const HrcOptions& options, std::span<const ClosedNode> closed) {
    LEAFLUX_CHECK(options.directionLevel >= 0 && options.directionLevel <= 4);
    LEAFLUX_CHECK(!scene.bands.empty());
    const ResourceClock clock;
    Stopwatch watch;
    SceneSolve solver(scene, flat, rays, options, closed);
    spdlog::debug("hrc: hierarchy built in {:.3f} s", watch.Lap());
    return solver.Run(clock);
}

LevelSolution SolveLevel(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                         const HrcOptions& options, std::span<const ClosedNode> closed,
                         LevelProblem problem) {
    LEAFLUX_CHECK(options.directionLevel >= 0 && options.directionLevel <= 4);
    LEAFLUX_CHECK(!scene.bands.empty());
    const ResourceClock clock;
    std::vector<DirectionalSource> sources = std::move(problem.sources);
    if (sources.empty()) sources = BeamsOf(scene, options.skyCones);
    problem.sources.clear();
    SceneSolve solver(scene, flat, rays, options, closed,
                      {static_cast<int>(scene.bands.size()), 1, ChannelMeasure::kSum},
                      std::move(sources), problem);
    LevelSolution level;
    level.solution = solver.Run(clock);
    solver.Arrived(level);
    return level;
}

LocalSolve SolveHrcThenLocal(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                             const HrcOptions& options, NodeId root) {
    LEAFLUX_CHECK(options.directionLevel >= 0 && options.directionLevel <= 4);
    LEAFLUX_CHECK(!scene.bands.empty());
    const ResourceClock clock;
    SceneSolve solver(scene, flat, rays, options, {});
    LocalSolve result;
    result.whole = solver.Run(clock);
    result.local = solver.RunLocal(root);
    return result;
}

}  // namespace leaflux
