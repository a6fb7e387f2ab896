// Small RAII handles over the SQLite C API: a connection and a prepared statement. Every
// failure is an InputError naming the database file and saying what SQLite said, with the
// SQLite result code kept so that callers can tell a full disk from a read-only file.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "solver/util/error.h"

namespace leaflux {

// An InputError from SQLite: Field() is the database file.
class SqliteError : public InputError {
  public:
    SqliteError(const std::string& path, int resultCode, const std::string& message);
    int ResultCode() const { return resultCode_; }  // SQLITE_FULL, SQLITE_READONLY, …

  private:
    int resultCode_;
};

// One connection. Invariant: db_ is open for the handle's lifetime; moving hands it over.
class SqliteConnection {
  public:
    // sqlite3_open_v2 with `flags` (SQLITE_OPEN_READONLY, SQLITE_OPEN_READWRITE, …).
    SqliteConnection(const std::string& path, int flags);
    ~SqliteConnection();
    SqliteConnection(const SqliteConnection&) = delete;
    SqliteConnection& operator=(const SqliteConnection&) = delete;

    sqlite3* Handle() const { return db_; }
    const std::string& Path() const { return path_; }
    // Runs statements that return no rows we need (pragmas that set, DDL, BEGIN/COMMIT).
    void Execute(const std::string& sql);
    // The first column of the first row of `sql`, as an integer (0 when no row).
    std::int64_t QueryInt(const std::string& sql);
    bool ReadOnly() const { return sqlite3_db_readonly(db_, "main") == 1; }
    // Throws SqliteError for `resultCode` with the connection's message, naming `what`.
    [[noreturn]] void Fail(int resultCode, std::string_view what) const;

  private:
    std::string path_;
    sqlite3* db_ = nullptr;
};

// A prepared statement of one connection; bind indices start at 1, columns at 0.
class SqliteStatement {
  public:
    SqliteStatement(SqliteConnection& connection, const std::string& sql);
    ~SqliteStatement();
    SqliteStatement(const SqliteStatement&) = delete;
    SqliteStatement& operator=(const SqliteStatement&) = delete;

    SqliteStatement& Bind(int index, std::string_view text);
    SqliteStatement& Bind(int index, std::int64_t value);
    SqliteStatement& Bind(int index, double value);
    SqliteStatement& Bind(int index, std::span<const std::uint8_t> blob);
    // True while a row is there to read; false when done. Throws on errors.
    bool Step();
    void Run() {
        while (Step()) {
        }
    }  // a statement whose rows are not read

    std::int64_t Int(int column) const;
    double Real(int column) const;
    std::string Text(int column) const;
    std::vector<std::uint8_t> Blob(int column) const;
    bool IsNull(int column) const;

  private:
    SqliteConnection& connection_;
    sqlite3_stmt* statement_ = nullptr;
};

}  // namespace leaflux
