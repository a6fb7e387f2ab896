#include "solver/util/directions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "solver/util/sampling.h"

namespace leaflux {
namespace {

TEST(DirectionSet, HasTheTetrahedralCounts) {
    const int counts[] = {4, 10, 34, 130, 514};
    for (int level = 0; level <= 4; ++level) {
        EXPECT_EQ(DirectionSet::OfLevel(level).Size(), counts[level]);
        EXPECT_EQ(DirectionSet::LevelWithCount(counts[level]), level);
    }
    EXPECT_EQ(DirectionSet::LevelWithCount(46), -1);
}

TEST(DirectionSet, SolidAnglesCoverTheSphere) {
    for (int level = 0; level <= 4; ++level) {
        const DirectionSet& set = DirectionSet::OfLevel(level);
        double total = 0.0;
        for (int i = 0; i < set.Size(); ++i) {
            EXPECT_GT(set.SolidAngleSr(i), 0.0);
            total += set.SolidAngleSr(i);
        }
        EXPECT_NEAR(total, 4.0 * glm::pi<double>(), 1e-9);
    }
}

// A function known at the directions and interpolated integrates to Σ f_i HatIntegralSr(i):
// checked against the interpolant integrated by stratified Monte Carlo (400,000 directions
// in 40,000 strata, which agree with the sum to about 1e-5 of the integral).
TEST(DirectionSet, HatIntegralsIntegrateTheInterpolant) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    for (int level = 0; level <= 4; ++level) {
        const DirectionSet& set = DirectionSet::OfLevel(level);
        double total = 0.0, formula = 0.0;
        for (int i = 0; i < set.Size(); ++i) {
            EXPECT_GT(set.HatIntegralSr(i), 0.0);
            total += set.HatIntegralSr(i);
            formula += std::abs(glm::dot(n, set.Direction(i))) * set.HatIntegralSr(i);
        }
        EXPECT_NEAR(total, 4.0 * glm::pi<double>(), 1e-9) << "level " << level;
        Random random(11);
        constexpr int kStrata = 200, kPerStratum = 10;
        double sampled = 0.0;
        for (int i = 0; i < kStrata; ++i) {
            for (int j = 0; j < kStrata; ++j) {
                for (int k = 0; k < kPerStratum; ++k) {
                    const auto w = set.Locate(UniformSphere((i + random.Uniform()) / kStrata,
                                                            (j + random.Uniform()) / kStrata));
                    for (int v = 0; v < 3; ++v)
                        sampled += w.weight[v] * std::abs(glm::dot(n, set.Direction(w.vertex[v])));
                }
            }
        }
        sampled *= 4.0 * glm::pi<double>() / (kStrata * kStrata * kPerStratum);
        EXPECT_NEAR(formula, sampled, 1e-4 * sampled) << "level " << level;
    }
}

TEST(DirectionSet, InterpolationReproducesLinearFunctionsAtVertices) {
    const DirectionSet& set = DirectionSet::OfLevel(3);
    for (int i = 0; i < set.Size(); ++i) {
        const auto located = set.Locate(set.Direction(i));
        double weightOfVertex = 0.0;
        for (int k = 0; k < 3; ++k) {
            if (located.vertex[k] == i) weightOfVertex += located.weight[k];
        }
        EXPECT_NEAR(weightOfVertex, 1.0, 1e-9) << "direction " << i;
    }
}

TEST(DirectionSet, EveryDirectionLiesInAFaceWithValidWeights) {
    const DirectionSet& set = DirectionSet::OfLevel(4);
    Random random(3);
    for (int i = 0; i < 20000; ++i) {
        const glm::dvec3 d = UniformSphere(random.Uniform(), random.Uniform());
        const auto located = set.Locate(d);
        double sum = 0.0;
        for (double w : located.weight) {
            EXPECT_GE(w, 0.0);
            sum += w;
        }
        EXPECT_NEAR(sum, 1.0, 1e-12);
        // The face is the one around d: its vertices are within one face size.
        for (int v : located.vertex) EXPECT_GT(glm::dot(set.Direction(v), d), 0.95);
    }
}

// Locate's face holds the direction: its unclamped barycentric weights (gnomonic) are all
// ≥ 0 and put the point back on d (the clamped weights Locate returns would pass
// EveryDirectionLiesInAFaceWithValidWeights from a neighbouring face too). At every level,
// for random directions and for those on the subdivision's edges, where rounding decides
// (the edges' midpoints), and at the faces' centres.
TEST(DirectionSet, LocateFindsTheFaceHoldingTheDirection) {
    Random random(11);
    std::vector<glm::dvec3> randomDirections;
    for (int i = 0; i < 20000; ++i)
        randomDirections.push_back(UniformSphere(random.Uniform(), random.Uniform()));
    for (int level = 0; level <= 4; ++level) {
        const DirectionSet& set = DirectionSet::OfLevel(level);
        std::vector<glm::dvec3> all = randomDirections;
        for (const auto& [a, b, c] : set.Faces()) {
            all.push_back(glm::normalize(set.Direction(a) + set.Direction(b)));
            all.push_back(glm::normalize(set.Direction(a) + set.Direction(b) + set.Direction(c)));
        }
        for (const glm::dvec3& d : all) {
            const auto located = set.Locate(d);
            const glm::dvec3 &a = set.Direction(located.vertex[0]),
                             &b = set.Direction(located.vertex[1]),
                             &c = set.Direction(located.vertex[2]);
            const glm::dvec3 w(glm::dot(glm::cross(b, c), d), glm::dot(glm::cross(c, a), d),
                               glm::dot(glm::cross(a, b), d));
            const double sum = w.x + w.y + w.z;
            ASSERT_GT(sum, 0.0);
            EXPECT_GE(glm::min(w.x, glm::min(w.y, w.z)), -1e-12 * sum)
                << "level " << level << " d " << d.x << ' ' << d.y << ' ' << d.z;
            const glm::dvec3 back = glm::normalize(w.x * a + w.y * b + w.z * c);
            EXPECT_NEAR(glm::distance(back, d), 0.0, 1e-12) << "level " << level;
        }
    }
}

// Angle is std::atan2 for a sine ≥ 0, to a few ulp: over every octant of the half-plane,
// at the bounds between its remainders' centres, near the axes and at extreme magnitudes.
TEST(Angle, IsTheArctangentOfTheHalfPlane) {
    Random random(7);
    double worst = 0.0;
    auto check = [&](double sine, double cosine) {
        const double want = std::atan2(sine, cosine), got = Angle(sine, cosine);
        worst = std::max(worst, want > 0.0 ? std::abs(got - want) / want : std::abs(got));
    };
    for (int i = 0; i < 200000; ++i) {
        const double angle = std::numbers::pi * random.Uniform();
        const double scale = std::ldexp(1.0, static_cast<int>(random.Uniform() * 400.0) - 200);
        check(scale * std::sin(angle), scale * std::cos(angle));
    }
    for (int k = 0; k <= 16; ++k) {
        for (double nudge : {1e-12, 0.0, -1e-12}) {
            const double angle = std::max(k * std::numbers::pi / 32.0 + nudge, 0.0);
            check(std::sin(angle), std::cos(angle));
            check(std::sin(angle), -std::cos(angle));
        }
    }
    for (double tiny : {1e-300, 1e-200, 1e-20, 1e-9}) {
        check(tiny, 1.0), check(tiny, -1.0), check(1.0, tiny), check(1.0, -tiny);
    }
    EXPECT_LT(worst, 4.0 * std::numeric_limits<double>::epsilon());
    EXPECT_EQ(Angle(0.0, 1.0), 0.0);
    EXPECT_EQ(Angle(0.0, -1.0), std::numbers::pi);
    EXPECT_EQ(Angle(1.0, 0.0), std::numbers::pi / 2.0);
}

}  // namespace
}  // namespace leaflux
