// Scene files: the text format round-trips, imports resolve, and every schema-level
// mistake is an InputError naming the field (or file line and column).
#include "server/scene_proto.h"

#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>

#include "solver/generate/generator.h"
#include "solver/util/error.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

const char* kHeader = R"(
bands { name: "PAR" }
optics { id: "leaf" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 tau_upper: 0.05 tau_lower: 0.05 } } }
)";

const char* kPlate = R"(
nodes { id: 1 type: NODE_TYPE_LEAF name: "plate"
        organ { optics: "leaf" mesh { positions: [0, 0, 0, 1, 0, 0, 1, 1, 0] triangles: [0, 1, 2] } } }
suns { solar { latitude_deg: 45 day_of_year: 172 solar_time_h: 12 } normal_irradiance { key: "PAR" value: 500 } }
)";

InputError ErrorOf(const std::string& text) {
    try {
        LoadSceneFile(testing::WriteTempFile("bad.scene.txtpb", text));
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "accepted:\n" << text;
    return InputError(ErrorCode::kInvalidArgument, "", "");
}

TEST(SceneFile, LoadsAPlateUnderASolarPositionSun) {
    const Scene scene =
        LoadSceneFile(testing::WriteTempFile("plate.scene.txtpb", std::string(kHeader) + kPlate));
    ASSERT_EQ(scene.nodes.size(), 1u);
    ASSERT_EQ(scene.sources.suns.size(), 1u);
    EXPECT_NEAR(glm::degrees(std::asin(scene.sources.suns[0].towardSun.z)), 68.44, 0.2);
}

TEST(SceneFile, RoundTripsAGeneratedTreeKeepingSharedMeshes) {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}}}, {"stem", {{0.1, 0.1, 0, 0}}}};
    TreeParameters tree;
    tree.leafCount = 50;
    AddTree(scene, tree, {0, 0, 0});
    scene.sources.skies.push_back({SkyModel::kCieOvercast, {120.0}, SkyDiscretization::kTurtle46});
    const std::string path = testing::TempPath("tree.scene.txtpb");
    SaveSceneFile(scene, path);
    const Scene back = LoadSceneFile(path);
    ASSERT_EQ(back.nodes.size(), scene.nodes.size());
    std::set<const Mesh*> meshes;
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        EXPECT_EQ(back.nodes[i].id, scene.nodes[i].id);
        EXPECT_EQ(back.nodes[i].parent, scene.nodes[i].parent);
        EXPECT_EQ(back.nodes[i].type(), scene.nodes[i].type());
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 3; ++r) {
                EXPECT_DOUBLE_EQ(back.nodes[i].parentFromLocal().At(c, r),
                                 scene.nodes[i].parentFromLocal().At(c, r));
            }
        }
        if (back.nodes[i].organ()) meshes.insert(back.nodes[i].organ()->mesh.get());
    }
    EXPECT_EQ(meshes.size(), 2u);  // one leaf prototype, one internode prototype
    EXPECT_EQ(back.sources.skies[0].discretization, SkyDiscretization::kTurtle46);
}

// A file whose name ends in .binpb holds the same message in protobuf's binary encoding:
// written and read back, it is the scene the text file gives; a file that is not one is
// refused with a typed error naming it.
TEST(SceneFile, ReadsAndWritesTheBinaryEncodingByItsName) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}, {0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0, 0}, {0.4, 0.4, 0, 0}}}};
    TreeParameters tree;
    tree.leafCount = 40;
    AddTree(scene, tree, {0, 0, 0});
    scene.sources.suns.push_back({glm::normalize(glm::dvec3(0.3, -0.4, 0.8)), {400.0, 350.0}, 0.0});
    const std::string text = testing::TempPath("tree.scene.txtpb"),
                      binary = testing::TempPath("tree.scene.binpb");
    SaveSceneFile(scene, text);
    SaveSceneFile(scene, binary);
    std::ifstream in(binary, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(bytes.substr(0, 7), "version");  // not text
    const v1::Scene fromText = ToProto(LoadSceneFile(text)),
                    fromBinary = ToProto(LoadSceneFile(binary));
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(fromText, fromBinary));
    EXPECT_EQ(fromBinary.nodes_size(), static_cast<int>(scene.nodes.size()));

    const std::string garbage =
        testing::WriteTempFile("garbage.scene.binpb", "version: PROTOCOL_VERSION_CURRENT\n");
    try {
        LoadSceneFile(garbage);
        ADD_FAILURE() << "a text file read as binary was accepted";
    } catch (const InputError& error) {
        EXPECT_EQ(error.Code(), ErrorCode::kParse);
        EXPECT_EQ(error.Field(), garbage);
    }
    try {
        LoadSceneFile(::testing::TempDir() + "absent.scene.binpb");
        ADD_FAILURE() << "an absent file was accepted";
    } catch (const InputError& error) {
        EXPECT_EQ(error.Code(), ErrorCode::kIo);
    }
}

// A binary file is read a node at a time: its nodes may come anywhere among the other
// fields (a concatenation of messages is their merge), a file cut short is refused, and
// the node limit holds before any node is converted.
TEST(SceneFile, ReadsABinaryFileANodeAtATime) {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}}}, {"stem", {{0.1, 0.1, 0, 0}}}};
    TreeParameters tree;
    tree.leafCount = 30;
    AddTree(scene, tree, {0, 0, 0});
    scene.sources.suns.push_back({glm::dvec3(0.0, 0.0, 1.0), {400.0}, 0.0});
    const v1::Scene whole = ToProto(scene);
    // Nodes first, then the bands and optics with more nodes, then the rest.
    v1::Scene first, second, third = whole;
    third.clear_nodes();
    third.clear_bands();
    third.clear_optics();
    *second.mutable_bands() = whole.bands();
    *second.mutable_optics() = whole.optics();
    for (int i = 0; i < whole.nodes_size(); ++i)
        *(i < 10 ? first : i < 40 ? second : third).add_nodes() = whole.nodes(i);
    const std::string bytes =
        first.SerializeAsString() + second.SerializeAsString() + third.SerializeAsString();
    const std::string path = testing::WriteTempFile("interleaved.scene.binpb", bytes);
    EXPECT_TRUE(
        google::protobuf::util::MessageDifferencer::Equals(ToProto(LoadSceneFile(path)), whole));

    SceneLimits limits;
    limits.maxNodes = static_cast<std::size_t>(whole.nodes_size()) - 1;
    try {
        LoadSceneFile(path, {}, limits);
        ADD_FAILURE() << "a file over the node limit was accepted";
    } catch (const TooLarge& error) {
        EXPECT_EQ(error.Field(), "nodes");
    }

    const std::string cut =
        testing::WriteTempFile("cut.scene.binpb", bytes.substr(0, bytes.size() / 2));
    try {
        LoadSceneFile(cut);
        ADD_FAILURE() << "a file cut short was accepted";
    } catch (const InputError& error) {
        EXPECT_EQ(error.Code(), ErrorCode::kParse);
        EXPECT_EQ(error.Field(), cut);
    }
}

TEST(SceneFile, ImportsCaribuWithItsOptics) {
    const std::string data = LEAFLUX_SHARED_DATA;
    const Scene scene = LoadSceneFile(testing::WriteTempFile(
        "bac1.scene.txtpb",
        R"(
bands { name: "PAR" } bands { name: "NIR" }
imports { path: ")" +
            data + R"(/caribu/bac1.can"
          can_optics { key: "PAR" value: ")" +
            data + R"(/caribu/par.opt" }
          can_optics { key: "NIR" value: ")" +
            data + R"(/caribu/nir.opt" } }
can_lights { path: ")" +
            data +
            R"(/caribu/Turtle46soc.light" scale { key: "PAR" value: 100 } scale { key: "NIR" value: 80 } }
)"));
    EXPECT_EQ(scene.sources.suns.size(), 46u);
    EXPECT_GE(scene.optics.size(), 5u);  // soil, two species and their stems
    const int species2 = scene.OpticsIndex("species2");
    ASSERT_GE(species2, 0);
    EXPECT_DOUBLE_EQ(scene.optics[species2].bands[0].rhoUpper, 0.01);
    EXPECT_DOUBLE_EQ(scene.optics[species2].bands[1].tauUpperToLower, 0.45);
}

TEST(SceneFile, ImportsObjAndOpfWithMaterialMaps) {
    const std::string data = LEAFLUX_SHARED_DATA;
    const Scene scene = LoadSceneFile(testing::WriteTempFile(
        "mixed.scene.txtpb",
        std::string(kHeader) + R"(
optics { id: "bark" bands { key: "PAR" value { rho_upper: 0.2 rho_lower: 0.2 } } }
nodes { id: 1 type: NODE_TYPE_PLANT name: "plant" }
imports { path: ")" +
            data + R"(/leaves/RedbudLeaf.obj" default_optics: "leaf" parent: 1 id_offset: 100
          frame { m: [0.1, 0, 0, 1,  0, 0.1, 0, 0,  0, 0, 0.1, 0.5] } }
imports { path: ")" +
            data + R"(/opf/simple_plant.opf" id_offset: 1000
          material_optics { key: "material0" value: "bark" } material_optics { key: "material1" value: "leaf" } }
)"));
    EXPECT_EQ(scene.nodes.size(), 1u + 1u + 7u);
    EXPECT_EQ(scene.nodes[1].parent, 1u);
    EXPECT_EQ(scene.nodes[1].id, 101u);
}

struct BadFile {
    const char* text;
    ErrorCode code;
    const char* field;
};

TEST(SceneFile, NamesTheLineOfAMistakeFarIntoALargeFile) {
    // A text file is parsed as it is read, in blocks: a mistake megabytes in is still named
    // by its own line and column.
    std::string text = kHeader;
    for (int i = 0; i < 40000; ++i)
        text += "# a comment line of the large scene file, " + std::to_string(i) + "\n";
    const auto line = std::count(text.begin(), text.end(), '\n') + 1;
    text += "bands { nme: \"PAR\" }\n";
    ASSERT_GT(text.size(), 1'000'000u);
    const InputError e = ErrorOf(text);
    EXPECT_EQ(e.Code(), ErrorCode::kParse) << e.what();
    // path:line:column, the column the parser had reached in the line.
    const std::string where = "bad.scene.txtpb:" + std::to_string(line) + ":";
    EXPECT_NE(e.Field().find(where), std::string::npos) << e.what();
}

TEST(SceneFile, NamesTheFieldOfEveryMistake) {
    const std::string header = kHeader;
    const BadFile cases[] = {
        {"bands { name: \"PAR\" } nodes { id: 1 frame { m: [1, 2, 3] } }",
         ErrorCode::kInvalidArgument, "frame"},
        {"bands { nme: \"PAR\" }", ErrorCode::kParse, ":1:"},
        {"bands { name: \"PAR\" } optics { id: \"x\" bands { key: \"UV\" value { } } }",
         ErrorCode::kNotFound, "optics[x].bands[UV]"},
        {"bands { name: \"PAR\" } optics { id: \"x\" }", ErrorCode::kNotFound, "optics[x].bands"},
        {"bands { name: \"PAR\" } nodes { id: 4 organ { mesh_ref: \"nope\" optics: \"x\" } }",
         ErrorCode::kNotFound, "organ.mesh_ref"},
        {"bands { name: \"PAR\" } nodes { id: 4 organ { optics: \"x\" mesh { positions: [0, 0] } } "
         "}",
         ErrorCode::kInvalidArgument, "organ.mesh.positions"},
        {"bands { name: \"PAR\" } suns { direction { } normal_irradiance { key: \"PAR\" value: 1 } "
         "}",
         ErrorCode::kInvalidArgument, "suns[0].direction"},
        {"bands { name: \"PAR\" } suns { direction { z: 1 } }", ErrorCode::kNotFound,
         "suns[0].normal_irradiance"},
        {"bands { name: \"PAR\" } suns { solar { latitude_deg: 95 day_of_year: 1 } "
         "normal_irradiance { key: \"PAR\" value: 1 } }",
         ErrorCode::kInvalidArgument, "suns[0].solar.latitude_deg"},
        {"bands { name: \"PAR\" } sun_periods { latitude_deg: 10 day_of_year: 5 start_h: 10 end_h: "
         "8 step_h: 1 }",
         ErrorCode::kInvalidArgument, "sun_periods[0]"},
        {"bands { name: \"PAR\" } sky { horizontal_irradiance { key: \"NIR\" value: 3 } }",
         ErrorCode::kNotFound, "sky.horizontal_irradiance[NIR]"},
        {"bands { name: \"PAR\" } imports { path: \"plant.xyz\" }", ErrorCode::kUnsupported,
         "imports[0].path"},
        {"bands { name: \"PAR\" } imports { path: \"missing.obj\" }", ErrorCode::kIo,
         "missing.obj"},
        {"version: 7 bands { name: \"PAR\" }", ErrorCode::kUnsupported, "version"},
    };
    for (const BadFile& c : cases) {
        const InputError e = ErrorOf(c.text);
        EXPECT_EQ(e.Code(), c.code) << c.text << "\n" << e.what();
        EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << c.text << "\n"
                                                                          << e.what();
    }
    // And the solver's own validation runs on what the file builds.
    const InputError e = ErrorOf(
        header +
        R"(nodes { id: 1 organ { optics: "leaf" mesh { positions: [0, 0, 0, 1, 0, 0, 2, 0, 0] triangles: [0, 1, 2] } } })");
    EXPECT_EQ(e.Code(), ErrorCode::kDegenerate);
    EXPECT_EQ(e.Node(), 1u);
}

}  // namespace
}  // namespace leaflux
