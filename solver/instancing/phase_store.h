// The phase-function database's file: originals persisted in an embedded SQLite database
// (Soler 2003 §5), so that a restarted process reuses what it knew.
//
// Invariants: every write is one transaction (WAL journal), so a process killed at any
// moment leaves the rows committed before it; every row carries a checksum over its key and
// blob, checked on every read. A file the store did not create is never modified: one that
// is not SQLite, or is SQLite of another application, or holds a newer schema, is refused
// with an InputError naming it. A new file is built beside its path and linked into place
// only once complete, so a kill during creation leaves no half-made database.
//
// Not thread-safe: its owner (PhaseDatabase) serialises calls.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "solver/instancing/phase_key.h"
#include "solver/util/sqlite.h"

namespace leaflux {

struct Original;

// PRAGMA application_id of leaflux phase databases ("LFPH") and the schema version held
// in PRAGMA user_version.
inline constexpr std::int32_t kPhaseApplicationId = 0x4C465048;
inline constexpr std::int32_t kPhaseSchemaVersion = 1;

enum class PhaseStoreMode {
    kCreate,    // read and write; a missing file is created
    kExisting,  // read and write; a missing file is an error
    kReadOnly,  // never writes, never creates (the command line's inspections)
};

// A row as listed: its metadata, not its functions.
struct PhaseRowInfo {
    std::int64_t id = 0;
    std::string key;  // PhaseKey::Canonical()
    std::string species, signature, kind, bands;
    int directionLevel = 0;
    int codeVersion = 0;
    std::string representative;
    std::int64_t leafCount = 0;
    double accuracy = 0.0;
    double computeSeconds = 0.0;
    std::int64_t blobBytes = 0;
    std::string storedUtc;  // "2026-12-01 18:00:00"
};

// A row as read: the blob and whether its checksum matches.
struct PhaseRow {
    PhaseRowInfo info;
    std::vector<std::uint8_t> blob;
    bool checksumOk = false;
};

struct PhaseVerifyReport {
    std::vector<std::string> integrity;  // PRAGMA integrity_check: {"ok"} when sound
    std::int64_t rows = 0;
    std::vector<PhaseRowInfo> badRows;  // bad checksum or an undecodable blob
    std::vector<std::string> badReasons;
    bool Ok() const { return integrity.size() == 1 && integrity[0] == "ok" && badRows.empty(); }
};

struct PhaseFileStats {
    std::int64_t rows = 0;
    std::int64_t fileBytes = 0;  // the database file, without its WAL
    std::int64_t walBytes = 0;
    std::int64_t blobBytes = 0;  // sum of the stored blobs
    std::int64_t freePages = 0, pageSize = 0;
    std::int32_t schemaVersion = 0;
    std::vector<std::pair<std::string, std::int64_t>> rowsByKind;
};

// The checksum of a row: ContentHash over its canonical key and blob, 16 hex digits.
std::string PhaseRowChecksum(const std::string& key, std::span<const std::uint8_t> blob);

class PhaseStore {
  public:
    // Throws InputError naming `path`: kParse for a foreign file, kUnsupported for a newer
    // schema, kIo when it cannot be opened or created, kNotFound for a missing file unless
    // kCreate. `diskCapMb` (10⁶ bytes, 0: none) caps the file: a write beyond it fails as on
    // a full disk.
    PhaseStore(const std::string& path, PhaseStoreMode mode, double diskCapMb = 0.0);

    const std::string& Path() const { return connection_->Path(); }
    // False when the file or its directory cannot be written (or kReadOnly).
    bool Writable() const { return !connection_->ReadOnly(); }

    std::optional<PhaseRow> Find(const std::string& canonicalKey);
    std::optional<PhaseRow> FindById(std::int64_t id);
    // Inserts or replaces the row of `key` in one transaction. Throws SqliteError (its
    // ResultCode() tells SQLITE_FULL from SQLITE_READONLY) and leaves the file as it was.
    void Put(const PhaseKey& key, const Original& original, std::span<const std::uint8_t> blob);

    std::vector<PhaseRowInfo> List();
    // PRAGMA integrity_check and every row's checksum and blob.
    PhaseVerifyReport Verify();
    // Moves the WAL's committed rows into the file and empties the WAL.
    void Checkpoint();
    // Checkpoints the WAL and VACUUMs: the file shrinks to its rows.
    void Compact();
    PhaseFileStats Stats();

  private:
    std::optional<PhaseRow> FindWhere(const std::string& where, const auto& bind);

    std::unique_ptr<SqliteConnection> connection_;
};

}  // namespace leaflux
