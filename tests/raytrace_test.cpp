#include "solver/raytrace/raytrace.h"

#include <gtest/gtest.h>

#include "solver/generate/generator.h"
#include "solver/util/sampling.h"
#include "tests/random_rays.h"
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

// Only the group's triangles block: three plates stacked at z = 0, 1 and 2, each of two
// triangles; a ray up from below the first passes the plates outside the group.
TEST(RayScene, ASelfShadowQuerySeesOnlyItsGroup) {
    const FlatScene flat = Plates({Rectangle(1, 1, 0), Rectangle(1, 1, 1), Rectangle(1, 1, 2)});
    const RayScene rays(flat, std::nullopt);
    const std::vector<std::uint32_t> rank = {0, 1, 2, 3, 4, 5};  // triangle t at place t
    const RayStart below{flat.ToLocal({0.1, 0.2, -1})};
    const RayScene::Group middle{rank.data(), 2, 4}, top{rank.data(), 4, 6},
        none{rank.data(), 0, 0};
    EXPECT_TRUE(rays.OccludedByGroup(below, {0, 0, 1}, 10.0, middle));
    EXPECT_TRUE(rays.OccludedByGroup(below, {0, 0, 1}, 10.0, top));
    EXPECT_FALSE(rays.OccludedByGroup(below, {0, 0, 1}, 2.5, top));  // ends short of it
    EXPECT_FALSE(rays.OccludedByGroup(below, {0, 0, 1}, 10.0, none));
    // Leaving a triangle of the group, the ray does not see that triangle.
    const Triangle& start = flat.triangles[2];
    const RayStart onMiddle{(start.a + start.b + start.c) / 3.0, 2};
    EXPECT_FALSE(rays.OccludedByGroup(onMiddle, {0, 0, 1}, 10.0, middle));
    EXPECT_TRUE(rays.OccludedByGroup(onMiddle, {0, 0, 1}, 10.0, top));
}

// The first triangles count but the ranges skipped (a closed instance's own organs, which
// its light already passed): three plates stacked at z = 0, 1 and 2, two triangles each.
TEST(RayScene, AnOcclusionQueryPassesTheTrianglesItSkips) {
    const FlatScene flat = Plates({Rectangle(1, 1, 0), Rectangle(1, 1, 1), Rectangle(1, 1, 2)});
    const RayScene rays(flat, std::nullopt);
    const RayStart below{flat.ToLocal({0.1, 0.2, -1})};
    const glm::dvec3 up{0, 0, 1};
    const RayScene::TriangleRanges first{{0, 2}}, lower{{0, 4}}, apart{{0, 2}, {4, 6}}, all{{0, 6}};
    EXPECT_TRUE(rays.OccludedByFirst(below, up, 10.0, 6, &first));   // the second plate
    EXPECT_TRUE(rays.OccludedByFirst(below, up, 10.0, 6, &lower));   // the third
    EXPECT_FALSE(rays.OccludedByFirst(below, up, 10.0, 4, &lower));  // beyond the first 4
    EXPECT_TRUE(rays.OccludedByFirst(below, up, 10.0, 6, &apart));   // the middle one
    EXPECT_FALSE(rays.OccludedByFirst(below, up, 10.0, 6, &all));
    EXPECT_FALSE(rays.OccludedByFirst(below, up, 1.5, 6, &first));  // ends short of the second
    for (std::uint32_t t = 0; t < 8; ++t)
        EXPECT_EQ(RayScene::InRanges(apart, t), t < 2 || (t >= 4 && t < 6)) << t;
}

// Ranges in any order, overlapping or touching, merge into the sorted, disjoint ranges
// of the same triangles.
TEST(RayScene, RangesMergeIntoTheSameTrianglesSortedAndDisjoint) {
    const RayScene::TriangleRanges ranges{{7, 10}, {0, 2}, {5, 8}, {2, 3}, {12, 13}, {8, 9}};
    const RayScene::TriangleRanges merged = RayScene::Merged(ranges);
    EXPECT_EQ(merged, (RayScene::TriangleRanges{{0, 3}, {5, 10}, {12, 13}}));
    for (std::uint32_t t = 0; t < 15; ++t) {
        bool in = false;
        for (const auto& range : ranges) in = in || (t >= range[0] && t < range[1]);
        EXPECT_EQ(RayScene::InRanges(merged, t), in) << t;
    }
    EXPECT_TRUE(RayScene::Merged({}).empty());
}

TEST(RayScene, OccludedAmongMeetsOnlyTheTrianglesListed) {
    // Three plates stacked 1 m apart, two triangles each: a ray up from below meets the
    // listed ones alone, within its length; the corners are the plates'.
    const FlatScene flat = Plates({Rectangle(1, 1, 0), Rectangle(1, 1, 1), Rectangle(1, 1, 2)});
    const RayScene rays(flat, std::nullopt);
    const RayStart below{flat.ToLocal({0.1, 0.2, -1})};
    const glm::dvec3 up{0, 0, 1};
    const RayScene::TriangleRanges top{{4, 6}}, none{{6, 6}};
    EXPECT_TRUE(rays.OccludedAmong(below, up, 10.0, top));
    EXPECT_FALSE(rays.OccludedAmong(below, up, 2.5, top));  // ends short of the top plate
    EXPECT_FALSE(rays.OccludedAmong(below, up, 10.0, none));
    // From a triangle of the listed ones, that one is left out.
    const RayStart onTop{flat.ToLocal({0.1, 0.2, 2}), 4};
    EXPECT_FALSE(rays.OccludedAmong(onTop, up, 10.0, top));
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const std::array<glm::dvec3, 3> corners = rays.Corners(t);
        const Triangle& tri = flat.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3& expected = k == 0 ? tri.a : k == 1 ? tri.b : tri.c;
            EXPECT_NEAR(glm::length(corners[k] - expected), 0.0, 1e-6) << t << ' ' << k;
        }
    }
}

// Six plates 1 µm to 0.3 m apart, shifted sideways.
FlatScene SteppedPlates() {
    std::vector<std::shared_ptr<const Mesh>> plates;
    for (int k = 0; k < 6; ++k) {
        const double x = 0.3 * k, z = k == 1 ? 1e-6 : 0.3 * k;
        plates.push_back(Quad({x, 0, z}, {x + 1, 0, z}, {x + 1, 1, z}, {x, 1, z}));
    }
    return Plates(plates);
}

TEST(RayScene, TracesRaysOfOneDirectionTogetherAsOneByOne) {
    // Rays leave every triangle (and points off the surfaces) towards one sun, some
    // blocked, some not.
    const FlatScene flat = SteppedPlates();
    const RayScene rays(flat, std::nullopt);
    const glm::dvec3 sun = glm::normalize(glm::dvec3(0.4, 0.1, 1.0));
    std::vector<RayStart> starts;
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const Triangle& tri = flat.triangles[t];
        for (const glm::dvec3& w : {glm::dvec3(1, 1, 1) / 3.0, glm::dvec3(0.8, 0.1, 0.1)}) {
            starts.push_back({w.x * tri.a + w.y * tri.b + w.z * tri.c, t});
        }
        starts.push_back({(tri.a + tri.b + tri.c) / 3.0 - 0.01 * sun});
    }
    std::vector<std::uint8_t> together;
    rays.Occluded(starts, sun, together);
    ASSERT_EQ(together.size(), starts.size());
    int blocked = 0;
    for (std::size_t i = 0; i < starts.size(); ++i) {
        EXPECT_EQ(together[i] != 0, rays.Occluded(starts[i], sun)) << "ray " << i;
        blocked += together[i];
    }
    EXPECT_GT(blocked, 0);
    EXPECT_LT(blocked, static_cast<int>(starts.size()));
}

TEST(RayScene, FindsTheFirstHitsOfRaysTracedTogetherAsOneByOne) {
    // Rays leave every triangle (and points above the plates) in directions all round,
    // some meeting a plate, some escaping.
    const FlatScene flat = SteppedPlates();
    const RayScene rays(flat, std::nullopt);
    Random random(7);
    std::vector<RayStart> starts;
    std::vector<glm::dvec3> directions;
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const Triangle& tri = flat.triangles[t];
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 w = UniformTriangle(random.Uniform(), random.Uniform());
            starts.push_back({w.x * tri.a + w.y * tri.b + w.z * tri.c, t});
            directions.push_back(UniformSphere(random.Uniform(), random.Uniform()));
        }
        starts.push_back({(tri.a + tri.b + tri.c) / 3.0 + glm::dvec3(0, 0, 0.05)});
        directions.push_back(glm::dvec3(0, 0, -1));
    }
    std::vector<RayHit> together;
    rays.Trace(starts, directions, together);
    ASSERT_EQ(together.size(), starts.size());
    int hits = 0;
    for (std::size_t i = 0; i < starts.size(); ++i) {
        const RayHit one = rays.Trace(starts[i], directions[i]);
        EXPECT_EQ(together[i].fate, one.fate) << "ray " << i;
        EXPECT_EQ(together[i].triangle, one.triangle) << "ray " << i;
        EXPECT_EQ(together[i].distance, one.distance) << "ray " << i;
        EXPECT_EQ(together[i].next.origin, one.next.origin) << "ray " << i;
        hits += one.fate == RayFate::kHit;
    }
    EXPECT_GT(hits, 0);
    EXPECT_LT(hits, static_cast<int>(starts.size()));
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

TEST(RayScene, TrianglesPlacedStraightInTraceAsTheFlatScenes) {
    // A tree of placed frames over a ground: the triangles written straight into the engine
    // from the scene (the instanced solver's shadows), in the default hierarchy and in the
    // compact one, against the flat scene's, ray by ray, the organs alone too
    // (OccludedByFirst), and the receivers without triangles against Flatten's.
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.2)}});
    TreeParameters tree;
    tree.leafCount = 200;
    AddTree(scene, tree, {40.0, -7.0, 0.0});
    scene.environment.push_back({"ground", Rectangle(6.0, 6.0, 0.0), "stem"});
    // A ground under the tree, and a wall beside it.
    scene.environment.push_back(
        {"ground under it", Quad({34, -13, 0}, {46, -13, 0}, {46, -1, 0}, {34, -1, 0}), "stem"});
    scene.environment.push_back(
        {"wall", Quad({42, -13, 0}, {42, -1, 0}, {42, -1, 6}, {42, -13, 6}), "stem"});
    scene.Validate();
    const FlatScene flat = Flatten(scene);
    const FlatScene receivers = ReceiversOf(scene);
    ASSERT_TRUE(receivers.triangles.empty());
    ASSERT_EQ(receivers.receivers.size(), flat.receivers.size());
    std::uint32_t organTriangles = 0;
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const Receiver &a = receivers.receivers[r], &b = flat.receivers[r];
        EXPECT_EQ(a.kind, b.kind);
        EXPECT_EQ(a.declared, b.declared);
        EXPECT_EQ(a.firstTriangle, b.firstTriangle);
        EXPECT_EQ(a.triangleCount, b.triangleCount);
        EXPECT_EQ(a.areaM2, b.areaM2);
        if (b.kind == ReceiverKind::kOrgan) organTriangles += b.triangleCount;
    }
    EXPECT_EQ(receivers.origin, flat.origin);
    EXPECT_EQ(receivers.boundsMin, flat.boundsMin);
    EXPECT_EQ(receivers.boundsMax, flat.boundsMax);
    ASSERT_LT(organTriangles, flat.triangles.size());  // the ground is not among them

    // Each vertex placed once and each triangle as its three: the flat scene's corners.
    std::size_t vertices = 0;
    for (const Receiver& r : receivers.receivers)
        vertices += ReceiverMesh(scene, r).positions.size();
    EXPECT_LT(vertices, 3 * flat.triangles.size());  // fewer than the corners one by one
    std::vector<float> xyz(3 * vertices);
    std::vector<std::uint32_t> indices(3 * flat.triangles.size());
    PlaceVertices(scene, receivers, xyz.data(), indices.data());
    int differing = 0;
    for (std::size_t t = 0; t < flat.triangles.size(); ++t) {
        const Triangle& tri = flat.triangles[t];
        const glm::dvec3 corners[] = {tri.a, tri.b, tri.c};
        for (int k = 0; k < 3; ++k) {
            const float* vertex = &xyz[3 * static_cast<std::size_t>(indices[3 * t + k])];
            for (int axis = 0; axis < 3; ++axis)
                differing += vertex[axis] != static_cast<float>(corners[k][axis]);
        }
    }
    EXPECT_EQ(differing, 0);

    const RayScene whole(flat, std::nullopt);
    const std::unique_ptr<RayScene> placed = SceneRays(scene, receivers);
    const std::unique_ptr<RayScene> compact = SceneRays(scene, receivers, true);
    Random random(7);
    int hits = 0, blocked = 0, byGround = 0;  // by the organs, and by the ground or wall alone
    for (int i = 0; i < 4000; ++i) {
        // From a point of an organ triangle, or from a point in the crown, any way.
        const auto [start, direction] = RandomRay(random, flat, organTriangles, i % 2 == 1);
        const bool occluded = placed->Occluded(start, direction);
        EXPECT_EQ(occluded, whole.Occluded(start, direction)) << "ray " << i;
        const bool byOrgans = placed->OccludedByFirst(start, direction, INFINITY, organTriangles);
        EXPECT_EQ(byOrgans, whole.OccludedByFirst(start, direction, INFINITY, organTriangles))
            << "ray " << i;
        blocked += byOrgans;
        byGround += occluded && !byOrgans;
        const RayHit hit = placed->Trace(start, direction);
        hits += hit.fate == RayFate::kHit;
        const RayHit first = whole.Trace(start, direction);
        EXPECT_EQ(hit.fate, first.fate) << "ray " << i;
        if (first.fate == RayFate::kHit) {
            EXPECT_EQ(hit.triangle, first.triangle) << "ray " << i;
            EXPECT_EQ(hit.distance, first.distance) << "ray " << i;
        }
        // The compact hierarchy holds the same triangles (--shadows geometry-compact).
        EXPECT_EQ(compact->Occluded(start, direction), occluded) << "ray " << i;
        EXPECT_EQ(compact->OccludedByFirst(start, direction, INFINITY, organTriangles), byOrgans)
            << "ray " << i;
        const RayHit packed = compact->Trace(start, direction);
        EXPECT_EQ(packed.fate, hit.fate) << "ray " << i;
        if (hit.fate == RayFate::kHit) {
            EXPECT_EQ(packed.triangle, hit.triangle) << "ray " << i;
            EXPECT_EQ(packed.distance, hit.distance) << "ray " << i;
        }
    }
    EXPECT_GT(byGround, 100);  // the ground and the wall are in the engine
    EXPECT_GT(blocked, 100);
    EXPECT_LT(blocked, 3900);
    EXPECT_EQ(hits, blocked + byGround);
}

}  // namespace
}  // namespace leaflux
