#include "solver/instancing/phase_db.h"

#include <spdlog/spdlog.h>

#include <cstdlib>

#include "solver/instancing/original_codec.h"
#include "solver/util/user_directory.h"

namespace leaflux {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string DefaultPhaseDatabasePath() {
    return LeafluxDirectory("XDG_DATA_HOME", ".local/share", ".") + "/phase.db";
}

const char* PhaseSourceName(PhaseSource source) {
    switch (source) {
        case PhaseSource::kMemory:
            return "memory";
        case PhaseSource::kDisk:
            return "disk";
        case PhaseSource::kComputed:
            return "computed";
        case PhaseSource::kRecomputed:
            return "recomputed";
        case PhaseSource::kAwaited:
            return "awaited";
    }
    return "unknown";
}

PhaseDatabase::PhaseDatabase(PhaseDatabaseOptions options) : options_(std::move(options)) {
    if (options_.path.empty()) return;
    try {
        store_ = std::make_unique<PhaseStore>(options_.path, PhaseStoreMode::kCreate,
                                              options_.diskCapMb);
    } catch (const InputError& e) {
        if (!options_.degradeToMemory) throw;
        openError_ = lastError_ = e.what();
        spdlog::warn("phase database: {}; functions are kept in memory only", e.what());
        return;
    }
    if (!store_->Writable()) {
        lastError_ = options_.path +
                     " is read-only: functions are read from it, new ones are "
                     "kept in memory only";
        spdlog::warn("phase database: {}", lastError_);
    }
}

PhaseDatabase::~PhaseDatabase() = default;

PhaseLookup PhaseDatabase::GetOrCompute(const PhaseKey& key,
                                        const std::function<Original()>& compute) {
    const std::string canonical = key.Canonical();
    std::promise<PhaseLookup> promise;
    {
        std::unique_lock lock(mutex_);
        if (const auto found = byKey_.find(canonical); found != byKey_.end()) {
            lru_.splice(lru_.begin(), lru_, found->second);
            ++stats_.memoryHits;
            return {found->second->original, PhaseSource::kMemory};
        }
        if (const auto running = pending_.find(canonical); running != pending_.end()) {
            const Pending pending = running->second;
            ++stats_.awaited;
            lock.unlock();
            return {pending.get().original, PhaseSource::kAwaited};  // rethrows its failure
        }
        pending_.emplace(canonical, promise.get_future().share());
    }
    try {
        PhaseLookup result = LoadOrCompute(key, canonical, compute);
        {
            std::lock_guard lock(mutex_);
            Remember(canonical, result.original);
            pending_.erase(canonical);
        }
        promise.set_value(result);
        return result;
    } catch (...) {
        {
            std::lock_guard lock(mutex_);
            pending_.erase(canonical);
        }
        promise.set_exception(std::current_exception());
        throw;
    }
}

PhaseLookup PhaseDatabase::LoadOrCompute(const PhaseKey& key, const std::string& canonical,
                                         const std::function<Original()>& compute) {
    bool badRow = false;
    if (store_) {
        if (auto loaded = Load(canonical, badRow)) return {std::move(loaded), PhaseSource::kDisk};
    }
    if (!badRow) {
        std::lock_guard lock(mutex_);
        ++stats_.misses;
    }
    const auto start = std::chrono::steady_clock::now();
    auto original = std::make_shared<const Original>(compute());
    {
        std::lock_guard lock(mutex_);
        ++stats_.computed;
        stats_.computeSeconds += SecondsSince(start);
    }
    if (store_) Store(key, *original);
    return {std::move(original), badRow ? PhaseSource::kRecomputed : PhaseSource::kComputed};
}

std::shared_ptr<const Original> PhaseDatabase::Load(const std::string& canonical, bool& badRow) {
    const auto start = std::chrono::steady_clock::now();
    std::optional<PhaseRow> row;
    try {
        std::lock_guard storeLock(storeMutex_);
        row = store_->Find(canonical);
    } catch (const InputError& e) {
        NoteError(&PhaseDatabaseStats::readErrors,
                  std::string(e.what()) + "; computing the function instead");
        return nullptr;
    }
    if (!row) {
        std::lock_guard lock(mutex_);
        stats_.loadSeconds += SecondsSince(start);
        return nullptr;
    }
    const std::string where = options_.path + " row " + std::to_string(row->info.id);
    try {
        if (!row->checksumOk)
            throw InputError(ErrorCode::kParse, where, "its checksum does not match its contents");
        auto original = std::make_shared<const Original>(DecodeOriginal(row->blob, where));
        std::lock_guard lock(mutex_);
        ++stats_.diskHits;
        stats_.loadSeconds += SecondsSince(start);
        return original;
    } catch (const InputError& e) {
        badRow = true;
        NoteError(&PhaseDatabaseStats::badRows,
                  std::string(e.what()) + " (key " + canonical + "); recomputing it");
        return nullptr;
    }
}

void PhaseDatabase::Store(const PhaseKey& key, const Original& original) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<std::uint8_t> blob = EncodeOriginal(original);
    try {
        std::lock_guard storeLock(storeMutex_);
        store_->Put(key, original, blob);
    } catch (const InputError& e) {
        NoteError(&PhaseDatabaseStats::writeErrors,
                  std::string(e.what()) + "; the function is kept in memory only");
        return;
    }
    std::lock_guard lock(mutex_);
    ++stats_.stored;
    stats_.storeSeconds += SecondsSince(start);
}

void PhaseDatabase::Remember(const std::string& canonical,
                             std::shared_ptr<const Original> original) {
    const auto capBytes = static_cast<std::size_t>(options_.memoryCapMb * 1e6);
    const std::size_t bytes = OriginalBytes(*original);
    if (bytes > capBytes) return;  // larger than the whole buffer: its users hold it
    lru_.push_front({canonical, std::move(original), bytes});
    byKey_[canonical] = lru_.begin();
    memoryBytes_ += bytes;
    while (memoryBytes_ > capBytes) {
        const Entry& oldest = lru_.back();
        memoryBytes_ -= oldest.bytes;
        byKey_.erase(oldest.key);
        lru_.pop_back();
        ++stats_.evictions;
    }
}

void PhaseDatabase::NoteError(std::int64_t PhaseDatabaseStats::*counter,
                              const std::string& message) {
    std::lock_guard lock(mutex_);
    ++(stats_.*counter);
    // A full disk fails every write alike: say it once, count every one.
    if (message != lastError_) spdlog::warn("phase database: {}", message);
    lastError_ = message;
}

PhaseStore& PhaseDatabase::OpenStore() {
    if (!store_)
        throw InputError(
            ErrorCode::kNotFound, options_.path,
            openError_.empty() ? "no phase database file is open" : "not open: " + openError_);
    return *store_;
}

std::vector<PhaseRowInfo> PhaseDatabase::List() {
    std::lock_guard storeLock(storeMutex_);
    return OpenStore().List();
}

PhaseVerifyReport PhaseDatabase::Verify() {
    std::lock_guard storeLock(storeMutex_);
    return OpenStore().Verify();
}

PhaseFileStats PhaseDatabase::FileStats() {
    std::lock_guard storeLock(storeMutex_);
    return OpenStore().Stats();
}

void PhaseDatabase::Flush() {
    std::lock_guard storeLock(storeMutex_);
    if (!store_ || !store_->Writable()) return;
    try {
        store_->Checkpoint();
    } catch (const SqliteError& e) {
        NoteError(&PhaseDatabaseStats::writeErrors, e.what());
    }
}

void PhaseDatabase::Compact() {
    std::lock_guard storeLock(storeMutex_);
    OpenStore().Compact();
}

PhaseDatabaseStats PhaseDatabase::Stats() const {
    std::lock_guard lock(mutex_);
    PhaseDatabaseStats stats = stats_;
    stats.memoryBytes = static_cast<std::int64_t>(memoryBytes_);
    stats.memoryEntries = static_cast<std::int64_t>(lru_.size());
    stats.persistent = store_ != nullptr;
    stats.health = lastError_;
    return stats;
}

std::string PhaseDatabase::Health() const {
    std::lock_guard lock(mutex_);
    return lastError_;
}

}  // namespace leaflux
