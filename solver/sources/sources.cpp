#include "solver/sources/sources.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <iterator>
#include <mutex>

#include "solver/util/check.h"
#include "solver/util/directions.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();

// A Turtle-like partition of the upper hemisphere into 46 cells of equal solid angle:
// a zenith cap and rings of 5, 10, 15 and 15 sectors. Ring k spans cos θ from
// 1 − n_k/46 to 1 − n_{k+1}/46 with n the cumulative cell counts.
constexpr std::array<int, 5> kTurtleRingCells = {1, 5, 10, 15, 15};

int TurtleCell(const glm::dvec3& d) {
    const double above = (1.0 - glm::clamp(d.z, 0.0, 1.0)) * 46.0;  // cells nearer the zenith
    int first = 0;
    for (std::size_t ring = 0; ring < kTurtleRingCells.size(); ++ring) {
        const int count = kTurtleRingCells[ring];
        if (above < first + count || ring + 1 == kTurtleRingCells.size()) {
            double phi = std::atan2(d.y, d.x);
            if (phi < 0.0) phi += 2.0 * kPi;
            // Alternate rings are turned by half a sector, as on a turtle's shell.
            const double offset = 0.5 * static_cast<double>(ring % 2);
            const int sector = static_cast<int>(phi / (2.0 * kPi) * count + offset) % count;
            return first + sector;
        }
        first += count;
    }
    return first - 1;
}

// ∫ |ω_z| dω over the cap of solid angle `solidAngle` around `axis`, by a midpoint rule
// in (cos θ, φ) about the axis, uniform in solid angle (relative error below 1e-6).
double CapIntegralOfAbsZ(const glm::dvec3& axis, double solidAngle) {
    constexpr int kRings = 64, kSectors = 128;
    const double cosMax = 1.0 - solidAngle / (2.0 * kPi);
    glm::dvec3 t = std::abs(axis.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    t = glm::normalize(glm::cross(axis, t));
    const glm::dvec3 b = glm::cross(axis, t);
    double sum = 0.0;
    for (int i = 0; i < kRings; ++i) {
        const double z = 1.0 - (i + 0.5) / kRings * (1.0 - cosMax);
        const double r = std::sqrt(1.0 - z * z);
        for (int j = 0; j < kSectors; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / kSectors;
            sum += std::abs((r * std::cos(phi) * t + r * std::sin(phi) * b + z * axis).z);
        }
    }
    return sum * solidAngle / (kRings * kSectors);
}

// Cells of a discretisation, with their solid angles and centroids integrated over a
constexpr SkyModel kSkyModels[] = {SkyModel::kUniform, SkyModel::kCieOvercast};

// A discretisation's cells, integrated over a Fibonacci lattice of the upper hemisphere
// (low discrepancy: cell solid angles to ~1e-4).
struct CellIntegration {
    static constexpr int kPoints = 1 << 18;
    std::vector<SkyCell> cells;
    // Per cell: the irradiance its cone gives a horizontal plane per unit radiance, ∫ |z|
    // over its cap, the part below the horizon folded up as the solvers fold it.
    std::vector<double> horizontalPerRadiance;
    // Per sky model, per cell: its cone's radiance under a unit horizontal irradiance (the
    // model's mean over the cell, renormalised as Sky::Cones says). Radiance is linear in
    // the horizontal irradiance, so a band's cones are these times its own.
    std::vector<double> unitRadiance[std::size(kSkyModels)];
};

CellIntegration Integrate(SkyDiscretization discretization) {
    CellIntegration result;
    const int level = discretization == SkyDiscretization::kTetra34    ? 2
                      : discretization == SkyDiscretization::kTetra130 ? 3
                      : discretization == SkyDiscretization::kTetra514 ? 4
                                                                       : -1;
    const DirectionSet* set = level >= 0 ? &DirectionSet::OfLevel(level) : nullptr;
    const int cellCount = set ? set->Size() : 46;
    constexpr std::size_t kModels = std::size(kSkyModels);
    std::vector<glm::dvec3> sum(cellCount, glm::dvec3(0.0));
    std::vector<int> count(cellCount, 0);
    std::vector<double> radiance(cellCount * kModels, 0.0);  // Σ over the cell's points
    std::array<Sky, kModels> unitSkies;
    for (std::size_t m = 0; m < kModels; ++m) unitSkies[m] = {kSkyModels[m], {1.0}};
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < CellIntegration::kPoints; ++i) {
        const double z = 1.0 - (i + 0.5) / CellIntegration::kPoints;  // uniform in solid angle
        const double r = std::sqrt(1.0 - z * z);
        const glm::dvec3 d(r * std::cos(golden * i), r * std::sin(golden * i), z);
        const int cell = set ? set->Nearest(d) : TurtleCell(d);
        sum[cell] += d;
        ++count[cell];
        for (std::size_t m = 0; m < kModels; ++m)
            radiance[cell * kModels + m] += unitSkies[m].Radiance(0, d);
    }
    // The cells that own part of the upper hemisphere, in order.
    std::vector<int> owning;
    for (int c = 0; c < cellCount; ++c) {
        if (count[c] == 0) continue;
        owning.push_back(c);
        result.cells.push_back(
            {glm::normalize(sum[c]), 2.0 * kPi * count[c] / CellIntegration::kPoints});
        result.horizontalPerRadiance.push_back(
            CapIntegralOfAbsZ(result.cells.back().direction, result.cells.back().solidAngleSr));
    }
    for (std::size_t m = 0; m < kModels; ++m) {
        std::vector<double>& unit = result.unitRadiance[m];
        double horizontal = 0.0;
        for (std::size_t k = 0; k < owning.size(); ++k) {
            unit.push_back(radiance[owning[k] * kModels + m] / count[owning[k]]);
            horizontal += unit.back() * result.horizontalPerRadiance[k];
        }
        for (double& value : unit) value = horizontal > 0.0 ? value / horizontal : 0.0;
    }
    return result;
}

// Integrated once per discretisation, when first asked for.
const CellIntegration& CellsOf(SkyDiscretization discretization) {
    LEAFLUX_CHECK(discretization != SkyDiscretization::kContinuous);
    static std::array<std::once_flag, 5> once;
    static std::array<CellIntegration, 5> cache;
    const int index = static_cast<int>(discretization);
    std::call_once(once[index], [&] { cache[index] = Integrate(discretization); });
    return cache[index];
}
}  // namespace

SolarAngles SolarPosition(double latitudeDeg, int dayOfYear, double solarTimeH) {
    const double gamma = 2.0 * kPi * (dayOfYear - 1) / 365.0;  // Spencer's day angle
    const double declination = 0.006918 - 0.399912 * std::cos(gamma) + 0.070257 * std::sin(gamma) -
                               0.006758 * std::cos(2 * gamma) + 0.000907 * std::sin(2 * gamma) -
                               0.002697 * std::cos(3 * gamma) + 0.00148 * std::sin(3 * gamma);
    const double hourAngle = glm::radians(15.0 * (solarTimeH - 12.0));
    const double latitude = glm::radians(latitudeDeg);
    const double sinElevation = std::sin(latitude) * std::sin(declination) +
                                std::cos(latitude) * std::cos(declination) * std::cos(hourAngle);
    const double elevation = std::asin(glm::clamp(sinElevation, -1.0, 1.0));
    // Azimuth from north, clockwise: from the horizontal components of the sun vector in
    // the east-north frame, which stays well defined at the poles and at noon.
    const double east = -std::cos(declination) * std::sin(hourAngle);
    const double north = std::sin(declination) * std::cos(latitude) -
                         std::cos(declination) * std::sin(latitude) * std::cos(hourAngle);
    double azimuth = std::atan2(east, north);
    if (azimuth < 0.0) azimuth += 2.0 * kPi;
    return {elevation, azimuth};
}

glm::dvec3 DirectionFromAngles(const SolarAngles& angles) {
    const double horizontal = std::cos(angles.elevationRad);
    return {horizontal * std::sin(angles.azimuthRad), horizontal * std::cos(angles.azimuthRad),
            std::sin(angles.elevationRad)};
}

std::vector<Sun> SunPositionsOverPeriod(double latitudeDeg, int dayOfYear, double startH,
                                        double endH, double stepH,
                                        const std::vector<double>& normalIrradianceWm2) {
    std::vector<Sun> suns;
    // Callers cap the steps (the daemon at --max-suns); this cap keeps the count an int
    // (1e-9 h steps would overflow it and silently make no sun).
    constexpr double kMaxSteps = 1e7;
    const double count = std::ceil((endH - startH) / stepH - 1e-9);
    if (!(count >= 0.0 && count <= kMaxSteps)) {
        throw InputError(ErrorCode::kInvalidArgument, "step_h",
                         "makes more than 10^7 sun positions (or none)");
    }
    const int steps = static_cast<int>(count);
    for (int i = 0; i < steps; ++i) {
        const double from = startH + i * stepH, to = std::min(endH, from + stepH);
        const SolarAngles angles = SolarPosition(latitudeDeg, dayOfYear, 0.5 * (from + to));
        if (angles.elevationRad <= 0.0) continue;
        Sun sun;
        sun.towardSun = DirectionFromAngles(angles);
        for (double e : normalIrradianceWm2) {
            sun.normalIrradianceWm2.push_back(e * (to - from) / (endH - startH));
        }
        suns.push_back(std::move(sun));
    }
    return suns;
}

double Sky::Radiance(int band, const glm::dvec3& towardSky) const {
    if (towardSky.z <= 0.0) return 0.0;
    const double horizontal = horizontalIrradianceWm2[band];
    switch (model) {
        case SkyModel::kUniform:
            return horizontal / kPi;
        case SkyModel::kCieOvercast: {
            // L(θ) = Lz (1 + 2 cos θ) / 3 integrates to E_h = 7π/9 · Lz.
            const double zenith = 9.0 * horizontal / (7.0 * kPi);
            return zenith * (1.0 + 2.0 * towardSky.z) / 3.0;
        }
    }
    return 0.0;
}

std::vector<SkyCell> SkyCells(SkyDiscretization discretization) {
    if (discretization == SkyDiscretization::kContinuous) return {};
    return CellsOf(discretization).cells;
}

std::vector<SkyCone> Sky::Cones() const {
    if (discretization == SkyDiscretization::kContinuous) return {};
    const CellIntegration& integration = CellsOf(discretization);
    const std::size_t m =
        std::find(std::begin(kSkyModels), std::end(kSkyModels), model) - std::begin(kSkyModels);
    LEAFLUX_CHECK(m < std::size(kSkyModels));
    std::vector<SkyCone> cones;
    for (std::size_t c = 0; c < integration.cells.size(); ++c) {
        const SkyCell& cell = integration.cells[c];
        SkyCone cone{cell.direction, cell.solidAngleSr, {}};
        for (double horizontal : horizontalIrradianceWm2)
            cone.radianceWm2Sr.push_back(horizontal * integration.unitRadiance[m][c]);
        cones.push_back(std::move(cone));
    }
    return cones;
}

}  // namespace leaflux
