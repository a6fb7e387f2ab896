#include "solver/sources/sources.h"

#include <array>
#include <cmath>
#include <glm/gtc/constants.hpp>
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
// Fibonacci lattice of the upper hemisphere (low discrepancy: cell solid angles to ~1e-4).
struct CellIntegration {
    static constexpr int kPoints = 1 << 18;
    std::vector<int> cellOfPoint;  // per lattice point
    std::vector<glm::dvec3> pointDirections;
    std::vector<SkyCell> cells;
    // Per cell: the irradiance its cone gives a horizontal plane per unit radiance, ∫ |z|
    // over its cap, the part below the horizon folded up as the solvers fold it.
    std::vector<double> horizontalPerRadiance;
};

CellIntegration Integrate(SkyDiscretization discretization) {
    CellIntegration result;
    const int level = discretization == SkyDiscretization::kTetra34    ? 2
                      : discretization == SkyDiscretization::kTetra130 ? 3
                      : discretization == SkyDiscretization::kTetra514 ? 4
                                                                       : -1;
    const DirectionSet* set = level >= 0 ? &DirectionSet::OfLevel(level) : nullptr;
    const int cellCount = set ? set->Size() : 46;
    std::vector<glm::dvec3> sum(cellCount, glm::dvec3(0.0));
    std::vector<int> count(cellCount, 0);
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < CellIntegration::kPoints; ++i) {
        const double z = 1.0 - (i + 0.5) / CellIntegration::kPoints;  // uniform in solid angle
        const double r = std::sqrt(1.0 - z * z);
        const glm::dvec3 d(r * std::cos(golden * i), r * std::sin(golden * i), z);
        const int cell = set ? set->Nearest(d) : TurtleCell(d);
        result.cellOfPoint.push_back(cell);
        result.pointDirections.push_back(d);
        sum[cell] += d;
        ++count[cell];
    }
    // Renumber the cells that own part of the upper hemisphere.
    std::vector<int> renumber(cellCount, -1);
    for (int c = 0; c < cellCount; ++c) {
        if (count[c] == 0) continue;
        renumber[c] = static_cast<int>(result.cells.size());
        result.cells.push_back(
            {glm::normalize(sum[c]), 2.0 * kPi * count[c] / CellIntegration::kPoints});
    }
    for (int& cell : result.cellOfPoint) cell = renumber[cell];
    for (const SkyCell& cell : result.cells) {
        result.horizontalPerRadiance.push_back(
            CapIntegralOfAbsZ(cell.direction, cell.solidAngleSr));
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
    const int bands = static_cast<int>(horizontalIrradianceWm2.size());
    std::vector<SkyCone> cones;
    for (const SkyCell& cell : integration.cells) {
        cones.push_back({cell.direction, cell.solidAngleSr, std::vector<double>(bands, 0.0)});
    }
    std::vector<int> points(cones.size(), 0);
    for (std::size_t i = 0; i < integration.cellOfPoint.size(); ++i) {
        SkyCone& cone = cones[integration.cellOfPoint[i]];
        ++points[integration.cellOfPoint[i]];
        for (int b = 0; b < bands; ++b) {
            cone.radianceWm2Sr[b] += Radiance(b, integration.pointDirections[i]);
        }
    }
    for (int b = 0; b < bands; ++b) {
        double horizontal = 0.0;
        for (std::size_t c = 0; c < cones.size(); ++c) {
            cones[c].radianceWm2Sr[b] /= points[c];
            horizontal += cones[c].radianceWm2Sr[b] * integration.horizontalPerRadiance[c];
        }
        const double scale = horizontal > 0.0 ? horizontalIrradianceWm2[b] / horizontal : 0.0;
        for (SkyCone& cone : cones) cone.radianceWm2Sr[b] *= scale;
    }
    return cones;
}

}  // namespace leaflux
