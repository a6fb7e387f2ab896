// The Monte Carlo reference against closed forms (shared/data/README.md). Every tolerance
// is a multiple of the standard error the solver reports. That error comes from the spread
// of kReplicates independent replicate means, so (value − truth) / error follows Student's
// t with kReplicates − 1 degrees of freedom: kSigmas is its two-sided 1e-4 quantile. Where
// geometry only approximates the closed form (a 256-gon for a disc) the bound adds that
// error, stated.
#include "solver/reference/reference.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

constexpr int kReplicates = 32;
constexpr double kSigmas = 4.6;  // t quantile, 31 degrees of freedom, 1 − 5e-5
// Floating-point rounding of sums of identical samples (an estimate with zero variance).
constexpr double kRounding = 1e-9;

struct Solved {
    FlatScene flat;
    Solution solution;
    std::vector<std::string> names;  // by receiver
    std::size_t Receiver(const std::string& name) const {
        for (std::size_t r = 0; r < names.size(); ++r) {
            if (names[r] == name) return r;
        }
        throw std::runtime_error("no receiver " + name);
    }
    const BandLight& Of(const std::string& name, int band = 0) const {
        return solution.light[Receiver(name)][band];
    }
    // Its standard errors.
    const BandError& ErrorOf(const std::string& name, int band = 0) const {
        return solution.error[Receiver(name)][band];
    }
};

Solved Solve(const Scene& scene, int samples = 4096, std::uint64_t seed = 7, int threads = 0) {
    scene.Validate();
    Solved solved{Flatten(scene), {}, {}};
    for (const auto& receiver : solved.flat.receivers)
        solved.names.push_back(ReceiverName(scene, receiver));
    std::optional<PeriodicDomain> periodic;
    if (scene.periodic) {
        periodic = *scene.periodic;
        periodic->xMin -= solved.flat.origin.x;
        periodic->xMax -= solved.flat.origin.x;
        periodic->yMin -= solved.flat.origin.y;
        periodic->yMax -= solved.flat.origin.y;
    }
    RayScene rays(solved.flat, periodic);
    ReferenceOptions options;
    options.samplesPerReceiver = samples;
    options.seed = seed;
    options.threads = threads;
    options.replicates = kReplicates;
    solved.solution = SolveReference(scene, solved.flat, rays, options);
    return solved;
}

void ExpectWithin(double value, double expected, double stderrValue, double extra = 0.0) {
    EXPECT_NEAR(value, expected, kSigmas * stderrValue + kRounding * std::abs(expected) + extra)
        << "standard error " << stderrValue;
}

TEST(SinglePlate, UnderSunGetsSinOfElevationOnTop) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1, 1, 0), "black"));
    scene.sources.suns.push_back(SunAt(30, 120, 1000));
    const Solved solved = Solve(scene, 256);
    const BandLight& light = solved.Of("plate");
    const BandError& error = solved.ErrorOf("plate");
    ExpectWithin(light.irradianceUpperWm2, 500.0, error.upperWm2);
    EXPECT_EQ(light.irradianceLowerWm2, 0.0);
    ExpectWithin(light.absorbedW, 500.0, error.absorbedW);
    // One collimated beam: the light vector is the unit vector towards the sun.
    const glm::dvec3 v = light.LightVector();
    EXPECT_NEAR(glm::length(v), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(v, scene.sources.suns[0].towardSun), 1.0, 1e-12);
}

TEST(SinglePlate, UnderUniformSkyGetsPiL) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1, 1, 0), "black"));
    const double radiance = 100.0;
    scene.sources.skies.push_back({SkyModel::kUniform, {kPi * radiance}});
    const Solved solved = Solve(scene, 16384);
    const BandLight& light = solved.Of("plate");
    const BandError& error = solved.ErrorOf("plate");
    ExpectWithin(light.irradianceUpperWm2, kPi * radiance, error.upperWm2);
    EXPECT_EQ(light.irradianceLowerWm2, 0.0);
    // Light from the whole upper hemisphere: the light vector points up, |v| = 1/2.
    EXPECT_NEAR(light.LightVector().z, 0.5, 0.02);
}

TEST(SinglePlate, UnderDiscretisedSkyKeepsTheHorizontalIrradiance) {
    for (auto discretization : {SkyDiscretization::kTurtle46, SkyDiscretization::kTetra130}) {
        Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
        scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1, 1, 0), "black"));
        scene.sources.skies.push_back({SkyModel::kCieOvercast, {300.0}, discretization});
        const Solved solved = Solve(scene, 16384);
        const BandLight& light = solved.Of("plate");
        const BandError& error = solved.ErrorOf("plate");
        // The cones are normalised to give exactly the horizontal irradiance.
        ExpectWithin(light.irradianceUpperWm2, 300.0, error.upperWm2);
    }
}

// An emitter of exitance M and a black receiver of equal area: E_receiver = M · F.
struct ViewFactorCase {
    const char* name;
    std::shared_ptr<const Mesh> emitter, receiver;
    double viewFactorTimesAreaRatio;
    double geometryError;  // relative, from approximating the closed form's shapes
};

class ViewFactor : public ::testing::TestWithParam<int> {};

std::vector<ViewFactorCase> ViewFactorCases() {
    const auto rect = [](double w, double h, double z, bool down) {
        const glm::dvec3 a(0, 0, z), b(w, 0, z), c(w, h, z), d(0, h, z);
        return down ? Quad(a, d, c, b) : Quad(a, b, c, d);
    };
    // Perpendicular: emitter in z = 0 (1 × w1, upper side +z), receiver in y = 0 (1 × w2).
    const auto perpendicular = [](double w1, double w2) {
        return std::make_pair(Quad({0, 0, 0}, {1, 0, 0}, {1, w1, 0}, {0, w1, 0}),
                              Quad({0, 0, 0}, {0, 0, w2}, {1, 0, w2}, {1, 0, 0}));
    };
    const auto [p1e, p1r] = perpendicular(1, 1);
    const auto [p2e, p2r] = perpendicular(1, 2);
    return {
        {"parallel_unit_gap_1", rect(1, 1, 0, false), rect(1, 1, 1, true), 0.199825, 0},
        {"parallel_1x2_gap_0.5", rect(1, 2, 0, false), rect(1, 2, 0.5, true), 0.508989, 0},
        {"parallel_unit_gap_0.1", rect(1, 1, 0, false), rect(1, 1, 0.1, true), 0.826995, 0},
        {"parallel_unit_gap_10", rect(1, 1, 0, false), rect(1, 1, 10, true), 0.003162, 1e-3},
        {"perpendicular_unit", p1e, p1r, 0.200044, 0},
        // F(1 → 2) = 0.232853 with A1 = 1, A2 = 2: E2 = M · F · A1 / A2.
        {"perpendicular_1_2", p2e, p2r, 0.232853 / 2.0, 0},
        {"coaxial_discs_1_1_1", Disc(1, 0, false), Disc(1, 1, true), 0.381966, 1e-4},
        // F(r 0.2 → r 0.5) = 0.480032: E2 = M · F · (0.2/0.5)².
        {"coaxial_discs_0.2_0.5", Disc(0.2, 0, false), Disc(0.5, 0.5, true), 0.480032 * 0.16, 1e-4},
    };
}

TEST_P(ViewFactor, BlackReceiverMatchesHowell) {
    const ViewFactorCase c = ViewFactorCases()[GetParam()];
    SCOPED_TRACE(c.name);
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    scene.nodes.push_back(OrganNode(1, "receiver", c.receiver, "black"));
    const double exitance = 1000.0;
    scene.sources.emitters.push_back({"lamp", c.emitter, {exitance}, ""});
    const Solved solved = Solve(scene, 65536);
    const BandLight& light = solved.Of("receiver");
    const BandError& stderrs = solved.ErrorOf("receiver");
    // The receiver's upper side faces away from the emitter in every case.
    const double e = light.irradianceLowerWm2 + light.irradianceUpperWm2;
    const double error = std::hypot(stderrs.lowerWm2, stderrs.upperWm2);
    ExpectWithin(e, exitance * c.viewFactorTimesAreaRatio, error,
                 // The table's 6 digits, and the shapes' approximation.
                 exitance * (5e-7 + c.geometryError * c.viewFactorTimesAreaRatio));
}

INSTANTIATE_TEST_SUITE_P(Howell, ViewFactor, ::testing::Range(0, 8));

TEST(Furnace, RadiosityIsEmittanceOverOneMinusRho) {
    for (double rho : {0.5, 0.9}) {
        SCOPED_TRACE(rho);
        const double exitance = 10.0;
        const Solved solved = Solve(Furnace(rho, exitance), 16384);
        for (int f = 0; f < 6; ++f) {
            const BandLight& light = solved.Of("face" + std::to_string(f));
            const BandError& error = solved.ErrorOf("face" + std::to_string(f));
            ExpectWithin(light.irradianceUpperWm2, exitance / (1.0 - rho), error.upperWm2);
            // Outside the box is dark, but for rays that leave a face at a shared edge and,
            // in single-precision traversal, graze into the box: a few 1e-8 of the inside.
            EXPECT_NEAR(light.irradianceLowerWm2, 0.0, 1e-6 * exitance / (1.0 - rho));
        }
        // Closed: nothing escapes and all that arrives is absorbed, in expectation.
        const EnergyBalance& balance = solved.solution.balance[0];
        EXPECT_NEAR(balance.escapedW, 0.0, 1e-6 * balance.incidentW);
        EXPECT_NEAR(balance.incidentW - balance.absorbedW, 0.0, kSigmas * balance.stderrW);
    }
}

// ReferenceOptions::only: the receivers asked are solved as in the whole solve, path for path
// (each receiver's paths have their own random streams), and the others are left dark.
TEST(ReferenceOnly, SolvesTheReceiversAskedAsTheWholeSolveDoes) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.3, 0.2)}});
    for (int i = 0; i < 4; ++i) {
        scene.nodes.push_back(OrganNode(i + 1, "plate" + std::to_string(i),
                                        Rectangle(1.0 + 0.3 * i, 1, 1.5 - 0.5 * i), "leaf"));
    }
    scene.sources.suns.push_back(SunAt(50, 30, 1000));
    scene.sources.skies.push_back({SkyModel::kUniform, {100.0}});
    scene.Validate();
    const FlatScene flat = Flatten(scene);
    const RayScene rays(flat, std::nullopt);
    ReferenceOptions options;
    options.samplesPerReceiver = 512;
    options.replicates = kReplicates;
    const Solution whole = SolveReference(scene, flat, rays, options);
    options.only = {1, 3};
    const Solution part = SolveReference(scene, flat, rays, options);
    for (std::uint32_t r = 0; r < flat.receivers.size(); ++r) {
        SCOPED_TRACE(ReceiverName(scene, flat.receivers[r]));
        const BandLight &a = whole.light[r][0], &b = part.light[r][0];
        if (r == 1 || r == 3) {
            EXPECT_GT(a.irradianceUpperWm2, 0.0);
            EXPECT_EQ(b.irradianceUpperWm2, a.irradianceUpperWm2);
            EXPECT_EQ(b.irradianceLowerWm2, a.irradianceLowerWm2);
            EXPECT_EQ(b.absorbedW, a.absorbedW);
            EXPECT_EQ(part.error[r][0].upperWm2, whole.error[r][0].upperWm2);
        } else {
            EXPECT_EQ(b.irradianceUpperWm2, 0.0);
            EXPECT_EQ(b.absorbedW, 0.0);
        }
    }
}

}  // namespace
}  // namespace leaflux
