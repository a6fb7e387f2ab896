// leaflux-grow against a real leafluxd on loopback: plants grow from the light they get,
// only deltas travel, every leaf gets its light, and light shapes the plants.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <stdexcept>

#include "growth_stub/run.h"
#include "tests/daemon_fixture.h"

namespace leaflux {
namespace {

grow::Scenario Scenario(const std::string& name) {
    return grow::LoadScenario(std::string(LEAFLUX_SOURCE_DIR) + "/growth_stub/scenarios/" + name +
                              ".txtpb");
}

class GrowthOnLoopback : public DaemonOnLoopback {
  protected:
    std::vector<grow::CycleRecord> Grow(const grow::Scenario& scenario, int cycles,
                                        grow::GrowthModel& model, bool branchLight = false) {
        Client client(server_->Endpoint());
        grow::RunOptions options;
        options.cycles = cycles;
        options.quiet = true;
        options.branchLight = branchLight;
        return grow::Run(scenario, model, options, client);
    }
};

// Leaf area on each side of the plane x = x0, from the leaves' triangles.
std::pair<double, double> LeafAreaEitherSideOf(const grow::GrowthModel& model, double x0) {
    std::set<grow::NodeId> leaves;
    for (const auto& leaf : model.Leaves()) leaves.insert(leaf.leaf);
    double below = 0.0, above = 0.0;
    for (const grow::WorldTriangle& t : model.Triangles()) {
        if (!leaves.count(t.organ)) continue;
        const double area = 0.5 * glm::length(glm::cross(t.b - t.a, t.c - t.a));
        ((t.a.x + t.b.x + t.c.x) / 3.0 < x0 ? below : above) += area;
    }
    return {below, above};
}

TEST_F(GrowthOnLoopback, PlantGrowsFromItsLightAndOnlyDeltasTravel) {
    const grow::Scenario scenario = Scenario("wall-hole");
    grow::GrowthModel model(scenario);
    const std::vector<grow::CycleRecord> records = Grow(scenario, 8, model);
    ASSERT_EQ(records.size(), 8u);
    // Run throws when a leaf has no light in a reply: every leaf got its light each cycle.
    for (std::size_t i = 1; i < records.size(); ++i) {
        EXPECT_GT(records[i].biomassG, records[i - 1].biomassG) << "cycle " << i + 1;
        EXPECT_GE(records[i].leaves, records[i - 1].leaves) << "cycle " << i + 1;
        EXPECT_GT(records[i].absorbedParW, 0.0);
    }
    EXPECT_GT(records.back().leaves, 3 * records.front().leaves);
    // The first cycle sends the seedling; later ones only what is new or changed.
    const auto nodes = model.Nodes();
    int added = 0, updated = 0;
    for (const grow::CycleRecord& r : records) added += r.added, updated += r.updated;
    EXPECT_EQ(records.front().added, 5);  // plant, axis, phytomer, internode, leaf
    EXPECT_GT(updated, 0);
    EXPECT_LE(added, static_cast<int>(nodes.size()));
    for (std::size_t i = 1; i < records.size(); ++i) {
        EXPECT_LT(records[i].added + records[i].updated, static_cast<int>(nodes.size()));
    }
}

TEST_F(GrowthOnLoopback, WallHolePlantGrowsTowardsTheHole) {
    const grow::Scenario scenario = Scenario("wall-hole");
    grow::GrowthModel model(scenario);
    const std::vector<grow::CycleRecord> records = Grow(scenario, 14, model);
    // The hole is in the wall at x = 1 m; the plant stands at x = 0.
    const double early = records[2].plants[0].leafCentroid.x;
    const double late = records.back().plants[0].leafCentroid.x;
    EXPECT_GT(late, early + 0.05) << "early " << early << " m, late " << late << " m";
    const auto [away, towards] = LeafAreaEitherSideOf(model, 0.0);
    EXPECT_GT(towards, 3.0 * away);
}

TEST_F(GrowthOnLoopback, LampSideEndsDenserThanTheShadedSide) {
    const grow::Scenario scenario = Scenario("lamp");
    grow::GrowthModel model(scenario);
    Grow(scenario, 18, model);
    const auto [shaded, lit] = LeafAreaEitherSideOf(model, 0.0);  // the lamp is at x = 0.4 m
    EXPECT_GT(lit, 2.0 * shaded) << "lit " << lit << " m², shaded " << shaded << " m²";
}

TEST_F(GrowthOnLoopback, ScatteredLightMakesAPlantInARoomGrowMore) {
    // Walls of ρ = 0.5 send back a good part of what enters through the hole: without it
    // (direct light only) the plant must end smaller.
    grow::Scenario scenario = Scenario("wall-hole");
    grow::GrowthModel full(scenario);
    const double fullArea = Grow(scenario, 10, full).back().leafAreaM2;
    scenario.mutable_settings()->set_direct_only(true);
    grow::GrowthModel direct(scenario);
    const double directArea = Grow(scenario, 10, direct).back().leafAreaM2;
    EXPECT_GT(fullArea, 1.05 * directArea) << "full " << fullArea << ", direct " << directArea;
}

// Phytomers are matched across runs by their topological address: each is unique, each
// branch hangs from a phytomer that exists, and ranks along an axis count from the base.
TEST_F(GrowthOnLoopback, PhytomerAddressesNameTheTopology) {
    const grow::Scenario scenario = Scenario("open-field");
    grow::GrowthModel model(scenario);
    Grow(scenario, 12, model);
    std::set<std::string> addresses;
    std::map<std::string, int> phytomersOnAxis;
    for (const grow::GrowthModel::PhytomerSize& p : model.Phytomers()) {
        EXPECT_TRUE(addresses.insert(p.address).second) << p.address << " twice";
        const std::string axis = p.address.substr(0, p.address.find('/'));
        EXPECT_EQ(std::stoi(p.address.substr(p.address.find('/') + 1)), phytomersOnAxis[axis]++)
            << p.address;
    }
    int branches = 0;
    for (const auto& [axis, count] : phytomersOnAxis) {
        const std::size_t dot = axis.rfind('.');
        if (dot == std::string::npos) continue;
        ++branches;
        const std::string bearer = axis.substr(0, dot) + "/" + axis.substr(dot + 1);
        EXPECT_TRUE(addresses.count(bearer)) << axis << " hangs from " << bearer;
    }
    EXPECT_GT(branches, 0) << "12 cycles in the open should break some buds";
}

TEST_F(GrowthOnLoopback, BranchLevelLightIsEnoughToGrow) {
    // Per-axis light only: each leaf gets its axis's irradiance and absorbed power per m².
    const grow::Scenario scenario = Scenario("open-field");
    grow::GrowthModel byLeaf(scenario), byBranch(scenario);
    const double leafArea = Grow(scenario, 6, byLeaf).back().leafAreaM2;
    const std::vector<grow::CycleRecord> records = Grow(scenario, 6, byBranch, true);
    EXPECT_GT(records.back().biomassG, records.front().biomassG);
    // A coarser answer, not a different plant: within a quarter of the per-leaf one.
    EXPECT_NEAR(records.back().leafAreaM2, leafArea, 0.25 * leafArea);
}

TEST(GrowthModel, DiffNamesOnlyTheTopmostRemovedNode) {
    std::map<grow::NodeId, v1::Node> before, after;
    const auto node = [](grow::NodeId id, grow::NodeId parent) {
        v1::Node n;
        n.set_id(id);
        n.set_parent(parent);
        return n;
    };
    before = {{1, node(1, 0)}, {2, node(2, 1)}, {3, node(3, 2)}, {4, node(4, 1)}};
    after = {{1, node(1, 0)}, {4, node(4, 1)}, {5, node(5, 4)}};
    after[4].set_name("moved");
    const v1::TopologyDelta delta = grow::Diff(before, after);
    ASSERT_EQ(delta.removed_size(), 1);
    EXPECT_EQ(delta.removed(0), 2u);
    ASSERT_EQ(delta.added_size(), 1);
    EXPECT_EQ(delta.added(0).id(), 5u);
    ASSERT_EQ(delta.updated_size(), 1);
    EXPECT_EQ(delta.updated(0).id(), 4u);
}

TEST(GrowthModel, BadScenariosNameTheirField) {
    grow::Scenario scenario = Scenario("wall-hole");
    scenario.mutable_species()->set_expansion_cycles(0);
    try {
        grow::GrowthModel model(scenario);
        FAIL() << "a species whose organs never expand was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("species.expansion_cycles"), std::string::npos);
    }
    scenario = Scenario("wall-hole");
    scenario.mutable_room()->set_opening_z_max(5.0);
    EXPECT_THROW(grow::GrowthModel{scenario}, std::invalid_argument);
    try {
        grow::LoadScenario(std::string(LEAFLUX_SHARED_DATA) + "/README.md");
        FAIL() << "a Markdown file parsed as a scenario";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("README.md:"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace leaflux
