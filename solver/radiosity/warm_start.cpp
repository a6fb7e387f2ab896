#include "solver/radiosity/warm_start.h"

#include <algorithm>

namespace leaflux {

WarmStart::WarmStart(const std::vector<Receiver>& receivers, const Solution& solution) {
    if (solution.light.empty()) return;
    bands_ = static_cast<int>(solution.light.front().size());
    for (std::size_t r = 0; r < receivers.size() && r < solution.light.size(); ++r) {
        if (receivers[r].kind != ReceiverKind::kOrgan) continue;
        if (!solution.unsolved.empty() && solution.unsolved[r]) continue;
        if (!row_.emplace(receivers[r].node, static_cast<std::uint32_t>(row_.size())).second)
            continue;
        for (const BandLight& band : solution.light[r]) {
            irradiance_.push_back(static_cast<float>(band.irradianceUpperWm2));
            irradiance_.push_back(static_cast<float>(band.irradianceLowerWm2));
        }
    }
}

std::int64_t WarmStart::Apply(const Hierarchy& hierarchy, const std::vector<Receiver>& receivers,
                              const std::vector<std::uint32_t>& leaves,
                              SideTable& irradiance) const {
    const int sides = 2 * bands_;
    std::vector<double> first(receivers.size() * sides, 0.0), area(receivers.size(), 0.0);
    for (std::uint32_t n : leaves) {
        const std::uint32_t r = hierarchy[n].receiver;
        if (receivers[r].kind != ReceiverKind::kOrgan) continue;
        const double a = hierarchy[n].areaM2;
        area[r] += a;
        for (int b = 0; b < bands_; ++b) {
            first[r * sides + 2 * b] += a * irradiance(n, kUpper)[b];
            first[r * sides + 2 * b + 1] += a * irradiance(n, kLower)[b];
        }
    }
    std::int64_t found = 0;
    for (std::uint32_t r = 0; r < receivers.size(); ++r) {
        const float* light = area[r] > 0.0 ? Of(receivers[r].node) : nullptr;
        if (light == nullptr) {
            area[r] = 0.0;
            continue;
        }
        ++found;
        for (int k = 0; k < sides; ++k)
            first[r * sides + k] =
                std::max(0.0, static_cast<double>(light[k]) - first[r * sides + k] / area[r]);
    }
    for (std::uint32_t n : leaves) {
        const std::uint32_t r = hierarchy[n].receiver;
        if (area[r] <= 0.0) continue;
        for (int b = 0; b < bands_; ++b) {
            irradiance(n, kUpper)[b] += first[r * sides + 2 * b];
            irradiance(n, kLower)[b] += first[r * sides + 2 * b + 1];
        }
    }
    return found;
}

}  // namespace leaflux
