// A sun or sky cone as the hierarchy sees it: light from the directions of a circular cone
// round `toward` (a parallel beam when cosRadius is 1), of uniform radiance. Its visibility
// is taken along directions spread over the cone, so that a leaf is partly shadowed from a
// sky cone as from the patch of sky it stands for; its irradiance on a side of a plane is
// normalIrradiance × SideShare, the part of the cone on that side of the plane.
#pragma once

#include <glm/glm.hpp>
#include <vector>

namespace leaflux {

struct DirectionalSource {
    glm::dvec3 toward;                     // unit, towards the source: the cone's axis
    std::vector<double> normalIrradiance;  // W/m² on a plane facing `toward`, per channel
    double cosRadius = 1.0;                // of the cone's half-angle
    // Its rays meet what lies outside a local problem (OutsideView) as well: true for the
    // scene's suns and sky cones; false for the light that arrived on an opened instance
    // from the rest of the scene, whose shadows outside it that light already holds.
    bool beyond = true;
    // Light incident on the scene, which its energy balance counts: the suns' and sky's,
    // not light scattered inside it.
    bool incident = true;
    // Its links reach each organ, whatever they carry (Refiner::JudgeSource): a sun's. A
    // link into a cluster hands every organ under it one visibility, sunlit and shaded
    // alike; a sun brings most of the light and its shadow edges fall between leaves.
    bool eachOrgan = false;
    // A sky cone reaching below the horizon has that part folded back above it, as the
    // reference takes it (FoldAtHorizon): its directions then, 8 × 8 of equal solid angle,
    // mirrored where below, and their mean.
    std::vector<glm::dvec3> folded{};
    glm::dvec3 foldedMean{0.0};

    bool Folded() const { return !folded.empty(); }
    // Folds a cone that reaches below the horizon (a sky cone; suns are not folded).
    void FoldAtHorizon();
    // A direction of the cone (UniformCone's u, v), folded above the horizon if it is.
    glm::dvec3 Direction(double u, double v) const;
    // The share of normalIrradiance that reaches the side of a plane facing n:
    // ∫ max(0, n · ω) dω over the cone, over π sin² r. n · toward for a cone wholly on
    // that side. A cone across the plane lights both its sides (Snyder's closed form for a
    // spherical cap, "Area light sources for real-time graphics", 1996); taken whole by
    // its axis, a side lost what fell on the other: a leaf tilted 30° under the 46-cone
    // uniform sky got 1.3 % too little light, 11 % on its lower side.
    double SideShare(const glm::dvec3& n) const;
    // ∫ ω dω over the cone, over π sin² r: its light vector per unit normalIrradiance.
    glm::dvec3 Moment() const { return Folded() ? foldedMean : toward; }
};

}  // namespace leaflux
