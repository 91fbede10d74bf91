// The fit of a curved boundary triangle's interior nodes to its CAD face
// (curving/face_fidelity_fit.hpp), on a unit sphere, where the exact normal is the position.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "curving/face_fidelity_fit.hpp"
#include "curving/face_node_placement.hpp"
#include "element/reference_element.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// The point at longitude u, latitude v on the unit sphere: OpenCASCADE's sphere parametrisation.
Eigen::Vector3d onSphere(double u, double v) {
  return {std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v)};
}

// The largest angle, in degrees, between the order-P triangle's normal and the sphere's (its
// position, normalised), on a lattice of 40 steps a side.
double largestAngle(int p, const std::vector<Eigen::Vector3d>& lattice) {
  const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, p);
  std::vector<Eigen::Vector3d> x(lattice.size());
  for (int n = 0; n < ref.numNodes(); ++n) {
    const LatticePoint& l = ref.lattice()[static_cast<std::size_t>(n)];
    x[static_cast<std::size_t>(n)] = lattice[static_cast<std::size_t>(latticeIndex(p, l[0], l[1]))];
  }
  double worst = 0.0;
  const int steps = 40;
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (int j = 0; j <= steps; ++j)
    for (int i = 0; i + j <= steps; ++i) {
      const double xi[2] = {static_cast<double>(i) / steps, static_cast<double>(j) / steps};
      ref.evaluate(xi, values, gradients);
      Eigen::Vector3d point = Eigen::Vector3d::Zero(), t1 = point, t2 = point;
      for (std::size_t n = 0; n < x.size(); ++n) {
        const auto k = static_cast<Eigen::Index>(n);
        point += values(k) * x[n];
        t1 += gradients(k, 0) * x[n];
        t2 += gradients(k, 1) * x[n];
      }
      const double c = std::abs(t1.cross(t2).normalized().dot(point.normalized()));
      worst = std::max(worst, std::acos(std::min(1.0, c)) * 180.0 / M_PI);
    }
  return worst;
}

// An order-P triangle spanning 54 to 80 degrees of the unit sphere (the size of the coarse
// triangles on examples/sphere_box.step at --size 0.8, whose largest normal angles issue 49
// measures), edges along great circles at equal angles, its interior the relaxed lattice of
// placeTriangleInterior. The fit must take the largest angle to at most a third (measured: order
// 4 1.07 -> 0.090 degrees, order 5 0.194 -> 0.022, order 6 0.019 -> 0.0026, 7.6 to 12 times
// smaller; the third leaves room for another machine's rounding of the Gauss-Newton steps), keep
// every node on the sphere to 1e-9 and lower F.
TEST(FaceFidelityFit, InteriorOfACoarseSphereTriangleFollowsTheSphere) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  const FaceChart chart(cad, 1);
  const std::array<FaceParameter, 3> corner{{{0.5, 0.1}, {1.9, 0.3}, {1.1, 1.1}}};
  for (const int p : {4, 5, 6}) {
    const auto count = static_cast<std::size_t>((p + 1) * (p + 2) / 2);
    std::vector<FaceParameter> uv(count);
    std::vector<Eigen::Vector3d> x(count);
    const auto set = [&](int i, int j, const Eigen::Vector3d& point) {
      const auto k = static_cast<std::size_t>(latticeIndex(p, i, j));
      x[k] = point;
      const SurfaceProjection foot = cad.projectOnSurface(1, point);
      uv[k] = chart.unwrapNear({foot.u, foot.v}, corner[0]);
    };
    const Eigen::Vector3d c0 = onSphere(corner[0][0], corner[0][1]),
                          c1 = onSphere(corner[1][0], corner[1][1]),
                          c2 = onSphere(corner[2][0], corner[2][1]);
    // Equal angles along the great circle from a to b.
    const auto arc = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double s) {
      const double angle = std::acos(a.dot(b));
      return ((std::sin((1.0 - s) * angle) * a + std::sin(s * angle) * b) / std::sin(angle)).eval();
    };
    for (int k = 0; k <= p; ++k) {
      const double s = static_cast<double>(k) / p;
      set(k, 0, arc(c0, c1, s));
      set(p - k, k, arc(c1, c2, s));
      set(0, p - k, arc(c0, c2, 1.0 - s));
    }
    const TrianglePlacement relaxed = placeTriangleInterior(chart, p, uv, x);
    ASSERT_TRUE(relaxed.valid);
    std::vector<Eigen::Vector3d> start = x;
    for (int j = 1; j < p; ++j)
      for (int i = 1; i + j < p; ++i) {
        const auto k = static_cast<std::size_t>(latticeIndex(p, i, j));
        start[k] = chart.point(relaxed.uv[k]);
      }
    const TriangleFit fit = fitTriangleInterior(chart, p, relaxed.uv, x);
    std::vector<Eigen::Vector3d> fitted = x;
    for (int j = 1; j < p; ++j)
      for (int i = 1; i + j < p; ++i) {
        const auto k = static_cast<std::size_t>(latticeIndex(p, i, j));
        fitted[k] = chart.point(fit.uv[k]);
        EXPECT_NEAR(fitted[k].norm(), 1.0, 1e-9);
        EXPECT_TRUE(chart.contains(fit.uv[k]));
      }
    const double before = largestAngle(p, start), after = largestAngle(p, fitted);
    std::printf("order %d: largest normal angle %.4g -> %.4g degrees, F %.3g -> %.3g in %d steps\n",
                p, before, after, fit.before, fit.after, fit.steps);
    EXPECT_LT(fit.after, fit.before);
    EXPECT_LT(after, before / 3.0) << "order " << p;
  }
}

// Orders 1 and 2 have no interior node: the triangle comes back as given.
TEST(FaceFidelityFit, NothingToMoveBelowOrderThree) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  const FaceChart chart(cad, 1);
  const std::vector<FaceParameter> uv{{0.1, 0.1},  {0.2, 0.1},   {0.1, 0.2},
                                      {0.15, 0.1}, {0.15, 0.15}, {0.1, 0.15}};
  std::vector<Eigen::Vector3d> x;
  for (const FaceParameter& q : uv) x.push_back(chart.point(q));
  const TriangleFit fit = fitTriangleInterior(chart, 2, uv, x);
  EXPECT_EQ(fit.uv, uv);
  EXPECT_EQ(fit.steps, 0);
}

}  // namespace
}  // namespace homesh
