#include "solver/directions.h"

#include <gtest/gtest.h>

#include "solver/sampling.h"

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

}  // namespace
}  // namespace leaflux
