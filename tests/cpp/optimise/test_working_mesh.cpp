// The optimiser's working mesh (working_mesh.hpp): incidence, element sizes, the working node
// set's round trip and the cached deformation gradients.
#include "optimise/working_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <vector>

#include "optimise/node_colouring.hpp"
#include "optimiser_parts.hpp"

namespace homesh {
namespace {

using optimiser::Block;
using optimiser::EnergyRule;
using optimiser::NodeColouring;
using optimiser::WorkingMesh;

std::vector<std::size_t> everyElement(const WorkingMesh<3>& w) {
  std::vector<std::size_t> all(w.totalElements);
  std::iota(all.begin(), all.end(), std::size_t{0});
  return all;
}

TEST(WorkingMesh, IncidenceListsEveryElementOfEveryNodeOnce) {
  Mesh mesh = test::perturbedCube();
  WorkingMesh<3> w(mesh, true);
  w.build();
  w.buildSamples(optimiser::EnergyRule::Collapsed);
  ASSERT_EQ(w.blocks.size(), 1u);  // the tetrahedra; the boundary triangles are left out
  EXPECT_EQ(w.totalElements, w.blocks[0].cells->count());
  std::vector<std::size_t> seen(w.totalElements * w.blocks[0].nodes, 0);
  for (std::size_t node = 0; node < mesh.numNodes(); ++node) {
    EXPECT_GT(w.incidenceStart[node + 1], w.incidenceStart[node]) << node;
    for (std::size_t k = w.incidenceStart[node]; k < w.incidenceStart[node + 1]; ++k) {
      const optimiser::Incidence& inc = w.incidence[k];
      const std::size_t g = w.globalIndex(inc);
      EXPECT_EQ(w.locate(g), std::make_pair(std::size_t{0}, inc.element));
      EXPECT_EQ(w.blocks[0].cells->element(inc.element)[inc.local],
                static_cast<std::int64_t>(node));
      ++seen[g * w.blocks[0].nodes + static_cast<std::size_t>(inc.local)];
    }
    EXPECT_GT(w.nodeSize[node], 0.0);
    EXPECT_LT(w.nodeSize[node], 0.4 * 2);  // the mesh size is 0.4
  }
  for (const std::size_t s : seen) EXPECT_EQ(s, 1u);
}

// The working node set is the same polynomial map: written back unchanged, every node returns
// to its equispaced position (to the rounding of the two conversions).
TEST(WorkingMesh, TheWorkingNodeSetWritesBackTheSameMesh) {
  Mesh mesh = test::perturbedCube();
  WorkingMesh<3> w(mesh, true);
  w.build();
  w.buildSamples(optimiser::EnergyRule::Collapsed);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    if ((w.position[i] - test::nodePoint(mesh, static_cast<std::int64_t>(i))).norm() > 1e-9)
      ++differ;
  EXPECT_GT(differ, 0u);  // the working set's nodes are not the equispaced ones
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) w.writeBack(static_cast<std::int64_t>(i));
  const Mesh& input = test::perturbedCube();
  for (std::size_t i = 0; i < mesh.xyz.size(); ++i) EXPECT_NEAR(mesh.xyz[i], input.xyz[i], 1e-13);
}

// On straight-sided elements (the ideal shapes themselves) F is the identity and J 1 at every
// sample point; on the curved mesh J is positive and the weights add up to the volume; with
// either energy rule.
TEST(WorkingMesh, GradientsOfTheIdealShapesAreTheIdentity) {
  const Mesh& curved = test::perturbedCube();
  Mesh straight = curved;
  // The straight-sided mesh: each element's nodes where its vertices' linear map puts them.
  {
    WorkingMesh<3> plain(straight, false);
    plain.build();
    plain.buildSamples(optimiser::EnergyRule::Collapsed);
    const Block<3>& b = plain.blocks[0];
    const ReferenceElement& ref = ReferenceElement::get(b.cells->type, b.cells->order);
    const ReferenceElement& lin = ReferenceElement::get(b.cells->type, 1);
    const Eigen::MatrixXd values = lin.valuesAt(ref.nodes());
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      const std::int64_t* v = b.cells->element(e);
      for (int i = 4; i < b.nodes; ++i)
        for (int c = 0; c < 3; ++c) {
          double x = 0.0;
          for (int j = 0; j < 4; ++j) x += values(i, j) * curved.xyz[3 * v[j] + c];
          straight.xyz[3 * static_cast<std::size_t>(v[i]) + c] = x;
        }
    }
  }
  for (const EnergyRule rule : {EnergyRule::Collapsed, EnergyRule::Symmetric})
    for (const Mesh* m : std::initializer_list<const Mesh*>{&straight, &curved}) {
      Mesh mesh = *m;
      WorkingMesh<3> w(mesh, false);
      w.build();
      w.buildSamples(rule);
      const NodeColouring<3> owners(2);  // not partitioned: any thread takes any element
      w.computeGradients(everyElement(w), owners);
      const Block<3>& b = w.blocks[0];
      double worstF = 0.0, minJ = HUGE_VAL, volume = 0.0;
      for (std::size_t e = 0; e < b.cells->count(); ++e)
        for (int q = 0; q < b.points; ++q) {
          worstF = std::max(worstF, (b.matrixF(e, q) - Eigen::Matrix3d::Identity()).norm());
          minJ = std::min(minJ, b.J[e * b.points + q]);
          volume += b.weights[e * b.points + q];
        }
      EXPECT_NEAR(volume / (1.0 + optimiser::kNodeShare), 1.0, 1e-12);
      EXPECT_GT(minJ, 0.0);
      if (m == &straight) {
        EXPECT_LT(worstF, 1e-12);
      } else {
        EXPECT_GT(worstF, 1e-3);
      }
    }
}

// The energy's samples: the symmetric rule and the vertices and edge nodes on tetrahedra of
// orders 3 and 4, where it has fewer points than the collapsed one (27 + 20 = 47 -> 14 + 16 = 30,
// 64 + 35 = 99 -> 35 + 22 = 57); the collapsed rule and every node elsewhere; the weights adding
// up to (1 + kNodeShare) x the reference volume either way.
TEST(WorkingMesh, TheSymmetricRuleSamplesFewerPointsOnTetrahedraOfOrders3And4) {
  // Points of the collapsed rule of degree 2P - 1 plus the element's nodes, then of the rule
  // taken with EnergyRule::Symmetric (0: the same).
  const struct {
    CellType type;
    int order, collapsed, symmetric;
  } cases[] = {
      {CellType::Tetrahedron, 2, 8 + 10, 0},        {CellType::Tetrahedron, 3, 27 + 20, 14 + 16},
      {CellType::Tetrahedron, 4, 64 + 35, 35 + 22}, {CellType::Tetrahedron, 5, 125 + 56, 0},
      {CellType::Triangle, 4, 16 + 15, 0},          {CellType::Prism, 3, 27 + 40, 0}};
  for (const auto& c : cases) {
    EXPECT_EQ(optimiser::takesSymmetricSamples(c.type, c.order), c.symmetric > 0)
        << cellShortName(c.type) << " order " << c.order;
    const ReferenceElement& equi = ReferenceElement::get(c.type, c.order);
    for (const EnergyRule rule : {EnergyRule::Collapsed, EnergyRule::Symmetric}) {
      const QuadratureRule samples = optimiser::energySamples(c.type, c.order, equi, rule);
      const int expected =
          rule == EnergyRule::Symmetric && c.symmetric > 0 ? c.symmetric : c.collapsed;
      EXPECT_EQ(samples.size(), expected) << cellShortName(c.type) << " order " << c.order;
      double sum = 0.0;
      for (const double w : samples.weights) sum += w;
      const double volume = c.type == CellType::Tetrahedron ? 1.0 / 6.0 : 0.5;  // tri, prism
      // The bound test_basis_quadrature.cpp takes for a rule's constant (n + 5) eps x the sum,
      // 8 times over: each weight a few ulps off, n of them summed.
      const double tol =
          8.0 * (samples.size() + 5.0) * std::numeric_limits<double>::epsilon() * sum;
      EXPECT_NEAR(sum, (1.0 + optimiser::kNodeShare) * volume, tol)
          << cellShortName(c.type) << " order " << c.order;
    }
  }
}

}  // namespace
}  // namespace homesh
