// The visibility of links and source links: the unoccluded fraction of what a link
// carries, from deterministic stratified rays through the ray engine (Occlusion: triangles
// block, closed instances pass their τ), and how far those rays disagreed (the spread
// refinement weighs). A ray from or to a point of a closed instance leaves that instance
// out. Reads the hierarchy, the node model and
// the light leaving the nodes (rays from a cluster are weighted by it); owns nothing.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <vector>

#include "solver/radiosity/directional_source.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/node_model.h"
#include "solver/raytrace/occlusion.h"
#include "solver/util/lattice.h"

namespace leaflux {

// How uncertain a visibility estimated from n rays is, as 2√(v(1−v)) with v taken by
// Laplace's rule, (visible + 1) / (n + 2): never zero, since eight rays that all pass do
// not prove that nothing is in the way. At most 1 (kWidestSpread), for v = ½.
inline constexpr double kWidestSpread = 1.0;
inline double VisibilitySpread(double visible, int rays) {
    const double v = (visible * rays + 1.0) / (rays + 2.0);
    return 2.0 * std::sqrt(v * (1.0 - v));
}

// The two sets of visibility rays of a link, as random streams: those that judge it and
// those that value its transfer where the verdict rested on the first (Refiner::Value).
enum class RaySet : std::uint64_t { kJudging = 0x5EED, kValuing = 0x5EEE };

// What a link's rays showed so far (LinkVisibility::Between), to go on from. They come in
// two rounds: the even points of the link's lattice, a lattice of half as many, then the
// odd ones, traced only where the first round leaves the verdict open (Refiner::JudgePair).
struct LinkRays {
    // The rays of the first round, of `count`: half, where even and at least 4.
    static int First(int count) { return count >= 4 && count % 2 == 0 ? count / 2 : count; }
    int taken = 0;   // rays taken so far, traced or not (their ends turned away)
    int traced = 0;  // and traced
    double passed = 0.0;
    double visible = 0.0, total = 0.0;            // each ray weighted by what it carries
    double visibleLight = 0.0, totalLight = 0.0;  // and by the light its sender's point sends
};

// What a link's rays show.
struct Sight {
    double visibility = 0.0;
    // How far the rays disagreed (VisibilitySpread of the fraction that passed): the
    // weighted visibility can be 0 or 1 while they did not, one near ray outweighing the
    // rest.
    double spread = 0.0;
};

// The rays of each source's links: `base`, and more for a source that brings much of the
// light, up to twice `base` for one that brings it all: 2 base √(its share of the sources'
// normal irradiance), rounded up. A leaf takes each source's light through one link, whose
// visibility varies by v(1 − v)/n from n rays; light spread over many cones averages their
// errors out, a sun's is its own. A sun's shadow edges were the 119k-leaf tree's largest
// error: its sun (78 % of the light) at 57 rays and the 46 sky cones at 32 took its PAR
// from 1.66 to 1.34 % L2 of max, its NIR from 2.16 to 1.97 %, for 11 % more rays
// (instanced, ε = 1e-4); all at 64, PAR to 1.29 % for 35 % more; the sun at 64 and the
// cones at 8, 1.39 %: a cone's link sits on a cluster, whose leaves all share its noise.
std::vector<int> SourceRayCounts(std::span<const DirectionalSource> sources,
                                 const Channels& channels, int base);

class LinkVisibility {
  public:
    // Along a ray from p towards a held surface, `length` long; `inside`: a held closed
    // instance the ray ends in, whose own organs it passes (what they take of its light is
    // in the intensity it sends).
    double HeldTransmittance(const Hierarchy::Point& p, const glm::dvec3& direction, double length,
                             const ClosedNode* inside = nullptr) const;
    // `sourceRays`: the rays of a link from a source of `sources`, more from one that brings
    // much of the light (SourceRayCounts).
    // `suns`: the maps of the suns over the hierarchy's own triangles (the whole scene's
    // for a level with the whole scene's shadows, ShadowView::suns).
    LinkVisibility(const NodeModel& model, const Field& field, const Occlusion& occlusion,
                   int visibilityRays, int sourceRays, std::span<const DirectionalSource> sources,
                   const SunMaps* suns = nullptr);

    int VisibilityRays() const { return visibilityRays_; }
    // The rays estimating the visibility of a link from source s.
    int SourceRays(std::uint32_t s) const { return sourceSampling_[s].lattice->Count(); }

    // rays between points x of r and y of s, each weighted by what it carries, the form
    // factor's kernel |cos θx| |cos θy| / |x − y|² (the receiving cosine as push-down hands
    // the light to patches). Unweighted, far pairs count as much as near ones and are more
    // often blocked: the 500-leaf canopy at ρ = τ = 0.45 lost 2.3 % of its NIR that way.
    // The points are spread over both ends, each end's on a rank-1 lattice (RankOneLattice),
    // the sender's paired with the receiver's in a random order (RandomStrata): each child of
    // a sending cluster gets its
    // share of the rays (drawn at random, the eight rays of a two-leaf cluster whose lower
    // leaf is hidden fell so that it sent 13 % too little: HrcExposure.AClusterSendsOnly…),
    // and no pair of strata is favoured (paired in a fixed order, the closed box of
    // ρ = 0.999 lost 1.2 % of its light, 0.19 % now).
    // Between two patches, the share of the form factor that is visible, from points x of
    // r each weighted by its estimate of its own form factor F(x → s); where s is near,
    // along a direction uniform in its solid angle (BetweenPatches): a visibility in [0, 1]
    // that follows F across r. Valued instead as the analytic form factor less the blocked
    // part that rays to uniform points of s find, it fell below 0 on 3.7 % of the dense
    // canopy's patch links at ε = 1e-5, which carried −0.34 % of its light; made
    // non-negative by more rays and a cut at 0, it gained 0.6 % of its NIR. From a cluster, each
    // ray is weighted as well by the radiosity of y's side facing x, all bands: the link carries
    // the visible share of the light the cluster sends, not of its area, and the leaves of a crown
    // that a ground patch sees are its outer, sunlit ones. Weighted by area alone, the 10k tree's
    // links from clusters into ground patches handed on 0.74 of what rays from their senders landed
    // (the audit of then) and its NIR balance was 0.83 % off; now 0.80 and 0.38 %. The radiosity is
    // that of when the link is valued: the direct light's at first, the solution's in the
    // refine–solve passes. In a local problem the rays meet its own triangles and closed instances
    // only (Occlusion::LocalTransmittance): the rest of the scene's shadow on its inner exchanges
    // is left out (on the 10k tree, no worse for 40 % less time). Counts the rays it traces in
    // `rays`. From a surface held from outside a local problem (NodeModel::Held), the rays meet the
    // whole scene's organs where the occlusion has them (ShadowView: exact shadows), else
    // what lies outside the problem as well (Occlusion::Transmittance).
    Sight Between(std::uint32_t r, std::uint32_t s, RaySet set, std::int64_t& rays) const;
    // The same from the link's first `upTo` rays, going on from those of `tally`.
    Sight Between(std::uint32_t r, std::uint32_t s, RaySet set, std::int64_t& rays, LinkRays& tally,
                  int upTo) const;

    // The lit fraction of node r's area as seen from directional source `source`: sample
    // points, each with a direction of the source's cone (stratified over it; one folded
    // back above the horizon where a sky cone dips below it, as the reference does),
    // weighted by |n · ω|, the weight with which push-down hands the source's light to each
    // patch. The points lie on a rank-1 lattice, which resolves a shadow edge across r in
    // both coordinates: stratified along one alone, the 10,000-leaf tree's PAR was 1.81 %
    // off the reference (L2, HRC at ε = 1e-4), 1.20 % now, for the same rays.
    // `set` picks the stream of rays, as for links between nodes; `rounds`: so many lattices
    // of rays, each shifted at random, together.
    // Through the whole scene's triangles (ShadowView), a closed instance's visibility is the
    // share of the light on its organs, lit past their own selves, that the rest of the scene
    // lets through: points of its organs (ClosedOrganLight), each weighted by its triangle's
    // area across the light, lit past everything over those lit past its own organs (what
    // they take of one another's light is in its phase function). Taken from where rays from
    // points of its box left the box, a neighbour's leaves inside the box never shaded it: in
    // the stand scenario at cycle 20 the middle plant, solved whole, took 4.3 times the
    // reference's light, and three crowns grown into one another 6 to 13 % too much direct
    // light (Instanced.PlantsSolvedWholeInEachOthersCrownsTakeTheirShade); along lines through
    // the box to the first organ each meets, the few lines that meet a sparse crown's organs
    // left it 5 % off.
    double FromSource(std::uint32_t r, std::uint32_t source, const DirectionalSource& light,
                      RaySet set, std::int64_t& rays, int rounds = 1) const;
    // The lit fraction of organ node r's area as its sun's map has it (SunMap), weighted
    // as FromSource weights its points; none where source s has no map, or r is a part of
    // a triangle, or no pixel of the map fell on its triangles that take the light.
    std::optional<double> Mapped(std::uint32_t r, std::uint32_t source) const;

  private:
    // The direct light on a point of closed instance c's organs from a light (unit
    // `toward`), in the whole scene's shadow engine, drawn from point x of its box
    // (Hierarchy::SampleClosed's three coordinates): one of its organs' triangles taken
    // evenly, a point of it, weighted by the triangle's area across the light
    // (ClosedOrganPoint, weight 0: none); then, from the first triangle the ray from it
    // meets, whether the point is lit past the instance's own organs, and past everything
    // of the scene (ClosedOrganLight). The rays of a link are traced together between.
    struct OrganPoint {
        RayStart start;
        double weight = 0.0;
    };
    struct OrganLight {
        bool ownLit = false, lit = false;
    };
    OrganPoint ClosedOrganPoint(std::int32_t c, const glm::dvec3& x,
                                const glm::dvec3& toward) const;
    OrganLight ClosedOrganLight(std::int32_t c, const RayHit& hit, const glm::dvec3& toward) const;
    Sight BetweenPatches(std::uint32_t r, std::uint32_t s, RaySet set, std::int64_t& rays,
                         LinkRays& tally, int upTo) const;
    // What passes along a link's ray from p, `length` long, towards an end inside closed
    // instance `closedEnd` (−1: none) or a surface held from outside (`held`): 0 or 1
    // through triangles alone, else the transmittance, the ray's own ends left out.
    double Passed(const Hierarchy::Point& p, std::int32_t closedEnd, const glm::dvec3& direction,
                  double length, bool held) const;
    // How far a ray from `from` along unit `direction` goes before it enters the box of
    // held closed instance `closed` (0 from inside it).
    double HeldEntry(std::int32_t closed, const glm::dvec3& from,
                     const glm::dvec3& direction) const;
    // What a sender's point q sends towards the ray (from the receiver, towardQ), all
    // channels: the radiosity of a patch's side facing it, a closed instance's radiance.
    double Brightness(const Hierarchy::Point& q, const glm::dvec3& towardQ) const {
        if (q.closed >= 0) return ClosedBrightness(q.closed, towardQ);
        return model_.SideRadiosity(field_, hierarchy_.PatchOf(q.triangle),
                                    glm::dot(q.normal, towardQ) < 0.0 ? kUpper : kLower);
    }
    double ClosedBrightness(std::int32_t closed, const glm::dvec3& towardQ) const;

    const Hierarchy& hierarchy_;
    const NodeModel& model_;
    const Field& field_;
    const Occlusion& occlusion_;
    const int visibilityRays_;
    // Where each end's rays start (its points are looked up once, not per link).
    const RankOneLattice& visibilityLattice_;
    // How the links from a source are sampled: the points of their receivers, and a sky
    // cone's directions, a grid of rings × turns of exactly the rays' count, each cell
    // taken once (of a grid with more, the cells left over would never be sampled), its
    // cells shuffled against the points.
    struct SourceSampling {
        const RankOneLattice* lattice;
        int rings, turns;
    };
    std::vector<SourceSampling> sourceSampling_;
    // Per source, its map (a sun's), or null; and where the map's triangles are the whole
    // scene's, the whole scene's triangle of each of the hierarchy's (ShadowView).
    std::vector<const SunMap*> sunMap_;
    const std::vector<std::uint32_t>* mapTriangleOf_ = nullptr;
};

}  // namespace leaflux
