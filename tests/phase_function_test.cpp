// A structure's transmittance and phase function (Soler 2003 §4.2) against closed forms
// and physical laws: a single two-sided Lambertian leaf, energy closure per beam,
// reciprocity, the gap-fraction law of a leaf cloud, and invariance under rigid motion.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>

#include "solver/instancing/phase_photons.h"
#include "solver/instancing/phase_radiosity.h"
#include "solver/instancing/structure.h"
#include "solver/instancing/transmittance.h"
#include "solver/util/sampling.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using testing::Quad;
using testing::Rectangle;

// n square leaves of side `side`, centres uniform in the cube [0, edge]³, orientations
// uniform, under a plant node (id 1) whose frame is `placement`.
Scene LeafCloud(int n, double side, double edge, std::uint64_t seed, BandOptics optics,
                const glm::dmat4& contents = glm::dmat4(1.0)) {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {optics}}};
    Node plant;
    plant.id = 1;
    plant.Edit().type = NodeType::kPlant;
    scene.nodes.push_back(plant);
    Random random(seed);
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 centre(edge * random.Uniform(), edge * random.Uniform(),
                                edge * random.Uniform());
        const glm::dvec3 normal = UniformSphere(random.Uniform(), random.Uniform());
        glm::dvec3 t, b;
        Basis(normal, t, b);
        const double spin = 2.0 * std::numbers::pi * random.Uniform();
        const glm::dvec3 u = std::cos(spin) * t + std::sin(spin) * b, v = glm::cross(normal, u);
        const double h = side / 2;
        Node leaf = testing::OrganNode(2 + i, "leaf" + std::to_string(i),
                                       Quad(centre - h * u - h * v, centre + h * u - h * v,
                                            centre + h * u + h * v, centre - h * u + h * v),
                                       "leaf", 1);
        leaf.Edit().parentFromLocal = contents;
        scene.nodes.push_back(std::move(leaf));
    }
    return scene;
}

// ∫ hat_k(ω) g(ω) dω / ∫ hat_k for every direction k of the set, by a Fibonacci lattice
// of m points: the hat projection a photon estimate converges to.
template <class G>
std::vector<double> HatProjection(const DirectionSet& set, G g, int m = 400000) {
    std::vector<double> weighted(set.Size(), 0.0), weights(set.Size(), 0.0);
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int j = 0; j < m; ++j) {
        const double z = 1.0 - (2.0 * j + 1.0) / m, r = std::sqrt(1.0 - z * z);
        const glm::dvec3 d(r * std::cos(golden * j), r * std::sin(golden * j), z);
        const DirectionSet::Interpolation at = set.Locate(d);
        for (int k = 0; k < 3; ++k) {
            weighted[at.vertex[k]] += at.weight[k] * g(d);
            weights[at.vertex[k]] += at.weight[k];
        }
    }
    for (int k = 0; k < set.Size(); ++k) weighted[k] /= weights[k];
    return weighted;
}

// Photons on the 34 directions, in `replicates` groups for the standard errors.
PhotonOptions OnTheTetrahedron34(int photonsPerBeam, int replicates) {
    PhotonOptions options;
    options.level = 2;
    options.photonsPerBeam = photonsPerBeam;
    options.replicates = replicates;
    return options;
}

Scene SingleLeaf(double side, BandOptics optics) {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {optics}}};
    scene.nodes.push_back(testing::OrganNode(1, "leaf", Rectangle(side, side, 0.0), "leaf"));
    return scene;
}

TEST(PhaseFunction, ASingleTwoSidedLambertianLeafMatchesItsClosedForm) {
    // Upper side along +z. From a source on the side it faces, a leaf of area A sends
    // ρ A |cos θi| |cos θo| / π back to that side and τ A |cos θi| |cos θo| / π through.
    const double side = 0.1, area = side * side;
    const BandOptics optics{0.4, 0.3, 0.2, 0.1};  // ρ upper, ρ lower, τ upper→lower, lower→upper
    const Scene scene = SingleLeaf(side, optics);
    const StructureAlone leaf(scene, 1);
    PhotonOptions options = OnTheTetrahedron34(40000, 32);
    const PhaseEstimate estimate = PhaseFromPhotons(leaf, options);
    const DirectionSet& set = estimate.phase.Directions();
    const auto up = HatProjection(set, [](const glm::dvec3& d) { return std::max(0.0, d.z); });
    const auto down = HatProjection(set, [](const glm::dvec3& d) { return std::max(0.0, -d.z); });
    const int n = set.Size();
    int checked = 0;
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int o = 0; o < n; ++o) {
            // Lit from above: reflected up, transmitted down; lit from below, the converse.
            const double expected =
                area / std::numbers::pi *
                (up[i] * (optics.rhoUpper * up[o] + optics.tauUpperToLower * down[o]) +
                 down[i] * (optics.rhoLower * down[o] + optics.tauLowerToUpper * up[o]));
            const double value = estimate.phase.Values()[i * n + o];
            const double error = estimate.standardError.Values()[i * n + o];
            if (error > 0.0) worst = std::max(worst, std::abs(value - expected) / error);
            EXPECT_LE(std::abs(value - expected), 5.0 * error + 1e-4 * expected)
                << "i " << i << " o " << o;
            ++checked;
        }
    }
    std::printf("single leaf: %d values of f, worst %.2f standard errors from the closed form\n",
                checked, worst);
    // Its transmittance: what the leaf does not cover of the box's cross-section.
    TransmittanceOptions tau;
    tau.level = 3;
    tau.raysPerDirection = 8192;
    const TransmittanceEstimate t = ComputeTransmittance(leaf, tau);
    const DirectionSet& tauSet = t.tau.Directions();
    for (int i = 0; i < tauSet.Size(); ++i) {
        const glm::dvec3 d = tauSet.Direction(i);
        const double expected = 1.0 - area * std::abs(d.z) / leaf.ProjectedArea(d);
        EXPECT_LE(std::abs(double(t.tau.At(i, 0)) - expected),
                  5.0 * double(t.standardError.At(i, 0)) + 1e-6)
            << "direction " << i;
    }
}

TEST(PhaseFunction, EveryBeamClosesScatteredPlusAbsorbedPlusTransmittedOnWhatEntered) {
    const Scene scene = LeafCloud(80, 0.06, 0.4, 11, {0.45, 0.35, 0.4, 0.4});
    const StructureAlone cloud(scene, 1);
    PhotonOptions options = OnTheTetrahedron34(20000, 32);
    const PhaseEstimate estimate = PhaseFromPhotons(cloud, options);
    double worst = 0.0;
    for (std::size_t i = 0; i < estimate.beams.size(); ++i) {
        const BeamBalance& beam = estimate.beams[i];
        EXPECT_NEAR(beam.interceptedW[0] + beam.transmittedW, beam.enteredW, 1e-12 * beam.enteredW);
        const double residual = beam.interceptedW[0] - beam.scatteredW[0] - beam.absorbedW[0];
        worst = std::max(worst, std::abs(residual) / beam.closureErrorW[0]);
        EXPECT_LE(std::abs(residual), 5.0 * beam.closureErrorW[0]) << "beam " << i;
        // The interpolated function integrates to the power the beam scattered.
        EXPECT_NEAR(estimate.phase.ScatteredPower(0, estimate.phase.Directions().Direction(i)),
                    beam.scatteredW[0], 1e-5 * beam.scatteredW[0]);
    }
    std::printf("energy closure: %zu beams, worst %.2f standard errors\n", estimate.beams.size(),
                worst);
}

// The mean of squared differences f(i, o) − f(o, i) over their standard errors: near 1
// when reciprocity holds, far above when it does not.
double ReciprocityStatistic(const PhaseEstimate& estimate, double& worst) {
    const int n = estimate.phase.Directions().Size();
    double sum = 0.0;
    int count = 0;
    worst = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int o = i + 1; o < n; ++o) {
            const double a = estimate.phase.Values()[i * n + o],
                         b = estimate.phase.Values()[o * n + i];
            const double ea = estimate.standardError.Values()[i * n + o],
                         eb = estimate.standardError.Values()[o * n + i];
            const double z = (a - b) / std::sqrt(ea * ea + eb * eb);
            sum += z * z;
            worst = std::max(worst, std::abs(z));
            ++count;
        }
    }
    return sum / count;
}

TEST(PhaseFunction, ReciprocityHoldsWithinTheStatedErrorAndTheTestSeesItBroken) {
    PhotonOptions options = OnTheTetrahedron34(20000, 32);
    // Reflectances may differ between the sides; reciprocity needs τ the same both ways.
    const Scene reciprocal = LeafCloud(60, 0.06, 0.3, 5, {0.45, 0.3, 0.35, 0.35});
    double worst = 0.0;
    const double statistic =
        ReciprocityStatistic(PhaseFromPhotons(StructureAlone(reciprocal, 1), options), worst);
    std::printf("reciprocity: mean squared deviation %.3f standard errors², worst %.2f\n",
                statistic, worst);
    EXPECT_LT(statistic, 1.3);
    EXPECT_LT(worst, 5.5);
    // Leaves that pass light one way only are not reciprocal: the statistic shows it.
    const Scene oneWay = LeafCloud(60, 0.06, 0.3, 5, {0.45, 0.3, 0.6, 0.05});
    const double broken =
        ReciprocityStatistic(PhaseFromPhotons(StructureAlone(oneWay, 1), options), worst);
    std::printf("one-way leaves: mean squared deviation %.3f\n", broken);
    EXPECT_GT(broken, 3.0);
}

// The chord of the line x + t d through the box [lo, hi].
double Chord(const glm::dvec3& x, const glm::dvec3& d, const glm::dvec3& lo, const glm::dvec3& hi) {
    double enter = -1e300, leave = 1e300;
    for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-15) {
            if (x[k] < lo[k] || x[k] > hi[k]) return 0.0;
            continue;
        }
        const double a = (lo[k] - x[k]) / d[k], b = (hi[k] - x[k]) / d[k];
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
    }
    return std::max(0.0, leave - enter);
}

TEST(Transmittance, ARandomLeafCloudFollowsTheGapFractionLaw) {
    // N leaves of area a, uniform in position and orientation in a cube of volume V: a
    // line with chord ℓ in the cube misses one leaf with probability 1 − G a ℓ / V, G = ½
    // for a uniform orientation, so τ(ω) is the mean over the lines of (1 − G a ℓ / V)^N.
    const int n = 20000;
    const double side = 0.01, edge = 1.0, a = side * side;
    const Scene scene = LeafCloud(n, side, edge, 3, {0.4, 0.4, 0.4, 0.4});
    const StructureAlone cloud(scene, 1);
    TransmittanceOptions options;
    options.level = 2;
    options.raysPerDirection = 16384;
    const TransmittanceEstimate t = ComputeTransmittance(cloud, options);
    const DirectionSet& set = t.tau.Directions();
    const glm::dvec3 lo = -cloud.Origin(), hi = glm::dvec3(edge) - cloud.Origin();
    double meanDifference = 0.0;
    for (int i = 0; i < set.Size(); ++i) {
        const glm::dvec3 d = set.Direction(i);
        Random random(100 + i);
        double law = 0.0;
        const int lines = 20000;
        for (int k = 0; k < lines; ++k) {
            const glm::dvec3 x =
                cloud.Entry(d, random.Uniform(), random.Uniform(), random.Uniform());
            law += std::pow(1.0 - 0.5 * a * Chord(x, d, lo, hi) / (edge * edge * edge), n);
        }
        law /= lines;
        const double measured = t.tau.At(i, 0);
        meanDifference += (measured - law) / set.Size();
        // Beyond the rays' error: the leaves at the cube's faces, which reach past it by
        // half a leaf (lines through the box but not the cube, chords cut short).
        EXPECT_NEAR(measured, law, 5.0 * double(t.standardError.At(i, 0)) + 0.01)
            << "direction " << i;
    }
    std::printf("gap fraction: mean τ − law %.4f over %d directions\n", meanDifference, set.Size());
    EXPECT_LT(std::abs(meanDifference), 0.005);
}

TEST(PhaseFunction, FunctionsAreInvariantUnderRigidMotion) {
    PhotonOptions options = OnTheTetrahedron34(10000, 16);
    TransmittanceOptions tauOptions;
    tauOptions.level = 2;
    const BandOptics optics{0.45, 0.3, 0.35, 0.35};
    // Where the structure stands does not matter: its functions are in its own frame.
    Scene placed = LeafCloud(40, 0.06, 0.3, 9, optics);
    const PhaseEstimate base = PhaseFromPhotons(StructureAlone(placed, 1), options);
    placed.nodes[0].Edit().parentFromLocal =
        glm::rotate(glm::translate(glm::dmat4(1.0), {3e3, -2e3, 40.0}), 0.7, {0.3, 0.2, 0.9});
    const PhaseEstimate moved = PhaseFromPhotons(StructureAlone(placed, 1), options);
    for (std::size_t k = 0; k < base.phase.Values().size(); ++k)
        EXPECT_NEAR(moved.phase.Values()[k], base.phase.Values()[k],
                    1e-4 * double(base.phase.Values()[k]) + 1e-12);
    // Contents turned by 120° about z, a symmetry of the direction sets, and the function
    // turned with them: the same function, within the photons' error.
    const glm::dmat4 turn = glm::rotate(glm::dmat4(1.0), 2.0 * std::numbers::pi / 3, {0, 0, 1});
    const Scene turned = LeafCloud(40, 0.06, 0.3, 9, optics, turn);
    const StructureAlone turnedAlone(turned, 1);
    const PhaseEstimate rotated = PhaseFromPhotons(turnedAlone, options);
    const StructureAlone alone(placed, 1);
    const TransmittanceEstimate tau = ComputeTransmittance(alone, tauOptions);
    const TransmittanceEstimate tauTurned = ComputeTransmittance(turnedAlone, tauOptions);
    const DirectionSet& set = base.phase.Directions();
    const int n = set.Size();
    std::vector<int> image(n);
    for (int i = 0; i < n; ++i) {
        image[i] = set.Nearest(glm::dmat3(turn) * set.Direction(i));
        ASSERT_GT(glm::dot(set.Direction(image[i]), glm::dmat3(turn) * set.Direction(i)),
                  1.0 - 1e-12);
    }
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int o = 0; o < n; ++o) {
            const std::size_t k = i * n + o, r = image[i] * n + image[o];
            const double ea = base.standardError.Values()[k],
                         eb = rotated.standardError.Values()[r];
            const double z = (double(base.phase.Values()[k]) - double(rotated.phase.Values()[r])) /
                             std::max(1e-30, std::sqrt(ea * ea + eb * eb));
            sum += z * z;
        }
        // τ is relative to the box, which is the contents' bounds along the frame's axes and
        // turns with them only approximately; the area the structure blocks, (1 − τ) times
        // the box's cross-section, is its own.
        const glm::dvec3 d = set.Direction(i), dTurned = set.Direction(image[i]);
        const double blocked = (1.0 - double(tau.tau.At(i, 0))) * alone.ProjectedArea(d);
        const double blockedTurned =
            (1.0 - double(tauTurned.tau.At(image[i], 0))) * turnedAlone.ProjectedArea(dTurned);
        EXPECT_NEAR(blocked, blockedTurned,
                    5.0 * std::hypot(double(tau.standardError.At(i, 0)) * alone.ProjectedArea(d),
                                     double(tauTurned.standardError.At(image[i], 0)) *
                                         turnedAlone.ProjectedArea(dTurned)))
            << "direction " << i;
    }
    std::printf("rotation: mean squared deviation %.3f standard errors²\n", sum / (n * n));
    EXPECT_LT(sum / (n * n), 1.3);
}

TEST(PhaseFromRadiosity, ASingleLeafIsItsClosedFormAtTheDirections) {
    const double side = 0.1, area = side * side;
    const BandOptics optics{0.4, 0.3, 0.2, 0.1};
    const Scene scene = SingleLeaf(side, optics);
    RadiosityPhaseOptions options;
    options.level = 2;
    const RadiosityPhase hr = PhaseFromRadiosity(StructureAlone(scene, 1), options);
    const DirectionSet& set = hr.phase.Directions();
    const int n = set.Size();
    for (int i = 0; i < n; ++i) {
        for (int o = 0; o < n; ++o) {
            const double zi = set.Direction(i).z, zo = set.Direction(o).z;
            const double lit = zi > 0 ? (zo > 0 ? optics.rhoUpper : optics.tauUpperToLower)
                                      : (zo < 0 ? optics.rhoLower : optics.tauLowerToUpper);
            const double expected = area * std::abs(zi) * std::abs(zo) * lit / std::numbers::pi;
            EXPECT_NEAR(hr.phase.Values()[i * n + o], expected, 1e-5 * expected + 1e-9)
                << "i " << i << " o " << o;
        }
    }
}

// 60 leaves whose τ is the same both ways, by radiosity on the 34 directions.
RadiosityPhase CloudByRadiosity(const StructureAlone& cloud) {
    RadiosityPhaseOptions options;
    options.level = 2;
    return PhaseFromRadiosity(cloud, options);
}
const Scene& ReciprocalCloud() {
    static const Scene cloud = LeafCloud(60, 0.06, 0.3, 5, {0.45, 0.3, 0.35, 0.35});
    return cloud;
}

TEST(PhaseFromRadiosity, AgreesWithPhotonsOnALeafCloud) {
    const StructureAlone cloud(ReciprocalCloud(), 1);
    const RadiosityPhase hr = CloudByRadiosity(cloud);
    PhotonOptions photonOptions = OnTheTetrahedron34(40000, 32);
    photonOptions.hatIncoming = false;
    const PhaseEstimate photons = PhaseFromPhotons(cloud, photonOptions);
    const DirectionSet& set = hr.phase.Directions();
    const int n = set.Size();
    double worst = 0.0, rms = 0.0, scale = 0.0, squares = 0.0;
    for (int i = 0; i < n; ++i) {
        const double p = photons.beams[i].scatteredW[0], e = photons.beams[i].scatteredErrorW[0];
        const double difference = hr.scatteredW[i] - p;
        worst = std::max(worst, std::abs(difference) / p);
        rms += difference * difference / n;
        scale += p / n;
        squares += difference * difference / (e * e) / n;
    }
    std::printf(
        "scattered power: radiosity against photons %.2f %% RMS, worst %.2f %%; %lld "
        "links, %.2f s against %.2f s\n",
        100.0 * std::sqrt(rms) / scale, 100.0 * worst, static_cast<long long>(hr.stats.links),
        hr.seconds, photons.seconds);
    // The photons' error is 1 % a beam here: radiosity at ε = 2e-3 of a beam differs by
    // about as much again, not more (the mean squared deviation in their standard errors
    // would be 1 with no error of its own).
    std::printf("mean squared deviation %.2f photon standard errors²\n", squares);
    EXPECT_LT(squares, 4.0);
    EXPECT_LT(worst, 0.05);
}

TEST(PhaseFromRadiosity, EveryBeamClosesAndFIsNearlyReciprocal) {
    // What a beam brings the structure, (1 − τ) A, by rays, against what radiosity makes
    // of it: scattered out plus absorbed. And f(i, o) against f(o, i).
    const StructureAlone cloud(ReciprocalCloud(), 1);
    const RadiosityPhase hr = CloudByRadiosity(cloud);
    TransmittanceOptions tauOptions;
    tauOptions.level = 2;
    tauOptions.raysPerDirection = 65536;
    const TransmittanceEstimate tau = ComputeTransmittance(cloud, tauOptions);
    const DirectionSet& set = hr.phase.Directions();
    const int n = set.Size();
    double worst = 0.0, rms = 0.0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 d = set.Direction(i);
        const double area = cloud.ProjectedArea(d);
        const double intercepted = (1.0 - double(tau.tau.At(i, 0))) * area;
        const double error = double(tau.standardError.At(i, 0)) * area;
        const double closure = hr.scatteredW[i] + hr.absorbedW[i] - intercepted;
        worst = std::max(worst, std::abs(closure) / intercepted);
        rms += closure * closure / (intercepted * intercepted) / n;
        // The rays' error, and radiosity's: ε = 2e-3 of a beam on each link.
        EXPECT_LE(std::abs(closure), 5.0 * error + 0.02 * intercepted) << "beam " << i;
    }
    std::printf("radiosity closure: %.2f %% RMS, worst %.2f %% of the intercepted power\n",
                100.0 * std::sqrt(rms), 100.0 * worst);
    double asymmetry = 0.0, scale = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int o = 0; o < n; ++o) {
            const double a = hr.phase.Values()[i * n + o], b = hr.phase.Values()[o * n + i];
            asymmetry += (a - b) * (a - b);
            scale += a * a;
        }
    }
    std::printf("radiosity reciprocity: |f − fᵀ| / |f| = %.2f %%\n",
                100.0 * std::sqrt(asymmetry / scale));
    EXPECT_LT(std::sqrt(asymmetry / scale), 0.05);
}

}  // namespace
}  // namespace leaflux
