// The phase-function database's costs against the number of functions it holds: a miss
// (the computation is a copy of a ready synthetic original, so this is the store's cost),
// a hit in memory, a hit on disk with a cold LRU (a restarted process), and the file's size.
// Bi-directional 130² × 2 bands (135 kB of floats) and mono-directional 130 × 2 functions.
// Prints a table and writes CSV.
// Run: build/release/tests/leaflux_bench_phase_db [out.csv, default out/bench/phase_db_bench.csv]
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "solver/instancing/original_codec.h"
#include "solver/instancing/phase_db.h"
#include "tests/phase_db_fixtures.h"

namespace leaflux {
namespace {

struct Row {
    const char* kind;
    int functions;
    std::size_t blobBytes;
    double missStoreMs, memoryHitUs, diskHitMs;
    double fileMb;  // the file and its log after the writes
    double compactedMb;
};

double Since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Row Measure(PhaseKind kind, int functions, const std::string& directory) {
    namespace fs = std::filesystem;
    const std::string path =
        directory + "/phase-" + PhaseKindName(kind) + "-" + std::to_string(functions) + ".db";
    // 16 distinct originals cycled: drawing 1000 × 34,000 random floats is not the subject.
    std::vector<Original> originals;
    for (unsigned s = 0; s < 16; ++s)
        originals.push_back(testing::SyntheticOriginal(kind, 3, 2, s));
    const auto keyOf = [&](int i) {
        return testing::SyntheticKey("f" + std::to_string(i), kind, 3);
    };
    PhaseDatabaseOptions options;
    options.path = path;
    options.memoryCapMb = 512.0;
    Row row{PhaseKindName(kind), functions, EncodeOriginal(originals[0]).size(), 0, 0, 0, 0, 0};
    {
        PhaseDatabase db(options);
        auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < functions; ++i) {
            db.GetOrCompute(keyOf(i), [&] { return originals[i % 16]; });
        }
        row.missStoreMs = 1e3 * Since(start) / functions;
        start = std::chrono::steady_clock::now();
        for (int i = 0; i < functions; ++i) db.GetOrCompute(keyOf(i), {});
        row.memoryHitUs = 1e6 * Since(start) / functions;
        if (db.Stats().stored != functions) std::fprintf(stderr, "%s\n", db.Health().c_str());
    }
    std::error_code error;
    row.fileMb = (fs::file_size(path) + fs::file_size(path + "-wal", error)) / 1e6;
    {
        PhaseDatabase db(options);  // a restarted process: every hit comes from the file
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < functions; ++i) db.GetOrCompute(keyOf(i), {});
        row.diskHitMs = 1e3 * Since(start) / functions;
        if (db.Stats().diskHits != functions) std::fprintf(stderr, "not every hit was on disk\n");
    }
    {
        PhaseStore store(path, PhaseStoreMode::kExisting);
        store.Compact();
    }
    row.compactedMb = fs::file_size(path) / 1e6;
    fs::remove(path);
    return row;
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    using namespace leaflux;
    const char* csvPath = argc > 1 ? argv[1] : "out/bench/phase_db_bench.csv";
    if (const auto folder = std::filesystem::path(csvPath).parent_path(); !folder.empty())
        std::filesystem::create_directories(folder);  // out/ from the checkout root
    char pattern[] = "/tmp/leaflux-phase-db-bench-XXXXXX";
    const std::string directory = ::mkdtemp(pattern);
    std::vector<Row> rows;
    for (const PhaseKind kind : {PhaseKind::kBiDirectional, PhaseKind::kMonoDirectional}) {
        for (const int functions : {10, 100, 1000})
            rows.push_back(Measure(kind, functions, directory));
    }
    std::filesystem::remove_all(directory);

    std::ofstream csv(csvPath);
    csv << "kind,level,bands,functions,blob_bytes,miss_store_ms,memory_hit_us,disk_hit_ms,file_mb,"
           "compacted_mb,file_bytes_per_function\n";
    std::printf("%-6s %9s %10s %13s %13s %11s %9s %12s %10s\n", "kind", "functions", "blob_kB",
                "miss+store_ms", "memory_hit_us", "disk_hit_ms", "file_MB", "compacted_MB",
                "B/function");
    for (const Row& r : rows) {
        const double perFunction = r.compactedMb * 1e6 / r.functions;
        csv << r.kind << ",3,2," << r.functions << ',' << r.blobBytes << ',' << r.missStoreMs << ','
            << r.memoryHitUs << ',' << r.diskHitMs << ',' << r.fileMb << ',' << r.compactedMb << ','
            << perFunction << '\n';
        std::printf("%-6s %9d %10.1f %13.3f %13.2f %11.3f %9.2f %12.2f %10.0f\n", r.kind,
                    r.functions, r.blobBytes / 1e3, r.missStoreMs, r.memoryHitUs, r.diskHitMs,
                    r.fileMb, r.compactedMb, perFunction);
    }
    std::printf("wrote %s\n", csvPath);
    return 0;
}
