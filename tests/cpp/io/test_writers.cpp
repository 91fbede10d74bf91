// Writers: Gmsh reads our MSH 4.1 back with the same nodes, elements, groups and data; files are
// replaced atomically; JSON is well formed.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "element/jacobian_sampler.hpp"
#include "element/reference_element.hpp"
#include "io/atomic_file.hpp"
#include "io/json_writer.hpp"
#include "io/mesh_writers.hpp"
#include "io/msh_reader.hpp"
#include "io/msh_writer.hpp"
#include "io/vtk_readers.hpp"
#include "io/vtu_writer.hpp"
#include "linear/linear_mesher.hpp"
#include "peers/gmsh_quality.hpp"
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
        // The shortest text that reads back as the same double (std::to_chars): bit for bit.
        ASSERT_EQ(coord[3 * k + c], mesh.xyz[3 * (tags[k] - 1) + c]);

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

// Curved pyramids, orders 1 to 6 (each a sheared reference pyramid with its nodes moved at
// random, a few tangled): our MSH reads back bit for bit, and Gmsh reads it and maps every
// pyramid as we do, point for point, its Jacobian included; at order 1 its verdict is ours.
// (Gmsh 4.8's AnalyseMeshQuality is no referee for pyramids above order 1: on these it gives 0 for
// curved pyramids our bounds and a dense sampling find valid at orders 2 and 3, and 0 and -0.59 for
// the straight one at orders 5 and 6, whose J is constant; test_jacobian_quality.cpp checks our
// bounds against sampling.)
TEST(MshWriter, PyramidsRoundTripAndGmshMapsThemAsWeDo) {
  const auto dir = test::tempDir();
  std::mt19937 rng(23);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int order = 1; order <= 6; ++order) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Pyramid, order);
    Mesh mesh;
    mesh.dim = 3;
    mesh.order = order;
    ElementBlock block;
    block.type = CellType::Pyramid;
    block.order = order;
    for (int e = 0; e < 8; ++e) {
      const double amplitude = 0.04 * e / std::pow(order, 1.5);
      for (int n = 0; n < ref.numNodes(); ++n) {
        const Eigen::Vector3d xi = ref.nodes().row(n).transpose();
        Eigen::Vector3d x(2.0 * xi.x() + 0.3 * xi.y() + 0.1 * xi.z() + 3.0 * e,
                          1.5 * xi.y() - 0.2 * xi.z(), 0.7 * xi.z());
        for (int c = 0; c < 3; ++c) x(c) += amplitude * gauss(rng);
        block.nodes.push_back(mesh.addNode(x.data(), 3, 1, NAN, NAN));
      }
      block.entity.push_back(1);
    }
    mesh.blocks.push_back(block);
    const std::string path = (dir / ("pyramids" + std::to_string(order) + ".msh")).string();
    writeMsh41(mesh, path, {}, false);

    const Mesh back = readMsh(path);
    ASSERT_EQ(back.xyz, mesh.xyz) << "order " << order;
    ASSERT_EQ(back.blocks.size(), 1u);
    EXPECT_EQ(back.blocks[0].type, CellType::Pyramid);
    EXPECT_EQ(back.blocks[0].order, order);
    EXPECT_EQ(back.blocks[0].nodes, mesh.blocks[0].nodes);
    // VTU: linear pyramids are VTK_PYRAMID and read back; VTK 9.1 has no curved pyramid, so
    // those are refused with the reason and nothing is written.
    const std::string vtu = (dir / ("pyramids" + std::to_string(order) + ".vtu")).string();
    if (order == 1) {
      writeVtu(mesh, vtu, {}, false);
      const Mesh fromVtu = readVtu(vtu);
      EXPECT_EQ(fromVtu.xyz, mesh.xyz);
      ASSERT_EQ(fromVtu.blocks.size(), 1u);
      EXPECT_EQ(fromVtu.blocks[0].type, CellType::Pyramid);
      EXPECT_EQ(fromVtu.blocks[0].nodes, mesh.blocks[0].nodes);
    } else {
      EXPECT_THROW(writeMesh(mesh, vtu, {}), ParameterError);
      EXPECT_FALSE(std::filesystem::exists(vtu));
    }

    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::open(path);
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> elementTags, nodeTags;
    gmsh::model::mesh::getElements(types, elementTags, nodeTags, 3);
    ASSERT_EQ(types, std::vector<int>{gmshElementType(CellType::Pyramid, order)});
    ASSERT_EQ(elementTags[0].size(), 8u);
    if (order == 1) {  // Gmsh's verdict agrees where it holds (see above): the worst minJ/maxJ,
                       // both refined to 1e-3 of J
      const std::vector<double>& ours = evaluateQuality(mesh).scaledJacobian;
      EXPECT_NEAR(peers::gmshAnalyseScaledJacobian(3), *std::min_element(ours.begin(), ours.end()),
                  2e-3);
    }
    // Gmsh's own map at random points of its reference pyramid (base [-1, 1]^2, apex (0, 0, 1)
    // above its centre): X = 2x + z - 1, Y = 2y + z - 1 from ours, so its J is ours / 4.
    std::vector<double> local, gmshX;
    Eigen::MatrixXd points(20, 3);
    std::uniform_real_distribution<double> u(0.01, 0.99);
    for (int q = 0; q < points.rows(); ++q) {
      const double z = u(rng), x = u(rng) * (1.0 - z), y = u(rng) * (1.0 - z);
      points.row(q) << x, y, z;
      local.insert(local.end(), {2.0 * x + z - 1.0, 2.0 * y + z - 1.0, z});
    }
    std::vector<double> jacobians, determinants;
    gmsh::model::mesh::getJacobians(types[0], local, jacobians, determinants, gmshX);
    gmsh::finalize();
    const JacobianSampler sampler(ref, points);
    Eigen::VectorXd jac;
    for (std::size_t e = 0; e < 8; ++e) {
      NodeCoordinates x(ref.numNodes(), 3);
      for (int n = 0; n < ref.numNodes(); ++n)
        for (int c = 0; c < 3; ++c)
          x(n, c) = mesh.xyz[3 * static_cast<std::size_t>(block.nodes[e * ref.numNodes() + n]) + c];
      sampler.jacobians(x, nullptr, jac);
      const Eigen::MatrixXd at = ref.valuesAt(points) * x;
      for (int q = 0; q < points.rows(); ++q) {
        const std::size_t k = e * static_cast<std::size_t>(points.rows()) + q;
        // Both interpolate the same nodes in the same space: each side errs by about N eps
        // times the Lebesgue function (below 20 here) times the coordinates (below 25), 1e-11
        // at N = 140, and J by a few times that relative to its size. Measured: 1.4e-13 and
        // 2.3e-12 at most; the tolerances are 1e-10 and 1e-9. A different space or node order
        // moves points by 1e-2 or more.
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(gmshX[3 * k + c], at(q, c), 1e-10) << "order " << order << " element " << e;
        ASSERT_NEAR(4.0 * determinants[k], jac(q), 1e-9 * std::max(1.0, std::abs(jac(q))))
            << "order " << order << " element " << e;
      }
    }
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
