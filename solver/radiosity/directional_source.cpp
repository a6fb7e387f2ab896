#include "solver/radiosity/directional_source.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/util/sampling.h"

namespace leaflux {
namespace {

constexpr int kFoldedSide = 8;  // the folded cone's directions: rings × turns

// ∫ max(0, n · ω) dω over a cap of half-angle r whose axis makes `cosine` with n, over
// π sin² r (Snyder 1996).
double CapShare(double cosine, double cosRadius) {
    const double sin2 = 1.0 - cosRadius * cosRadius;
    if (sin2 <= 0.0 || cosine * cosine >= sin2) return std::max(cosine, 0.0);
    const double sine = std::sqrt(std::max(0.0, 1.0 - cosine * cosine));
    const double x = cosRadius / std::sqrt(sin2);  // cot r
    const double y = -x * cosine / sine;
    const double arc = sine * std::sqrt(std::max(0.0, 1.0 - y * y));
    const double lit =
        (cosine * std::acos(std::clamp(y, -1.0, 1.0)) - x * arc) * sin2 + std::atan(arc / x);
    return std::max(lit, 0.0) / (std::numbers::pi * sin2);
}

}  // namespace

void DirectionalSource::FoldAtHorizon() {
    folded.clear();
    foldedMean = glm::dvec3(0.0);
    if (cosRadius >= 1.0 || toward.z < 0.0) return;
    // The cone reaches below the horizon when its axis is lower than its radius.
    if (toward.z >= std::sqrt(1.0 - cosRadius * cosRadius)) return;
    for (int i = 0; i < kFoldedSide; ++i) {
        for (int j = 0; j < kFoldedSide; ++j) {
            glm::dvec3 w =
                UniformCone(toward, cosRadius, (i + 0.5) / kFoldedSide, (j + 0.5) / kFoldedSide);
            w.z = std::abs(w.z);
            folded.push_back(w);
            foldedMean += w;
        }
    }
    // Each direction stands for Ω / N of the cone, Ω = 2π (1 − cos r); over π sin² r.
    foldedMean *= 2.0 / ((1.0 + cosRadius) * static_cast<double>(folded.size()));
}

glm::dvec3 DirectionalSource::Direction(double u, double v) const {
    if (cosRadius >= 1.0) return toward;
    glm::dvec3 w = UniformCone(toward, cosRadius, u, v);
    if (Folded()) w.z = std::abs(w.z);
    return w;
}

double DirectionalSource::SideShare(const glm::dvec3& n) const {
    const double cosine = glm::dot(n, toward);
    if (!Folded()) return CapShare(cosine, cosRadius);
    // Across the cone or its mirror image, the plane cuts the folded cone: its directions.
    const double sine = std::sqrt(1.0 - cosRadius * cosRadius);
    const glm::dvec3 mirrored(toward.x, toward.y, -toward.z);
    if (std::abs(cosine) >= sine && std::abs(glm::dot(n, mirrored)) >= sine &&
        (cosine > 0.0) == (glm::dot(n, mirrored) > 0.0))
        return std::max(0.0, glm::dot(n, foldedMean));
    double lit = 0.0;
    for (const glm::dvec3& w : folded) lit += std::max(0.0, glm::dot(n, w));
    return lit * 2.0 / ((1.0 + cosRadius) * static_cast<double>(folded.size()));
}

}  // namespace leaflux
