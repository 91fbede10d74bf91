// Node orderings against Gmsh's own reference coordinates (getElementProperties), for every
// shape and order Gmsh 4.8 has (triangles, quadrilaterals, tetrahedra to 10; prisms and
// hexahedra to 9).
#include <gmsh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "element/node_ordering.hpp"
#include "element/reference_element.hpp"
#include "io/mesh_writers.hpp"

namespace homesh {
namespace {

// Gmsh's reference shapes: lines, quadrilaterals and hexahedra on [-1, 1]; prisms have
// z in [-1, 1]; simplices are unit like ours.
double fromGmsh(CellType type, int axis, double x) {
  const bool box =
      type == CellType::Line || type == CellType::Quadrilateral || type == CellType::Hexahedron;
  if (box || (type == CellType::Prism && axis == 2)) return 0.5 * (x + 1.0);
  return x;
}

int maxGmshOrder(CellType type) {
  return type == CellType::Prism || type == CellType::Hexahedron ? 9 : 10;
}

std::string shapeName(const ::testing::TestParamInfo<CellType>& param) {
  return cellShortName(param.param);
}

class GmshOrdering : public ::testing::TestWithParam<CellType> {
 protected:
  static void SetUpTestSuite() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    // Gmsh 4.8 logs "FaceClosureFull not implemented for prisms of order >= 3" while building
    // the element's properties; the reference nodes it returns are complete.
    gmsh::option::setNumber("General.AbortOnError", 0);
  }
  static void TearDownTestSuite() { gmsh::finalize(); }
};

TEST_P(GmshOrdering, MatchesGmshReferenceNodes) {
  const CellType type = GetParam();
  for (int p = 1; p <= maxGmshOrder(type); ++p) {
    std::string name;
    int dim = 0, order = 0, numNodes = 0, numPrimary = 0;
    std::vector<double> coord;
    gmsh::model::mesh::getElementProperties(gmshElementType(type, p), name, dim, order, numNodes,
                                            coord, numPrimary);
    ASSERT_EQ(order, p);
    const ReferenceElement& ref = ReferenceElement::get(type, p);
    ASSERT_EQ(numNodes, ref.numNodes()) << name;
    for (int i = 0; i < numNodes; ++i)
      for (int k = 0; k < dim; ++k)
        ASSERT_NEAR(ref.nodes()(i, k), fromGmsh(type, k, coord[i * dim + k]), 1e-12)
            << name << " order " << p << " node " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllShapes, GmshOrdering,
                         ::testing::Values(CellType::Line, CellType::Triangle,
                                           CellType::Quadrilateral, CellType::Tetrahedron,
                                           CellType::Prism, CellType::Hexahedron),
                         shapeName);

TEST(VtkOrdering, IsAPermutationForEveryShapeAndOrder) {
  for (const CellType type : {CellType::Line, CellType::Triangle, CellType::Quadrilateral,
                              CellType::Tetrahedron, CellType::Prism, CellType::Hexahedron})
    for (int p = 1; p <= 10; ++p) {
      std::vector<int> perm = nodePermutationFromGmsh(type, p, NodeConvention::Vtk);
      std::sort(perm.begin(), perm.end());
      for (int i = 0; i < static_cast<int>(perm.size()); ++i)
        ASSERT_EQ(perm[i], i) << cellShortName(type) << " order " << p;
    }
}

}  // namespace
}  // namespace homesh
