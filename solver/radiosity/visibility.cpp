#include "solver/radiosity/visibility.h"

#include <algorithm>
#include <vector>

#include "solver/util/sampling.h"

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();
}  // namespace

Sight LinkVisibility::Between(std::uint32_t r, std::uint32_t s, RaySet set, std::int64_t& rays,
                              double unoccluded) const {
    Random random(StreamSeed(static_cast<std::uint64_t>(set), r, s));
    const int count = visibilityRays_;
    const bool fromCluster = !hierarchy_[s].patch;
    double visible = 0.0, total = 0.0, visibleLight = 0.0, totalLight = 0.0;
    int traced = 0, passed = 0;
    for (int i = 0; i < count; ++i) {
        const Hierarchy::Point p =
            hierarchy_.Sample(r, (i + random.Uniform()) / count, random.Uniform());
        const Hierarchy::Point q = hierarchy_.Sample(s, random.Uniform(), random.Uniform());
        const glm::dvec3 d = q.position - p.position;
        const double distance = glm::length(d);
        if (distance <= 0.0) continue;
        const double weight = model_.ReceivingWeight(p.triangle, p.normal, d / distance) *
                              std::abs(glm::dot(q.normal, d)) / (distance * distance * distance);
        if (weight <= 0.0) continue;
        const double light =
            fromCluster
                ? weight * model_.SideRadiosity(field_, hierarchy_.PatchOf(q.triangle),
                                                glm::dot(q.normal, d) < 0.0 ? kUpper : kLower)
                : 0.0;
        ++rays, ++traced;
        total += weight;
        totalLight += light;
        if (!rays_.Occluded({p.position, p.triangle}, d / distance, distance * (1.0 - 1e-4))) {
            visible += weight;
            visibleLight += light;
            ++passed;
        }
    }
    Sight sight;
    sight.spread =
        VisibilitySpread(traced > 0 ? static_cast<double>(passed) / traced : 1.0, visibilityRays_);
    if (unoccluded > 0.0) {
        const double blocked = hierarchy_[s].areaM2 / kPi * (total - visible) / count;
        sight.visibility = std::clamp(1.0 - blocked / unoccluded, -1.0, 1.0);
    } else if (totalLight > 0.0) {
        sight.visibility = visibleLight / totalLight;
    } else {
        sight.visibility = total > 0.0 ? visible / total : 0.0;
    }
    return sight;
}

double LinkVisibility::FromSource(std::uint32_t r, std::uint32_t source, const glm::dvec3& toward,
                                  std::int64_t& rays) const {
    Random random(StreamSeed(0x50C, r, source));
    const int count = sourceRays_;
    thread_local std::vector<RayStart> starts;
    thread_local std::vector<double> weights;
    thread_local std::vector<std::uint8_t> occluded;
    starts.clear(), weights.clear();
    for (int i = 0; i < count; ++i) {
        const Hierarchy::Point p =
            hierarchy_.Sample(r, (i + random.Uniform()) / count, random.Uniform());
        const double weight = model_.ReceivingWeight(p.triangle, p.normal, toward);
        if (weight <= 0.0) continue;
        starts.push_back({p.position, p.triangle});
        weights.push_back(weight);
    }
    rays += static_cast<std::int64_t>(starts.size());
    rays_.Occluded(starts, toward, occluded);
    double visible = 0.0, total = 0.0;
    for (std::size_t i = 0; i < starts.size(); ++i) {
        total += weights[i];
        if (!occluded[i]) visible += weights[i];
    }
    return total > 0.0 ? visible / total : 0.0;
}

}  // namespace leaflux
