#include "solver/instancing/directional.h"

#include <numbers>
#include <stdexcept>

#include "solver/util/check.h"

namespace leaflux {
namespace {
constexpr double kFourPi = 4.0 * std::numbers::pi;

void CheckLevel(int level) {
    if (level < 0 || level > 4)
        throw std::invalid_argument("direction level " + std::to_string(level) + " is not in 0..4");
}

std::size_t PhaseValueCount(PhaseKind kind, int level, int bands) {
    const std::size_t n = DirectionSet::OfLevel(level).Size();
    switch (kind) {
        case PhaseKind::kConstant:
            return static_cast<std::size_t>(bands);
        case PhaseKind::kMonoDirectional:
            return n * bands;
        case PhaseKind::kBiDirectional:
            return n * n * bands;
    }
    throw std::invalid_argument("unknown phase function kind");
}
}  // namespace

SphereFunction::SphereFunction(int level, int channels) : level_(level), channels_(channels) {
    CheckLevel(level);
    LEAFLUX_CHECK(channels > 0);
    values_.assign(static_cast<std::size_t>(Directions().Size()) * channels, 0.0f);
}

SphereFunction SphereFunction::FromValues(int level, int channels, std::vector<float> values) {
    CheckLevel(level);
    if (channels <= 0 ||
        values.size() != static_cast<std::size_t>(DirectionSet::OfLevel(level).Size()) * channels)
        throw std::invalid_argument("a sphere function of level " + std::to_string(level) +
                                    " and " + std::to_string(channels) + " channels cannot have " +
                                    std::to_string(values.size()) + " values");
    SphereFunction f;
    f.level_ = level;
    f.channels_ = channels;
    f.values_ = std::move(values);
    return f;
}

double SphereFunction::Value(const glm::dvec3& direction, int channel) const {
    const DirectionSet::Interpolation at = Directions().Locate(direction);
    double value = 0.0;
    for (int k = 0; k < 3; ++k)
        value += at.weight[k] * static_cast<double>(At(at.vertex[k], channel));
    return value;
}

double SphereFunction::Integral(int channel) const {
    const DirectionSet& set = Directions();
    double total = 0.0;
    for (int i = 0; i < set.Size(); ++i)
        total += static_cast<double>(At(i, channel)) * set.HatIntegralSr(i);
    return total;
}

const char* PhaseKindName(PhaseKind kind) {
    switch (kind) {
        case PhaseKind::kConstant:
            return "constant";
        case PhaseKind::kMonoDirectional:
            return "mono";
        case PhaseKind::kBiDirectional:
            return "bi";
    }
    return "unknown";
}

PhaseFunction::PhaseFunction(PhaseKind kind, int level, int bands)
    : kind_(kind), level_(kind == PhaseKind::kConstant ? 0 : level), bands_(bands) {
    CheckLevel(level);
    LEAFLUX_CHECK(bands > 0);
    values_.assign(PhaseValueCount(kind, level_, bands), 0.0f);
}

PhaseFunction PhaseFunction::FromValues(PhaseKind kind, int level, int bands,
                                        std::vector<float> values) {
    CheckLevel(level);
    if (kind == PhaseKind::kConstant) level = 0;
    if (bands <= 0 || values.size() != PhaseValueCount(kind, level, bands))
        throw std::invalid_argument(std::string("a ") + PhaseKindName(kind) +
                                    " phase function of level " + std::to_string(level) + " and " +
                                    std::to_string(bands) + " bands cannot have " +
                                    std::to_string(values.size()) + " values");
    PhaseFunction f;
    f.kind_ = kind;
    f.level_ = level;
    f.bands_ = bands;
    f.values_ = std::move(values);
    return f;
}

double PhaseFunction::Value(int band, const glm::dvec3& towardSource,
                            const glm::dvec3& outgoing) const {
    if (kind_ == PhaseKind::kConstant) return V(band);
    const DirectionSet& set = Directions();
    const DirectionSet::Interpolation in = set.Locate(towardSource);
    if (kind_ == PhaseKind::kMonoDirectional) {
        double value = 0.0;
        for (int k = 0; k < 3; ++k) value += in.weight[k] * V(in.vertex[k] * bands_ + band);
        return value;
    }
    const DirectionSet::Interpolation out = set.Locate(outgoing);
    const std::size_t n = set.Size();
    double value = 0.0;
    for (int k = 0; k < 3; ++k) {
        const std::size_t row = in.vertex[k] * n;
        double along = 0.0;
        for (int j = 0; j < 3; ++j)
            along += out.weight[j] * V((row + out.vertex[j]) * bands_ + band);
        value += in.weight[k] * along;
    }
    return value;
}

void PhaseFunction::Table(int band, std::span<const glm::dvec3> towardSources,
                          std::span<const glm::dvec3> outgoing, double* table) const {
    const std::size_t inputs = towardSources.size();
    if (kind_ != PhaseKind::kBiDirectional) {  // alike towards every outgoing direction
        for (std::size_t i = 0; i < inputs; ++i) {
            const double value = Value(band, towardSources[i], towardSources[i]);
            for (std::size_t o = 0; o < outgoing.size(); ++o) table[o * inputs + i] = value;
        }
        return;
    }
    const DirectionSet& set = Directions();
    const std::size_t n = set.Size();
    // Per incoming direction, f interpolated there towards each of the set's directions.
    std::vector<double> rows(inputs * n, 0.0);
    for (std::size_t i = 0; i < inputs; ++i) {
        const DirectionSet::Interpolation in = set.Locate(towardSources[i]);
        double* row = rows.data() + i * n;
        for (int k = 0; k < 3; ++k) {
            for (std::size_t o = 0; o < n; ++o)
                row[o] += in.weight[k] * V((in.vertex[k] * n + o) * bands_ + band);
        }
    }
    for (std::size_t o = 0; o < outgoing.size(); ++o) {
        const DirectionSet::Interpolation out = set.Locate(outgoing[o]);
        for (std::size_t i = 0; i < inputs; ++i) {
            const double* row = rows.data() + i * n;
            double value = 0.0;
            for (int j = 0; j < 3; ++j) value += out.weight[j] * row[out.vertex[j]];
            table[o * inputs + i] = value;
        }
    }
}

double PhaseFunction::ScatteredPower(int band, const glm::dvec3& towardSource) const {
    if (kind_ != PhaseKind::kBiDirectional)
        return kFourPi * Value(band, towardSource, towardSource);
    const DirectionSet& set = Directions();
    const DirectionSet::Interpolation in = set.Locate(towardSource);
    const std::size_t n = set.Size();
    double power = 0.0;
    for (int k = 0; k < 3; ++k) {
        const std::size_t row = in.vertex[k] * n;
        for (std::size_t o = 0; o < n; ++o)
            power += in.weight[k] * V((row + o) * bands_ + band) * set.HatIntegralSr(o);
    }
    return power;
}

PhaseFunction PhaseFunction::Reduced(PhaseKind kind) const {
    LEAFLUX_CHECK(static_cast<int>(kind) <= static_cast<int>(kind_));
    if (kind == kind_) return *this;
    const DirectionSet& set = Directions();
    const int n = set.Size();
    // Scattered power per incoming direction and band.
    std::vector<double> power(static_cast<std::size_t>(n) * bands_, 0.0);
    for (int i = 0; i < n; ++i) {
        for (int b = 0; b < bands_; ++b) {
            if (kind_ == PhaseKind::kMonoDirectional) {
                power[i * bands_ + b] = kFourPi * V(i * bands_ + b);
                continue;
            }
            double sum = 0.0;
            for (int o = 0; o < n; ++o)
                sum += V((static_cast<std::size_t>(i) * n + o) * bands_ + b) * set.HatIntegralSr(o);
            power[i * bands_ + b] = sum;
        }
    }
    PhaseFunction reduced(kind, level_, bands_);
    for (int b = 0; b < bands_; ++b) {
        double mean = 0.0;
        for (int i = 0; i < n; ++i) {
            const double even = power[i * bands_ + b] / kFourPi;
            if (kind == PhaseKind::kMonoDirectional) reduced.values_[i * bands_ + b] = float(even);
            mean += even * set.HatIntegralSr(i) / kFourPi;
        }
        if (kind == PhaseKind::kConstant) reduced.values_[b] = static_cast<float>(mean);
    }
    return reduced;
}

}  // namespace leaflux
