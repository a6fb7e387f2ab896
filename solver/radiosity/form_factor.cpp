#include "solver/radiosity/form_factor.h"

#include <cmath>
#include <glm/gtc/constants.hpp>

#include "solver/directions.h"

namespace leaflux {
namespace {

// The part of the polygon where n · (p − x) ≥ 0 (Sutherland–Hodgman on one plane).
std::vector<glm::dvec3> ClipAbove(const glm::dvec3& x, const glm::dvec3& n,
                                  const std::vector<glm::dvec3>& polygon) {
    std::vector<glm::dvec3> out;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3& p = polygon[i];
        const glm::dvec3& q = polygon[(i + 1) % polygon.size()];
        const double dp = glm::dot(n, p - x), dq = glm::dot(n, q - x);
        if (dp >= 0.0) out.push_back(p);
        if ((dp >= 0.0) != (dq >= 0.0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
    }
    return out;
}

}  // namespace

double PointToPolygonAbove(const glm::dvec3& x, const glm::dvec3& n,
                           const std::vector<glm::dvec3>& polygon) {
    if (polygon.size() < 3) return 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3 r0 = polygon[i] - x;
        const glm::dvec3 r1 = polygon[(i + 1) % polygon.size()] - x;
        const glm::dvec3 cross = glm::cross(r0, r1);
        const double length = glm::length(cross);
        if (length <= 0.0) continue;  // an edge seen end-on adds nothing
        const double angle = std::atan2(length, glm::dot(r0, r1));
        sum += angle * glm::dot(n, cross) / length;
    }
    return std::min(1.0, std::abs(sum) / (2.0 * glm::pi<double>()));
}

SidedFormFactor PointToTriangle(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a,
                                const glm::dvec3& b, const glm::dvec3& c) {
    const std::vector<glm::dvec3> triangle = {a, b, c};
    SidedFormFactor f;
    f.upper = PointToPolygonAbove(x, n, ClipAbove(x, n, triangle));
    f.lower = PointToPolygonAbove(x, -n, ClipAbove(x, -n, triangle));
    const glm::dvec3 ra = a - x, rb = b - x, rc = c - x;
    const double la = glm::length(ra), lb = glm::length(rb), lc = glm::length(rc);
    if (la > 0.0 && lb > 0.0 && lc > 0.0) {
        f.solidAngleSr = SphericalTriangleSolidAngle(ra / la, rb / lb, rc / lc);
    }
    return f;
}

}  // namespace leaflux
