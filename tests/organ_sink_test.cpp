// Organs' light handed over as a solver reaches them (OrganSink): the per-organ CSV written
// as it comes is the one the light table gives, whatever the order and the threads.
#include "solver/results/organ_sink.h"

#include <gtest/gtest.h>

#include <optional>
#include <sstream>
#include <thread>

#include "server/policy_proto.h"
#include "solver/instancing/instanced.h"
#include "solver/results/export.h"
#include "solver/results/leaf_csv_stream.h"
#include "tests/instanced_scenes.h"

namespace leaflux {
namespace {

using testing::Copies;

// Two threads hand the rows over, one the even receivers from the first, the other the odd
// ones from the last, some skipped: the CSV is the table's, row for row.
TEST(LeafCsvStream, WritesTheTablesCsvWhateverTheOrderRowsComeIn) {
    const Scene scene = Copies(2, 30);
    const PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    Solution solution = testing::Hrc(prepared, 1e-3);
    const std::size_t count = flat.receivers.size();
    solution.unsolved.assign(count, 0);
    for (std::size_t r = 3; r < count; r += 7) solution.unsolved[r] = 1;
    std::ostringstream table, streamed;
    WriteLeafCsv(table, scene, flat, solution);
    LeafCsvStream stream(streamed, scene, flat);
    const auto hand = [&](std::size_t r) {
        if (solution.unsolved[r]) {
            stream.Skip(r);
        } else {
            stream.Put(r, solution.light[r]);
        }
    };
    std::thread even([&] {
        for (std::size_t r = 0; r < count; r += 2) hand(r);
    });
    std::thread odd([&] {
        for (std::size_t r = count - 1 - count % 2; r < count; r -= 2) hand(r);
    });
    even.join();
    odd.join();
    stream.Finish();
    EXPECT_GT(stream.MostWaiting(), 0u);
    EXPECT_EQ(streamed.str(), table.str());
}

// The instanced solver with a sink: the CSV written as it reaches the organs is the one its
// light table gives, with instances nested (the default policy's plants and axes), on one
// core or two, and with plants solved whole, their organs left out or their light handed
// down.
TEST(InstancedOrganSink, StreamsTheCsvItsLightTableGives) {
    const Scene scene = Copies(3, 80);
    const PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    struct Case {
        int threads;
        std::optional<NodeType> outputLevel;
        bool pushDown;
    };
    for (const Case& c : {Case{2, std::nullopt, false}, Case{1, std::nullopt, false},
                          Case{2, NodeType::kPlant, false}, Case{2, NodeType::kPlant, true}}) {
        InstancedOptions options;
        options.hrc.epsilon = 1e-2;
        options.hrc.threads = c.threads;
        options.outputLevel = c.outputLevel;
        options.pushDown = c.pushDown;
        const auto solve = [&]() {
            PhaseDatabase database({});
            return SolveInstanced(scene, flat, &prepared.Rays(), DefaultPolicy(), database,
                                  options);
        };
        const InstancedSolution held = solve();
        ASSERT_GE(held.stats.depths.size(), 3u);  // plants holding axes
        std::ostringstream table, streamed;
        WriteLeafCsv(table, scene, flat, held.solution);
        LeafCsvStream stream(streamed, scene, flat);
        options.organSink = &stream;
        const InstancedSolution handed = solve();
        stream.Finish();
        EXPECT_TRUE(handed.solution.light.empty());
        EXPECT_EQ(streamed.str(), table.str()) << c.threads << " threads, push-down " << c.pushDown;
    }
}

}  // namespace
}  // namespace leaflux
