// Writers: Gmsh reads our MSH 4.1 back with the same nodes, elements, groups and data; files are
// replaced atomically; JSON is well formed.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "io/atomic_file.hpp"
#include "io/json_writer.hpp"
#include "io/mesh_writers.hpp"
#include "io/msh_writer.hpp"
#include "io/vtu_writer.hpp"
#include "linear/linear_mesher.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

Mesh curvedBoxWithHole(int order) {
  const CadModel cad = test::toModel(test::boxWithHole());
  return elevateOrder(generateLinearMesh(cad, LinearMeshOptions::uniform(0.9)), order, &cad);
}

std::vector<CellField> fieldFor(const Mesh& mesh) {
  const QualitySummary q = evaluateQuality(mesh);
  CellField f{"scaled_jacobian", q.scaledJacobian};
  f.values.insert(f.values.end(), q.boundaryScaledJacobian.begin(), q.boundaryScaledJacobian.end());
  return {f};
}

TEST(MshWriter, GmshReadsBackNodesElementsGroupsAndData) {
  const auto dir = test::tempDir();
  for (const int order : {1, 3, 6}) {
    const Mesh mesh = curvedBoxWithHole(order);
    const std::string path = (dir / ("mesh" + std::to_string(order) + ".msh")).string();
    writeMsh41(mesh, path, fieldFor(mesh), false);

    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::open(path);
    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, true, false);
    EXPECT_EQ(tags.size(), mesh.numNodes());
    for (std::size_t k = 0; k < tags.size(); ++k)
      for (int c = 0; c < 3; ++c)
        ASSERT_DOUBLE_EQ(coord[3 * k + c], mesh.xyz[3 * (tags[k] - 1) + c]);  // 17 digits: exact

    std::map<int, std::size_t> counts;  // gmsh type -> count
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> elementTags, nodeTags;
    gmsh::model::mesh::getElements(types, elementTags, nodeTags);
    for (std::size_t k = 0; k < types.size(); ++k) counts[types[k]] += elementTags[k].size();
    for (const ElementBlock& b : mesh.blocks)
      EXPECT_EQ(counts[gmshElementType(b.type, order)], b.count()) << cellShortName(b.type);

    gmsh::vectorpair groups;
    gmsh::model::getPhysicalGroups(groups, 3);
    ASSERT_EQ(groups.size(), 1u);
    std::string name;
    gmsh::model::getPhysicalName(3, groups[0].second, name);
    EXPECT_EQ(name, "Solid1");
    gmsh::model::getPhysicalGroups(groups, 2);
    EXPECT_EQ(groups.size(), 7u);

    std::vector<int> views;
    gmsh::view::getTags(views);
    ASSERT_EQ(views.size(), 1u);
    std::string dataType;
    std::vector<std::size_t> dataTags;
    std::vector<std::vector<double>> data;
    double time = 0.0;
    int components = 0;
    gmsh::view::getModelData(views[0], 0, dataType, dataTags, data, time, components);
    EXPECT_EQ(dataType, "ElementData");
    EXPECT_EQ(dataTags.size(), fieldFor(mesh)[0].values.size());
    gmsh::finalize();
  }
}

TEST(VtuWriter, WritesLagrangeCellsAndFields) {
  const auto dir = test::tempDir();
  const Mesh mesh = curvedBoxWithHole(3);
  const std::string path = (dir / "mesh.vtu").string();
  writeVtu(mesh, path, fieldFor(mesh), false);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  EXPECT_NE(xml.find("NumberOfCells=\"" + std::to_string(mesh.numElements()) + "\""),
            std::string::npos);
  EXPECT_NE(xml.find("NumberOfPoints=\"" + std::to_string(mesh.numNodes()) + "\""),
            std::string::npos);
  EXPECT_NE(xml.find("Name=\"scaled_jacobian\""), std::string::npos);
  EXPECT_NE(xml.find("</VTKFile>"), std::string::npos);
}

TEST(Writers, FailuresLeaveNoPartialFileAndNameThePath) {
  const auto dir = test::tempDir();
  const Mesh mesh = curvedBoxWithHole(2);
  try {
    writeMesh(mesh, (dir / "missing" / "out.msh").string(), {});
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos);
  }
  EXPECT_THROW(writeMesh(mesh, (dir / "out.xyz").string(), {}), IoError);
  CellField wrong{"q", {1.0, 2.0}};
  EXPECT_THROW(writeMesh(mesh, (dir / "out.msh").string(), {wrong}), Error);
  // Nothing was left behind, not even the temporary ".part" file.
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(AtomicFile, UncommittedOrFailedWritesLeaveNothingBehind) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "out.txt").string();
  {
    AtomicFile file(path, false);
    file.stream() << "half a file";
    EXPECT_TRUE(std::filesystem::exists(path + ".part"));
  }  // destroyed without commit, as when a writer throws half-way
  EXPECT_TRUE(std::filesystem::is_empty(dir));

  // The final rename fails (the target is a folder): IoError, and no ".part" is left.
  std::filesystem::create_directory(dir / "taken");
  const std::string taken = (dir / "taken").string();
  {
    AtomicFile file(taken, false);
    file.stream() << "data";
    EXPECT_THROW(file.commit(), IoError);
  }
  EXPECT_FALSE(std::filesystem::exists(taken + ".part"));

  // A committed file replaces the old one completely.
  writeFileAtomically(path, "first version, long");
  writeFileAtomically(path, "second");
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "second");
}

TEST(JsonWriter, NestsAndEscapes) {
  JsonWriter json;
  json.beginObject();
  json.value("name", "a \"quoted\"\nline");
  json.value("n", 3);
  json.value("x", 0.25);
  json.value("nan", std::numeric_limits<double>::quiet_NaN());
  json.beginObject("empty").endObject();
  json.beginArray("list").value("", 1).value("", true).endArray();
  json.numbers("edges", std::vector<double>{0, 0.5, 1});
  json.numbers("counts", std::vector<std::size_t>{2, 0});
  json.endObject();
  EXPECT_EQ(json.str(),
            "{\n  \"name\": \"a \\\"quoted\\\"\\nline\",\n  \"n\": 3,\n  \"x\": 0.25,\n"
            "  \"nan\": null,\n  \"empty\": {},\n  \"list\": [\n    1,\n    true\n  ],\n"
            "  \"edges\": [0, 0.5, 1],\n  \"counts\": [2, 0]\n}\n");
}

}  // namespace
}  // namespace homesh
