#include "solver/radiosity/gathering.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <utility>

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();
}  // namespace

ReceiverOptics::ReceiverOptics(const Scene& scene, const FlatScene& flat, const Channels& channels)
    : rho(channels.Count(), flat.receivers.size()), tau(channels.Count(), flat.receivers.size()) {
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const Receiver& receiver = flat.receivers[r];
        if (receiver.optics < 0) continue;
        const auto& bands = scene.optics[receiver.optics].bands;
        for (int c = 0; c < channels.Count(); ++c) {
            const auto& band = bands[channels.BandOf(c)];
            rho(r, kUpper)[c] = band.rhoUpper;
            rho(r, kLower)[c] = band.rhoLower;
            tau(r, kUpper)[c] = band.tauUpperToLower;
            tau(r, kLower)[c] = band.tauLowerToUpper;
        }
    }
}

template <bool kDirections>
void Gather(const NodeModel& model, const Field& field, const Links& links,
            const std::vector<std::uint32_t>& receivers, Gathered& gathered) {
    const Hierarchy& hierarchy = model.Nodes();
    const int channels = model.ChannelSet().Count();
    const int bins = model.BinCount();
    using Range = tbb::blocked_range<std::size_t>;
    tbb::parallel_for(Range(0, receivers.size()), [&](const Range& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const std::uint32_t r = receivers[i];
            const HrcNode& R = hierarchy[r];
            double* upper = gathered.sides(r, kUpper);
            double* lower = gathered.sides(r, kLower);
            double* integral = gathered.integral[r];
            glm::dvec3* moment = gathered.moment[r];
            gathered.sides.ClearRow(r);
            if constexpr (kDirections) gathered.integral.ClearRow(r), gathered.moment.ClearRow(r);
            const bool plane = model.Planar(r);
            double* bin = plane ? nullptr : gathered.bins[model.Slot(r)];
            if (bin) std::fill(bin, bin + bins * channels, 0.0);
            for (const NodeLink& link : links.node[r]) {
                if (!link.Carries()) continue;
                const glm::dvec3 toSender(link.toSender);
                const glm::dvec3 transfer(link.transfer[0], link.transfer[1], link.transfer[2]);
                if (link.exact || link.sided) {
                    const double* b = field.radiosity(link.sender, link.senderSide);
                    for (int k = 0; k < channels; ++k) {
                        upper[k] += transfer[0] * b[k];
                        lower[k] += transfer[1] * b[k];
                        if constexpr (kDirections) {
                            const double radiance = b[k] / kPi * transfer[2];
                            integral[k] += radiance;
                            moment[k] += radiance * toSender;
                        }
                    }
                    continue;
                }
                const double geometric = transfer[0];
                const std::uint32_t slot = model.Slot(link.sender);
                if (plane) {
                    // Towards the sender's centre; a side facing into its own solid (an
                    // internode's inner side) gets nothing, as a patch's links give it
                    // (Estimator::Pair).
                    const double cosine = glm::dot(R.normal, toSender);
                    if (R.patch && model.Inner(R.triangle, cosine > 0.0 ? kUpper : kLower))
                        continue;
                    double* side = cosine > 0.0 ? upper : lower;
                    ForEachSent(link, field, slot, channels, [&](int k, double sent) {
                        const double normal = sent * geometric;  // W/m² facing the sender
                        side[k] += normal * std::abs(cosine);
                        if constexpr (kDirections) {
                            integral[k] += normal;
                            moment[k] += normal * toSender;
                        }
                    });
                } else {
                    double* at[3];
                    double weight[3];
                    for (int j = 0; j < 3; ++j) {
                        at[j] = bin + link.receiverBins.index[j] * channels;
                        weight[j] = link.receiverBins.Weight(j) * geometric;
                    }
                    ForEachSent(link, field, slot, channels, [&](int k, double sent) {
                        for (int j = 0; j < 3; ++j) at[j][k] += weight[j] * sent;
                    });
                }
            }
        }
    });
}

template void Gather<false>(const NodeModel&, const Field&, const Links&,
                            const std::vector<std::uint32_t>&, Gathered&);
template void Gather<true>(const NodeModel&, const Field&, const Links&,
                           const std::vector<std::uint32_t>&, Gathered&);

double UpdateRadiosity(const Hierarchy& hierarchy, const std::vector<std::uint32_t>& leaves,
                       const ReceiverOptics& optics, LeafLight& leafLight, Field& field) {
    // The largest change and value are order-free maxima, so the parallel sweep is exact.
    const int channels = field.radiosity.Channels();
    using Range = tbb::blocked_range<std::size_t>;
    const auto [change, largest] = tbb::parallel_reduce(
        Range(0, leaves.size()), std::pair<double, double>{0.0, 0.0},
        [&](const Range& range, std::pair<double, double> acc) {
            for (std::size_t i = range.begin(); i < range.end(); ++i) {
                const std::uint32_t n = leaves[i];
                const std::uint32_t receiver = hierarchy[n].receiver;
                const double* rhoUpper = optics.rho(receiver, kUpper);
                const double* rhoLower = optics.rho(receiver, kLower);
                const double* tauUpper = optics.tau(receiver, kUpper);
                const double* tauLower = optics.tau(receiver, kLower);
                const double* eUpper = leafLight.irradiance(n, kUpper);
                const double* eLower = leafLight.irradiance(n, kLower);
                const double* emission = leafLight.emission[n];
                double* bUpper = field.radiosity(n, kUpper);
                double* bLower = field.radiosity(n, kLower);
                double* dUpper = leafLight.change(n, kUpper);
                double* dLower = leafLight.change(n, kLower);
                for (int k = 0; k < channels; ++k) {
                    const double upper =
                        emission[k] + rhoUpper[k] * eUpper[k] + tauLower[k] * eLower[k];
                    const double lower = rhoLower[k] * eLower[k] + tauUpper[k] * eUpper[k];
                    dUpper[k] = upper - bUpper[k];
                    dLower[k] = lower - bLower[k];
                    acc.first = std::max({acc.first, std::abs(dUpper[k]), std::abs(dLower[k])});
                    // Against the light scattered, not emitted: beside a lamp a leaf's change
                    // is small against the lamp's exitance long before it has settled.
                    acc.second = std::max({acc.second, upper - emission[k], lower});
                    bUpper[k] = upper;
                    bLower[k] = lower;
                }
            }
            return acc;
        },
        [](std::pair<double, double> a, std::pair<double, double> b) {
            return std::pair{std::max(a.first, b.first), std::max(a.second, b.second)};
        });
    return largest > 0.0 ? change / largest : 0.0;
}

void Extrapolate(const std::vector<std::uint32_t>& leaves, const LeafLight& leafLight,
                 double factor, Field& field) {
    const int channels = field.radiosity.Channels();
    // A value the jump would take below zero is cut at zero. That adds light only to the
    // estimate the sweeps start from again: they converge to the same fixed point, the
    // jump only hastens them. Cutting the factor for every value instead, so that none
    // went below zero, kept it near zero in the wall-hole room (a patch's tiny negative
    // change) and made its cycles four times slower, for the same light.
    tbb::parallel_for(std::size_t{0}, leaves.size(), [&](std::size_t i) {
        const std::uint32_t n = leaves[i];
        for (int s : {kUpper, kLower}) {
            double* b = field.radiosity(n, s);
            const double* change = leafLight.change(n, s);
            for (int k = 0; k < channels; ++k) b[k] = std::max(b[k] + factor * change[k], 0.0);
        }
    });
}

}  // namespace leaflux
