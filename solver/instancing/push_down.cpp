#include "solver/instancing/push_down.h"

#include <algorithm>
#include <cmath>

#include "solver/radiosity/channels.h"
#include "solver/util/box.h"

namespace leaflux {
namespace {

// What the structure lets through from the box's side towards `toward` to x: τ to the power
// of the share of the line through the box between x and that side. (Weighting the line by
// where the structure's organ area lies, its AreaGrid, changed nothing on the 119k tree's
// branches, whose τ is near 1, for 8 times the cost.)
double Through(const ClosedNode& closed, double tau, const glm::dvec3& x,
               const glm::dvec3& toward) {
    const BoxSpan span = LineThroughBox(x, toward, closed.boxMin, closed.boxMax);
    if (!span.Meets() || span.exit <= 0.0) return 1.0;  // beyond the box
    const double share = (span.exit - std::max(span.enter, 0.0)) / (span.exit - span.enter);
    return std::pow(tau, std::clamp(share, 0.0, 1.0));
}

// What a side absorbs of the light arriving on it, by band.
double Absorptance(const std::vector<Optics>& optics, int index, int band, int side) {
    if (index < 0) return 1.0;  // black
    const BandOptics& o = optics[index].bands[band];
    return side == kUpper ? 1.0 - o.rhoUpper - o.tauUpperToLower
                          : 1.0 - o.rhoLower - o.tauLowerToUpper;
}

}  // namespace

std::vector<std::vector<BandLight>> PushDown(const FlatScene& organs, const ClosedNode& closed,
                                             const std::function<double(const glm::dvec3&)>& tau,
                                             std::span<const Arrival> arrivals,
                                             std::span<const BandLight> structure,
                                             const std::vector<Optics>& optics) {
    const int bands = static_cast<int>(structure.size());
    const std::size_t receivers = organs.receivers.size();
    // The light straight from the box's sides: area-weighted sums by receiver, side, band.
    std::vector<double> through(receivers * 2 * bands, 0.0);
    const auto index = [&](std::size_t r, int side, int b) { return (r * 2 + side) * bands + b; };
    std::vector<double> passes(arrivals.size());
    for (std::size_t a = 0; a < arrivals.size(); ++a)
        passes[a] = std::clamp(tau(arrivals[a].toward), 0.0, 1.0);
    for (const Triangle& t : organs.triangles) {
        const glm::dvec3 x = organs.origin + (t.a + t.b + t.c) / 3.0;
        for (std::size_t a = 0; a < arrivals.size(); ++a) {
            const double cosine = glm::dot(t.normal, arrivals[a].toward);
            if (cosine == 0.0) continue;
            const int side = cosine > 0.0 ? kUpper : kLower;
            const double facing = t.areaM2 * std::abs(cosine);
            const double passed = Through(closed, passes[a], x, arrivals[a].toward);
            for (int b = 0; b < bands; ++b) {
                through[index(t.receiver, side, b)] += facing * passed * arrivals[a].irradiance[b];
            }
        }
    }
    std::vector<std::vector<BandLight>> light(receivers, std::vector<BandLight>(bands));
    for (int b = 0; b < bands; ++b) {
        // What the straight light makes the organs absorb, and what 1 W/m² on both sides of
        // every organ would; the rest of what the structure absorbs, handed out evenly.
        double absorbed = 0.0, capacity = 0.0;
        for (std::size_t r = 0; r < receivers; ++r) {
            for (int side : {kUpper, kLower}) {
                const double alpha = Absorptance(optics, organs.receivers[r].optics, b, side);
                absorbed += alpha * through[index(r, side, b)];
                capacity += alpha * organs.receivers[r].areaM2;
            }
        }
        const double even =
            capacity > 0.0 ? std::max(0.0, structure[b].absorbedW - absorbed) / capacity : 0.0;
        for (std::size_t r = 0; r < receivers; ++r) {
            const Receiver& receiver = organs.receivers[r];
            if (receiver.areaM2 <= 0.0) continue;
            BandLight& band = light[r][b];
            band.irradianceUpperWm2 = through[index(r, kUpper, b)] / receiver.areaM2 + even;
            band.irradianceLowerWm2 = through[index(r, kLower, b)] / receiver.areaM2 + even;
            band.absorbedW =
                receiver.areaM2 *
                (Absorptance(optics, receiver.optics, b, kUpper) * band.irradianceUpperWm2 +
                 Absorptance(optics, receiver.optics, b, kLower) * band.irradianceLowerWm2);
            band.radianceIntegral = structure[b].radianceIntegral;
            band.radianceMoment = structure[b].radianceMoment;
        }
    }
    return light;
}

}  // namespace leaflux
