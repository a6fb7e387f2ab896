// The Monte Carlo reference on canopies with known statistics (shared/data/README.md):
// random leaves in a periodic cell against the exact finite-N gap fraction, the layered
// checkerboard filterT.can, and energy conservation when ρ + τ → 1.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/io/importers.h"
#include "solver/solve.h"
#include "solver/util/sampling.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

// N square leaves of LAI `lai` in the unit cell, normals uniform on the sphere (spherical
// leaf angle distribution, G = 1/2), centres uniform in x, y and in z ∈ [1, 2]; a ground
// in z = 0.
Scene RandomCanopy(int leaves, double lai, std::uint64_t seed, BandOptics leafOptics,
                   double groundRho) {
    Scene scene = OneBandScene({{"leaf", leafOptics}, {"ground", Opaque(groundRho)}});
    scene.periodic = PeriodicDomain{0, 0, 1, 1};
    Random random(seed);
    const double side = std::sqrt(lai / leaves);
    for (int i = 0; i < leaves; ++i) {
        const glm::dvec3 centre(random.Uniform(), random.Uniform(), 1.0 + random.Uniform());
        const glm::dvec3 normal = UniformSphere(random.Uniform(), random.Uniform());
        glm::dvec3 t, b;
        Basis(normal, t, b);
        const double spin = 2.0 * kPi * random.Uniform();
        const glm::dvec3 u = 0.5 * side * (std::cos(spin) * t + std::sin(spin) * b);
        const glm::dvec3 v = glm::cross(normal, u);
        scene.nodes.push_back(OrganNode(
            i + 1, "leaf" + std::to_string(i + 1),
            Quad(centre - u - v, centre + u - v, centre + u + v, centre - u + v), "leaf"));
    }
    scene.environment.push_back(
        {"ground", Quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}), "ground"});
    return scene;
}

struct Statistics {
    double mean = 0.0, stderrValue = 0.0;
};
Statistics Of(const std::vector<double>& values) {
    Statistics s;
    for (double v : values) s.mean += v / values.size();
    double squares = 0.0;
    for (double v : values) squares += (v - s.mean) * (v - s.mean);
    s.stderrValue = std::sqrt(squares / (values.size() - 1) / values.size());
    return s;
}

// Over independent canopies, the ground's lit fraction and the leaves' sunlit area
// fraction have expectations (1 − a)^N and (1 − (1 − a)^N) / (N a), a = G·LAI/(N cos θ).
// The check is against the spread of the realisations: t quantile, 7 degrees of freedom,
// two-sided 1e-4.
TEST(RandomCanopy, GapAndSunlitFractionsMatchTheFiniteNLaw) {
    constexpr int kLeaves = 2000, kCanopies = 8;
    constexpr double kLai = 3.0, kZenithDeg = 30.0, kTQuantile = 8.0;
    const double cosZenith = std::cos(glm::radians(kZenithDeg));
    const double a = 0.5 * kLai / (kLeaves * cosZenith);
    const double gapExpected = std::pow(1.0 - a, kLeaves);
    const double sunlitExpected = (1.0 - gapExpected) / (kLeaves * a);
    std::vector<double> gaps, sunlit;
    for (int c = 0; c < kCanopies; ++c) {
        Scene scene = RandomCanopy(kLeaves, kLai, 100 + c, Leaf(0, 0), 0.0);
        scene.sources.suns.push_back(SunAt(90.0 - kZenithDeg, 200.0, 1000.0));
        scene.Validate();
        const PreparedScene prepared(scene);
        SolverSettings settings;
        settings.monteCarlo.samplesPerReceiver = 1024;
        settings.monteCarlo.seed = c;
        const Solution solution = Solve(prepared, settings);
        double litArea = 0.0, area = 0.0;
        for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
            const Receiver& receiver = prepared.Flat().receivers[r];
            const BandLight& light = solution.light[r][0];
            const double direct = light.irradianceUpperWm2 + light.irradianceLowerWm2;
            if (receiver.kind == ReceiverKind::kEnvironment) {
                gaps.push_back(direct / (1000.0 * cosZenith));
                continue;
            }
            const glm::dvec3 n = prepared.Flat().triangles[receiver.firstTriangle].normal;
            const double full = 1000.0 * std::abs(glm::dot(n, scene.sources.suns[0].towardSun));
            if (full < 1e-3) continue;  // edge-on: no sunlit fraction to speak of
            litArea += receiver.areaM2 * direct / full;
            area += receiver.areaM2;
        }
        sunlit.push_back(litArea / area);
    }
    const Statistics gap = Of(gaps), lit = Of(sunlit);
    EXPECT_NEAR(gap.mean, gapExpected, kTQuantile * gap.stderrValue) << "expected " << gapExpected;
    EXPECT_NEAR(lit.mean, sunlitExpected, kTQuantile * lit.stderrValue)
        << "expected " << sunlitExpected;
    // And the realisations are not so noisy that the check says nothing.
    EXPECT_LT(gap.stderrValue, 0.05 * gapExpected);
    EXPECT_LT(lit.stderrValue, 0.05 * sunlitExpected);
}

TEST(RandomCanopy, ConservesEnergyWhenLeavesScatterNinetyNinePercent) {
    Scene scene = RandomCanopy(300, 3.0, 5, {0.5, 0.5, 0.49, 0.49}, 0.3);
    scene.sources.suns.push_back(SunAt(40, 100, 800));
    scene.sources.skies.push_back({SkyModel::kCieOvercast, {150.0}});
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = 256;
    settings.monteCarlo.replicates = 32;
    const Solution solution = Solve(prepared, settings);
    const EnergyBalance& e = solution.balance[0];
    // Light bounces about a hundred times: the solution must still be finite and balanced.
    EXPECT_GT(e.incidentW, 0.0);
    EXPECT_GT(e.escapedW, 0.3 * e.incidentW);  // ground ρ = 0.3 under a white canopy
    EXPECT_NEAR(e.incidentW - e.absorbedW - e.escapedW, 0.0, 4.6 * e.stderrW);
    // Long paths make every estimate noisy; at 256 paths a leaf the balance is still known
    // to a few percent, so the check above can fail.
    EXPECT_LT(e.stderrW, 0.05 * e.incidentW);
    ExpectFiniteLight(solution);
}

TEST(Determinism, SameSeedSameResultWhateverTheThreads) {
    Scene scene = RandomCanopy(200, 2.0, 9, Leaf(0.45, 0.45), 0.2);
    scene.sources.suns.push_back(SunAt(50, 150, 700));
    scene.sources.skies.push_back({SkyModel::kUniform, {100.0}});
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = 64;
    settings.monteCarlo.seed = 42;
    settings.monteCarlo.threads = 1;
    const Solution one = Solve(prepared, settings);
    settings.monteCarlo.threads = 2;
    const Solution two = Solve(prepared, settings);
    const Solution again = Solve(prepared, settings);
    settings.monteCarlo.seed = 43;
    const Solution other = Solve(prepared, settings);
    bool differs = false;
    for (std::size_t r = 0; r < one.light.size(); ++r) {
        EXPECT_EQ(one.light[r][0].irradianceUpperWm2, two.light[r][0].irradianceUpperWm2);
        EXPECT_EQ(one.light[r][0].irradianceLowerWm2, two.light[r][0].irradianceLowerWm2);
        EXPECT_EQ(two.light[r][0].absorbedW, again.light[r][0].absorbedW);
        EXPECT_EQ(two.light[r][0].radianceMoment, again.light[r][0].radianceMoment);
        differs |= other.light[r][0].irradianceUpperWm2 != two.light[r][0].irradianceUpperWm2;
    }
    EXPECT_TRUE(differs) << "another seed must give another estimate";
}

// filterT.can: three horizontal checkerboards of 50 % cover at z = 5, 10 and 15. Under a
// vertical sun the layers are lit 1, 0.5 and 0.25 and the ground 0.125, exactly.
TEST(FilterT, LayersAreLitOneHalfQuarterAndGroundEighth) {
    const ImportedGeometry geometry =
        ReadCan(std::string(LEAFLUX_SHARED_DATA) + "/caribu/filterT.can");
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    // The file is one organ; split it into its layers by height.
    auto layers = std::vector<std::shared_ptr<Mesh>>{};
    for (int l = 0; l < 3; ++l) layers.push_back(std::make_shared<Mesh>());
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const Node& node : geometry.nodes) {
        if (!node.organ()) continue;
        const Mesh& mesh = *node.organ()->mesh;
        for (const glm::uvec3& t : mesh.triangles) {
            const double z = mesh.positions[t.x].z;
            Mesh& layer = *layers[z < 7.5 ? 0 : z < 12.5 ? 1 : 2];
            const auto first = static_cast<unsigned>(layer.positions.size());
            for (unsigned v : {t.x, t.y, t.z}) {
                layer.positions.push_back(mesh.positions[v]);
                lo = glm::min(lo, mesh.positions[v]);
                hi = glm::max(hi, mesh.positions[v]);
            }
            layer.triangles.push_back({first, first + 1, first + 2});
        }
    }
    for (int l = 0; l < 3; ++l)
        scene.nodes.push_back(OrganNode(l + 1, "layer" + std::to_string(l), layers[l], "black"));
    scene.environment.push_back(
        {"ground", Quad({lo.x, lo.y, 0}, {hi.x, lo.y, 0}, {hi.x, hi.y, 0}, {lo.x, hi.y, 0}),
         "black"});
    scene.sources.suns.push_back({{0, 0, 1}, {1000.0}, 0.0});
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = 8192;
    settings.monteCarlo.replicates = 32;
    const Solution solution = Solve(prepared, settings);
    const double expected[] = {0.25, 0.5, 1.0, 0.125};  // layers at z = 5, 10, 15; ground
    for (int r = 0; r < 4; ++r) {
        const BandLight& light = solution.light[r][0];
        const double lit = (light.irradianceUpperWm2 + light.irradianceLowerWm2) / 1000.0;
        const BandError& stderrs = solution.error[r][0];
        const double error = std::hypot(stderrs.upperWm2, stderrs.lowerWm2) / 1000.0;
        EXPECT_NEAR(lit, expected[r], 4.6 * error + 1e-12)
            << ReceiverName(prepared.Source(), prepared.Flat().receivers[r]);
    }
}

}  // namespace
}  // namespace leaflux
