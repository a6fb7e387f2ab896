// Where a held closed instance's light leaves from along a line (EmittersAlong): its organs'
// density is constant in each cell of its AreaGrid, so the integral along a line is the sum
// of the pieces of the line in each cell times the cell's density, in closed form.
#include "solver/radiosity/closed_exchange.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/util/box.h"

namespace leaflux {
namespace {

constexpr double kSide = 6.0;  // a box of 6 m: cells of 1 m
constexpr double kVolume = kSide * kSide * kSide;

ClosedNode Box(std::shared_ptr<const AreaGrid> grid) {
    ClosedNode node;
    node.boxMin = glm::dvec3(0.0);
    node.boxMax = glm::dvec3(kSide);
    node.organArea = std::move(grid);
    return node;
}

// The part of the line x + t ω inside [lo, hi], t ≥ 0.
BoxSpan Inside(const glm::dvec3& x, const glm::dvec3& omega, const glm::dvec3& lo,
               const glm::dvec3& hi) {
    BoxSpan span = LineThroughBox(x, omega, lo, hi);
    span.enter = std::max(span.enter, 0.0);
    return span;
}

TEST(EmittersAlong, WithoutAGridTheLightLeavesEvenlyFromTheBox) {
    const ClosedNode box = Box(nullptr);
    const Emitters e =
        EmittersAlong(box, glm::dvec3(1.0), glm::normalize(glm::dvec3(1, 2, 3)), 0.5, 2.5, kVolume);
    EXPECT_DOUBLE_EQ(e.integral, 2.0 / kVolume);
    EXPECT_DOUBLE_EQ(e.distance, 1.5);
}

TEST(EmittersAlong, AnEvenGridGivesTheLengthOverTheVolume) {
    auto grid = std::make_shared<AreaGrid>();
    grid->share.fill(1.0f / AreaGrid::kCount);
    const ClosedNode box = Box(grid);
    // Oblique, every component's sign, from outside the box and from inside it. The shares
    // are floats: 1/216 to a relative 3e-8, the bound 1e-6.
    for (const glm::dvec3& omega : {glm::dvec3(0.3, 0.5, 0.8), glm::dvec3(-0.7, 0.2, -0.4),
                                    glm::dvec3(0.0, -1.0, 0.2), glm::dvec3(0.0, 0.0, 1.0)}) {
        const glm::dvec3 along = glm::normalize(omega);
        for (const glm::dvec3& x : {glm::dvec3(3.1, 2.7, 2.9), glm::dvec3(0.4, 5.5, 1.3)}) {
            const BoxSpan span = Inside(x, along, box.boxMin, box.boxMax);
            ASSERT_TRUE(span.Meets());
            const Emitters e = EmittersAlong(box, x, along, span.enter, span.exit, kVolume);
            const double length = span.exit - span.enter;
            EXPECT_NEAR(e.integral, length / kVolume, 1e-6 * length / kVolume);
            EXPECT_NEAR(e.distance, span.enter + 0.5 * length, 1e-6 * kSide);
        }
    }
}

TEST(EmittersAlong, OneCellsOrgansGiveItsChordTimesItsDensity) {
    // Every organ in the cell [2,3] × [3,4] × [1,2]; a line through it from a corner.
    auto grid = std::make_shared<AreaGrid>();
    const glm::ivec3 cell(2, 3, 1);
    grid->share[AreaGrid::Index(cell.x, cell.y, cell.z)] = 1.0f;
    const ClosedNode box = Box(grid);
    const glm::dvec3 lo(cell), hi = lo + 1.0;
    for (const glm::dvec3& x : {glm::dvec3(0.1, 0.5, 0.2), glm::dvec3(5.9, 5.8, 4.7)}) {
        const glm::dvec3 along = glm::normalize(glm::dvec3(2.4, 3.6, 1.3) - x);
        const BoxSpan whole = Inside(x, along, box.boxMin, box.boxMax);
        const BoxSpan chord = Inside(x, along, lo, hi);
        ASSERT_TRUE(chord.Meets());
        const Emitters e = EmittersAlong(box, x, along, whole.enter, whole.exit, kVolume);
        // The cell holds all the area in 1/216 of the volume.
        const double density = AreaGrid::kCount / kVolume;
        EXPECT_NEAR(e.integral, density * (chord.exit - chord.enter), 1e-9);
        EXPECT_NEAR(e.distance, 0.5 * (chord.enter + chord.exit), 1e-9);
        // Stopped before the cell, the line meets none of the organs.
        EXPECT_NEAR(EmittersAlong(box, x, along, whole.enter, chord.enter, kVolume).integral, 0.0,
                    1e-9);
    }
}

}  // namespace
}  // namespace leaflux
