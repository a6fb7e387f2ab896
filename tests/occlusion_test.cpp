// Occlusion through closed instances: triangles block, boxes attenuate by their τ(ω) in
// their own frame, each once along a ray, whatever Embree's build quality.
#include "solver/raytrace/occlusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

// A unit box centred at (x, 0, 0) of constant transmittance tau.
ClosedProxy BoxAt(double x, double tau) {
    ClosedProxy proxy;
    proxy.sceneFromInstance = glm::translate(glm::dmat4(1.0), glm::dvec3(x, 0, 0));
    proxy.boxMin = glm::dvec3(-0.5);
    proxy.boxMax = glm::dvec3(0.5);
    proxy.transmittance = [tau](const glm::dvec3&) { return tau; };
    return proxy;
}

// A scene without triangles but one far away, for the ray engine.
PreparedScene Empty() {
    Scene scene = OneBandScene({{"black", Opaque(0)}});
    scene.nodes.push_back(OrganNode(1, "far", Rectangle(0.1, 0.1, 100.0), "black"));
    scene.Validate();
    return PreparedScene(scene);
}

constexpr RTCBuildQuality kQualities[] = {RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_MEDIUM,
                                          RTC_BUILD_QUALITY_HIGH};

TEST(Occlusion, ARayThroughTwoClosedNodesTakesTheProductOnce) {
    const PreparedScene prepared = Empty();
    for (RTCBuildQuality quality : kQualities) {
        const Occlusion occlusion(prepared.Rays(), {BoxAt(2, 0.5), BoxAt(4, 0.4)}, quality);
        const RayStart start{{0, 0.1, 0.2}};
        EXPECT_NEAR(occlusion.Transmittance(start, {1, 0, 0}), 0.2, 1e-15);
        EXPECT_NEAR(occlusion.Transmittance(start, {1, 0, 0}, 3.0), 0.5, 1e-15);  // ends before
        EXPECT_NEAR(occlusion.Transmittance(start, {-1, 0, 0}), 1.0, 0.0);        // away
        const std::uint32_t first = 0;
        EXPECT_NEAR(occlusion.Transmittance(start, {1, 0, 0}, INFINITY, {&first, 1}), 0.4, 1e-15);
    }
}

// Two hundred boxes in a row, overlapping so that Embree's leaves share them: each is
// multiplied in once.
TEST(Occlusion, ManyBoxesAlongARayEachCountOnce) {
    const PreparedScene prepared = Empty();
    std::vector<ClosedProxy> row;
    for (int i = 0; i < 200; ++i) row.push_back(BoxAt(1.0 + 0.3 * i, 0.99));
    for (RTCBuildQuality quality : kQualities) {
        const Occlusion occlusion(prepared.Rays(), row, quality);
        EXPECT_NEAR(occlusion.Transmittance({{-1, 0, 0}}, {1, 0, 0}), std::pow(0.99, 200), 1e-12);
    }
}

// A segment that ends halfway through a box crosses half of its chord: τ^½, so that two
// halves make τ.
TEST(Occlusion, AHalfCrossingTakesTheRootOfTau) {
    const PreparedScene prepared = Empty();
    const Occlusion occlusion(prepared.Rays(), {BoxAt(2, 0.36)});
    EXPECT_NEAR(occlusion.Transmittance({{0, 0, 0}}, {1, 0, 0}, 2.0), 0.6, 1e-12);
    EXPECT_NEAR(occlusion.Transmittance({{2, 0, 0}}, {1, 0, 0}), 0.6, 1e-12);
}

TEST(Occlusion, ATriangleInTheWayBlocks) {
    Scene scene = OneBandScene({{"black", Opaque(0)}});
    scene.nodes.push_back(
        OrganNode(1, "wall", Quad({3, -1, -1}, {3, 1, -1}, {3, 1, 1}, {3, -1, 1}), "black"));
    scene.Validate();
    const PreparedScene prepared(scene);
    // The ray scene's frame is the flat scene's, centred on the wall.
    const double x = prepared.Flat().ToLocal({0, 0, 0}).x;
    const Occlusion occlusion(prepared.Rays(), {BoxAt(x + 1.5, 0.5), BoxAt(x + 4.5, 0.5)});
    const glm::dvec3 origin = prepared.Flat().ToLocal({0, 0, 0});
    EXPECT_EQ(occlusion.Transmittance({origin}, {1, 0, 0}), 0.0);
    EXPECT_NEAR(occlusion.Transmittance({origin}, {1, 0, 0}, 2.9), 0.5, 1e-12);
}

// τ is looked up in the instance's frame: a box whose τ depends on its own z, turned so
// that its z lies along the world's x, passes what the unturned box passes along z.
TEST(Occlusion, TransmittanceIsLookedUpInTheInstanceFrame) {
    const PreparedScene prepared = Empty();
    ClosedProxy upright = BoxAt(2, 0.0);
    upright.transmittance = [](const glm::dvec3& omega) { return 0.2 + 0.7 * std::abs(omega.z); };
    ClosedProxy turned = upright;
    turned.sceneFromInstance =
        glm::rotate(upright.sceneFromInstance, glm::radians(90.0), glm::dvec3(0, 1, 0));
    const Occlusion a(prepared.Rays(), {upright}), b(prepared.Rays(), {turned});
    const RayStart start{{0, 0, 0}};
    EXPECT_NEAR(a.Transmittance(start, {1, 0, 0}), 0.2, 1e-12);
    EXPECT_NEAR(b.Transmittance(start, {1, 0, 0}), 0.9, 1e-12);
    const glm::dvec3 slant = glm::normalize(glm::dvec3(1, 0, 1));
    EXPECT_NEAR(b.Transmittance({{2 - 2, 0, -2}}, slant), 0.2 + 0.7 * std::sqrt(0.5), 1e-12);
}

}  // namespace
}  // namespace leaflux
