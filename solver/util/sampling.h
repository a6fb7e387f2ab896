// Random numbers and warps for the Monte Carlo solvers. Every random choice in leaflux
// takes a seed: a stream is keyed by (seed, what it is for), never by thread, so results
// do not depend on scheduling.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>
#include <vector>

namespace leaflux {

// SplitMix64 finaliser: mixes keys into well-spread 64-bit seeds.
inline std::uint64_t MixBits(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

inline std::uint64_t StreamSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
    return MixBits(MixBits(MixBits(seed) ^ a) ^ b);
}

// PCG32 (O'Neill 2014): small state, good statistics, one stream per seed.
class Random {
  public:
    explicit Random(std::uint64_t seed) : state_(0), increment_((seed << 1u) | 1u) {
        Next();
        state_ += MixBits(seed);
        Next();
    }

    std::uint32_t Next() {
        const std::uint64_t old = state_;
        state_ = old * 6364136223846793005ull + increment_;
        const auto xorShifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rotation = static_cast<std::uint32_t>(old >> 59u);
        return (xorShifted >> rotation) | (xorShifted << ((32u - rotation) & 31u));
    }

    // Uniform in [0, 1).
    double Uniform() {
        const std::uint64_t bits = (static_cast<std::uint64_t>(Next()) << 21) ^ Next();
        return static_cast<double>(bits & ((1ull << 53) - 1)) * 0x1.0p-53;
    }

    // Uniform integer in [0, n).
    std::uint32_t Below(std::uint32_t n) { return static_cast<std::uint32_t>(Uniform() * n); }

  private:
    std::uint64_t state_;
    std::uint64_t increment_;
};

// An orthonormal frame whose z is `n` (Duff et al. 2017, branchless).
inline void Basis(const glm::dvec3& n, glm::dvec3& t, glm::dvec3& b) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::dvec3(c, sign + n.y * n.y * a, -n.y);
}

inline glm::dvec3 FromLocal(const glm::dvec3& n, const glm::dvec3& local) {
    glm::dvec3 t, b;
    Basis(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// Uniform over the sphere; pdf 1/(4π).
inline glm::dvec3 UniformSphere(double u, double v) {
    const double z = 1.0 - 2.0 * u;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * glm::pi<double>() * v;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Cosine-weighted around n; pdf cos θ / π.
inline glm::dvec3 CosineHemisphere(const glm::dvec3& n, double u, double v) {
    const double r = std::sqrt(u);
    const double phi = 2.0 * glm::pi<double>() * v;
    return FromLocal(n, {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u))});
}

// Uniform inside the cone of half-angle acos(cosMax) around `axis`.
inline glm::dvec3 UniformCone(const glm::dvec3& axis, double cosMax, double u, double v) {
    const double z = 1.0 - u * (1.0 - cosMax);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * glm::pi<double>() * v;
    return FromLocal(axis, {r * std::cos(phi), r * std::sin(phi), z});
}

// 0 .. count − 1 in an order drawn from `random` (Fisher–Yates): a second coordinate
// stratified over the same samples, its strata taken in this order, keeps each sample's
// pair uniform (Latin hypercube sampling); in a fixed order, pairs stratum i only with
// stratum π(i), which is a bias where the integrand couples the two.
inline void RandomStrata(Random& random, std::vector<int>& order, int count) {
    order.resize(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) order[i] = i;
    for (int i = count - 1; i > 0; --i) {
        const int j = std::min(i, static_cast<int>(random.Uniform() * (i + 1)));
        std::swap(order[i], order[j]);
    }
}

// Uniform on a triangle: barycentric weights of a, b, c.
inline glm::dvec3 UniformTriangle(double u, double v) {
    const double s = std::sqrt(u);
    return {1.0 - s, s * (1.0 - v), s * v};
}

// Uniform in the solid angle of the spherical triangle of unit vectors a, b, c (Arvo 1995,
// "Stratified sampling of spherical triangles"): a sub-triangle of area u × its area is
// cut off at a, and its far edge sampled by v.
inline glm::dvec3 UniformSphericalTriangle(const glm::dvec3& a, const glm::dvec3& b,
                                           const glm::dvec3& c, double u, double v) {
    // The angles at the vertices, between the great circles through them.
    auto angle = [](const glm::dvec3& at, const glm::dvec3& p, const glm::dvec3& q) {
        const glm::dvec3 toP = glm::cross(at, p), toQ = glm::cross(at, q);
        const double lengths = glm::length(toP) * glm::length(toQ);
        return lengths > 0.0 ? std::acos(std::clamp(glm::dot(toP, toQ) / lengths, -1.0, 1.0)) : 0.0;
    };
    const double alpha = angle(a, b, c);
    const double area = alpha + angle(b, c, a) + angle(c, a, b) - glm::pi<double>();
    const double part = u * area;
    const double s = std::sin(part - alpha), t = std::cos(part - alpha);
    const double sinAlpha = std::sin(alpha), cosAlpha = std::cos(alpha);
    const double p = t - cosAlpha, q = s + sinAlpha * glm::dot(a, b);
    const double denominator = (q * s + p * t) * sinAlpha;
    const double cosine =
        denominator != 0.0 ? std::clamp(((q * t - p * s) * cosAlpha - q) / denominator, -1.0, 1.0)
                           : 1.0;
    // The sub-triangle's third vertex, on the arc from a to c.
    const glm::dvec3 awayFromA = c - glm::dot(c, a) * a;
    const double awayLength = glm::length(awayFromA);
    const glm::dvec3 cut =
        awayLength > 0.0
            ? cosine * a + std::sqrt(std::max(0.0, 1.0 - cosine * cosine)) * awayFromA / awayLength
            : a;
    // Along the arc from b to that vertex.
    const double z = 1.0 - v * (1.0 - glm::dot(cut, b));
    const glm::dvec3 awayFromB = cut - glm::dot(cut, b) * b;
    const double awayFromBLength = glm::length(awayFromB);
    if (awayFromBLength <= 0.0) return b;
    return glm::normalize(z * b +
                          std::sqrt(std::max(0.0, 1.0 - z * z)) * awayFromB / awayFromBLength);
}

}  // namespace leaflux
