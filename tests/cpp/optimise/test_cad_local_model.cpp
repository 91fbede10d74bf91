// The optimiser's local CAD model (cad_local_model.hpp), alone: its points converge to the CAD's
// at third order, and its chain rule gives the derivatives of an energy of the CAD point.
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeCylinder.hxx>
#include <cmath>

#include "optimise/cad_local_model.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// err(h) / err(h/2) for a Taylor model of order two is 8 up to the next term's share, O(h):
// with h from 0.2 down to 0.025 (radius-1 curvature), the ratio lies within 8 (1 +- 0.25).
// A first-order model would give 4 in the point's error, a wrong curvature term 4 as well.
constexpr double kRatioLow = 6.0, kRatioHigh = 10.0;

TEST(LocalCadModel, SurfacePointsConvergeAtThirdOrder) {
  const CadModel cad = test::toModel(test::torus(2.0, 0.6));
  const Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  for (int face = 1; face <= cad.numFaces(); ++face) {
    const SurfaceBounds b = cad.faceBounds(face);
    const double u0 = b.uMin + 0.37 * (b.uMax - b.uMin), v0 = b.vMin + 0.61 * (b.vMax - b.vMin);
    const LocalCadModel<3> m = LocalCadModel<3>::surface(cad.evaluateSurface(face, u0, v0), frame);
    ASSERT_EQ(m.parameters, 2);
    const double dir[2] = {0.8, -0.6};
    double last = 0.0;
    for (int halving = 0; halving < 4; ++halving) {
      const double h = 0.2 * std::ldexp(1.0, -halving);
      const double dp[2] = {h * dir[0], h * dir[1]};
      const double err =
          (m.at(dp) - cad.evaluateSurface(face, u0 + dp[0], v0 + dp[1]).point).norm();
      ASSERT_GT(err, 1e-12) << "the remainder must be well above rounding for the ratio";
      if (last > 0.0) {
        EXPECT_GT(last / err, kRatioLow) << "face " << face << " h " << h;
        EXPECT_LT(last / err, kRatioHigh) << "face " << face << " h " << h;
      }
      last = err;
    }
    const double zero[2] = {0.0, 0.0};
    EXPECT_EQ((m.at(zero) - cad.evaluateSurface(face, u0, v0).point).norm(), 0.0);
  }
}

// In 2D the model lives in the plane's frame: a circle of the cylinder's base seen from its
// xy frame.
TEST(LocalCadModel, CurvePointsConvergeAtThirdOrderInThePlanesFrame) {
  const CadModel cad = test::toModel(BRepPrimAPI_MakeCylinder(1.0, 1.0).Shape());
  Eigen::Matrix<double, 2, 3> frame;
  frame << 1, 0, 0, 0, 1, 0;
  int circles = 0;
  for (int edge = 1; edge <= cad.numEdges(); ++edge) {
    if (cad.isDegenerated(edge)) continue;
    const ParameterRange r = cad.edgeRange(edge);
    const double t0 = r.first + 0.3 * (r.last - r.first);
    const CurveDerivatives c0 = cad.evaluateCurve(edge, t0);
    if (c0.d2.norm() == 0.0) continue;  // the seam line: straight, nothing to converge
    ++circles;
    const LocalCadModel<2> m = LocalCadModel<2>::curve(c0, frame);
    ASSERT_EQ(m.parameters, 1);
    double last = 0.0;
    for (int halving = 0; halving < 4; ++halving) {
      const double h = 0.2 * std::ldexp(1.0, -halving);
      const double dp[2] = {h, 0.0};
      const double err = (m.at(dp) - frame * cad.evaluateCurve(edge, t0 + h).point).norm();
      if (last > 0.0) {
        EXPECT_GT(last / err, kRatioLow) << "edge " << edge << " h " << h;
        EXPECT_LT(last / err, kRatioHigh) << "edge " << edge << " h " << h;
      }
      last = err;
    }
  }
  EXPECT_EQ(circles, 2);
}

// E(x) = |x - c|^2 on the sphere: the model's g and h against central differences of E(S(p)).
// With step k the differences' truncation error is k^2 |E'''| / 6 (gradient) and k^2 |E''''| / 12
// (Hessian), about 1e-8 for k = 1e-4 and derivatives of order 10; their rounding 1e-16 / k and
// 1e-16 / k^2 = 1e-8: 1e-6 holds both with margin.
TEST(LocalCadModel, ChainRuleGivesTheDerivativesOfAnEnergyOfTheCadPoint) {
  const CadModel cad = test::toModel(test::sphere(1.5));
  const Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c(0.3, -2.0, 0.7);
  const auto energy = [&](double u, double v) {
    return (cad.evaluateSurface(1, u, v).point - c).squaredNorm();
  };
  const double u0 = 0.9, v0 = 0.4, k = 1e-4;
  const LocalCadModel<3> m = LocalCadModel<3>::surface(cad.evaluateSurface(1, u0, v0), frame);
  Eigen::VectorXd g;
  Eigen::MatrixXd h;
  m.chainRule(2.0 * (m.point - c), 2.0 * Eigen::Matrix3d::Identity(), g, h);
  ASSERT_EQ(g.size(), 2);
  const double e0 = energy(u0, v0);
  const double gu = (energy(u0 + k, v0) - energy(u0 - k, v0)) / (2 * k);
  const double gv = (energy(u0, v0 + k) - energy(u0, v0 - k)) / (2 * k);
  const double huu = (energy(u0 + k, v0) - 2 * e0 + energy(u0 - k, v0)) / (k * k);
  const double hvv = (energy(u0, v0 + k) - 2 * e0 + energy(u0, v0 - k)) / (k * k);
  const double huv = (energy(u0 + k, v0 + k) - energy(u0 + k, v0 - k) - energy(u0 - k, v0 + k) +
                      energy(u0 - k, v0 - k)) /
                     (4 * k * k);
  EXPECT_NEAR(g(0), gu, 1e-6);
  EXPECT_NEAR(g(1), gv, 1e-6);
  EXPECT_NEAR(h(0, 0), huu, 1e-6);
  EXPECT_NEAR(h(1, 1), hvv, 1e-6);
  EXPECT_NEAR(h(0, 1), huv, 1e-6);
  EXPECT_EQ(h(0, 1), h(1, 0));
  // Without the curvature term grad . X'' the Hessian is off by far more than the tolerance.
  EXPECT_GT(std::abs(h(0, 0) - 2.0 * m.d[0].squaredNorm()), 1e-2);
}

}  // namespace
}  // namespace homesh
