#include "solver/radiosity/form_factor.h"

#include <array>
#include <cmath>
#include <glm/gtc/constants.hpp>

#include "solver/util/directions.h"

namespace leaflux {
namespace {

// A triangle clipped by one plane: at most four corners, on the stack (form factors are
// found for every pair of patches refinement judges).
struct Clipped {
    std::array<glm::dvec3, 4> corners;
    std::size_t count = 0;
};

// The part of the triangle where n · (p − x) ≥ 0 (Sutherland–Hodgman on one plane).
Clipped ClipAbove(const glm::dvec3& x, const glm::dvec3& n,
                  const std::array<glm::dvec3, 3>& triangle) {
    Clipped out;
    for (std::size_t i = 0; i < triangle.size(); ++i) {
        const glm::dvec3& p = triangle[i];
        const glm::dvec3& q = triangle[(i + 1) % triangle.size()];
        const double dp = glm::dot(n, p - x), dq = glm::dot(n, q - x);
        if (dp >= 0.0) out.corners[out.count++] = p;
        if ((dp >= 0.0) != (dq >= 0.0)) out.corners[out.count++] = p + (q - p) * (dp / (dp - dq));
    }
    return out;
}

// F from a differential element at x (normal n) to the polygon lying entirely on the +n
// side of x's plane.
double PolygonAbove(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3* polygon,
                    std::size_t count) {
    if (count < 3) return 0.0;
    double sum = 0.0;
    glm::dvec3 r0 = polygon[count - 1] - x;  // each edge from the previous corner
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 r1 = polygon[i] - x;
        const glm::dvec3 cross = glm::cross(r0, r1);
        const double length = glm::length(cross);
        if (length > 0.0) sum += Angle(length, glm::dot(r0, r1)) * glm::dot(n, cross) / length;
        r0 = r1;  // an edge seen end-on (length 0) adds nothing
    }
    return std::min(1.0, std::abs(sum) / (2.0 * glm::pi<double>()));
}

}  // namespace

SidedFormFactor PointToTriangle(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a,
                                const glm::dvec3& b, const glm::dvec3& c) {
    return MeanPointToTriangle(x, &x, 1, n, a, b, c);
}

SidedFormFactor MeanPointToTriangle(const glm::dvec3& centre, const glm::dvec3* xs, int count,
                                    const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                    const glm::dvec3& c, const double* weights) {
    const std::array<glm::dvec3, 3> triangle = {a, b, c};
    SidedFormFactor f;
    const glm::dvec3& x = centre;
    const Clipped upper = ClipAbove(x, n, triangle), lower = ClipAbove(x, -n, triangle);
    for (int k = 0; k < count; ++k) {
        const double weight = weights ? weights[k] : 1.0 / count;
        f.upper += weight * PolygonAbove(xs[k], n, upper.corners.data(), upper.count);
        f.lower += weight * PolygonAbove(xs[k], -n, lower.corners.data(), lower.count);
    }
    const glm::dvec3 ra = a - x, rb = b - x, rc = c - x;
    const double la = glm::length(ra), lb = glm::length(rb), lc = glm::length(rc);
    if (la > 0.0 && lb > 0.0 && lc > 0.0) {
        f.solidAngleSr = SphericalTriangleSolidAngle(ra / la, rb / lb, rc / lc);
    }
    return f;
}

glm::dvec3 TriangleMoment(const glm::dvec3& x, const glm::dvec3& a, const glm::dvec3& b,
                          const glm::dvec3& c) {
    const std::array<glm::dvec3, 3> triangle = {a, b, c};
    glm::dvec3 sum(0.0);
    glm::dvec3 r0 = triangle[2] - x;
    for (const glm::dvec3& corner : triangle) {
        const glm::dvec3 r1 = corner - x;
        const glm::dvec3 cross = glm::cross(r0, r1);
        const double length = glm::length(cross);
        if (length > 0.0) sum += Angle(length, glm::dot(r0, r1)) * cross / length;
        r0 = r1;
    }
    const glm::dvec3 toward = (triangle[0] + triangle[1] + triangle[2]) / 3.0 - x;
    return (glm::dot(sum, toward) < 0.0 ? -0.5 : 0.5) * sum;
}

}  // namespace leaflux
