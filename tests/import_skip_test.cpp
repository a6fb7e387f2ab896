// Plant files as measured plants have them: geometry that carries no light (zero-length
// internodes, NaN diameters, zero-area faces) is skipped and named, or refused under strict;
// and the errors of broken files name the file, the line, the node or the shared mesh.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "server/scene_proto.h"
#include "solver/io/importers.h"
#include "solver/scene/world_frames.h"
#include "solver/solve.h"
#include "solver/util/error.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

using testing::WriteTempFile;

// The 1-based line of the first `needle` after the first `after` in `text`.
int LineOf(const std::string& text, const std::string& needle, const std::string& after = "") {
    const std::size_t from = text.find(after);
    const std::size_t at = text.find(needle, from);
    EXPECT_NE(at, std::string::npos) << needle;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

template <typename F>
InputError ErrorOf(F read) {
    try {
        read();
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "accepted";
    return InputError(ErrorCode::kInvalidArgument, "", "");
}

// An OPF node: `mat` is its 3×4 global frame in centimetres, `extra` more geometry lines.
std::string OpfOrgan(const char* element, const char* opfClass, int id, int shape,
                     const std::string& mat, const std::string& extra, const std::string& inside) {
    std::ostringstream out;
    out << "<" << element << " class=\"" << opfClass << "\" scale=\"3\" id=\"" << id << "\">\n"
        << "<geometry class=\"Mesh\">\n<shapeIndex>" << shape << "</shapeIndex>\n<mat>\n"
        << mat << "\n</mat>\n"
        << extra << "</geometry>\n"
        << inside << "</" << element << ">\n";
    return out.str();
}

// A vertical internode of length L cm from height z cm: local x up, local y along world x.
std::string Upright(double lengthCm, double zCm) {
    std::ostringstream m;
    m << "0 1 0 0\n0 0 1 0\n" << lengthCm << " 0 0 " << zCm;
    return m.str();
}
// A horizontal 5 × 3 cm leaf at (x, 0, z) cm.
std::string FlatLeaf(double xCm, double zCm) {
    std::ostringstream m;
    m << "5 0 0 " << xCm << "\n0 3 0 0\n0 0 1 " << zCm;
    return m.str();
}

// An axis of three internodes, each bearing a leaf; the second internode has zero length
// (a singular frame, as AMAPStudio writes it), the third NaN diameters.
std::string MeasuredPlant(const std::string& secondMat = Upright(0.0, 10.0)) {
    const std::string unitQuad =
        "<points>0 -0.5 0  1 -0.5 0  1 0.5 0  0 0.5 0</points>\n<faces>\n"
        "<face Id=\"0\">0 1 2</face>\n<face Id=\"1\">0 2 3</face>\n</faces>\n";
    const std::string leaf8 = OpfOrgan("branch", "Leaf", 8, 1, FlatLeaf(-8, 20), "", "");
    const std::string third = OpfOrgan("follow", "Internode", 7, 0, Upright(10, 10),
                                       "<dUp>NaN</dUp>\n<dDwn>NaN</dDwn>\n", leaf8);
    const std::string leaf6 = OpfOrgan("branch", "Leaf", 6, 1, FlatLeaf(2, 10), "", "");
    const std::string second = OpfOrgan("follow", "Internode", 5, 0, secondMat,
                                        "<dUp>0.5</dUp>\n<dDwn>0.5</dDwn>\n", leaf6 + third);
    const std::string first = OpfOrgan("decomp", "Internode", 4, 0, Upright(10, 0),
                                       "<dUp>0.5</dUp>\n<dDwn>0.5</dDwn>\n", second);
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<opf version=\"2.0\" editable=\"true\">\n"
           "<meshBDD>\n<mesh name=\"\" Id=\"0\">\n" +
           unitQuad + "</mesh>\n<mesh name=\"\" Id=\"1\">\n" + unitQuad +
           "</mesh>\n</meshBDD>\n<shapeBDD>\n"
           "<shape Id=\"0\"><meshIndex>0</meshIndex><materialIndex>0</materialIndex></shape>\n"
           "<shape Id=\"1\"><meshIndex>1</meshIndex><materialIndex>1</materialIndex></shape>\n"
           "</shapeBDD>\n<topology class=\"Scene\" scale=\"0\" id=\"1\">\n"
           "<decomp class=\"Plant\" scale=\"1\" id=\"2\">\n<decomp class=\"Axis\" scale=\"2\" "
           "id=\"3\">\n" +
           first + "</decomp>\n</decomp>\n</topology>\n</opf>\n";
}

const Node& NodeWithId(const ImportedGeometry& g, NodeId id) {
    for (const Node& node : g.nodes) {
        if (node.id == id) return node;
    }
    throw std::runtime_error("no node " + std::to_string(id));
}

TEST(OpfSkip, ZeroLengthInternodeAndNaNDiametersAreSkippedAndNamed) {
    const std::string text = MeasuredPlant();
    const std::string path = WriteTempFile("measured.opf", text);
    const ImportedGeometry g = ReadOpf(path);
    ASSERT_EQ(g.nodes.size(), 8u);  // every node stays in the topology
    EXPECT_FALSE(NodeWithId(g, 5).organ());
    EXPECT_FALSE(NodeWithId(g, 7).organ());
    for (NodeId lit : {4u, 6u, 8u}) EXPECT_TRUE(NodeWithId(g, lit).organ()) << lit;
    ASSERT_EQ(g.skipped.size(), 2u);
    EXPECT_EQ(g.skipped[0].node, 5u);
    EXPECT_NE(g.skipped[0].reason.find("singular"), std::string::npos) << g.skipped[0].reason;
    EXPECT_EQ(g.skipped[1].node, 7u);
    EXPECT_EQ(g.skipped[1].reason, "dUp is NaN");
    const std::string warning = SkippedSummary(path, g.skipped);
    const auto line = [&](const char* id) {
        return std::to_string(LineOf(text, "<geometry", std::string("id=\"") + id + "\""));
    };
    EXPECT_NE(warning.find("node 5 Internode5 at line " + line("5") + ": frame is singular"),
              std::string::npos)
        << warning;
    EXPECT_NE(warning.find("node 7 Internode7 at line " + line("7") + ": dUp is NaN"),
              std::string::npos)
        << warning;
    EXPECT_NE(warning.find("skipped 4 triangles"), std::string::npos) << warning;

    // The skipped node keeps its own origin, and the leaf it bears the place its global
    // frame gives it (a singular frame must not be composed through).
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"material0", {{0.1, 0.1, 0, 0}}}, {"material1", {{0.1, 0.1, 0.05, 0.05}}}};
    scene.nodes = g.nodes;
    ASSERT_NO_THROW(scene.Validate());
    const auto world = WorldFromLocal(scene);
    EXPECT_NEAR(glm::length(glm::dvec3(world.at(5)[3]) - glm::dvec3(0, 0, 0.10)), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(glm::dvec3(world.at(6)[3]) - glm::dvec3(0.02, 0, 0.10)), 0.0, 1e-12);
    EXPECT_NEAR(MeshArea(*NodeWithId(g, 6).organ()->mesh, world.at(6)), 15e-4, 1e-12);
    EXPECT_NEAR(glm::length(glm::dvec3(world.at(8)[3]) - glm::dvec3(-0.08, 0, 0.20)), 0.0, 1e-12);
}

TEST(OpfSkip, StrictRefusesNamingTheNodeAndLine) {
    const std::string text = MeasuredPlant();
    const std::string path = WriteTempFile("measured_strict.opf", text);
    const InputError singular = ErrorOf([&] { ReadOpf(path, ImportOptions{true}); });
    EXPECT_EQ(singular.Code(), ErrorCode::kDegenerate);
    EXPECT_EQ(singular.Node(), 5u);
    EXPECT_EQ(singular.Field(), path + ":" + std::to_string(LineOf(text, "<geometry", "id=\"5\"")));
    EXPECT_NE(std::string(singular.what()).find("singular"), std::string::npos);

    // With the second internode mended, the NaN diameters of the third are what is refused.
    const std::string mended = MeasuredPlant(Upright(10, 10));
    const std::string mendedPath = WriteTempFile("measured_nan.opf", mended);
    EXPECT_TRUE(ReadOpf(mendedPath).skipped.size() == 1u);
    const InputError nan = ErrorOf([&] { ReadOpf(mendedPath, ImportOptions{true}); });
    EXPECT_EQ(nan.Node(), 7u);
    EXPECT_EQ(nan.Field(),
              mendedPath + ":" + std::to_string(LineOf(mended, "<geometry", "id=\"7\"")));
    EXPECT_NE(std::string(nan.what()).find("dUp is NaN"), std::string::npos) << nan.what();
}

TEST(OpfSkip, TheRestOfThePlantIsLitAndStrictKeepsTheRefusal) {
    // The scene imports the plant by its name beside it: the test's own file.
    const std::string opf = WriteTempFile("lit.opf", MeasuredPlant());
    const std::string scenePath =
        WriteTempFile("lit.scene.txtpb", R"(
bands { name: "PAR" }
optics { id: "bark" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 } } }
optics { id: "leaf" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 tau_upper: 0.05 tau_lower: 0.05 } } }
imports { path: ")" + std::filesystem::path(opf).filename().string() +
                                             R"(" material_optics { key: "material0" value: "bark" }
          material_optics { key: "material1" value: "leaf" } }
suns { direction { x: 0 y: 0 z: 1 } normal_irradiance { key: "PAR" value: 400 } }
)");
    EXPECT_THROW(LoadSceneFile(scenePath, ImportOptions{true}), InputError);
    const Scene scene = LoadSceneFile(scenePath);
    PreparedScene prepared(scene);
    SolverSettings settings;
    settings.monteCarlo.directOnly = true;
    settings.monteCarlo.samplesPerReceiver = 64;
    const Solution solution = Solve(prepared, settings);
    int leaves = 0;
    for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
        const Receiver& receiver = prepared.Flat().receivers[r];
        if (receiver.node != 6 && receiver.node != 8) continue;
        ++leaves;
        // Flat leaves in full sun, nothing above them.
        EXPECT_NEAR(solution.light[r][0].irradianceUpperWm2, 400.0, 1e-6)
            << "node " << receiver.node;
    }
    EXPECT_EQ(leaves, 2);
}

// Two organs share a mesh of a horizontal and a vertical triangle; the frame of the second
// flattens the vertical one (z scaled by 1e-12, still invertible); a third has a NaN in its
// frame.
std::string FlatteningFrames() {
    const auto organ = [](int id, const std::string& mat) {
        return "<decomp class=\"Leaf\" scale=\"3\" id=\"" + std::to_string(id) +
               "\">\n<geometry class=\"Mesh\">\n<shapeIndex>0</shapeIndex>\n<mat>\n" + mat +
               "\n</mat>\n</geometry>\n</decomp>\n";
    };
    return "<opf version=\"2.0\">\n<meshBDD>\n<mesh Id=\"0\">\n"
           "<points>0 0 0  1 0 0  0 1 0  0 0 1</points>\n"
           "<faces><face Id=\"0\">0 1 2</face><face Id=\"1\">0 1 3</face></faces>\n"
           "</mesh>\n</meshBDD>\n<shapeBDD><shape Id=\"0\"><meshIndex>0</meshIndex>"
           "<materialIndex>0</materialIndex></shape></shapeBDD>\n"
           "<topology class=\"Plant\" scale=\"1\" id=\"1\">\n" +
           organ(2, "1 0 0 0\n0 1 0 0\n0 0 1 0") + organ(3, "1 0 0 5\n0 1 0 0\n0 0 1e-12 0") +
           organ(4, "1 0 0 9\n0 NaN 0 0\n0 0 1 0") + "</topology>\n</opf>\n";
}

TEST(OpfSkip, AFrameThatFlattensPartOfASharedMeshCopiesItForThatOrganOnly) {
    const std::string path = WriteTempFile("flattening.opf", FlatteningFrames());
    const ImportedGeometry g = ReadOpf(path);
    const Node& upright = NodeWithId(g, 2);
    const Node& flattened = NodeWithId(g, 3);
    ASSERT_TRUE(upright.organ() && flattened.organ());
    EXPECT_EQ(upright.organ()->mesh->triangles.size(), 2u);
    EXPECT_EQ(upright.organ()->mesh->name, "meshBDD mesh 0");  // still the shared mesh
    ASSERT_EQ(flattened.organ()->mesh->triangles.size(), 1u);  // its own copy
    EXPECT_NE(flattened.organ()->mesh, upright.organ()->mesh);
    EXPECT_EQ(flattened.organ()->mesh->triangles[0], glm::uvec3(0, 1, 2));
    EXPECT_FALSE(NodeWithId(g, 4).organ());
    ASSERT_EQ(g.skipped.size(), 2u);
    EXPECT_EQ(g.skipped[0].node, 4u);  // read first: the NaN frame
    EXPECT_EQ(g.skipped[0].reason, "<mat> is not finite");
    EXPECT_EQ(g.skipped[1].node, 3u);
    EXPECT_EQ(g.skipped[1].triangles, 1u);
    EXPECT_EQ(ErrorOf([&] { ReadOpf(path, ImportOptions{true}); }).Node(), 4u);
}

TEST(SkippedSummary, NamesTheFirstTenAndCountsTheRest) {
    std::vector<SkippedGeometry> skipped;
    for (NodeId id = 1; id <= 12; ++id)
        skipped.push_back({"p.opf:" + std::to_string(10 * id), id, "Leaf" + std::to_string(id),
                           "dUp is NaN", 20});
    const std::string text = SkippedSummary("p.opf", skipped);
    EXPECT_EQ(text.rfind("p.opf: skipped 240 triangles that carry no light, in 12 organs", 0), 0u)
        << text;
    EXPECT_NE(text.find("node 10 Leaf10 at line 100: dUp is NaN; and 2 more"), std::string::npos)
        << text;
    EXPECT_EQ(text.find("Leaf11"), std::string::npos) << text;
}

TEST(ObjSkip, ZeroAreaFacesAreSkippedByLineAndStrictRefusesThem) {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 2 0 0\nv 0 1 0\nv 2 2 0\n"  // lines 1-6
        "g blade\n"                                               // 7
        "f 1 2 3\n"                                               // 8: lit
        "f 1 2 4\n"                                               // 9: collinear
        "f 1 2 2\n"                                               // 10: repeated vertex
        "f 1 2 3 6\n"                                             // 11: second fan triangle flat
        "g speck\nf 1 1 1\n";                                     // 12-13: an organ of nothing
    const std::string path = WriteTempFile("flat.obj", text);
    const ImportedGeometry g = ReadObj(path);
    ASSERT_EQ(g.nodes.size(), 2u);
    ASSERT_TRUE(g.nodes[0].organ());
    EXPECT_EQ(g.nodes[0].organ()->mesh->triangles.size(), 2u);  // line 8 and line 11's first
    EXPECT_FALSE(g.nodes[1].organ());
    std::vector<std::string> where;
    for (const SkippedGeometry& s : g.skipped) where.push_back(s.where);
    ASSERT_EQ(where, (std::vector<std::string>{path + ":9", path + ":10", path + ":11",
                                               path + ":13", path}));
    EXPECT_EQ(g.skipped[2].reason, "triangle 2 of the face has zero area");
    const InputError strict = ErrorOf([&] { ReadObj(path, ImportOptions{true}); });
    EXPECT_EQ(strict.Code(), ErrorCode::kDegenerate);
    EXPECT_EQ(strict.Field(), path + ":9");
    // Nothing left that carries light: refused, whatever the options.
    EXPECT_EQ(
        ErrorOf([&] { ReadObj(WriteTempFile("dust.obj", "v 0 0 0\nv 1 0 0\nf 1 2 2\n")); }).Code(),
        ErrorCode::kDegenerate);
}

TEST(CanSkip, ZeroAreaPolygonsAreSkippedByLineAndStrictRefusesThem) {
    const std::string text =
        "p 1 100001001001 3 0 0 0 1 0 0 0 1 0\n"        // a leaf triangle
        "p 1 100001001002 3 0 0 0 1 0 0 2 0 0\n"        // the same leaf, collinear
        "p 1 100001002001 3 0 0 1 0 0 1 0 0 1\n"        // another leaf, a point
        "p 1 000000000001 4 0 0 0 1 0 0 1 1 0 2 2 0\n"  // soil; its second triangle is flat
        "p 1 000000000002 3 0 0 0 2 0 0 0 2 0\n";       // soil
    const std::string path = WriteTempFile("flat.can", text);
    const ImportedGeometry g = ReadCan(path);
    int organs = 0;
    for (const Node& node : g.nodes) organs += node.organ().has_value();
    EXPECT_EQ(organs, 1);
    ASSERT_EQ(g.environment.size(), 1u);
    EXPECT_EQ(g.environment[0].mesh->triangles.size(), 2u);
    std::vector<std::string> where;
    for (const SkippedGeometry& s : g.skipped) where.push_back(s.where);
    ASSERT_EQ(where, (std::vector<std::string>{path + ":2", path + ":3", path + ":4", path}));
    EXPECT_EQ(g.skipped[0].name, "plant1_organ1");
    EXPECT_EQ(g.skipped[2].name, "soil");
    const InputError strict = ErrorOf([&] { ReadCan(path, ImportOptions{true}); });
    EXPECT_EQ(strict.Field(), path + ":2");
}

TEST(ImportErrors, OpfErrorsNameTheFileAndLine) {
    const std::string unclosed = WriteTempFile("unclosed.opf", "<opf>\n<meshBDD>\n</opf>\n");
    const InputError xml = ErrorOf([&] { ReadOpf(unclosed); });
    EXPECT_EQ(xml.Code(), ErrorCode::kParse);
    EXPECT_EQ(xml.Field(), unclosed + ":3") << xml.what();

    std::string text = MeasuredPlant(Upright(10, 10));
    text.replace(text.find("5 0 0 2"), 7, "5 0 x 2");  // leaf 6's mat
    const std::string badMat = WriteTempFile("badmat.opf", text);
    const InputError mat = ErrorOf([&] { ReadOpf(badMat); });
    EXPECT_EQ(mat.Field(), badMat + ":" + std::to_string(LineOf(text, "<mat>", "id=\"6\"")));
    EXPECT_NE(std::string(mat.what()).find("'x'"), std::string::npos) << mat.what();

    text = MeasuredPlant(Upright(10, 10));
    text.replace(text.find("<shapeIndex>1</shapeIndex>"), 26, "<shapeIndex>9</shapeIndex>");
    const std::string badShape = WriteTempFile("badshape.opf", text);
    const InputError shape = ErrorOf([&] { ReadOpf(badShape); });
    EXPECT_EQ(shape.Code(), ErrorCode::kNotFound);
    EXPECT_EQ(shape.Node(), 6u);  // leaf 6 is the first to use shape 1 in document order
    EXPECT_EQ(shape.Field(), badShape + ":" + std::to_string(LineOf(text, "<shapeIndex>9")));
}

TEST(ImportErrors, ObjErrorsNameTheFileAndLine) {
    const std::string path = WriteTempFile("words.obj", "v 0 0 0\nv 1 0 0\n\nv 0 one 0\n");
    const InputError e = ErrorOf([&] { ReadObj(path); });
    EXPECT_EQ(e.Code(), ErrorCode::kParse);
    EXPECT_EQ(e.Field(), path + ":4");
    EXPECT_NE(std::string(e.what()).find("vertex y"), std::string::npos) << e.what();
}

TEST(ImportErrors, SharedMeshErrorsNameTheMeshAndListPosition) {
    // OPF: the second face of mesh 1 names a point the mesh does not have.
    std::string text = MeasuredPlant(Upright(10, 10));
    const std::size_t mesh1 = text.find("<mesh name=\"\" Id=\"1\">");
    text.replace(text.find("0 2 3", mesh1), 5, "0 2 7");
    const std::string path = WriteTempFile("badface.opf", text);
    const InputError opf = ErrorOf([&] { ReadOpf(path); });
    EXPECT_NE(std::string(opf.what()).find("meshBDD mesh 1, faces[1]"), std::string::npos)
        << opf.what();
    EXPECT_EQ(opf.Field(), path + ":" + std::to_string(LineOf(text, "0 2 7")));

    // Scene files: a shared mesh's zero-area triangle is named by the mesh and its position,
    // not by whichever organ was checked first.
    const std::string scene = WriteTempFile("shared.scene.txtpb", R"(
bands { name: "PAR" }
optics { id: "leaf" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 } } }
meshes { key: "blade" value { positions: [0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0] triangles: [0, 1, 2, 0, 1, 3] } }
nodes { id: 1 name: "a" organ { optics: "leaf" mesh_ref: "blade" } }
nodes { id: 2 name: "b" organ { optics: "leaf" mesh_ref: "blade" } }
)");
    const InputError shared = ErrorOf([&] { LoadSceneFile(scene); });
    EXPECT_EQ(shared.Code(), ErrorCode::kDegenerate);
    EXPECT_EQ(shared.Field(), "meshes[blade].triangles[1]") << shared.what();
    EXPECT_NE(std::string(shared.what()).find("shared mesh"), std::string::npos) << shared.what();
}

TEST(ImportErrors, HugeCoordinatesAreOutOfRangeNotZeroArea) {
    const std::string obj = WriteTempFile("far.obj", "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n");
    const InputError read = ErrorOf([&] { ReadObj(obj); });
    EXPECT_EQ(read.Field(), obj + ":2");
    EXPECT_NE(std::string(read.what()).find("out of range"), std::string::npos) << read.what();

    // An OPF frame that throws a leaf 1e300 cm away.
    std::string text = MeasuredPlant(Upright(10, 10));
    text.replace(text.find("5 0 0 2"), 7, "5 0 0 1e300");
    const std::string opf = WriteTempFile("far.opf", text);
    for (bool strict : {false, true}) {
        const InputError placed = ErrorOf([&] { ReadOpf(opf, ImportOptions{strict}); });
        EXPECT_EQ(placed.Code(), ErrorCode::kInvalidArgument);
        EXPECT_EQ(placed.Node(), 6u);
        EXPECT_EQ(placed.Field(), opf + ":" + std::to_string(LineOf(text, "<mat>", "id=\"6\"")));
        EXPECT_NE(std::string(placed.what()).find("out of range"), std::string::npos)
            << placed.what();
    }

    // Scene validation says the same of a mesh given directly.
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0, 0}}}};
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {{0, 0, 0}, {1e300, 0, 0}, {0, 1, 0}};
    mesh->triangles = {{0, 1, 2}};
    Node leaf;
    leaf.id = 1;
    leaf.Edit().organ = Organ{mesh, "leaf"};
    scene.nodes = {leaf};
    const InputError valid = ErrorOf([&] { scene.Validate(); });
    EXPECT_EQ(valid.Code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(valid.what()).find("out of range"), std::string::npos) << valid.what();
    EXPECT_EQ(std::string(valid.what()).find("zero area"), std::string::npos) << valid.what();
}

}  // namespace
}  // namespace leaflux
