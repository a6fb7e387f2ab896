#include "solver/scene/light_units.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cctype>
#include <cmath>

namespace leaflux {

bool IsParBand(const Band& band) {
    std::string lower;
    for (char c : band.name)
        lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return lower == "par" || (std::abs(band.wavelengthMinNm - 400.0) < 1.0 &&
                              std::abs(band.wavelengthMaxNm - 700.0) < 1.0);
}

std::optional<double> PhotonUmolPerJ(const Band& band) {
    if (band.photonUmolPerJ > 0.0) return band.photonUmolPerJ;
    if (IsParBand(band)) return kDaylightParUmolPerJ;
    return std::nullopt;
}

std::vector<std::string> IrradianceWarnings(const Scene& scene,
                                            const std::vector<double>& irradianceWm2,
                                            const std::string& field) {
    std::vector<std::string> warnings;
    for (std::size_t b = 0; b < irradianceWm2.size() && b < scene.bands.size(); ++b) {
        const Band& band = scene.bands[b];
        const double value = irradianceWm2[b];
        const bool par = IsParBand(band);
        const double limit = par ? kSolarConstantParWm2 : kSolarConstantWm2;
        // 10 % over the limit: a value at the limit is a sun above the atmosphere, meant.
        if (!(value > 1.1 * limit)) continue;
        std::string warning = fmt::format(
            "{}[{}] is {:g} W/m², more than the sun brings {}above the atmosphere "
            "(about {:g} W/m²)",
            field, band.name, value, par ? "in PAR " : "", limit);
        const std::optional<double> photons = PhotonUmolPerJ(band);
        if (photons) {
            warning += fmt::format(
                ": is it a photon flux in µmol m⁻² s⁻¹? Irradiances are in W/m²; {:g} µmol "
                "m⁻² s⁻¹ is {:.4g} W/m² at {:g} µmol/J",
                value, value / *photons, *photons);
        }
        warnings.push_back(std::move(warning));
    }
    return warnings;
}

std::vector<std::string> SunWarnings(const Scene& scene, const Sun& sun, const std::string& field) {
    std::vector<std::string> warnings;
    if (sun.towardSun.z < 0.0 && std::isfinite(sun.towardSun.z)) {
        const double below = -std::asin(std::max(-1.0, sun.towardSun.z)) * 180.0 / M_PI;
        warnings.push_back(fmt::format(
            "{} is {:.3g}° below the horizon: it lights the scene from underneath (the ground "
            "and the leaves' lower sides); leave it out at night",
            field, below));
    }
    for (std::string& w :
         IrradianceWarnings(scene, sun.normalIrradianceWm2, field + ".normal_irradiance")) {
        warnings.push_back(std::move(w));
    }
    return warnings;
}

}  // namespace leaflux
