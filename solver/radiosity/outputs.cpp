#include "solver/radiosity/outputs.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "solver/util/check.h"
#include "solver/util/sampling.h"

namespace leaflux {

std::int64_t WriteOutputs(const NodeModel& model, const RayScene& rays,
                          const std::vector<std::uint32_t>& allLeaves, const ReceiverOptics& optics,
                          const Field& field, const LeafLight& leafLight, LightSink& sink,
                          std::vector<EnergyBalance>& balances, const Occlusion* occlusion) {
    const Hierarchy& hierarchy = model.Nodes();
    // Surfaces held from outside a local problem have no output and are not in its balance.
    std::vector<std::uint32_t> leaves;
    leaves.reserve(allLeaves.size());
    for (std::uint32_t n : allLeaves) {
        if (!model.Held(n)) leaves.push_back(n);
    }
    const int bands = model.ChannelSet().Count();
    LEAFLUX_CHECK(model.ChannelSet().beams == 1);
    std::int64_t traced = 0;
    // Escape: the cosine-weighted fraction of each leaf patch's sides that sees out.
    std::vector<std::array<double, 2>> sent(leaves.size());
    double total = 0.0;
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const std::uint32_t n = leaves[i];
        for (int s : {kUpper, kLower}) {
            double radiosity = 0.0;
            for (int b = 0; b < bands; ++b)
                radiosity +=
                    field.radiosity(n, s)[b] - (s == kUpper ? leafLight.emission[n][b] : 0.0);
            total += sent[i][s] = hierarchy[n].areaM2 * std::max(radiosity, 0.0);
        }
    }
    const double mean = total / std::max<std::size_t>(1, 2 * leaves.size());
    // Per side: the escaping fraction and the variance of that estimate (none where every
    // ray agrees: a closed box's walls, whose every ray hits).
    std::vector<std::array<double, 2>> escape(leaves.size()), doubt(leaves.size());
    std::vector<std::int64_t> traces(leaves.size(), 0);
    // With the whole scene's triangles (shadows by geometry), a ray escapes past every organ
    // and surface of it, as it does for Monte Carlo, instead of through the closed
    // instances' transmittance and each level further out in turn.
    const ShadowView* shadows =
        occlusion != nullptr && occlusion->Shadows().rays ? &occlusion->Shadows() : nullptr;
    const auto passes = [&](const Hierarchy::Point& p, const glm::dvec3& omega) -> double {
        const RayStart start{p.position, p.triangle};
        if (shadows != nullptr && shadows->triangleOf[p.triangle] != kNoTriangle) {
            // The level's own triangles first: most rays they stop need no more.
            if (rays.Occluded(start, omega)) return 0.0;
            const RayStart there{p.position + shadows->offset, shadows->triangleOf[p.triangle]};
            return shadows->rays->Occluded(there, omega) ? 0.0 : 1.0;
        }
        if (occlusion != nullptr) return occlusion->Transmittance(start, omega);
        return rays.Trace(start, omega).fate != RayFate::kHit ? 1.0 : 0.0;
    };
    tbb::parallel_for(std::size_t{0}, leaves.size(), [&](std::size_t i) {
        SetFlushToZero();
        const HrcNode& node = hierarchy[leaves[i]];
        Random random(StreamSeed(0xE5C, leaves[i]));
        // Stratified rays a side, in proportion to the power it sends (2 for the mean side,
        // 2 to 64): the estimate is unbiased, only its sum over the scene matters (the
        // escaped power of the energy balance), and that sum is dominated by bright sides
        // (a leaf patch over a lamp 1 mm below it).
        for (int s : {kUpper, kLower}) {
            const int count =
                mean > 0.0
                    ? static_cast<int>(std::clamp(std::lround(2.0 * sent[i][s] / mean), 2L, 64L))
                    : 2;
            double out = 0.0, squares = 0.0;
            for (int k = 0; k < count; ++k) {
                const Hierarchy::Point p =
                    hierarchy.Sample(leaves[i], random.Uniform(), random.Uniform());
                const glm::dvec3 n = s == kUpper ? node.normal : -node.normal;
                const glm::dvec3 omega =
                    CosineHemisphere(n, (k + random.Uniform()) / count, random.Uniform());
                const double passed = passes(p, omega);
                out += passed, squares += passed * passed;
            }
            // The mean's variance from the rays' own spread (for rays that pass or not,
            // f (1 − f) / (count − 1)).
            escape[i][s] = out / count;
            doubt[i][s] =
                std::max(0.0, squares / count - escape[i][s] * escape[i][s]) / (count - 1.0);
            traces[i] += count;
        }
    });
    for (std::int64_t r : traces) traced += r;
    // A receiver's leaf patches lie together in the hierarchy's order (under its organ's or
    // surface's node): its light is handed to the sink once the last is reached.
    std::vector<double> variance(bands, 0.0);
    std::vector<BandLight> light(bands);
    std::uint32_t receiver = kNoNode;
    double area = 0.0;
    const auto emit = [&] {
        if (receiver == kNoNode) return;
        for (BandLight& band : light) {
            if (area <= 0.0) continue;
            band.irradianceUpperWm2 /= area;
            band.irradianceLowerWm2 /= area;
            band.radianceIntegral /= area;
            band.radianceMoment /= area;
        }
        sink.Receiver(receiver, light);
    };
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const std::uint32_t n = leaves[i];
        const HrcNode& node = hierarchy[n];
        const double a = node.areaM2;
        if (node.receiver != receiver) {
            emit();
            receiver = node.receiver;
            light.assign(bands, BandLight{});
            area = 0.0;
        }
        area += a;
        for (int k = 0; k < bands; ++k) {
            BandLight& band = light[k];
            const double eUpper = leafLight.irradiance(n, kUpper)[k];
            const double eLower = leafLight.irradiance(n, kLower)[k];
            band.irradianceUpperWm2 += a * eUpper;
            band.irradianceLowerWm2 += a * eLower;
            const double absorbed = a * ((1.0 - optics.rho(node.receiver, kUpper)[k] -
                                          optics.tau(node.receiver, kUpper)[k]) *
                                             eUpper +
                                         (1.0 - optics.rho(node.receiver, kLower)[k] -
                                          optics.tau(node.receiver, kLower)[k]) *
                                             eLower);
            band.absorbedW += absorbed;
            band.radianceIntegral += a * leafLight.integral[n][k];
            band.radianceMoment += a * leafLight.moment[n][k];
            EnergyBalance& balance = balances[k];
            balance.incidentW +=
                a * (leafLight.direct(n, kUpper)[k] + leafLight.direct(n, kLower)[k]);
            balance.absorbedW += absorbed;
            const double upper = a * (field.radiosity(n, kUpper)[k] - leafLight.emission[n][k]);
            const double lower = a * field.radiosity(n, kLower)[k];
            balance.escapedW += upper * escape[i][kUpper] + lower * escape[i][kLower];
            variance[k] += upper * upper * doubt[i][kUpper] + lower * lower * doubt[i][kLower];
        }
    }
    emit();
    // The links' own error is not in it: this is the escape estimate's noise alone.
    for (int k = 0; k < bands; ++k) balances[k].stderrW = std::sqrt(variance[k]);
    return traced;
}

std::int64_t AddClosedEscape(const NodeModel& model, const Occlusion& occlusion, const Field& field,
                             std::vector<EnergyBalance>& balances) {
    const Hierarchy& hierarchy = model.Nodes();
    const DirectionSet& directions = model.Directions();
    const Channels& channels = model.ChannelSet();
    const int bins = model.BinCount(), count = channels.Count();
    const std::size_t closed = hierarchy.Closed().size();
    constexpr int kRaysPerBin = 8;
    // Per closed instance and channel: escaped W and the variance of that estimate.
    std::vector<std::vector<double>> escaped(closed, std::vector<double>(count, 0.0)),
        variance(closed, std::vector<double>(count, 0.0));
    std::vector<std::int64_t> traced(closed, 0);
    tbb::parallel_for(std::size_t{0}, closed, [&](std::size_t c) {
        SetFlushToZero();
        const ClosedNode& node = hierarchy.Closed()[c];
        // A held one's light is the level's that holds it; an opened one's, its organs'.
        if (node.Held() || node.opens) return;
        const double* sent =
            field.intensity[model.Slot(hierarchy.NodeOfClosed(static_cast<std::int32_t>(c)))];
        const std::uint32_t self = static_cast<std::uint32_t>(c);
        Random random(StreamSeed(0xE5CC, c));
        for (int o = 0; o < bins; ++o) {
            if (std::all_of(sent + o * count, sent + (o + 1) * count,
                            [](double i) { return i <= 0.0; }))
                continue;
            const glm::dvec3& omega = directions.Direction(o);
            double out = 0.0, squares = 0.0;
            for (int k = 0; k < kRaysPerBin; ++k) {
                // A point of the box, the ray leaving it where the box ends.
                const glm::dvec3 local =
                    glm::mix(node.boxMin, node.boxMax,
                             glm::dvec3(random.Uniform(), random.Uniform(), random.Uniform()));
                const glm::dvec3 p(node.sceneFromInstance * glm::dvec4(local, 1.0));
                const double exit = std::max(occlusion.ChordOf(self, p, omega).exit, 0.0);
                const double passed = occlusion.Transmittance(
                    {p + exit * omega}, omega, std::numeric_limits<double>::infinity(), {&self, 1});
                out += passed, squares += passed * passed;
            }
            traced[c] += kRaysPerBin;
            const double fraction = out / kRaysPerBin;
            const double doubt =
                std::max(0.0, squares / kRaysPerBin - fraction * fraction) / (kRaysPerBin - 1.0);
            for (int k = 0; k < count; ++k) {
                const double power = sent[o * count + k] * directions.HatIntegralSr(o);
                escaped[c][k] += power * fraction;
                variance[c][k] += power * power * doubt;
            }
        }
    });
    std::int64_t rays = 0;
    for (std::size_t c = 0; c < closed; ++c) {
        rays += traced[c];
        for (int k = 0; k < count; ++k) {
            EnergyBalance& balance = balances[channels.BandOf(k)];
            const double before = std::max(balance.stderrW, 0.0);
            balance.escapedW += escaped[c][k];
            balance.stderrW = std::sqrt(before * before + variance[c][k]);
        }
    }
    return rays;
}

}  // namespace leaflux
