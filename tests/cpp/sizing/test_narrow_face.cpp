// The narrow-face bound of the sizing, on shapes whose widths are known: a cylinder (its end
// circles are its height apart) and two coaxial cylinders fused, whose step leaves a planar ledge
// 0.05 wide between circles of radius 20 and 19.95.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Fuse.hxx>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.hpp"
#include "sizing/boundary_sampling.hpp"
#include "sizing/narrow_face.hpp"
#include "sizing/sizing_octree.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A cylinder of radius 20 from z = 0 to 5 under one of radius 19.95 from z = 5 to 10.
TopoDS_Shape ledge() {
  const TopoDS_Shape lower = test::cylinder(20.0, 5.0);
  const TopoDS_Shape upper =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 5), gp_Dir(0, 0, 1)), 19.95, 5.0).Shape();
  return BRepAlgoAPI_Fuse(lower, upper).Shape();
}

SizingParameters params(double narrowFace) {
  SizingParameters p;
  p.minDelta = 0.1;
  p.maxDelta = 5.0;
  p.eps = 0.05;
  p.narrowFace = narrowFace;
  return p;
}

// The circle edge of `radius` at height z (the test shapes have one each).
int circle(const CadModel& cad, double radius, double z) {
  for (int e = 1; e <= cad.numEdges(); ++e) {
    if (cad.isDegenerated(e)) continue;
    const ParameterRange r = cad.edgeRange(e);
    const Eigen::Vector3d p = cad.evaluateCurve(e, 0.3 * r.first + 0.7 * r.last).point;
    if (std::abs(std::hypot(p.x(), p.y()) - radius) < 1e-9 && std::abs(p.z() - z) < 1e-9) return e;
  }
  return 0;
}

// The projection is found to 1e-9 of the bounding diagonal (CadModel::projectOnCurve); the
// circles are exact, so the width is the ledge's to that precision.
double precision(const CadModel& cad) {
  return 2e-9 * cad.boundingDiagonal();
}

TEST(NarrowFaces, LedgeIsItsWidthFromBothCircles) {
  const CadModel cad = test::toModel(ledge());
  const NarrowFaces narrow(cad);
  for (const double radius : {20.0, 19.95}) {
    const int e = circle(cad, radius, 5.0);
    ASSERT_GT(e, 0) << radius;
    const ParameterRange r = cad.edgeRange(e);
    for (int k = 0; k <= 8; ++k) {  // the ends included: the seam vertex is no edge across
      const Eigen::Vector3d x = cad.evaluateCurve(e, r.first + k / 8.0 * (r.last - r.first)).point;
      EXPECT_NEAR(narrow.width(e, x, 1.0), 0.05, precision(cad)) << radius << " " << k;
      EXPECT_EQ(narrow.width(e, x, 0.04), kInf);  // nothing across within the reach
    }
  }
}

TEST(NarrowFaces, CylinderEndsAreItsHeightApart) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 2.0));
  const NarrowFaces narrow(cad);
  const int top = circle(cad, 1.0, 2.0);
  ASSERT_GT(top, 0);
  // Across the side face lies the bottom circle; the seam meets the circle at its vertex.
  const Eigen::Vector3d x = cad.evaluateCurve(top, cad.edgeRange(top).first).point;
  EXPECT_NEAR(narrow.width(top, x, 3.0), 2.0, precision(cad));
  EXPECT_EQ(narrow.width(top, x, 1.9), kInf);
}

TEST(NarrowFaces, SizeIsTheChordOfTheWidthsSagittaAboveMinDelta) {
  const SizingParameters p = params(0.25);
  // Sagitta 0.25 x 0.05 on radius 20.
  EXPECT_DOUBLE_EQ(NarrowFaces::size(20.0, 0.05, 5.0, p), chordSize(20.0, 0.0125 / 20.0));
  EXPECT_DOUBLE_EQ(NarrowFaces::size(20.0, 0.05, 1.0, p), 1.0);         // does not bind
  EXPECT_DOUBLE_EQ(NarrowFaces::size(20.0, 1e-6, 5.0, p), p.minDelta);  // floor
  EXPECT_DOUBLE_EQ(NarrowFaces::size(20.0, kInf, 5.0, p), 5.0);
  EXPECT_DOUBLE_EQ(NarrowFaces::size(20.0, 0.05, 5.0, params(0.0)), 5.0);
  // The reach is where the bound would give `current` back (10 % beyond).
  const double reach = NarrowFaces::reach(20.0, 2.0, p);
  EXPECT_NEAR(NarrowFaces::size(20.0, reach / 1.1, 2.0 + 1e-9, p), 2.0, 1e-8);
  EXPECT_EQ(NarrowFaces::reach(20.0, 2.0, params(0.0)), 0.0);
}

TEST(NarrowFaces, BoundTheSizesAlongTheLedgeAndNowhereElse) {
  const CadModel cad = test::toModel(ledge());
  const SizingParameters p = params(0.25);
  std::size_t narrowed = 0;
  for (const BoundarySample& s : sampleBoundary(cad, 3, p)) {
    if (!s.narrowFace) continue;
    ++narrowed;
    const double radius = std::hypot(s.x.x(), s.x.y());
    EXPECT_NEAR(s.x.z(), 5.0, 1e-9);  // only the ledge's circles
    // width 0.05 (to the projection's precision) and R = 1 / curvature = the circle's radius
    // (to rounding): the size changes with sqrt(width), so by half the width's relative error.
    const double relative = 0.5 * precision(cad) / 0.05 + 1e-12;
    EXPECT_NEAR(s.delta, chordSize(radius, 0.25 * 0.05 / radius), relative * s.delta)
        << s.x.transpose();
  }
  EXPECT_GT(narrowed, 80u);  // both circles, at least 40 samples each

  for (const BoundarySample& s : sampleBoundary(cad, 3, params(0.0))) EXPECT_FALSE(s.narrowFace);
  // A plain cylinder 5 high: its side is too wide for the bound to bind below MaxDelta.
  const CadModel plain = test::toModel(test::cylinder(20.0, 5.0));
  for (const BoundarySample& s : sampleBoundary(plain, 3, p)) EXPECT_FALSE(s.narrowFace);

  const SizingOctree octree = SizingOctree::build(cad, p);
  EXPECT_EQ(octree.statistics().narrowFaceSamples, narrowed);
}

TEST(NarrowFaces, RejectsABadRatio) {
  SizingParameters p = params(0.25);
  EXPECT_NO_THROW(p.validate());
  for (const double bad : {-0.1, 1.5, std::nan("")}) {
    p.narrowFace = bad;
    EXPECT_THROW(p.validate(), ParameterError) << bad;
  }
}

}  // namespace
}  // namespace homesh
