#include "solver/instancing/instanced.h"

#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <mutex>
#include <numbers>
#include <set>
#include <tuple>

#include "solver/instancing/instance_tree.h"
#include "solver/instancing/original.h"
#include "solver/instancing/push_down.h"
#include "solver/instancing/scene_originals.h"
#include "solver/instancing/signature.h"
#include "solver/radiosity/beams.h"
#include "solver/radiosity/closed_exchange.h"
#include "solver/raytrace/occlusion.h"
#include "solver/scene/geometry.h"
#include "solver/scene/organ_receivers.h"
#include "solver/scene/subtrees.h"
#include "solver/scene/world_frames.h"
#include "solver/util/box.h"
#include "solver/util/check.h"
#include "solver/util/cores.h"
#include "solver/util/directions.h"
#include "solver/util/error.h"
#include "solver/util/memory.h"

namespace leaflux {
namespace {

// What the instances opened in a level hold fixed from it and the levels it lies in
// (InstancedOptions::holdOutside): their organs' and surfaces' patches as emitters, their
// closed instances with the intensity each sent (ClosedNode::held), placed in the world
// (sceneFromInstance: the world's frame): those the level held, then its own.
struct HeldOutside {
    std::vector<Emitter> emitters;
    std::vector<ClosedNode> closed;
};

// One part of the scene as a scene of its own, in the world frame, with its instances
// closed; it lives while the parts under it are solved (their rays meet it).
struct Level {
    Scene scene;
    FlatScene flat;
    std::unique_ptr<RayScene> rays;
    std::vector<ClosedNode> closed;
    std::vector<std::uint32_t> closedPart;  // by closed instance: its part
    std::vector<glm::dmat4> worldFromClosed;
    std::unique_ptr<Occlusion> occlusion;
    // What it holds from further out: the emitters of `held` and, after its own
    // `closedPart.size()` in `closed`, the closed instances of `held` but the one it is.
    std::shared_ptr<const HeldOutside> held;
};

glm::dvec3 Centre(const glm::dvec3& lo, const glm::dvec3& hi) { return 0.5 * (lo + hi); }

class InstancedSolve {
  public:
    InstancedSolve(const Scene& scene, const FlatScene& receivers, const RayScene* shadows,
                   const InstanceTree& tree, const SceneOriginals& originals,
                   const InstancedOptions& options, InstancedSolution& out)
        : scene_(scene),
          receivers_(receivers),
          shadows_(shadows),
          tree_(tree),
          originals_(originals),
          options_(DirectOnlyAlone(options)),
          out_(out),
          directions_(DirectionSet::OfLevel(options.hrc.directionLevel)),
          organs_(receivers),
          firstOther_(organs_.Count() < receivers.receivers.size() ? organs_.Count()
                                                                   : kNoReceiver) {
        if (shadows_ != nullptr) shadowTriangles_ = ShadowTriangles();
        out_.solution.balance.assign(scene.bands.size(), EnergyBalance{});
        out_.stats.depths.assign(tree.Depth() + 1, InstancedStats::Depth{});
        for (const InstanceTree::Part& part : tree.Parts()) {
            ++out_.stats.depths[part.depth].instances;
            out_.stats.depths[part.depth].merged += part.merged;
        }
        out_.stats.depths[0].opened = 1;
    }

    void Run() {
        if (shadows_ != nullptr) DrawSuns();
        organsProjected_ = OrgansProjectedAreas();
        // Every organ's light from here on, not beside the walk of OrgansProjectedAreas.
        const std::size_t all = receivers_.receivers.size();
        if (options_.organSink == nullptr) out_.solution.light.assign(all, scene_.bands.size());
        out_.solution.unsolved.assign(all, 0);
        if (options_.pushDown) out_.solution.pushedDown.assign(all, 0);
        const std::unique_ptr<Level> top = Build(InstanceTree::kTop, glm::dmat4(1.0), nullptr, 0);
        LevelSolution light = Solve(InstanceTree::kTop, *top, {});
        organsProjected_ = {};
        if (options_.hrc.directOnly) {
            held_ = Lamps();
        } else if (!options_.holdOutside) {
            held_ = Emitters(light.surfaces);
        }
        errorW_ = light.errorW;
        sourceCount_ = light.sourceCount;
        OpenInstances(*top, light);
    }

  private:
    static constexpr std::uint32_t kNoReceiver = OrganReceivers::kNone;

    // Σ A |n · ω| over every organ triangle for each of the top's sources (BeamsOf), in one
    // walk: each triangle's A n held through the top's solve made a plantation's peak.
    std::vector<std::pair<glm::dvec3, double>> OrgansProjectedAreas() const {
        std::vector<std::pair<glm::dvec3, double>> areas;
        for (const DirectionalSource& source : BeamsOf(scene_, options_.hrc.skyCones))
            areas.emplace_back(source.toward, 0.0);
        ForEachWorldFrame(scene_, [&](const Node& node, const glm::dmat4& worldFromLocal) {
            if (!node.organ()) return;
            for (const Triangle& t : PlaceMesh(*node.organ()->mesh, worldFromLocal)) {
                for (auto& [omega, area] : areas)
                    area += t.areaM2 * std::abs(glm::dot(t.normal, omega));
            }
        });
        return areas;
    }

    // Direct light alone: an opened instance takes the suns, sky and lamps alone, not what
    // the levels it lies in scattered (held, or per bin).
    static InstancedOptions DirectOnlyAlone(InstancedOptions options) {
        if (options.hrc.directOnly) options.holdOutside = false;
        return options;
    }

    std::unique_ptr<Level> Build(std::uint32_t p, const glm::dmat4& worldFromRoot,
                                 const Level* outside, std::uint32_t indexOutside,
                                 std::shared_ptr<const HeldOutside> held = nullptr,
                                 std::size_t heldSelf = 0) const;
    // What the instances opened in `level` hold (holdOutside): what it held, and its own
    // patches and closed instances as solved.
    std::shared_ptr<const HeldOutside> HeldBy(const Level& level, const LevelSolution& light) const;
    LevelSolution Solve(std::uint32_t p, const Level& level,
                        std::vector<DirectionalSource> sources);
    // The scene's receiver that receiver r of a level with `organs` organ receivers is:
    // environment surfaces and emitters are the top's, after its organs, in order.
    std::uint32_t Global(const FlatScene& flat, std::uint32_t organs, std::uint32_t r) const {
        const Receiver& receiver = flat.receivers[r];
        if (receiver.kind == ReceiverKind::kOrgan) {
            const std::uint32_t global = OrganReceiver(receiver.node);
            LEAFLUX_CHECK(global != kNoReceiver);
            return global;
        }
        return firstOther_ + (r - organs);
    }
    // The scene's receiver of an organ; kNoReceiver for a node that is none.
    std::uint32_t OrganReceiver(NodeId node) const { return organs_.Of(node); }
    // Receiver `global`'s light: to the organ sink, or into the light table.
    void Emit(std::uint32_t global, std::span<const BandLight> bands) {
        if (options_.organSink != nullptr) return options_.organSink->Put(global, bands);
        std::ranges::copy(bands, out_.solution.light[global].begin());
    }
    // The top's receivers are all the scene's; an opened part's are its organs, then the
    // surfaces it holds.
    static std::uint32_t OwnReceivers(std::uint32_t p, const FlatScene& flat) {
        return p == InstanceTree::kTop ? static_cast<std::uint32_t>(flat.receivers.size())
                                       : LeadingOrgans(flat);
    }
    ShadowView ShadowsOf(std::uint32_t p, const FlatScene& flat) const;
    // A map of each sun over the whole scene's triangles (SunMap): the light of the suns on
    // every organ solved, found once for all the levels, for the sources the levels take.
    void DrawSuns() {
        Stopwatch clock;
        sunMaps_ = leaflux::DrawSuns(receivers_, *shadows_, BeamsOf(scene_, options_.hrc.skyCones),
                                     SolvedTriangles());
        spdlog::debug("instanced: sun maps drawn in {:.2f} s", clock.Lap());
    }
    // Per organ triangle, whether an opened level holds it: those of the instances solved
    // whole (Opens) are not asked for, and their leaves cost the maps nothing. Empty when
    // every instance opens.
    std::vector<std::uint8_t> SolvedTriangles() const;
    // The light that arrived on closed instance c of `level`, as the sources of its contents.
    std::vector<DirectionalSource> ArrivedOn(const LevelSolution& light, std::size_t c) const;
    // Each patch side that sends light, as an emitter held fixed (ReceiverKind::kHeld).
    static std::vector<Emitter> Emitters(const std::vector<LevelSolution::SurfacePatch>& patches);
    // The scene's lamps, held: what they emit, not what they reflect (direct light alone).
    std::vector<Emitter> Lamps() const {
        std::vector<Emitter> lamps = scene_.sources.emitters;
        for (Emitter& lamp : lamps) {
            lamp.held = true;
            lamp.lamp = lamp.opticsId.empty();
        }
        return lamps;
    }
    void OpenInstances(const Level& level, const LevelSolution& light);
    // Whether part q, placed by worldFromRoot, is opened (InstancedOptions::maxDepth,
    // outputLevel, inView).
    bool Opens(std::uint32_t q, const glm::dmat4& worldFromRoot) const;
    // Whether part q is opened but for the view: what the solve asks (maxDepth, outputLevel).
    bool OpensAsked(std::uint32_t q) const;
    // Closed instance c of `level` solved whole from the light that arrived on it.
    void SolveWhole(const Level& level, const LevelSolution& light, std::size_t c);
    // Where the organs of each part and of the parts in it lie in the shadow engine
    // (ClosedNode::shadowTriangles), by part.
    std::vector<std::shared_ptr<const RayScene::TriangleRanges>> ShadowTriangles() const;
    // Counts the organs of part q and of the parts in it, and their area, into `whole`;
    // marks them unsolved, or pushed down (InstancedOptions::pushDown).
    void MarkUnsolved(std::uint32_t q, StructureLight& whole);
    // The light of part q, closed as `closed` and solved whole into `whole` from
    // `arrivals`, handed down to its organs (push_down.h).
    void PushDownInto(std::uint32_t q, const ClosedNode& closed, std::span<const Arrival> arrivals,
                      const StructureLight& whole);
    void Open(const Level& parent, std::size_t c, std::vector<DirectionalSource> sources,
              std::shared_ptr<const HeldOutside> held, std::size_t heldSelf);

    const Scene& scene_;
    const FlatScene& receivers_;
    const RayScene* const shadows_;
    SunMaps sunMaps_;                                             // over shadows_, when it is given
    std::vector<std::pair<glm::dvec3, double>> organsProjected_;  // while the top is solved
    // Each part's organs in shadows_, when it is given (ShadowTriangles).
    std::vector<std::shared_ptr<const RayScene::TriangleRanges>> shadowTriangles_;
    const InstanceTree& tree_;
    const SceneOriginals& originals_;
    const InstancedOptions options_;  // directOnly: holdOutside off (DirectOnlyAlone)
    InstancedSolution& out_;
    const DirectionSet& directions_;
    const OrganReceivers organs_;             // which receiver each organ is
    std::uint32_t firstOther_ = kNoReceiver;  // the first environment surface or emitter
    // The top's surfaces as solved, each patch side that sends light an emitter, which
    // every opened instance holds (ReceiverKind::kHeld); their meshes shared.
    std::vector<Emitter> held_;
    double errorW_ = 0.0;
    std::size_t sourceCount_ = 0;
    std::mutex statsMutex_;
};

std::unique_ptr<Level> InstancedSolve::Build(std::uint32_t p, const glm::dmat4& worldFromRoot,
                                             const Level* outside, std::uint32_t indexOutside,
                                             std::shared_ptr<const HeldOutside> held,
                                             std::size_t heldSelf) const {
    const InstanceTree::Part& part = tree_[p];
    auto level = std::make_unique<Level>();
    Scene& local = level->scene;
    local.bands = scene_.bands;
    local.optics = scene_.optics;
    if (p == InstanceTree::kTop) {
        local.environment = scene_.environment;
        local.sources = scene_.sources;
    } else {
        local.sources.emitters = held ? held->emitters : held_;
    }
    local.nodes = Rerooted(scene_, part.nodes, part.root, worldFromRoot);
    level->flat = Flatten(local);
    // Its closed instances where they are in the world.
    const auto worldFromLocal = WorldFromLocal(local);
    glm::dvec3 middle(0.0);
    for (std::uint32_t q : part.instances) {
        const InstanceTree::Part& instance = tree_[q];
        const Node& root = scene_.nodes[instance.rootIndex];
        const glm::dmat4 world = root.parent == kNoParent ? glm::dmat4(root.parentFromLocal())
                                                          : worldFromLocal.at(root.parent) *
                                                                glm::dmat4(root.parentFromLocal());
        level->worldFromClosed.push_back(world);
        middle += glm::dvec3(world * glm::dvec4(Centre(instance.boxMin, instance.boxMax), 1.0));
    }
    // A part of closed instances alone has no triangles to centre its frame on.
    if (level->flat.Empty() && !part.instances.empty())
        level->flat.origin = middle / static_cast<double>(part.instances.size());
    const glm::dmat4 sceneFromWorld = glm::translate(glm::dmat4(1.0), -level->flat.origin);
    for (std::size_t j = 0; j < part.instances.size(); ++j) {
        const std::uint32_t q = part.instances[j];
        const InstanceTree::Part& instance = tree_[q];
        const Node& root = scene_.nodes[instance.rootIndex];
        ClosedNode closed;
        closed.name = scene_.NodeName(root);
        closed.parent = root.parent;
        closed.sceneFromInstance = sceneFromWorld * level->worldFromClosed[j];
        closed.boxMin = instance.boxMin;
        closed.boxMax = instance.boxMax;
        closed.areaM2 = instance.leafAreaM2;
        closed.organArea = instance.area;
        closed.opens = Opens(q, level->worldFromClosed[j]);
        closed.relit = OpensAsked(q);
        if (shadows_ != nullptr) closed.shadowTriangles = shadowTriangles_[q];
        const std::shared_ptr<const Original>& original =
            originals_.bySignature.at(instance.signature);
        closed.contents = std::make_shared<OriginalContents>(
            original, MemberScale(*original, instance.leafAreaM2));
        level->closed.push_back(std::move(closed));
        level->closedPart.push_back(q);
    }
    // Those held from further out, after its own, but the one it is: the rays do not meet
    // them (their levels' occlusion holds their proxies).
    std::vector<ClosedProxy> proxies;
    for (const ClosedNode& closed : level->closed) proxies.push_back(closed.Proxy());
    if (held) {
        for (std::size_t i = 0; i < held->closed.size(); ++i) {
            if (i == heldSelf) continue;
            ClosedNode closed = held->closed[i];
            closed.sceneFromInstance = sceneFromWorld * closed.sceneFromInstance;
            level->closed.push_back(std::move(closed));
        }
        level->held = std::move(held);
    }
    // An opened part's rays meet its own organs; the surfaces it holds are seen by their
    // links alone.
    level->rays = std::make_unique<RayScene>(
        level->flat, std::nullopt, RayDevice::Shared(),
        p == InstanceTree::kTop ? kNoTriangle : LeadingOrganTriangles(level->flat));
    OutsideView view;
    if (outside != nullptr) {
        view = {
            outside->occlusion.get(), {indexOutside}, level->flat.origin - outside->flat.origin};
    }
    level->occlusion = std::make_unique<Occlusion>(*level->rays, std::move(proxies),
                                                   std::move(view), ShadowsOf(p, level->flat));
    return level;
}

ShadowView InstancedSolve::ShadowsOf(std::uint32_t p, const FlatScene& flat) const {
    if (shadows_ == nullptr) return {};
    ShadowView view{shadows_, std::vector<std::uint32_t>(flat.triangles.size(), kNoTriangle),
                    flat.origin - receivers_.origin, organs_.Triangles(), &sunMaps_};
    const std::uint32_t organs = LeadingOrgans(flat);
    for (std::uint32_t r = 0; r < OwnReceivers(p, flat); ++r) {
        const Receiver& local = flat.receivers[r];
        const Receiver& whole = receivers_.receivers[Global(flat, organs, r)];
        LEAFLUX_CHECK_EQ(local.triangleCount, whole.triangleCount);
        for (std::uint32_t t = 0; t < local.triangleCount; ++t)
            view.triangleOf[local.firstTriangle + t] = whole.firstTriangle + t;
    }
    return view;
}

LevelSolution InstancedSolve::Solve(std::uint32_t p, const Level& level,
                                    std::vector<DirectionalSource> sources) {
    const auto start = std::chrono::steady_clock::now();
    LevelProblem problem;
    problem.occlusion = level.occlusion.get();
    problem.sources = std::move(sources);
    problem.errorW = errorW_;
    problem.sourceCount = sourceCount_;
    // Σ A |n · ω| over every organ triangle of the scene (OrgansProjectedAreas) scales ε at
    // the top as it scales HRC's on the flattened scene.
    if (p == InstanceTree::kTop) {
        problem.organsProjectedArea = [this](const glm::dvec3& omega) {
            for (const auto& [toward, area] : organsProjected_) {
                if (toward == omega) return area;
            }
            return 0.0;  // not a source of the top: the level's own organs and instances
        };
    }
    problem.splitSurfaces = true;  // the surfaces' light, held by the contents (Build)
    problem.holdLevel = options_.holdOutside;
    LevelSolution light = SolveLevel(level.scene, level.flat, *level.rays, options_.hrc,
                                     level.closed, std::move(problem));
    // Its receivers' light, where the scene has them.
    const FlatScene& flat = level.flat;
    const std::uint32_t organs = LeadingOrgans(flat);
    for (std::uint32_t r = 0; r < OwnReceivers(p, flat); ++r) {
        Emit(Global(flat, organs, r), light.solution.light[r]);
    }
    InstancedStats::Problem size;
    size.depth = tree_[p].depth;
    size.triangles = static_cast<std::int64_t>(flat.triangles.size());
    size.closed = static_cast<std::int64_t>(level.closed.size());
    size.elements = light.solution.stats.elements;
    size.links = light.solution.stats.links;
    size.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::lock_guard lock(statsMutex_);
    out_.stats.problems.push_back(size);
    if (p != InstanceTree::kTop) ++out_.stats.depths[size.depth].opened;
    Solution& solution = out_.solution;
    solution.stats.rays += light.solution.stats.rays;
    solution.stats.warmOrgans += light.solution.stats.warmOrgans;
    solution.stats.links = std::max(solution.stats.links, light.solution.stats.links);
    solution.stats.elements = std::max(solution.stats.elements, light.solution.stats.elements);
    solution.stats.iterations =
        std::max(solution.stats.iterations, light.solution.stats.iterations);
    solution.stats.residual = std::max(solution.stats.residual, light.solution.stats.residual);
    // What escapes the scene from each level's organs and surfaces, and from its closed
    // instances that are not opened (ClosedNode::opens): an opened one's organs say what
    // leaves it.
    for (std::size_t b = 0; b < solution.balance.size(); ++b) {
        EnergyBalance& total = solution.balance[b];
        const EnergyBalance& part = light.solution.balance[b];
        total.absorbedW += part.absorbedW;
        total.incidentW += part.incidentW;
        total.escapedW += part.escapedW;
        total.stderrW = std::hypot(std::max(total.stderrW, 0.0), std::max(part.stderrW, 0.0));
    }
    return light;
}

std::vector<Emitter> InstancedSolve::Emitters(
    const std::vector<LevelSolution::SurfacePatch>& patches) {
    // A surface's patches that send light from one side, one emitter: the hierarchy then
    // clusters them as the surface (a plane where it is one), as the level did. Each patch
    // its own emitter, the greenhouse's walls lit its leaves' upper sides through clusters
    // of scattered patches of every wall, the floor and the lamps, 12 % short.
    std::map<std::pair<std::uint32_t, int>, std::size_t> of;  // by surface and side
    std::vector<Emitter> held;
    std::vector<Mesh> meshes;
    std::vector<double> areas;
    for (const LevelSolution::SurfacePatch& patch : patches) {
        for (int side : {kUpper, kLower}) {
            const std::vector<double>& exitance = side == kUpper ? patch.upper : patch.lower;
            if (std::none_of(exitance.begin(), exitance.end(), [](double e) { return e > 0.0; }))
                continue;
            const auto [at, added] = of.try_emplace({patch.surface, side}, held.size());
            if (added) {
                held.push_back({"held surface", nullptr, std::vector<double>(exitance.size(), 0.0),
                                "", true, patch.lamp});
                meshes.emplace_back();
                areas.push_back(0.0);
            }
            Emitter& emitter = held[at->second];
            Mesh& mesh = meshes[at->second];
            const auto first = static_cast<std::uint32_t>(mesh.positions.size());
            mesh.positions.insert(
                mesh.positions.end(),
                {patch.a, side == kUpper ? patch.b : patch.c, side == kUpper ? patch.c : patch.b});
            mesh.triangles.push_back({first, first + 1, first + 2});
            emitter.triangleExitanceWm2.insert(emitter.triangleExitanceWm2.end(), exitance.begin(),
                                               exitance.end());
            // exitanceWm2: the mean over the emitter's area.
            const double area = 0.5 * glm::length(glm::cross(patch.b - patch.a, patch.c - patch.a));
            areas[at->second] += area;
            for (std::size_t k = 0; k < exitance.size(); ++k)
                emitter.exitanceWm2[k] += area * exitance[k];
        }
    }
    for (std::size_t e = 0; e < held.size(); ++e) {
        for (double& mean : held[e].exitanceWm2) mean /= std::max(areas[e], 1e-300);
        held[e].mesh = std::make_shared<const Mesh>(std::move(meshes[e]));
    }
    return held;
}

std::shared_ptr<const HeldOutside> InstancedSolve::HeldBy(const Level& level,
                                                          const LevelSolution& light) const {
    auto held = std::make_shared<HeldOutside>();
    if (level.held) held->emitters = level.held->emitters;
    std::vector<Emitter> own = Emitters(light.surfaces);
    held->emitters.insert(held->emitters.end(), std::make_move_iterator(own.begin()),
                          std::make_move_iterator(own.end()));
    // Its closed instances where they are: those it held, then its own.
    const glm::dmat4 worldFromScene = glm::translate(glm::dmat4(1.0), level.flat.origin);
    const std::size_t owned = level.closedPart.size();
    const auto hold = [&](std::size_t c) {
        ClosedNode closed = level.closed[c];
        closed.sceneFromInstance = worldFromScene * closed.sceneFromInstance;
        closed.parent = kNoParent;
        if (c < owned && !light.closedIntensity.empty()) closed.held = light.closedIntensity[c];
        // A level nothing lit hands on no intensity: its instances send nothing.
        if (closed.held.empty())
            closed.held.assign(static_cast<std::size_t>(light.bins) * scene_.bands.size(), 0.0);
        if (closed.heldDepth.empty()) closed.heldDepth = HeldDepths(closed, directions_);
        held->closed.push_back(std::move(closed));
    };
    for (std::size_t c = owned; c < level.closed.size(); ++c) hold(c);
    for (std::size_t c = 0; c < owned; ++c) hold(c);
    return held;
}

std::vector<DirectionalSource> InstancedSolve::ArrivedOn(const LevelSolution& light,
                                                         std::size_t c) const {
    const int channels = static_cast<int>(scene_.bands.size());
    const auto lit = [](const std::vector<double>& e) {
        return std::any_of(e.begin(), e.end(), [](double v) { return v > 0.0; });
    };
    std::vector<DirectionalSource> sources;
    // The scene's suns and sky cones, traced again from the contents through everything.
    for (const DirectionalSource& source : light.sources) {
        if (source.beyond) sources.push_back(source);
    }
    if (options_.hrc.directOnly) return sources;
    // The rest, per bin: what the level's links brought, and what the cones of light that
    // lit the level from further out brought through it. Holding the level (holdOutside),
    // its links' light comes by links from what the contents hold instead (Build).
    std::vector<double> bins = options_.holdOutside
                                   ? std::vector<double>(light.arrivedBins[c].size(), 0.0)
                                   : light.arrivedBins[c];
    for (std::size_t s = 0; s < light.sources.size(); ++s) {
        const DirectionalSource& source = light.sources[s];
        const double visibility = light.sourceVisibility[c][s];
        if (source.beyond || visibility <= 0.0) continue;
        const auto located = directions_.Locate(source.toward);
        for (int j = 0; j < 3; ++j) {
            for (int k = 0; k < channels; ++k)
                bins[located.vertex[j] * channels + k] +=
                    located.weight[j] * visibility * source.normalIrradiance[k];
        }
    }
    // Less what the surfaces sent: the contents hold those surfaces (Build) and take
    // their light with its parallax.
    for (int d = 0; d < light.bins; ++d) {
        std::vector<double> e(bins.begin() + d * channels, bins.begin() + (d + 1) * channels);
        if (!light.surfaceBins.empty()) {
            for (int k = 0; k < channels; ++k)
                e[k] = std::max(0.0, e[k] - light.surfaceBins[c][d * channels + k]);
        }
        if (!lit(e)) continue;
        DirectionalSource cone{directions_.Direction(d), std::move(e),
                               1.0 - directions_.HatIntegralSr(d) / (2.0 * std::numbers::pi)};
        cone.beyond = false;    // what it met outside, its irradiance holds
        cone.incident = false;  // scattered inside the scene
        sources.push_back(std::move(cone));
    }
    return sources;
}

void InstancedSolve::OpenInstances(const Level& level, const LevelSolution& light) {
    std::vector<std::size_t> opened;
    for (std::size_t c = 0; c < level.closedPart.size(); ++c) {
        if (Opens(level.closedPart[c], level.worldFromClosed[c])) {
            opened.push_back(c);
        } else {
            SolveWhole(level, light, c);
        }
    }
    if (opened.empty()) return;
    std::vector<std::vector<DirectionalSource>> arrived(opened.size());
    for (std::size_t i = 0; i < opened.size(); ++i) arrived[i] = ArrivedOn(light, opened[i]);
    // What they hold of this level and those further out (holdOutside): an instance's own
    // entry there is after those this level held.
    const std::shared_ptr<const HeldOutside> held =
        options_.holdOutside ? HeldBy(level, light) : nullptr;
    const std::size_t inherited = level.closed.size() - level.closedPart.size();
    // Siblings are independent once their parent is solved: each its own problem, started
    // in their order, each thread taking the next, so that an organ sink gets few organs
    // out of order (LeafCsvStream), not half the scene's as a share a thread took.
    std::atomic<std::size_t> next{0};
    const std::size_t threads =
        std::min(opened.size(), static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()));
    tbb::parallel_for(std::size_t{0}, threads, [&](std::size_t) {
        for (std::size_t i; (i = next++) < opened.size();)
            Open(level, opened[i], std::move(arrived[i]), held, inherited + opened[i]);
    });
}

std::vector<std::uint8_t> InstancedSolve::SolvedTriangles() const {
    if (options_.maxDepth == 0 && !options_.outputLevel && !options_.inView) return {};
    std::vector<std::uint8_t> solved(organs_.Triangles(), 0);
    const auto opens = [&](std::uint32_t q, const glm::dmat4& world) { return Opens(q, world); };
    for (std::uint32_t p : tree_.Opened(opens, options_.inView ? &scene_ : nullptr)) {
        for (std::size_t i : tree_[p].nodes) {
            const std::uint32_t global = OrganReceiver(scene_.nodes[i].id);
            if (global == kNoReceiver) continue;
            const Receiver& r = receivers_.receivers[global];
            std::fill_n(solved.begin() + r.firstTriangle, r.triangleCount, std::uint8_t{1});
        }
    }
    return solved;
}

bool InstancedSolve::Opens(std::uint32_t q, const glm::dmat4& worldFromRoot) const {
    if (!OpensAsked(q)) return false;
    if (!options_.inView) return true;
    const auto [low, high] = PlacedBounds(worldFromRoot, tree_[q].boxMin, tree_[q].boxMax);
    return options_.inView(low, high);
}

bool InstancedSolve::OpensAsked(std::uint32_t q) const {
    if (options_.maxDepth > 0 && tree_[q].depth > options_.maxDepth) return false;
    if (!options_.outputLevel) return true;
    // Down to the smallest structures of the type that are instances; a structure of
    // another type (a plant, for light per axis) holding structures of the type that are
    // not instances opens too, so that they are solved.
    const NodeType type = *options_.outputLevel;
    return tree_.HoldsInstanceOf(scene_, q, type) ||
           (scene_.nodes[tree_[q].rootIndex].type() != type && tree_.HoldsNodeOf(scene_, q, type));
}

std::vector<std::shared_ptr<const RayScene::TriangleRanges>> InstancedSolve::ShadowTriangles()
    const {
    // From the last part up, each part's instances coming after it: its own organs' ranges
    // and its instances', merged. Each node is looked up once, not once for every instance
    // it lies in, as finding them when each level is built would.
    std::vector<std::shared_ptr<const RayScene::TriangleRanges>> own(tree_.Parts().size());
    for (std::size_t q = own.size(); q-- > 1;) {
        const InstanceTree::Part& part = tree_[static_cast<std::uint32_t>(q)];
        RayScene::TriangleRanges ranges;
        for (std::size_t i : part.nodes) {
            const std::uint32_t global = OrganReceiver(scene_.nodes[i].id);
            if (global == kNoReceiver) continue;
            const Receiver& r = receivers_.receivers[global];
            if (r.triangleCount > 0)
                ranges.push_back({r.firstTriangle, r.firstTriangle + r.triangleCount});
        }
        for (std::uint32_t inner : part.instances) {
            if (own[inner]) ranges.insert(ranges.end(), own[inner]->begin(), own[inner]->end());
        }
        if (!ranges.empty()) {
            own[q] = std::make_shared<const RayScene::TriangleRanges>(
                RayScene::Merged(std::move(ranges)));
        }
    }
    return own;
}

void InstancedSolve::MarkUnsolved(std::uint32_t q, StructureLight& whole) {
    for (std::size_t i : tree_[q].nodes) {
        const std::uint32_t global = OrganReceiver(scene_.nodes[i].id);
        if (global == kNoReceiver) continue;
        (options_.pushDown ? out_.solution.pushedDown : out_.solution.unsolved)[global] = 1;
        if (!options_.pushDown && options_.organSink != nullptr) options_.organSink->Skip(global);
        ++whole.organCount;
        whole.areaM2 += receivers_.receivers[global].areaM2;
    }
    for (std::uint32_t inner : tree_[q].instances) MarkUnsolved(inner, whole);
}

void InstancedSolve::PushDownInto(std::uint32_t q, const ClosedNode& closed,
                                  std::span<const Arrival> arrivals, const StructureLight& whole) {
    // Its organs in its own frame: its nodes and those of the parts in it, the root at the
    // origin.
    std::vector<std::uint32_t> nodes;
    std::vector<std::uint32_t> parts{q};
    while (!parts.empty()) {
        const InstanceTree::Part& part = tree_[parts.back()];
        parts.pop_back();
        nodes.insert(nodes.end(), part.nodes.begin(), part.nodes.end());
        parts.insert(parts.end(), part.instances.begin(), part.instances.end());
    }
    std::sort(nodes.begin(), nodes.end());  // scene order: parents first
    Scene own;
    own.bands = scene_.bands;
    own.optics = scene_.optics;
    own.nodes = Rerooted(scene_, nodes, tree_[q].root, glm::dmat4(1.0));
    const FlatScene organs = Flatten(own);
    const Original& original = *originals_.bySignature.at(tree_[q].signature);
    const auto tau = [&](const glm::dvec3& in) { return original.transmittance.Value(in, 0); };
    const std::vector<std::vector<BandLight>> light =
        PushDown(organs, closed, tau, arrivals, whole.bands, scene_.optics);
    for (std::size_t r = 0; r < organs.receivers.size(); ++r) {
        const std::uint32_t global = OrganReceiver(organs.receivers[r].node);
        if (global != kNoReceiver) Emit(global, light[r]);
    }
}

void InstancedSolve::SolveWhole(const Level& level, const LevelSolution& light, std::size_t c) {
    const std::uint32_t q = level.closedPart[c];
    const InstanceTree::Part& part = tree_[q];
    const Node& root = scene_.nodes[part.rootIndex];
    const Original& original = *originals_.bySignature.at(part.signature);
    const double scale = MemberScale(original, part.leafAreaM2);
    const glm::dvec3 extent = original.boxMax - original.boxMin;
    const ClosedNode& closed = level.closed[c];
    const int channels = static_cast<int>(scene_.bands.size());
    StructureLight whole;
    whole.node = root.id;
    whole.name = scene_.NodeName(root);
    whole.type = root.type();
    whole.bands.assign(channels, BandLight{});
    for (BandLight& band : whole.bands)
        band.irradianceUpperWm2 = band.irradianceLowerWm2 = std::nan("");
    // Irradiance e (W/m² normal to ω) arriving from unit ω (world, towards the source); from
    // a sun or sky cone, light incident on the scene, counted in the balance.
    std::vector<double> incident(channels, 0.0);
    std::vector<Arrival> arrivals;
    const auto arrive = [&](const glm::dvec3& omega, const double* e, bool fromSource) {
        const glm::dvec3 in = closed.ToInstance(omega);
        if (options_.pushDown) arrivals.push_back({in, std::vector<double>(e, e + channels)});
        const glm::dvec3 a = glm::abs(in);
        const double section =
            a.x * extent.y * extent.z + a.y * extent.x * extent.z + a.z * extent.x * extent.y;
        const double intercepted = section * (1.0 - original.transmittance.Value(in, 0));
        for (int k = 0; k < channels; ++k) {
            BandLight& band = whole.bands[k];
            // Format-1 originals have no absorption: what f does not scatter of it.
            band.absorbedW +=
                scale * e[k] *
                (original.absorption.Empty()
                     ? std::max(0.0, intercepted - original.phase.ScatteredPower(k, in))
                     : original.absorption.Value(in, k));
            band.radianceIntegral += e[k];
            band.radianceMoment += e[k] * omega;
            if (fromSource) incident[k] += scale * e[k] * intercepted;
        }
    };
    std::vector<double> e(channels);
    for (std::size_t s = 0; s < light.sources.size(); ++s) {
        const double visibility = light.sourceVisibility[c][s];
        if (visibility <= 0.0) continue;
        for (int k = 0; k < channels; ++k) e[k] = visibility * light.sources[s].normalIrradiance[k];
        arrive(light.sources[s].toward, e.data(), light.sources[s].incident);
    }
    for (int d = 0; d < light.bins; ++d)
        arrive(directions_.Direction(d), light.arrivedBins[c].data() + d * channels, false);
    if (options_.pushDown) PushDownInto(q, closed, arrivals, whole);
    std::lock_guard lock(statsMutex_);
    for (int k = 0; k < channels; ++k) {
        out_.solution.balance[k].absorbedW += whole.bands[k].absorbedW;
        out_.solution.balance[k].incidentW += incident[k];
    }
    MarkUnsolved(q, whole);
    ++out_.stats.depths[part.depth].whole;
    out_.solution.wholeStructures.push_back(std::move(whole));
}

void InstancedSolve::Open(const Level& parent, std::size_t c,
                          std::vector<DirectionalSource> sources,
                          std::shared_ptr<const HeldOutside> held, std::size_t heldSelf) {
    const std::uint32_t q = parent.closedPart[c];
    const std::unique_ptr<Level> level =
        Build(q, parent.worldFromClosed[c], &parent, static_cast<std::uint32_t>(c), std::move(held),
              heldSelf);
    const LevelSolution light = Solve(q, *level, std::move(sources));
    OpenInstances(*level, light);
}

}  // namespace

InstancedSolution SolveInstanced(const Scene& scene, const FlatScene& receivers,
                                 const RayScene* shadows, const InstancingPolicy& policy,
                                 PhaseDatabase& database, const InstancedOptions& options) {
    if (scene.periodic)
        throw InputError(ErrorCode::kUnsupported, "periodic",
                         "the instanced solver does not repeat a tile; use hrc or mc");
    const ResourceClock clock;
    const std::size_t freeAtStart = FreeHeapBytes();
    InstancedSolution out;
    // On the cores asked (hrc.threads), the functions computed as well as the problems.
    const int threads = CoresOf(options.hrc.threads);
    SceneOriginals originals;
    // The signatures are not needed once the functions and the tree are made.
    const InstanceTree tree = [&] {
        const SceneSignatures signatures = ComputeSignatures(scene, policy, /*unbinned=*/false);
        InstanceTree parts(scene, signatures);
        if (!options.outputLevel) {
            parts.Merge(options.mergeTriangles, [&](std::uint32_t q) {
                return options.maxDepth == 0 || parts[q].depth <= options.maxDepth;
            });
        }
        // The functions of the instances some level closes.
        std::set<std::string> closed;
        for (const InstanceTree::Part& part : parts.Parts()) {
            if (part.depth > 0 && !part.merged) closed.insert(part.signature);
        }
        if (!closed.empty()) {
            OnCores(threads, [&] {
                originals =
                    OriginalsOf(scene, signatures, policy, options.originals, database, closed);
            });
        }
        return parts;
    }();
    InstancedSolve solve(scene, receivers, shadows, tree, originals, options, out);
    // What the setup freed (the signatures, the scratch of the functions', the tree's and
    // the ray engine's builds) goes back before the local problems, when it is much: on
    // the daemon's growing 1,000-leaf plant a trim at every cycle cost 10 ms of its
    // median 60 for the little it gave back (the heap walked, its pages faulted in anew).
    constexpr std::size_t kWorthHandingBack = std::size_t{16} << 20;
    if (FreeHeapBytes() >= freeAtStart + kWorthHandingBack) HandFreedPagesBack();
    const auto start = std::chrono::steady_clock::now();
    OnCores(threads, [&] { solve.Run(); });
    out.stats.solveSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The structures solved whole by node, and the problems by depth and size, whatever
    // order the threads solved them in.
    std::sort(out.solution.wholeStructures.begin(), out.solution.wholeStructures.end(),
              [](const StructureLight& a, const StructureLight& b) { return a.node < b.node; });
    if (out.solution.wholeStructures.empty()) {
        out.solution.unsolved.clear();
        out.solution.pushedDown.clear();
    }
    std::sort(out.stats.problems.begin(), out.stats.problems.end(),
              [](const InstancedStats::Problem& a, const InstancedStats::Problem& b) {
                  return std::tie(a.depth, a.triangles, a.elements, a.links) <
                         std::tie(b.depth, b.triangles, b.elements, b.links);
              });
    out.stats.originalsComputed = originals.computed;
    out.stats.originalsReused = originals.reused;
    out.stats.originalSeconds = originals.computeSeconds;
    out.stats.reuseSeconds = originals.reuseSeconds;
    const std::int64_t rays = out.solution.stats.rays;
    clock.Stamp(out.solution.stats);
    out.solution.stats.rays = rays;
    out.solution.stats.threads = threads;
    out.stats.peakRssBytes = out.solution.stats.peakRssBytes;
    spdlog::debug("instanced: {} parts, {} originals computed, {} reused", tree.Parts().size(),
                  originals.computed, originals.reused);
    return out;
}

}  // namespace leaflux
