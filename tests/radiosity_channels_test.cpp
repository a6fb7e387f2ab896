// The radiosity engine's channels: a scene of many bands solves, each band as it would
// alone (bands never mix), in HRC and in the Monte Carlo reference.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

constexpr int kBands = 16;

// Three leaves over a grey floor under a sun, with 16 bands whose optics and sun differ.
Scene SixteenBandScene() {
    Scene scene;
    BandOptics leafBand, floorBand;
    Optics leaf{"leaf", {}}, floor{"floor", {}};
    Sun sun = SunAt(60, 30, 0.0);
    sun.normalIrradianceWm2.clear();
    for (int b = 0; b < kBands; ++b) {
        scene.bands.push_back({"band" + std::to_string(b)});
        const double rho = 0.05 + 0.05 * b, tau = 0.9 - rho - 0.01 * (b % 3);
        leaf.bands.push_back(Leaf(rho, tau));
        floor.bands.push_back(Opaque(0.1 + 0.04 * b));
        sun.normalIrradianceWm2.push_back(100.0 + 37.0 * b);
    }
    scene.optics = {leaf, floor};
    scene.nodes.push_back(OrganNode(
        1, "a", Quad({0, 0, 0.5}, {0.2, 0, 0.55}, {0.2, 0.2, 0.5}, {0, 0.2, 0.45}), "leaf"));
    scene.nodes.push_back(OrganNode(
        2, "b", Quad({0.1, 0.05, 0.3}, {0.3, 0.05, 0.3}, {0.3, 0.25, 0.32}, {0.1, 0.25, 0.3}),
        "leaf"));
    scene.nodes.push_back(OrganNode(
        3, "c", Quad({-0.1, 0.1, 0.15}, {0.1, 0.1, 0.1}, {0.1, 0.3, 0.1}, {-0.1, 0.3, 0.15}),
        "leaf"));
    scene.environment.push_back({"floor", Rectangle(1.0, 1.0, 0.0), "floor"});
    scene.sources.suns.push_back(sun);
    return scene;
}

// With ε = 0 every link is refined to the finest patches whatever the bands' light, so a
// band solved with the others and alone takes the same links; converged far below the
// comparison, the two are the same fixed point.
TEST(HrcChannels, SixteenBandsEachEqualToTheBandSolvedAlone) {
    const Scene scene = SixteenBandScene();
    scene.Validate();
    SolverSettings settings;
    settings.kind = SolverKind::kHrc;
    settings.hrc.epsilon = 0.0;
    settings.hrc.maxSubdivision = 1;
    settings.hrc.tolerance = 1e-11;
    const Solution all = Solve(PreparedScene(scene), settings);
    ASSERT_EQ(all.light.front().size(), static_cast<std::size_t>(kBands));
    for (int b : {0, 5, 15}) {
        const Scene alone = WithBands(scene, {b});
        const Solution one = Solve(PreparedScene(alone), settings);
        for (std::size_t r = 0; r < one.light.size(); ++r) {
            const BandLight& x = all.light[r][b];
            const BandLight& y = one.light[r][0];
            SCOPED_TRACE("receiver " + std::to_string(r) + ", band " + std::to_string(b));
            EXPECT_GT(y.irradianceUpperWm2 + y.irradianceLowerWm2, 0.0);
            EXPECT_NEAR(x.irradianceUpperWm2, y.irradianceUpperWm2, 1e-8 * y.irradianceUpperWm2);
            EXPECT_NEAR(x.irradianceLowerWm2, y.irradianceLowerWm2, 1e-8 * y.irradianceLowerWm2);
            EXPECT_NEAR(x.absorbedW, y.absorbedW, 1e-8 * y.absorbedW);
        }
    }
}

// The reference solves a scene of more bands than a path carries a group at a time; each
// band agrees with the band alone within the two estimates' standard errors.
TEST(ReferenceChannels, SixteenBandsEachAgreeWithTheBandSolvedAlone) {
    const Scene scene = SixteenBandScene();
    scene.Validate();
    SolverSettings settings;
    settings.kind = SolverKind::kMonteCarlo;
    settings.monteCarlo.samplesPerReceiver = 4096;
    const Solution all = Solve(PreparedScene(scene), settings);
    ASSERT_EQ(all.light.front().size(), static_cast<std::size_t>(kBands));
    ASSERT_EQ(all.balance.size(), static_cast<std::size_t>(kBands));
    for (int b : {3, 12}) {
        const Solution one = Solve(PreparedScene(WithBands(scene, {b})), settings);
        for (std::size_t r = 0; r < one.light.size(); ++r) {
            const BandLight& x = all.light[r][b];
            const BandLight& y = one.light[r][0];
            SCOPED_TRACE("receiver " + std::to_string(r) + ", band " + std::to_string(b));
            EXPECT_GT(y.irradianceUpperWm2, 0.0);
            const BandError &xe = all.error[r][b], &ye = one.error[r][0];
            const double upper = std::hypot(xe.upperWm2, ye.upperWm2);
            const double lower = std::hypot(xe.lowerWm2, ye.lowerWm2);
            EXPECT_NEAR(x.irradianceUpperWm2, y.irradianceUpperWm2,
                        5.0 * upper + 1e-9 * y.irradianceUpperWm2);
            EXPECT_NEAR(x.irradianceLowerWm2, y.irradianceLowerWm2,
                        5.0 * lower + 1e-9 * y.irradianceLowerWm2);
        }
    }
}

}  // namespace
}  // namespace leaflux
