#include "solver/raytrace/sun_map.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include "solver/util/check.h"

namespace leaflux {
namespace {

constexpr int kTile = 128;                    // pixels a side of a tile
constexpr std::int64_t kMostTiles = 1 << 22;  // of the plane over the organs

// The plane across a direction of light: pixel (i, j) has its centre at
// origin + size (i + ½, j + ½) along u and v; depth grows towards the light.
struct Plane {
    glm::dvec3 u{0.0}, v{0.0}, toward{0.0};
    glm::dvec2 origin{0.0};
    double size = 0.0;  // m a pixel side
    std::int64_t width = 0, height = 0;
    std::int64_t tilesAcross = 0, tilesDown = 0;

    Plane(const glm::dvec3& w) : toward(w) {
        const glm::dvec3 a =
            std::abs(w.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
        u = glm::normalize(glm::cross(a, w));
        v = glm::cross(w, u);
    }
    glm::dvec2 Across(const glm::dvec3& x) const { return {glm::dot(x, u), glm::dot(x, v)}; }
};

// A triangle on the plane: corners in pixels, ordered anticlockwise, with their depths,
// and the pixels whose centres its box holds (clipped to the plane).
struct Drawn {
    glm::dvec2 p[3];
    double depth[3];
    double area2 = 0.0;  // twice its area in pixels; 0: it covers no pixel centre
    std::int64_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;
};

Drawn Draw(const RayScene& scene, const Plane& plane, std::uint32_t t) {
    const std::array<glm::dvec3, 3> corners = scene.Corners(t);
    Drawn d;
    for (int k = 0; k < 3; ++k) {
        d.p[k] = (plane.Across(corners[k]) - plane.origin) / plane.size;
        d.depth[k] = glm::dot(corners[k], plane.toward);
    }
    d.area2 = (d.p[1].x - d.p[0].x) * (d.p[2].y - d.p[0].y) -
              (d.p[2].x - d.p[0].x) * (d.p[1].y - d.p[0].y);
    if (d.area2 < 0.0) {
        std::swap(d.p[1], d.p[2]);
        std::swap(d.depth[1], d.depth[2]);
        d.area2 = -d.area2;
    }
    if (!(d.area2 > 0.0)) return d;
    const auto first = [](double lo) { return static_cast<std::int64_t>(std::ceil(lo - 0.5)); };
    const auto last = [](double hi) { return static_cast<std::int64_t>(std::floor(hi - 0.5)); };
    const double xMin = std::min({d.p[0].x, d.p[1].x, d.p[2].x});
    const double xMax = std::max({d.p[0].x, d.p[1].x, d.p[2].x});
    const double yMin = std::min({d.p[0].y, d.p[1].y, d.p[2].y});
    const double yMax = std::max({d.p[0].y, d.p[1].y, d.p[2].y});
    // Far off the plane (a ground's far corners): clipped before they are rounded.
    const double w = static_cast<double>(plane.width), h = static_cast<double>(plane.height);
    d.x0 = first(std::max(xMin, 0.0)), d.x1 = last(std::min(xMax, w));
    d.y0 = first(std::max(yMin, 0.0)), d.y1 = last(std::min(yMax, h));
    d.x0 = std::max<std::int64_t>(d.x0, 0), d.x1 = std::min(d.x1, plane.width - 1);
    d.y0 = std::max<std::int64_t>(d.y0, 0), d.y1 = std::min(d.y1, plane.height - 1);
    return d;
}

// Visits the rows of the pixels of tile (tx0, ty0) whose centres triangle d covers:
// visit(at, n, z, dz), the row's first pixel at index `at` of the tile, n pixels, depth z
// at the first and dz from one to the next. Edge k faces corner k: e_k(q) = (p[k+2] −
// p[k+1]) × (q − p[k+1]), all ≥ 0 inside, summing to area2; the depth is Σ e_k depth_k /
// area2. A row's pixels inside are those between the bounds each edge sets.
template <class Visit>
void EachSpan(const Drawn& d, std::int64_t tx0, std::int64_t ty0, int tile, Visit visit) {
    const std::int64_t x0 = std::max(d.x0, tx0), x1 = std::min(d.x1, tx0 + tile - 1);
    const std::int64_t y0 = std::max(d.y0, ty0), y1 = std::min(d.y1, ty0 + tile - 1);
    double ex[3], ey[3], e0[3];
    for (int e = 0; e < 3; ++e) {
        const glm::dvec2 a = d.p[(e + 1) % 3], b = d.p[(e + 2) % 3];
        ex[e] = -(b.y - a.y), ey[e] = b.x - a.x;
        const glm::dvec2 q(x0 + 0.5, y0 + 0.5);
        e0[e] = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
    }
    const auto depthAt = [&](const double* e) {
        return (e[0] * d.depth[0] + e[1] * d.depth[1] + e[2] * d.depth[2]) / d.area2;
    };
    const double dzdx = depthAt(ex);
    const std::int64_t columns = x1 - x0;
    for (std::int64_t y = y0; y <= y1; ++y) {
        double e[3];
        std::int64_t from = 0, to = columns;
        for (int j = 0; j < 3; ++j) {
            e[j] = e0[j] + ey[j] * static_cast<double>(y - y0);
            // e_j + ex_j k ≥ 0 for the k-th pixel of the row.
            if (ex[j] > 0.0) {
                const double first = std::ceil(-e[j] / ex[j]);
                if (first > static_cast<double>(from))
                    from = first > static_cast<double>(columns) ? columns + 1
                                                                : static_cast<std::int64_t>(first);
            } else if (ex[j] < 0.0) {
                const double last = std::floor(e[j] / -ex[j]);
                if (last < static_cast<double>(to))
                    to = last < 0.0 ? -1 : static_cast<std::int64_t>(last);
            } else if (e[j] < 0.0) {
                to = -1;
            }
        }
        if (from > to) continue;
        visit(static_cast<std::size_t>((y - ty0) * tile + (x0 - tx0) + from), to - from + 1,
              depthAt(e) + dzdx * static_cast<double>(from), dzdx);
    }
}

// The pixel counts of the organ triangles under one direction of light.
struct Counts {
    std::vector<std::uint32_t> covered, lit;
    std::vector<std::uint8_t> tied;  // another triangle as near in a pixel of it
    double pixelM = 0.0;
};

// Tiles first..last of `drawn` (their triangles' places in a list of all from `start`):
// each triangle meeting them listed, then each tile drawn and its organs' pixels counted.
template <class Asked, class EachTile>
void DrawTiles(const RayScene& scene, const Plane& plane, std::uint32_t triangles,
               std::uint32_t organs, const Asked& asked, double coplanar,
               const std::vector<std::int64_t>& drawn, const std::vector<std::uint32_t>& start,
               std::size_t first, std::size_t last, const EachTile& eachTile,
               std::vector<std::uint32_t>& listed, Counts& counts) {
    const std::uint32_t base = start[first];
    listed.resize(start[last] - base);
    {
        std::vector<std::uint32_t> next(start.begin() + first, start.begin() + last);
        tbb::parallel_for(std::uint32_t{0}, triangles, [&](std::uint32_t t) {
            eachTile(Draw(scene, plane, t), [&](std::uint32_t k) {
                if (k < first || k >= last) return;
                listed[std::atomic_ref<std::uint32_t>(next[k - first])
                           .fetch_add(1, std::memory_order_relaxed) -
                       base] = t;
            });
        });
    }
    tbb::parallel_for(first, last, [&](std::size_t k) {
        const std::int64_t tx0 = drawn[k] % plane.tilesAcross * kTile;
        const std::int64_t ty0 = drawn[k] / plane.tilesAcross * kTile;
        // In triangle order, whatever order the threads listed them in.
        std::sort(listed.begin() + (start[k] - base), listed.begin() + (start[k + 1] - base));
        const std::span<const std::uint32_t> list(listed.data() + (start[k] - base),
                                                  start[k + 1] - start[k]);
        thread_local std::vector<double> depth;
        thread_local std::vector<std::uint32_t> covered, lit, tied;
        depth.assign(kTile * kTile, -std::numeric_limits<double>::infinity());
        covered.assign(list.size(), 0);
        lit.assign(list.size(), 0);
        tied.assign(list.size(), 0);
        // The depth nearest the light at each pixel, then the organ triangles' pixels that
        // are within `coplanar` of it: two triangles in one plane do not shade each other,
        // as a ray from a point of one passes the other.
        for (std::size_t i = 0; i < list.size(); ++i) {
            EachSpan(Draw(scene, plane, list[i]), tx0, ty0, kTile,
                     [&](std::size_t at, std::int64_t n, double z, double dz) {
                         covered[i] += static_cast<std::uint32_t>(n);
                         for (std::int64_t c = 0; c < n; ++c, z += dz)
                             depth[at + c] = std::max(depth[at + c], z);
                     });
        }
        for (std::size_t i = 0; i < list.size() && list[i] < organs; ++i) {
            if (covered[i] == 0 || !asked(list[i])) continue;
            EachSpan(Draw(scene, plane, list[i]), tx0, ty0, kTile,
                     [&](std::size_t at, std::int64_t n, double z, double dz) {
                         for (std::int64_t c = 0; c < n; ++c, z += dz) {
                             if (z < depth[at + c] - coplanar) continue;
                             ++lit[i];
                             tied[i] += z < depth[at + c] ? 1 : 0;
                         }
                     });
            std::atomic_ref<std::uint32_t>(counts.covered[list[i]])
                .fetch_add(covered[i], std::memory_order_relaxed);
            std::atomic_ref<std::uint32_t>(counts.lit[list[i]])
                .fetch_add(lit[i], std::memory_order_relaxed);
            if (tied[i] > 0)
                std::atomic_ref<std::uint8_t>(counts.tied[list[i]])
                    .store(1, std::memory_order_relaxed);
        }
    });
}

// Draws the scene's triangles across `toward` into `counts`: per organ triangle, the pixels
// it covers and those where it is the nearest to the light.
void DrawAlong(const RayScene& scene, std::uint32_t triangles, std::uint32_t organs,
               std::span<const std::uint8_t> wanted, const glm::dvec3& toward,
               double pixelsPerTriangle, std::uint32_t mostListed, Counts& counts) {
    const auto asked = [&](std::uint32_t t) { return t < organs && (wanted.empty() || wanted[t]); };
    Plane plane(toward);
    // The organs' extent and mean area across the light, which size the pixel.
    struct Extent {
        glm::dvec2 lo{std::numeric_limits<double>::infinity()};
        glm::dvec2 hi{-std::numeric_limits<double>::infinity()};
        double area = 0.0;
        std::int64_t count = 0;
    };
    const Extent extent = tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(0, organs), Extent{},
        [&](const tbb::blocked_range<std::uint32_t>& range, Extent e) {
            for (std::uint32_t t = range.begin(); t != range.end(); ++t) {
                const std::array<glm::dvec3, 3> c = scene.Corners(t);
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k) {
                    p[k] = plane.Across(c[k]);
                    e.lo = glm::min(e.lo, p[k]), e.hi = glm::max(e.hi, p[k]);
                }
                const double area = 0.5 * std::abs((p[1].x - p[0].x) * (p[2].y - p[0].y) -
                                                   (p[2].x - p[0].x) * (p[1].y - p[0].y));
                if (area > 0.0) e.area += area, ++e.count;
            }
            return e;
        },
        [](Extent a, const Extent& b) {
            a.lo = glm::min(a.lo, b.lo), a.hi = glm::max(a.hi, b.hi);
            a.area += b.area, a.count += b.count;
            return a;
        });
    if (extent.count == 0) return;
    plane.origin = extent.lo;
    plane.size =
        std::sqrt(extent.area / std::max(static_cast<double>(extent.count) * pixelsPerTriangle,
                                         SunMap::kLeastPixels));
    const glm::dvec2 span = extent.hi - extent.lo;
    for (;;) {
        plane.width = static_cast<std::int64_t>(std::ceil(span.x / plane.size)) + 1;
        plane.height = static_cast<std::int64_t>(std::ceil(span.y / plane.size)) + 1;
        plane.tilesAcross = (plane.width + kTile - 1) / kTile;
        plane.tilesDown = (plane.height + kTile - 1) / kTile;
        if (plane.tilesAcross * plane.tilesDown <= kMostTiles) break;
        plane.size *= 2.0;  // organs spread far and wide: coarser pixels
    }
    const std::int64_t tiles = plane.tilesAcross * plane.tilesDown;
    // Depths this close are one plane's: the corners' single precision, 2⁻²¹ of the
    // scene's largest coordinate (and of 1 m), under a micrometre for a plant.
    const FlatScene& frame = scene.Flat();
    const double coplanar = std::ldexp(
        std::max({1.0, glm::length(frame.boundsMin), glm::length(frame.boundsMax)}), -21);
    counts.pixelM = std::max(counts.pixelM, plane.size);
    // The tiles the organs asked for lie in, numbered.
    std::vector<std::uint8_t> organTile(tiles, 0);
    tbb::parallel_for(std::uint32_t{0}, organs, [&](std::uint32_t t) {
        if (!asked(t)) return;
        const Drawn d = Draw(scene, plane, t);
        for (std::int64_t ty = d.y0 / kTile; ty <= d.y1 / kTile && d.y0 <= d.y1; ++ty) {
            for (std::int64_t tx = d.x0 / kTile; tx <= d.x1 / kTile && d.x0 <= d.x1; ++tx)
                std::atomic_ref<std::uint8_t>(organTile[ty * plane.tilesAcross + tx])
                    .store(1, std::memory_order_relaxed);
        }
    });
    // The tiles drawn, rising, and where each row of tiles starts among them: a number for
    // every tile of the plane took 4 bytes a tile, 16 MB at a plantation's peak.
    std::vector<std::int64_t> drawn;
    std::vector<std::uint32_t> rowStart(plane.tilesDown + 1, 0);
    for (std::int64_t k = 0; k < tiles; ++k) {
        if (!organTile[k]) continue;
        drawn.push_back(k);
        ++rowStart[k / plane.tilesAcross + 1];
    }
    organTile = {};
    for (std::int64_t row = 0; row < plane.tilesDown; ++row) rowStart[row + 1] += rowStart[row];
    // Every triangle into the drawn tiles its box meets (their numbers, rising): counted,
    // then listed.
    std::vector<std::uint32_t> start(drawn.size() + 1, 0);
    const auto eachTile = [&](const Drawn& d, auto&& visit) {
        if (d.x0 > d.x1 || d.y0 > d.y1) return;
        for (std::int64_t ty = d.y0 / kTile; ty <= d.y1 / kTile; ++ty) {
            const auto rowEnd = drawn.begin() + rowStart[ty + 1];
            const std::int64_t last = ty * plane.tilesAcross + d.x1 / kTile;
            for (auto k = std::lower_bound(drawn.begin() + rowStart[ty], rowEnd,
                                           ty * plane.tilesAcross + d.x0 / kTile);
                 k != rowEnd && *k <= last; ++k)
                visit(static_cast<std::uint32_t>(k - drawn.begin()));
        }
    };
    tbb::parallel_for(std::uint32_t{0}, triangles, [&](std::uint32_t t) {
        eachTile(Draw(scene, plane, t), [&](std::uint32_t k) {
            std::atomic_ref<std::uint32_t>(start[k + 1]).fetch_add(1, std::memory_order_relaxed);
        });
    });
    for (std::size_t k = 0; k < drawn.size(); ++k) start[k + 1] += start[k];
    std::vector<std::uint32_t> listed;
    for (std::size_t first = 0, last; first < drawn.size(); first = last) {
        last = first + 1;
        while (last < drawn.size() && start[last + 1] - start[first] <= mostListed) ++last;
        DrawTiles(scene, plane, triangles, organs, asked, coplanar, drawn, start, first, last,
                  eachTile, listed, counts);
    }
}

}  // namespace

SunMaps::SunMaps(const RayScene& rays, const FlatScene& receivers, const std::vector<Sun>& suns,
                 std::span<const std::uint8_t> wanted) {
    if (rays.Periodic()) return;
    std::uint32_t triangles = 0, organs = 0;
    bool organsFirst = true;
    for (const Receiver& r : receivers.receivers) {
        triangles = std::max(triangles, r.firstTriangle + r.triangleCount);
        organsFirst = organsFirst && r.kind == ReceiverKind::kOrgan;
        if (organsFirst) organs += r.triangleCount;
    }
    if (organs == 0) return;
    for (const Sun& sun : suns)
        maps.emplace_back(rays, triangles, organs, sun.toward, sun.cosRadius,
                          SunMap::kPixelsPerTriangle, wanted);
}

SunMap::SunMap(const RayScene& scene, std::uint32_t triangles, std::uint32_t organTriangles,
               const glm::dvec3& toward, double cosRadius, double pixelsPerTriangle,
               std::span<const std::uint8_t> wanted, std::uint32_t mostListed)
    : toward_(toward), cosRadius_(cosRadius) {
    LEAFLUX_CHECK(!scene.Periodic());
    LEAFLUX_CHECK(organTriangles <= triangles);
    LEAFLUX_CHECK(wanted.empty() || wanted.size() == organTriangles);
    Counts counts{std::vector<std::uint32_t>(organTriangles, 0),
                  std::vector<std::uint32_t>(organTriangles, 0),
                  std::vector<std::uint8_t>(organTriangles, 0)};
    if (cosRadius >= 1.0) {
        DrawAlong(scene, triangles, organTriangles, wanted, toward, pixelsPerTriangle, mostListed,
                  counts);
    } else {
        // Directions even in solid angle over the disc, turning by the golden angle.
        const Plane around(toward);
        const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
        for (int k = 0; k < kDiscDirections; ++k) {
            const double cosTheta = 1.0 - (k + 0.5) / kDiscDirections * (1.0 - cosRadius);
            const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
            const double phi = golden * k;
            const glm::dvec3 w = cosTheta * toward +
                                 sinTheta * (std::cos(phi) * around.u + std::sin(phi) * around.v);
            DrawAlong(scene, triangles, organTriangles, wanted, glm::normalize(w),
                      pixelsPerTriangle, mostListed, counts);
        }
    }
    // Once drawn: beside the counts and the tiles' lists it took 10 MB more at a plantation's
    // peak.
    lit_.assign(organTriangles, kNone);
    for (std::uint32_t t = 0; t < organTriangles; ++t) {
        if (counts.covered[t] == 0) continue;
        lit_[t] = static_cast<std::uint16_t>(
            std::lround(static_cast<double>(counts.lit[t]) * kWhole / counts.covered[t]));
    }
    tied_ = std::move(counts.tied);
    pixelM_ = counts.pixelM;
}

}  // namespace leaflux
