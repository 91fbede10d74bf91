// The boundary facets' in-surface energy (optimise/facet_energy.hpp) on single triangles and
// quadrilaterals: zero and stationary for a rigid motion of the straight facet, positive for
// nodes bunched along it, the trial energy equal to the energy recomputed at the moved node, and
// a clear error for a degenerate facet; its fidelity part zero for a facet on a planar CAD face
// and for a slide within it, and an exact quadratic in a move off it. Its derivatives are checked
// against AD and finite differences in test_derivatives.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "element/reference_element.hpp"
#include "optimise/facet_energy.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;

// One order-P triangle (or quadrilateral) on CAD face 7 of a 3D mesh: the reference cell's
// equispaced nodes mapped by a shear with unequal sides (so that W is neither a multiple of the
// identity nor symmetric: a W^-1 / W^-T mix-up shows), scaled by `side`, rotated and
// translated. A straight facet (the quadrilateral a parallelogram), so its own ideal up to a
// rigid motion.
struct OneFacet {
  Mesh mesh;
  std::vector<Eigen::Vector3d> positions;
  double area = 0.0;
};

OneFacet straightFacet(int order, double side, CellType type = CellType::Triangle) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  Eigen::Matrix2d shear;
  shear << 1.0, 0.45, 0.0, 0.8;
  shear *= side;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(0.3, -1.2, 2.0);
  OneFacet f;
  f.mesh.dim = 3;
  f.mesh.order = order;
  f.area = (type == CellType::Triangle ? 0.5 : 1.0) * shear.determinant();
  for (int i = 0; i < ref.numNodes(); ++i) {
    const Eigen::Vector2d xi = shear * Eigen::Vector2d(ref.nodes()(i, 0), ref.nodes()(i, 1));
    const Eigen::Vector3d x = rotation * Eigen::Vector3d(xi[0], xi[1], 0.0) + shift;
    const double p[3] = {x[0], x[1], x[2]};
    f.mesh.addNode(p, 2, 7, 0.0, 0.0);
    f.positions.push_back(x);
  }
  ElementBlock b;
  b.type = type;
  b.order = order;
  for (int i = 0; i < ref.numNodes(); ++i) b.nodes.push_back(i);
  b.entity = {7};
  f.mesh.blocks.push_back(b);
  return f;
}

// The largest |grad_xi l_n| of the order-P cell's basis over a grid of the cell.
double largestBasisGradient(int order, CellType type) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  Eigen::VectorXd values;
  Eigen::MatrixXd grad;
  double largest = 0.0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20 && (type != CellType::Triangle || i + j <= 20); ++j) {
      const double xi[2] = {i / 20.0, j / 20.0};
      ref.evaluate(xi, values, grad);
      largest = std::max(largest, grad.rowwise().norm().maxCoeff());
    }
  return largest;
}

// The first node on the edge from vertex 0 to vertex 1, in Gmsh's order (after the vertices).
std::int64_t firstEdgeNode(CellType type) {
  return type == CellType::Triangle ? 3 : 4;
}

class FacetShapes : public ::testing::TestWithParam<CellType> {};

TEST_P(FacetShapes, ARigidMotionOfTheStraightFacetCostsNothing) {
  const CellType type = GetParam();
  const double side = 2.5, weight = 1.0;
  const int order = 3;
  OneFacet f = straightFacet(order, side, type);
  const std::vector<std::uint8_t> movable(f.positions.size(), 1);
  FacetEnergy energy(f.mesh, f.positions, movable, weight);
  ASSERT_EQ(energy.size(), 1U);
  // The points' weights add up to weight x area x sqrt(area). At every point C = I to the
  // rounding of M = T W^-1 (T a sum over the nodes of |x| |grad l|, a few hundred u relative
  // here), so each density, (|C| - 2)/2 - ln J + ..., is that rounding too.
  const double scale = weight * f.area * std::sqrt(f.area);
  EXPECT_LE(std::abs(energy.total(f.positions)), 1e3 * kU * scale);
  // Stationary too: a point's gradient is mu (a1 m1 + a2 m2) - mu dl, and at C = I the two cancel
  // to the rounding of M times |a| <= |W^-1| |grad l| (W^-1 of norm at most about 2 / side
  // for this shear).
  const double a = 2.0 / side * largestBasisGradient(order, type);
  for (std::int64_t node = 0; node < static_cast<std::int64_t>(f.positions.size()); ++node) {
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    FacetEnergy::Patch patch;
    energy.assemble(node, f.positions, g, h, patch);
    EXPECT_LE(g.norm(), 1e3 * kU * scale * a) << "node " << node;
    EXPECT_GT(h.trace(), 0.0) << "node " << node;
  }
}

TEST_P(FacetShapes, BunchedNodesCostAndTrialsMatchTheMovedFacet) {
  const CellType type = GetParam();
  OneFacet f = straightFacet(4, 1.0, type);
  const std::vector<std::uint8_t> movable(f.positions.size(), 1);
  FacetEnergy energy(f.mesh, f.positions, movable, 1.0);
  // The first node on edge 0-1 (at a quarter of it) slid towards vertex 0, along the edge.
  const std::int64_t node = firstEdgeNode(type);
  const Eigen::Vector3d along = (f.positions[1] - f.positions[0]).normalized();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  FacetEnergy::Patch patch;
  double size = 0.0;
  const double e0 = energy.assemble(node, f.positions, g, h, patch, &size);
  for (const double s : {0.02, 0.1}) {
    const Eigen::Vector3d d = -s * along;
    std::vector<Eigen::Vector3d> moved = f.positions;
    moved[node] += d;
    const double direct = energy.total(moved);
    EXPECT_GT(direct, e0 + 1e-6) << "bunching by " << s << " costs nothing";
    // total() keeps each facet's share from its last call: the moved facet's is computed again,
    // to the last bit what a term that never saw the other positions finds.
    EXPECT_EQ(direct, FacetEnergy(f.mesh, f.positions, movable, 1.0).total(moved));
    // The trial formula (M + d a^T) and the recomputed facet agree to the rounding of the terms
    // the energy sums, sum w (|W_s| + |M|^2) (`size`, near 2 x the weights at the ideal, where
    // the energy itself is near 0), a few hundred u of them, plus that of the moved facet.
    EXPECT_NEAR(FacetEnergy::energyAfter(patch, d), direct, 1e3 * kU * (size + direct))
        << "bunching by " << s;
  }
}

TEST(FacetEnergy, OnlyFacetsOfMovableNodesAndADegenerateFacetIsNamed) {
  OneFacet f = straightFacet(2, 1.0);
  std::vector<std::uint8_t> movable(f.positions.size(), 0);
  EXPECT_TRUE(FacetEnergy(f.mesh, f.positions, movable, 1.0).empty());
  movable[4] = 1;
  EXPECT_EQ(FacetEnergy(f.mesh, f.positions, movable, 1.0).size(), 1u);
  // All three vertices on one line.
  f.positions[2] = 0.5 * (f.positions[0] + f.positions[1]);
  try {
    const FacetEnergy degenerate(f.mesh, f.positions, movable, 1.0);
    FAIL() << "a facet of zero area was accepted";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("CAD face 7"), std::string::npos) << e.what();
  }
}

// The fidelity part on a planar CAD face: an order-3 facet of the unit box's face z = 0 (its
// straight shape lies on it), targets refreshed from the CAD.
TEST(FacetEnergy, TheFidelityPartIsZeroOnAPlaneAndAnExactQuadraticOffIt) {
  std::vector<CadModel> cads;
  cads.push_back(CadModel::fromBrepText(test::brepText(test::box(1.0, 1.0, 1.0))));
  int face = 0;
  for (int i = 1; i <= cads[0].numFaces() && face == 0; ++i)
    if (cads[0].isPlanar(i) && std::abs(cads[0].plane(i).second.z()) > 0.5 &&
        std::abs(cads[0].plane(i).first.z()) < 1e-12)
      face = i;
  ASSERT_NE(face, 0) << "no face z = 0";
  const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, 3);
  OneFacet f;
  f.mesh.dim = 3;
  f.mesh.order = 3;
  for (int i = 0; i < ref.numNodes(); ++i) {
    const Eigen::Vector3d x(0.2 + 0.5 * ref.nodes()(i, 0) + 0.2 * ref.nodes()(i, 1),
                            0.1 + 0.6 * ref.nodes()(i, 1), 0.0);
    const SurfaceProjection on = cads[0].projectOnSurface(face, x);
    const double p[3] = {x[0], x[1], x[2]};
    f.mesh.addNode(p, 2, face, on.u, on.v);
    f.positions.push_back(x);
  }
  ElementBlock b;
  b.type = CellType::Triangle;
  b.order = 3;
  for (int i = 0; i < ref.numNodes(); ++i) b.nodes.push_back(i);
  b.entity = {face};
  f.mesh.blocks.push_back(b);
  const std::vector<std::uint8_t> movable(f.positions.size(), 1);
  FacetEnergy energy(f.mesh, f.positions, movable, 0.0, 10.0);
  EXPECT_EQ(energy.total(f.positions), 0.0) << "no targets yet: nothing to follow";
  energy.refreshTargets(f.positions, f.mesh, cads);
  // On the plane every point's residual and M^T n are rounding: (1e-16)^2-sized terms.
  EXPECT_LE(energy.total(f.positions), 1e-20);
  const std::int64_t node = 9;  // the interior node
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  FacetEnergy::Patch patch;
  energy.assemble(node, f.positions, g, h, patch);
  ASSERT_FALSE(patch.wf.empty());
  // A slide within the plane keeps the facet on it: nothing; one off it, the saturated
  // quadratic rho(q) = q / (1 + q / kFidelitySaturation) of each point's q, quadratic in the
  // distance, which the trial formula has exactly. Moves of 1e-4 and 2e-4 (the facet's size is
  // about 1) keep q below 1e-6, where rho's quotient deviates from the quadratic's 4 by about
  // 4 x 3 q / 0.25 < 1e-4.
  EXPECT_LE(FacetEnergy::energyAfter(patch, Eigen::Vector3d(0.05, -0.03, 0.0)), 1e-20);
  double previous = 0.0;
  for (const double s : {1e-4, 2e-4}) {
    std::vector<Eigen::Vector3d> moved = f.positions;
    moved[node].z() += s;
    const double direct = energy.total(moved);
    EXPECT_GT(direct, 0.0);
    EXPECT_NEAR(FacetEnergy::energyAfter(patch, Eigen::Vector3d(0.0, 0.0, s)), direct,
                1e-12 * direct);
    if (previous > 0.0) {
      EXPECT_NEAR(direct / previous, 4.0, 1e-4);
      EXPECT_LT(direct / previous, 4.0);  // the saturation bends it down
    }
    previous = direct;
  }
  // The gradient points along the normal, zero at the plane, and the Hessian is its rank one.
  EXPECT_LE(g.norm(), 1e-12);
  EXPECT_NEAR(h(2, 2), h.trace(), 1e-12 * h.trace());
  EXPECT_GT(h(2, 2), 0.0);
}

INSTANTIATE_TEST_SUITE_P(FacetEnergy, FacetShapes,
                         ::testing::Values(CellType::Triangle, CellType::Quadrilateral),
                         [](const ::testing::TestParamInfo<CellType>& param) {
                           return cellShortName(param.param);
                         });

}  // namespace
}  // namespace homesh
