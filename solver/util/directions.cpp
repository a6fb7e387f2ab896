#include "solver/util/directions.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>
#include <utility>

#include "solver/util/check.h"

namespace leaflux {
namespace {
constexpr int kMaxLevel = 4;

// Inside the spherical triangle: on the inner side of its three great-circle planes. A
// small tolerance keeps directions on an edge inside both faces.
bool InsideFace(const glm::dvec3& d, const std::array<glm::dvec3, 3>& edges) {
    constexpr double kTolerance = -1e-12;
    return glm::dot(edges[0], d) >= kTolerance && glm::dot(edges[1], d) >= kTolerance &&
           glm::dot(edges[2], d) >= kTolerance;
}

// atan(u) for |u| ≤ tan(π/64) ≈ 0.049: its Taylor series to u¹³ (the next term is under
// 1e-19 of u), evaluated in pairs so that the sums do not wait on each other.
double SmallArctangent(double u) {
    constexpr double c1 = -1.0 / 3, c2 = 1.0 / 5, c3 = -1.0 / 7, c4 = 1.0 / 9, c5 = -1.0 / 11,
                     c6 = 1.0 / 13;
    const double u2 = u * u, u4 = u2 * u2;
    const double low = c1 + u2 * c2, middle = c3 + u2 * c4, high = c5 + u2 * c6;
    return u + u * u2 * (low + u4 * (middle + u4 * high));
}
}  // namespace

double Angle(double sine, double cosine) {
    // atan(t) for t = smaller / larger of |sine|, |cosine| in [0, 1], from the nearest of
    // the centres tan(kπ/32), k = 0..8: atan(t) = kπ/32 + atan((t − c) / (1 + t c)), the
    // remainder within ±tan(π/64). One division: t's is folded into the remainder's.
    constexpr int kCentres = 9;
    struct Table {
        std::array<double, kCentres> centre, angle;
        std::array<double, kCentres - 1> bound;  // tan((2k + 1)π/64): centre k + 1 is nearer above
    };
    static const Table table = [] {
        Table t;
        for (int k = 0; k < kCentres; ++k) {
            t.angle[k] = k * std::numbers::pi / 32.0;
            t.centre[k] = k == kCentres - 1 ? 1.0 : std::tan(t.angle[k]);
        }
        for (int k = 0; k + 1 < kCentres; ++k)
            t.bound[k] = std::tan((2 * k + 1) * std::numbers::pi / 64.0);
        return t;
    }();
    const double a = std::abs(cosine);
    if (!(sine > 0.0) || !(a < std::numeric_limits<double>::infinity())) {
        return std::atan2(sine, cosine);  // on an axis, infinite or not a number
    }
    const bool steep = sine > a;
    const double smaller = steep ? a : sine, larger = steep ? sine : a;
    int k = 0;
    for (double bound : table.bound) k += smaller > bound * larger;
    const double c = table.centre[k];
    const double angle =
        table.angle[k] + SmallArctangent((smaller - c * larger) / (larger + c * smaller));
    // Reflected by arithmetic rather than branches, which the data would mispredict: the
    // steep octant about π/4, the obtuse quadrant about π/2.
    const double steepAngle = steep * (std::numbers::pi / 2.0) + (1.0 - 2.0 * steep) * angle;
    const double obtuse = cosine < 0.0;
    return obtuse * std::numbers::pi + (1.0 - 2.0 * obtuse) * steepAngle;
}

double SphericalTriangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const double numerator = std::abs(glm::dot(a, glm::cross(b, c)));
    const double denominator = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
    return 2.0 * Angle(numerator, denominator);
}

DirectionSet::DirectionSet(int level) {
    LEAFLUX_CHECK(level >= 0 && level <= kMaxLevel);
    const double s = std::sqrt(8.0 / 9.0), t = std::sqrt(2.0 / 9.0), u = std::sqrt(2.0 / 3.0);
    directions_ = {{0, 0, 1}, {s, 0, -1.0 / 3}, {-t, u, -1.0 / 3}, {-t, -u, -1.0 / 3}};
    levels_.push_back({{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}});
    // Counter-clockwise seen from outside, as InsideFace expects; subdivision keeps it.
    for (auto& [a, b, c] : levels_[0]) {
        const glm::dvec3 &pa = directions_[a], &pb = directions_[b], &pc = directions_[c];
        if (glm::dot(glm::cross(pb - pa, pc - pa), pa + pb + pc) < 0.0) std::swap(b, c);
    }
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<int, int>, int> midpoints;
        auto midpoint = [&](int i, int j) {
            const auto key = std::minmax(i, j);
            if (auto it = midpoints.find(key); it != midpoints.end()) return it->second;
            directions_.push_back(glm::normalize(directions_[i] + directions_[j]));
            const int index = static_cast<int>(directions_.size()) - 1;
            midpoints.emplace(key, index);
            return index;
        };
        std::vector<std::array<int, 3>> children;
        for (const auto& [a, b, c] : levels_.back()) {
            const int ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            children.push_back({a, ab, ca});
            children.push_back({ab, b, bc});
            children.push_back({ca, bc, c});
            children.push_back({ab, bc, ca});
        }
        levels_.push_back(std::move(children));
    }
    faces_ = levels_.back();
    for (const auto& faces : levels_) {
        auto& edges = edges_.emplace_back();
        for (const auto& [a, b, c] : faces) {
            const glm::dvec3 &pa = directions_[a], &pb = directions_[b], &pc = directions_[c];
            edges.push_back({glm::cross(pa, pb), glm::cross(pb, pc), glm::cross(pc, pa)});
        }
    }
    // Each direction gets a third of the solid angle of every face around it.
    solidAngles_.assign(directions_.size(), 0.0);
    for (const auto& [a, b, c] : faces_) {
        const double third =
            SphericalTriangleSolidAngle(directions_[a], directions_[b], directions_[c]) / 3.0;
        solidAngles_[a] += third;
        solidAngles_[b] += third;
        solidAngles_[c] += third;
    }
    // The weights are barycentric on the face's plane (gnomonic): each face is cut into
    // m² small triangles on that plane, whose solid angles are exact, each weighted by the
    // weights at its centre (midpoint rule; m² = 4096 per face of the tetrahedron, 16 per
    // face of level 4).
    const int m = std::max(4, 64 >> level);
    hatIntegrals_.assign(directions_.size(), 0.0);
    for (const auto& [a, b, c] : faces_) {
        const auto on = [&](const glm::dvec2& p) {  // p: weights of b and c
            return glm::normalize((1.0 - p.x - p.y) * directions_[a] + p.x * directions_[b] +
                                  p.y * directions_[c]);
        };
        const auto add = [&](const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& r) {
            const double omega = SphericalTriangleSolidAngle(on(p), on(q), on(r));
            const Interpolation w = Locate(on((p + q + r) / 3.0));
            for (int k = 0; k < 3; ++k) hatIntegrals_[w.vertex[k]] += omega * w.weight[k];
        };
        const double h = 1.0 / m;
        for (int i = 0; i < m; ++i) {
            for (int j = 0; i + j < m; ++j) {
                const glm::dvec2 p(i * h, j * h);
                add(p, p + glm::dvec2(h, 0.0), p + glm::dvec2(0.0, h));
                if (i + j + 1 < m)
                    add(p + glm::dvec2(h, 0.0), p + glm::dvec2(h, h), p + glm::dvec2(0.0, h));
            }
        }
    }
}

const DirectionSet& DirectionSet::OfLevel(int level) {
    static std::once_flag once;
    static std::array<std::unique_ptr<DirectionSet>, kMaxLevel + 1> sets;
    std::call_once(once, [] {
        for (int l = 0; l <= kMaxLevel; ++l) sets[l].reset(new DirectionSet(l));
    });
    LEAFLUX_CHECK(level >= 0 && level <= kMaxLevel);
    return *sets[level];
}

int DirectionSet::LevelWithCount(int directionCount) {
    for (int l = 0, count = 4; l <= kMaxLevel; ++l, count = 4 * count - 6) {
        if (count == directionCount) return l;
    }
    return -1;
}

int DirectionSet::LocateFace(const glm::dvec3& d) const {
    int face = -1;
    for (std::size_t l = 0; l < levels_.size(); ++l) {
        const int first = l == 0 ? 0 : 4 * face;
        constexpr int count = 4;  // the tetrahedron's faces, then a face's children
        int found = -1;
        for (int f = first; f < first + count; ++f) {
            if (InsideFace(d, edges_[l][f])) {
                found = f;
                break;
            }
        }
        // Rounding can leave a direction on an edge outside every child: take the child
        // whose centre is nearest, which shares that edge.
        if (found < 0) {
            double best = -2.0;
            for (int f = first; f < first + count; ++f) {
                const auto& [a, b, c] = levels_[l][f];
                const double cosine =
                    glm::dot(glm::normalize(directions_[a] + directions_[b] + directions_[c]), d);
                if (cosine > best) best = cosine, found = f;
            }
        }
        face = found;
    }
    return face;
}

DirectionSet::Interpolation DirectionSet::Locate(const glm::dvec3& direction) const {
    const glm::dvec3 d = glm::normalize(direction);
    const auto& [a, b, c] = faces_[LocateFace(d)];
    // Barycentric weights of the point where d crosses the face's plane (gnomonic).
    const glm::dvec3 &pa = directions_[a], &pb = directions_[b], &pc = directions_[c];
    const double wa = glm::dot(glm::cross(pb, pc), d);
    const double wb = glm::dot(glm::cross(pc, pa), d);
    const double wc = glm::dot(glm::cross(pa, pb), d);
    glm::dvec3 w = glm::max(glm::dvec3(wa, wb, wc), glm::dvec3(0.0));
    const double sum = w.x + w.y + w.z;
    w = sum > 0.0 ? w / sum : glm::dvec3(1.0, 0.0, 0.0);
    return {{a, b, c}, {w.x, w.y, w.z}};
}

int DirectionSet::Nearest(const glm::dvec3& direction) const {
    const glm::dvec3 d = glm::normalize(direction);
    const auto& [a, b, c] = faces_[LocateFace(d)];
    int best = a;
    for (int v : {b, c}) {
        if (glm::dot(directions_[v], d) > glm::dot(directions_[best], d)) best = v;
    }
    return best;
}

}  // namespace leaflux
