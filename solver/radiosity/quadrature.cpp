#include "solver/radiosity/quadrature.h"

#include <algorithm>
#include <cmath>

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();
}  // namespace

std::array<glm::dvec3, 3> ThreePoints(const HrcNode& p) {
    return {(4.0 * p.a + p.b + p.c) / 6.0, (p.a + 4.0 * p.b + p.c) / 6.0,
            (p.a + p.b + 4.0 * p.c) / 6.0};
}

std::array<glm::dvec3, 7> SevenPoints(const HrcNode& p) {
    constexpr double a1 = 0.10128650732345634, b1 = 1.0 - 2.0 * a1;
    constexpr double a2 = 0.47014206410511509, b2 = 1.0 - 2.0 * a2;
    return {(p.a + p.b + p.c) / 3.0,        b1 * p.a + a1 * p.b + a1 * p.c,
            a1 * p.a + b1 * p.b + a1 * p.c, a1 * p.a + a1 * p.b + b1 * p.c,
            b2 * p.a + a2 * p.b + a2 * p.c, a2 * p.a + b2 * p.b + a2 * p.c,
            a2 * p.a + a2 * p.b + b2 * p.c};
}

std::array<glm::dvec3, 3> PlanePoints(const Hierarchy& hierarchy, std::uint32_t r) {
    const HrcNode& R = hierarchy[r];
    if (R.patch) return ThreePoints(R);
    const glm::dvec3 u =
        glm::normalize(std::abs(R.normal.x) < 0.9 ? glm::cross(R.normal, glm::dvec3(1, 0, 0))
                                                  : glm::cross(R.normal, glm::dvec3(0, 1, 0)));
    const glm::dvec3 v = glm::cross(R.normal, u);
    double uu = 0.0, uv = 0.0, vv = 0.0;
    for (std::uint32_t part : R.children) {
        const HrcNode& C = hierarchy[part];
        const double weight = C.areaM2 / (3.0 * R.areaM2);
        const std::array<glm::dvec3, 3> points =
            C.patch ? ThreePoints(C) : std::array{C.centroid, C.centroid, C.centroid};
        for (const glm::dvec3& p : points) {
            const double a = glm::dot(p - R.centroid, u), b = glm::dot(p - R.centroid, v);
            uu += weight * a * a, uv += weight * a * b, vv += weight * b * b;
        }
    }
    static const std::array<glm::dvec2, 3> kUnitCovariance = [] {
        std::array<glm::dvec2, 3> unit;
        for (int k = 0; k < 3; ++k) {
            const double angle = kPi / 2.0 + k * 2.0 * kPi / 3.0;
            unit[k] = std::sqrt(2.0) * glm::dvec2(std::cos(angle), std::sin(angle));
        }
        return unit;
    }();
    const double l11 = std::sqrt(uu), l21 = l11 > 0.0 ? uv / l11 : 0.0;
    const double l22 = std::sqrt(std::max(vv - l21 * l21, 0.0));
    std::array<glm::dvec3, 3> points;
    for (int k = 0; k < 3; ++k) {
        const auto [x, y] = kUnitCovariance[k];
        points[k] = R.centroid + l11 * x * u + (l21 * x + l22 * y) * v;
    }
    return points;
}

Quadrature ReceiverPoints(const Hierarchy& hierarchy, std::uint32_t r, Points rule) {
    Quadrature q;
    if (hierarchy[r].patch && rule == Points::kTransfer) {
        q.points = SevenPoints(hierarchy[r]);
        q.weights = kSevenWeights;
        q.count = 7;
        return q;
    }
    const std::array<glm::dvec3, 3> three = PlanePoints(hierarchy, r);
    std::copy(three.begin(), three.end(), q.points.begin());
    q.weights.fill(1.0 / 3.0);
    q.count = 3;
    return q;
}

}  // namespace leaflux
