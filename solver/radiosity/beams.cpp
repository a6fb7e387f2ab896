#include "solver/radiosity/beams.h"

#include <cmath>
#include <numbers>

namespace leaflux {

std::vector<DirectionalSource> BeamsOf(const Scene& scene, SkyDiscretization skyCones) {
    std::vector<DirectionalSource> sources;
    const auto add = [&](const glm::dvec3& toward, const std::vector<double>& irradiance,
                         double cosRadius) {
        DirectionalSource source{toward, std::vector<double>(scene.bands.size(), 0.0), cosRadius};
        double total = 0.0;
        for (std::size_t b = 0; b < scene.bands.size(); ++b)
            total += source.normalIrradiance[b] = irradiance[b];
        if (total <= 0.0) return static_cast<DirectionalSource*>(nullptr);
        return &sources.emplace_back(std::move(source));
    };
    for (const Sun& sun : scene.sources.suns) {
        if (DirectionalSource* added =
                add(sun.towardSun, sun.normalIrradianceWm2, std::cos(sun.angularRadiusRad)))
            added->eachOrgan = true;
    }
    for (const Sky& sky : scene.sources.skies) {
        Sky discrete = sky;
        if (discrete.discretization == SkyDiscretization::kContinuous)
            discrete.discretization = skyCones;
        for (const SkyCone& cone : discrete.Cones()) {
            // A circular cone of the cell's solid angle, as the reference takes it: on a
            // plane facing its axis it brings L ∫ cos = L Ω (1 + cos r) / 2.
            const double cosRadius = 1.0 - cone.solidAngleSr / (2.0 * std::numbers::pi);
            std::vector<double> irradiance;
            for (double radiance : cone.radianceWm2Sr)
                irradiance.push_back(radiance * cone.solidAngleSr * (1.0 + cosRadius) / 2.0);
            if (DirectionalSource* added = add(cone.direction, irradiance, cosRadius))
                added->FoldAtHorizon();
        }
    }
    return sources;
}

std::vector<DirectionalSource> UnitBeams(const Channels& channels,
                                         std::span<const glm::dvec3> towardSource) {
    std::vector<DirectionalSource> sources;
    for (int beam = 0; beam < channels.beams; ++beam) {
        DirectionalSource source{glm::normalize(towardSource[beam]),
                                 std::vector<double>(channels.Count(), 0.0)};
        for (int b = 0; b < channels.bands; ++b)
            source.normalIrradiance[beam * channels.bands + b] = 1.0;
        sources.push_back(std::move(source));
    }
    return sources;
}

SunMaps DrawSuns(const FlatScene& flat, const RayScene& rays,
                 std::span<const DirectionalSource> sources, std::span<const std::uint8_t> wanted) {
    std::vector<SunMaps::Sun> suns;
    for (const DirectionalSource& source : sources) {
        if (source.eachOrgan && source.beyond) suns.push_back({source.toward, source.cosRadius});
    }
    return suns.empty() ? SunMaps{} : SunMaps(rays, flat, suns, wanted);
}

}  // namespace leaflux
