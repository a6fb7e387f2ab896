// leaflux-grow's cycle loop: the growth model on one side, leafluxd on the other, and only
// the protocol between them. Each cycle sends the delta of the plants, reads the light,
// writes the cycle's rows and, at chosen cycles, a PLY of the plants with their light and a
// picture the daemon draws.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "growth_stub/model.h"
#include "server/client.h"

namespace leaflux::grow {

struct RunOptions {
    int cycles = 25;
    std::string outDir;  // cycles.csv, plants.csv, cycle<N>.ply; "" writes nothing
    // Cycles whose geometry and light are written: cycle<N>.ply, and the scene solved and
    // its light, cycle<N>.scene.txtpb and cycle<N>.csv, for `leaflux render`.
    std::set<int> plyCycles;
    // Cycles whose picture the daemon draws (the scenario's `picture`): cycle<N>.png.
    std::set<int> pngCycles;
    bool branchLight = false;  // ask for per-axis light only, not per leaf
    bool quiet = false;
};

// One cycle, after the daemon lit it.
struct CycleRecord {
    int cycle = 0;
    int leaves = 0;
    double leafAreaM2 = 0.0, biomassG = 0.0, absorbedParW = 0.0;
    int added = 0, updated = 0, removed = 0;
    double solveSeconds = 0.0, roundTripSeconds = 0.0, daemonPeakMib = 0.0;
    // The instanced solver's phase functions: computed this cycle, reused, and the seconds
    // computing them took.
    int phaseComputed = 0, phaseReused = 0;
    double phaseComputeSeconds = 0.0;
    std::vector<PlantSummary> plants;
};

// Opens a session for the scenario (settings as in it), runs the cycles and closes the
// session. A cycle unanswered within the client's timeout, or whose session the daemon lost
// (it restarted), is sent once more after a reconnection and a Resync (Client::Cycle).
// Throws ClientError for a rejected request, std::runtime_error when a leaf got no light.
// `model` grows in place (built from `scenario`, it may be inspected afterwards).
std::vector<CycleRecord> Run(const Scenario& scenario, GrowthModel& model,
                             const RunOptions& options, Client& client);

// Cycle numbers from a list such as "2,9,13" ("" is none); anything else is refused with
// std::invalid_argument, a sentence naming `option` and the item.
std::set<int> CycleList(const std::string& list, const std::string& option);

// Reads a scenario file (protobuf text format); errors name the file, line and column.
Scenario LoadScenario(const std::string& path);

}  // namespace leaflux::grow
