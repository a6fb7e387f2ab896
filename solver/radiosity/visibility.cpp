#include "solver/radiosity/visibility.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/util/box.h"
#include "solver/util/sampling.h"

namespace leaflux {
namespace {
// How large a patch's radius is against its distance where its rays go in directions
// uniform over it rather than to points uniform on it.
constexpr double kNear = 0.5;
// An organ whose area would cover fewer pixels of a sun's map than this, facing the sun,
// takes the sun's rays instead (Mapped): a straight shadow edge across n pixels misplaces
// about 0.3 √n of them, 2 % of 256, about what two lattices of 57 rays (kOrganRounds)
// leave. The map's pixels are sized for the organs on the mean, and a small one among
// large ones would take few.
constexpr double kLeastMappedPixels = 256.0;

// Rays' weights: all of them, and those that passed.
struct Tally {
    double total = 0.0, visible = 0.0;
};

// The closed instances a ray leaves out: those of its two ends (−1: none).
struct Exclusion {
    std::uint32_t ids[2];
    std::size_t count = 0;
    explicit Exclusion(const std::int32_t (&ends)[2]) {
        for (std::int32_t end : ends) {
            if (end >= 0) ids[count++] = static_cast<std::uint32_t>(end);
        }
    }
    operator std::span<const std::uint32_t>() const { return {ids, count}; }
};

// Where a link's rays start and end: the points of one rank-1 lattice, shifted apart for
// each end. The even points come first (LinkRays::First), a lattice of half as many, then
// the odd ones; within each half the sender's points are paired with the receiver's in a
// random order (RandomStrata), so that no point of one end is always paired with the same
// point of the other.
class EndPoints {
  public:
    EndPoints(Random& random, const RankOneLattice& lattice)
        : lattice_(lattice),
          first_(LinkRays::First(lattice.Count())),
          receiver_(random.Uniform(), random.Uniform()),
          sender_(random.Uniform(), random.Uniform()) {
        RandomStrata(random, order_[0], first_);
        RandomStrata(random, order_[1], lattice.Count() - first_);
    }
    // The points of the link's ray i.
    glm::dvec2 Receiver(int i) const { return lattice_.Point(Point(i), receiver_); }
    glm::dvec2 Sender(int i) const {
        const bool second = i >= first_;
        const int base = second ? first_ : 0;
        return lattice_.Point(Point(base + order_[second][i - base]), sender_);
    }

  private:
    // The lattice's point at position `at` of the rays' order.
    int Point(int at) const {
        if (first_ == lattice_.Count()) return at;
        return at < first_ ? 2 * at : 2 * (at - first_) + 1;
    }
    const RankOneLattice& lattice_;
    const int first_;
    const glm::dvec2 receiver_, sender_;
    // One thread's rays are traced one link at a time.
    static thread_local std::vector<int> order_[2];
};
thread_local std::vector<int> EndPoints::order_[2];

// What the rays of `tally` show; the visibility `unseen` where none was traced.
Sight Seen(const LinkRays& tally, double unseen) {
    Sight sight;
    sight.spread =
        VisibilitySpread(tally.traced > 0 ? tally.passed / tally.traced : 1.0, tally.taken);
    if (tally.totalLight > 0.0) {
        sight.visibility = tally.visibleLight / tally.totalLight;
    } else {
        sight.visibility = tally.total > 0.0 ? tally.visible / tally.total : unseen;
    }
    return sight;
}
}  // namespace

std::vector<int> SourceRayCounts(std::span<const DirectionalSource> sources,
                                 const Channels& channels, int base) {
    double total = 0.0;
    for (const DirectionalSource& source : sources)
        total += channels.Measure(source.normalIrradiance.data());
    std::vector<int> counts;
    for (const DirectionalSource& source : sources) {
        const double share =
            total > 0.0 ? channels.Measure(source.normalIrradiance.data()) / total : 0.0;
        const int more = static_cast<int>(std::ceil(2.0 * base * std::sqrt(share)));
        counts.push_back(std::max(base, more));
    }
    return counts;
}

LinkVisibility::LinkVisibility(const NodeModel& model, const Field& field,
                               const Occlusion& occlusion, int visibilityRays, int sourceRays,
                               std::span<const DirectionalSource> sources, const SunMaps* suns)
    : hierarchy_(model.Nodes()),
      model_(model),
      field_(field),
      occlusion_(occlusion),
      visibilityRays_(visibilityRays),
      visibilityLattice_(RankOneLattice::Of(visibilityRays)) {
    for (int count : SourceRayCounts(sources, model.ChannelSet(), sourceRays)) {
        int rings = 1;  // the largest divisor of count not over √count
        for (int d = 1; d * d <= count; ++d) {
            if (count % d == 0) rings = d;
        }
        sourceSampling_.push_back({&RankOneLattice::Of(count), rings, count / rings});
    }
    if (suns == nullptr && occlusion.Shadows().rays != nullptr) {
        suns = occlusion.Shadows().suns;
        mapTriangleOf_ = &occlusion.Shadows().triangleOf;
    }
    for (const DirectionalSource& source : sources) {
        sunMap_.push_back(suns != nullptr && source.eachOrgan && source.beyond
                              ? suns->Of(source.toward, source.cosRadius)
                              : nullptr);
    }
}

std::optional<double> LinkVisibility::Mapped(std::uint32_t r, std::uint32_t source) const {
    const SunMap* map = sunMap_[source];
    const HrcNode& node = hierarchy_[r];
    if (map == nullptr || node.closed >= 0 || (node.patch && node.depth > 0)) return std::nullopt;
    const FlatScene& flat = hierarchy_.Flat();
    double lit = 0.0, total = 0.0, missed = 0.0, area = 0.0;
    bool tied = false;
    const auto add = [&](std::uint32_t t) {
        const Triangle& triangle = flat.triangles[t];
        const double weight =
            triangle.areaM2 * model_.ReceivingWeight(t, triangle.normal, map->Toward());
        if (weight <= 0.0) return;
        area += triangle.areaM2;
        const std::uint32_t whole = mapTriangleOf_ ? (*mapTriangleOf_)[t] : t;
        tied = tied || (whole != kNoTriangle && map->Tied(whole));
        const double share = whole == kNoTriangle ? -1.0 : map->Lit(whole);
        if (share < 0.0) {
            missed += weight;
            return;
        }
        lit += weight * share, total += weight;
    };
    if (node.patch) {
        add(node.triangle);
    } else {
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
            if (const std::uint32_t t = hierarchy_.TriangleAt(i); t != kNoTriangle) add(t);
        }
    }
    // Rays where the map cannot say (Tied), or where the organ is too small for its pixels
    // to beat them, as many as its area would cover facing the sun (turned away, it takes
    // fewer, but so much less light that their error is less).
    const double pixels = area / (map->PixelM() * map->PixelM());
    if (tied || (total <= 0.0 && missed > 0.0) || pixels < kLeastMappedPixels) return std::nullopt;
    return total > 0.0 ? lit / total : 0.0;
}

double LinkVisibility::ClosedBrightness(std::int32_t closed, const glm::dvec3& towardQ) const {
    // A closed instance's radiance towards the ray: its intensity over its area seen.
    const std::uint32_t n = hierarchy_.NodeOfClosed(closed);
    const double area = model_.ProjectedArea(n, -towardQ);
    return area > 0.0 ? model_.Power(field_, n, -towardQ) / area : 0.0;
}

double LinkVisibility::HeldEntry(std::int32_t closed, const glm::dvec3& from,
                                 const glm::dvec3& direction) const {
    const ClosedNode& node = hierarchy_.Closed()[closed];
    const glm::dmat4 instanceFromScene = glm::inverse(node.sceneFromInstance);
    const glm::dvec3 o(instanceFromScene * glm::dvec4(from, 1.0));
    const glm::dvec3 d = glm::dmat3(instanceFromScene) * direction;
    return std::max(LineThroughBox(o, d, node.boxMin, node.boxMax).enter, 0.0);
}

double LinkVisibility::HeldTransmittance(const Hierarchy::Point& p, const glm::dvec3& direction,
                                         double length, const ClosedNode* inside) const {
    const std::int32_t ends[2] = {p.closed, -1};
    const ShadowView& shadows = occlusion_.Shadows();
    if (!shadows.rays) {
        return occlusion_.Transmittance({p.position, p.triangle}, direction, length,
                                        Exclusion(ends));
    }
    // The whole scene's organs, from where the ray leaves a closed instance's box (what its
    // own contents take of the light is in its phase function).
    RayStart start{p.position + shadows.offset};
    double from = 0.0;
    if (p.closed >= 0) {
        from = std::max(0.0, occlusion_.ChordOf(p.closed, p.position, direction).exit);
        start.origin += from * direction;
    } else {
        start.triangle = shadows.triangleOf[p.triangle];
    }
    if (from >= length) return 1.0;
    return shadows.rays->OccludedByFirst(start, direction, length - from, shadows.organTriangles,
                                         inside ? inside->shadowTriangles.get() : nullptr)
               ? 0.0
               : 1.0;
}

double LinkVisibility::Passed(const Hierarchy::Point& p, std::int32_t closedEnd,
                              const glm::dvec3& direction, double length, bool held) const {
    const RayStart start{p.position, p.triangle};
    if (held) return HeldTransmittance(p, direction, length);
    if (occlusion_.TrianglesOnly()) {  // triangles alone: a ray passes or not
        return occlusion_.Triangles().Occluded(start, direction, length) ? 0.0 : 1.0;
    }
    const std::int32_t ends[2] = {p.closed, closedEnd};
    return occlusion_.LocalTransmittance(start, direction, length, Exclusion(ends));
}

Sight LinkVisibility::BetweenPatches(std::uint32_t r, std::uint32_t s, RaySet set,
                                     std::int64_t& rays, LinkRays& tally, int upTo) const {
    Random random(StreamSeed(static_cast<std::uint64_t>(set), r, s));
    const HrcNode& S = hierarchy_[s];
    const bool held = model_.Held(s);
    const EndPoints ends(random, visibilityLattice_);
    for (; tally.taken < upTo; ++tally.taken) {
        const int i = tally.taken;
        const glm::dvec2 at = ends.Receiver(i);
        const Hierarchy::Point p = hierarchy_.Sample(r, at.x, at.y);
        const auto [u, v] = ends.Sender(i);
        // Each ray weighted by its estimate of π F(x → S): where S is near (its radius
        // more than kNear of its distance), Ω |n · ω| for a direction uniform in S's solid
        // angle Ω; farther, A_S |n · ω| |cos θy| / d² to a point uniform on S, that kernel
        // varying little over it.
        glm::dvec3 omega;
        double weight, length;
        if (S.radius > kNear * glm::length(S.centroid - p.position)) {
            const glm::dvec3 a = glm::normalize(S.a - p.position),
                             b = glm::normalize(S.b - p.position),
                             c = glm::normalize(S.c - p.position);
            omega = UniformSphericalTriangle(a, b, c, u, v);
            const double along = glm::dot(omega, S.normal);
            if (along == 0.0) continue;
            length = glm::dot(S.a - p.position, S.normal) / along;
            weight = SphericalTriangleSolidAngle(a, b, c) *
                     model_.ReceivingWeight(p.triangle, p.normal, omega);
        } else {
            const Hierarchy::Point q = hierarchy_.Sample(s, u, v);
            const glm::dvec3 d = q.position - p.position;
            length = glm::length(d);
            if (!(length > 0.0)) continue;
            omega = d / length;
            weight = S.areaM2 * model_.ReceivingWeight(p.triangle, p.normal, omega) *
                     std::abs(glm::dot(q.normal, omega)) / (length * length);
        }
        if (!(weight > 0.0) || !(length > 0.0)) continue;
        // The ray ends short of S's plane by its last 10⁻⁴, and where it comes within 10⁻⁴
        // of S's radius of that plane: a ray grazing it from a point by its edge (a corner
        // of a room) would meet S's coplanar neighbours there, by rounding alone.
        length -= std::max(1e-4 * length, 1e-4 * S.radius / std::abs(glm::dot(omega, S.normal)));
        ++rays, ++tally.traced;
        tally.total += weight;
        const double through = length > 0.0 ? Passed(p, -1, omega, length, held) : 1.0;
        tally.visible += weight * through;
        tally.passed += through;
    }
    return Seen(tally, 1.0);
}

Sight LinkVisibility::Between(std::uint32_t r, std::uint32_t s, RaySet set,
                              std::int64_t& rays) const {
    LinkRays tally;
    return Between(r, s, set, rays, tally, visibilityRays_);
}

Sight LinkVisibility::Between(std::uint32_t r, std::uint32_t s, RaySet set, std::int64_t& rays,
                              LinkRays& tally, int upTo) const {
    if (hierarchy_[r].patch && hierarchy_[s].patch)
        return BetweenPatches(r, s, set, rays, tally, upTo);
    Random random(StreamSeed(static_cast<std::uint64_t>(set), r, s));
    const bool fromCluster = !hierarchy_[s].patch;
    const bool held = model_.Held(s);
    const EndPoints ends(random, visibilityLattice_);
    for (; tally.taken < upTo; ++tally.taken) {
        const int i = tally.taken;
        const glm::dvec2 at = ends.Receiver(i), from = ends.Sender(i);
        const Hierarchy::Point p = hierarchy_.Sample(r, at.x, at.y);
        // Spread over S as well: a cluster's children each get their share of rays.
        const Hierarchy::Point q = hierarchy_.Sample(s, from.x, from.y);
        const glm::dvec3 d = q.position - p.position;
        const double distance = glm::length(d);
        if (distance <= 0.0) continue;
        // |cos θy| d: a point of a closed instance sends alike in every direction.
        const double sending = q.closed >= 0 ? distance : std::abs(glm::dot(q.normal, d));
        const double weight = model_.ReceivingWeight(p.triangle, p.normal, d / distance) * sending /
                              (distance * distance * distance);
        if (weight <= 0.0) continue;
        const double light = fromCluster ? weight * Brightness(q, d) : 0.0;
        ++rays, ++tally.traced;
        tally.total += weight;
        tally.totalLight += light;
        // From a closed instance held from outside, the ray ends where it enters the box:
        // what its own contents do to its light is in the intensity it was given.
        double length = distance * (1.0 - 1e-4);
        if (held && q.closed >= 0)
            length = std::min(length, HeldEntry(q.closed, p.position, d / distance));
        const double through = length > 0.0 ? Passed(p, q.closed, d / distance, length, held) : 1.0;
        tally.visible += weight * through;
        tally.visibleLight += light * through;
        tally.passed += through;
    }
    return Seen(tally, 0.0);
}

LinkVisibility::OrganPoint LinkVisibility::ClosedOrganPoint(std::int32_t c, const glm::dvec3& x,
                                                            const glm::dvec3& toward) const {
    const ShadowView& shadows = occlusion_.Shadows();
    const ClosedNode& node = hierarchy_.Closed()[c];
    if (!node.shadowTriangles) return {};
    const RayScene::TriangleRanges& own = *node.shadowTriangles;
    // x's place in its box, each coordinate uniform in [0, 1) (Hierarchy::SampleClosed).
    const glm::dvec3 size = node.boxMax - node.boxMin;
    const glm::dvec3 local = occlusion_.InInstance(c, x);
    glm::dvec3 f(0.5);
    for (int i = 0; i < 3; ++i) {
        if (size[i] > 0.0) f[i] = std::clamp((local[i] - node.boxMin[i]) / size[i], 0.0, 1.0);
    }
    // A triangle by the first (the lattice's, stratified over the organs in their order),
    // a point of it by the other two.
    std::uint64_t count = 0;
    for (const auto& range : own) count += range[1] - range[0];
    if (count == 0) return {};
    std::uint64_t k = std::min(count - 1, static_cast<std::uint64_t>(f.x * count));
    std::uint32_t t = own.front()[0];
    for (const auto& range : own) {
        if (k < range[1] - range[0]) {
            t = range[0] + static_cast<std::uint32_t>(k);
            break;
        }
        k -= range[1] - range[0];
    }
    const std::array<glm::dvec3, 3> corners = shadows.rays->Corners(t);
    OrganPoint point;
    point.weight = 0.5 * std::abs(glm::dot(
                             glm::cross(corners[1] - corners[0], corners[2] - corners[0]), toward));
    if (!(point.weight > 0.0)) return {};
    const glm::dvec3 w = UniformTriangle(f.y, f.z);
    point.start = {w.x * corners[0] + w.y * corners[1] + w.z * corners[2], t};
    return point;
}

LinkVisibility::OrganLight LinkVisibility::ClosedOrganLight(std::int32_t c, const RayHit& hit,
                                                            const glm::dvec3& toward) const {
    const ShadowView& shadows = occlusion_.Shadows();
    const RayScene::TriangleRanges& own = *hierarchy_.Closed()[c].shadowTriangles;
    // The first triangle it meets: none, it is lit; one of its own organs, it is not, nor
    // past them; another, it is not, and past its own organs only if none lies further on
    // (in its box: past its side, the ray has passed them).
    OrganLight organ;
    organ.lit = hit.fate != RayFate::kHit;
    organ.ownLit =
        organ.lit ||
        (!RayScene::InRanges(own, hit.triangle) &&
         !shadows.rays->OccludedAmong(
             hit.next, toward,
             std::max(0.0, occlusion_.ChordOf(c, hit.next.origin - shadows.offset, toward).exit),
             own));
    return organ;
}

double LinkVisibility::FromSource(std::uint32_t r, std::uint32_t source,
                                  const DirectionalSource& light, RaySet set, std::int64_t& rays,
                                  int rounds) const {
    Random random(StreamSeed(set == RaySet::kJudging ? 0x50C : 0x50D, r, source));
    const SourceSampling& sampling = sourceSampling_[source];
    const int count = sampling.lattice->Count();
    const bool beam = light.cosRadius >= 1.0;
    thread_local std::vector<RayStart> starts;
    thread_local std::vector<glm::dvec3> directions;
    thread_local std::vector<double> weights;
    thread_local std::vector<std::uint8_t> occluded;
    thread_local std::vector<std::int32_t> closed;
    starts.clear(), directions.clear(), weights.clear(), closed.clear();
    thread_local std::vector<int> cells;
    for (int round = 0; round < rounds; ++round) {
        const glm::dvec2 shift(random.Uniform(), random.Uniform());
        // The cells of the cone in a random order: in a fixed one, each point of the
        // lattice would always take its direction from the same cell, a bias where a point
        // lies and where the light comes from go together (the box of a closed instance).
        if (!beam) RandomStrata(random, cells, count);
        for (int i = 0; i < count; ++i) {
            const glm::dvec2 at = sampling.lattice->Point(i, shift);
            const Hierarchy::Point p = hierarchy_.Sample(r, at.x, at.y);
            glm::dvec3 toward = light.toward;
            if (!beam) {
                const int cell = cells[i];
                toward =
                    light.Direction((cell % sampling.rings + random.Uniform()) / sampling.rings,
                                    (cell / sampling.rings + random.Uniform()) / sampling.turns);
            }
            const double weight = model_.ReceivingWeight(p.triangle, p.normal, toward);
            if (weight <= 0.0) continue;
            starts.push_back({p.position, p.triangle});
            directions.push_back(toward);
            weights.push_back(weight);
            closed.push_back(p.closed);
        }
    }
    rays += static_cast<std::int64_t>(starts.size());
    double visible = 0.0, total = 0.0;
    if (const ShadowView& shadows = occlusion_.Shadows(); light.beyond && shadows.rays) {
        // Through the whole scene's triangles: from a triangle's points, traced together; for a
        // closed instance, from points of its organs (ClosedOrganLight).
        double closedWeight = 0.0;
        Tally organs, boxes;
        struct ClosedRay {
            glm::dvec3 origin, direction;
            std::int32_t closed;
        };
        thread_local std::vector<ClosedRay> closedRays;
        // The rays from points of closed instances' organs, and their weights.
        thread_local std::vector<RayStart> organStarts;
        thread_local std::vector<glm::dvec3> organDirections;
        thread_local std::vector<double> organWeights;
        thread_local std::vector<std::int32_t> organClosed;
        thread_local std::vector<RayHit> organHits;
        closedRays.clear(), organStarts.clear(), organDirections.clear(), organWeights.clear(),
            organClosed.clear();
        std::size_t batch = 0;  // the rays traced together, moved to the front
        for (std::size_t i = 0; i < starts.size(); ++i) {
            total += weights[i];
            if (closed[i] >= 0) {
                closedWeight += weights[i];
                const OrganPoint organ =
                    ClosedOrganPoint(closed[i], starts[i].origin, directions[i]);
                if (organ.weight > 0.0) {
                    organStarts.push_back(organ.start);
                    organDirections.push_back(directions[i]);
                    organWeights.push_back(weights[i] * organ.weight);
                    organClosed.push_back(closed[i]);
                }
                closedRays.push_back({starts[i].origin, directions[i], closed[i]});
                continue;
            }
            starts[batch] = {starts[i].origin + shadows.offset,
                             shadows.triangleOf[starts[i].triangle]};
            directions[batch] = directions[i];
            weights[batch++] = weights[i];
        }
        starts.resize(batch), directions.resize(batch), weights.resize(batch);
        shadows.rays->Trace(organStarts, organDirections, organHits);
        for (std::size_t k = 0; k < organStarts.size(); ++k) {
            const OrganLight organ =
                ClosedOrganLight(organClosed[k], organHits[k], organDirections[k]);
            if (!organ.ownLit) continue;
            organs.total += organWeights[k];
            if (organ.lit) organs.visible += organWeights[k];
        }
        shadows.rays->Occluded(starts, directions, occluded);
        for (std::size_t i = 0; i < batch; ++i) {
            if (!occluded[i]) visible += weights[i];
        }
        // Where no point of its organs was lit past them, what passes rays from its points
        // where they leave its box.
        if (organs.total <= 0.0 && !closedRays.empty()) {
            starts.clear(), directions.clear();
            for (const ClosedRay& ray : closedRays) {
                const double exit = occlusion_.ChordOf(ray.closed, ray.origin, ray.direction).exit;
                starts.push_back(
                    {ray.origin + shadows.offset + std::max(exit, 0.0) * ray.direction});
                directions.push_back(ray.direction);
            }
            shadows.rays->Occluded(starts, directions, occluded);
            for (std::uint8_t blocked : occluded) {
                boxes.total += 1.0;
                if (!blocked) boxes.visible += 1.0;
            }
        }
        const Tally& closedSight = organs.total > 0.0 ? organs : boxes;
        if (closedSight.total > 0.0)
            visible += closedWeight * closedSight.visible / closedSight.total;
        return total > 0.0 ? visible / total : 0.0;
    }
    // Light that arrived on an opened instance meets its contents alone.
    if (light.beyond ? occlusion_.TrianglesOnly()
                     : occlusion_.ProxyCount() == 0) {  // triangles alone: traced together
        if (beam) {
            occlusion_.Triangles().Occluded(starts, light.toward, occluded);
        } else {
            occlusion_.Triangles().Occluded(starts, directions, occluded);
        }
        for (std::size_t i = 0; i < starts.size(); ++i) {
            total += weights[i];
            if (!occluded[i]) visible += weights[i];
        }
        return total > 0.0 ? visible / total : 0.0;
    }
    for (std::size_t i = 0; i < starts.size(); ++i) {
        const std::int32_t ends[2] = {closed[i], -1};
        total += weights[i];
        visible +=
            weights[i] * (light.beyond ? occlusion_.Transmittance(starts[i], directions[i],
                                                                  INFINITY, Exclusion(ends))
                                       : occlusion_.LocalTransmittance(starts[i], directions[i],
                                                                       INFINITY, Exclusion(ends)));
    }
    return total > 0.0 ? visible / total : 0.0;
}

}  // namespace leaflux
