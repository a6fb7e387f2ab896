#include "solver/raytrace/raytrace.h"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <cmath>
#include <string>

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
};

void IgnoreStartTriangle(const RTCFilterFunctionNArguments* args) {
    const auto* start = reinterpret_cast<const StartContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const unsigned triangle = RTCRayN_id(args->ray, args->N, i);
        if (triangle == kNoTriangle && !start->group && start->limit == kNoTriangle &&
            !start->skip && !start->only)
            continue;
        const unsigned instance = RTCHitN_instID(args->hit, args->N, i, 0);
        const int copy = instance == RTC_INVALID_GEOMETRY_ID ? 0 : static_cast<int>(instance);
        const unsigned primitive = RTCHitN_primID(args->hit, args->N, i);
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

StartContext MakeContext(int copy) {
    StartContext context;
    rtcInitIntersectContext(&context.context);
    context.copy = copy;
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

RayHit HitOf(const RTCRayHit& rayHit, const RayStart& start, const glm::dvec3& direction) {
    RayHit result;
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return result;
    result.fate = RayFate::kHit;
    result.triangle = rayHit.hit.primID;
    result.distance = rayHit.ray.tfar;
    result.next.origin = start.origin + direction * result.distance;
    result.next.triangle = rayHit.hit.primID;
    const unsigned instance = rayHit.hit.instID[0];
    result.next.copy = instance == RTC_INVALID_GEOMETRY_ID ? 0 : static_cast<int>(instance);
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

RayScene::RayScene(const FlatScene& frame, std::uint32_t triangles, std::uint32_t vertices,
                   const PlaceMesh& place, bool compact, std::shared_ptr<RayDevice> device)
    : flat_(frame), device_(std::move(device)) {
    BuildMesh(triangles, vertices, place, compact);
    BuildTop();
}

void RayScene::BuildMesh(std::size_t triangles, std::size_t vertices, const PlaceMesh& place,
                         bool compact) {
    SetFlushToZero();
    RTCDevice rtc = device_->Get();
    mesh_ = rtcNewScene(rtc);
    rtcSetSceneBuildQuality(mesh_, RTC_BUILD_QUALITY_HIGH);
    if (compact) rtcSetSceneFlags(mesh_, RTC_SCENE_FLAG_COMPACT);
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
        RTCGeometry instance = rtcNewGeometry(rtc, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(instance, mesh_);
        // Column-major 3×4: identity rotation, then the copy's translation.
        const float transform[12] = {1,
                                     0,
                                     0,
                                     0,
                                     1,
                                     0,
                                     0,
                                     0,
                                     1,
                                     static_cast<float>(kCopyOffsets[k][0] * width),
                                     static_cast<float>(kCopyOffsets[k][1] * depth),
                                     0};
        rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, transform);
        rtcCommitGeometry(instance);
        rtcAttachGeometryByID(top_, instance, k);
        rtcReleaseGeometry(instance);
    }
    rtcCommitScene(top_);
}

RayScene::~RayScene() {
    if (top_) rtcReleaseScene(top_);
    if (mesh_) rtcReleaseScene(mesh_);
}

RayHit RayScene::TraceOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const {
    StartContext context = MakeContext(start.copy);
    RTCRayHit rayHit = EmbreeRayHit(start, direction, tFar);
    rtcIntersect1(top_, &context.context, &rayHit);
    return HitOf(rayHit, start, direction);
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
    StartContext context = MakeContext(0);
    rtcIntersect1M(top_, &context.context, rayHits.data(), static_cast<unsigned>(rayHits.size()),
                   sizeof(RTCRayHit));
    for (std::size_t i = 0; i < starts.size(); ++i) {
        hits[i] = HitOf(rayHits[i], starts[i], directions[i]);
        if (hits[i].fate != RayFate::kHit) hits[i].fate = Escape(directions[i]);
    }
}

bool RayScene::OccludedOnce(const RayStart& start, const glm::dvec3& direction, double tFar) const {
    StartContext context = MakeContext(start.copy);
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
    StartContext context = MakeContext(0);
    context.limit = triangles;
    context.skip = skip != nullptr && !skip->empty() ? skip : nullptr;
    RTCRay ray = EmbreeRay(start, direction, maxDistance);
    rtcOccluded1(top_, &context.context, &ray);
    return ray.tfar < 0.0f;
}

bool RayScene::OccludedAmong(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                             const TriangleRanges& only) const {
    LEAFLUX_CHECK(!periodic_);
    StartContext context = MakeContext(0);
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
    StartContext context = MakeContext(0);
    if (coherent) context.context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded1M(top_, &context.context, rays.data(), static_cast<unsigned>(rays.size()),
                  sizeof(RTCRay));
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = rays[i].tfar < 0.0f;
}

bool RayScene::OccludedByGroup(const RayStart& start, const glm::dvec3& direction,
                               double maxDistance, const Group& group) const {
    StartContext context = MakeContext(start.copy);
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

std::unique_ptr<RayScene> SceneRays(const Scene& scene, const FlatScene& receivers, bool compact) {
    std::uint32_t triangles = 0, vertices = 0;
    for (const Receiver& receiver : receivers.receivers) {
        triangles += receiver.triangleCount;
        vertices += static_cast<std::uint32_t>(ReceiverMesh(scene, receiver).positions.size());
    }
    return std::make_unique<RayScene>(
        receivers, triangles, vertices,
        [&](float* xyz, std::uint32_t* indices) { PlaceVertices(scene, receivers, xyz, indices); },
        compact);
}

}  // namespace leaflux
