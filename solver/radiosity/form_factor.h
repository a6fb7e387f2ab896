// Point-to-polygon form factors (Lambert's contour formula), bounded in the near field:
// the differential element at x, normal n, sees the polygon as F ∈ [0, 1] of its
// cosine-weighted hemisphere, whatever the distance — never the 1/r² point formula that
// exceeds 1 when elements nearly touch (Howell's catalogue, case B-5 generalised).
#pragma once

#include <glm/glm.hpp>

namespace leaflux {

struct SidedFormFactor {
    double upper = 0.0;         // towards +n
    double lower = 0.0;         // towards −n
    double solidAngleSr = 0.0;  // of the polygon seen from x, both sides
};

// Form factors from the point x (unit normal n) to the triangle a, b, c, for each side of
// x: the triangle is clipped by the plane of x and each part seen by its side.
SidedFormFactor PointToTriangle(const glm::dvec3& x, const glm::dvec3& n, const glm::dvec3& a,
                                const glm::dvec3& b, const glm::dvec3& c);

// The form factors of each side averaged over points xs[0..count) of the plane through
// `centre` of normal n (the triangle clipped by that plane once), with weights[0..count)
// summing to one or, without them, evenly; the solid angle seen from `centre`.
SidedFormFactor MeanPointToTriangle(const glm::dvec3& centre, const glm::dvec3* xs, int count,
                                    const glm::dvec3& n, const glm::dvec3& a, const glm::dvec3& b,
                                    const glm::dvec3& c, const double* weights = nullptr);

// ∫ ω dω over the triangle a, b, c seen from x, ½ Σ θᵢ Γᵢ over its edges (θᵢ the angle an
// edge subtends, Γᵢ the unit normal of the plane through x and it): the irradiance vector
// of unit radiance, whose component along a normal is π F; its length is at most the
// triangle's solid angle.
glm::dvec3 TriangleMoment(const glm::dvec3& x, const glm::dvec3& a, const glm::dvec3& b,
                          const glm::dvec3& c);

}  // namespace leaflux
