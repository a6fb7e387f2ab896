// A node kind without triangles: a closed instance known only by its phase function and
// transmittance sends and receives light through links and attenuates rays through it.
// The stand-in is an isotropic scatterer of albedo a and constant transmittance τ in a unit
// box: under a beam of irradiance E it sends I = a E A(ω)(1 − τ) / 4π alike in every
// direction, A(ω) the box's projected area.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

#include "solver/radiosity/hrc.h"
#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

constexpr double kAlbedo = 0.6, kTau = 0.3, kSun = 1000.0;

class IsotropicScatterer : public ClosedContents {
  public:
    double Transmittance(const glm::dvec3&) const override { return kTau; }
    double Phase(int, const glm::dvec3& towardSource, const glm::dvec3&) const override {
        // A unit cube's projected area along ω: |ωx| + |ωy| + |ωz|.
        const double area =
            std::abs(towardSource.x) + std::abs(towardSource.y) + std::abs(towardSource.z);
        return kAlbedo * area * (1.0 - kTau) / (4.0 * kPi);
    }
};

// A black vertical plate 10 m from the box, facing it, and a black horizontal plate 2 m
// below it, in its shadow, under a vertical sun.
Scene PlatesBesideAndBelow() {
    Scene scene = OneBandScene({{"black", Opaque(0)}});
    scene.nodes.push_back(OrganNode(
        1, "beside", Quad({10, -0.1, -0.1}, {10, -0.1, 0.1}, {10, 0.1, 0.1}, {10, 0.1, -0.1}),
        "black"));
    scene.nodes.push_back(OrganNode(2, "below", Rectangle(0.4, 0.4, -2.0), "black"));
    scene.sources.suns.push_back(SunAt(90, 0, kSun));
    return scene;
}

ClosedNode UnitBoxAtOrigin(const FlatScene& flat) {
    ClosedNode node;
    node.name = "scatterer";
    node.sceneFromInstance = glm::translate(glm::dmat4(1.0), flat.ToLocal({0, 0, 0}));
    node.boxMin = glm::dvec3(-0.5);
    node.boxMax = glm::dvec3(0.5);
    node.areaM2 = 2.0;
    node.contents = std::make_shared<IsotropicScatterer>();
    return node;
}

// The plates lit beside the scatterer, by HRC at ε = 1e-5.
Solution SolveWithScatterer(bool directOnly) {
    const Scene scene = PlatesBesideAndBelow();
    scene.Validate();
    const PreparedScene prepared(scene);
    const ClosedNode closed = UnitBoxAtOrigin(prepared.Flat());
    HrcOptions options;
    options.epsilon = 1e-5;
    options.directOnly = directOnly;
    return SolveHrc(scene, prepared.Flat(), prepared.Rays(), options, {&closed, 1});
}

// The irradiance a uniform isotropic volume emitter of intensity I (the unit cube at the
// origin) gives the plate x = 10 facing it: ∫∫ (I / V) cos θ / r² dV dA / A by the midpoint
// rule, 16³ cells of the cube and 8² of the plate (its error far below the solver's).
double BesidePlateReference(double intensity) {
    constexpr int kBox = 16, kPlate = 8;
    double sum = 0.0;
    for (int i = 0; i < kBox; ++i)
        for (int j = 0; j < kBox; ++j)
            for (int k = 0; k < kBox; ++k) {
                const glm::dvec3 y(-0.5 + (i + 0.5) / kBox, -0.5 + (j + 0.5) / kBox,
                                   -0.5 + (k + 0.5) / kBox);
                for (int u = 0; u < kPlate; ++u)
                    for (int v = 0; v < kPlate; ++v) {
                        const glm::dvec3 x(10.0, -0.1 + 0.2 * (u + 0.5) / kPlate,
                                           -0.1 + 0.2 * (v + 0.5) / kPlate);
                        const glm::dvec3 d = y - x;
                        const double r2 = glm::dot(d, d);
                        sum += -d.x / std::sqrt(r2) / r2;
                    }
            }
    return intensity * sum / (kBox * kBox * kBox * kPlate * kPlate);
}

TEST(ClosedNode, AnIsotropicScattererLightsAReceiverBesideItAsItsClosedForm) {
    const Solution s = SolveWithScatterer(false);
    const double intensity = kAlbedo * kSun * 1.0 * (1.0 - kTau) / (4.0 * kPi);
    const double expected = BesidePlateReference(intensity);
    // The link carries the box's light as a point transfer with its spread's second-order
    // correction; its geometric error, ((r_R + r_S) / d)², bounds what is left.
    const double bound = std::pow((std::sqrt(0.02) + std::sqrt(0.75)) / 10.0, 2.0);
    std::printf("plate beside: %.5f W/m², by quadrature %.5f W/m², bound %.2f %%\n",
                s.light[0][0].irradianceUpperWm2, expected, 100.0 * bound);
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2, expected, bound * expected);
    EXPECT_NEAR(s.light[0][0].irradianceLowerWm2, 0.0, 1e-12);
    // Below the box, its scattered light comes on top of the sun it lets through.
    EXPECT_GT(s.light[1][0].irradianceUpperWm2, kTau * kSun);
}

TEST(ClosedNode, RaysThroughItAreAttenuatedByExactlyItsTransmittance) {
    const Solution s = SolveWithScatterer(true);
    // Exactly but for the single precision a source link keeps its visibility in.
    EXPECT_NEAR(s.light[1][0].irradianceUpperWm2, kTau * kSun, 0x1p-24 * kSun);
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2, 0.0, 1e-9);  // the sun grazes it
}

}  // namespace
}  // namespace leaflux
