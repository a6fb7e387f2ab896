// An axis-aligned box's corners, the world bounds of a box placed by a transform, and where
// a line crosses it.
#pragma once

#include <algorithm>
#include <glm/glm.hpp>
#include <limits>
#include <utility>

namespace leaflux {

// Corner `corner` (0–7: bit 0 picks x's max, bit 1 y's, bit 2 z's) of [boxMin, boxMax].
inline glm::dvec3 BoxCorner(const glm::dvec3& boxMin, const glm::dvec3& boxMax, int corner) {
    return {corner & 1 ? boxMax.x : boxMin.x, corner & 2 ? boxMax.y : boxMin.y,
            corner & 4 ? boxMax.z : boxMin.z};
}

// The axis-aligned bounds of [boxMin, boxMax] placed by `outerFromBox`: its eight corners'.
inline std::pair<glm::dvec3, glm::dvec3> PlacedBounds(const glm::dmat4& outerFromBox,
                                                      const glm::dvec3& boxMin,
                                                      const glm::dvec3& boxMax) {
    glm::dvec3 lower(std::numeric_limits<double>::infinity()), upper(-lower);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p(outerFromBox * glm::dvec4(BoxCorner(boxMin, boxMax, corner), 1.0));
        lower = glm::min(lower, p);
        upper = glm::max(upper, p);
    }
    return {lower, upper};
}

// Where the line origin + t d meets [boxMin, boxMax]: t from `enter` to `exit` (in the
// units of d); exit ≤ enter when it misses the box.
struct BoxSpan {
    double enter = -std::numeric_limits<double>::infinity();
    double exit = std::numeric_limits<double>::infinity();
    bool Meets() const { return exit > enter; }
};
inline BoxSpan LineThroughBox(const glm::dvec3& origin, const glm::dvec3& d,
                              const glm::dvec3& boxMin, const glm::dvec3& boxMax) {
    BoxSpan span;
    for (int axis = 0; axis < 3; ++axis) {
        if (d[axis] == 0.0) {
            if (origin[axis] < boxMin[axis] || origin[axis] > boxMax[axis])
                return {std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
            continue;
        }
        double t0 = (boxMin[axis] - origin[axis]) / d[axis];
        double t1 = (boxMax[axis] - origin[axis]) / d[axis];
        if (t0 > t1) std::swap(t0, t1);
        span.enter = std::max(span.enter, t0);
        span.exit = std::min(span.exit, t1);
    }
    return span;
}

}  // namespace leaflux
