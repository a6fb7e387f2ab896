// The phase-function database (Soler 2003 §5, "Instantiation Database"; DESIGN §3): the
// originals of the signatures met so far, found by PhaseKey, computed once when missing.
//
// Three tiers: an LRU buffer in memory capped in MB, then the SQLite file (PhaseStore),
// then the caller's computation. Concurrent requests for one missing key share one load or
// computation: the first runs it, the others wait for its result (or its exception, after
// which nothing is stored). A row read back is checked (checksum, decoding) and a bad one
// is reported, recomputed and overwritten, never returned. When the file cannot be opened
// (in the degrading mode) or written (read-only, full), the error is kept in Health() and
// the statistics, and the database goes on in memory, still reading what it can.
//
// Thread-safe. Returned originals are shared and immutable: eviction never frees one in use.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "solver/instancing/original.h"
#include "solver/instancing/phase_key.h"
#include "solver/instancing/phase_store.h"

namespace leaflux {

// $XDG_DATA_HOME/leaflux/phase.db, else ~/.local/share/leaflux/phase.db, else ./phase.db.
std::string DefaultPhaseDatabasePath();

struct PhaseDatabaseOptions {
    std::string path;            // "" keeps everything in memory
    double memoryCapMb = 256.0;  // the LRU buffer (10⁶ bytes of OriginalBytes)
    double diskCapMb = 0.0;      // the file (0: as large as the disk allows)
    // When the file cannot be opened (foreign, newer, unreadable): true goes on in memory
    // with the error in Health(), false throws it from the constructor.
    bool degradeToMemory = false;
};

enum class PhaseSource {
    kMemory,      // in the LRU buffer
    kDisk,        // read from the file
    kComputed,    // not known: computed (and stored when the file allows)
    kRecomputed,  // its stored row was bad: computed again and the row overwritten
    kAwaited,     // another request was loading or computing it: its result
};
const char* PhaseSourceName(PhaseSource source);

struct PhaseLookup {
    std::shared_ptr<const Original> original;
    PhaseSource source = PhaseSource::kMemory;
};

struct PhaseDatabaseStats {
    std::int64_t memoryHits = 0, diskHits = 0, awaited = 0;
    std::int64_t misses = 0;    // in neither memory nor the file (computed)
    std::int64_t computed = 0;  // misses + bad rows, the computations that finished
    std::int64_t badRows = 0;   // rows found corrupt, recomputed and overwritten
    std::int64_t stored = 0, writeErrors = 0, readErrors = 0, evictions = 0;
    // Summed over requests (s): reading and decoding rows, computing, encoding and writing.
    double loadSeconds = 0.0, computeSeconds = 0.0, storeSeconds = 0.0;
    std::int64_t memoryBytes = 0, memoryEntries = 0;  // the LRU buffer now (OriginalBytes)
    bool persistent = false;                          // a file is open
    std::string health;  // "" when sound, else the last open, read or write error
};

class PhaseDatabase {
  public:
    // Throws InputError naming the file when it cannot be opened, unless degradeToMemory.
    explicit PhaseDatabase(PhaseDatabaseOptions options);
    ~PhaseDatabase();

    // The original of `key`: from memory, else from the file, else `compute()` (run at most
    // once at a time per key, its result stored). Rethrows what compute throws. `compute`
    // must not ask for its own key: it would wait for itself.
    PhaseLookup GetOrCompute(const PhaseKey& key, const std::function<Original()>& compute);

    // The open file's rows, soundness and size, and its compaction (PhaseStore's, through
    // this database's connection). Throw InputError(kNotFound) when no file is open.
    std::vector<PhaseRowInfo> List();
    PhaseVerifyReport Verify();
    PhaseFileStats FileStats();
    void Compact();
    // Every row committed so far written into the file itself (its WAL checkpointed), as
    // before a process exits; waits for a write in progress. A failure is kept in Health().
    void Flush();

    PhaseDatabaseStats Stats() const;
    // "" when the file is open and every write so far succeeded; else what went wrong,
    // naming the file.
    std::string Health() const;
    // Why the file could not be opened ("" when it was, or no file was asked for).
    const std::string& OpenError() const { return openError_; }
    bool Persistent() const { return store_ != nullptr; }

  private:
    struct Entry {
        std::string key;
        std::shared_ptr<const Original> original;
        std::size_t bytes;
    };
    // A key's load or computation in progress, shared by the requests that wait for it.
    using Pending = std::shared_future<PhaseLookup>;

    PhaseLookup LoadOrCompute(const PhaseKey& key, const std::string& canonical,
                              const std::function<Original()>& compute);
    std::shared_ptr<const Original> Load(const std::string& canonical, bool& badRow);
    void Store(const PhaseKey& key, const Original& original);
    void Remember(const std::string& canonical, std::shared_ptr<const Original> original);
    void NoteError(std::int64_t PhaseDatabaseStats::*counter, const std::string& message);
    PhaseStore& OpenStore();  // throws when there is none

    PhaseDatabaseOptions options_;
    std::string openError_;

    mutable std::mutex mutex_;  // guards everything below but store_'s calls
    std::list<Entry> lru_;      // most recently used first
    std::unordered_map<std::string, std::list<Entry>::iterator> byKey_;
    std::size_t memoryBytes_ = 0;
    std::unordered_map<std::string, Pending> pending_;
    PhaseDatabaseStats stats_;
    std::string lastError_;

    std::mutex storeMutex_;  // one SQLite connection, one caller at a time
    std::unique_ptr<PhaseStore> store_;
};

}  // namespace leaflux
