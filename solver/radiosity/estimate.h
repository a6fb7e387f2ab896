// What a link from node S to node R would carry and how wrong it may be, before its
// visibility: form factors between patches and planes, point transfers between clusters
// through the direction set, and the geometric error refinement weighs (Soler 2003 §3.1,
// after Smits 1994 and Sillion 1995). Reads the hierarchy, the node model and the light
// leaving the nodes; owns nothing.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <utility>

#include "solver/radiosity/form_factor.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/node_model.h"
#include "solver/radiosity/quadrature.h"

namespace leaflux {

struct Estimate {
    double geometric = 0.0;  // cluster link: see NodeLink; exact link: unused
    SidedFormFactor form;    // exact link: at R's points
    double power = 0.0;      // W the link may carry, unoccluded
    double reach = -1.0;     // power per unit of the sender's light (see NodeLink)
    double geometricError = 0.0;
    int senderSide = kUpper;
    glm::dvec3 toSender{0, 0, 1};
    bool near = false;   // exact link: R's centre does not speak for all of R
    bool sided = false;  // `form` is the transfer (NodeLink::sided)
    // Exact link: W that parts of R across S's plane take from S's other side, which the
    // link (one side, the centre's) gets wrong, and that per unit of difference between S's
    // sides.
    double sideError = 0.0, sideReach = 0.0;

    // The error the link would carry with a visibility of this spread (W).
    double Error(double spread) const { return power * (geometricError + spread) + sideError; }
};

class Estimator {
  public:
    Estimator(const NodeModel& model, const Field& field)
        : hierarchy_(model.Nodes()), model_(model), field_(field) {}

    // Plane s seen from R's centroid: the mean of ω over its solid angle Ω, ∫ ω dω / Ω
    // (its patches' exactly, TriangleMoment; a flat cluster part's towards its centroid),
    // shorter than 1 where s is seen wide: where an exact or sided link's light arrives
    // from, for the light vector (NodeLink::toSender).
    glm::dvec3 Arrival(std::uint32_t r, std::uint32_t s) const;
    // Node ← node, at least one of them a cluster, or plane ← plane one a flat cluster.
    Estimate Pair(std::uint32_t r, std::uint32_t s, Points rule = Points::kJudging) const;
    // Patch ← patch: Lambert's formula per side, averaged over points of R.
    Estimate Exact(std::uint32_t r, std::uint32_t s, Points rule = Points::kJudging) const;

    // How far patch R's corners lie below and above the plane of patch S (≤ 0 and ≥ 0),
    // rounding below 1e-9 of R's size counted as in the plane.
    static std::pair<double, double> Heights(const HrcNode& R, const HrcNode& S);
    // Whether node R reaches across the plane of patch S: then its centroid's side is not
    // the side all of R sees (a wall beside a lamp, partly above it). A patch in S's plane
    // sees nothing of S and is not across it.
    static bool Across(const HrcNode& R, const HrcNode& S);
    // Whether patch R lies in the plane of patch S (two triangles of one flat leaf), where
    // no light passes between them.
    static bool InPlane(const HrcNode& R, const HrcNode& S);

  private:
    SidedFormFactor PlanesForm(std::uint32_t r, std::uint32_t s, Points rule) const;
    // Takes off what `form` hands the inner side of a solid's face R (an internode's).
    void HideInnerSides(const HrcNode& R, SidedFormFactor& form) const;
    // R's area facing the light of a sender, for the error estimate.
    double ExposedArea(std::uint32_t r, double projected, double geometricError) const {
        return projected + geometricError * std::max(hierarchy_[r].areaM2 - projected, 0.0);
    }

    const Hierarchy& hierarchy_;
    const NodeModel& model_;
    const Field& field_;
};

}  // namespace leaflux
