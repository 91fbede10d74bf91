// Putting a mesh made elsewhere on the CAD: the linear mesher's own mesh of a shape, stripped of
// its node records (as FreeCAD FEM's meshers hand a mesh over), classified again, must get the
// records the mesher gave it: the same entity for every node, parameters that reproduce the
// node, the same boundary triangles on the same faces and segments on the same edges.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "core/error.hpp"
#include "linear/cad_classification.hpp"
#include "linear/linear_mesher.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::nodePoint;

// Only the tetrahedra and the coordinates, in reverse node order and with half the tetrahedra
// turned over: what another tool may hand over.
Mesh strip(const Mesh& made) {
  Mesh bare;
  bare.dim = 3;
  bare.order = 1;
  const std::size_t n = made.numNodes();
  bare.xyz.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) bare.xyz[3 * (n - 1 - i) + k] = made.xyz[3 * i + k];
  ElementBlock tets = made.blocks[0];
  for (std::size_t e = 0; e < tets.count(); ++e) {
    std::int64_t* t = tets.nodes.data() + 4 * e;
    for (int k = 0; k < 4; ++k) t[k] = static_cast<std::int64_t>(n) - 1 - t[k];
    if (e % 2 == 1) std::swap(t[1], t[2]);
  }
  bare.blocks.push_back(tets);
  bare.nodeCadDim.assign(n, 3);
  bare.nodeCadIndex.assign(n, 0);
  bare.nodeCadParam.assign(2 * n, std::nan(""));
  return bare;
}

using Key = std::vector<std::int64_t>;

std::map<Key, int> cellsByNodes(const ElementBlock& b, std::size_t n, bool reversed) {
  std::map<Key, int> out;
  const int k = cellNumVertices(b.type);
  for (std::size_t e = 0; e < b.count(); ++e) {
    Key key(b.element(e), b.element(e) + k);
    if (reversed)
      for (auto& v : key) v = static_cast<std::int64_t>(n) - 1 - v;
    std::sort(key.begin(), key.end());
    out[key] = b.entity[e];
  }
  return out;
}

TEST(CadClassification, AMeshOfTheShapeGetsBackTheRecordsItsMesherGaveIt) {
  for (const bool hole : {false, true}) {
    const CadModel cad = CadModel::fromBrepText(
        test::brepText(hole ? test::boxWithHole() : test::cylinder(1.0, 2.0)));
    const Mesh made = generateLinearMesh(cad, LinearMeshOptions::uniform(hole ? 0.6 : 0.4));
    CadClassificationStats stats;
    const Mesh again = classifyOnCad(strip(made), cad, 0.0, &stats);
    const std::size_t n = made.numNodes();
    ASSERT_EQ(again.numNodes(), n);
    // Gmsh computes each boundary node through OCCT from its parameters, so a node is on its
    // entity to rounding (|x| <= 4: ~1e-15); the classification's tolerance is 1e-5 of the
    // diagonal. Entities must match exactly; positions after the snap within the tolerance.
    const double tolerance = 1e-5 * cad.boundingDiagonal();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = n - 1 - i;
      ASSERT_EQ(again.nodeCadDim[j], made.nodeCadDim[i]) << "node " << i;
      if (made.nodeCadDim[i] < 3) {
        ASSERT_EQ(again.nodeCadIndex[j], made.nodeCadIndex[i]) << "node " << i;
      }
      EXPECT_LE((nodePoint(again, j) - nodePoint(made, i)).norm(), tolerance);
      const int dim = made.nodeCadDim[i];
      const int index = made.nodeCadIndex[i];
      const double* p = &again.nodeCadParam[2 * j];
      if (dim == 1) {
        EXPECT_LE((cad.evaluateCurve(index, p[0]).point - nodePoint(again, j)).norm(), 1e-9);
      }
      if (dim == 2) {
        EXPECT_LE((cad.evaluateSurface(index, p[0], p[1]).point - nodePoint(again, j)).norm(),
                  1e-9);
      }
    }
    EXPECT_EQ(stats.boundaryNodes, stats.onVertices + stats.onEdges + stats.onFaces);
    EXPECT_GT(stats.onEdges, 0u);
    // Boundary triangles and segments: the same cells on the same entities.
    EXPECT_EQ(cellsByNodes(again.blocks[1], n, true), cellsByNodes(made.blocks[1], n, false));
    EXPECT_EQ(cellsByNodes(again.blocks[2], n, true), cellsByNodes(made.blocks[2], n, false));
    // Every tetrahedron positive, every boundary triangle pointing out of the solid.
    const ElementBlock& tets = again.blocks[0];
    for (std::size_t e = 0; e < tets.count(); ++e) {
      const std::int64_t* t = tets.element(e);
      const Eigen::Vector3d a = nodePoint(again, t[0]);
      EXPECT_GT((nodePoint(again, t[1]) - a)
                    .cross(nodePoint(again, t[2]) - a)
                    .dot(nodePoint(again, t[3]) - a),
                0.0);
    }
  }
}

TEST(CadClassification, ANodeOffTheShapeIsNamed) {
  const CadModel cad = CadModel::fromBrepText(test::brepText(test::box(1, 1, 1)));
  Mesh mesh = strip(generateLinearMesh(cad, LinearMeshOptions::uniform(0.5)));
  // The first node made is a vertex of the box (a corner, last after the strip): moved out of
  // the box along its diagonal, it is on no face.
  const std::size_t last = mesh.numNodes() - 1;
  const Eigen::Vector3d corner = nodePoint(mesh, last);
  const Eigen::Vector3d out = (corner - Eigen::Vector3d(0.5, 0.5, 0.5)).normalized();
  for (int k = 0; k < 3; ++k) mesh.xyz[3 * last + k] += 0.01 * out[k];
  try {
    classifyOnCad(mesh, cad);
    FAIL() << "a node 0.01 off the box was accepted";
  } catch (const MeshingError& e) {
    const std::string expected = "boundary node " + std::to_string(last + 1) + " at";
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nearest: Face"), std::string::npos) << e.what();
  }
  Mesh flat = mesh;
  flat.dim = 2;
  EXPECT_THROW(classifyOnCad(flat, cad), ParameterError);
}

}  // namespace
}  // namespace homesh
