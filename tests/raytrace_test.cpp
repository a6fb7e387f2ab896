#include "solver/raytrace.h"

#include <gtest/gtest.h>

#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

FlatScene Plates(std::vector<std::shared_ptr<const Mesh>> meshes) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    NodeId id = 1;
    for (auto& mesh : meshes) {
        scene.nodes.push_back(OrganNode(id, "plate" + std::to_string(id), mesh, "black"));
        ++id;
    }
    scene.Validate();
    return Flatten(scene);
}

TEST(RayScene, FindsTheClosestPlateAndEscapesPastIt) {
    const FlatScene flat = Plates({Rectangle(1, 1, 0), Rectangle(1, 1, 2)});
    const RayScene rays(flat, std::nullopt);
    const glm::dvec3 below = flat.ToLocal({0, 0, -1});
    const RayHit hit = rays.Trace({below}, {0, 0, 1});
    ASSERT_EQ(hit.fate, RayFate::kHit);
    EXPECT_EQ(flat.triangles[hit.triangle].receiver, 0u);
    EXPECT_NEAR(hit.distance, 1.0, 1e-6);
    EXPECT_EQ(rays.Trace({below}, {0, 0, -1}).fate, RayFate::kEscapedDown);
    EXPECT_EQ(rays.Trace({flat.ToLocal({5, 0, 1})}, glm::normalize(glm::dvec3(0, 1, 1))).fate,
              RayFate::kEscapedUp);
    EXPECT_TRUE(rays.Occluded({below}, {0, 0, 1}));
    EXPECT_FALSE(rays.Occluded({below}, {0, 0, 1}, 0.5));
}

TEST(RayScene, LeavesItsStartTriangleEvenOneMicrometreFromTheNext) {
    const FlatScene flat = Plates({Rectangle(1, 1, 0), Rectangle(1, 1, 1e-6)});
    const RayScene rays(flat, std::nullopt);
    const Triangle& start = flat.triangles[0];
    const glm::dvec3 origin = (start.a + start.b + start.c) / 3.0;
    const RayHit up = rays.Trace({origin, 0}, {0, 0, 1});
    ASSERT_EQ(up.fate, RayFate::kHit);
    EXPECT_EQ(flat.triangles[up.triangle].receiver, 1u);
    EXPECT_NEAR(up.distance, 1e-6, 1e-7);
    EXPECT_EQ(rays.Trace({origin, 0}, {0, 0, -1}).fate, RayFate::kEscapedDown);
}

TEST(RayScene, WrapsAroundAPeriodicTile) {
    // A plate overhanging the tile [0, 1]² on the +x side, at z = 1.
    const auto plate = Quad({0.8, 0.4, 1}, {1.2, 0.4, 1}, {1.2, 0.6, 1}, {0.8, 0.6, 1});
    const FlatScene flat = Plates({plate, Quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0})});
    PeriodicDomain tile{0, 0, 1, 1};
    tile.xMin -= flat.origin.x, tile.xMax -= flat.origin.x;
    tile.yMin -= flat.origin.y, tile.yMax -= flat.origin.y;
    const RayScene rays(flat, tile);
    // Straight down at x = 0.1: the overhang of the left neighbour's copy is there.
    const RayHit down = rays.Trace({flat.ToLocal({0.1, 0.5, 2})}, {0, 0, -1});
    ASSERT_EQ(down.fate, RayFate::kHit);
    EXPECT_EQ(flat.triangles[down.triangle].receiver, 0u);
    // Slanting out of the tile through x = 0 and in again from x = 1, ten tiles away.
    const glm::dvec3 d = glm::normalize(glm::dvec3(-10.0, 0.0, -1.0));
    const RayHit far = rays.Trace({flat.ToLocal({0.9, 0.5, 2})}, d);
    ASSERT_EQ(far.fate, RayFate::kHit);
    EXPECT_EQ(flat.triangles[far.triangle].receiver, 0u);
    EXPECT_NEAR(far.distance, std::sqrt(101.0), 1e-4);
    // Up and out of the canopy: the sky.
    EXPECT_EQ(rays.Trace({flat.ToLocal({0.5, 0.5, 0.5})}, glm::normalize(glm::dvec3(3, 1, 1))).fate,
              RayFate::kEscapedUp);
    EXPECT_FALSE(
        rays.Occluded({flat.ToLocal({0.5, 0.1, 0.5})}, glm::normalize(glm::dvec3(0, 1, 0.1))));
}

}  // namespace
}  // namespace leaflux
