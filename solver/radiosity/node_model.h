// What each node of a hierarchy answers, whatever drives the solve: whether it sends and
// takes light as a plane, its area projected towards a direction, the intensity it sends,
// how a point on it takes light, whether it can split, and the plane parts whose form
// factors add up to its own. Invariant: the per-node tables cover the hierarchy as built
// (its clusters never change); patches added by subdivision answer from their own triangle.
// The model owns those tables; the hierarchy, flat scene and ray scene are the caller's.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/hierarchy.h"
#include "solver/radiosity/light_state.h"
#include "solver/raytrace/raytrace.h"
#include "solver/util/directions.h"

namespace leaflux {

class NodeModel {
  public:
    // `directions`: the set through which clusters send and take light (§4.2.2).
    NodeModel(Hierarchy& hierarchy, const Scene& scene, const RayScene& rays,
              const DirectionSet& directions, const Channels& channels, int maxSubdivision);

    const Hierarchy& Nodes() const { return hierarchy_; }
    const DirectionSet& Directions() const { return directions_; }
    const Channels& ChannelSet() const { return channels_; }
    int BinCount() const { return bins_; }

    // Whether node n sends and takes light as a plane: a patch, or a flat cluster (a leaf of
    // coplanar triangles, a wall) with no inner side of a solid under it, whose light then
    // needs no direction set. Through the set, a two-triangle leaf's light was too strong in
    // the directions of its links (the interpolated lobe's shape): on the 500-leaf canopy at
    // ε = 1e-5 the links between such leaves handed on 1.029 of what rays from their
    // receivers find.
    bool Planar(std::uint32_t n) const {
        return hierarchy_[n].patch || (n < planes_.size() && planes_[n]);
    }
    // Whether side `side` of a triangle faces the inside of its own solid (an internode,
    // a fruit): it then gets no light.
    bool Inner(std::uint32_t triangle, int side) const {
        return triangle != kNoTriangle && inner_[triangle] >> side & 1;
    }
    // How much a receiving point of normal n on a triangle takes of light from ω: |n · ω|,
    // but nothing on the inner side of a solid.
    // A point in a closed instance's box takes light from every direction alike: 1.
    double ReceivingWeight(std::uint32_t triangle, const glm::dvec3& n,
                           const glm::dvec3& omega) const {
        if (triangle == kNoTriangle) return 1.0;
        const double cosine = glm::dot(n, omega);
        return Inner(triangle, cosine > 0.0 ? kUpper : kLower) ? 0.0 : std::abs(cosine);
    }
    // The closed instance node n is, or null.
    const ClosedNode* Closed(std::uint32_t n) const {
        const std::int32_t c = hierarchy_[n].closed;
        return c >= 0 ? &hierarchy_.Closed()[c] : nullptr;
    }
    // Whether a link into node r hands the same light to organs that may see it unevenly:
    // r is a cluster with organs under it (a closed instance is one).
    bool Shared(std::uint32_t r) const { return !hierarchy_[r].patch && organs_[r]; }
    // n holds only surfaces and closed instances held from outside a local problem
    // (ReceiverKind::kHeld, ClosedNode::held): it sends its held light and receives nothing.
    bool Held(std::uint32_t n) const {
        const HrcNode& node = hierarchy_[n];
        return node.patch ? flat_.receivers[node.receiver].kind == ReceiverKind::kHeld
                          : held_[n] == kAllHeld;
    }
    // n holds an emitter or what is held from outside a local problem: light not scattered
    // by the surfaces solved with it, which may be all some organs get.
    bool FirstHand(std::uint32_t n) const {
        const HrcNode& node = hierarchy_[n];
        if (!node.patch) return held_[n] != 0 || emitters_[n] != 0;
        const ReceiverKind kind = flat_.receivers[node.receiver].kind;
        return kind == ReceiverKind::kEmitter || kind == ReceiverKind::kHeld;
    }
    // n is a cluster holding both: what lands on it would reach held parts, which receive
    // nothing, and its points may be theirs. It is split before anything links to it.
    bool PartlyHeld(std::uint32_t n) const {
        return !hierarchy_[n].patch && held_[n] == kPartlyHeld;
    }
    // n is an organ's patch, or a cluster with organs under it.
    bool HoldsOrgans(std::uint32_t n) const {
        const HrcNode& node = hierarchy_[n];
        return node.patch ? flat_.receivers[node.receiver].kind == ReceiverKind::kOrgan
                          : organs_[n] != 0;
    }
    // n lies within one organ: a patch of it, or a cluster of its triangles alone.
    bool OneOrgan(std::uint32_t n) const {
        return hierarchy_[n].patch ? HoldsOrgans(n) : organOf_[n] != kNoOrgan;
    }
    // How much a node's own error matters to the organs, as a factor on its links'
    // threshold: 1 for organs. A surface's error reaches the organs only through the light
    // it sends on, the share ρ + τ of what it takes (its largest over bands and sides,
    // Onward), and only the part of that the organs intercept: at most all of it within
    // the organs' bounding sphere's radius of them; beyond, a part falling as 1 / (1 + (d /
    // R)²), d the gap between the node and that sphere of radius R. A 200 m ground is then
    // fine under the canopy and coarse far from it, and a dark soil (ρ = 0.1) is split ten
    // times less finely than a white floor would be: the 7 suns' shadows of a stand's
    // young plants were resolved on its ground to ε of the plants' own small light.
    double Importance(std::uint32_t n) const {
        if (organsRadius_ <= 0.0 || HoldsOrgans(n)) return 1.0;
        const HrcNode& node = hierarchy_[n];
        const double gap =
            std::max(0.0, glm::length(node.centre - organsCentre_) - organsRadius_ - node.radius);
        return (1.0 + (gap / organsRadius_) * (gap / organsRadius_)) /
               std::max(Onward(n), kLeastOnward);
    }
    // n's surfaces are all lamps without optics (black emitters): its light is its
    // exitance, even over it.
    bool Lamp(std::uint32_t n) const {
        const HrcNode& node = hierarchy_[n];
        return node.patch ? lampOf_[node.receiver] != 0 : lamps_[n] != 0;
    }
    // The largest share of the light it takes that a node's surfaces send on, ρ + τ, over
    // bands and sides: 1 over an organ or a closed instance. (Clusters are never built
    // after the model: onward_ covers them.)
    double Onward(std::uint32_t n) const {
        const HrcNode& node = hierarchy_[n];
        return static_cast<double>(node.patch ? onwardOf_[node.receiver] : onward_[n]);
    }

    // The side of patch p facing direction d of the set and p's lobe |n · ω| there, scaled
    // so that each side's interpolated lobe integrates to π (ScaleLobes).
    std::pair<int, double> BinCosine(const HrcNode& p, int d) const {
        const double cosine = glm::dot(p.normal, directions_.Direction(d));
        const int side = cosine > 0.0 ? kUpper : kLower;
        return {side, std::abs(cosine) * lobeScale_[p.triangle][side]};
    }
    // BinCosine for every direction at once: lobes[d] on the upper side, lobes[bins + d] on
    // the lower, 0 on the side d does not face. For the loops that run it per patch and
    // sweep (push/pull): the directions' coordinates lie apart, so that it vectorises.
    void BinLobes(const HrcNode& p, double* lobes) const {
        const double* x = axes_.data();
        const double* y = x + bins_;
        const double* z = y + bins_;
        const double upper = lobeScale_[p.triangle][kUpper];
        const double lower = lobeScale_[p.triangle][kLower];
        for (int d = 0; d < bins_; ++d) {
            const double cosine = p.normal.x * x[d] + p.normal.y * y[d] + p.normal.z * z[d];
            lobes[d] = cosine > 0.0 ? cosine * upper : 0.0;
            lobes[bins_ + d] = cosine > 0.0 ? 0.0 : -cosine * lower;
        }
    }
    // A cluster's index into the per-bin tables (Field::intensity, Gathered::bins).
    std::uint32_t Slot(std::uint32_t n) const { return slot_[n]; }
    std::uint32_t SlotCount() const { return slots_; }

    // Σ A |n · ω| of the node's patches (both sides together); `at`: ω located in the
    // direction set already (a cluster's value is interpolated between its bins).
    double ProjectedArea(std::uint32_t n, const glm::dvec3& omega,
                         const DirectionSet::Interpolation* at = nullptr) const;
    // A cluster's projected area towards direction d of the set.
    double ProjectedBin(std::uint32_t n, int d) const {
        return projected_[static_cast<std::size_t>(slot_[n]) * bins_ + d];
    }
    // Radiant intensity (W/sr) leaving node n towards ω, all channels (Channels::Measure).
    double Power(const Field& field, std::uint32_t n, const glm::dvec3& omega,
                 const DirectionSet::Interpolation* at = nullptr) const;
    // Radiosity of node s's side, all channels (Channels::Measure).
    double SideRadiosity(const Field& field, std::uint32_t s, int side) const {
        return channels_.Measure(field.radiosity(s, side));
    }

    // Whether node n can be split: a cluster with children, a patch already split or not
    // yet at the deepest level and not too small.
    bool CanSplit(std::uint32_t n) const;
    // The smallest area a part of this patch may have.
    double MinArea(const HrcNode& patch) const;
    // Splits patch n into four (CanSplit holds); the new nodes are at the hierarchy's end.
    void Subdivide(std::uint32_t n);
    // Releases the nodes made since the hierarchy had `size` (Hierarchy::Truncate).
    void Truncate(std::size_t size) {
        hierarchy_.Truncate(size);
        slot_.resize(size);
    }

    // A plane's parts, whose form factors and solid angles add up to its own: a patch
    // itself, a flat cluster its children.
    std::span<const std::uint32_t> PlaneParts(const std::uint32_t& n) const {
        const HrcNode& node = hierarchy_[n];
        return node.patch ? std::span<const std::uint32_t>(&n, 1)
                          : std::span<const std::uint32_t>(node.children);
    }
    // The solid angle of a plane's part p seen from x: a patch's exactly, a flat cluster's
    // as its projected area over the squared distance (at most a hemisphere).
    double PartSolidAngle(std::uint32_t p, const glm::dvec3& x) const;
    // The solid angle of plane s (Planar) seen from x, its parts' together.
    double PlaneSolidAngle(std::uint32_t s, const glm::dvec3& x) const;

  private:
    void FindOrgans();
    void FindInnerSides(const Scene& scene);
    // Onward and Lamp.
    void FindOnward(const Scene& scene);
    void FindPlanes();
    void ScaleLobes();
    void AssignSlots();

    Hierarchy& hierarchy_;
    const FlatScene& flat_;
    const RayScene& rays_;
    const DirectionSet& directions_;
    const Channels channels_;
    const int bins_;
    const int maxSubdivision_;
    // The organs' bounding sphere (radius 0 without organs), and by flat triangle how many
    // times it may be split in four: maxSubdivision_ for organs; for a surface enough to
    // come down to the organs' size where it matters (Importance).
    glm::dvec3 organsCentre_{0.0};
    double organsRadius_ = 0.0;
    std::vector<std::uint8_t> maxDepth_;
    std::vector<std::uint8_t> inner_;  // by flat triangle: bit s set when side s is inside
    std::vector<std::array<double, 2>> lobeScale_;  // by flat triangle and side: BinCosine
    std::vector<double> axes_;  // the directions' x, then their y, then their z: BinLobes
    // A surface that sends on no light would never be split for the organs' sake; it is
    // split as one sending on this much.
    static constexpr double kLeastOnward = 0.01;
    std::vector<float> onwardOf_;       // by receiver: Onward of its patches
    std::vector<float> onward_;         // by node as built: Onward
    std::vector<std::uint8_t> lampOf_;  // by receiver: Lamp of its patches
    std::vector<std::uint8_t> lamps_;   // by node as built: Lamp
    std::vector<std::uint8_t> organs_;  // by node as built: 1 over an organ
    static constexpr std::uint32_t kNoOrgan = 0xFFFFFFFFu;
    std::vector<std::uint32_t> organOf_;  // by node as built: the one organ it lies in
    static constexpr std::uint8_t kPartlyHeld = 1, kAllHeld = 2;
    std::vector<std::uint8_t> held_;      // by node as built: Held, PartlyHeld
    std::vector<std::uint8_t> emitters_;  // by node as built: an emitter under it
    std::vector<std::uint8_t> planes_;    // by node as built: Planar
    std::vector<std::uint32_t> slot_;     // by node: clusters' slots, kNoNode for patches
    std::uint32_t slots_ = 0;
    std::vector<double> projected_;  // [slot][bin]
};

}  // namespace leaflux
