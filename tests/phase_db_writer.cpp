// Writes originals into a phase database without end, printing each one's key once its
// row is committed, for phase_db_kill9.sh to kill at random moments.
// Usage: leaflux_phase_db_writer DB RUN
#include <cstdio>
#include <string>

#include "solver/instancing/phase_db.h"
#include "tests/phase_db_fixtures.h"

int main(int argc, char** argv) {
    using namespace leaflux;
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s DB RUN\n", argv[0]);
        return 2;
    }
    PhaseDatabaseOptions options;
    options.path = argv[1];
    options.memoryCapMb = 1.0;
    PhaseDatabase db(options);
    const std::string run = argv[2];
    for (int i = 0; i < 1'000'000; ++i) {
        // Large rows (130² × 2 bands, 135 kB) between small ones, so that kills land inside
        // long writes as well as between them.
        const PhaseKind kind = i % 3 == 0 ? PhaseKind::kBiDirectional : PhaseKind::kMonoDirectional;
        const PhaseKey key = testing::SyntheticKey("run" + run + "-" + std::to_string(i), kind, 3);
        const std::int64_t storedBefore = db.Stats().stored;
        db.GetOrCompute(key, [&] { return testing::SyntheticOriginal(kind, 3, 2, i); });
        if (db.Stats().stored != storedBefore + 1) {
            std::fprintf(stderr, "not stored: %s\n", db.Health().c_str());
            return 1;
        }
        std::printf("%s\n", key.Canonical().c_str());
        std::fflush(stdout);
    }
    return 0;
}
