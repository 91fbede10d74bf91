// Node orderings against Gmsh's own reference coordinates (getElementProperties).
#include <gmsh.h>
#include <gtest/gtest.h>

#include <cmath>

#include "element/node_ordering.hpp"
#include "element/reference_element.hpp"
#include "io/mesh_writers.hpp"

namespace homesh {
namespace {

class GmshOrdering : public ::testing::TestWithParam<CellType> {
 protected:
  static void SetUpTestSuite() { gmsh::initialize(0, nullptr, false); }
  static void TearDownTestSuite() { gmsh::finalize(); }
};

TEST_P(GmshOrdering, MatchesGmshReferenceNodesUpToOrder10) {
  const CellType type = GetParam();
  for (int p = 1; p <= 10; ++p) {
    std::string name;
    int dim = 0, order = 0, numNodes = 0, numPrimary = 0;
    std::vector<double> coord;
    gmsh::model::mesh::getElementProperties(gmshElementType(type, p), name, dim, order, numNodes,
                                            coord, numPrimary);
    ASSERT_EQ(order, p);
    const ReferenceElement& ref = ReferenceElement::get(type, p);
    ASSERT_EQ(numNodes, ref.numNodes()) << name;
    for (int i = 0; i < numNodes; ++i) {
      for (int k = 0; k < dim; ++k) {
        double expected = coord[i * dim + k];
        if (type == CellType::Line) expected = 0.5 * (expected + 1.0);  // Gmsh's line is [-1, 1]
        EXPECT_NEAR(ref.nodes()(i, k), expected, 1e-12) << name << " node " << i;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Simplices, GmshOrdering,
                         ::testing::Values(CellType::Line, CellType::Triangle,
                                           CellType::Tetrahedron));

TEST(VtkOrdering, IsAPermutation) {
  for (int p = 1; p <= 10; ++p) {
    const auto perm = nodePermutationFromGmsh(CellType::Tetrahedron, p, NodeConvention::Vtk);
    std::vector<int> sorted = perm;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < static_cast<int>(sorted.size()); ++i) EXPECT_EQ(sorted[i], i);
  }
}

}  // namespace
}  // namespace homesh
