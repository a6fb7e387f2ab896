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
                          std::vector<EnergyBalance>& balances) {
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
            int out = 0;
            for (int k = 0; k < count; ++k) {
                const Hierarchy::Point p =
                    hierarchy.Sample(leaves[i], random.Uniform(), random.Uniform());
                const glm::dvec3 n = s == kUpper ? node.normal : -node.normal;
                const glm::dvec3 omega =
                    CosineHemisphere(n, (k + random.Uniform()) / count, random.Uniform());
                out += rays.Trace({p.position, p.triangle}, omega).fate != RayFate::kHit;
            }
            escape[i][s] = static_cast<double>(out) / count;
            doubt[i][s] = escape[i][s] * (1.0 - escape[i][s]) / (count - 1.0);
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

}  // namespace leaflux
