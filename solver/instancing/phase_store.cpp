#include "solver/instancing/phase_store.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "solver/instancing/original.h"
#include "solver/instancing/original_codec.h"
#include "solver/util/content_hash.h"

namespace leaflux {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE phase_functions (
    id INTEGER PRIMARY KEY,
    key TEXT NOT NULL UNIQUE,
    key_hash TEXT NOT NULL,
    species TEXT NOT NULL,
    signature TEXT NOT NULL,
    policy_hash TEXT NOT NULL,
    optics_hash TEXT NOT NULL,
    bands TEXT NOT NULL,
    kind TEXT NOT NULL,
    direction_level INTEGER NOT NULL,
    code_version INTEGER NOT NULL,
    representative TEXT NOT NULL,
    leaf_count INTEGER NOT NULL,
    accuracy REAL NOT NULL,
    compute_seconds REAL NOT NULL,
    blob BLOB NOT NULL,
    checksum TEXT NOT NULL,
    stored_utc TEXT NOT NULL DEFAULT (datetime('now'))
);)sql";

// The columns of PhaseRowInfo, then the checksum and the blob, in ReadRow's order.
constexpr const char* kRowColumns =
    "id, key, species, signature, kind, bands, direction_level, code_version, representative, "
    "leaf_count, accuracy, compute_seconds, length(blob), stored_utc";

PhaseRowInfo ReadInfo(const SqliteStatement& row) {
    PhaseRowInfo info;
    info.id = row.Int(0);
    info.key = row.Text(1);
    info.species = row.Text(2);
    info.signature = row.Text(3);
    info.kind = row.Text(4);
    info.bands = row.Text(5);
    info.directionLevel = static_cast<int>(row.Int(6));
    info.codeVersion = static_cast<int>(row.Int(7));
    info.representative = row.Text(8);
    info.leafCount = row.Int(9);
    info.accuracy = row.Real(10);
    info.computeSeconds = row.Real(11);
    info.blobBytes = row.Int(12);
    info.storedUtc = row.Text(13);
    return info;
}

PhaseRow ReadRow(const SqliteStatement& row) {
    PhaseRow out{ReadInfo(row), row.Blob(15), false};
    out.checksumOk = row.Text(14) == PhaseRowChecksum(out.info.key, out.blob);
    return out;
}

std::int32_t BigEndian32(const unsigned char* p) {
    return static_cast<std::int32_t>((std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) |
                                     (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]});
}

// The schema version a file holds, refused unless it is this leaflux's.
void CheckVersion(const std::string& path, std::int64_t version) {
    if (version > kPhaseSchemaVersion)
        throw InputError(ErrorCode::kUnsupported, path,
                         "a phase database of schema version " + std::to_string(version) +
                             ", newer than this leaflux's " + std::to_string(kPhaseSchemaVersion) +
                             " (written by a newer leaflux); it is left as it is");
    if (version < kPhaseSchemaVersion)
        throw InputError(ErrorCode::kUnsupported, path,
                         "a phase database of unknown schema version " + std::to_string(version) +
                             "; it is left as it is");
}

// Refuses, before SQLite opens it, a file that is not one of ours or is newer: SQLite's
// header holds the application id at byte 68 and the user version at byte 60.
void CheckHeader(const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
        throw InputError(ErrorCode::kIo, path, "not a regular file; it is left as it is");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(ErrorCode::kIo, path, "cannot be read: " + std::string(strerror(errno)));
    unsigned char header[100] = {};
    in.read(reinterpret_cast<char*>(header), sizeof header);
    const std::streamsize got = in.gcount();
    if (got == 0)
        throw InputError(ErrorCode::kParse, path,
                         "an empty file, not a leaflux phase database; it is left as it is");
    if (got < static_cast<std::streamsize>(sizeof header) ||
        std::memcmp(header, "SQLite format 3", 16) != 0)
        throw InputError(ErrorCode::kParse, path,
                         "not an SQLite database, so not a leaflux phase database; it is left "
                         "as it is");
    if (const std::int32_t id = BigEndian32(header + 68); id != kPhaseApplicationId) {
        char text[96];
        std::snprintf(text, sizeof text,
                      "an SQLite database of another application (id 0x%08x, "
                      "leaflux's is 0x%08x)",
                      static_cast<unsigned>(id), static_cast<unsigned>(kPhaseApplicationId));
        throw InputError(ErrorCode::kParse, path,
                         std::string(text) + ", not a leaflux phase database; it is left as it is");
    }
    CheckVersion(path, BigEndian32(header + 60));
}

// The header may lag a WAL not yet checkpointed: the connection's view is the truth.
void CheckSchemaVersion(SqliteConnection& connection) {
    const std::int64_t id = connection.QueryInt("PRAGMA application_id");
    if (id != kPhaseApplicationId)
        throw InputError(ErrorCode::kParse, connection.Path(),
                         "not a leaflux phase database (application id " + std::to_string(id) +
                             "); it is left as it is");
    CheckVersion(connection.Path(), connection.QueryInt("PRAGMA user_version"));
}

// Builds a complete empty database beside `path` and moves it into place without ever
// replacing a file: if another process got there first, its file is kept.
void CreateDatabase(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ignored;  // a directory that cannot be made fails the open below
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty()) fs::create_directories(parent, ignored);
    static std::atomic<int> counter{0};
    const std::string temporary =
        path + ".new-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    try {
        SqliteConnection connection(temporary, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        connection.Execute("PRAGMA application_id = " + std::to_string(kPhaseApplicationId));
        connection.Execute("PRAGMA user_version = " + std::to_string(kPhaseSchemaVersion));
        connection.Execute(kSchema);
        connection.Execute("PRAGMA journal_mode = WAL");
    }  // closing checkpoints the WAL into the file and removes it
    catch (const SqliteError& e) {
        ::unlink(temporary.c_str());
        throw InputError(ErrorCode::kIo, path, std::string("cannot be created: ") + e.what());
    }
    int rc = ::renameat2(AT_FDCWD, temporary.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE);
    if (rc != 0 && errno == EINVAL) rc = ::link(temporary.c_str(), path.c_str());  // no renameat2
    const int error = rc == 0 ? 0 : errno;
    ::unlink(temporary.c_str());  // gone after a rename; after a link or a loss, not needed
    // EEXIST: another process made it meanwhile, and its file is the one kept.
    if (error != 0 && error != EEXIST)
        throw InputError(ErrorCode::kIo, path,
                         std::string("cannot be created: ") + strerror(error));
}

}  // namespace

std::string PhaseRowChecksum(const std::string& key, std::span<const std::uint8_t> blob) {
    return ContentHash().Add(key).Add(blob).Hex();
}

PhaseStore::PhaseStore(const std::string& path, PhaseStoreMode mode, double diskCapMb) {
    if (!std::filesystem::exists(path)) {
        if (mode != PhaseStoreMode::kCreate)
            throw InputError(ErrorCode::kNotFound, path, "no phase database there");
        CreateDatabase(path);
    }
    CheckHeader(path);
    {  // looked at read-only first: a refused file is not even opened for writing
        SqliteConnection inspection(path, SQLITE_OPEN_READONLY);
        sqlite3_busy_timeout(inspection.Handle(), 5000);
        CheckSchemaVersion(inspection);
    }
    connection_ = std::make_unique<SqliteConnection>(
        path, mode == PhaseStoreMode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE);
    // Another process (the daemon, the command line) may be writing: wait for it.
    sqlite3_busy_timeout(connection_->Handle(), 5000);
    if (Writable()) {
        connection_->Execute("PRAGMA journal_mode = WAL");
        // In WAL mode NORMAL loses no committed transaction when the process dies, only
        // (after a power cut) the last few, which the database recomputes: it is a cache.
        connection_->Execute("PRAGMA synchronous = NORMAL");
        if (diskCapMb > 0.0) {
            const std::int64_t pageSize = connection_->QueryInt("PRAGMA page_size");
            const auto pages = static_cast<std::int64_t>(std::ceil(diskCapMb * 1e6 / pageSize));
            connection_->Execute("PRAGMA max_page_count = " + std::to_string(pages));
        }
    }
}

std::optional<PhaseRow> PhaseStore::FindWhere(const std::string& where, const auto& bind) {
    SqliteStatement select(*connection_, std::string("SELECT ") + kRowColumns +
                                             ", checksum, blob FROM phase_functions WHERE " +
                                             where);
    bind(select);
    if (!select.Step()) return std::nullopt;
    return ReadRow(select);
}

std::optional<PhaseRow> PhaseStore::Find(const std::string& canonicalKey) {
    return FindWhere("key = ?", [&](SqliteStatement& s) { s.Bind(1, canonicalKey); });
}

std::optional<PhaseRow> PhaseStore::FindById(std::int64_t id) {
    return FindWhere("id = ?", [&](SqliteStatement& s) { s.Bind(1, id); });
}

void PhaseStore::Put(const PhaseKey& key, const Original& original,
                     std::span<const std::uint8_t> blob) {
    const std::string canonical = key.Canonical();
    // One statement, so one transaction: the row is there whole or not at all.
    SqliteStatement insert(*connection_, R"sql(
INSERT INTO phase_functions (key, key_hash, species, signature, policy_hash, optics_hash, bands,
    kind, direction_level, code_version, representative, leaf_count, accuracy,
    compute_seconds, blob, checksum)
VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16)
ON CONFLICT (key) DO UPDATE SET key_hash = excluded.key_hash,
    representative = excluded.representative, leaf_count = excluded.leaf_count,
    accuracy = excluded.accuracy, compute_seconds = excluded.compute_seconds,
    blob = excluded.blob, checksum = excluded.checksum, stored_utc = datetime('now'))sql");
    const OriginalProvenance& p = original.provenance;
    insert.Bind(1, canonical)
        .Bind(2, key.HashHex())
        .Bind(3, key.species)
        .Bind(4, key.signature)
        .Bind(5, key.policyHash)
        .Bind(6, key.opticsHash)
        .Bind(7, JoinBands(key.bands))
        .Bind(8, std::string_view(PhaseKindName(key.kind)))
        .Bind(9, std::int64_t{key.directionLevel})
        .Bind(10, std::int64_t{key.codeVersion})
        .Bind(11, p.representative)
        .Bind(12, p.leafCount)
        .Bind(13, p.accuracy)
        .Bind(14, p.computeSeconds)
        .Bind(15, blob)
        .Bind(16, PhaseRowChecksum(canonical, blob));
    insert.Run();
}

std::vector<PhaseRowInfo> PhaseStore::List() {
    SqliteStatement select(
        *connection_, std::string("SELECT ") + kRowColumns + " FROM phase_functions ORDER BY id");
    std::vector<PhaseRowInfo> rows;
    while (select.Step()) rows.push_back(ReadInfo(select));
    return rows;
}

PhaseVerifyReport PhaseStore::Verify() {
    PhaseVerifyReport report;
    // A damaged page may stop either scan: that is a finding, not a failure to verify.
    try {
        SqliteStatement integrity(*connection_, "PRAGMA integrity_check");
        while (integrity.Step()) report.integrity.push_back(integrity.Text(0));
    } catch (const SqliteError& e) {
        report.integrity.push_back(std::string("integrity_check stopped: ") + e.what());
    }
    try {
        SqliteStatement select(*connection_,
                               std::string("SELECT ") + kRowColumns +
                                   ", checksum, blob FROM phase_functions ORDER BY id");
        while (select.Step()) {
            ++report.rows;
            PhaseRow row = ReadRow(select);
            std::string reason;
            if (!row.checksumOk) {
                reason = "checksum mismatch";
            } else {
                try {
                    DecodeOriginal(row.blob, Path() + " row " + std::to_string(row.info.id));
                } catch (const InputError& e) {
                    reason = e.what();
                }
            }
            if (!reason.empty()) {
                report.badRows.push_back(std::move(row.info));
                report.badReasons.push_back(std::move(reason));
            }
        }
    } catch (const SqliteError& e) {
        report.integrity.push_back(std::string("the rows' scan stopped: ") + e.what());
    }
    return report;
}

void PhaseStore::Checkpoint() { connection_->Execute("PRAGMA wal_checkpoint(TRUNCATE)"); }

void PhaseStore::Compact() {
    Checkpoint();
    connection_->Execute("VACUUM");
}

PhaseFileStats PhaseStore::Stats() {
    PhaseFileStats stats;
    stats.rows = connection_->QueryInt("SELECT count(*) FROM phase_functions");
    stats.pageSize = connection_->QueryInt("PRAGMA page_size");
    stats.fileBytes = connection_->QueryInt("PRAGMA page_count") * stats.pageSize;
    stats.freePages = connection_->QueryInt("PRAGMA freelist_count");
    stats.blobBytes =
        connection_->QueryInt("SELECT coalesce(sum(length(blob)), 0) FROM phase_functions");
    stats.schemaVersion = static_cast<std::int32_t>(connection_->QueryInt("PRAGMA user_version"));
    std::error_code error;
    const auto wal = std::filesystem::file_size(Path() + "-wal", error);
    stats.walBytes = error ? 0 : static_cast<std::int64_t>(wal);
    SqliteStatement kinds(*connection_,
                          "SELECT kind, count(*) FROM phase_functions GROUP BY kind ORDER BY kind");
    while (kinds.Step()) stats.rowsByKind.emplace_back(kinds.Text(0), kinds.Int(1));
    return stats;
}

}  // namespace leaflux
