// Every importer on the files of ../shared/data, and on broken files.
#include "solver/io/importers.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>

#include "solver/scene/scene.h"
#include "solver/scene/world_frames.h"
#include "solver/util/error.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

std::string Data(const std::string& name) { return std::string(LEAFLUX_SHARED_DATA) + "/" + name; }

using testing::WriteTempFile;

int TriangleCount(const ImportedGeometry& g) {
    int count = 0;
    for (const Node& node : g.nodes)
        count += node.organ() ? static_cast<int>(node.organ()->mesh->triangles.size()) : 0;
    return count;
}

TEST(ReadObj, ReadsEachLeafPrototypeAsOneNamedOrgan) {
    for (const char* file : {"AlmondLeaf.obj", "BindweedLeaf.obj", "RedbudLeaf.obj"}) {
        const ImportedGeometry g = ReadObj(Data(std::string("leaves/") + file));
        ASSERT_EQ(g.nodes.size(), 1u) << file;
        EXPECT_EQ(g.nodes[0].name(), "leaf");
        EXPECT_EQ(g.nodes[0].type(), NodeType::kLeaf);
        EXPECT_FALSE(g.nodes[0].organ()->opticsId.empty());
        EXPECT_GT(MeshArea(*g.nodes[0].organ()->mesh, glm::dmat4(1.0)), 0.0);
    }
    // Quads are split in two: the Almond leaf's 16 faces.
    EXPECT_GE(TriangleCount(ReadObj(Data("leaves/AlmondLeaf.obj"))), 16);
}

TEST(ReadObj, SplitsGroupsAndMaterials) {
    const std::string path =
        WriteTempFile("groups.obj",
                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                      "g stem\nusemtl bark\nf 1 2 3\n"
                      "g blade\nusemtl green\nf 1 3 4\nusemtl yellow\nf -4 -3 -1\n");
    const ImportedGeometry g = ReadObj(path);
    ASSERT_EQ(g.nodes.size(), 3u);
    EXPECT_EQ(g.nodes[0].name(), "stem");
    EXPECT_EQ(g.nodes[0].organ()->opticsId, "bark");
    EXPECT_EQ(g.nodes[0].type(), NodeType::kInternode);
    EXPECT_EQ(g.nodes[1].organ()->opticsId, "green");
    EXPECT_EQ(g.nodes[2].name(), "blade/yellow");
}

TEST(ReadObj, RejectsBadFacesWithFileAndLine) {
    try {
        ReadObj(WriteTempFile("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n"));
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kParse);
        EXPECT_NE(e.Field().find("bad.obj:3"), std::string::npos) << e.what();
    }
    EXPECT_THROW(ReadObj(WriteTempFile("nan.obj", "v 0 0 nan\n")), InputError);
    EXPECT_THROW(ReadObj(Data("no/such/file.obj")), InputError);
}

TEST(ReadCan, DecodesLabelsOfTheSeedlingTray) {
    const ImportedGeometry g = ReadCan(Data("caribu/bac1.can"));
    EXPECT_EQ(TriangleCount(g), 2270);
    int plants = 0, species1 = 0, species2 = 0;
    for (const Node& node : g.nodes) {
        plants += node.type() == NodeType::kPlant;
        if (!node.organ()) continue;
        EXPECT_NE(node.parent, kNoParent);
        species1 += node.organ()->opticsId.str().rfind("species1", 0) == 0;
        species2 += node.organ()->opticsId.str().rfind("species2", 0) == 0;
    }
    EXPECT_GT(plants, 1);
    EXPECT_GT(species1, 0);
    EXPECT_GT(species2, 0);
}

TEST(ReadCan, ReadsSoilAsEnvironment) {
    const ImportedGeometry g = ReadCan(Data("caribu/test.can"));
    ASSERT_EQ(g.environment.size(), 0u);  // test.can has no species-0 polygon
    const ImportedGeometry s = ReadCan(WriteTempFile("soil.can",
                                                     "p 1 000000000001 3 0 0 0 1 0 0 0 1 0\n"
                                                     "p 1 100001001001 3 0 0 1 1 0 1 0 1 1\n"));
    ASSERT_EQ(s.environment.size(), 1u);
    EXPECT_EQ(s.environment[0].opticsId, "soil");
    EXPECT_THROW(ReadCan(WriteTempFile("badlabel.can", "p 1 12ab 3 0 0 0 1 0 0 0 1 0\n")),
                 InputError);
}

TEST(ReadCanOptics, ReadsSoilAndSpecies) {
    const CanOptics par = ReadCanOptics(Data("caribu/par.opt"));
    EXPECT_DOUBLE_EQ(par.soilRho, 0.15);
    ASSERT_EQ(par.species.size(), 2u);
    EXPECT_DOUBLE_EQ(par.species[0].stemRho, 0.10);
    EXPECT_DOUBLE_EQ(par.species[0].leaf.rhoUpper, 0.10);
    EXPECT_DOUBLE_EQ(par.species[0].leaf.tauUpperToLower, 0.05);
    EXPECT_DOUBLE_EQ(par.species[1].leaf.tauLowerToUpper, 0.005);
    const CanOptics nir = ReadCanOptics(Data("caribu/nir.opt"));
    EXPECT_DOUBLE_EQ(nir.species[0].leaf.tauUpperToLower, 0.45);
}

TEST(ReadCanLights, PointsTowardsTheSourceAndSumsTheSky) {
    const auto zenith = ReadCanLights(Data("caribu/zenith.light"));
    ASSERT_EQ(zenith.size(), 1u);
    EXPECT_EQ(zenith[0].towardSource, glm::dvec3(0, 0, 1));
    const auto turtle = ReadCanLights(Data("caribu/Turtle46soc.light"));
    ASSERT_EQ(turtle.size(), 46u);
    double total = 0.0;
    for (const CanLight& light : turtle) {
        EXPECT_GT(light.towardSource.z, 0.0);
        total += light.horizontalIrradiance;
    }
    EXPECT_NEAR(total, 1.0, 1e-3);  // the file's energies sum to one
}

TEST(ReadOpf, KeepsSharedMeshesAndTheTopology) {
    const ImportedGeometry g = ReadOpf(Data("opf/simple_plant.opf"));
    int organs = 0, leaves = 0;
    std::set<const Mesh*> meshes;
    for (const Node& node : g.nodes) {
        if (!node.organ()) continue;
        ++organs;
        leaves += node.type() == NodeType::kLeaf;
        meshes.insert(node.organ()->mesh.get());
    }
    EXPECT_EQ(organs, 4);
    EXPECT_EQ(leaves, 2);
    EXPECT_EQ(meshes.size(), 2u);  // two internodes share one mesh, two leaves the other
    // The topology validates, and the leaves sit where the file's global frames put them
    // (centimetres to metres): the second leaf's origin is 0.2 m up.
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"material0", {{0.1, 0.1, 0, 0}}}, {"material1", {{0.1, 0.1, 0.05, 0.05}}}};
    scene.nodes = g.nodes;
    EXPECT_NO_THROW(scene.Validate());
    const auto world = WorldFromLocal(scene);
    EXPECT_NEAR(world.at(7)[3].z, 0.20, 1e-6);
    EXPECT_NEAR(world.at(7)[3].x, -0.01, 1e-6);
}

TEST(ReadOpf, RejectsMalformedXml) {
    EXPECT_THROW(ReadOpf(WriteTempFile("bad.opf", "<opf><meshBDD></opf>")), InputError);
    EXPECT_THROW(ReadOpf(WriteTempFile(
                     "nomesh.opf",
                     "<opf><topology class=\"Scene\" "
                     "id=\"1\"><geometry><shapeIndex>3</shapeIndex></geometry></topology></opf>")),
                 InputError);
}

}  // namespace
}  // namespace leaflux
