#include "solver/sources/sources.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/constants.hpp>
#include <vector>

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();

TEST(SolarPosition, EquinoxNoonAtTheEquatorIsNearZenith) {
    // Day 80 ≈ 21 March: declination within half a degree of 0.
    const SolarAngles angles = SolarPosition(0.0, 80, 12.0);
    EXPECT_NEAR(glm::degrees(angles.elevationRad), 90.0, 0.5);
}

TEST(SolarPosition, NoonElevationIsNinetyMinusLatitudePlusDeclination) {
    // 21 June (day 172), declination ≈ 23.44°: at 45° N the noon sun is 68.4° high, south.
    const SolarAngles angles = SolarPosition(45.0, 172, 12.0);
    EXPECT_NEAR(glm::degrees(angles.elevationRad), 90.0 - 45.0 + 23.44, 0.2);
    EXPECT_NEAR(glm::degrees(angles.azimuthRad), 180.0, 1e-6);
}

TEST(SolarPosition, MorningSunIsInTheEastAfternoonInTheWest) {
    EXPECT_LT(glm::degrees(SolarPosition(45.0, 172, 8.0).azimuthRad), 180.0);
    EXPECT_GT(glm::degrees(SolarPosition(45.0, 172, 16.0).azimuthRad), 180.0);
    const glm::dvec3 morning = DirectionFromAngles(SolarPosition(45.0, 172, 8.0));
    EXPECT_GT(morning.x, 0.0);  // x is east
}

TEST(SunPositions, SplitTheDailyIrradianceOverTheStepsAboveTheHorizon) {
    const auto suns = SunPositionsOverPeriod(45.0, 172, 0.0, 24.0, 1.0, {240.0});
    EXPECT_GT(suns.size(), 12u);
    EXPECT_LT(suns.size(), 18u);  // about 15.5 h of day at 45° N in June
    for (const Sun& sun : suns) {
        EXPECT_GT(sun.towardSun.z, 0.0);
        EXPECT_NEAR(sun.normalIrradianceWm2[0], 10.0, 1e-12);
    }
}

// ∫ L cos θ dω over the hemisphere, by a fine midpoint rule in θ.
double HorizontalIrradiance(const Sky& sky) {
    const int steps = 20000;
    double total = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double theta = (i + 0.5) * (kPi / 2) / steps;
        const glm::dvec3 d(std::sin(theta), 0.0, std::cos(theta));
        total +=
            sky.Radiance(0, d) * std::cos(theta) * std::sin(theta) * 2 * kPi * (kPi / 2) / steps;
    }
    return total;
}

TEST(Sky, RadianceIntegratesToTheHorizontalIrradiance) {
    for (SkyModel model : {SkyModel::kUniform, SkyModel::kCieOvercast}) {
        const Sky sky{model, {250.0}};
        EXPECT_NEAR(HorizontalIrradiance(sky), 250.0, 1e-3);
    }
}

TEST(Sky, CieOvercastZenithIsThreeTimesTheHorizon) {
    const Sky sky{SkyModel::kCieOvercast, {100.0}};
    EXPECT_NEAR(sky.Radiance(0, {0, 0, 1}) / sky.Radiance(0, {1, 0, 1e-12}), 3.0, 1e-9);
}

TEST(Sky, ConesCoverTheHemisphereAndKeepTheHorizontalIrradiance) {
    for (auto discretization : {SkyDiscretization::kTurtle46, SkyDiscretization::kTetra34,
                                SkyDiscretization::kTetra130, SkyDiscretization::kTetra514}) {
        const Sky sky{SkyModel::kCieOvercast, {100.0}, discretization};
        const auto cones = sky.Cones();
        double solidAngle = 0.0, horizontal = 0.0, widest = 0.0;
        for (const SkyCone& cone : cones) {
            widest = std::max(widest, cone.solidAngleSr);
            solidAngle += cone.solidAngleSr;
            horizontal += cone.radianceWm2Sr[0] * cone.solidAngleSr * cone.direction.z;
            EXPECT_GT(cone.direction.z, 0.0);
        }
        EXPECT_NEAR(solidAngle, 2 * kPi, 1e-9);
        // The caps are normalised on ∫|cos θ| over each cap, which is at least the cap-mean
        // factor (1 + cos α)/2 times the axis's cos θ: weighted by the axes alone they give
        // at most 2 / (1 + cos α) of the irradiance, α the widest cap's half-angle.
        const double cosAlpha = 1.0 - widest / (2 * kPi);
        EXPECT_LT(horizontal, 100.0 * 2.0 / (1.0 + cosAlpha) + 1e-9);
        EXPECT_GT(horizontal, 99.0);
    }
    EXPECT_EQ(Sky({SkyModel::kUniform, {1.0}, SkyDiscretization::kTurtle46}).Cones().size(), 46u);
}

// The turtle's 46 cells (a zenith cap and rings of 5, 10, 15 and 15 sectors, each ring a
// band of cos θ 1/46 per sector wide, alternate rings turned by half a sector): each is
// 2π/46 sr, and each cone points along the mean of ω over its cell, here summed over 2^20
// points even in solid angle; under the CIE overcast sky, (1 + 2 cos θ) / 3 of the zenith,
// its radiance is the mean over the cell, up to the factor common to all (the horizontal
// irradiance kept).
TEST(Sky, TurtleConesAreTheMeansOfTheirCells) {
    const std::vector<SkyCone> cones =
        Sky{SkyModel::kCieOvercast, {1.0}, SkyDiscretization::kTurtle46}.Cones();
    ASSERT_EQ(cones.size(), 46u);
    constexpr int kRings[] = {1, 5, 10, 15, 15};
    const auto cellOf = [&](const glm::dvec3& d) {
        const double above = (1.0 - d.z) * 46.0;
        int first = 0;
        for (int ring = 0; ring < 5; ++ring) {
            const int count = kRings[ring];
            if (above < first + count || ring == 4) {
                double phi = std::atan2(d.y, d.x);
                if (phi < 0.0) phi += 2.0 * kPi;
                const double turn = 0.5 * (ring % 2);
                return first + static_cast<int>(phi / (2.0 * kPi) * count + turn) % count;
            }
            first += count;
        }
        return -1;
    };
    constexpr int kPoints = 1 << 20;
    std::vector<glm::dvec3> sum(46, glm::dvec3(0.0));
    std::vector<double> radiance(46, 0.0);
    std::vector<int> count(46, 0);
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kPoints; ++i) {
        const double z = 1.0 - (i + 0.5) / kPoints, r = std::sqrt(1.0 - z * z);
        const glm::dvec3 d(r * std::cos(golden * i), r * std::sin(golden * i), z);
        const int c = cellOf(d);
        sum[c] += d, radiance[c] += (1.0 + 2.0 * z) / 3.0, ++count[c];
    }
    const double scale = cones[0].radianceWm2Sr[0] / (radiance[0] / count[0]);
    for (int c = 0; c < 46; ++c) {
        EXPECT_NEAR(cones[c].solidAngleSr, 2.0 * kPi / 46.0, 1e-12) << c;
        // The points' share of the cell is its solid angle within ~1e-3 (their discrepancy).
        EXPECT_NEAR(count[c] * 46.0 / kPoints, 1.0, 2e-3) << c;
        EXPECT_LT(glm::length(cones[c].direction - glm::normalize(sum[c])), 1e-4) << c;
        EXPECT_NEAR(cones[c].radianceWm2Sr[0] / scale, radiance[c] / count[c], 1e-4) << c;
    }
}

}  // namespace
}  // namespace leaflux
