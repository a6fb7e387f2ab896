#include "solver/radiosity/closed_scattering.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/util/check.h"

namespace leaflux {
namespace {

// The power (W) an intensity per bin and channel ([bin][channel], W/sr) sends, per channel.
std::vector<double> PowerSent(const DirectionSet& directions, const double* intensity, int bins,
                              int count) {
    std::vector<double> power(count, 0.0);
    for (int o = 0; o < bins; ++o) {
        for (int k = 0; k < count; ++k)
            power[k] += intensity[o * count + k] * directions.HatIntegralSr(o);
    }
    return power;
}

}  // namespace

ClosedResponse::ClosedResponse(const NodeModel& model,
                               const std::vector<DirectionalSource>& sources)
    : bands_(model.ChannelSet().bands),
      bins_(model.BinCount()),
      inputs_(model.BinCount() + sources.size()) {
    const Hierarchy& hierarchy = model.Nodes();
    const DirectionSet& directions = model.Directions();
    const std::size_t closedCount = hierarchy.Closed().size();
    slot_.assign(closedCount, kHeld);
    std::size_t scattering = 0;
    for (std::size_t c = 0; c < closedCount; ++c) {
        if (!hierarchy.Closed()[c].Held()) slot_[c] = scattering++;
    }
    values_.assign(scattering * bands_ * bins_ * inputs_, 0.0);
    tbb::parallel_for(std::size_t{0}, closedCount, [&](std::size_t c) {
        const ClosedNode& closed = hierarchy.Closed()[c];
        if (closed.Held()) return;  // it sends what it was given
        std::vector<glm::dvec3> in(inputs_), out(bins_);
        for (std::size_t d = 0; d < bins_; ++d)
            out[d] = in[d] = closed.ToInstance(directions.Direction(static_cast<int>(d)));
        for (std::size_t s = 0; s < sources.size(); ++s)
            in[bins_ + s] = closed.ToInstance(sources[s].toward);
        for (std::size_t b = 0; b < bands_; ++b) {
            closed.contents->PhaseTable(static_cast<int>(b), in, out,
                                        values_.data() + (slot_[c] * bands_ + b) * bins_ * inputs_);
        }
    });
}

double ScatterClosed(const NodeModel& model, const std::vector<DirectionalSource>& sources,
                     const ClosedResponse& response, const ClosedLight& arrived, bool directional,
                     Field& field) {
    const Hierarchy& hierarchy = model.Nodes();
    const DirectionSet& directions = model.Directions();
    const Channels& channels = model.ChannelSet();
    const int bins = model.BinCount(), count = channels.Count();
    const std::size_t closedCount = hierarchy.Closed().size();
    std::vector<double> change(closedCount, 0.0), largest(closedCount, 0.0);
    tbb::parallel_for(std::size_t{0}, closedCount, [&](std::size_t c) {
        if (hierarchy.Closed()[c].Held()) return;
        const std::uint32_t n = hierarchy.NodeOfClosed(static_cast<std::int32_t>(c));
        double* out = field.intensity[model.Slot(n)];
        const double* fromBins = arrived.bins[c];
        const double* fromSources = arrived.sources[c];
        std::vector<double> sent(static_cast<std::size_t>(bins) * count);
        for (int o = 0; o < bins; ++o) {
            for (int k = 0; k < count; ++k) {
                const double* f = response.Row(c, channels.BandOf(k), o);
                double intensity = 0.0;
                for (int i = 0; i < bins; ++i) intensity += fromBins[i * count + k] * f[i];
                for (std::size_t s = 0; s < sources.size(); ++s)
                    intensity += fromSources[s] * sources[s].normalIrradiance[k] * f[bins + s];
                sent[o * count + k] = intensity;
            }
        }
        const std::vector<double> power = PowerSent(directions, sent.data(), bins, count);
        if (!directional) {
            for (int o = 0; o < bins; ++o) {
                for (int k = 0; k < count; ++k)
                    sent[o * count + k] = power[k] / (4.0 * std::numbers::pi);
            }
        }
        for (std::size_t i = 0; i < sent.size(); ++i) {
            change[c] = std::max(change[c], std::abs(sent[i] - out[i]));
            largest[c] = std::max(largest[c], sent[i]);
            out[i] = sent[i];
        }
        field.emitted[n] = channels.Measure(power.data());
    });
    const double most = closedCount > 0 ? *std::max_element(largest.begin(), largest.end()) : 0.0;
    return most > 0.0 ? *std::max_element(change.begin(), change.end()) / most : 0.0;
}

void HoldClosed(const NodeModel& model, Field& field) {
    const Hierarchy& hierarchy = model.Nodes();
    const int bins = model.BinCount(), count = model.ChannelSet().Count();
    for (std::size_t c = 0; c < hierarchy.Closed().size(); ++c) {
        const ClosedNode& closed = hierarchy.Closed()[c];
        if (!closed.Held()) continue;
        LEAFLUX_CHECK_EQ(closed.held.size(), static_cast<std::size_t>(bins) * count);
        const std::uint32_t n = hierarchy.NodeOfClosed(static_cast<std::int32_t>(c));
        std::copy(closed.held.begin(), closed.held.end(), field.intensity[model.Slot(n)]);
        const std::vector<double> power =
            PowerSent(model.Directions(), closed.held.data(), bins, count);
        field.emitted[n] = model.ChannelSet().Measure(power.data());
    }
}

void DarkenClosed(const NodeModel& model, Field& field) {
    const Hierarchy& hierarchy = model.Nodes();
    const int width = model.BinCount() * model.ChannelSet().Count();
    for (std::size_t c = 0; c < hierarchy.Closed().size(); ++c) {
        if (hierarchy.Closed()[c].Held()) continue;
        const std::uint32_t n = hierarchy.NodeOfClosed(static_cast<std::int32_t>(c));
        std::fill_n(field.intensity[model.Slot(n)], width, 0.0);
        field.emitted[n] = 0.0;
    }
}

std::vector<double> InterceptedByClosed(const NodeModel& model, const ClosedLight& arrived) {
    const Hierarchy& hierarchy = model.Nodes();
    const int count = model.ChannelSet().Count();
    std::vector<double> power(count, 0.0);
    for (std::size_t c = 0; c < hierarchy.Closed().size(); ++c) {
        const std::uint32_t n = hierarchy.NodeOfClosed(static_cast<std::int32_t>(c));
        for (int d = 0; d < model.BinCount(); ++d) {
            for (int k = 0; k < count; ++k)
                power[k] += arrived.bins[c][d * count + k] * model.ProjectedBin(n, d);
        }
    }
    return power;
}

}  // namespace leaflux
