// Rays for comparing two ray engines over one scene: from a point of one of the flat
// scene's first triangles (which the ray then ignores), or from a point up to 2.5 cm off it
// in the crown, along a direction uniform over the sphere.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <utility>

#include "solver/raytrace/raytrace.h"
#include "solver/util/sampling.h"

namespace leaflux::testing {

inline std::pair<RayStart, glm::dvec3> RandomRay(Random& random, const FlatScene& flat,
                                                 std::uint32_t triangles, bool inCrown) {
    const auto t = static_cast<std::uint32_t>(random.Uniform() * triangles);
    const Triangle& tri = flat.triangles[t];
    const double u = random.Uniform(), v = random.Uniform() * (1.0 - u);
    RayStart start{tri.a + u * (tri.b - tri.a) + v * (tri.c - tri.a), t};
    if (inCrown)
        start = {start.origin + 0.05 * glm::dvec3(random.Uniform() - 0.5, random.Uniform() - 0.5,
                                                  random.Uniform() - 0.5)};
    const double z = 2.0 * random.Uniform() - 1.0, phi = 2.0 * glm::pi<double>() * random.Uniform();
    const double s = std::sqrt(1.0 - z * z);
    return {start, glm::dvec3(s * std::cos(phi), s * std::sin(phi), z)};
}

}  // namespace leaflux::testing
