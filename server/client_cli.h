// `leaflux client`: one request to a running leafluxd by hand — open a session from a scene
// file, send a cycle from a delta file, status, close, shutdown. A cycle's light can go to
// a CSV file, with a summary printed instead of the reply.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <ostream>
#include <string>

#include "leaflux.pb.h"
#include "server/client.h"

namespace leaflux {

struct ClientCommand {
    std::string endpoint = "tcp://127.0.0.1:5555", scene, session, delta, solver = "hrc";
    std::string curveServerKeyFile, out;
    std::int64_t number = 1;
    bool leaves = true, structures = false, strict = false;
    double epsilon = 1e-4;
    ClientTimeouts timeouts;
    double timeoutS = 0.0;  // 0: the defaults of ClientTimeouts
};

// The `client` subcommand of `app` and its own subcommands, bound to `command`.
struct ClientApps {
    CLI::App *client, *open, *cycle, *status, *close, *shutdown;
};
ClientApps AddClientCommand(CLI::App& app, ClientCommand& command);

// Runs the subcommand parsed; the process's exit status.
int RunClientCommand(const ClientApps& apps, const ClientCommand& command);

// The light of a cycle as CSV, a row per organ or structure and band, with the columns of
// the Python package's CycleLight.to_csv (leaflux.CSV_COLUMNS), which reads it back:
// cycle,kind,node,name,type,organs,area_m2,band,irradiance_upper_wm2,irradiance_lower_wm2,
// absorbed_w,light_vector_x,light_vector_y,light_vector_z,stderr_upper_wm2,stderr_lower_wm2
void WriteCycleCsv(std::ostream& out, const v1::CycleResult& cycle);

// One paragraph: the cycle's organs, structures and bands, the power the plants absorbed
// per band, the solve's time and balance.
std::string CycleSummary(const v1::CycleResult& cycle);

}  // namespace leaflux
