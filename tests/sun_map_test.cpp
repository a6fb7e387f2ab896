#include "solver/raytrace/sun_map.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/util/sampling.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

FlatScene Leaves(const std::vector<std::shared_ptr<const Mesh>>& meshes) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    NodeId id = 1;
    for (const auto& mesh : meshes) {
        scene.nodes.push_back(OrganNode(id, "leaf" + std::to_string(id), mesh, "black"));
        ++id;
    }
    scene.Validate();
    return Flatten(scene);
}

// A receiver's share of its area across the light that the sun reaches: its triangles'
// lit shares by their areas across the light.
double Lit(const FlatScene& flat, const SunMap& map, std::uint32_t receiver) {
    double lit = 0.0, area = 0.0;
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const Triangle& triangle = flat.triangles[t];
        if (triangle.receiver != receiver) continue;
        const double across = triangle.areaM2 * std::abs(glm::dot(triangle.normal, map.Toward()));
        lit += across * map.Lit(t), area += across;
    }
    return lit / area;
}

// A 10 cm leaf at z = 0 and another 5 cm above it, shifted by 10 cm towards a sun 45°
// from the zenith: its shadow falls on the near half of the lower leaf. The pixels that a
// straight edge across the map can give to the wrong side are at most its length over
// the pixel, each a pixel's area: the tolerance is the lengths of the lower leaf's outline
// and of the shadow's edge across it, across the light, times the pixel, over its area
// across the light. `upperAsked` false: the upper leaf's light is not asked for (SunMap's
// `wanted`), yet it casts its shadow all the same.
void ExpectHalfLit(double angularRadiusDeg, bool upperAsked = true) {
    const FlatScene flat = Leaves(
        {Quad({-0.05, -0.05, 0}, {0.05, -0.05, 0}, {0.05, 0.05, 0}, {-0.05, 0.05, 0}),
         Quad({0.05, -0.05, 0.05}, {0.15, -0.05, 0.05}, {0.15, 0.05, 0.05}, {0.05, 0.05, 0.05})});
    const RayScene rays(flat, std::nullopt);
    const glm::dvec3 toward = glm::normalize(glm::dvec3(1.0, 0.0, 1.0));
    const double cosRadius = std::cos(glm::radians(angularRadiusDeg));
    const std::vector<std::uint8_t> asked = {1, 1, upperAsked, upperAsked};
    const SunMap map(rays, 4, 4, toward, cosRadius, SunMap::kPixelsPerTriangle, asked);
    const double across = 0.01 * toward.z;
    const double outline = 2.0 * 0.1 * toward.z + 2.0 * 0.1, edge = 0.1;
    // A sun of some radius blurs the edge over 5 cm × tan(radius) on each side, evenly
    // over the disc; its directions' mean shifts the edge by at most that.
    const double blur = 0.05 * std::tan(glm::radians(angularRadiusDeg)) * edge / across;
    const double tolerance = (outline + edge) * map.PixelM() / across + blur;
    EXPECT_NEAR(Lit(flat, map, 0), 0.5, tolerance);
    if (upperAsked) {
        EXPECT_NEAR(Lit(flat, map, 1), 1.0, outline * map.PixelM() / across);
    } else {
        EXPECT_EQ(map.Lit(2), -1.0);
        EXPECT_EQ(map.Lit(3), -1.0);
    }
}

TEST(SunMap, ALeafHalfInAnothersShadowIsHalfLit) { ExpectHalfLit(0.0); }

TEST(SunMap, ALeafIsShadedByOneWhoseLightIsNotAskedFor) { ExpectHalfLit(0.0, false); }

TEST(SunMap, ASunsDiscBlursTheShadowsEdgeWithoutMovingIt) { ExpectHalfLit(0.267); }

// 300 random leaves in a 0.5 m box, 1 m up.
FlatScene RandomLeaves(Random& random) {
    std::vector<std::shared_ptr<const Mesh>> meshes;
    for (int i = 0; i < 300; ++i) {
        const glm::dvec3 centre(random.Uniform() * 0.5, random.Uniform() * 0.5,
                                1.0 + random.Uniform() * 0.5);
        auto mesh = std::make_shared<Mesh>();
        for (int k = 0; k < 3; ++k) {
            mesh->positions.push_back(centre + 0.1 * glm::dvec3(random.Uniform() - 0.5,
                                                                random.Uniform() - 0.5,
                                                                random.Uniform() - 0.5));
        }
        mesh->triangles = {{0, 1, 2}};
        meshes.push_back(std::move(mesh));
    }
    return Leaves(meshes);
}

// Drawn a few tiles at a time (what a plantation's millions of triangles are), the map is
// the one drawn at once, to the bit, for a point sun and a disc.
TEST(SunMap, DrawnInRunsOfTilesItIsTheMapDrawnAtOnce) {
    Random random(StreamSeed(0x5A9, 2));
    const FlatScene flat = RandomLeaves(random);
    const RayScene rays(flat, std::nullopt);
    const glm::dvec3 toward = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    const auto count = static_cast<std::uint32_t>(flat.triangles.size());
    for (const double cosRadius : {1.0, std::cos(glm::radians(0.267))}) {
        const SunMap once(rays, count, count, toward, cosRadius);
        const SunMap runs(rays, count, count, toward, cosRadius, SunMap::kPixelsPerTriangle, {},
                          64);
        int lit = 0;
        for (std::uint32_t t = 0; t < count; ++t) {
            EXPECT_EQ(runs.Lit(t), once.Lit(t)) << t;
            EXPECT_EQ(runs.Tied(t), once.Tied(t)) << t;
            lit += once.Lit(t) > 0.0 ? 1 : 0;
        }
        EXPECT_GT(lit, static_cast<int>(count) / 4);
    }
}

// The light the organs stop is what a plane behind them, across the light, misses: the
// map's lit shares times the organs' areas across the light against rays cast towards the
// sun from a jittered grid over that plane, 300 random leaves in a 0.5 m box. Within 4.6
// standard errors of the grid's estimate (at most that of as many independent rays).
TEST(SunMap, TheOrgansStopTheLightTheirShadowLacks) {
    Random random(StreamSeed(0x5A9, 1));
    const FlatScene flat = RandomLeaves(random);
    const RayScene rays(flat, std::nullopt);
    const glm::dvec3 toward = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    const auto count = static_cast<std::uint32_t>(flat.triangles.size());
    const SunMap map(rays, count, count, toward, 1.0);
    // Crossing leaves share the pixels along the lines they cross in (Tied): few.
    double stopped = 0.0;
    int tied = 0;
    for (std::uint32_t t = 0; t < count; ++t) {
        const Triangle& triangle = flat.triangles[t];
        ASSERT_GE(map.Lit(t), 0.0);
        stopped += map.Lit(t) * triangle.areaM2 * std::abs(glm::dot(triangle.normal, toward));
        tied += map.Tied(t) ? 1 : 0;
    }
    EXPECT_LT(tied, static_cast<int>(count) / 4);
    // A square across the light, 3 m below the box along it, wide enough for its shadow.
    const glm::dvec3 u = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), toward));
    const glm::dvec3 v = glm::cross(toward, u);
    const glm::dvec3 centre = flat.ToLocal({0.25, 0.25, 1.25}) - 3.0 * toward;
    constexpr int kGrid = 400;
    constexpr double kSide = 1.1;
    std::int64_t blocked = 0;
    for (int i = 0; i < kGrid; ++i) {
        for (int j = 0; j < kGrid; ++j) {
            const glm::dvec3 x = centre + kSide * ((i + random.Uniform()) / kGrid - 0.5) * u +
                                 kSide * ((j + random.Uniform()) / kGrid - 0.5) * v;
            blocked += rays.Occluded({x}, toward) ? 1 : 0;
        }
    }
    const double n = static_cast<double>(kGrid) * kGrid, f = blocked / n;
    const double shadow = f * kSide * kSide;
    EXPECT_NEAR(stopped, shadow, 4.6 * std::sqrt(f * (1.0 - f) / n) * kSide * kSide);
    EXPECT_GT(f, 0.05);  // the grid holds the shadow: the test can fail
    EXPECT_LT(f, 0.95);
}

}  // namespace
}  // namespace leaflux
