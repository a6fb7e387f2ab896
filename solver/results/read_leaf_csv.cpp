#include "solver/results/read_leaf_csv.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <unordered_map>

#include "solver/util/error.h"

namespace leaflux {
namespace {

// One CSV record's fields: commas split them, double quotes protect commas and quotes
// ("" inside quotes is one quote), as CsvQuoted writes them.
std::vector<std::string> Fields(const std::string& line) {
    std::vector<std::string> fields(1);
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
            fields.back() += '"';
            ++i;
        } else if (c == '"') {
            quoted = !quoted;
        } else if (c == ',' && !quoted) {
            fields.emplace_back();
        } else {
            fields.back() += c;
        }
    }
    return fields;
}

}  // namespace

Solution ReadLeafCsv(const std::string& path, const Scene& scene, const FlatScene& flat) {
    std::ifstream in(path);
    if (!in) throw InputError(ErrorCode::kIo, path, "cannot open");
    std::string line;
    if (!std::getline(in, line)) throw InputError(ErrorCode::kParse, path + ":1", "empty file");
    const std::vector<std::string> header = Fields(line);
    const auto column = [&](const std::string& name) {
        for (std::size_t k = 0; k < header.size(); ++k)
            if (header[k] == name) return k;
        throw InputError(ErrorCode::kParse, path + ":1", "no column " + name);
    };
    const std::size_t organ = column("organ"), band = column("band"),
                      upper = column("irradiance_upper_wm2"),
                      lower = column("irradiance_lower_wm2"), absorbed = column("absorbed_w");

    std::unordered_map<std::string, std::uint32_t> receivers;
    for (std::uint32_t r = 0; r < flat.receivers.size(); ++r)
        receivers.emplace(ReceiverName(scene, flat.receivers[r]), r);
    std::unordered_map<std::string, int> bands;
    for (int b = 0; b < static_cast<int>(scene.bands.size()); ++b)
        bands.emplace(scene.bands[b].name, b);

    Solution solution;
    solution.light.assign(flat.receivers.size(), scene.bands.size());
    std::vector<std::uint8_t> seen(flat.receivers.size() * scene.bands.size(), 0);
    for (int number = 2; std::getline(in, line); ++number) {
        if (line.empty()) continue;
        const std::string where = path + ":" + std::to_string(number);
        const std::vector<std::string> fields = Fields(line);
        if (fields.size() != header.size()) {
            throw InputError(ErrorCode::kParse, where,
                             std::to_string(fields.size()) + " fields, the header has " +
                                 std::to_string(header.size()));
        }
        const auto r = receivers.find(fields[organ]);
        if (r == receivers.end())
            throw InputError(ErrorCode::kNotFound, where,
                             "organ '" + fields[organ] + "' is not in the scene");
        const auto b = bands.find(fields[band]);
        if (b == bands.end())
            throw InputError(ErrorCode::kNotFound, where,
                             "band '" + fields[band] + "' is not in the scene");
        std::uint8_t& once = seen[r->second * scene.bands.size() + b->second];
        if (once)
            throw InputError(ErrorCode::kAlreadyExists, where,
                             "organ " + fields[organ] + " listed twice");
        once = 1;
        const auto value = [&](std::size_t k) {
            char* end = nullptr;
            const double v = std::strtod(fields[k].c_str(), &end);
            if (fields[k].empty() || end != fields[k].c_str() + fields[k].size() ||
                !std::isfinite(v))
                throw InputError(ErrorCode::kParse, where + " " + header[k],
                                 "not a number: '" + fields[k] + "'");
            return v;
        };
        BandLight& light = solution.light[r->second][b->second];
        light.irradianceUpperWm2 = value(upper);
        light.irradianceLowerWm2 = value(lower);
        light.absorbedW = value(absorbed);
    }
    solution.unsolved.assign(flat.receivers.size(), 1);
    for (std::size_t r = 0; r < flat.receivers.size(); ++r)
        for (std::size_t b = 0; b < scene.bands.size(); ++b)
            if (seen[r * scene.bands.size() + b]) solution.unsolved[r] = 0;
    return solution;
}

}  // namespace leaflux
