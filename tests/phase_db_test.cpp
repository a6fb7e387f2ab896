// The phase-function database (Soler 2003 §5): what it keeps, across processes, under
// concurrency, and when its file is corrupt, foreign, newer, read-only or full.
#include "solver/instancing/phase_db.h"

#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <latch>
#include <sstream>
#include <thread>

#include "solver/instancing/original_codec.h"
#include "tests/phase_db_fixtures.h"

namespace leaflux {
namespace {

using testing::SyntheticKey;
using testing::SyntheticOriginal;
namespace fs = std::filesystem;

class TemporaryDirectory {
  public:
    TemporaryDirectory() {
        char pattern[] = "/tmp/leaflux-phase-db-XXXXXX";
        path_ = ::mkdtemp(pattern);
    }
    ~TemporaryDirectory() { fs::remove_all(path_); }
    std::string File(const std::string& name) const { return path_ + "/" + name; }
    const std::string& Path() const { return path_; }

  private:
    std::string path_;
};

std::string Contents(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

bool SameValues(const Original& a, const Original& b) {
    const auto same = [](std::span<const float> x, std::span<const float> y) {
        return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size_bytes()) == 0;
    };
    return a.boxMin == b.boxMin && a.boxMax == b.boxMax && a.phase.Kind() == b.phase.Kind() &&
           a.phase.Level() == b.phase.Level() && a.phase.Bands() == b.phase.Bands() &&
           same(a.phase.Values(), b.phase.Values()) &&
           a.transmittance.Level() == b.transmittance.Level() &&
           same(a.transmittance.Values(), b.transmittance.Values()) &&
           a.absorption.Level() == b.absorption.Level() &&
           a.absorption.Channels() == b.absorption.Channels() &&
           same(a.absorption.Values(), b.absorption.Values()) &&
           a.provenance.representative == b.provenance.representative &&
           a.provenance.leafCount == b.provenance.leafCount &&
           a.provenance.accuracy == b.provenance.accuracy &&
           a.provenance.computeSeconds == b.provenance.computeSeconds;
}

// Runs `sql` on the file with raw SQLite, binding `blob` to ?1 when given.
void RawSql(const std::string& path, const std::string& sql,
            const std::vector<std::uint8_t>* blob = nullptr) {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
    sqlite3_stmt* statement = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr), SQLITE_OK)
        << sqlite3_errmsg(db);
    if (blob)
        sqlite3_bind_blob(statement, 1, blob->data(), static_cast<int>(blob->size()), nullptr);
    while (sqlite3_step(statement) == SQLITE_ROW) {
    }
    sqlite3_finalize(statement);
    sqlite3_close(db);
}

std::vector<std::uint8_t> RawBlob(const std::string& path, std::int64_t id) {
    sqlite3* db = nullptr;
    sqlite3_open(path.c_str(), &db);
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(db, "SELECT blob FROM phase_functions WHERE id = ?", -1, &statement,
                       nullptr);
    sqlite3_bind_int64(statement, 1, id);
    std::vector<std::uint8_t> blob;
    if (sqlite3_step(statement) == SQLITE_ROW) {
        const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(statement, 0));
        blob.assign(data, data + sqlite3_column_bytes(statement, 0));
    }
    sqlite3_finalize(statement);
    sqlite3_close(db);
    return blob;
}

// A compute function that counts its calls.
struct CountingCompute {
    Original original;
    std::shared_ptr<std::atomic<int>> calls = std::make_shared<std::atomic<int>>(0);
    std::function<Original()> Function() const {
        return [original = original, calls = calls] {
            ++*calls;
            return original;
        };
    }
};

CountingCompute Counting(unsigned seed, PhaseKind kind = PhaseKind::kBiDirectional, int level = 2) {
    return {SyntheticOriginal(kind, level, 2, seed)};
}

PhaseDatabaseOptions OnFile(const std::string& path, double memoryCapMb = 64.0) {
    PhaseDatabaseOptions options;
    options.path = path;
    options.memoryCapMb = memoryCapMb;
    return options;
}

TEST(PhaseDbCodec, RoundTripIsBitIdentical) {
    for (const PhaseKind kind :
         {PhaseKind::kConstant, PhaseKind::kMonoDirectional, PhaseKind::kBiDirectional}) {
        const Original original = SyntheticOriginal(kind, 3, 2, 7);
        const std::vector<std::uint8_t> blob = EncodeOriginal(original);
        EXPECT_TRUE(SameValues(DecodeOriginal(blob, "blob"), original)) << PhaseKindName(kind);
    }
}

// Originals stored before the absorption was (format 1) are read, without it.
TEST(PhaseDbCodec, AFormatOneBlobIsReadWithoutItsAbsorption) {
    Original original = SyntheticOriginal(PhaseKind::kMonoDirectional, 2, 2, 1);
    original.absorption = SphereFunction();
    std::vector<std::uint8_t> blob = EncodeOriginal(original);
    // Format 1: no absorption's level, channels and (empty) values after f's values.
    const std::size_t tau = 4 + 1 + 48 + 4 + 4 + 4 + original.transmittance.Values().size_bytes();
    const std::size_t absorption = tau + 1 + 4 + 4 + 4 + original.phase.Bytes();
    blob.erase(blob.begin() + absorption, blob.begin() + absorption + 12);
    blob[4] = 1;
    const Original decoded = DecodeOriginal(blob, "row 1");
    EXPECT_TRUE(decoded.absorption.Empty());
    EXPECT_TRUE(SameValues(decoded, original));
}

TEST(PhaseDbCodec, DamagedBlobsAreParseErrors) {
    const std::vector<std::uint8_t> blob =
        EncodeOriginal(SyntheticOriginal(PhaseKind::kMonoDirectional, 2, 2, 1));
    auto truncated = blob;
    truncated.resize(blob.size() / 2);
    auto longer = blob;
    longer.push_back(0);
    auto version = blob;
    version[4] = kOriginalFormatVersion + 1;
    auto kind = blob;
    kind[4 + 1 + 48 + 8 + 4 + 34 * 4] = 9;  // the phase kind byte, after τ of 34 values
    // An absorption of one channel for f's two bands: lookups of the second would run past it.
    Original oneChannel = SyntheticOriginal(PhaseKind::kMonoDirectional, 2, 2, 1);
    oneChannel.absorption = SphereFunction(2, 1);
    auto channels = EncodeOriginal(oneChannel);
    for (const auto* damaged : {&truncated, &longer, &version, &kind, &channels}) {
        try {
            DecodeOriginal(*damaged, "row 1");
            ADD_FAILURE() << "a damaged blob of " << damaged->size() << " bytes decoded";
        } catch (const InputError& e) {
            EXPECT_EQ(e.Code(), ErrorCode::kParse);
            EXPECT_NE(e.Field().find("row 1"), std::string::npos) << e.what();
            if (damaged == &channels) {
                EXPECT_EQ(e.Field(), "row 1.absorption.channels");
            }
        }
    }
}

TEST(PhaseDbStore, RoundTripThroughDiskAcrossReopening) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    const CountingCompute compute = Counting(3);
    {
        PhaseDatabase db(OnFile(path));
        const PhaseLookup first = db.GetOrCompute(SyntheticKey("a"), compute.Function());
        EXPECT_EQ(first.source, PhaseSource::kComputed);
        EXPECT_EQ(db.GetOrCompute(SyntheticKey("a"), compute.Function()).source,
                  PhaseSource::kMemory);
        EXPECT_EQ(db.Stats().stored, 1);
        EXPECT_EQ(db.Health(), "");
    }
    // A restarted process: the row is read from the file, bit for bit, and not recomputed.
    PhaseDatabase again(OnFile(path));
    const PhaseLookup reloaded = again.GetOrCompute(SyntheticKey("a"), compute.Function());
    EXPECT_EQ(reloaded.source, PhaseSource::kDisk);
    EXPECT_TRUE(SameValues(*reloaded.original, compute.original));
    EXPECT_EQ(*compute.calls, 1);
    const PhaseDatabaseStats stats = again.Stats();
    EXPECT_EQ(stats.diskHits, 1);
    EXPECT_EQ(stats.misses, 0);
    EXPECT_GT(stats.loadSeconds, 0.0);
}

TEST(PhaseDbStore, MakesItsDirectoryAndOnlyReadsWhenAskedTo) {
    TemporaryDirectory directory;
    const std::string path = directory.File("data/leaflux/phase.db");
    EXPECT_THROW(PhaseStore(path, PhaseStoreMode::kReadOnly), InputError);
    EXPECT_THROW(PhaseStore(path, PhaseStoreMode::kExisting), InputError);
    EXPECT_FALSE(fs::exists(path));
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("a"), Counting(1).Function());
    EXPECT_EQ(PhaseStore(path, PhaseStoreMode::kReadOnly).Stats().rows, 1);
    // Nothing is left beside it but the database and SQLite's own -wal and -shm.
    for (const auto& entry : fs::directory_iterator(fs::path(path).parent_path())) {
        const std::string name = entry.path().filename();
        EXPECT_TRUE(name == "phase.db" || name == "phase.db-wal" || name == "phase.db-shm") << name;
    }
    try {
        PhaseStore store(directory.Path(), PhaseStoreMode::kCreate);
        ADD_FAILURE() << "a directory was opened";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Field(), directory.Path());
    }
}

TEST(PhaseDbStore, VerifyListStatsAndCompactDescribeTheFile) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    {
        PhaseDatabase db(OnFile(path));
        for (int i = 0; i < 5; ++i) {
            db.GetOrCompute(SyntheticKey("s" + std::to_string(i), PhaseKind::kMonoDirectional),
                            Counting(i, PhaseKind::kMonoDirectional).Function());
        }
    }
    PhaseStore store(path, PhaseStoreMode::kExisting);
    const std::vector<PhaseRowInfo> rows = store.List();
    ASSERT_EQ(rows.size(), 5u);
    EXPECT_EQ(rows[2].signature, "s2");
    EXPECT_EQ(rows[2].kind, "mono");
    EXPECT_EQ(rows[2].bands, "PAR,NIR");
    EXPECT_EQ(rows[2].leafCount, 12);
    EXPECT_EQ(rows[2].key, SyntheticKey("s2", PhaseKind::kMonoDirectional).Canonical());
    EXPECT_TRUE(store.Verify().Ok());
    store.Compact();
    const PhaseFileStats stats = store.Stats();
    EXPECT_EQ(stats.rows, 5);
    EXPECT_EQ(stats.schemaVersion, kPhaseSchemaVersion);
    EXPECT_GT(stats.fileBytes, stats.blobBytes);
    ASSERT_EQ(stats.rowsByKind.size(), 1u);
    EXPECT_EQ(stats.rowsByKind[0].second, 5);
    EXPECT_TRUE(store.FindById(rows[4].id).has_value());
}

TEST(PhaseDbLru, EvictsUnderItsCapThenReloadsFromDisk) {
    TemporaryDirectory directory;
    // 130² × 2 bands of floats: 135 kB each; a cap of 0.5 MB holds three.
    const CountingCompute first = Counting(1, PhaseKind::kBiDirectional, 3);
    const double capMb = 3.5 * static_cast<double>(OriginalBytes(first.original)) / 1e6;
    PhaseDatabase db(OnFile(directory.File("phase.db"), capMb));
    for (int i = 0; i < 8; ++i) {
        db.GetOrCompute(SyntheticKey("k" + std::to_string(i), PhaseKind::kBiDirectional, 3),
                        Counting(i, PhaseKind::kBiDirectional, 3).Function());
        EXPECT_LE(db.Stats().memoryBytes, capMb * 1e6);
    }
    const PhaseDatabaseStats stats = db.Stats();
    EXPECT_EQ(stats.memoryEntries, 3);
    EXPECT_EQ(stats.evictions, 5);
    // The newest are in memory; the oldest was evicted and comes back from the file.
    EXPECT_EQ(db.GetOrCompute(SyntheticKey("k7", PhaseKind::kBiDirectional, 3), {}).source,
              PhaseSource::kMemory);
    const CountingCompute again = Counting(0, PhaseKind::kBiDirectional, 3);
    const PhaseLookup reloaded =
        db.GetOrCompute(SyntheticKey("k0", PhaseKind::kBiDirectional, 3), again.Function());
    EXPECT_EQ(reloaded.source, PhaseSource::kDisk);
    EXPECT_EQ(*again.calls, 0);
    EXPECT_TRUE(SameValues(*reloaded.original, again.original));
}

TEST(PhaseDbConcurrency, EightThreadsAskingForOneMissingKeyComputeItOnce) {
    TemporaryDirectory directory;
    PhaseDatabase db(OnFile(directory.File("phase.db")));
    const Original original = SyntheticOriginal(PhaseKind::kBiDirectional, 2, 2, 5);
    std::atomic<int> calls{0};
    std::latch start(8);
    std::vector<PhaseLookup> results(8);
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t) {
        threads.emplace_back([&, t] {
            start.arrive_and_wait();
            results[t] = db.GetOrCompute(SyntheticKey("shared"), [&] {
                ++calls;
                // Long enough for every other thread to arrive while it runs.
                std::this_thread::sleep_for(std::chrono::milliseconds(200));
                return original;
            });
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(calls, 1);
    int computed = 0;
    for (const PhaseLookup& result : results) {
        computed += result.source == PhaseSource::kComputed;
        EXPECT_EQ(result.original, results[0].original);  // one shared original
    }
    EXPECT_EQ(computed, 1);
    const PhaseDatabaseStats stats = db.Stats();
    EXPECT_EQ(stats.computed, 1);
    EXPECT_EQ(stats.awaited + stats.memoryHits, 7);
    EXPECT_EQ(stats.stored, 1);
}

TEST(PhaseDbConcurrency, AFailedComputationReachesItsWaitersAndStoresNothing) {
    TemporaryDirectory directory;
    PhaseDatabase db(OnFile(directory.File("phase.db")));
    std::latch start(4);
    std::atomic<int> calls{0}, failures{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back([&] {
            start.arrive_and_wait();
            try {
                db.GetOrCompute(SyntheticKey("fails"), [&]() -> Original {
                    ++calls;
                    std::this_thread::sleep_for(std::chrono::milliseconds(200));
                    throw std::runtime_error("the representative has no leaves");
                });
            } catch (const std::runtime_error& e) {
                failures += std::string(e.what()) == "the representative has no leaves";
            }
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(failures, 4);
    EXPECT_EQ(db.Stats().stored, 0);
    // Nothing was kept: the next request computes it.
    const CountingCompute compute = Counting(2);
    EXPECT_EQ(db.GetOrCompute(SyntheticKey("fails"), compute.Function()).source,
              PhaseSource::kComputed);
}

TEST(PhaseDbConcurrency, ManyThreadsOnOverlappingKeysComputeEachOnce) {
    TemporaryDirectory directory;
    // A small buffer, so that evictions and reloads from the file run among the requests.
    const Original original = SyntheticOriginal(PhaseKind::kMonoDirectional, 3, 2, 1);
    PhaseDatabase db(OnFile(directory.File("phase.db"), 10.5 * OriginalBytes(original) / 1e6));
    constexpr int kKeys = 40;
    std::vector<std::atomic<int>> calls(kKeys);
    std::latch start(8);
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t) {
        threads.emplace_back([&, t] {
            start.arrive_and_wait();
            for (int round = 0; round < 200; ++round) {
                const int k = (round * 7 + t * 3) % kKeys;
                const PhaseLookup lookup = db.GetOrCompute(
                    SyntheticKey("k" + std::to_string(k), PhaseKind::kMonoDirectional, 3), [&] {
                        ++calls[k];
                        return original;
                    });
                EXPECT_TRUE(SameValues(*lookup.original, original));
            }
        });
    }
    for (std::thread& thread : threads) thread.join();
    for (int k = 0; k < kKeys; ++k) EXPECT_EQ(calls[k], 1) << "key " << k;
    const PhaseDatabaseStats stats = db.Stats();
    EXPECT_EQ(stats.computed, kKeys);
    EXPECT_EQ(stats.stored, kKeys);
    EXPECT_GT(stats.evictions, 0);
    EXPECT_GT(stats.diskHits, 0);
    EXPECT_EQ(stats.memoryHits + stats.diskHits + stats.awaited + stats.misses, 8 * 200);
    EXPECT_TRUE(db.Verify().Ok());
    EXPECT_EQ(db.List().size(), static_cast<std::size_t>(kKeys));
}

TEST(PhaseDbKey, AKeyDifferingInAnyFieldIsAMiss) {
    TemporaryDirectory directory;
    PhaseDatabase db(OnFile(directory.File("phase.db")));
    const PhaseKey base = SyntheticKey("type=axis;leaves=2");
    db.GetOrCompute(base, Counting(1).Function());
    std::vector<PhaseKey> variants(10, base);
    variants[0].species = "oak";
    variants[1].policyHash = "00112233445566ab";
    variants[2].signature = "type=axis;leaves=3";
    variants[3].opticsHash = "ffeeddccbbaa9989";
    variants[4].bands = {"PAR"};
    variants[5].bands = {"NIR", "PAR"};
    variants[6].kind = PhaseKind::kMonoDirectional;
    variants[7].directionLevel = 3;
    variants[8].codeVersion = kPhaseCodeVersion + 1;
    variants[9].settings = "mc photons=40000";
    for (std::size_t v = 0; v < variants.size(); ++v) {
        EXPECT_NE(variants[v].Canonical(), base.Canonical()) << v;
        EXPECT_EQ(db.GetOrCompute(variants[v], Counting(2).Function()).source,
                  PhaseSource::kComputed)
            << variants[v].Canonical();
    }
    EXPECT_EQ(db.GetOrCompute(base, {}).source, PhaseSource::kMemory);
    // Separators inside fields cannot make two keys one.
    PhaseKey a = base, b = base;
    a.species = "x|signature=y";
    b.species = "x";
    b.signature = "y";
    EXPECT_NE(a.Canonical(), b.Canonical());
    a = b = base;
    a.bands = {"A,B"};
    b.bands = {"A", "B"};
    EXPECT_NE(a.Canonical(), b.Canonical());
}

TEST(PhaseDbFaults, ACorruptedRowIsReportedRecomputedAndNeverReturned) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    const CountingCompute compute = Counting(4);
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("c"), compute.Function());
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("d"), Counting(5).Function());
    std::vector<std::uint8_t> blob = RawBlob(path, 1);
    ASSERT_FALSE(blob.empty());
    for (std::size_t i = 100; i < 108; ++i) blob[i] ^= 0x5a;  // inside f's values
    RawSql(path, "UPDATE phase_functions SET blob = ?1 WHERE id = 1", &blob);
    {
        PhaseStore store(path, PhaseStoreMode::kReadOnly);
        const PhaseVerifyReport report = store.Verify();
        EXPECT_FALSE(report.Ok());
        ASSERT_EQ(report.badRows.size(), 1u);
        EXPECT_EQ(report.badRows[0].id, 1);
        EXPECT_EQ(report.rows, 2);
    }
    PhaseDatabase db(OnFile(path));
    const PhaseLookup lookup = db.GetOrCompute(SyntheticKey("c"), compute.Function());
    EXPECT_EQ(lookup.source, PhaseSource::kRecomputed);
    EXPECT_TRUE(SameValues(*lookup.original, compute.original));
    EXPECT_EQ(*compute.calls, 2);
    EXPECT_EQ(db.Stats().badRows, 1);
    EXPECT_NE(db.Health().find(path + " row 1"), std::string::npos) << db.Health();
    // The other row was left alone, and the bad one is overwritten with sound contents.
    EXPECT_EQ(db.GetOrCompute(SyntheticKey("d"), {}).source, PhaseSource::kDisk);
    EXPECT_TRUE(PhaseStore(path, PhaseStoreMode::kReadOnly).Verify().Ok());
    EXPECT_EQ(PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("c"), {}).source,
              PhaseSource::kDisk);
}

TEST(PhaseDbFaults, AnUndecodableBlobWithAMatchingChecksumIsRecomputed) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    const CountingCompute compute = Counting(6);
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("e"), compute.Function());
    std::vector<std::uint8_t> blob = RawBlob(path, 1);
    blob.resize(40);
    RawSql(path,
           "UPDATE phase_functions SET blob = ?1, checksum = '" +
               PhaseRowChecksum(SyntheticKey("e").Canonical(), blob) + "' WHERE id = 1",
           &blob);
    PhaseDatabase db(OnFile(path));
    const PhaseLookup lookup = db.GetOrCompute(SyntheticKey("e"), compute.Function());
    EXPECT_EQ(lookup.source, PhaseSource::kRecomputed);
    EXPECT_TRUE(SameValues(*lookup.original, compute.original));
    EXPECT_EQ(db.Stats().badRows, 1);
}

// Opening `path` is refused with `code`, naming it, and leaves it byte-identical; the
// degrading mode goes on in memory with the error kept.
void ExpectRefused(const std::string& path, ErrorCode code) {
    const std::string before = Contents(path);
    try {
        PhaseDatabase db(OnFile(path));
        ADD_FAILURE() << path << " was opened";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), code) << e.what();
        EXPECT_EQ(e.Field(), path);
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    }
    EXPECT_THROW(PhaseStore(path, PhaseStoreMode::kReadOnly), InputError);
    PhaseDatabaseOptions options = OnFile(path);
    options.degradeToMemory = true;
    PhaseDatabase db(options);
    EXPECT_FALSE(db.Persistent());
    EXPECT_NE(db.OpenError().find(path), std::string::npos);
    EXPECT_THROW(db.Verify(), InputError);
    EXPECT_EQ(db.Stats().health, db.OpenError());
    const CountingCompute compute = Counting(1);
    EXPECT_EQ(db.GetOrCompute(SyntheticKey("m"), compute.Function()).source,
              PhaseSource::kComputed);
    EXPECT_EQ(db.GetOrCompute(SyntheticKey("m"), compute.Function()).source, PhaseSource::kMemory);
    EXPECT_EQ(Contents(path), before);
    EXPECT_FALSE(fs::exists(path + "-wal"));
}

TEST(PhaseDbFaults, AForeignSqliteFileIsRefusedAndLeftAsItWas) {
    TemporaryDirectory directory;
    const std::string path = directory.File("other.db");
    RawSql(path, "CREATE TABLE photos (id INTEGER PRIMARY KEY, name TEXT)");
    RawSql(path, "INSERT INTO photos (name) VALUES ('tree.jpg')");
    ExpectRefused(path, ErrorCode::kParse);
    // With another application's id but our own table name, too.
    const std::string tagged = directory.File("tagged.db");
    RawSql(tagged, "PRAGMA application_id = 1234");
    RawSql(tagged, "CREATE TABLE phase_functions (x)");
    ExpectRefused(tagged, ErrorCode::kParse);
}

TEST(PhaseDbFaults, AFileThatIsNotSqliteIsRefusedAndLeftAsItWas) {
    TemporaryDirectory directory;
    const std::string path = directory.File("notes.txt");
    std::ofstream(path) << "leaf area index 3.2\n" << std::string(200, 'x');
    ExpectRefused(path, ErrorCode::kParse);
    const std::string empty = directory.File("empty.db");
    std::ofstream{empty};
    ExpectRefused(empty, ErrorCode::kParse);
}

TEST(PhaseDbFaults, ANewerSchemaVersionIsRefusedAndLeftAsItWas) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("n"), Counting(1).Function());
    RawSql(path, "PRAGMA user_version = " + std::to_string(kPhaseSchemaVersion + 1));
    ExpectRefused(path, ErrorCode::kUnsupported);
    try {
        PhaseStore store(path, PhaseStoreMode::kExisting);
        ADD_FAILURE() << "a newer file was opened";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos) << e.what();
    }
}

// Runs `body` where the file's permissions bind: as `nobody` in a child when this is root
// (root writes read-only files). "" from body means it held.
std::string AsUnprivileged(const std::function<std::string()>& body) {
    if (::geteuid() != 0) return body();
    int pipeFds[2];
    if (::pipe(pipeFds) != 0) return "no pipe";
    const pid_t child = ::fork();
    if (child == 0) {
        ::close(pipeFds[0]);
        std::string result = ::setgid(65534) == 0 && ::setuid(65534) == 0 ? body() : "no setuid";
        if (::write(pipeFds[1], result.data(), result.size()) < 0) ::_exit(2);
        ::_exit(0);
    }
    ::close(pipeFds[1]);
    std::string result;
    char buffer[512];
    for (ssize_t got; (got = ::read(pipeFds[0], buffer, sizeof buffer)) > 0;)
        result.append(buffer, got);
    ::close(pipeFds[0]);
    int status = 0;
    ::waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "the child failed: " + result;
    return result;
}

TEST(PhaseDbFaults, AReadOnlyFileIsReadAndNewFunctionsAreKeptInMemory) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    const CountingCompute known = Counting(8);
    PhaseDatabase(OnFile(path)).GetOrCompute(SyntheticKey("known"), known.Function());
    // The directory stays writable: SQLite reads a WAL database through its -shm file.
    ::chmod(directory.Path().c_str(), 0777);
    ::chmod(path.c_str(), 0444);
    const std::string before = Contents(path);
    const std::string failure = AsUnprivileged([&]() -> std::string {
        PhaseDatabase db(OnFile(path));
        if (db.Health().find("read-only") == std::string::npos) return "health: " + db.Health();
        const PhaseLookup read = db.GetOrCompute(SyntheticKey("known"), known.Function());
        if (read.source != PhaseSource::kDisk || !SameValues(*read.original, known.original))
            return std::string("the known row came from ") + PhaseSourceName(read.source);
        const CountingCompute fresh = Counting(9);
        if (db.GetOrCompute(SyntheticKey("new"), fresh.Function()).source != PhaseSource::kComputed)
            return "the new key was not computed";
        const PhaseDatabaseStats stats = db.Stats();
        if (stats.writeErrors != 1 || stats.stored != 0)
            return "write errors " + std::to_string(stats.writeErrors);
        if (stats.health.find(path) == std::string::npos) return "health: " + stats.health;
        if (db.GetOrCompute(SyntheticKey("new"), fresh.Function()).source != PhaseSource::kMemory)
            return "the new function was not kept in memory";
        return "";
    });
    EXPECT_EQ(failure, "");
    EXPECT_EQ(Contents(path), before);
}

TEST(PhaseDbFaults, AFullDiskKeepsNewFunctionsInMemoryAndTheFileSound) {
    TemporaryDirectory directory;
    const std::string path = directory.File("phase.db");
    PhaseDatabaseOptions options = OnFile(path);
    options.diskCapMb = 0.6;  // four 130² × 2 functions of 135 kB, not eight
    PhaseDatabase db(options);
    for (int i = 0; i < 8; ++i) {
        const PhaseLookup lookup =
            db.GetOrCompute(SyntheticKey("f" + std::to_string(i), PhaseKind::kBiDirectional, 3),
                            Counting(i, PhaseKind::kBiDirectional, 3).Function());
        EXPECT_EQ(lookup.source, PhaseSource::kComputed);
    }
    const PhaseDatabaseStats stats = db.Stats();
    EXPECT_GE(stats.stored, 2);
    EXPECT_GE(stats.writeErrors, 1);
    EXPECT_EQ(stats.stored + stats.writeErrors, 8);
    EXPECT_NE(stats.health.find("full"), std::string::npos) << stats.health;
    EXPECT_NE(stats.health.find(path), std::string::npos) << stats.health;
    for (int i = 0; i < 8; ++i) {
        EXPECT_EQ(
            db.GetOrCompute(SyntheticKey("f" + std::to_string(i), PhaseKind::kBiDirectional, 3), {})
                .source,
            PhaseSource::kMemory);
    }
    PhaseStore store(path, PhaseStoreMode::kReadOnly);
    EXPECT_TRUE(store.Verify().Ok());
    EXPECT_EQ(store.Stats().rows, stats.stored);
}

}  // namespace
}  // namespace leaflux
