// Units of light: a band's photons per joule (PAR in µmol m⁻² s⁻¹ beside W/m²) in scene
// files and in the result CSVs, and the log's warnings for source values that look like a
// photon flux given as W/m² or a sun below the horizon.
#include "solver/scene/light_units.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <map>
#include <sstream>

#include "server/scene_proto.h"
#include "solver/results/export.h"
#include "solver/solve.h"
#include "solver/util/error.h"
#include "tests/scene_builders.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

// The log lines of `run`, at warning level and above.
template <typename F>
std::string LogOf(F run) {
    std::ostringstream text;
    auto logger = std::make_shared<spdlog::logger>(
        "capture", std::make_shared<spdlog::sinks::ostream_sink_st>(text));
    const auto previous = spdlog::default_logger();
    spdlog::set_default_logger(logger);
    try {
        run();
    } catch (...) {
        spdlog::set_default_logger(previous);
        throw;
    }
    spdlog::set_default_logger(previous);
    return text.str();
}

// A 1 m² plate under a sun; `bands` and `sources` are text-format lines.
std::string PlateScene(const std::string& bands, const std::string& sources) {
    return bands + R"(
optics { id: "leaf" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 tau_upper: 0.05 tau_lower: 0.05 } }
                    bands { key: "NIR" value { rho_upper: 0.4 rho_lower: 0.4 tau_upper: 0.4 tau_lower: 0.4 } } }
nodes { id: 1 type: NODE_TYPE_LEAF name: "plate"
        organ { optics: "leaf" mesh { positions: [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0] triangles: [0, 1, 2, 0, 2, 3] } } }
)" + sources;
}

const char* kTwoBands = R"(bands { name: "PAR" } bands { name: "NIR" })";

std::string Sun(double par, double nir, const std::string& position = "direction { z: 1 }") {
    return "suns { " + position +
           " normal_irradiance { key: \"PAR\" value: " + std::to_string(par) +
           " } normal_irradiance { key: \"NIR\" value: " + std::to_string(nir) + " } }\n";
}

TEST(PhotonUnits, APARBandHasTheDaylightFactorUnlessItGivesItsOwn) {
    EXPECT_EQ(PhotonUmolPerJ({"PAR"}), kDaylightParUmolPerJ);
    EXPECT_EQ(PhotonUmolPerJ({"par"}), kDaylightParUmolPerJ);
    EXPECT_EQ(PhotonUmolPerJ({"visible", 400.0, 700.0}), kDaylightParUmolPerJ);
    EXPECT_EQ(PhotonUmolPerJ({"PAR", 400.0, 700.0, 4.6}), 4.6);  // a lamp's spectrum
    EXPECT_EQ(PhotonUmolPerJ({"red", 600.0, 700.0, 5.43}), 5.43);
    EXPECT_FALSE(PhotonUmolPerJ({"NIR", 700.0, 2500.0}).has_value());
    EXPECT_FALSE(PhotonUmolPerJ({"PARx"}).has_value());
    EXPECT_FALSE(PhotonUmolPerJ({"blue", 400.0, 500.0}).has_value());
}

TEST(PhotonUnits, AScenesFactorRoundTripsAndABadOneIsRefusedByField) {
    const std::string bands =
        R"(bands { name: "PAR" } bands { name: "NIR" photon_umol_per_j: 9.5 })";
    const Scene scene = LoadSceneFile(
        testing::WriteTempFile("photons.scene.txtpb", PlateScene(bands, Sun(400, 300))));
    EXPECT_EQ(scene.bands[0].photonUmolPerJ, 0.0);  // as given: the default is PhotonUmolPerJ's
    EXPECT_EQ(scene.bands[1].photonUmolPerJ, 9.5);
    const std::string path = testing::TempPath("photons_again.scene.txtpb");
    SaveSceneFile(scene, path);
    EXPECT_EQ(LoadSceneFile(path).bands[1].photonUmolPerJ, 9.5);

    for (const char* bad : {"-1", "nan", "5000"}) {
        const std::string text =
            PlateScene(std::string(R"(bands { name: "PAR" photon_umol_per_j: )") + bad +
                           R"( } bands { name: "NIR" })",
                       Sun(400, 300));
        try {
            LoadSceneFile(testing::WriteTempFile("bad_photons.scene.txtpb", text));
            ADD_FAILURE() << "accepted photon_umol_per_j: " << bad;
        } catch (const InputError& e) {
            EXPECT_EQ(e.Field(), "bands[PAR].photon_umol_per_j") << bad;
            EXPECT_NE(std::string(e.what()).find("µmol/J"), std::string::npos) << e.what();
        }
    }
}

// The CSV's rows by organ and band, column name → cell.
std::map<std::string, std::map<std::string, std::string>> Rows(const std::string& csv) {
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> header;
    std::stringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
    std::map<std::string, std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        std::map<std::string, std::string> row;
        std::stringstream cells(line);
        std::string cell;
        for (std::size_t i = 0; i < header.size(); ++i) {
            if (!std::getline(cells, cell, ',')) cell.clear();
            row[header[i]] = cell;
        }
        rows[row["organ"] + "/" + row["band"]] = row;
    }
    return rows;
}

TEST(PhotonUnits, CsvColumnsGivePARInMicromolesBesideWatts) {
    const Scene scene = LoadSceneFile(
        testing::WriteTempFile("csv_photons.scene.txtpb", PlateScene(kTwoBands, Sun(400, 300))));
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.kind = SolverKind::kHrc;
    settings.hrc.directOnly = true;
    const Solution solution = Solve(prepared, settings);
    std::ostringstream csv;
    WriteLeafCsv(csv, scene, prepared.Flat(), solution);
    const auto rows = Rows(csv.str());
    ASSERT_EQ(rows.count("plate/PAR"), 1u) << csv.str();
    const auto& par = rows.at("plate/PAR");
    // A horizontal plate under a vertical sun: 400 W/m² on top, 1828 µmol m⁻² s⁻¹.
    EXPECT_NEAR(std::stod(par.at("irradiance_upper_wm2")), 400.0, 1e-6);
    EXPECT_NEAR(std::stod(par.at("photon_irradiance_upper_umol_m2_s")), 1828.0, 1e-3);
    EXPECT_NEAR(std::stod(par.at("photon_irradiance_lower_umol_m2_s")),
                4.57 * std::stod(par.at("irradiance_lower_wm2")), 1e-6);
    EXPECT_NEAR(std::stod(par.at("absorbed_umol_s")), 4.57 * std::stod(par.at("absorbed_w")), 1e-6);
    EXPECT_GT(std::stod(par.at("absorbed_umol_s")), 0.0);
    const auto& nir = rows.at("plate/NIR");  // no photon factor: empty cells
    EXPECT_EQ(nir.at("photon_irradiance_upper_umol_m2_s"), "");
    EXPECT_EQ(nir.at("absorbed_umol_s"), "");
    EXPECT_NEAR(std::stod(nir.at("irradiance_upper_wm2")), 300.0, 1e-6);

    const std::string summary = Summary("hrc", scene, prepared.Flat(), solution);
    EXPECT_NE(summary.find("umol/s"), std::string::npos) << summary;

    std::ostringstream structures;
    WriteStructureCsv(structures, scene, AggregateStructures(scene, prepared.Flat(), solution));
    EXPECT_NE(structures.str().find(",absorbed_umol_s\n"), std::string::npos) << structures.str();
}

TEST(SourceWarnings, ASunInMicromolesGivenAsWattsIsWarnedOf) {
    const std::string log = LogOf([] {
        LoadSceneFile(
            testing::WriteTempFile("umol_sun.scene.txtpb", PlateScene(kTwoBands, Sun(2000, 300))));
    });
    EXPECT_NE(log.find("suns[0].normal_irradiance[PAR] is 2000 W/m²"), std::string::npos) << log;
    EXPECT_NE(log.find("µmol m⁻² s⁻¹"), std::string::npos) << log;
    EXPECT_NE(log.find("437.6 W/m²"), std::string::npos) << log;  // 2000 / 4.57
    EXPECT_EQ(log.find("NIR"), std::string::npos) << log;
}

TEST(SourceWarnings, PlausibleSourcesAreNotWarnedOf) {
    const std::string log = LogOf([] {
        LoadSceneFile(testing::WriteTempFile("plausible.scene.txtpb",
                                             PlateScene(kTwoBands, Sun(450, 400) + R"(
sky { horizontal_irradiance { key: "PAR" value: 200 } horizontal_irradiance { key: "NIR" value: 150 } }
)")));
    });
    EXPECT_EQ(log, "");
}

TEST(SourceWarnings, OtherBandsAreWarnedOfAboveTheSolarConstantOnly) {
    const std::string log = LogOf([] {
        LoadSceneFile(
            testing::WriteTempFile("nir_high.scene.txtpb", PlateScene(kTwoBands, Sun(400, 1400))));
    });
    EXPECT_EQ(log, "");  // within the whole spectrum's 1361 W/m² (and 10 %)
    const std::string high = LogOf([] {
        LoadSceneFile(testing::WriteTempFile("nir_higher.scene.txtpb",
                                             PlateScene(kTwoBands, Sun(400, 2000))));
    });
    EXPECT_NE(high.find("suns[0].normal_irradiance[NIR] is 2000 W/m²"), std::string::npos) << high;
    EXPECT_EQ(high.find("µmol"), std::string::npos) << high;  // NIR has no photon unit here
}

TEST(SourceWarnings, ASkyAndASunPeriodInMicromolesAreWarnedOf) {
    const std::string log = LogOf([] {
        LoadSceneFile(testing::WriteTempFile("umol_sky.scene.txtpb", PlateScene(kTwoBands, R"(
sky { horizontal_irradiance { key: "PAR" value: 900 } horizontal_irradiance { key: "NIR" value: 150 } }
sun_periods { latitude_deg: 45 day_of_year: 172 start_h: 8 end_h: 16 step_h: 1
              normal_irradiance { key: "PAR" value: 1800 } normal_irradiance { key: "NIR" value: 400 } }
)")));
    });
    EXPECT_NE(log.find("sky.horizontal_irradiance[PAR] is 900 W/m²"), std::string::npos) << log;
    EXPECT_NE(log.find("sun_periods[0].normal_irradiance[PAR] is 1800 W/m²"), std::string::npos)
        << log;
}

TEST(SourceWarnings, ASunBelowTheHorizonIsWarnedOf) {
    const std::string byDirection = LogOf([] {
        LoadSceneFile(testing::WriteTempFile(
            "sun_below.scene.txtpb",
            PlateScene(kTwoBands, Sun(400, 300, "direction { x: 1 z: -0.2 }"))));
    });
    EXPECT_NE(byDirection.find("suns[0] is 11.3° below the horizon"), std::string::npos)
        << byDirection;
    const std::string atNight = LogOf([] {
        LoadSceneFile(testing::WriteTempFile(
            "sun_night.scene.txtpb",
            PlateScene(kTwoBands, Sun(400, 300,
                                      "solar { latitude_deg: 45 "
                                      "day_of_year: 172 solar_time_h: 1 }"))));
    });
    EXPECT_NE(atNight.find("suns[0] is "), std::string::npos) << atNight;
    EXPECT_NE(atNight.find("below the horizon"), std::string::npos) << atNight;
    const std::string low = LogOf([] {
        LoadSceneFile(testing::WriteTempFile(
            "sun_low.scene.txtpb",
            PlateScene(kTwoBands, Sun(400, 300, "direction { x: 1 z: 0.01 }"))));
    });
    EXPECT_EQ(low, "");  // just above: meant
}

TEST(SourceWarnings, ACyclesSunIsWarnedOfAsTheDaemonReadsIt) {
    const Scene scene = LoadSceneFile(
        testing::WriteTempFile("cycle_sun.scene.txtpb", PlateScene(kTwoBands, Sun(400, 300))));
    v1::Sun sun;
    sun.mutable_direction()->set_z(-1.0);
    (*sun.mutable_normal_irradiance())["PAR"] = 1500.0;
    (*sun.mutable_normal_irradiance())["NIR"] = 300.0;
    const std::string log = LogOf([&] { SunFromProto(scene, sun, "suns[3]"); });
    EXPECT_NE(log.find("suns[3] is 90° below the horizon"), std::string::npos) << log;
    EXPECT_NE(log.find("suns[3].normal_irradiance[PAR] is 1500 W/m²"), std::string::npos) << log;
}

}  // namespace
}  // namespace leaflux
