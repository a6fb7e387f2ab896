#include "solver/sources/sources.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <iterator>
#include <mutex>
#include <span>

#include "solver/util/check.h"
#include "solver/util/directions.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();

// A Turtle-like partition of the upper hemisphere into 46 cells of equal solid angle:
// a zenith cap and rings of 5, 10, 15 and 15 sectors. Ring k spans cos θ from
// 1 − n_{k+1}/46 to 1 − n_k/46 with n the cumulative cell counts; alternate rings are
// turned by half a sector, as on a turtle's shell.
constexpr std::array<int, 5> kTurtleRingCells = {1, 5, 10, 15, 15};

// ∫ |ω_z| dω over the cap of solid angle `solidAngle` around `axis`: π sin² α |axis_z| (α
// its half-angle) for a cap on one side of the horizon, ∫ ω dω being π sin² α axis; for one
// across it, by a midpoint rule in (cos θ, φ) about the axis, uniform in solid angle
// (relative error below 1e-6).
double CapIntegralOfAbsZ(const glm::dvec3& axis, double solidAngle) {
    constexpr int kRings = 64, kSectors = 128;
    const double cosMax = 1.0 - solidAngle / (2.0 * kPi);
    const double sin2Max = 1.0 - cosMax * cosMax;
    if (axis.z * axis.z >= sin2Max) return kPi * sin2Max * std::abs(axis.z);
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

constexpr SkyModel kSkyModels[] = {SkyModel::kUniform, SkyModel::kCieOvercast};

// A discretisation's cells: the turtle's in closed form (IntegrateTurtle), the others
// integrated over a Fibonacci lattice of the upper hemisphere (low discrepancy: cell solid
// angles to ~1e-4).
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

// The turtle's cells in closed form, ring by ring from the zenith, each ring's sectors by
// azimuth: sector s of a ring of c spans the azimuths 2π (s − o) / c to 2π (s + 1 − o) / c,
// o the ring's half-sector turn. Each is 2π/46 sr; its direction is the
// mean of ω over it, ∫ (sin θ cos φ, sin θ sin φ, z) dz dφ with ∫ sin θ dz = F(z₁) − F(z₀),
// F(z) = (z √(1 − z²) + asin z) / 2; a sky model's mean radiance over it is the model's at
// the ring's mean z, the models being linear in z alone (uniform, CIE overcast). The 2^18
// points of the integration the other discretisations take had the cells' solid angles
// within 4e-4 and cost about 20 ms of every process that lit a scene under a sky.
void IntegrateTurtle(std::vector<SkyCell>& cells, std::vector<double>& radiance,
                     const std::span<const Sky> unitSkies) {
    const auto F = [](double z) { return 0.5 * (z * std::sqrt(1.0 - z * z) + std::asin(z)); };
    int first = 0;
    for (std::size_t ring = 0; ring < kTurtleRingCells.size(); ++ring) {
        const int count = kTurtleRingCells[ring];
        const double zHigh = 1.0 - first / 46.0;
        const double zLow =
            ring + 1 == kTurtleRingCells.size() ? 0.0 : 1.0 - (first + count) / 46.0;
        const double offset = 0.5 * static_cast<double>(ring % 2);
        const double across = F(zHigh) - F(zLow), up = 0.5 * (zHigh * zHigh - zLow * zLow);
        const double zMean = 0.5 * (zLow + zHigh);
        const glm::dvec3 atMean(std::sqrt(1.0 - zMean * zMean), 0.0, zMean);
        for (int sector = 0; sector < count; ++sector) {
            const double phi0 = 2.0 * kPi * (sector - offset) / count;
            const double phi1 = 2.0 * kPi * (sector + 1 - offset) / count;
            const glm::dvec3 sum(across * (std::sin(phi1) - std::sin(phi0)),
                                 across * (std::cos(phi0) - std::cos(phi1)), up * (phi1 - phi0));
            cells.push_back({glm::normalize(sum), (zHigh - zLow) * (phi1 - phi0)});
            for (const Sky& sky : unitSkies) radiance.push_back(sky.Radiance(0, atMean));
        }
        first += count;
    }
}

CellIntegration Integrate(SkyDiscretization discretization) {
    CellIntegration result;
    constexpr std::size_t kModels = std::size(kSkyModels);
    std::array<Sky, kModels> unitSkies;
    for (std::size_t m = 0; m < kModels; ++m) unitSkies[m] = {kSkyModels[m], {1.0}};
    // Per cell, per model: its mean radiance under a unit horizontal irradiance.
    std::vector<double> meanRadiance;
    if (discretization == SkyDiscretization::kTurtle46) {
        IntegrateTurtle(result.cells, meanRadiance, unitSkies);
    } else {
        const int level = discretization == SkyDiscretization::kTetra34    ? 2
                          : discretization == SkyDiscretization::kTetra130 ? 3
                                                                           : 4;
        const DirectionSet& set = DirectionSet::OfLevel(level);
        const int cellCount = set.Size();
        std::vector<glm::dvec3> sum(cellCount, glm::dvec3(0.0));
        std::vector<int> count(cellCount, 0);
        std::vector<double> radiance(cellCount * kModels, 0.0);  // Σ over the cell's points
        const double golden = kPi * (3.0 - std::sqrt(5.0));
        for (int i = 0; i < CellIntegration::kPoints; ++i) {
            const double z = 1.0 - (i + 0.5) / CellIntegration::kPoints;  // uniform in solid angle
            const double r = std::sqrt(1.0 - z * z);
            const glm::dvec3 d(r * std::cos(golden * i), r * std::sin(golden * i), z);
            const int cell = set.Nearest(d);
            sum[cell] += d;
            ++count[cell];
            for (std::size_t m = 0; m < kModels; ++m)
                radiance[cell * kModels + m] += unitSkies[m].Radiance(0, d);
        }
        // The cells that own part of the upper hemisphere, in order.
        for (int c = 0; c < cellCount; ++c) {
            if (count[c] == 0) continue;
            result.cells.push_back(
                {glm::normalize(sum[c]), 2.0 * kPi * count[c] / CellIntegration::kPoints});
            for (std::size_t m = 0; m < kModels; ++m)
                meanRadiance.push_back(radiance[c * kModels + m] / count[c]);
        }
    }
    for (const SkyCell& cell : result.cells) {
        result.horizontalPerRadiance.push_back(
            CapIntegralOfAbsZ(cell.direction, cell.solidAngleSr));
    }
    for (std::size_t m = 0; m < kModels; ++m) {
        std::vector<double>& unit = result.unitRadiance[m];
        double horizontal = 0.0;
        for (std::size_t k = 0; k < result.cells.size(); ++k) {
            unit.push_back(meanRadiance[k * kModels + m]);
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
