// Hierarchical instantiation (`instanced`, Soler 2003 §3.2–3.5, Fig. 4–6): the scene's
// structures that the policy gives a signature become instances of a shared original
// (phase function and transmittance, from the phase-function database), and the scene is
// solved one part at a time (instance_tree.h), so that the memory in use follows the depth
// of instances rather than the size of the scene.
//
// 1. The top: everything that lies in no instance, with the largest instances closed
//    (closed_node.h): links reach them but are not refined into them, they have no
//    self-link, rays through them are attenuated by τ(ω), and each sends what its phase
//    function makes of the light that arrived on it, per direction of the cluster light's
//    set (HrcOptions::directionalInstances: false sends the paper's single value).
// 2. Opening an instance (§3.4, Fig. 6): its contents are built as a local hierarchy, its
//    smaller instances closed, and solved as a scene of its own (SolveLevel) under the
//    light that arrived on it, held fixed: the suns and sky cones, their rays meeting the
//    whole scene outside it (OutsideView: the levels it lies in, their closed instances
//    but it); and everything the levels it lies in hold that sends light, as solved there
//    and held fixed (InstancedOptions::holdOutside): the surfaces' and organs' patches
//    (ReceiverKind::kHeld: each sends its radiosity and receives nothing) and the other
//    closed instances, each sending the intensity it sent there (ClosedNode::held).
//    These are linked to the contents as any sender is, with their parallax across them
//    and, by geometry, through the whole scene's organs: the paper's copies of the links
//    that arrived on the instance, made again from their senders. A closed instance
//    whose bounds the contents overlap lights them from all around (HeldAroundLinks).
//    Its links are refined under the top level's threshold, so that ε means the same at
//    every depth. Its leaves' light is written as they are reached, its smaller
//    instances opened in turn — siblings in parallel, each a problem of its own, so the
//    answer does not depend on the number of threads — and then it is freed.
//
// Without holdOutside, only the top's surfaces are held; what other instances and the
// levels' organs sent arrives as the instance's incoming light per direction bin (34
// directions at the default level), the same at every point of it: cheaper, and its
// branches share that light too evenly (the generated trees of 10,000 and 44,500 leaves:
// NIR 2.83 and 3.72 % L2 off the reference against 2.43 and 3.25 % held, in 0.79 and 0.70
// of the time, docs/results.md). Held as bins, the ground's light came down to the leaves
// as the instance's centre sees it: the lower sides got twice what they get from the
// ground (under the crown the ground is in its shadow). The direct light, most of what
// leaves get, is traced from every point through the whole scene.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "solver/instancing/compute_original.h"
#include "solver/instancing/phase_db.h"
#include "solver/instancing/policy.h"
#include "solver/radiosity/hrc.h"
#include "solver/results/light.h"
#include "solver/results/organ_sink.h"

namespace leaflux {

struct InstancedOptions {
    HrcOptions hrc;  // every level's radiosity, and ε
    // How an original missing from the database is computed; the policy sets the kinds
    // and direction sets of its functions (SettingsOf).
    OriginalSettings originals;
    // Where opening stops (Soler 2003 §7.1): an instance deeper than maxDepth (1: the
    // largest; 0: no limit) stays closed, and so does one holding no instance of type
    // outputLevel when it is set (kAxis: light per branch; the smallest branches the
    // policy instantiates are never built into a hierarchy of their leaves), unless it is
    // of another type and holds structures of the type that are not instances (a plant
    // whose axes are too small to be instances opens, so that they are solved). A
    // structure left closed is solved whole from the light that arrived on it and its
    // original (Solution::wholeStructures): its absorbed power is that light times the
    // original's absorption per direction (scaled by organ area as f is); its light vector
    // is that of the light arriving on its box; its leaves' irradiances are not solved.
    int maxDepth = 0;
    std::optional<NodeType> outputLevel;
    // A structure solved whole hands its light down to its organs (push_down.h), which are
    // then in the organ results, marked Solution::pushedDown: approximate. Off, they are
    // left out (Solution::unsolved).
    bool pushDown = false;
    // When set, an instance opens only if this accepts its box in the world (the bounds of
    // its box's corners): a picture opens only the instances in view (Soler 2003 §7.1,
    // leaflux render). The others are solved whole, as beyond maxDepth.
    std::function<bool(const glm::dvec3& worldMin, const glm::dvec3& worldMax)> inView;
    // What an opened instance takes from the level it was closed in (Soler 2003 §3.4). True:
    // that level's organs' patches (each organ's triangles as its own, the area mean of
    // their parts), its surfaces' patches and its other closed instances, held fixed as
    // solved there, and what that level held in turn, each linked into the contents and
    // refined there, so that the light keeps its parallax across the instance: the
    // paper's link copies. False: the light that arrived on the closed instance per
    // direction bin, the same at each of its points (the top's surfaces still held);
    // cheaper, less accurate in scattered light.
    bool holdOutside = true;
    // An opened instance of at most this many organ triangles in all, whose smaller
    // instances would all open by maxDepth (inView is not asked: those out of view are
    // solved with the rest), is solved as one local problem with them, their organs
    // among its own (InstanceTree::Merge), rather than with them closed and each opened in
    // turn: below some size a structure's own problem costs more than its leaves solved
    // with its neighbours', and its phase function is not needed. Ignored with outputLevel
    // (the command line and the daemon refuse the two together). 0: every instance a problem
    // of its own.
    std::int64_t mergeTriangles = 0;
    // When set, each organ's light goes here as it is solved, and Solution::light stays
    // empty: what a plantation's memory would otherwise hold to the end. Its other
    // receivers' too (the top's surfaces and emitters).
    OrganSink* organSink = nullptr;
};

struct InstancedStats {
    struct Depth {
        int instances = 0;  // structures instantiated at this depth (1: the largest)
        int opened = 0;
        int whole = 0;   // left closed and solved whole (maxDepth, outputLevel)
        int merged = 0;  // solved in the problem of an instance holding it (mergeTriangles)
    };
    std::vector<Depth> depths;  // [0] is the top
    // Every part solved, the top first: the local problems' sizes (Fig. 14, right).
    struct Problem {
        int depth = 0;
        std::int64_t triangles = 0, closed = 0, elements = 0, links = 0;
        double seconds = 0.0;
    };
    std::vector<Problem> problems;
    int originalsComputed = 0, originalsReused = 0;
    double originalSeconds = 0.0;  // computing the missing originals
    double reuseSeconds = 0.0;     // finding the reused ones (SceneOriginals::reuseSeconds)
    double solveSeconds = 0.0;     // everything else
    std::int64_t peakRssBytes = 0;
};

struct InstancedSolution {
    Solution solution;  // by the receivers of `receivers` (ReceiversOf the scene)
    InstancedStats stats;
};

// `scene` validated and not periodic; `flat` its flat scene, or its receivers alone
// (ReceiversOf) when `shadows` is null. `shadows`: the flat scene's rays, which the direct
// light from the suns and sky cones then meets instead of the closed instances' τ (exact
// shadows, for the memory of the whole scene's triangles). Throws InputError
// (kUnsupported) for a periodic scene.
InstancedSolution SolveInstanced(const Scene& scene, const FlatScene& flat, const RayScene* shadows,
                                 const InstancingPolicy& policy, PhaseDatabase& database,
                                 const InstancedOptions& options);

}  // namespace leaflux
