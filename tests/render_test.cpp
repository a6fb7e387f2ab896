// leaflux render: pictures that show what was solved. A plate under a known irradiance
// takes the colour bar's colour at that value; a plate with half the irradiance is half as
// bright on the linear grey scale; true colour shows three bands' radiosities; the scale
// bar measures a plate; the north arrow points north; a bad camera is refused naming its
// field; a solution read back from its CSV draws the same picture.
#include "solver/render/render.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "solver/render/legend.h"
#include "solver/results/export.h"
#include "solver/results/read_leaf_csv.h"
#include "solver/solve.h"
#include "solver/util/error.h"
#include "tests/scene_builders.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

using namespace leaflux::testing;

// Black unit plates (no scattering: the irradiance is the sun's, in closed form) under a
// vertical sun of `sun` W/m²; plate k at x = 3k, tilted by tiltDeg[k] about the y axis.
Scene Plates(const std::vector<double>& tiltDeg, double sun) {
    Scene scene = OneBandScene({{"black", Opaque(0.0)}});
    for (std::size_t k = 0; k < tiltDeg.size(); ++k) {
        const double t = glm::radians(tiltDeg[k]), x = 3.0 * k;
        const glm::dvec3 u(0.5 * std::cos(t), 0.0, -0.5 * std::sin(t)), v(0.0, 0.5, 0.0);
        const glm::dvec3 c(x, 0.0, 1.0);
        scene.nodes.push_back(OrganNode(k + 1, "plate" + std::to_string(k),
                                        Quad(c - u - v, c + u - v, c + u + v, c - u + v), "black"));
    }
    scene.sources.suns.push_back(SunAt(90.0, 0.0, sun));
    scene.Validate();
    return scene;
}

Solution SolveHrc(const PreparedScene& prepared) {
    SolverSettings settings;
    settings.kind = SolverKind::kHrc;
    settings.hrc.epsilon = 1e-4;
    return Solve(prepared, settings);
}

// A camera 10 m above the point (x, 0, 1), looking down, north at the top.
Camera Above(double x) { return {{x, 0.0, 11.0}, {x, 0.0, 1.0}, {0.0, 1.0, 0.0}, 4.0}; }

TEST(Render, APlateTakesTheColourBarsColourAtItsIrradiance) {
    const double sun = 400.0;
    const Scene scene = Plates({0.0}, sun);
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    ASSERT_NEAR(solution.light[0][0].irradianceUpperWm2, sun, 1e-6 * sun);
    for (Palette palette : {Palette::kViridis, Palette::kGrey}) {
        RenderSettings settings;
        settings.camera = Above(0.0);
        settings.width = 200, settings.height = 150;
        settings.range = {0.0, 1.6 * sun};  // the plate at 5/8 of the scale
        settings.palette = palette;
        const Rendering picture = Render(scene, prepared.Rays(), solution, settings);
        EXPECT_EQ(picture.image.Width(), 200);
        EXPECT_GT(picture.image.Height(), 150);  // the bar's panel below the view
        EXPECT_EQ(picture.beyondFraction, 0.0);
        const Rgb plate = picture.image.At(100, 75);
        const Rgb bar =
            picture.image.At(picture.BarColumn(sun), (picture.barTop + picture.barBottom) / 2);
        // The bar's column holds the value to within half a column (under 1/300 of the
        // scale here), less than one colour step of either palette.
        EXPECT_NEAR(plate.r, bar.r, 1) << static_cast<int>(palette);
        EXPECT_NEAR(plate.g, bar.g, 1);
        EXPECT_NEAR(plate.b, bar.b, 1);
        EXPECT_EQ(plate, picture.scale.AtFraction(sun / (1.6 * sun)));
    }
}

TEST(Render, APlateWithHalfTheLightIsHalfAsBrightOnTheGreyScale) {
    const double sun = 300.0;
    const Scene scene = Plates({0.0, 60.0}, sun);  // cos 60° = 1/2
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    RenderSettings settings;
    settings.camera = {{1.5, 0.0, 31.0}, {1.5, 0.0, 1.0}, {0.0, 1.0, 0.0}, 8.0};
    settings.width = 320, settings.height = 160;
    settings.palette = Palette::kGrey;
    settings.samples = 1;
    const Rendering picture = Render(scene, prepared.Rays(), solution, settings);
    // The scale runs from 0 to the brightest value in view, the flat plate's.
    EXPECT_NEAR(picture.scale.max, sun, 1e-6 * sun);
    const View view(settings.camera, settings.width, settings.height);
    // Pixels over each plate's centre: the flat one at x = 0 m and the tilted one at 3 m,
    // 1.5 m either side of the view's centre; tan(4°)·30 m spans half the view's height.
    const double metresPerPixel = 2.0 * std::tan(glm::radians(4.0)) * 30.0 / settings.height;
    const int offset = static_cast<int>(std::lround(1.5 / metresPerPixel));
    const Rgb flat = picture.image.At(160 - offset, 80),
              tilted = picture.image.At(160 + offset, 80);
    EXPECT_EQ(flat.r, 255);
    // 255 / 2 rounds to 128: the ratio within one grey level.
    EXPECT_NEAR(static_cast<double>(tilted.r) / flat.r, 0.5, 1.0 / 255.0);
    EXPECT_EQ(tilted.r, tilted.g);
}

// Both sides: an organ's two summed, but a wall's seen side alone (its outside lies in
// another space than its inside). A grey ground lit from above, seen from below, stays dark;
// a leaf (ρ = τ = 0.5) beside it shows its two sides' sum.
TEST(Render, BothSidesSumAnOrgansSidesButNotAWalls) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.25, 0.25)}, {"ground", Opaque(0.5)}});
    scene.nodes.push_back(OrganNode(1, "leaf", Rectangle(1.0, 1.0, 1.0), "leaf"));
    Surface ground;
    ground.name = "ground";
    ground.mesh = Quad({2.5, -0.5, 0.0}, {3.5, -0.5, 0.0}, {3.5, 0.5, 0.0}, {2.5, 0.5, 0.0});
    ground.opticsId = "ground";
    scene.environment.push_back(ground);
    scene.sources.suns.push_back(SunAt(90.0, 0.0, 200.0));
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    const BandLight& leaf = solution.light[0][0];
    ASSERT_GT(leaf.irradianceLowerWm2,
              0.0);  // the light the leaf lets through, back from the ground
    RenderSettings settings;
    settings.camera = {{1.5, 0.0, -30.0}, {1.5, 0.0, 0.5}, {0.0, 1.0, 0.0}, 8.0};  // from below
    settings.width = 320, settings.height = 160;
    settings.palette = Palette::kGrey;
    settings.samples = 1;
    settings.side = Side::kBothSides;
    settings.range = {0.0, 400.0};
    const Rendering picture = Render(scene, prepared.Rays(), solution, settings);
    const double metresPerPixel = 2.0 * std::tan(glm::radians(4.0)) * 30.5 / settings.height;
    const int offset = static_cast<int>(std::lround(1.5 / metresPerPixel));
    // The camera looks up: its right is -x, so the leaf (x = 0) is right of the centre.
    const Rgb leafPixel = picture.image.At(160 + offset, 80),
              groundPixel = picture.image.At(160 - offset, 80);
    EXPECT_EQ(leafPixel, picture.scale.AtFraction(
                             (leaf.irradianceUpperWm2 + leaf.irradianceLowerWm2) / 400.0));
    EXPECT_EQ(groundPixel,
              picture.scale.AtFraction(solution.light[1][0].irradianceLowerWm2 / 400.0));
    EXPECT_EQ(groundPixel, Rgb{}) << "the ground's underside gets nothing";
}

// The view's box test: a box ahead is seen, one behind the eye or beside the picture is
// not, and one the picture's edge crosses is kept.
TEST(Render, TheViewSeesTheBoxesAheadOfItAndNotThoseBehindOrBeside) {
    const View view({{0.0, 0.0, 0.0}, {0.0, 10.0, 0.0}, {0.0, 0.0, 1.0}, 40.0}, 400, 300);
    EXPECT_TRUE(view.MaySee({-1, 9, -1}, {1, 11, 1}));
    EXPECT_FALSE(view.MaySee({-1, -11, -1}, {1, -9, 1}));     // behind
    EXPECT_FALSE(view.MaySee({9, 9, -1}, {11, 11, 1}));       // right of a 52° wide view
    EXPECT_FALSE(view.MaySee({-1, 9, 6}, {1, 11, 8}));        // above a 40° high one
    EXPECT_TRUE(view.MaySee({3, 9, -1}, {6, 11, 1}));         // across its right edge
    EXPECT_TRUE(view.MaySee({-50, -50, -50}, {50, 50, 50}));  // round the eye
}

// The error a camera text gets, as "field: message".
std::string CameraError(const std::string& text) {
    try {
        ParseCamera(text);
    } catch (const InputError& e) {
        return e.Field() + ": " + e.Message();
    }
    return "accepted";
}

TEST(Render, APictureTooLargeToHoldIsRefusedBeforeAnyRay) {
    const Scene scene = Plates({0.0}, 100.0);
    RenderSettings settings;
    settings.camera = Above(0.0);
    settings.width = settings.height = 16384;
    settings.samples = 16;  // 2^32 rays
    try {
        Validate(settings, scene);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Field(), "samples");
    }
    settings.samples = 1;  // 2^28 rays: the most a picture may take
    EXPECT_NO_THROW(Validate(settings, scene));
}

TEST(Render, ABadCameraIsRefusedNamingItsField) {
    EXPECT_EQ(CameraError("eye=0,0,10 look=0,0,0 up=0,1,0 fov=30"), "accepted");
    EXPECT_EQ(CameraError("eye=1,2,3 look=1,2,3").substr(0, 12), "camera.look:");
    EXPECT_EQ(CameraError("eye=0,0,10 look=0,0,0 up=0,1,0 fov=0").substr(0, 11), "camera.fov:");
    EXPECT_EQ(CameraError("eye=0,0,10 look=0,0,0 up=0,1,0 fov=180").substr(0, 11), "camera.fov:");
    EXPECT_EQ(CameraError("eye=nan,0,10 look=0,0,0 up=0,1,0").substr(0, 11), "camera.eye:");
    EXPECT_EQ(CameraError("eye=0,0,10 look=0,0,0 up=0,0,1").substr(0, 10), "camera.up:");
    EXPECT_EQ(CameraError("eye=0,0 look=0,0,0").substr(0, 11), "camera.eye:");
    EXPECT_EQ(CameraError("eye=0,0,10").substr(0, 12), "camera.look:");
    EXPECT_EQ(CameraError("eye=0,0,10 look=0,0,0 up=0,1,0 zoom=2").substr(0, 12), "camera.zoom:");
}

TEST(Render, ASolutionReadBackFromItsCsvDrawsTheSamePicture) {
    const Scene scene = Plates({0.0, 30.0, 60.0}, 500.0);
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    const std::string path = testing::TempPath("render_plates.csv");
    {
        std::ofstream out(path);
        WriteLeafCsv(out, scene, prepared.Flat(), solution);
    }
    const Solution read = ReadLeafCsv(path, scene, prepared.Flat());
    RenderSettings settings;
    settings.camera = {{3.0, -12.0, 8.0}, {3.0, 0.0, 1.0}, {0.0, 0.0, 1.0}, 35.0};
    settings.width = 160, settings.height = 120;
    const Rendering a = Render(scene, prepared.Rays(), solution, settings);
    const Rendering b = Render(scene, prepared.Rays(), read, settings);
    EXPECT_EQ(a.scale.max, b.scale.max);
    for (int y = 0; y < a.image.Height(); ++y)
        for (int x = 0; x < a.image.Width(); ++x)
            ASSERT_EQ(a.image.At(x, y), b.image.At(x, y)) << x << "," << y;
    // And written as PNG, read back pixel for pixel.
    const std::string png = testing::TempPath("render_plates.png");
    WritePng(a.image, png);
    const Image back = ReadPng(png);
    ASSERT_EQ(back.Width(), a.image.Width());
    ASSERT_EQ(back.Height(), a.image.Height());
    for (int y = 0; y < back.Height(); ++y)
        for (int x = 0; x < back.Width(); ++x) ASSERT_EQ(back.At(x, y), a.image.At(x, y));
}

TEST(Render, ACsvThatDoesNotMatchTheSceneIsRefusedNamingItsLine) {
    const Scene scene = Plates({0.0}, 100.0);
    const FlatScene flat = Flatten(scene);
    const std::string path = testing::TempPath("render_bad.csv");
    const auto refusal = [&](const std::string& text) -> std::string {
        std::ofstream(path) << text;
        try {
            ReadLeafCsv(path, scene, flat);
        } catch (const InputError& e) {
            return e.Field() + ": " + e.Message();
        }
        return "accepted";
    };
    const std::string header =
        "organ,band,area_m2,irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w\n";
    EXPECT_EQ(refusal(header + "plate0,PAR,1,100,0,100\n"), "accepted");
    EXPECT_EQ(refusal(header + "plate0,PAR,1,100,0,100\nplate9,PAR,1,1,1,1\n"),
              path + ":3: organ 'plate9' is not in the scene");
    EXPECT_EQ(refusal(header + "plate0,NIR,1,100,0,100\n"),
              path + ":2: band 'NIR' is not in the scene");
    EXPECT_EQ(refusal(header + "plate0,PAR,1,abc,0,100\n"),
              path + ":2 irradiance_upper_wm2: not a number: 'abc'");
    EXPECT_EQ(refusal("organ,band\nplate0,PAR\n"), path + ":1: no column irradiance_upper_wm2");
}

// True colour: a white-lit plate of ρ = 0.8, 0.4, 0.2 in bands R, G, B sends ρ E in each;
// on one linear scale up to the largest, its pixel is (255, 255 / 2, 255 / 4).
TEST(Render, TrueColourShowsEachBandsRadiosityOnOneLinearScale) {
    Scene scene;
    scene.bands = {{"R"}, {"G"}, {"B"}};
    scene.optics.push_back({"paint", {Opaque(0.8), Opaque(0.4), Opaque(0.2)}});
    scene.nodes.push_back(OrganNode(1, "plate", Rectangle(1.0, 1.0, 1.0), "paint"));
    Sun sun = SunAt(90.0, 0.0, 100.0);
    sun.normalIrradianceWm2 = {100.0, 100.0, 100.0};
    scene.sources.suns.push_back(sun);
    scene.Validate();
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    RenderSettings settings;
    settings.camera = Above(0.0);
    settings.width = 64, settings.height = 48;
    settings.quantity = Quantity::kTrueColour;
    settings.rgb = {0, 1, 2};
    const Rendering picture = Render(scene, prepared.Rays(), solution, settings);
    EXPECT_NEAR(picture.scale.max, 80.0, 1e-6 * 80.0);
    EXPECT_EQ(picture.image.At(32, 24), (Rgb{255, 128, 64}));
    EXPECT_EQ(picture.scale.palette, Palette::kGrey);  // the bar: one channel's scale
    settings.rgb = {2, 1, 0};                          // the bands swapped: the colour too
    EXPECT_EQ(Render(scene, prepared.Rays(), solution, settings).image.At(32, 24),
              (Rgb{64, 128, 255}));
    settings.rgb = {0, 1, 3};
    EXPECT_THROW(Render(scene, prepared.Rays(), solution, settings), InputError);
}

// The scale bar is as long as its length measured on a plate at the look point's distance:
// a 1 m plate facing the camera spans the bar's pixels per metre.
TEST(Render, TheScaleBarMeasuresThePlateAtTheLookPoint) {
    const Scene scene = Plates({0.0}, 100.0);
    const PreparedScene prepared(scene);
    const Solution solution = SolveHrc(prepared);
    RenderSettings settings;
    settings.camera = {{0.0, 0.0, 11.0}, {0.0, 0.0, 1.0}, {0.0, 1.0, 0.0}, 20.0};
    settings.width = 400, settings.height = 300;
    settings.samples = 1;
    settings.palette = Palette::kGrey;
    settings.scaleBar = true;
    const Rendering picture = Render(scene, prepared.Rays(), solution, settings);
    int plate = 0;  // the lit plate's pixels along the view's middle row
    for (int x = 0; x < settings.width; ++x)
        plate += picture.image.At(x, 150) == Rgb{255, 255, 255};
    // 10 m away in a 20° view: 300 px span 2·10·tan 10° = 3.53 m, a fifth of the width
    // 0.94 m: the bar is 0.5 m.
    EXPECT_EQ(picture.scaleBar.metres, 0.5);
    EXPECT_NEAR(picture.scaleBar.pixels, 0.5 * plate, 1.0);
    // The bar drawn in ink at the bottom-left, its length from its first column.
    const int row = settings.height - 14, left = 12;
    int drawn = 0;
    while (picture.image.At(left + drawn, row) == Rgb{20, 20, 20}) ++drawn;
    EXPECT_EQ(drawn, picture.scaleBar.pixels);
}

// North (+y) in the picture: up for a camera looking down with north up, left with east up
// or looking east, none looking due north.
TEST(Render, TheNorthArrowPointsNorthAtTheLookPoint) {
    const auto north = [](const Camera& camera) {
        return NorthInPicture(camera, View(camera, 200, 100));
    };
    const auto near = [](std::optional<glm::dvec2> v, glm::dvec2 expected) {
        return v && glm::length(*v - expected) < 1e-9;
    };
    EXPECT_TRUE(near(north(Above(0.0)), {0.0, -1.0}));
    EXPECT_TRUE(near(north({{0, 0, 10}, {0, 0, 0}, {1, 0, 0}, 45.0}), {-1.0, 0.0}));
    EXPECT_TRUE(near(north({{-10, 0, 0}, {0, 0, 0}, {0, 0, 1}, 45.0}), {-1.0, 0.0}));
    EXPECT_TRUE(near(north({{0, 0, 10}, {0, 0, 0}, {0, -1, 0}, 45.0}), {0.0, 1.0}));
    EXPECT_FALSE(north({{0, -10, 0}, {0, 0, 0}, {0, 0, 1}, 45.0}));
}

TEST(Render, TicksAreRoundValuesWithinTheScale) {
    EXPECT_EQ(Ticks(0.0, 483.0, 5), (std::vector<double>{0, 100, 200, 300, 400}));
    EXPECT_EQ(Ticks(0.0, 1.0, 4), (std::vector<double>{0, 0.5, 1}));
    const std::vector<double> ticks = Ticks(-20.0, 20.0, 4);
    EXPECT_EQ(ticks, (std::vector<double>{-20, -10, 0, 10, 20}));
}

}  // namespace
}  // namespace leaflux
