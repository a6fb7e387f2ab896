// Points of a receiving plane where links take its form factor (Estimator): a patch's
// degree-2 rule (three points) to judge a link and Radon's degree-5 rule (seven) to carry
// its light, the same for every link into it, so that in a closed room they sum to one; a
// flat cluster's three points with the moments of its area.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>

#include "solver/radiosity/hierarchy.h"

namespace leaflux {

// Which points of a receiver a link takes its form factor at: those that judge it, or
// those that carry its light.
enum class Points { kJudging, kTransfer };

// The degree-2 rule's three points of a patch (barycentric (2/3, 1/6, 1/6)).
std::array<glm::dvec3, 3> ThreePoints(const HrcNode& p);

// Radon's degree-5 rule on a triangle: its centroid and two orbits of three points,
// barycentric (1 − 2α, α, α) with α = (6 ∓ √15)/21, of weights (155 ∓ √15)/1200.
inline constexpr std::array<double, 7> kSevenWeights = {
    9.0 / 40.0,          0.12593918054482715, 0.12593918054482715, 0.12593918054482715,
    0.13239415278850618, 0.13239415278850618, 0.13239415278850618};
std::array<glm::dvec3, 7> SevenPoints(const HrcNode& p);

// Three points with the mean and second moments of plane r's area: a patch's ThreePoints;
// a flat cluster's from those of its parts (a cluster part at its centroid), as the
// centroid plus the Cholesky factor of their covariance in the plane applied to three
// points of unit covariance, √2 (cos θ, sin θ) at θ = 90°, 210°, 330°. A two-triangle leaf
// so takes three points where its triangles' rules took six.
std::array<glm::dvec3, 3> PlanePoints(const Hierarchy& hierarchy, std::uint32_t r);

struct Quadrature {
    std::array<glm::dvec3, 7> points;
    std::array<double, 7> weights;
    int count = 0;
};
// Points of plane r where a link takes its form factor, with their weights.
Quadrature ReceiverPoints(const Hierarchy& hierarchy, std::uint32_t r, Points rule);

}  // namespace leaflux
