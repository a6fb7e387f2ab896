// HRC where users work (stiff cases the error tables do not hold): a canopy under a sky of
// cones against the continuous sky, and a canopy on a small and on a large ground. Each
// compares with the Monte Carlo reference on the same scene, per leaf side: the RMS of the
// difference over the mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "solver/generate/generator.h"
#include "solver/solve.h"

namespace leaflux {
namespace {

Scene Canopy(int leaves, SkyDiscretization sky, double groundHalfWidthM, bool sun,
             double leafRho = 0.45, double groundRho = 0.3) {
    Scene scene;
    scene.bands = {{"NIR"}};
    scene.optics = {{"leaf", {{leafRho, leafRho, leafRho, leafRho}}},
                    {"ground", {{groundRho, groundRho, 0.0, 0.0}}}};
    CanopyParameters canopy;
    canopy.leaves = leaves;
    canopy.widthM = 1.0;
    canopy.bottomM = 0.1;
    canopy.topM = 1.1;
    canopy.leafAreaIndex = leaves * 0.05 * 0.05;  // 5 cm square leaves in a 1 m square
    canopy.seed = 4;
    AddRandomCanopy(scene, canopy);
    if (groundHalfWidthM > 0.0) {
        auto mesh = std::make_shared<Mesh>();
        const double h = groundHalfWidthM;
        mesh->positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
        mesh->triangles = {{0, 1, 2}, {0, 2, 3}};
        scene.environment.push_back({"ground", mesh, "ground"});
    }
    Sky uniform;
    uniform.model = SkyModel::kUniform;
    uniform.horizontalIrradianceWm2 = {100.0};
    uniform.discretization = sky;
    scene.sources.skies.push_back(uniform);
    if (sun) {
        const double h = glm::radians(50.0), a = glm::radians(160.0);
        scene.sources.suns.push_back(
            {{std::cos(h) * std::sin(a), std::cos(h) * std::cos(a), std::sin(h)}, {350.0}});
    }
    scene.Validate();
    return scene;
}

Solution SolveWith(const Scene& scene, SolverKind kind, double epsilon = 1e-4, int samples = 8192) {
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.kind = kind;
    settings.hrc.epsilon = epsilon;
    settings.monteCarlo.samplesPerReceiver = samples;
    return Solve(prepared, settings);
}

// Per side: RMS(other − reference) / mean(reference), over the organs.
double SideError(const Solution& reference, const Solution& other, std::size_t organs) {
    double sum = 0.0, mean = 0.0;
    for (std::size_t r = 0; r < organs; ++r) {
        const BandLight &a = reference.light[r][0], &b = other.light[r][0];
        sum += std::pow(a.irradianceUpperWm2 - b.irradianceUpperWm2, 2) +
               std::pow(a.irradianceLowerWm2 - b.irradianceLowerWm2, 2);
        mean += a.irradianceUpperWm2 + a.irradianceLowerWm2;
    }
    return std::sqrt(sum / (2.0 * organs)) / (mean / (2.0 * organs));
}

TEST(HrcAccuracy, SkyConesAreSoftShadowsNotHardBeams) {
    // The 46 cones cost Monte Carlo their discretisation error and no more; HRC on them must
    // come as close to the continuous sky. As parallel beams it was 1.9 times as far off at
    // ε = 1e-5 (4.2 % against 2.2 % on 500 leaves), and no nearer at 1e-5 than at 1e-4.
    const int leaves = 250;
    const Scene continuous = Canopy(leaves, SkyDiscretization::kContinuous, 0.0, false);
    const Scene cones = Canopy(leaves, SkyDiscretization::kTurtle46, 0.0, false);
    const Solution reference = SolveWith(continuous, SolverKind::kMonteCarlo, 0.0, 16384);
    const double mc = SideError(reference, SolveWith(cones, SolverKind::kMonteCarlo), leaves);
    const double coarse = SideError(reference, SolveWith(cones, SolverKind::kHrc, 1e-4), leaves);
    const double fine = SideError(reference, SolveWith(cones, SolverKind::kHrc, 1e-5), leaves);
    std::printf(
        "46-cone sky against the continuous one, per side: Monte Carlo %.2f %%, HRC "
        "%.2f %% at ε = 1e-4, %.2f %% at 1e-5\n",
        100 * mc, 100 * coarse, 100 * fine);
    EXPECT_LT(fine, 1.2 * mc);
    EXPECT_LT(fine, coarse);
}

TEST(HrcAccuracy, AGroundAroundTheCanopyDoesNotMakeItsLeavesCoarse) {
    // ε is relative to the power reaching the organs: on a ±200 m ground, the leaves are as
    // accurate as on a ±10 m one (before, 25 % against 7.8 % per side at ε = 1e-4, and the
    // same at 1e-5).
    const int leaves = 150;
    double errors[2];
    const double widths[2] = {10.0, 200.0};
    for (int k = 0; k < 2; ++k) {
        const Scene scene = Canopy(leaves, SkyDiscretization::kTurtle46, widths[k], true);
        errors[k] = SideError(SolveWith(scene, SolverKind::kMonteCarlo, 0.0, 8192),
                              SolveWith(scene, SolverKind::kHrc, 1e-4), leaves);
    }
    std::printf("per side at ε = 1e-4: %.2f %% on a ±10 m ground, %.2f %% on a ±200 m one\n",
                100 * errors[0], 100 * errors[1]);
    EXPECT_LT(errors[1], 1.5 * errors[0]);
    EXPECT_LT(errors[1], 0.05);
}

// RAMI's purist corner: leaves with ρ + τ = 1 over a white ground (here ±200 m) under a
// uniform sky of 46 cones. The light field is then isotropic: every leaf side gets the
// sky's irradiance and every light vector vanishes, whatever the leaves' places. A link's
// light vector takes the mean of ω over its sender's solid angle (Estimator::Arrival):
// taken towards a large patch's centre it pulled towards that centre with the whole
// solid angle, and a leaf's |v| reached 0.088.
TEST(HrcAccuracy, AnIsotropicFieldLightsEverySideAlikeFromEveryDirection) {
    const int leaves = 300;
    const Scene scene = Canopy(leaves, SkyDiscretization::kTurtle46, 200.0, false, 0.5, 1.0);
    for (SolverKind kind : {SolverKind::kMonteCarlo, SolverKind::kHrc}) {
        const Solution s = SolveWith(scene, kind, 1e-4, 4096);
        double worst = 0.0, largest = 0.0, sum = 0.0, squares = 0.0;
        for (int r = 0; r < leaves; ++r) {
            const BandLight& b = s.light[r][0];
            for (const auto& [e, error] : {std::pair{b.irradianceUpperWm2, b.stderrUpperWm2},
                                           std::pair{b.irradianceLowerWm2, b.stderrLowerWm2}}) {
                worst = std::max(worst, std::abs(e / 100.0 - 1.0));
                sum += e, squares += e * e;
                // Monte Carlo: each side within its noise (5.5 σ: 2e-5 over 600 sides; the
                // cones' 0.26 % is far below it).
                if (kind == SolverKind::kMonteCarlo) {
                    EXPECT_NEAR(e, 100.0, 5.5 * error);
                }
            }
            largest = std::max(largest, glm::length(b.LightVector()));
        }
        const double mean = sum / (2 * leaves);
        std::printf("%s: mean side %.3f W/m², sd %.2f %%, worst %.2f %%, largest |v| %.3f\n",
                    kind == SolverKind::kHrc ? "hrc" : "mc", mean,
                    100 * std::sqrt(squares / (2 * leaves) - mean * mean) / mean, 100 * worst,
                    largest);
        if (kind == SolverKind::kHrc) {
            // Nothing is absorbed: the mean side within 1 %, the balance's closure as the
            // stability suite holds it (0.5 %) plus the cones' own discretisation (Monte
            // Carlo's mean on them, printed above, 99.74 W/m²).
            EXPECT_NEAR(mean, 100.0, 1.0);
            EXPECT_LE(largest, 0.05);
        }
    }
}

// Under a sun and a sky of cones, over a grey ground: each leaf's light vector against
// the Monte Carlo reference's, its length and, where it is over 0.2, its direction. With
// links' vectors towards their senders' centres: worst length 0.030, directions p95 2.9°,
// worst 7.3°; with the mean of ω over a plane sender, 0.029, 2.6° and 5.6°.
TEST(HrcAccuracy, LightVectorsUnderSunAndSkyFollowTheReference) {
    const int leaves = 250;
    const Scene scene = Canopy(leaves, SkyDiscretization::kTurtle46, 10.0, true);
    const Solution reference = SolveWith(scene, SolverKind::kMonteCarlo, 0.0, 8192);
    const Solution hrc = SolveWith(scene, SolverKind::kHrc, 1e-4);
    double worstLength = 0.0, worstAngle = 0.0, sumLength = 0.0;
    std::vector<double> angles;
    for (int r = 0; r < leaves; ++r) {
        const glm::dvec3 want = reference.light[r][0].LightVector();
        const glm::dvec3 got = hrc.light[r][0].LightVector();
        const double dl = std::abs(glm::length(got) - glm::length(want));
        worstLength = std::max(worstLength, dl);
        sumLength += dl;
        if (glm::length(want) > 0.2) {
            const double c = glm::dot(got, want) / (glm::length(got) * glm::length(want));
            angles.push_back(glm::degrees(std::acos(std::clamp(c, -1.0, 1.0))));
            worstAngle = std::max(worstAngle, angles.back());
        }
    }
    std::sort(angles.begin(), angles.end());
    const double p95 = angles[angles.size() * 95 / 100];
    std::printf(
        "light vectors: |v| off by %.3f mean, %.3f worst; direction (%zu leaves with |v| > "
        "0.2) median %.2f°, p95 %.2f°, worst %.2f°\n",
        sumLength / leaves, worstLength, angles.size(), angles[angles.size() / 2], p95, worstAngle);
    // Two references of 8,192 paths a leaf, on other seeds, differ by up to 0.025 in
    // length and 6.2° in direction (p95 2.2°): at that budget the test sees the goal
    // (within 0.05 and 5°) through the reference's noise.
    EXPECT_LE(worstLength, 0.05);
    EXPECT_LE(p95, 5.0);
}

}  // namespace
}  // namespace leaflux
