#include "solver/radiosity/link_audit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <array>
#include <cmath>

#include "solver/radiosity/estimate.h"
#include "solver/util/sampling.h"

namespace leaflux {

std::vector<LinkAudit> AuditLinks(const NodeModel& model, const RayScene& rays,
                                  const std::vector<std::uint32_t>& leaves, const Field& field,
                                  Links& links, SourceLight& sources, LeafLight& leafLight,
                                  const std::function<void()>& collect) {
    const Hierarchy& hierarchy = model.Nodes();
    const FlatScene& flat = hierarchy.Flat();
    const int bands = model.ChannelSet().Count();
    enum Kind {
        kExact,
        kSided,
        kFromPlane,
        kIntoPlane,
        kBetweenClusters,
        kNoLink,
        kTwoLinks,
        kKinds
    };
    const auto kindOf = [&](std::uint32_t r, const NodeLink& link) {
        if (link.exact) return kExact;
        if (link.sided) return kSided;
        if (link.senderPlane) return kFromPlane;
        return model.Planar(r) ? kIntoPlane : kBetweenClusters;
    };
    // What the links of each kind hand on: the light the leaf patches' outer sides gather
    // through them alone, all bands, as push-down hands it on (a cluster's projected area
    // counts the back faces of its solids, whose inner sides get none of it).
    std::array<std::int64_t, kKinds> count{};
    std::array<double, kKinds> handed{};
    const std::vector<std::vector<NodeLink>> all = links.node;
    const SideTable irradiance = leafLight.irradiance, fromSources = sources.sides;
    for (std::uint32_t n : leaves) sources.sides.ClearRow(n);
    for (int kind = 0; kind < kNoLink; ++kind) {
        for (std::uint32_t r = 0; r < all.size(); ++r) {
            links.node[r].clear();
            for (const NodeLink& link : all[r]) {
                if (kindOf(r, link) == kind) links.node[r].push_back(link);
            }
            count[kind] += static_cast<std::int64_t>(links.node[r].size());
        }
        collect();
        for (std::uint32_t n : leaves) {
            for (int side : {kUpper, kLower}) {
                if (model.Inner(hierarchy[n].triangle, side)) continue;
                for (int b = 0; b < bands; ++b)
                    handed[kind] += hierarchy[n].areaM2 * leafLight.irradiance(n, side)[b];
            }
        }
    }
    links.node = all;
    leafLight.irradiance = irradiance;
    sources.sides = fromSources;
    // Per leaf patch side, what its rays find, by the kind of link that covers each point.
    constexpr int kShots = 64;
    using Found = std::array<std::array<double, 2>, kKinds>;  // W and W² per kind
    using Range = tbb::blocked_range<std::size_t>;
    const Found found = tbb::parallel_reduce(
        Range(0, leaves.size()), Found{},
        [&](const Range& range, Found acc) {
            SetFlushToZero();
            for (std::size_t i = range.begin(); i != range.end(); ++i) {
                const std::uint32_t n = leaves[i];
                const HrcNode& node = hierarchy[n];
                Random random(StreamSeed(0xA0D17, n));
                for (int side : {kUpper, kLower}) {
                    if (model.Inner(node.triangle, side)) continue;
                    std::array<double, kKinds> sum{}, square{};
                    for (int k = 0; k < kShots; ++k) {
                        const Hierarchy::Point p =
                            hierarchy.Sample(n, random.Uniform(), random.Uniform());
                        const glm::dvec3 omega =
                            CosineHemisphere(side == kUpper ? node.normal : -node.normal,
                                             (k + random.Uniform()) / kShots, random.Uniform());
                        RayHit hit = rays.Trace({p.position, p.triangle}, omega);
                        // A triangle overlapping the patch in its plane (a mesh that repeats a
                        // face) exchanges nothing with it: the ray goes on through.
                        while (hit.fate == RayFate::kHit &&
                               hierarchy.PatchOf(hit.triangle) != kNoNode &&
                               Estimator::InPlane(node, hierarchy[hierarchy.PatchOf(hit.triangle)]))
                            hit = rays.Trace(hit.next, omega);
                        if (hit.fate != RayFate::kHit) continue;
                        const glm::dvec3& y = hit.next.origin;
                        // The leaf patch at y, and its side facing the ray.
                        std::uint32_t at = hierarchy.PatchOf(hit.triangle);
                        for (bool down = true; down;) {
                            down = false;
                            for (std::uint32_t c : hierarchy[at].children) {
                                if (hierarchy.Covers(c, hit.triangle, y)) {
                                    at = c, down = true;
                                    break;
                                }
                            }
                        }
                        const int facing =
                            glm::dot(flat.triangles[hit.triangle].normal, omega) < 0.0 ? kUpper
                                                                                       : kLower;
                        const double b = node.areaM2 * model.SideRadiosity(field, at, facing);
                        int covering = 0;
                        Kind kind = kNoLink;
                        for (std::uint32_t r = n; r != kNoNode; r = hierarchy[r].parent) {
                            for (const NodeLink& link : links.node[r]) {
                                if (hierarchy.Covers(link.sender, hit.triangle, y))
                                    ++covering, kind = kindOf(r, link);
                            }
                        }
                        if (covering > 1) kind = kTwoLinks;
                        sum[kind] += b;
                        square[kind] += b * b;
                    }
                    for (int k = 0; k < kKinds; ++k) {
                        const double mean = sum[k] / kShots;
                        acc[k][0] += mean;
                        acc[k][1] += (square[k] / kShots - mean * mean) / (kShots - 1);
                    }
                }
            }
            return acc;
        },
        [](Found a, const Found& b) {
            for (int k = 0; k < kKinds; ++k) a[k][0] += b[k][0], a[k][1] += b[k][1];
            return a;
        });
    const char* names[kKinds] = {"patch from patch (exact)",
                                 "between planes, a flat cluster at one end",
                                 "from a plane into a cluster",
                                 "cluster into a plane",
                                 "between clusters",
                                 "covered by no link",
                                 "covered by two links"};
    std::vector<LinkAudit> audit;
    for (int k = 0; k < kKinds; ++k) {
        audit.push_back({names[k], count[k], handed[k], found[k][0], std::sqrt(found[k][1])});
    }
    return audit;
}

}  // namespace leaflux
