// The ray engine: RAII handles around Embree 3 and the two queries every solver needs,
// closest hit and occlusion, on a FlatScene — optionally repeated periodically in x and y.
//
// A RayScene is committed once in its constructor and read-only afterwards: trace it from
// any number of threads; to change the geometry, build a new one (rebuild after a change).
// Nothing invalid reaches Embree: FlatScene comes from a validated Scene.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "solver/scene/geometry.h"

namespace leaflux {

// Sets flush-to-zero and denormals-are-zero on the calling thread, as Embree asks.
void SetFlushToZero();

struct RayStart;
// Embree's ray from start along direction up to tFar (infinity: unbounded); its id is the
// start's triangle, which the triangles' filter ignores.
RTCRay EmbreeRay(const RayStart& start, const glm::dvec3& direction, double tFar);

class RayDevice {
  public:
    RayDevice();
    ~RayDevice();
    RayDevice(const RayDevice&) = delete;
    RayDevice& operator=(const RayDevice&) = delete;

    RTCDevice Get() const { return device_; }
    // One device for the process; Embree devices are thread-safe.
    static std::shared_ptr<RayDevice> Shared();

  private:
    RTCDevice device_;
};

inline constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

// Where a ray starts: a point (FlatScene local frame) and, when it leaves a surface, that
// surface's triangle, which the ray then never hits again (robust without an offset, even
// between leaves 1 µm apart).
struct RayStart {
    glm::dvec3 origin;
    std::uint32_t triangle = kNoTriangle;
    int copy = 0;  // which periodic copy of `triangle` the origin is on (0 in a plain scene)
};

enum class RayFate { kHit, kEscapedUp, kEscapedDown, kEscaped };

struct RayHit {
    RayFate fate = RayFate::kEscaped;
    std::uint32_t triangle = kNoTriangle;
    double distance = std::numeric_limits<double>::infinity();
    RayStart next;  // the hit point as the start of the next ray (kHit only)
};

// A run of a RayScene's triangles: `count` triangles of `vertices` vertices of its own, or
// (copyOf ≥ 0) those of the earlier run copyOf, moved by `moved` (in the engine's frame)
// and numbered after the runs before it.
struct RayRun {
    std::uint32_t count = 0, vertices = 0;
    std::int32_t copyOf = -1;
    glm::dmat4 moved{1.0};
};

class RayScene {
  public:
    // `periodic`: the tile, in the FlatScene's local frame, repeated in x and y. Geometry
    // may overhang the tile by less than one tile width.
    // `triangles`: the flat scene's first so many alone (all of them by default).
    RayScene(const FlatScene& flat, std::optional<PeriodicDomain> periodic,
             std::shared_ptr<RayDevice> device = RayDevice::Shared(),
             std::uint32_t triangles = kNoTriangle);
    // Over runs of triangles, numbered one after the other (RayRun): each of its own, whose
    // vertices (3 floats each, in the frame of `frame`: origin, bounds; its triangles
    // unused) and triangles (3 indices into the run's vertices each) `place` writes, a
    // buffer per run (null for a copy); or a copy of an earlier run, held as an Embree
    // instance of it. Not periodic. `compact`: Embree's compact hierarchy, whose leaves
    // index the vertices instead of copying them: a lower peak for a slower solve (the
    // instanced-compact rows of docs/results.md, "Time and memory against size").
    using PlaceRuns = std::function<void(const std::vector<float*>& xyz,
                                         const std::vector<std::uint32_t*>& indices)>;
    RayScene(const FlatScene& frame, std::vector<RayRun> runs, const PlaceRuns& place,
             bool compact = false, std::shared_ptr<RayDevice> device = RayDevice::Shared());
    ~RayScene();
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    // The first surface along the ray. In a periodic scene a ray that leaves the tile
    // sideways re-enters on the other side; it escapes up or down past the scene's bounds.
    RayHit Trace(const RayStart& start, const glm::dvec3& direction) const;
    // Trace for many rays, traced together: hits[i] is ray i's.
    void Trace(const std::vector<RayStart>& starts, const std::vector<glm::dvec3>& directions,
               std::vector<RayHit>& hits) const;

    // Whether anything lies along the ray within maxDistance (infinity: to the sky).
    bool Occluded(const RayStart& start, const glm::dvec3& direction,
                  double maxDistance = std::numeric_limits<double>::infinity()) const;
    // Occluded to the sky, for rays from many starts in one direction (the rays of a sun
    // or sky cone), traced together: occluded[i] is 1 where ray i is blocked.
    void Occluded(const std::vector<RayStart>& starts, const glm::dvec3& direction,
                  std::vector<std::uint8_t>& occluded) const;
    // The same with a direction per ray (the rays of a cone of light).
    void Occluded(const std::vector<RayStart>& starts, const std::vector<glm::dvec3>& directions,
                  std::vector<std::uint8_t>& occluded) const;
    // Triangles as sorted, disjoint ranges [from, to) of their indices.
    using TriangleRanges = std::vector<std::array<std::uint32_t, 2>>;
    // Ranges in any order, overlapping or touching, as such: sorted, those that meet merged.
    static TriangleRanges Merged(TriangleRanges ranges) {
        std::sort(ranges.begin(), ranges.end());
        TriangleRanges merged;
        for (const auto& range : ranges) {
            if (!merged.empty() && range[0] <= merged.back()[1]) {
                merged.back()[1] = std::max(merged.back()[1], range[1]);
            } else {
                merged.push_back(range);
            }
        }
        return merged;
    }
    static bool InRanges(const TriangleRanges& ranges, std::uint32_t triangle) {
        const auto after = std::upper_bound(
            ranges.begin(), ranges.end(), triangle,
            [](std::uint32_t t, const std::array<std::uint32_t, 2>& r) { return t < r[0]; });
        return after != ranges.begin() && triangle < (after - 1)->at(1);
    }
    // Whether one of the scene's first `triangles` triangles (a flat scene's organs, which
    // it lists first), but those of `skip`, lies along the ray within maxDistance. Not
    // periodic.
    bool OccludedByFirst(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                         std::uint32_t triangles, const TriangleRanges* skip = nullptr) const;
    // Whether a triangle of `only` lies along the ray within maxDistance, the others passed.
    // Not periodic.
    bool OccludedAmong(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                       const TriangleRanges& only) const;
    // The corners of triangle t, in the frame its rays are traced in (not periodic copies).
    std::array<glm::dvec3, 3> Corners(std::uint32_t t) const {
        if (!runs_.empty()) return RunCorners(t);
        std::array<glm::dvec3, 3> corners;
        for (int k = 0; k < 3; ++k) {
            const float* v = xyz_ + 3 * static_cast<std::size_t>(indices_[3 * std::size_t{t} + k]);
            corners[k] = glm::dvec3(v[0], v[1], v[2]);
        }
        return corners;
    }

    // A group of triangles: those whose rank (an index by triangle) lies in [first, last).
    struct Group {
        const std::uint32_t* rank;
        std::uint32_t first, last;
    };
    // Whether a triangle of the group lies along the ray within maxDistance, in the tile
    // itself (a periodic scene's copies do not count): the shadow a group casts on itself.
    bool OccludedByGroup(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                         const Group& group) const;

    const FlatScene& Flat() const { return flat_; }
    bool Periodic() const { return periodic_.has_value(); }

  private:
    using PlaceMesh = std::function<void(float* xyz, std::uint32_t* indices)>;
    void BuildMesh(std::size_t triangles, std::size_t vertices, const PlaceMesh& place);
    void BuildTop();  // the mesh, or its 9 periodic copies
    std::array<glm::dvec3, 3> RunCorners(std::uint32_t t) const;
    // What the filter reads to number a hit: each run's first triangle (null: one mesh).
    const std::uint32_t* RunFirst() const { return runFirst_.empty() ? nullptr : runFirst_.data(); }
    template <class Direction>
    void OccludedAlong(const std::vector<RayStart>& starts, const Direction& direction,
                       bool coherent, std::vector<std::uint8_t>& occluded) const;
    RayHit TraceOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const;
    bool OccludedOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const;
    // Wraps a start into the tile; returns the distance to the tile's side along direction.
    double IntoTile(RayStart& start, const glm::dvec3& direction) const;
    // Moves `at` to where it leaves the tile; false when it has left the scene up or down.
    bool StepToTileSide(RayStart& at, const glm::dvec3& direction, double toSide) const;

    const FlatScene& flat_;
    std::optional<PeriodicDomain> periodic_;
    std::shared_ptr<RayDevice> device_;
    RTCScene mesh_ = nullptr;     // the triangles
    RTCScene top_ = nullptr;      // the triangles, or 9 instances of them in a periodic scene
    const float* xyz_ = nullptr;  // the triangles' vertices, 3 floats each
    const std::uint32_t* indices_ = nullptr;  // and their 3 vertex indices each
    // Built from runs of which some are copies (one mesh of its own is xyz_ and indices_):
    // each run's first triangle (by its geometry's id in top_, which the
    // filter and hits read), its vertices and indices (its original's for a copy) and
    // where a copy is moved to; the originals' scenes, which copies instance.
    struct Run {
        std::uint32_t first = 0;
        const float* xyz = nullptr;
        const std::uint32_t* indices = nullptr;
        std::optional<glm::dmat4> moved;
    };
    std::vector<Run> runs_;
    std::vector<std::uint32_t> runFirst_;
    std::vector<RTCScene> originals_;
};

// The scene's triangles in a ray engine, numbered as Flatten numbers them, in the frame of
// `receivers` (ReceiversOf the scene), placed straight into it: the instanced solver's
// exact shadows without a flat scene of the triangles in double precision. Its organs come
// first; walls, roofs and the ground shade the organs and one another as in the flat
// scene's engine (the organs alone, a room's leaves took the sky through its walls).
// `compact`: Embree's compact hierarchy (as RayScene's), and each plant that copies
// another exactly (FindCopies) held as an instance of it, the two in one hierarchy: less
// memory for a slower solve (rays cross two hierarchies where a copy is met, and a turned
// copy's box is wider than its tree).
std::unique_ptr<RayScene> SceneRays(const Scene& scene, const FlatScene& receivers,
                                    bool compact = false);

}  // namespace leaflux
