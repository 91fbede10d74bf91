// Readers of FreeCAD FEM's formats (I-DEAS UNV, legacy VTK, VTU) on small files written here:
// node orders against the reference element's lattice, mirrored solids, errors naming the line.
// tests/python/test_fem_formats.py reads files FreeCAD itself wrote.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "element/element_measure.hpp"
#include "element/node_ordering.hpp"
#include "io/mesh_readers.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

std::string writeFile(const std::string& name, const std::string& text) {
  std::string path = (test::tempDir() / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The unit tetrahedron's order-2 lattice point (c / 2) of each node, in Gmsh's order.
std::vector<std::array<double, 3>> gmshPositions(CellType type, int order) {
  std::vector<std::array<double, 3>> out;
  for (const LatticePoint& c : latticeOrder(type, order, NodeConvention::Gmsh))
    out.push_back({double(c[0]) / order, double(c[1]) / order, double(c[2]) / order});
  return out;
}

std::string unvNode(int label, const std::array<double, 3>& x) {
  std::ostringstream os;
  os.precision(17);
  os << "  " << label << " 1 1 11\n  " << x[0] << " " << x[1] << " " << x[2] << "\n";
  return os.str();
}

// A UNV file of the unit parabolic tetrahedron with a parabolic triangle on its face z = 0 and
// a 3-node beam on edge x, node labels 101.. in an order unrelated to either convention.
std::string parabolicTetrahedronUnv() {
  const auto p = gmshPositions(CellType::Tetrahedron, 2);  // c0 c1 c2 c3 m01 m12 m20 m03 m23 m13
  std::string text = "    -1\n  2411\n";
  const int labelOf[10] = {107, 103, 110, 101, 105, 102, 109, 104, 108, 106};
  for (int k = 0; k < 10; ++k) text += unvNode(labelOf[k], p[k]);
  text += "    -1\n    -1\n  2412\n";
  // UNV order of the parabolic tetrahedron: c0 m01 c1 m12 c2 m20 m03 m13 m23 c3.
  const int tet[10] = {0, 4, 1, 5, 2, 6, 7, 9, 8, 3};
  text += "  1 118 2 1 7 10\n";
  for (int k = 0; k < 10; ++k) text += " " + std::to_string(labelOf[tet[k]]) + (k == 7 ? "\n" : "");
  text += "\n  2 42 2 1 7 6\n";  // triangle c0 m01 c1 m12 c2 m20: face z = 0 (0, 1, 2)
  for (const int k : {0, 4, 1, 5, 2, 6}) text += " " + std::to_string(labelOf[k]);
  text += "\n  3 22 2 1 7 3\n  0 1 1\n";  // beam c0 m c1 along x: nodes 0, 4, 1
  for (const int k : {0, 4, 1}) text += " " + std::to_string(labelOf[k]);
  return text + "\n    -1\n";
}

TEST(UnvReader, ParabolicCellsLandInGmshOrder) {
  std::vector<std::string> notes;
  const Mesh mesh = readMesh(writeFile("tet.unv", parabolicTetrahedronUnv()), &notes);
  ASSERT_EQ(mesh.dim, 3);
  ASSERT_EQ(mesh.order, 2);
  ASSERT_EQ(mesh.blocks.size(), 3u);
  EXPECT_TRUE(notes.empty());
  for (const ElementBlock& b : mesh.blocks) {
    ASSERT_EQ(b.count(), 1u);
    const auto expect = gmshPositions(b.type, 2);  // line and triangle lie on the tet's axes
    for (int k = 0; k < b.nodesPerElement(); ++k)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(mesh.xyz[3 * b.element(0)[k] + c], expect[k][c])
            << cellShortName(b.type) << " node " << k;
  }
  EXPECT_NEAR(elementMeasures(mesh)[0], 1.0 / 6.0, 1e-15);
}

TEST(UnvReader, MidEdgeNodePastTheQuarterPointInvalidatesTheTetrahedron) {
  // The node of edge 0-1 at t along it: J at vertex 0 is proportional to 4t - 1.
  for (const double t : {0.2, 0.3}) {
    std::string text = parabolicTetrahedronUnv();
    const std::string midpoint = "  105 1 1 11\n  0.5 0 0\n";
    const auto at = text.find(midpoint);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, midpoint.size(), "  105 1 1 11\n  " + std::to_string(t) + " 0 0\n");
    const Mesh mesh = readMesh(writeFile("t.unv", text));
    const QualitySummary q = evaluateQuality(mesh);
    EXPECT_EQ(q.invalid, t < 0.25 ? 1u : 0u) << "t = " << t;
  }
}

TEST(UnvReader, ErrorsNameTheFileLineAndLabel) {
  const std::string good = parabolicTetrahedronUnv();
  struct Case {
    std::string from, to, phrase;
  };
  const std::vector<Case> cases = {
      {"  1 118 2 1 7 10", "  1 118 2 1 7 9",
       "line 26: element 1 (FE descriptor 118, a "
       "tetrahedron) has 9 nodes"},
      {"  1 118 2 1 7 10", "  1 116 2 1 7 20", "serendipity"},
      {"  1 118 2 1 7 10", "  1 137 2 1 7 10", "line 26: element 1 has FE descriptor 137"},
      {" 107 105 103 102 110 109 104 106", " 107 105 103 102 110 109 104 999",
       "element 1 refers to node 999, which dataset 2411 does not define"},
      {"  107 1 1 11\n  0 0 0", "  107 1 1 11\n  0 0 nan", "line 4: node 107 has a coordinate"},
      {"  107 1 1 11\n  0 0 0", "  107 1 1 11\n  0 0", "line 4: node 107: 3 coordinates"},
      {"  103 1 1 11", "  107 1 1 11", "line 5: node 107 is defined twice"},
      {"  3 22 2 1 7 3\n  0 1 1\n", "  3 22 2 1 7 3\n",
       "line 31: element 3 lists 0 of its 3 nodes"},
      {"  2412", "  2412b", "dataset 2412 is binary"},
      {"    -1\n    -1\n  2412", "    -1\n  2412", "'-1' expected"},
  };
  for (const Case& c : cases) {
    std::string text = good;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    const std::string path = writeFile("bad.unv", text);
    try {
      readMesh(path);
      ADD_FAILURE() << "no error for " << c.to;
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path), std::string::npos) << what;
      EXPECT_NE(what.find(c.phrase), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  // Truncated anywhere: an error, never a crash or a silently short mesh.
  for (std::size_t n = 0; n + 8 < good.size(); n += 7) {
    const std::string path = writeFile("cut.unv", good.substr(0, n));
    EXPECT_THROW(readMesh(path), IoError) << "cut at " << n;
  }
}

TEST(MirrorPermutation, IsAnInvolutionThatReversesTheSign) {
  for (const CellType type : {CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
                              CellType::Prism, CellType::Hexahedron})
    for (int order = 1; order <= 4; ++order) {
      const std::vector<int> perm = mirrorPermutation(type, order);
      const auto p = gmshPositions(type, order);
      NodeCoordinates x(static_cast<int>(p.size()), 3), mirrored(static_cast<int>(p.size()), 3);
      for (std::size_t k = 0; k < p.size(); ++k) {
        // A curved element: the reference one bent by a smooth map.
        const double u = p[k][0], v = p[k][1], w = p[k][2];
        x.row(static_cast<int>(k)) << u + 0.1 * v * v, v + 0.05 * u * w, w + 0.1 * u * v;
        EXPECT_EQ(perm[perm[k]], static_cast<int>(k));
      }
      for (std::size_t k = 0; k < p.size(); ++k) mirrored.row(static_cast<int>(k)) = x.row(perm[k]);
      const Eigen::Vector3d normal(0, 0, 1);
      const Eigen::Vector3d* n = cellDimension(type) == 2 ? &normal : nullptr;
      const double a = elementMeasure(type, order, x, n),
                   b = elementMeasure(type, order, mirrored, n);
      EXPECT_GT(a, 0.0);
      EXPECT_NEAR(b, -a, 1e-13) << cellShortName(type) << " order " << order;
    }
}

// Legacy VTK files (version 4.2: CELLS lists) of one quadratic tetrahedron listed left-handed,
// read mirrored with a note, and of one VTK_WEDGE, whose right-handed form in VTK turns its
// first triangle away from the second (the opposite of Gmsh's prism), read as it is.
TEST(LegacyVtkReader, HandednessOfTetrahedraAndWedges) {
  const auto p = gmshPositions(CellType::Tetrahedron, 2);
  std::ostringstream tet;
  tet << "# vtk DataFile Version 4.2\nleft-handed\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      << "POINTS 10 double\n";
  for (const auto& x : p) tet << x[0] << " " << x[1] << " " << x[2] << "\n";
  // VTK_QUADRATIC_TETRA with corners 1 and 2 swapped: c0 c2 c1 c3, then its edges (0,1) (1,2)
  // (2,0) (0,3) (1,3) (2,3), which are Gmsh's m20 m12 m01 m03 m23 m13: nodes 6 5 4 7 8 9.
  tet << "CELLS 1 11\n10 0 2 1 3 6 5 4 7 8 9\nCELL_TYPES 1\n24\n";
  std::vector<std::string> notes;
  const Mesh mesh = readMesh(writeFile("left.vtk", tet.str()), &notes);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("the 1 tetrahedron of the file has negative volume"), std::string::npos)
      << notes[0];
  EXPECT_NEAR(elementMeasures(mesh)[0], 1.0 / 6.0, 1e-15);
  EXPECT_EQ(evaluateQuality(mesh).invalid, 0u);

  const std::string wedge =
      "# vtk DataFile Version 4.2\nwedge\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 6 float\n0 0 0 0 1 0 1 0 0 0 0 1 0 1 1 1 0 1\n"
      "CELLS 1 7\n6 0 1 2 3 4 5\nCELL_TYPES 1\n13\n";
  notes.clear();
  const Mesh prism = readMesh(writeFile("wedge.vtk", wedge), &notes);
  EXPECT_TRUE(notes.empty());
  EXPECT_NEAR(elementMeasures(prism)[0], 0.5, 1e-15);
}

}  // namespace
}  // namespace homesh
