#include "solver/raytrace/raytrace.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <string>
#include <unordered_map>

#include "solver/scene/copies.h"
#include "solver/util/check.h"

namespace leaflux {
namespace {

// A ray crossing this many tiles of a periodic scene without hitting anything runs nearly
// parallel to the ground through empty space: it is taken as escaped.
constexpr int kMaxTileCrossings = 10000;

// Periodic copies: index 0 is the tile itself, 1..8 its neighbours.
constexpr int kCopyOffsets[9][2] = {{0, 0}, {1, 0},  {-1, 0}, {0, 1},  {0, -1},
                                    {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};

int CopyIndex(int i, int j) {
    for (int k = 0; k < 9; ++k) {
        if (kCopyOffsets[k][0] == i && kCopyOffsets[k][1] == j) return k;
    }
    return -1;
}

// The intersect context with the periodic copy of the triangle rays leave from; the ray's
// id holds that triangle, which the filter ignores. With a group (RayScene::OccludedByGroup),
// only the group's triangles in the tile itself count; with a limit, only the triangles
// before it.
struct StartContext {
    RTCIntersectContext context;
    int copy;
    const RayScene::Group* group = nullptr;
    std::uint32_t limit = kNoTriangle;
    const RayScene::TriangleRanges* skip = nullptr;  // triangles that do not count
    const RayScene::TriangleRanges* only = nullptr;  // the only triangles that count
    // A scene built from runs: each run's first triangle, by its geometry's id in the top
    // scene (an instance's for a copy); null for one mesh, whose instances are periodic copies.
    const std::uint32_t* runFirst = nullptr;
};

// The triangle a hit is on, numbered as the scene's, and the periodic copy it is on.
std::pair<std::uint32_t, int> HitTriangle(const std::uint32_t* runFirst, unsigned instance,
                                          unsigned geometry, unsigned primitive) {
    if (runFirst) {
        const unsigned run = instance == RTC_INVALID_GEOMETRY_ID ? geometry : instance;
        return {runFirst[run] + primitive, 0};
    }
    return {primitive, instance == RTC_INVALID_GEOMETRY_ID ? 0 : static_cast<int>(instance)};
}

void IgnoreStartTriangle(const RTCFilterFunctionNArguments* args) {
    const auto* start = reinterpret_cast<const StartContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned triangle = RTCRayN_id(args->ray, args->N, i);
        if (triangle == kNoTriangle && !start->group && start->limit == kNoTriangle &&
            !start->skip && !start->only)
            continue;
        const auto [primitive, copy] = HitTriangle(
            start->runFirst, RTCHitN_instID(args->hit, args->N, i, 0),
            RTCHitN_geomID(args->hit, args->N, i), RTCHitN_primID(args->hit, args->N, i));
        if (primitive >= start->limit) args->valid[i] = 0;
        if (start->skip && RayScene::InRanges(*start->skip, primitive)) args->valid[i] = 0;
        if (start->only && !RayScene::InRanges(*start->only, primitive)) args->valid[i] = 0;
        if (primitive == triangle && copy == start->copy) args->valid[i] = 0;
        if (const RayScene::Group* group = start->group) {
            const std::uint32_t rank = group->rank[primitive];
            if (copy != 0 || rank < group->first || rank >= group->last) args->valid[i] = 0;
        }
    }
}

void ThrowOnEmbreeError(void*, RTCError code, const char* message) {
    throw InternalError("embree error " + std::to_string(code) + ": " + (message ? message : ""));
}

StartContext MakeContext(int copy, const std::uint32_t* runFirst) {
    StartContext context;
    rtcInitIntersectContext(&context.context);
    context.copy = copy;
    context.runFirst = runFirst;
    return context;
}

}  // namespace

RTCRay EmbreeRay(const RayStart& start, const glm::dvec3& direction, double tFar) {
    RTCRay ray;
    ray.org_x = static_cast<float>(start.origin.x);
    ray.org_y = static_cast<float>(start.origin.y);
    ray.org_z = static_cast<float>(start.origin.z);
    ray.dir_x = static_cast<float>(direction.x);
    ray.dir_y = static_cast<float>(direction.y);
    ray.dir_z = static_cast<float>(direction.z);
    ray.tnear = 0.0f;
    ray.tfar = std::isinf(tFar) ? std::numeric_limits<float>::infinity() : static_cast<float>(tFar);
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = start.triangle;
    ray.flags = 0;
    return ray;
}

namespace {

RayFate Escape(const glm::dvec3& direction) {
    return direction.z > 0.0 ? RayFate::kEscapedUp : RayFate::kEscapedDown;
}

RTCRayHit EmbreeRayHit(const RayStart& start, const glm::dvec3& direction, double tFar) {
    RTCRayHit rayHit;
    rayHit.ray = EmbreeRay(start, direction, tFar);
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayHit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rayHit;
}

RayHit HitOf(const RTCRayHit& rayHit, const RayStart& start, const glm::dvec3& direction,
             const std::uint32_t* runFirst) {
    RayHit result;
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return result;
    result.fate = RayFate::kHit;
    const auto [triangle, copy] =
        HitTriangle(runFirst, rayHit.hit.instID[0], rayHit.hit.geomID, rayHit.hit.primID);
    result.triangle = triangle;
    result.distance = rayHit.ray.tfar;
    result.next.origin = start.origin + direction * result.distance;
    result.next.triangle = triangle;
    result.next.copy = copy;
    return result;
}
}  // namespace

void SetFlushToZero() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

RayDevice::RayDevice() : device_(rtcNewDevice(nullptr)) {
    if (!device_) throw InternalError("embree: cannot create a device");
    rtcSetDeviceErrorFunction(device_, ThrowOnEmbreeError, nullptr);
}

RayDevice::~RayDevice() { rtcReleaseDevice(device_); }

std::shared_ptr<RayDevice> RayDevice::Shared() {
    static std::shared_ptr<RayDevice> device = std::make_shared<RayDevice>();
    return device;
}

RayScene::RayScene(const FlatScene& flat, std::optional<PeriodicDomain> periodic,
                   std::shared_ptr<RayDevice> device, std::uint32_t triangles)
    : flat_(flat), periodic_(periodic), device_(std::move(device)) {
    const std::size_t count = std::min<std::size_t>(flat.triangles.size(), triangles);
    BuildMesh(count, 3 * count, [&](float* xyz, std::uint32_t* indices) {
        for (std::size_t t = 0; t < count; ++t) {
            const Triangle& tri = flat.triangles[t];
            for (const glm::dvec3* corner : {&tri.a, &tri.b, &tri.c}) {
                *xyz++ = static_cast<float>(corner->x);
                *xyz++ = static_cast<float>(corner->y);
                *xyz++ = static_cast<float>(corner->z);
            }
        }
        for (std::size_t i = 0; i < 3 * count; ++i) indices[i] = static_cast<std::uint32_t>(i);
    });
    BuildTop();
}

namespace {
// Embree's column-major 3×4 of an affine frame.
std::array<float, 12> Float3x4(const glm::dmat4& m) {
    std::array<float, 12> out;
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 3; ++r) out[3 * c + r] = static_cast<float>(m[c][r]);
    }
    return out;
}

void AttachInstance(RTCDevice rtc, RTCScene top, RTCScene instanced, const glm::dmat4& moved,
                    unsigned id) {
    RTCGeometry instance = rtcNewGeometry(rtc, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(instance, instanced);
    const std::array<float, 12> transform = Float3x4(moved);
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, transform.data());
    rtcCommitGeometry(instance);
    rtcAttachGeometryByID(top, instance, id);
    rtcReleaseGeometry(instance);
}

RTCScene NewScene(RTCDevice rtc, bool compact) {
    RTCScene scene = rtcNewScene(rtc);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    if (compact) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_COMPACT);
    return scene;
}
}  // namespace

RayScene::RayScene(const FlatScene& frame, std::vector<RayRun> runs, const PlaceRuns& place,
                   bool compact, std::shared_ptr<RayDevice> device)
    : flat_(frame), device_(std::move(device)) {
    SetFlushToZero();
    RTCDevice rtc = device_->Get();
    top_ = NewScene(rtc, compact);
    // A run that has copies becomes a scene of its own, which it and its copies instance.
    std::vector<bool> copied(runs.size(), false);
    for (std::size_t k = 0; k < runs.size(); ++k) {
        if (runs[k].copyOf < 0) continue;
        const auto original = static_cast<std::size_t>(runs[k].copyOf);
        LEAFLUX_CHECK(original < k && runs[original].copyOf < 0 &&
                      runs[original].count == runs[k].count);
        copied[original] = true;
    }
    std::vector<RTCGeometry> geometries(runs.size(), nullptr);
    std::vector<float*> xyz(runs.size(), nullptr);
    std::vector<std::uint32_t*> indices(runs.size(), nullptr);
    runs_.resize(runs.size());
    runFirst_.resize(runs.size());
    std::uint32_t first = 0;
    for (std::size_t k = 0; k < runs.size(); ++k) {
        runs_[k].first = runFirst_[k] = first;
        first += runs[k].count;
        if (runs[k].copyOf >= 0 || runs[k].count == 0) continue;
        RTCGeometry geometry = rtcNewGeometry(rtc, RTC_GEOMETRY_TYPE_TRIANGLE);
        xyz[k] = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                             RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                             runs[k].vertices));
        indices[k] = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(std::uint32_t), runs[k].count));
        rtcSetGeometryIntersectFilterFunction(geometry, IgnoreStartTriangle);
        rtcSetGeometryOccludedFilterFunction(geometry, IgnoreStartTriangle);
        geometries[k] = geometry;
    }
    place(xyz, indices);
    std::vector<RTCScene> sceneOf(runs.size(), nullptr);
    for (std::size_t k = 0; k < runs.size(); ++k) {
        const auto id = static_cast<unsigned>(k);
        if (RTCGeometry geometry = geometries[k]) {
            runs_[k].xyz = xyz[k], runs_[k].indices = indices[k];
            rtcCommitGeometry(geometry);
            if (copied[k]) {
                sceneOf[k] = originals_.emplace_back(NewScene(rtc, compact));
                rtcAttachGeometryByID(sceneOf[k], geometry, 0);
                rtcCommitScene(sceneOf[k]);
                AttachInstance(rtc, top_, sceneOf[k], glm::dmat4(1.0), id);
            } else {
                rtcAttachGeometryByID(top_, geometry, id);
            }
            rtcReleaseGeometry(geometry);  // its scene holds it now
        } else if (runs[k].copyOf >= 0 && runs[k].count > 0) {
            const auto original = static_cast<std::size_t>(runs[k].copyOf);
            runs_[k].xyz = xyz[original], runs_[k].indices = indices[original];
            runs_[k].moved = runs[k].moved;
            AttachInstance(rtc, top_, sceneOf[original], runs[k].moved, id);
        }
    }
    rtcCommitScene(top_);
    if (runs_.size() == 1 && !runs_[0].moved) {  // one mesh: hits numbered as its own
        xyz_ = runs_[0].xyz, indices_ = runs_[0].indices;
        runs_.clear();
        runFirst_.clear();
    }
}

std::array<glm::dvec3, 3> RayScene::RunCorners(std::uint32_t t) const {
    // The last run starting at or before t: the one holding it (runs of no triangle start
    // where the next does).
    const auto after = std::upper_bound(runFirst_.begin(), runFirst_.end(), t);
    const Run& run = runs_[static_cast<std::size_t>(after - runFirst_.begin()) - 1];
    const std::size_t local = t - run.first;
    std::array<glm::dvec3, 3> corners;
    for (int k = 0; k < 3; ++k) {
        const float* v = run.xyz + 3 * static_cast<std::size_t>(run.indices[3 * local + k]);
        corners[k] = glm::dvec3(v[0], v[1], v[2]);
        if (run.moved) corners[k] = glm::dvec3(*run.moved * glm::dvec4(corners[k], 1.0));
    }
    return corners;
}

void RayScene::BuildMesh(std::size_t triangles, std::size_t vertices, const PlaceMesh& place) {
    SetFlushToZero();
    RTCDevice rtc = device_->Get();
    mesh_ = NewScene(rtc, false);
    if (triangles > 0) {
        RTCGeometry geometry = rtcNewGeometry(rtc, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* xyz = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
        auto* indices = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(std::uint32_t), triangles));
        place(xyz, indices);
        xyz_ = xyz, indices_ = indices;
        rtcSetGeometryIntersectFilterFunction(geometry, IgnoreStartTriangle);
        rtcSetGeometryOccludedFilterFunction(geometry, IgnoreStartTriangle);
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(mesh_, geometry, 0);
        rtcReleaseGeometry(geometry);  // the scene holds it now
    }
    rtcCommitScene(mesh_);
}

void RayScene::BuildTop() {
    if (!periodic_) {
        top_ = mesh_;
        rtcRetainScene(top_);
        return;
    }
    RTCDevice rtc = device_->Get();
    top_ = rtcNewScene(rtc);
    const double width = periodic_->xMax - periodic_->xMin;
    const double depth = periodic_->yMax - periodic_->yMin;
    for (unsigned k = 0; k < 9; ++k) {
        const glm::dvec3 offset(kCopyOffsets[k][0] * width, kCopyOffsets[k][1] * depth, 0.0);
        AttachInstance(rtc, top_, mesh_, glm::translate(glm::dmat4(1.0), offset), k);
    }
    rtcCommitScene(top_);
}

RayScene::~RayScene() {
    if (top_) rtcReleaseScene(top_);
    for (RTCScene original : originals_) rtcReleaseScene(original);
    if (mesh_) rtcReleaseScene(mesh_);
}

RayHit RayScene::TraceOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const {
    StartContext context = MakeContext(start.copy, RunFirst());
    RTCRayHit rayHit = EmbreeRayHit(start, direction, tFar);
    rtcIntersect1(top_, &context.context, &rayHit);
    return HitOf(rayHit, start, direction, RunFirst());
}

void RayScene::Trace(const std::vector<RayStart>& starts, const std::vector<glm::dvec3>& directions,
                     std::vector<RayHit>& hits) const {
    hits.resize(starts.size());
    if (periodic_) {
        for (std::size_t i = 0; i < starts.size(); ++i) hits[i] = Trace(starts[i], directions[i]);
        return;
    }
    thread_local std::vector<RTCRayHit> rayHits;
    rayHits.clear();
    for (std::size_t i = 0; i < starts.size(); ++i) {
        rayHits.push_back(
            EmbreeRayHit(starts[i], directions[i], std::numeric_limits<double>::infinity()));
    }
    StartContext context = MakeContext(0, RunFirst());
    rtcIntersect1M(top_, &context.context, rayHits.data(), static_cast<unsigned>(rayHits.size()),
                   sizeof(RTCRayHit));
    for (std::size_t i = 0; i < starts.size(); ++i) {
        hits[i] = HitOf(rayHits[i], starts[i], directions[i], RunFirst());
        if (hits[i].fate != RayFate::kHit) hits[i].fate = Escape(directions[i]);
    }
}

bool RayScene::OccludedOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const {
    StartContext context = MakeContext(start.copy, RunFirst());
    RTCRay ray = EmbreeRay(start, direction, tFar);
    rtcOccluded1(top_, &context.context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to -inf on occlusion
}

double RayScene::IntoTile(RayStart& start, const glm::dvec3& direction) const {
    const PeriodicDomain& tile = *periodic_;
    const double width = tile.xMax - tile.xMin, depth = tile.yMax - tile.yMin;
    const double shiftX = std::floor((start.origin.x - tile.xMin) / width);
    const double shiftY = std::floor((start.origin.y - tile.yMin) / depth);
    if (shiftX != 0.0 || shiftY != 0.0) {
        start.origin.x -= shiftX * width;
        start.origin.y -= shiftY * depth;
        // The start triangle's copy moves the other way; beyond the 3×3 it cannot be hit.
        if (start.triangle != kNoTriangle) {
            const int copy = CopyIndex(kCopyOffsets[start.copy][0] - static_cast<int>(shiftX),
                                       kCopyOffsets[start.copy][1] - static_cast<int>(shiftY));
            if (copy < 0) start.triangle = kNoTriangle;
            start.copy = copy < 0 ? 0 : copy;
        }
    }
    double t = std::numeric_limits<double>::infinity();
    if (direction.x > 0.0) t = std::min(t, (tile.xMax - start.origin.x) / direction.x);
    if (direction.x < 0.0) t = std::min(t, (tile.xMin - start.origin.x) / direction.x);
    if (direction.y > 0.0) t = std::min(t, (tile.yMax - start.origin.y) / direction.y);
    if (direction.y < 0.0) t = std::min(t, (tile.yMin - start.origin.y) / direction.y);
    return std::max(t, 0.0);
}

bool RayScene::StepToTileSide(RayStart& at, const glm::dvec3& direction, double toSide) const {
    at.origin += direction * toSide;
    if ((at.origin.z > flat_.boundsMax.z && direction.z >= 0.0) ||
        (at.origin.z < flat_.boundsMin.z && direction.z <= 0.0)) {
        return false;  // above or below everything, and moving away
    }
    // Land exactly on the side so that rounding cannot keep the point in this tile; the
    // next IntoTile moves it to the opposite side.
    const PeriodicDomain& tile = *periodic_;
    const double eps = 1e-12 * (tile.xMax - tile.xMin + tile.yMax - tile.yMin);
    if (direction.x > 0.0 && at.origin.x >= tile.xMax - eps) at.origin.x = tile.xMax;
    if (direction.x < 0.0 && at.origin.x <= tile.xMin + eps) at.origin.x = tile.xMin - eps;
    if (direction.y > 0.0 && at.origin.y >= tile.yMax - eps) at.origin.y = tile.yMax;
    if (direction.y < 0.0 && at.origin.y <= tile.yMin + eps) at.origin.y = tile.yMin - eps;
    return true;
}

RayHit RayScene::Trace(const RayStart& start, const glm::dvec3& direction) const {
    if (!periodic_) {
        RayHit hit = TraceOnce(start, direction, std::numeric_limits<double>::infinity());
        if (hit.fate != RayFate::kHit) hit.fate = Escape(direction);
        return hit;
    }
    RayStart at = start;
    double travelled = 0.0;
    for (int crossing = 0; crossing < kMaxTileCrossings; ++crossing) {
        const double toSide = IntoTile(at, direction);
        RayHit hit = TraceOnce(at, direction, toSide);
        if (hit.fate == RayFate::kHit) {
            hit.distance += travelled;
            return hit;
        }
        if (std::isinf(toSide)) break;
        if (!StepToTileSide(at, direction, toSide)) break;
        travelled += toSide;
    }
    RayHit escaped;
    escaped.fate = Escape(direction);
    return escaped;
}

void RayScene::Occluded(const std::vector<RayStart>& starts, const glm::dvec3& direction,
                        std::vector<std::uint8_t>& occluded) const {
    OccludedAlong(
        starts, [&](std::size_t) -> const glm::dvec3& { return direction; }, true, occluded);
}

void RayScene::Occluded(const std::vector<RayStart>& starts,
                        const std::vector<glm::dvec3>& directions,
                        std::vector<std::uint8_t>& occluded) const {
    OccludedAlong(
        starts, [&](std::size_t i) -> const glm::dvec3& { return directions[i]; }, false, occluded);
}

bool RayScene::OccludedByFirst(const RayStart& start, const glm::dvec3& direction,
                               double maxDistance, std::uint32_t triangles,
                               const TriangleRanges* skip) const {
    LEAFLUX_CHECK(!periodic_);
    StartContext context = MakeContext(0, RunFirst());
    context.limit = triangles;
    context.skip = skip != nullptr && !skip->empty() ? skip : nullptr;
    RTCRay ray = EmbreeRay(start, direction, maxDistance);
    rtcOccluded1(top_, &context.context, &ray);
    return ray.tfar < 0.0f;
}

bool RayScene::OccludedAmong(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                             const TriangleRanges& only) const {
    LEAFLUX_CHECK(!periodic_);
    StartContext context = MakeContext(0, RunFirst());
    context.only = &only;
    RTCRay ray = EmbreeRay(start, direction, maxDistance);
    rtcOccluded1(top_, &context.context, &ray);
    return ray.tfar < 0.0f;
}

template <class Direction>
void RayScene::OccludedAlong(const std::vector<RayStart>& starts, const Direction& direction,
                             bool coherent, std::vector<std::uint8_t>& occluded) const {
    occluded.resize(starts.size());
    if (periodic_) {
        for (std::size_t i = 0; i < starts.size(); ++i)
            occluded[i] = Occluded(starts[i], direction(i));
        return;
    }
    thread_local std::vector<RTCRay> rays;
    rays.clear();
    for (std::size_t i = 0; i < starts.size(); ++i) {
        rays.push_back(EmbreeRay(starts[i], direction(i), std::numeric_limits<double>::infinity()));
    }
    StartContext context = MakeContext(0, RunFirst());
    if (coherent) context.context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded1M(top_, &context.context, rays.data(), static_cast<unsigned>(rays.size()),
                  sizeof(RTCRay));
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = rays[i].tfar < 0.0f;
}

bool RayScene::OccludedByGroup(const RayStart& start, const glm::dvec3& direction,
                               double maxDistance, const Group& group) const {
    StartContext context = MakeContext(start.copy, RunFirst());
    context.group = &group;
    RTCRay ray = EmbreeRay(start, direction, maxDistance);
    rtcOccluded1(top_, &context.context, &ray);
    return ray.tfar < 0.0f;
}

bool RayScene::Occluded(const RayStart& start, const glm::dvec3& direction,
                        double maxDistance) const {
    if (!periodic_) return OccludedOnce(start, direction, maxDistance);
    RayStart at = start;
    double remaining = maxDistance;
    for (int crossing = 0; crossing < kMaxTileCrossings && remaining > 0.0; ++crossing) {
        const double toSide = IntoTile(at, direction);
        if (OccludedOnce(at, direction, std::min(toSide, remaining))) return true;
        if (std::isinf(toSide) || toSide >= remaining) return false;
        if (!StepToTileSide(at, direction, toSide)) return false;
        remaining -= toSide;
    }
    return false;
}

namespace {
// SceneRays' runs: the copies' (FindCopies), their originals', and those of the receivers
// between them, each run a range of receivers.
struct ReceiverRun {
    std::uint32_t first = 0, receivers = 0;
    const PlantCopy* copy = nullptr;
};

std::vector<ReceiverRun> RunsOf(const std::vector<PlantCopy>& copies, std::uint32_t receivers) {
    std::vector<ReceiverRun> plants;
    for (const PlantCopy& copy : copies) {
        plants.push_back({copy.firstReceiver, copy.receivers, &copy});
        plants.push_back({copy.original, copy.receivers, nullptr});
    }
    std::sort(plants.begin(), plants.end(),
              [](const ReceiverRun& a, const ReceiverRun& b) { return a.first < b.first; });
    plants.erase(
        std::unique(plants.begin(), plants.end(),
                    [](const ReceiverRun& a, const ReceiverRun& b) { return a.first == b.first; }),
        plants.end());
    std::vector<ReceiverRun> runs;
    std::uint32_t next = 0;
    for (const ReceiverRun& plant : plants) {
        if (plant.first > next) runs.push_back({next, plant.first - next, nullptr});
        runs.push_back(plant);
        next = plant.first + plant.receivers;
    }
    if (receivers > next) runs.push_back({next, receivers - next, nullptr});
    return runs;
}
}  // namespace

std::unique_ptr<RayScene> SceneRays(const Scene& scene, const FlatScene& receivers, bool compact) {
    const std::vector<Receiver>& all = receivers.receivers;
    const std::vector<PlantCopy> copies =
        compact ? FindCopies(scene, receivers) : std::vector<PlantCopy>{};
    const std::vector<ReceiverRun> spans = RunsOf(copies, static_cast<std::uint32_t>(all.size()));
    // Each run's triangles and vertices, each receiver's first vertex in its run.
    std::vector<RayRun> runs(spans.size());
    std::vector<std::uint32_t> runOf(all.size()), firstVertex(all.size());
    std::unordered_map<std::uint32_t, std::int32_t> runStarting;  // by first receiver
    const glm::dmat4 toFrame = glm::translate(glm::dmat4(1.0), -receivers.origin);
    const glm::dmat4 fromFrame = glm::translate(glm::dmat4(1.0), receivers.origin);
    for (std::size_t k = 0; k < spans.size(); ++k) {
        runStarting[spans[k].first] = static_cast<std::int32_t>(k);
        for (std::uint32_t r = spans[k].first; r < spans[k].first + spans[k].receivers; ++r) {
            runOf[r] = static_cast<std::uint32_t>(k);
            firstVertex[r] = runs[k].vertices;
            runs[k].count += all[r].triangleCount;
            runs[k].vertices +=
                static_cast<std::uint32_t>(ReceiverMesh(scene, all[r]).positions.size());
        }
        if (const PlantCopy* copy = spans[k].copy) {
            runs[k].copyOf = runStarting.at(copy->original);
            runs[k].moved = toFrame * copy->moved * fromFrame;
        }
    }
    return std::make_unique<RayScene>(
        receivers, std::move(runs),
        [&](const std::vector<float*>& xyz, const std::vector<std::uint32_t*>& indices) {
            PlaceVertices(scene, receivers, [&](std::uint32_t r) {
                const std::uint32_t k = runOf[r];
                if (!xyz[k]) return VertexSlot{};
                const std::uint32_t firstTriangle =
                    all[r].firstTriangle - all[spans[k].first].firstTriangle;
                return VertexSlot{xyz[k] + 3 * static_cast<std::size_t>(firstVertex[r]),
                                  indices[k] + 3 * static_cast<std::size_t>(firstTriangle),
                                  firstVertex[r]};
            });
        },
        compact);
}

}  // namespace leaflux
