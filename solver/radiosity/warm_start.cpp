#include "solver/radiosity/warm_start.h"

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

}  // namespace leaflux
