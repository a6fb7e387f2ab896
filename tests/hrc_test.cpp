// The HRC solver against closed forms and against the Monte Carlo reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "solver/generate/generator.h"
#include "solver/radiosity/form_factor.h"
#include "solver/radiosity/visibility.h"
#include "solver/results/accuracy.h"
#include "solver/solve.h"
#include "solver/util/directions.h"
#include "solver/util/error.h"
#include "solver/util/sampling.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

SolverSettings HrcSettings(double epsilon) {
    SolverSettings settings;
    settings.kind = SolverKind::kHrc;
    settings.hrc.epsilon = epsilon;
    return settings;
}

Solution SolveWithHrc(const PreparedScene& prepared, double epsilon, int subdivision = 3) {
    SolverSettings settings = HrcSettings(epsilon);
    settings.hrc.maxSubdivision = subdivision;
    return Solve(prepared, settings);
}

TEST(HrcPlate, UnderSunGetsSinOfElevationOnTop) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1, 1, 0), "black"));
    scene.sources.suns.push_back(SunAt(30, 120, 1000));
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution s = SolveWithHrc(prepared, 1e-3);
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2, 500.0, 1e-9);
    EXPECT_NEAR(s.light[0][0].irradianceLowerWm2, 0.0, 1e-9);
}

TEST(HrcPlate, UnderDiscretisedSkyKeepsTheHorizontalIrradiance) {
    Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
    scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1, 1, 0), "black"));
    scene.sources.skies.push_back({SkyModel::kCieOvercast, {300.0}, SkyDiscretization::kTurtle46});
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution s = SolveWithHrc(prepared, 1e-3);
    // The cones' discretisation of the overcast sky keeps it within 2 %.
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2, 300.0, 0.02 * 300.0);
}

// Stems as importers give them: a strip is lit on both sides (as by the reference's rays);
// the faces of a tube, open at both ends, on their outer sides only.
TEST(HrcStem, AStripIsLitOnBothSidesAndATubeOnlyOutside) {
    Scene scene = OneBandScene({{"stem", Opaque(0.0)}});
    auto internode = [&](NodeId id, const std::string& name, std::shared_ptr<const Mesh> mesh) {
        Node node = OrganNode(id, name, std::move(mesh), "stem");
        node.Edit().type = NodeType::kInternode;
        scene.nodes.push_back(node);
    };
    // A strip facing east (+x) at x = 0, and a 10 cm square tube 1 m south of it.
    internode(1, "strip", Quad({0, -0.05, 0}, {0, 0.05, 0}, {0, 0.05, 1}, {0, -0.05, 1}));
    auto tube = std::make_shared<Mesh>();
    for (double z : {0.0, 1.0}) {
        for (auto [x, y] :
             {std::pair{-0.05, -1.05}, {0.05, -1.05}, {0.05, -0.95}, {-0.05, -0.95}}) {
            tube->positions.push_back({x, y, z});
        }
    }
    for (unsigned i = 0; i < 4; ++i) {  // counter-clockwise seen from outside
        const unsigned j = (i + 1) % 4;
        tube->triangles.push_back({i, j, j + 4});
        tube->triangles.push_back({i, j + 4, i + 4});
    }
    internode(2, "tube", tube);
    scene.sources.suns.push_back(SunAt(30, 90, 1000));  // from the east
    scene.sources.suns.push_back(SunAt(30, 0, 1000));   // from the north: grazes the strip
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution s = SolveWithHrc(prepared, 1e-4);
    // The strip: the east sun on its upper side; nothing on its lower side, which the
    // north sun only grazes.
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2, 1000 * std::cos(glm::radians(30.0)), 1e-6);
    EXPECT_NEAR(s.light[0][0].irradianceLowerWm2, 0.0, 1e-6);
    // The tube: east and north faces lit outside (cos 30° each, a quarter of the area),
    // nothing inside.
    EXPECT_NEAR(s.light[1][0].irradianceUpperWm2, 0.5 * 1000 * std::cos(glm::radians(30.0)), 1e-6);
    EXPECT_EQ(s.light[1][0].irradianceLowerWm2, 0.0);

    // Turned round, the strip faces west: the east sun now lights its lower side.
    scene.nodes[0].Edit().organ->mesh =
        Quad({0, 0.05, 0}, {0, -0.05, 0}, {0, -0.05, 1}, {0, 0.05, 1});
    const PreparedScene turned(scene);
    const Solution t = SolveWithHrc(turned, 1e-4);
    EXPECT_NEAR(t.light[0][0].irradianceLowerWm2, 1000 * std::cos(glm::radians(30.0)), 1e-6);
}

// The same tube, white, in a ring of white leaves lit by a sun: the leaves' light reaches
// the tube's faces through links from clusters of leaves, each towards the cluster's
// centre. A cluster beyond a face's plane lit that face's inner side (the 10,000-leaf
// tree's internodes got 12 times the reference's light inside, instanced); the inside of
// the tube must stay dark at every ε.
TEST(HrcStem, LeavesAroundATubeDoNotLightItsInside) {
    Scene scene = OneBandScene({{"stem", Opaque(0.5)}, {"leaf", Leaf(0.45, 0.45)}});
    auto tube = std::make_shared<Mesh>();
    for (double z : {0.0, 1.0}) {
        for (auto [x, y] : {std::pair{-0.05, -0.05}, {0.05, -0.05}, {0.05, 0.05}, {-0.05, 0.05}})
            tube->positions.push_back({x, y, z});
    }
    for (unsigned i = 0; i < 4; ++i) {  // counter-clockwise seen from outside
        const unsigned j = (i + 1) % 4;
        tube->triangles.push_back({i, j, j + 4});
        tube->triangles.push_back({i, j + 4, i + 4});
    }
    Node stem = OrganNode(1, "tube", tube, "stem");
    stem.Edit().type = NodeType::kInternode;
    scene.nodes.push_back(stem);
    Random random(5);
    for (int i = 0; i < 60; ++i) {  // 8 cm leaves 0.2 to 0.5 m from the tube's axis
        const double angle = 2.0 * kPi * random.Uniform(), r = 0.2 + 0.3 * random.Uniform();
        const glm::dvec3 centre(r * std::cos(angle), r * std::sin(angle), random.Uniform());
        const glm::dvec3 n = UniformSphere(random.Uniform(), random.Uniform());
        glm::dvec3 t, b;
        Basis(n, t, b);
        t *= 0.04, b *= 0.04;
        scene.nodes.push_back(OrganNode(
            static_cast<NodeId>(10 + i), "leaf" + std::to_string(i),
            Quad(centre - t - b, centre + t - b, centre + t + b, centre - t + b), "leaf"));
    }
    scene.sources.suns.push_back(SunAt(40, 120, 1000));
    scene.Validate();
    const PreparedScene prepared(scene);
    for (double epsilon : {1e-2, 1e-3, 1e-4}) {
        const Solution s = SolveWithHrc(prepared, epsilon);
        EXPECT_GT(s.light[0][0].irradianceUpperWm2, 0.0);
        EXPECT_EQ(s.light[0][0].irradianceLowerWm2, 0.0) << "ε = " << epsilon;
    }
}

// A lamp bar (15 cm × 5.12 m, its two triangles slivers) facing down 2.4 m up, beside a
// black wall 0.78 m away that rises above it: the power onto the wall against the
// double integral of L cos θ_s cos θ_r / r² (midpoint rule, ≈ 0.02 % here). A wall patch
// across the lamp's plane sees its emitting side from its lower part only; judged by its
// centre alone it was taken as unlit, and the wall got 12 % too little.
TEST(HrcLamp, LightsAWallThatRisesAboveIt) {
    Scene scene = OneBandScene({{"black", Opaque(0.0)}});
    const double halfWidth = 0.075, halfLength = 2.56, height = 2.4, wallX = 0.855;
    scene.sources.emitters.push_back(
        {"lamp",
         Quad({-halfWidth, -halfLength, height}, {-halfWidth, halfLength, height},
              {halfWidth, halfLength, height}, {halfWidth, -halfLength, height}),  // facing down
         {1000.0},
         ""});
    scene.environment.push_back(
        {"wall", Quad({wallX, -3, 0}, {wallX, -3, 3}, {wallX, 3, 3}, {wallX, 3, 0}), "black"});
    scene.Validate();
    double expectedW = 0.0;
    const int lampX = 4, lampY = 200, wallY = 120, wallZ = 60;
    const double lampCell = (2 * halfWidth / lampX) * (2 * halfLength / lampY);
    const double wallCell = (6.0 / wallY) * (3.0 / wallZ);
    for (int i = 0; i < wallY; ++i) {
        for (int j = 0; j < wallZ; ++j) {
            const glm::dvec3 p(wallX, -3.0 + 6.0 * (i + 0.5) / wallY, 3.0 * (j + 0.5) / wallZ);
            if (p.z >= height) continue;  // above the lamp: its back only
            for (int k = 0; k < lampX; ++k) {
                for (int l = 0; l < lampY; ++l) {
                    const glm::dvec3 q(-halfWidth + 2 * halfWidth * (k + 0.5) / lampX,
                                       -halfLength + 2 * halfLength * (l + 0.5) / lampY, height);
                    const glm::dvec3 d = q - p;
                    const double r2 = glm::dot(d, d);
                    expectedW += 1000.0 / kPi * (d.z * -d.x) / (r2 * r2) * lampCell * wallCell;
                }
            }
        }
    }
    SolverSettings settings = HrcSettings(1e-6);
    settings.hrc.directOnly = true;
    const PreparedScene prepared(scene);
    const Solution s = Solve(prepared, settings);
    EXPECT_NEAR(s.light[0][0].irradianceUpperWm2 * 18.0, expectedW, 0.01 * expectedW);
}

struct ViewFactorCase {
    const char* name;
    std::shared_ptr<const Mesh> emitter, receiver;
    double expected;
};

TEST(HrcViewFactor, MatchesHowellWithinOnePercent) {
    const auto rect = [](double w, double h, double z, bool down) {
        const glm::dvec3 a(0, 0, z), b(w, 0, z), c(w, h, z), d(0, h, z);
        return down ? Quad(a, d, c, b) : Quad(a, b, c, d);
    };
    const ViewFactorCase cases[] = {
        {"parallel_unit_gap_1", rect(1, 1, 0, false), rect(1, 1, 1, true), 0.199825},
        {"parallel_unit_gap_0.1", rect(1, 1, 0, false), rect(1, 1, 0.1, true), 0.826995},
        {"parallel_1x2_gap_0.5", rect(1, 2, 0, false), rect(1, 2, 0.5, true), 0.508989},
        {"perpendicular_unit", Quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}),
         Quad({0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}), 0.200044},
    };
    for (const ViewFactorCase& c : cases) {
        Scene scene = OneBandScene({{"black", Leaf(0, 0)}});
        scene.nodes.push_back(OrganNode(1, "receiver", c.receiver, "black"));
        scene.sources.emitters.push_back({"lamp", c.emitter, {1000.0}, ""});
        scene.Validate();
        const PreparedScene prepared(scene);
        // Tight: ε = 1e-6 and triangles split up to 4 times (1/16 of the plates' side,
        // against the 0.1 gap of the near-field case).
        const Solution s = SolveWithHrc(prepared, 1e-6, 4);
        const double e = s.light[0][0].irradianceUpperWm2 + s.light[0][0].irradianceLowerWm2;
        EXPECT_NEAR(e, 1000.0 * c.expected, 0.01 * 1000.0 * c.expected) << c.name;
    }
}

// Exact links into a patch take the form factor averaged over three points of it (to
// judge) or seven weighted ones (to carry light): each point sees a closed cube's other
// faces with form factors summing to one, so their mean does too (what keeps a closed
// room's light), and the mean is that of the points taken one by one.
TEST(FormFactor, MeanOverPointsOfAFaceSumsToOneInsideACube) {
    const glm::dvec3 n(0, 0, 1);  // the floor's triangle, facing in
    const glm::dvec3 a(0.1, 0.1, 0), b(0.9, 0.2, 0), c(0.3, 0.8, 0);
    const glm::dvec3 centre = (a + b + c) / 3.0;
    const glm::dvec3 points[3] = {(4.0 * a + b + c) / 6.0, (a + 4.0 * b + c) / 6.0,
                                  (a + b + 4.0 * c) / 6.0};
    std::vector<std::array<glm::dvec3, 3>> faces;  // the other five faces, two triangles each
    const auto quad = [&](glm::dvec3 p, glm::dvec3 q, glm::dvec3 r, glm::dvec3 s) {
        faces.push_back({p, q, r});
        faces.push_back({p, r, s});
    };
    quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1});
    quad({0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1});
    quad({0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1});
    quad({0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1});
    quad({1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1});
    // Radon's seven points (degree 5), weighted, as exact links take their transfer.
    const double r15 = std::sqrt(15.0);
    const double a1 = (6.0 - r15) / 21.0, a2 = (6.0 + r15) / 21.0;
    const double w1 = (155.0 - r15) / 1200.0, w2 = (155.0 + r15) / 1200.0;
    const auto at = [&](double u, double v) { return (1.0 - u - v) * a + u * b + v * c; };
    const glm::dvec3 seven[7] = {centre,
                                 at(a1, a1),
                                 at(1.0 - 2.0 * a1, a1),
                                 at(a1, 1.0 - 2.0 * a1),
                                 at(a2, a2),
                                 at(1.0 - 2.0 * a2, a2),
                                 at(a2, 1.0 - 2.0 * a2)};
    const double weights[7] = {9.0 / 40.0, w1, w1, w1, w2, w2, w2};
    double sum = 0.0, weightedSum = 0.0;
    for (const auto& [p, q, r] : faces) {
        const SidedFormFactor f = MeanPointToTriangle(centre, points, 3, n, p, q, r);
        double oneByOne = 0.0;
        for (const glm::dvec3& x : points) oneByOne += PointToTriangle(x, n, p, q, r).upper / 3.0;
        EXPECT_NEAR(f.upper, oneByOne, 1e-12);
        EXPECT_EQ(f.lower, 0.0);
        EXPECT_NEAR(f.solidAngleSr, PointToTriangle(centre, n, p, q, r).solidAngleSr, 1e-12);
        sum += f.upper;
        const SidedFormFactor g = MeanPointToTriangle(centre, seven, 7, n, p, q, r, weights);
        double weighted = 0.0;
        for (int k = 0; k < 7; ++k)
            weighted += weights[k] * PointToTriangle(seven[k], n, p, q, r).upper;
        EXPECT_NEAR(g.upper, weighted, 1e-12);
        weightedSum += g.upper;
    }
    EXPECT_NEAR(sum, 1.0, 1e-9);
    EXPECT_NEAR(weightedSum, 1.0, 1e-9);
}

// The directions exact links' near rays take (LinkVisibility::BetweenPatches): uniform in a
// spherical triangle's solid angle, so that a sub-triangle gets its share of the samples,
// and Ω |n · ω| / π averages to the point's form factor (Lambert's formula).
TEST(FormFactor, DirectionsUniformInASphericalTriangleAverageToItsFormFactor) {
    const glm::dvec3 x(0.0), n = glm::normalize(glm::dvec3(0.2, -0.1, 1.0));
    const glm::dvec3 a(-0.3, -0.2, 0.15), b(0.6, -0.1, 0.4), c(0.1, 0.5, 0.05);
    const glm::dvec3 ua = glm::normalize(a), ub = glm::normalize(b), uc = glm::normalize(c);
    const glm::dvec3 um = glm::normalize(0.5 * (ub + uc));  // splits it into a b m and a m c
    const double solidAngle = SphericalTriangleSolidAngle(ua, ub, uc);
    const double share = SphericalTriangleSolidAngle(ua, ub, um) / solidAngle;
    const glm::dvec3 split = glm::cross(ua, um);  // the great circle through a and m
    const int count = 200000;
    Random random(11);
    double sum = 0.0, squares = 0.0;
    int inFirst = 0;
    for (int i = 0; i < count; ++i) {
        const glm::dvec3 omega =
            UniformSphericalTriangle(ua, ub, uc, random.Uniform(), random.Uniform());
        ASSERT_NEAR(glm::length(omega), 1.0, 1e-12);
        const double value = solidAngle * std::abs(glm::dot(n, omega)) / glm::pi<double>();
        sum += value;
        squares += value * value;
        if (glm::dot(split, omega) * glm::dot(split, ub) > 0.0) ++inFirst;
    }
    const double mean = sum / count;
    const double error = std::sqrt((squares / count - mean * mean) / count);
    const SidedFormFactor f = PointToTriangle(x, n, a, b, c);
    std::printf("form factor %.6f by directions, %.6f by Lambert's formula\n", mean,
                f.upper + f.lower);
    EXPECT_NEAR(mean, f.upper + f.lower, 5.0 * error);
    EXPECT_NEAR(static_cast<double>(inFirst) / count, share,
                5.0 * std::sqrt(share * (1.0 - share) / count));
}

// Hierarchical radiosity does not make form factors sum to one exactly; an excess δ comes
// back as B = E / (1 − ρ(1 + δ)), so the error grows as 1/(1 − ρ): within 1 % for ρ ≤ 0.9
// at ε = 1e-6, and for ρ = 0.99 (stiff) a converged, finite answer within 3 %.
TEST(HrcFurnace, RadiosityIsEmittanceOverOneMinusRho) {
    const double cases[][2] = {{0.5, 0.01}, {0.9, 0.01}, {0.99, 0.03}};
    for (const auto& [rho, tolerance] : cases) {
        SCOPED_TRACE(rho);
        const Scene scene = Furnace(rho, 10.0);
        scene.Validate();
        const PreparedScene prepared(scene);
        const Solution s = SolveWithHrc(prepared, 1e-6);
        for (const auto& light : s.light) {
            // Irradiance on the inner side equals the radiosity everywhere.
            EXPECT_NEAR(light[0].irradianceUpperWm2, 10.0 / (1.0 - rho),
                        tolerance * 10.0 / (1.0 - rho));
        }
        EXPECT_LE(s.stats.residual, 1e-5);
        const EnergyBalance& e = s.balance[0];
        EXPECT_NEAR(e.incidentW, e.absorbedW + e.escapedW, 0.005 * e.incidentW);
    }
}

// A 300-leaf generated tree under a sun and a Turtle-like sky, NIR-like leaves.
Scene SmallTree(BandOptics leaf) {
    Scene scene;
    scene.bands = {{"NIR"}};
    scene.optics = {{"leaf", {leaf}}, {"stem", {{0.4, 0.4, 0, 0}}}};
    TreeParameters tree;
    tree.leafCount = 300;
    tree.seed = 11;
    AddTree(scene, tree, {0, 0, 0});
    scene.sources.suns.push_back({glm::normalize(glm::dvec3(0.3, -0.5, 0.8)), {500.0}, 0.0});
    scene.sources.skies.push_back({SkyModel::kCieOvercast, {100.0}, SkyDiscretization::kTurtle46});
    scene.Validate();
    return scene;
}

// Mean relative error over leaves getting at least 5 % of the brightest leaf's light.
double MeanRelativeError(const PreparedScene& prepared, const Solution& value,
                         const Solution& reference) {
    const FlatScene& flat = prepared.Flat();
    double largest = 0.0, sum = 0.0;
    int count = 0;
    auto total = [](const BandLight& l) { return l.irradianceUpperWm2 + l.irradianceLowerWm2; };
    for (std::size_t r = 0; r < flat.receivers.size(); ++r)
        largest = std::max(largest, total(reference.light[r][0]));
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const double expected = total(reference.light[r][0]);
        if (ReceiverName(prepared.Source(), flat.receivers[r]).rfind("leaf", 0) != 0 ||
            expected < 0.05 * largest)
            continue;
        sum += std::abs(total(value.light[r][0]) - expected) / expected;
        ++count;
    }
    return sum / count;
}

TEST(HrcTree, ErrorAgainstMonteCarloFallsWithEpsilon) {
    const Scene scene = SmallTree({0.45, 0.45, 0.45, 0.45});
    const PreparedScene prepared(scene);
    SolverSettings mc;
    mc.monteCarlo.samplesPerReceiver = 2048;
    const Solution reference = Solve(prepared, mc);
    double previous = 1e300;
    for (double epsilon : {1e-3, 1e-4, 1e-5}) {
        const Solution hrc = SolveWithHrc(prepared, epsilon);
        const double error = MeanRelativeError(prepared, hrc, reference);
        EXPECT_LT(error, previous) << "epsilon " << epsilon;
        RecordProperty("mean_relative_error_at_" + std::to_string(epsilon), std::to_string(error));
        previous = error;
    }
    // The bound HRC must meet for lit leaves (3 %); this tree measures 1.2 % at ε = 1e-5, with the
    // reference's own noise (about 1 % a leaf at 2,048 paths) inside that.
    EXPECT_LT(previous, 0.03);
}

// Refinement judges its candidate links in parallel and carries the verdicts out in order;
// sweeps share the hierarchy among the threads: one thread or two, the same links and the
// same light to the last bit.
TEST(HrcTree, SameAnswerWhateverTheThreadCount) {
    const Scene scene = SmallTree({0.45, 0.45, 0.45, 0.45});
    const PreparedScene prepared(scene);
    SolverSettings settings = HrcSettings(1e-5);
    settings.hrc.threads = 1;
    const Solution one = Solve(prepared, settings);
    settings.hrc.threads = 2;
    const Solution two = Solve(prepared, settings);
    EXPECT_EQ(one.stats.links, two.stats.links);
    EXPECT_EQ(one.stats.elements, two.stats.elements);
    EXPECT_EQ(one.stats.iterations, two.stats.iterations);
    for (std::size_t r = 0; r < one.light.size(); ++r) {
        EXPECT_EQ(one.light[r][0].irradianceUpperWm2, two.light[r][0].irradianceUpperWm2) << r;
        EXPECT_EQ(one.light[r][0].irradianceLowerWm2, two.light[r][0].irradianceLowerWm2) << r;
    }
}

// The progress bar's feed (HrcOptions::progress): it starts above 0, never goes back, ends
// at exactly 1 and moves in between (the refinement's tasks carried out, the sweeps'
// change falling); watching the solve does not change its answer.
TEST(HrcTree, ProgressRisesToOneAndLeavesTheAnswerAsItWas) {
    const Scene scene = SmallTree({0.45, 0.45, 0.45, 0.45});
    const PreparedScene prepared(scene);
    SolverSettings settings = HrcSettings(1e-5);
    const Solution unwatched = Solve(prepared, settings);
    std::vector<double> reports;
    settings.hrc.progress = [&](double done) { reports.push_back(done); };
    const Solution watched = Solve(prepared, settings);
    ASSERT_GE(reports.size(), 10u);
    EXPECT_GT(reports.front(), 0.0);
    EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
    EXPECT_EQ(std::adjacent_find(reports.begin(), reports.end()), reports.end()) << "repeats";
    EXPECT_EQ(reports.back(), 1.0);
    // Every stage reports (hrc.cpp's Stage constants: exposure, source links, the other links,
    // the passes, the outputs), and the passes more than their end.
    for (auto [from, to] :
         {std::pair{0.0, 0.05}, {0.05, 0.2}, {0.2, 0.67}, {0.67, 0.96}, {0.97, 1.0}}) {
        EXPECT_TRUE(std::any_of(reports.begin(), reports.end(),
                                [&](double d) { return d > from && d <= to; }))
            << "nothing reported in (" << from << ", " << to << "]";
    }
    for (std::size_t r = 0; r < watched.light.size(); ++r) {
        EXPECT_EQ(watched.light[r][0].irradianceUpperWm2, unwatched.light[r][0].irradianceUpperWm2);
        EXPECT_EQ(watched.light[r][0].irradianceLowerWm2, unwatched.light[r][0].irradianceLowerWm2);
    }
}

TEST(HrcTree, StiffLeavesGiveAFiniteConvergedAnswer) {
    const Scene scene = SmallTree({0.5, 0.5, 0.49, 0.49});
    const PreparedScene prepared(scene);
    const Solution hrc = SolveWithHrc(prepared, 1e-4);
    EXPECT_LE(hrc.stats.residual, 1e-5);
    ExpectFiniteLight(hrc);
}

// The link audit's rays from the receivers find all the light the surfaces send that does
// not escape, and find every point they hit covered by exactly one link: the links
// partition the exchanges.
TEST(HrcTree, LinkAuditFindsTheLightThatDoesNotEscapeCoveredOnce) {
    const Scene scene = SmallTree({0.45, 0.45, 0.45, 0.45});
    const PreparedScene prepared(scene);
    SolverSettings settings = HrcSettings(1e-4);
    settings.hrc.auditLinks = true;
    const Solution hrc = Solve(prepared, settings);
    ASSERT_EQ(hrc.linkAudit.size(), 7u);
    double sent = 0.0;
    for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
        const Receiver& receiver = prepared.Flat().receivers[r];
        if (receiver.optics < 0) continue;
        const BandOptics& o = scene.optics[receiver.optics].bands[0];
        const BandLight& e = hrc.light[r][0];
        sent += receiver.areaM2 * ((o.rhoUpper + o.tauUpperToLower) * e.irradianceUpperWm2 +
                                   (o.rhoLower + o.tauLowerToUpper) * e.irradianceLowerWm2);
    }
    double found = 0.0, uncovered = 0.0, variance = hrc.balance[0].stderrW * hrc.balance[0].stderrW;
    for (const LinkAudit& audit : hrc.linkAudit) {
        found += audit.foundW;
        variance += audit.foundStderrW * audit.foundStderrW;
        if (audit.links == 0) uncovered += audit.foundW;
    }
    const double expected = sent - hrc.balance[0].escapedW;
    EXPECT_NEAR(found, expected, 4.6 * std::sqrt(variance));
    EXPECT_LT(uncovered, 1e-4 * found);
    RecordProperty("audit_found_w", std::to_string(found));
    RecordProperty("sent_not_escaping_w", std::to_string(expected));
    RecordProperty("standard_error_w", std::to_string(std::sqrt(variance)));
    RecordProperty("uncovered_w", std::to_string(uncovered));
}

// A plant (node 10) of two 20 cm square leaves, "top" (node 1) 10 cm above "bottom"
// (node 2) at z = 1 m, of the given optics.
void AddStackedPlant(Scene& scene, const std::string& topOptics, const std::string& bottomOptics) {
    Node plant;
    plant.id = 10;
    plant.Edit().type = NodeType::kPlant;
    plant.Edit().name = "plant";
    scene.nodes.push_back(plant);
    scene.nodes.push_back(OrganNode(1, "top", Rectangle(0.2, 0.2, 1.1), topOptics, 10));
    scene.nodes.push_back(OrganNode(2, "bottom", Rectangle(0.2, 0.2, 1.0), bottomOptics, 10));
}

// A cluster hands its children the light it gathers weighted by how open each is towards
// it (HrcOptions::exposureRays). Two black leaves of one plant, one above the other, under
// a small lamp 5 m up that lights the plant through one link: handed down evenly, each
// leaf gets half of the light; by exposure, the top leaf nearly all of it, as the Monte
// Carlo reference finds, and the two absorb the same power either way (to the single
// precision the shares are kept in, 2^-24 of each). The lamp reflects a little: a black
// one's links into a cluster of organs split the cluster first.
TEST(HrcExposure, SharesOutTheLightAClusterGathersTowardsTheOpenLeaf) {
    Scene scene = OneBandScene({{"leaf", Leaf(0, 0)}, {"lamp", Opaque(0.01)}});
    AddStackedPlant(scene, "leaf", "leaf");
    scene.sources.emitters.push_back({"lamp", Rectangle(0.3, 0.3, 6.0, true), {5000.0}, "lamp"});
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings = HrcSettings(1e-3);
    const Solution open = Solve(prepared, settings);
    settings.hrc.exposureRays = 0;
    const Solution even = Solve(prepared, settings);
    settings.kind = SolverKind::kMonteCarlo;
    settings.monteCarlo.samplesPerReceiver = 4096;
    const Solution reference = Solve(prepared, settings);
    EXPECT_NEAR(open.balance[0].absorbedW, even.balance[0].absorbedW,
                1e-7 * even.balance[0].absorbedW);
    const BandLight& evenTop = even.light[0][0];
    const BandLight& evenBottom = even.light[1][0];
    EXPECT_NEAR(evenBottom.irradianceUpperWm2, evenTop.irradianceUpperWm2,
                1e-9 * evenTop.irradianceUpperWm2)
        << "the lamp must light the plant through one link";
    for (std::size_t r : {0u, 1u}) {
        const BandLight& want = reference.light[r][0];
        const double error =
            std::abs(open.light[r][0].irradianceUpperWm2 - want.irradianceUpperWm2);
        const double evenError =
            std::abs(even.light[r][0].irradianceUpperWm2 - want.irradianceUpperWm2);
        std::printf("%s: reference %.4g ± %.2g, exposure %.4g, even %.4g W/m²\n",
                    ReceiverName(scene, prepared.Flat().receivers[r]).c_str(),
                    want.irradianceUpperWm2, reference.error[r][0].upperWm2,
                    open.light[r][0].irradianceUpperWm2, even.light[r][0].irradianceUpperWm2);
        EXPECT_LT(error, 0.5 * evenError - 4.6 * reference.error[r][0].upperWm2);
    }
}

// A sun's light reaches each organ by the organ's own lit share (the sun's map, or rays),
// whatever ε (DirectionalSource::eachOrgan): at ε = 0.05, a link from a vertical sun into the
// stacked plant, 2 % of the sun's power on the organs beside a 2 m black leaf, is within ε, and it
// would hand the top leaf and the one it shades alike half of the sun each. Split to the
// leaves, the top one takes all the sun and the one beneath none (black leaves: no light
// but the sun's).
TEST(HrcSources, ASunLightsEachOrganByItsOwnShareAtACoarseEpsilon) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.0, 0.0)}});
    AddStackedPlant(scene, "leaf", "leaf");
    scene.nodes.push_back(OrganNode(
        3, "beside", Quad({2.0, -1.0, 1.0}, {4.0, -1.0, 1.0}, {4.0, 1.0, 1.0}, {2.0, 1.0, 1.0}),
        "leaf"));
    scene.sources.suns.push_back(SunAt(90.0, 0.0, 1000.0));
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution hrc = Solve(prepared, HrcSettings(0.05));
    EXPECT_NEAR(hrc.light[0][0].irradianceUpperWm2, 1000.0, 1e-9 * 1000.0);  // top
    EXPECT_NEAR(hrc.light[1][0].irradianceUpperWm2, 0.0, 1e-9 * 1000.0);     // bottom
    EXPECT_NEAR(hrc.light[2][0].irradianceUpperWm2, 1000.0, 1e-9 * 1000.0);  // beside
}

// Sending, a cluster needs no exposure of its own: a link's rays run from the receiver to
// points of the sender cluster weighted by what each sends (LinkVisibility::Between), so
// they meet the cluster's own leaves in the way. Two leaves of one plant (ρ = 0.5 on top,
// black below, τ = 0), one 10 cm above the other, both lit on top by a sun 30° high; a
// black sensor 5 m straight above sees the top leaf alone, which sends ρ E sin 30°:
// E_sensor = ρ E sin 30° F(sensor → top leaf). Counted unshaded, the lower leaf's light
// would add 0.84 of that. The cluster's intensity is interpolated in its direction set
// (§4.2.2), each leaf's lobe scaled to integrate to π: at 514 directions it is within
// 0.3 % of ρ E sin 30° A |cos θ| / π towards the sensor; at the default 34 it is 6.5 %
// over (a coarser lobe), so the test takes 514.
TEST(HrcExposure, AClusterSendsOnlyWhatItsOpenLeavesSend) {
    Scene scene = OneBandScene(
        {{"top", {0.5, 0.0, 0.0, 0.0}}, {"bottom", Leaf(0.5, 0.0)}, {"black", Leaf(0.0, 0.0)}});
    AddStackedPlant(scene, "top", "bottom");
    scene.nodes.push_back(OrganNode(3, "sensor", Rectangle(0.2, 0.2, 6.0, true), "black"));
    scene.sources.suns.push_back(SunAt(30.0, 90.0, 1000.0));
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings = HrcSettings(1e-3);
    settings.hrc.auditLinks = true;
    settings.hrc.directionLevel = 4;
    const Solution hrc = Solve(prepared, settings);
    // The sensor takes the plant's light through a link from the cluster.
    const auto fromCluster =
        std::find_if(hrc.linkAudit.begin(), hrc.linkAudit.end(), [](const LinkAudit& audit) {
            return audit.kind.find("cluster into a plane") != std::string::npos;
        });
    ASSERT_NE(fromCluster, hrc.linkAudit.end());
    ASSERT_EQ(fromCluster->links, 1);
    // Parallel opposed squares of side a at distance d (Howell's catalogue, C-11).
    const double x = 0.2 / 4.9, root = std::sqrt(1.0 + x * x);
    const double form = 2.0 / (kPi * x * x) *
                        (std::log((1.0 + x * x) * (1.0 + x * x) / (1.0 + 2.0 * x * x)) / 2.0 +
                         2.0 * x * root * std::atan(x / root) - 2.0 * x * std::atan(x));
    const double expected = 0.5 * 1000.0 * std::sin(glm::radians(30.0)) * form;
    const double got = hrc.light[2][0].irradianceUpperWm2;
    std::printf("sensor: %.5g W/m², closed form %.5g W/m²\n", got, expected);
    EXPECT_NEAR(got, expected, 0.01 * expected);
}

// Direct light only: the sun's light arrives, what the leaves scatter does not. The top
// leaf's upper side sees the sun alone either way; its lower side gets only what the
// bottom leaf reflects, and the bottom leaf's shaded part only what the top one transmits.
TEST(DirectOnly, DropsScatteredLightInBothSolvers) {
    Scene scene = TwoLeaves(0.02, glm::dvec3(0.0));
    scene.sources.suns.push_back(SunAt(90, 0, 1000));
    scene.Validate();
    const PreparedScene prepared(scene);
    for (const SolverKind kind : {SolverKind::kMonteCarlo, SolverKind::kHrc}) {
        SolverSettings settings;
        settings.kind = kind;
        settings.monteCarlo.samplesPerReceiver = 256;
        settings.hrc.epsilon = 1e-5;
        const Solution full = Solve(prepared, settings);
        settings.monteCarlo.directOnly = settings.hrc.directOnly = true;
        const Solution direct = Solve(prepared, settings);
        SCOPED_TRACE(kind == SolverKind::kHrc ? "hrc" : "mc");
        EXPECT_NEAR(direct.light[0][0].irradianceUpperWm2, 1000.0, 1e-6);
        EXPECT_EQ(direct.light[0][0].irradianceLowerWm2, 0.0);
        EXPECT_GT(full.light[0][0].irradianceLowerWm2, 10.0);
        EXPECT_GT(full.light[1][0].irradianceUpperWm2,
                  direct.light[1][0].irradianceUpperWm2 + 100.0);
    }
}

// A link from one of the 46 sky cones into a cluster of leaves hands every leaf under it
// the cluster's mean light; on a leaf the errors of the 46 links share their sign and add
// up, so such links are held to ε / √46. Direct light at ε = 1e-3 is then within the 2 %
// L2 error HRC must reach of the converged answer (ε = 1e-6): 0.95 % here, 7.4 % with
// such links held to ε alone.
TEST(HrcSky, LinksIntoClustersOfLeavesAreHeldToEpsilonOverRootOfSources) {
    Scene scene = SmallTree({0.45, 0.45, 0.45, 0.45});
    scene.sources.suns.clear();
    const PreparedScene prepared(scene);
    const auto direct = [&](double epsilon) {
        SolverSettings settings = HrcSettings(epsilon);
        settings.hrc.directOnly = true;
        return Solve(prepared, settings);
    };
    const std::vector<BandAccuracy> accuracy =
        CompareLeaves(scene, prepared.Flat(), direct(1e-6), direct(1e-3));
    EXPECT_LT(accuracy[0].l2PctOfMax, 2.0);
    RecordProperty("l2_pct_of_max_at_1e-3", std::to_string(accuracy[0].l2PctOfMax));
}

// A sun bringing most of the light has its shadow edges' error to itself, the cones of a sky
// share theirs: its links take up to twice the rays, 2 × base × √(its share).
TEST(SourceRays, ASunBringingMostOfTheLightTakesMoreAndTheConesTheBase) {
    const Channels channels{2, 1, ChannelMeasure::kSum};
    std::vector<DirectionalSource> sources(5);
    sources[0].normalIrradiance = {400.0, 380.0};  // 78 % of the light: ⌈64 √0.78⌉ = 57
    for (int cone = 1; cone < 5; ++cone) sources[cone].normalIrradiance = {30.0, 25.0};
    EXPECT_EQ(SourceRayCounts(sources, channels, 32), (std::vector<int>{57, 32, 32, 32, 32}));
    sources.resize(1);  // alone, twice the base
    EXPECT_EQ(SourceRayCounts(sources, channels, 32), std::vector<int>{64});
    EXPECT_EQ(SourceRayCounts(sources, channels, 1), std::vector<int>{2});
    sources[0].normalIrradiance = {0.0, 0.0};  // dark: the base
    EXPECT_EQ(SourceRayCounts(sources, channels, 32), std::vector<int>{32});
}

TEST(Hrc, RefusesPeriodicDomainsWithATypedError) {
    Scene scene = TwoLeaves(0.02, glm::dvec3(0.0));
    scene.periodic = PeriodicDomain{-1, -1, 1, 1};
    scene.sources.suns.push_back(SunAt(60, 30, 1000));
    scene.Validate();
    const PreparedScene prepared(scene);
    try {
        SolveWithHrc(prepared, 1e-4);
        FAIL() << "a periodic scene was solved by hrc";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kUnsupported);
        EXPECT_EQ(e.Field(), "periodic");
    }
}

// The extreme scenes (leaves 1 µm apart, a 10⁵ m offset, a grazing sun, a lamp 1 mm from a
// leaf, …) are in stability_test.cpp, for every solver.

}  // namespace
}  // namespace leaflux
