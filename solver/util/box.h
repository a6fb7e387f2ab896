// An axis-aligned box's corners, and the world bounds of a box placed by a transform.
#pragma once

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

}  // namespace leaflux
