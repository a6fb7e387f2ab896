// Hierarchical radiosity with clustering (`hrc`), the paper's baseline (Soler 2003 §3.1,
// after Smits 1994 and Sillion 1995), with two-sided leaves (§4.3).
//
// Links join the nodes of a Hierarchy (clusters and patches) and the directional sources (suns,
// sky cones) to nodes. A link between clusters carries light as a point transfer I_S(ω) · v / d²,
// the sender's intensity sampled on a tetrahedral direction set (DirectionSet, §4.2.2) and the
// receiver's incoming light kept per direction, so that clusters emit and receive as volumes with
// no assumption of flatness; a patch's cosine lobe, interpolated between the directions, is scaled
// to integrate to π per side as the lobe does. A flat cluster (a leaf of coplanar triangles, a
// wall) sends and takes light as its plane does, as a patch. A link between two patches uses the
// analytic point-to-polygon form factor, bounded in the near field, averaged over seven points
// of the receiver (three to judge it); between two planes, one of them a flat cluster, the
// same from the sender's parts at three points with the moments of the receiver's area. A
// cluster hands the light it gathers to its children weighted by how open each is towards it
// inside the cluster (HrcOptions::exposureRays). Visibility is the unoccluded fraction of
// deterministic stratified rays through Embree, each ray weighted by the form factor's kernel.
//
// Refinement: a link is split (the larger node, or a patch subdivided into four) while its
// estimated error — the power it carries times its geometric error ((r_R + r_S)/d)² plus its
// visibility spread 2√(v(1−v)), v the fraction of its rays that pass — exceeds ε times the power
// the suns and sky cones bring onto the organs (and the lamps' power; less for links into
// clusters of organs: from the suns and sky cones ε / √(their number), from surfaces
// HrcOptions::clusterTolerance; more for links into surfaces far from the organs,
// NodeModel::Importance); the candidate links are
// judged in parallel chunks and the verdicts carried out in order, so the links do not depend on
// the number of threads. A link kept only because its rays agreed takes its transfer from rays of
// its own, so that the choice of links does not bias the light they carry. Solution: Jacobi
// gathering with push/pull (B₁ = ρ₁I₁ + τ₂→₁I₂, B₂ = ρ₂I₂ + τ₁→₂I₁; what is pulled up is the
// intensity of both sides), accelerated by extrapolating the geometric series of the changes and
// iterated until the change still to come is below the tolerance; between solutions every link is
// judged again with the light found (refine–solve passes), so that senders dark when first linked
// are refined too.
//
// The engine is a set of units, each in its own file, that this whole-scene driver (hrc.cpp)
// runs and that other drivers reuse: hierarchy (cluster creation), node_model (what each node
// answers), quadrature and estimate (form factors, transfers, geometric error), visibility,
// exposure, refinement (linking, judging, splitting, judging again), traversal and push_pull,
// gathering (sweeps and convergence), outputs and link_audit, closed_node and
// closed_scattering (closed instances); channels and light_state hold the per-node light of
// a run-time number of channels (bands × beams).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/closed_node.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/warm_start.h"
#include "solver/raytrace/raytrace.h"
#include "solver/results/light.h"

namespace leaflux {

struct HrcOptions {
    // Largest error a link may carry, as a fraction of the power the suns and sky cones
    // bring onto the organs, unoccluded (and the lamps' power): a leaf's accuracy does not
    // depend on the ground or walls around it.
    double epsilon = 1e-4;
    // A link into a cluster of organs hands every organ under it the cluster's mean light:
    // one hidden in the cluster gets too much from every such link, an exposed one too
    // little, so on an organ their errors add up where those of links into single patches
    // average out. From the suns and sky cones, such links may carry ε / √(their number);
    // from surfaces, ε times this. Against 1, 0.3 gave the canopies less error for the
    // time (the 500-leaf NIR canopy 0.98 % L2 at ε = 2e-4 where 1 gave 1.08 %, for 5 %
    // more time; the dense canopy at 1e-4 1.76 % where 1 needed 5e-5 and 25 % more time
    // for 1.78 %), the tray its balance (1.1 % short at 1e-3 instead of 3.1 %), and left
    // the trees and the greenhouse as they were for the time: measured before exact links
    // took seven points (README, "The hierarchical radiosity solver").
    double clusterTolerance = 0.3;
    int maxSubdivision = 3;  // a triangle splits into at most 4^this patches
    int visibilityRays = 8;  // per link (stratified pairs of points)
    // Per link from a sun or a sky cone: direct light is most of what a leaf gets, and
    // there are few such links.
    int sourceRays = 32;
    int directionLevel = 2;  // direction set of cluster light: 2 → 34 directions
    // A cluster hands the light it gathers to its children weighted by how open each is
    // towards the light within the cluster (exposure.h): rays per child and
    // direction of the 10-direction set. 0: evenly by area facing the light, as the clusters
    // of Sillion 1995. It costs 80 short rays per node: 2–5 % of the 500-leaf canopy's time,
    // 10–20 % of the 10k tree's, whose error it leaves as it was (README).
    int exposureRays = 8;
    double tolerance = 1e-5;  // iteration stops when the change still to come is less
                              // than this times the largest radiosity
    int maxIterations = 2000;
    // Direct light only: one gathering sweep from the sources and lamps, no links for
    // light scattered by leaves and surfaces (it shows as missing in the energy balance).
    bool directOnly = false;
    // The light vectors (∫ L dω, ∫ L ω dω per leaf): false leaves them zero and gathers
    // only each side's irradiance.
    bool lightVectors = true;
    // After the solve, every kind of link against rays from the receivers, and the
    // partition of the exchanges among the links checked (Solution::linkAudit).
    bool auditLinks = false;
    int threads = 0;  // 0: every core of the calling task arena (all, outside one)
    // Called with the fraction of the solve done (0 to 1), when set: a progress bar. The
    // solve's stages take fixed parts of it (hrc.cpp, the Stage constants); within a stage, the
    // refinement counts the parts of its tasks carried out and the iteration how far its
    // change has fallen towards `tolerance`.
    std::function<void(double)> progress;
    // A continuous sky is discretised into these cones for the hierarchy's links.
    SkyDiscretization skyCones = SkyDiscretization::kTurtle46;
    // A closed instance sends what its phase function makes of its light towards each
    // direction of the cluster light's set; false: the same power alike in every direction,
    // the single value of Soler 2003 (§6 names it the main error at small ε).
    bool directionalInstances = true;
    // Where set, the leaves of the organs it has start from the light they had there
    // instead of from the direct light alone (warm_start.h): a cold start's answer within a
    // small part of what ε costs, in fewer sweeps where the light changed little.
    std::shared_ptr<const WarmStart> warmStart;
};

// `closed`: closed instances beside the scene's geometry (closed_node.h), each under the
// scene node it names, in the flat scene's frame; they are not receivers and get no output.
// Their own absorption is outside the energy balance.
Solution SolveHrc(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                  const HrcOptions& options, std::span<const ClosedNode> closed = {});

// The scene solved whole, then the structure under scene node `root` solved again alone as
// a local problem (Soler 2003 §3.3–3.4): everything outside it held fixed — the links that
// reach into it from outside, copied with their senders never split nor updated, the
// directional sources' links into it, and the light its ancestors hand down — its own
// exchanges refined again from its own emission under the whole solve's threshold. `local`
// has the structure's receivers' light (the others' are zero); its balance is the
// structure's.
// One structure alone under unit parallel beams from each of `towardSource` (unit
// irradiance normal to each beam), the beams as channels of one solve, for the links do not
// depend on where the light comes from (Soler 2003 §4.2.3): channel k · bands + b is band b
// of beam k, and refinement judges each beam as a scene of its own (kWorstBeam). The answer
// is every leaf patch's radiosity, from which a phase function is read.
struct BeamPatch {
    glm::dvec3 a, b, c, normal;  // the flat scene's frame; normal: the upper side
    double areaM2;
    std::uint32_t triangle;  // its flat triangle, which rays leaving it ignore
};
struct BeamSolution {
    Channels channels;
    std::vector<BeamPatch> patches;
    // Exitance (W/m² per W/m² of beam): [patch][side][channel], side kUpper then kLower.
    std::vector<double> radiosity;
    std::vector<double> absorbedW;  // per channel (W per W/m² of beam)
    SolveStats stats;
    const double* Radiosity(std::size_t patch, int side) const {
        return radiosity.data() + (2 * patch + side) * channels.Count();
    }
};
BeamSolution SolveBeams(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                        const HrcOptions& options, std::span<const glm::dvec3> towardSource);

// One level of hierarchical instantiation (Soler 2003 §3.3–3.4; solver/instancing/instanced.h):
// a part of a scene — the top with its largest instances closed, or an opened instance's
// contents with its smaller instances closed — solved as a scene of its own: lit by the
// given sources, its rays meeting what lies outside it through the occlusion's outside view,
// its links refined under the threshold the top level chose.
struct LevelProblem {
    const Occlusion* occlusion = nullptr;  // rays' scene with `closed`'s proxies; null: its own
    // The suns and sky cones, and the light that arrived from the rest of the scene
    // (DirectionalSource::beyond false); empty: the scene's suns and sky cones.
    std::vector<DirectionalSource> sources;
    // The error a link may carry (W) and how many sources share it on a cluster of organs
    // (Thresholds); errorW 0: ε times the power the sources bring onto its organs.
    double errorW = 0.0;
    std::size_t sourceCount = 0;
    // With errorW 0: Σ A |n · ω| over the organs whose unoccluded projected area scales ε,
    // in place of the level's own organs and closed instances (the top of an instanced
    // solve: every organ in every instance, so that ε means what it means to HRC on the
    // flattened scene). Empty: the level's own.
    std::function<double(const glm::dvec3& omega)> organsProjectedArea;
    // Whether to tell apart, of what arrived on each closed instance, the light of the
    // level's surfaces (LevelSolution::surfaceBins), and to hand them on (surfaces).
    bool splitSurfaces = false;
    // Whether to hand on, besides the surfaces, the organs' triangles (each with the area
    // mean of its patches) and each closed instance's intensity (closedIntensity), so that
    // an opened instance can hold the whole level it was closed in (Soler 2003 §3.4: the
    // links that arrived on it, copied with their senders held fixed) instead of taking
    // its light per bin.
    bool holdLevel = false;
};
struct LevelSolution {
    Solution solution;  // its receivers' light (those of the flat scene given)
    std::vector<DirectionalSource> sources;
    double errorW = 0.0;
    std::size_t sourceCount = 0;
    int bins = 0;  // of the cluster light's direction set (HrcOptions::directionLevel)
    // Per closed instance, what arrived on it: from the level's nodes per bin, [bin][channel]
    // in W/m² normal to the bin; and the visibility of each of the level's sources.
    std::vector<std::vector<double>> arrivedBins, sourceVisibility;
    // With LevelProblem::splitSurfaces: the part of arrivedBins that the links from
    // surfaces brought (nodes holding no organ nor closed instance: a ground, walls, lamps,
    // surfaces held from further out), and the level's own surfaces' patches as solved
    // (not those held), so that an opened instance can hold them (ReceiverKind::kHeld)
    // and take their light with its parallax across it.
    std::vector<std::vector<double>> surfaceBins;
    struct SurfacePatch {
        glm::dvec3 a, b, c;                // world frame; the upper side by a, b, c
        std::vector<double> upper, lower;  // exitance per channel (W/m²)
        std::uint32_t surface = 0;         // the level's receiver it is part of
        bool lamp = false;                 // a piece of a black lamp (NodeModel::Lamp)
    };
    std::vector<SurfacePatch> surfaces;
    // With LevelProblem::holdLevel: per closed instance (not held), its intensity as solved,
    // [bin][channel] in W/sr (ClosedNode::held); `surfaces` then has the organs' triangles too.
    std::vector<std::vector<double>> closedIntensity;
};
LevelSolution SolveLevel(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                         const HrcOptions& options, std::span<const ClosedNode> closed,
                         LevelProblem problem);

struct LocalSolve {
    Solution whole, local;
};
LocalSolve SolveHrcThenLocal(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                             const HrcOptions& options, NodeId root);

}  // namespace leaflux
