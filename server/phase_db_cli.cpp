#include "server/phase_db_cli.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "server/cli_checks.h"
#include "solver/instancing/original_codec.h"
#include "solver/instancing/phase_db.h"
#include "solver/instancing/phase_store.h"

namespace leaflux {
namespace {

int RunStats(PhaseStore& store) {
    const PhaseFileStats stats = store.Stats();
    std::printf("file            %s\n", store.Path().c_str());
    std::printf("schema version  %d\n", stats.schemaVersion);
    std::printf("functions       %lld\n", static_cast<long long>(stats.rows));
    for (const auto& [kind, rows] : stats.rowsByKind) {
        std::printf("  %-13s %lld\n", kind.c_str(), static_cast<long long>(rows));
    }
    std::printf("size            %.3f MB (%.3f MB of functions, %lld free pages of %lld B)\n",
                stats.fileBytes / 1e6, stats.blobBytes / 1e6,
                static_cast<long long>(stats.freePages), static_cast<long long>(stats.pageSize));
    std::printf("write-ahead log %.3f MB\n", stats.walBytes / 1e6);
    return 0;
}

int RunList(PhaseStore& store, bool keysOnly) {
    const std::vector<PhaseRowInfo> rows = store.List();
    if (keysOnly) {
        for (const PhaseRowInfo& row : rows) std::printf("%s\n", row.key.c_str());
        return 0;
    }
    std::printf("%6s %-8s %5s %-12s %-12s %-28s %8s %10s %9s %9s  %s\n", "id", "kind", "level",
                "bands", "species", "signature", "leaves", "accuracy", "compute_s", "kB",
                "stored (UTC)");
    for (const PhaseRowInfo& row : rows) {
        std::printf("%6lld %-8s %5d %-12s %-12s %-28s %8lld %10.4g %9.3f %9.1f  %s\n",
                    static_cast<long long>(row.id), row.kind.c_str(), row.directionLevel,
                    row.bands.c_str(), row.species.c_str(), row.signature.c_str(),
                    static_cast<long long>(row.leafCount), row.accuracy, row.computeSeconds,
                    row.blobBytes / 1e3, row.storedUtc.c_str());
    }
    return 0;
}

int RunVerify(PhaseStore& store) {
    const PhaseVerifyReport report = store.Verify();
    for (const std::string& line : report.integrity) std::printf("integrity: %s\n", line.c_str());
    for (std::size_t i = 0; i < report.badRows.size(); ++i) {
        std::printf("bad row %lld (%s): %s\n", static_cast<long long>(report.badRows[i].id),
                    report.badRows[i].key.c_str(), report.badReasons[i].c_str());
    }
    std::printf("%lld rows, %zu bad: %s\n", static_cast<long long>(report.rows),
                report.badRows.size(), report.Ok() ? "sound" : "DAMAGED");
    return report.Ok() ? 0 : 1;
}

int RunCompact(PhaseStore& store) {
    const PhaseFileStats before = store.Stats();
    store.Compact();
    const PhaseFileStats after = store.Stats();
    std::printf("%s: %.3f MB + %.3f MB of log before, %.3f MB after\n", store.Path().c_str(),
                before.fileBytes / 1e6, before.walBytes / 1e6, after.fileBytes / 1e6);
    return 0;
}

// The row's band names, split at the commas JoinBands wrote; indices when they do not fit.
std::vector<std::string> BandNames(const std::string& joined, int bands) {
    std::vector<std::string> names;
    for (std::size_t start = 0;;) {
        const std::size_t comma = joined.find(',', start);
        names.push_back(joined.substr(start, comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    if (static_cast<int>(names.size()) != bands) {
        names.clear();
        for (int b = 0; b < bands; ++b) names.push_back(std::to_string(b));
    }
    return names;
}

// One line per value: τ per direction, then f per incoming, outgoing direction and band
// (the columns a coarser kind does not follow are left empty).
void WriteFunctionCsv(std::ostream& out, const Original& original,
                      const std::vector<std::string>& bands) {
    out << "quantity,incoming,incoming_x,incoming_y,incoming_z,outgoing,outgoing_x,outgoing_y,"
           "outgoing_z,band,value\n";
    const auto direction = [&](const DirectionSet& set, int i) {
        const glm::dvec3& d = set.Direction(i);
        out << i << ',' << d.x << ',' << d.y << ',' << d.z << ',';
    };
    out.precision(9);  // every float exactly
    const SphereFunction& tau = original.transmittance;
    for (int d = 0; !tau.Empty() && d < tau.Directions().Size(); ++d) {
        out << "tau,";
        direction(tau.Directions(), d);
        out << ",,,,," << tau.At(d, 0) << '\n';
    }
    const PhaseFunction& f = original.phase;
    if (f.Empty()) return;
    const std::span<const float> values = f.Values();
    const int n = f.Directions().Size();
    const int incoming = f.Kind() == PhaseKind::kConstant ? 1 : n;
    const int outgoing = f.Kind() == PhaseKind::kBiDirectional ? n : 1;
    for (int i = 0; i < incoming; ++i) {
        for (int o = 0; o < outgoing; ++o) {
            for (int b = 0; b < f.Bands(); ++b) {
                out << "f,";
                if (f.Kind() == PhaseKind::kConstant)
                    out << ",,,,";
                else
                    direction(f.Directions(), i);
                if (f.Kind() == PhaseKind::kBiDirectional)
                    direction(f.Directions(), o);
                else
                    out << ",,,,";
                out << bands[b] << ','
                    << values[(static_cast<std::size_t>(i) * outgoing + o) * f.Bands() + b] << '\n';
            }
        }
    }
}

int RunExport(PhaseStore& store, const std::string& key, std::int64_t id, const std::string& path) {
    const std::optional<PhaseRow> row = key.empty() ? store.FindById(id) : store.Find(key);
    const std::string what =
        store.Path() + (key.empty() ? " row " + std::to_string(id) : " key " + key);
    if (!row) throw InputError(ErrorCode::kNotFound, what, "no such function");
    if (!row->checksumOk)
        throw InputError(ErrorCode::kParse, what, "its checksum does not match its contents");
    const Original original = DecodeOriginal(row->blob, what);
    const std::vector<std::string> bands = BandNames(row->info.bands, original.phase.Bands());
    if (path == "-") {
        WriteFunctionCsv(std::cout, original, bands);
        return 0;
    }
    std::ofstream out(path);
    if (!out) throw InputError(ErrorCode::kIo, path, "cannot write");
    WriteFunctionCsv(out, original, bands);
    if (!out) throw InputError(ErrorCode::kIo, path, "cannot write");
    std::fprintf(stderr, "wrote %s: %s %s, row %lld\n", path.c_str(), row->info.kind.c_str(),
                 row->info.signature.c_str(), static_cast<long long>(row->info.id));
    return 0;
}

}  // namespace

PhaseDbCli::PhaseDbCli(CLI::App& parent) {
    path_ = DefaultPhaseDatabasePath();
    app_ = parent.add_subcommand(
        "phase-db",
        "Inspect the phase-function database: the originals (phase function f and "
        "transmittance τ of a signature) leafluxd computed and kept");
    app_->require_subcommand(1);
    app_->fallthrough();  // `phase-db verify --db PATH` as well as `phase-db --db PATH verify`
    app_->add_option("--db", path_, "The database file")->capture_default_str();
    stats_ = app_->add_subcommand("stats", "Functions by kind, file and log sizes");
    list_ = app_->add_subcommand(
        "list",
        "One line per function: id, kind, level, bands, species, signature, leaves, "
        "accuracy, compute time, size, when stored");
    list_->add_flag("--keys", keysOnly_, "Only the full keys, one a line");
    verify_ = app_->add_subcommand(
        "verify", "PRAGMA integrity_check and every row's checksum; exit status 1 when damaged");
    compact_ = app_->add_subcommand("compact", "Checkpoint the log and VACUUM the file");
    export_ = app_->add_subcommand(
        "export",
        "One function as CSV for plotting: quantity (tau or f), incoming direction "
        "(index, x, y, z), outgoing direction, band, value");
    auto* select = export_->add_option_group("function", "Which function");
    select->add_option("--key", key_, "Its full key (as `list --keys` prints it)");
    select->add_option("--id", id_, "Its row id (as `list` prints it)");
    select->require_option(1);
    export_->add_option("--out", out_, "CSV file (its folder is made; '-': standard output)")
        ->capture_default_str();
}

bool PhaseDbCli::Parsed() const { return app_->parsed(); }

int PhaseDbCli::Run() const {
    if (compact_->parsed()) {
        PhaseStore store(path_, PhaseStoreMode::kExisting);
        return RunCompact(store);
    }
    // As every --out: its folder made and the file checked before the database is read.
    if (export_->parsed() && out_ != "-") CheckWritable(out_, "--out");
    PhaseStore store(path_, PhaseStoreMode::kReadOnly);
    if (stats_->parsed()) return RunStats(store);
    if (list_->parsed()) return RunList(store, keysOnly_);
    if (verify_->parsed()) return RunVerify(store);
    return RunExport(store, key_, id_, out_);
}

}  // namespace leaflux
