#include "solver/raytrace/occlusion.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "solver/util/box.h"
#include "solver/util/check.h"

namespace leaflux {

// What the boxes' callbacks read and write for one ray: the ray in double precision, the
// instances to leave out, and the product so far with the instances already in it.
struct ProxyQuery {
    RTCIntersectContext context;  // first: Embree hands the callbacks this pointer
    const Occlusion* occlusion;
    glm::dvec3 origin, direction;
    double tFar;
    std::span<const std::uint32_t> exclude;
    double transmittance = 1.0;
    std::vector<std::uint32_t>* counted = nullptr;  // the thread's, reused from ray to ray

    // Multiplies in box `id` once; false when nothing passes any more.
    bool Cross(std::uint32_t id) {
        if (std::find(exclude.begin(), exclude.end(), id) != exclude.end()) return true;
        if (std::find(counted->begin(), counted->end(), id) != counted->end()) return true;
        const Occlusion::Chord chord = occlusion->ChordOf(id, origin, direction);
        const double enter = chord.enter, exit = chord.exit;
        const double from = std::max(enter, 0.0), to = std::min(exit, tFar);
        if (!(to > from) || !(exit > enter)) return true;
        counted->push_back(id);
        const double tau =
            std::clamp(occlusion->proxies_[id].transmittance(chord.direction), 0.0, 1.0);
        const double fraction = std::min((to - from) / (exit - enter), 1.0);
        transmittance *= fraction >= 1.0 ? tau : std::pow(tau, fraction);
        return transmittance > 0.0;
    }
};

Occlusion::Chord Occlusion::ChordOf(std::uint32_t c, const glm::dvec3& origin,
                                    const glm::dvec3& direction) const {
    const Box& box = boxes_[c];
    const glm::dvec3 o = glm::dvec3(box.instanceFromScene * glm::dvec4(origin, 1.0));
    const glm::dvec3 d = glm::dmat3(box.instanceFromScene) * direction;
    const BoxSpan span = LineThroughBox(o, d, box.boxMin, box.boxMax);
    Chord chord{span.enter, span.exit, glm::dvec3(0.0)};
    if (span.Meets()) chord.direction = glm::normalize(d);  // only for a line that meets it
    return chord;
}

void Occlusion::Bounds(const RTCBoundsFunctionArguments* args) {
    const auto* self = static_cast<const Occlusion*>(args->geometryUserPtr);
    const Box& box = self->boxes_[args->primID];
    RTCBounds* out = args->bounds_o;
    // Rounded outwards, so that the float box holds the double one.
    out->lower_x = std::nextafter(static_cast<float>(box.lower.x), -INFINITY);
    out->lower_y = std::nextafter(static_cast<float>(box.lower.y), -INFINITY);
    out->lower_z = std::nextafter(static_cast<float>(box.lower.z), -INFINITY);
    out->upper_x = std::nextafter(static_cast<float>(box.upper.x), INFINITY);
    out->upper_y = std::nextafter(static_cast<float>(box.upper.y), INFINITY);
    out->upper_z = std::nextafter(static_cast<float>(box.upper.z), INFINITY);
}

void Occlusion::Crossed(const RTCOccludedFunctionNArguments* args) {
    auto* query = reinterpret_cast<ProxyQuery*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        // Nothing passes: the ray is occluded and traversal may stop.
        if (!query->Cross(args->primID)) RTCRayN_tfar(args->ray, args->N, i) = -INFINITY;
    }
}

void Occlusion::CrossedIntersect(const RTCIntersectFunctionNArguments* args) {
    // Only occlusion rays are traced through the boxes; an intersect query reports no hit.
    (void)args;
}

Occlusion::Occlusion(const RayScene& triangles, std::vector<ClosedProxy> proxies,
                     RTCBuildQuality quality, std::shared_ptr<RayDevice> device)
    : triangles_(triangles), proxies_(std::move(proxies)), device_(std::move(device)) {
    for (const ClosedProxy& proxy : proxies_) {
        LEAFLUX_CHECK(proxy.transmittance != nullptr);
        Box box;
        box.instanceFromScene = glm::inverse(proxy.sceneFromInstance);
        box.boxMin = proxy.boxMin;
        box.boxMax = proxy.boxMax;
        std::tie(box.lower, box.upper) =
            PlacedBounds(proxy.sceneFromInstance, proxy.boxMin, proxy.boxMax);
        boxes_.push_back(box);
    }
    RTCDevice rtc = device_->Get();
    scene_ = rtcNewScene(rtc);
    rtcSetSceneBuildQuality(scene_, quality);
    if (!boxes_.empty()) {
        RTCGeometry geometry = rtcNewGeometry(rtc, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryBuildQuality(geometry, quality);
        rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(boxes_.size()));
        rtcSetGeometryUserData(geometry, this);
        rtcSetGeometryBoundsFunction(geometry, Bounds, this);
        rtcSetGeometryOccludedFunction(geometry, Crossed);
        rtcSetGeometryIntersectFunction(geometry, CrossedIntersect);
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene_, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(scene_);
}

Occlusion::Occlusion(const RayScene& triangles, std::vector<ClosedProxy> proxies,
                     OutsideView outside, ShadowView shadows)
    : Occlusion(triangles, std::move(proxies)) {
    outside_ = std::move(outside);
    shadows_ = std::move(shadows);
}

Occlusion::~Occlusion() {
    if (scene_) rtcReleaseScene(scene_);
}

double Occlusion::ThroughBoxes(const RayStart& start, const glm::dvec3& direction,
                               double maxDistance, std::span<const std::uint32_t> exclude) const {
    thread_local std::vector<std::uint32_t> counted;
    counted.clear();
    ProxyQuery query;
    query.counted = &counted;
    rtcInitIntersectContext(&query.context);
    query.occlusion = this;
    query.origin = start.origin;
    query.direction = direction;
    query.tFar = maxDistance;
    query.exclude = exclude;
    RTCRay ray = EmbreeRay(start, direction, maxDistance);
    // A little beyond the end in float: the callback clips to the exact segment in double.
    if (!std::isinf(maxDistance)) ray.tfar = std::nextafter(ray.tfar, INFINITY);
    rtcOccluded1(scene_, &query.context, &ray);
    return query.transmittance;
}

}  // namespace leaflux
