// The wall thickness behind boundary samples and the thin-wall bound of the sizing, on shapes
// whose thickness is known: a tube (coaxial cylinders) and a solid cylinder.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/error.hpp"
#include "sizing/boundary_sampling.hpp"
#include "sizing/sizing_octree.hpp"
#include "sizing/wall_thickness.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kTan30 = 0.57735026918962576;

// A tube of outer radius 1 and inner radius `inner`, 2 high, along z.
TopoDS_Shape tube(double inner) {
  const TopoDS_Shape outer = test::cylinder(1.0, 2.0);
  const TopoDS_Shape hole =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -1), gp_Dir(0, 0, 1)), inner, 4.0).Shape();
  return BRepAlgoAPI_Cut(outer, hole).Shape();
}

SizingParameters params(double thinWall) {
  SizingParameters p;
  p.minDelta = 0.01;
  p.maxDelta = 1.0;
  p.eps = 0.05;
  p.thinWall = thinWall;
  return p;
}

double radial(const BoundarySample& s) {
  return std::hypot(s.x.x(), s.x.y());
}

// A sample of a curved face (curves' samples carry sizes only, no wall).
bool curvedWall(const BoundarySample& s) {
  return s.curvature > 0.0 && s.outward.squaredNorm() > 0.0;
}

// The far side is found up to the cone's slack: from radius r0 across to radius r1 the sample
// found lies at most phi = (tan30 a + half the spacing) / r away around the axis, which changes
// a = (q - p) . n by at most r phi^2 / 2 from the wall's true thickness |r1 - r0|.
double slack(double thickness, double spacing, double r) {
  const double phi = (kTan30 * thickness + 0.5 * spacing) / r;
  return 0.5 * r * phi * phi + 1e-12;
}

TEST(WallThickness, TubeWallIsItsThicknessFromBothSides) {
  const CadModel cad = test::toModel(tube(0.9));
  const std::vector<BoundarySample> samples = sampleBoundary(cad, 3, params(0.1));
  std::vector<double> reach(samples.size(), 0.0);
  double widest = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (curvedWall(samples[i])) reach[i] = 0.5;
    widest = std::max(widest, samples[i].spacing);
  }
  const std::vector<double> t = wallThickness(samples, reach, 2);
  std::size_t outer = 0, inner = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const BoundarySample& s = samples[i];
    if (reach[i] == 0.0) {
      EXPECT_TRUE(std::isinf(t[i]));  // planar ends and curves: not searched
      continue;
    }
    const bool onOuter = radial(s) > 0.95;
    (onOuter ? outer : inner)++;
    ASSERT_TRUE(std::isfinite(t[i])) << s.x.transpose();
    EXPECT_NEAR(t[i], 0.1, slack(0.1, widest, 0.9)) << s.x.transpose();
  }
  EXPECT_GT(outer, 100u);
  EXPECT_GT(inner, 100u);
}

TEST(WallThickness, SolidCylinderIsItsDiameterAndReachLimitsTheSearch) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 2.0));
  const std::vector<BoundarySample> samples = sampleBoundary(cad, 3, params(0.1));
  double widest = 0.0;
  std::vector<double> far(samples.size(), 0.0), close(samples.size(), 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    widest = std::max(widest, samples[i].spacing);
    if (curvedWall(samples[i])) {
      far[i] = 3.0;
      close[i] = 1.5;
    }
  }
  const std::vector<double> across = wallThickness(samples, far, 1);
  const std::vector<double> near = wallThickness(samples, close, 1);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (far[i] == 0.0) continue;
    EXPECT_NEAR(across[i], 2.0, slack(2.0, widest, 1.0)) << samples[i].x.transpose();
    EXPECT_TRUE(std::isinf(near[i]));  // the far side is 2 away, beyond 1.5
  }
}

TEST(WallThickness, ThinWallBoundsTheSizeOnlyWhereTheWallIsThin) {
  // eps 0.05 on radius 1 asks for chordSize(1, 0.05) = 0.62; across a 0.1 wall the sagitta is
  // at most 0.1 x 0.1, chordSize(1, 0.01) = 0.28 (0.9 / 1 on the inner face).
  const CadModel thin = test::toModel(tube(0.9));
  std::vector<BoundarySample> samples = sampleBoundary(thin, 3, params(0.1));
  std::vector<BoundarySample> plain = samples;
  EXPECT_EQ(applyThinWallSizes(plain, params(0.0)), 0u);
  const std::size_t limited = applyThinWallSizes(samples, params(0.1), 2);
  double widest = 0.0;
  for (const BoundarySample& s : samples) widest = std::max(widest, s.spacing);
  std::size_t curved = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const BoundarySample& s = samples[i];
    EXPECT_EQ(plain[i].delta, s.delta == 0.0 ? 0.0 : plain[i].delta);
    if (!curvedWall(s)) continue;
    ++curved;
    const double r = 1.0 / s.curvature;
    const double lo = 0.1 - slack(0.1, widest, 0.9), hi = 0.1 + slack(0.1, widest, 0.9);
    EXPECT_GE(s.delta, chordSize(r, 0.1 * lo / r) * (1 - 1e-12)) << s.x.transpose();
    EXPECT_LE(s.delta, chordSize(r, 0.1 * hi / r) * (1 + 1e-12)) << s.x.transpose();
    EXPECT_LT(s.delta, plain[i].delta);
  }
  EXPECT_EQ(limited, curved);

  // A wall of 0.001 would ask for chordSize(1, 1e-4) = 0.028; the size is at most 3 times
  // smaller than the curvature's.
  std::vector<BoundarySample> foil = sampleBoundary(test::toModel(tube(0.999)), 3, params(0.1));
  const std::vector<BoundarySample> foilPlain = foil;
  EXPECT_GT(applyThinWallSizes(foil, params(0.1)), 0u);
  for (std::size_t i = 0; i < foil.size(); ++i) {
    if (curvedWall(foil[i])) {
      EXPECT_DOUBLE_EQ(foil[i].delta, foilPlain[i].delta / 3.0);
    }
  }

  // A solid cylinder is no thin wall: its diameter (2) is beyond eps R / thinWall = 0.5.
  const CadModel thick = test::toModel(test::cylinder(1.0, 2.0));
  std::vector<BoundarySample> solid = sampleBoundary(thick, 3, params(0.1));
  EXPECT_EQ(applyThinWallSizes(solid, params(0.1)), 0u);

  // The octree takes the bound: on the tube's outer face the size is about 0.28, not 0.62.
  const SizingOctree tree = SizingOctree::build(thin, params(0.1));
  EXPECT_EQ(tree.statistics().thinWallSamples, limited);
  const double size = tree.delta(Eigen::Vector3d(1.0, 0.0, 1.0));
  EXPECT_LT(size, 0.5 * (chordSize(1.0, 0.01) + chordSize(1.0, 0.05)));
  EXPECT_GE(size, chordSize(1.0, 0.1 * (0.1 - slack(0.1, widest, 0.9))) * 0.999);
}

TEST(WallThickness, RejectsABadRatio) {
  for (const double bad : {-0.1, 1.5, std::nan("")}) {
    SizingParameters p = params(bad);
    EXPECT_THROW(p.validate(), ParameterError) << bad;
  }
}

}  // namespace
}  // namespace homesh
