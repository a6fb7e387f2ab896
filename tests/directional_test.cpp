// Directional functions on the tetrahedral sets (Soler 2003 §4.2.2): interpolation,
// integrals and the coarser kinds obtained from a bi-directional function.
#include "solver/instancing/directional.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/util/sampling.h"

namespace leaflux {
namespace {

// The point where unit d crosses the plane of the face holding it: the interpolation is
// linear there, so an affine function of that point is reproduced exactly.
glm::dvec3 OnFacePlane(const DirectionSet& set, const glm::dvec3& d) {
    const DirectionSet::Interpolation at = set.Locate(d);
    const glm::dvec3 a = set.Direction(at.vertex[0]), b = set.Direction(at.vertex[1]),
                     c = set.Direction(at.vertex[2]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    return d * (glm::dot(n, a) / glm::dot(n, d));
}

TEST(SphereFunction, InterpolationReproducesAFunctionLinearOnEachFaceExactly) {
    const glm::dvec3 slope(0.3, -1.7, 2.1);
    const double offset = 0.8;
    for (int level = 0; level <= 4; ++level) {
        SphereFunction f(level, 2);
        const DirectionSet& set = f.Directions();
        for (int i = 0; i < set.Size(); ++i) {
            f.At(i, 0) = static_cast<float>(glm::dot(slope, set.Direction(i)) + offset);
            f.At(i, 1) = 5.0f;
        }
        Random random(level);
        double worst = 0.0;
        for (int k = 0; k < 2000; ++k) {
            const glm::dvec3 d = UniformSphere(random.Uniform(), random.Uniform());
            const double expected = glm::dot(slope, OnFacePlane(set, d)) + offset;
            worst = std::max(worst, std::abs(f.Value(d, 0) - expected));
            EXPECT_NEAR(f.Value(d, 1), 5.0, 5e-6);
        }
        // The values are floats: a few of their ulps at |f| ≤ 4.
        EXPECT_LT(worst, 4e-6) << "level " << level;
        // At a vertex, the value stored.
        for (int i = 0; i < set.Size(); ++i)
            EXPECT_NEAR(f.Value(set.Direction(i), 0), f.At(i, 0), 1e-6);
    }
}

TEST(SphereFunction, AConstantIntegratesToItsValueTimesFourPi) {
    for (int level = 0; level <= 4; ++level) {
        SphereFunction f(level, 1);
        for (int i = 0; i < f.Directions().Size(); ++i) f.At(i, 0) = 2.5f;
        EXPECT_NEAR(f.Integral(0), 2.5 * 4.0 * std::numbers::pi, 1e-5) << "level " << level;
    }
}

TEST(PhaseFunction, BiDirectionalInterpolationIsLinearOnBothSides) {
    const glm::dvec3 a(1.0, 0.5, -0.2), b(-0.4, 0.9, 1.3);
    PhaseFunction f(PhaseKind::kBiDirectional, 2, 1);
    const DirectionSet& set = f.Directions();
    const int n = set.Size();
    for (int i = 0; i < n; ++i)
        for (int o = 0; o < n; ++o)
            f.MutableValues()[i * n + o] = static_cast<float>(
                (glm::dot(a, set.Direction(i)) + 2.0) * (glm::dot(b, set.Direction(o)) + 3.0));
    Random random(7);
    for (int k = 0; k < 500; ++k) {
        const glm::dvec3 in = UniformSphere(random.Uniform(), random.Uniform());
        const glm::dvec3 out = UniformSphere(random.Uniform(), random.Uniform());
        const double expected =
            (glm::dot(a, OnFacePlane(set, in)) + 2.0) * (glm::dot(b, OnFacePlane(set, out)) + 3.0);
        EXPECT_NEAR(f.Value(0, in, out), expected, 2e-5 * std::abs(expected) + 1e-6);
    }
}

TEST(PhaseFunction, CoarserKindsKeepTheScatteredPower) {
    PhaseFunction f(PhaseKind::kBiDirectional, 2, 2);
    Random random(3);
    for (float& v : f.MutableValues()) v = static_cast<float>(random.Uniform());
    const PhaseFunction mono = f.Reduced(PhaseKind::kMonoDirectional);
    const PhaseFunction constant = f.Reduced(PhaseKind::kConstant);
    const DirectionSet& set = f.Directions();
    for (int band = 0; band < 2; ++band) {
        double mean = 0.0;
        for (int i = 0; i < set.Size(); ++i) {
            const glm::dvec3 in = set.Direction(i);
            const double power = f.ScatteredPower(band, in);
            EXPECT_NEAR(mono.ScatteredPower(band, in), power, 1e-5 * power);
            // Evenly in every direction.
            EXPECT_NEAR(mono.Value(band, in, -in), power / (4.0 * std::numbers::pi), 1e-6);
            mean += power * set.HatIntegralSr(i) / (4.0 * std::numbers::pi);
        }
        EXPECT_NEAR(constant.ScatteredPower(band, {0, 0, 1}), mean, 1e-5 * mean);
    }
    EXPECT_EQ(constant.Bytes(), 2 * sizeof(float));
    EXPECT_EQ(mono.Bytes(), 34 * 2 * sizeof(float));
}

TEST(PhaseFunction, ItsTableHoldsItsValueAtEveryPair) {
    PhaseFunction bi(PhaseKind::kBiDirectional, 2, 2);
    Random random(11);
    for (float& v : bi.MutableValues()) v = static_cast<float>(random.Uniform());
    std::vector<glm::dvec3> in(7), out(5);
    for (glm::dvec3& d : in) d = UniformSphere(random.Uniform(), random.Uniform());
    for (glm::dvec3& d : out) d = UniformSphere(random.Uniform(), random.Uniform());
    for (PhaseKind kind :
         {PhaseKind::kBiDirectional, PhaseKind::kMonoDirectional, PhaseKind::kConstant}) {
        const PhaseFunction f = bi.Reduced(kind);
        for (int band = 0; band < 2; ++band) {
            std::vector<double> table(in.size() * out.size());
            f.Table(band, in, out, table.data());
            for (std::size_t o = 0; o < out.size(); ++o) {
                for (std::size_t i = 0; i < in.size(); ++i)
                    EXPECT_NEAR(table[o * in.size() + i], f.Value(band, in[i], out[o]), 1e-12)
                        << PhaseKindName(kind) << " band " << band;
            }
        }
    }
}

TEST(PhaseFunction, StoredValuesOfTheWrongCountAreRefused) {
    EXPECT_THROW(PhaseFunction::FromValues(PhaseKind::kBiDirectional, 1, 1, std::vector<float>(99)),
                 std::invalid_argument);
    EXPECT_THROW(SphereFunction::FromValues(5, 1, std::vector<float>(4)), std::invalid_argument);
    EXPECT_NO_THROW(
        PhaseFunction::FromValues(PhaseKind::kMonoDirectional, 1, 2, std::vector<float>(20)));
}

}  // namespace
}  // namespace leaflux
