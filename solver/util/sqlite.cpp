#include "solver/util/sqlite.h"

#include <algorithm>

namespace leaflux {

SqliteError::SqliteError(const std::string& path, int resultCode, const std::string& message)
    : InputError(ErrorCode::kIo, path, message), resultCode_(resultCode) {}

SqliteConnection::SqliteConnection(const std::string& path, int flags) : path_(path) {
    const int rc = sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_NOMUTEX, nullptr);
    if (rc != SQLITE_OK) {
        const std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
        sqlite3_close(db_);
        db_ = nullptr;
        throw SqliteError(path, rc, "cannot open: " + message);
    }
    sqlite3_extended_result_codes(db_, 1);
}

SqliteConnection::~SqliteConnection() { sqlite3_close(db_); }

void SqliteConnection::Fail(int resultCode, std::string_view what) const {
    std::string message = std::string(what) + ": " + sqlite3_errmsg(db_);
    if (const std::string_view code = sqlite3_errstr(resultCode);
        message.find(code) == message.npos)
        message += " (" + std::string(code) + ")";
    throw SqliteError(path_, resultCode, message);
}

void SqliteConnection::Execute(const std::string& sql) {
    char* message = nullptr;
    const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message);
    if (rc != SQLITE_OK) {
        const std::string text = message ? message : sqlite3_errstr(rc);
        sqlite3_free(message);
        throw SqliteError(path_, rc, "`" + sql + "`: " + text);
    }
}

std::int64_t SqliteConnection::QueryInt(const std::string& sql) {
    SqliteStatement statement(*this, sql);
    return statement.Step() ? statement.Int(0) : 0;
}

SqliteStatement::SqliteStatement(SqliteConnection& connection, const std::string& sql)
    : connection_(connection) {
    const int rc = sqlite3_prepare_v2(connection.Handle(), sql.c_str(),
                                      static_cast<int>(sql.size()), &statement_, nullptr);
    if (rc != SQLITE_OK) connection.Fail(rc, "`" + sql + "`");
}

SqliteStatement::~SqliteStatement() { sqlite3_finalize(statement_); }

SqliteStatement& SqliteStatement::Bind(int index, std::string_view text) {
    const int rc = sqlite3_bind_text(statement_, index, text.data(), static_cast<int>(text.size()),
                                     SQLITE_TRANSIENT);
    if (rc != SQLITE_OK) connection_.Fail(rc, "bind");
    return *this;
}

SqliteStatement& SqliteStatement::Bind(int index, std::int64_t value) {
    const int rc = sqlite3_bind_int64(statement_, index, value);
    if (rc != SQLITE_OK) connection_.Fail(rc, "bind");
    return *this;
}

SqliteStatement& SqliteStatement::Bind(int index, double value) {
    const int rc = sqlite3_bind_double(statement_, index, value);
    if (rc != SQLITE_OK) connection_.Fail(rc, "bind");
    return *this;
}

SqliteStatement& SqliteStatement::Bind(int index, std::span<const std::uint8_t> blob) {
    // A zero-length blob is still a blob, not NULL.
    const int rc = blob.empty() ? sqlite3_bind_zeroblob(statement_, index, 0)
                                : sqlite3_bind_blob64(statement_, index, blob.data(), blob.size(),
                                                      SQLITE_TRANSIENT);
    if (rc != SQLITE_OK) connection_.Fail(rc, "bind");
    return *this;
}

bool SqliteStatement::Step() {
    const int rc = sqlite3_step(statement_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    sqlite3_reset(statement_);
    // Named by its first words ("INSERT INTO phase_functions"), not its whole text.
    std::string_view sql = sqlite3_sql(statement_);
    sql.remove_prefix(std::min(sql.find_first_not_of(" \n"), sql.size()));
    sql = sql.substr(0, std::min<std::size_t>(sql.find_first_of("(\n"), 48));
    connection_.Fail(rc, sql.substr(0, sql.find_last_not_of(' ') + 1));
}

std::int64_t SqliteStatement::Int(int column) const {
    return sqlite3_column_int64(statement_, column);
}
double SqliteStatement::Real(int column) const { return sqlite3_column_double(statement_, column); }
std::string SqliteStatement::Text(int column) const {
    const auto* text = sqlite3_column_text(statement_, column);
    return text ? std::string(reinterpret_cast<const char*>(text),
                              static_cast<std::size_t>(sqlite3_column_bytes(statement_, column)))
                : std::string();
}
std::vector<std::uint8_t> SqliteStatement::Blob(int column) const {
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(statement_, column));
    const int bytes = sqlite3_column_bytes(statement_, column);
    return data ? std::vector<std::uint8_t>(data, data + bytes) : std::vector<std::uint8_t>();
}
bool SqliteStatement::IsNull(int column) const {
    return sqlite3_column_type(statement_, column) == SQLITE_NULL;
}

}  // namespace leaflux
