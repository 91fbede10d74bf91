// An automatic MinDelta from the shape's own scales (sizing/automatic_min_delta.hpp): the rule
// on samples whose sizes are known, and a long cylinder, whose MinDelta from its bounding box
// alone (MaxDelta / 20) was wider than its circle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"
#include "sizing/automatic_min_delta.hpp"
#include "sizing/sizing_octree.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// A face sample (3D: it has an outward normal) of curvature `k` and size `delta` on face 7.
BoundarySample faceSample(double k, double delta) {
  BoundarySample s;
  s.outward = Eigen::Vector3d::UnitZ();
  s.curvature = k;
  s.delta = delta;
  s.cadIndex = 7;
  return s;
}

SizingParameters automaticWithMax(double maxDelta) {
  SizingParameters p;
  p.maxDelta = maxDelta;
  return p;
}

TEST(AutomaticMinDelta, IsTheSmallestSizeTheSamplesAskForWithinItsBounds) {
  const double eps = parameterDefault("eps");
  // Radius 2 asks for chordSize(2) = 1.25, between the floor (0.5) and the ceiling (5).
  SizingParameters p = automaticWithMax(100.0);
  EXPECT_EQ(samplingMinDelta(p), 100.0 * kMinDeltaFloor);
  std::vector<BoundarySample> samples{faceSample(0.0, 0.0), faceSample(0.5, chordSize(2.0, eps)),
                                      faceSample(0.1, chordSize(10.0, eps))};
  resolveAutomaticMinDelta(samples, p, 3);
  EXPECT_EQ(p.minDelta, chordSize(2.0, eps));
  EXPECT_EQ(p.minDeltaSetBy, "curvature radius 2 of face 7");
  EXPECT_EQ(samples[0].delta, 0.0);  // a flat sample stays without a size
  EXPECT_EQ(samples[2].delta, chordSize(10.0, eps));

  // Nothing asks for less than MaxDelta / 20: the rule before.
  p = automaticWithMax(1.0);
  samples = {faceSample(0.1, 0.5)};
  resolveAutomaticMinDelta(samples, p, 3);
  EXPECT_EQ(p.minDelta, 1.0 * kMinDeltaCeiling);
  EXPECT_EQ(p.minDeltaSetBy, "MaxDelta / 20 (no boundary asks for less)");

  // Below the floor: the floor, and the samples' sizes raised to it (a 3D curve's sample has
  // no normal). A thin wall's size is below its curvature's.
  p = automaticWithMax(1000.0);
  samples = {faceSample(1.0, chordSize(1.0, eps) / 3.0), faceSample(1e3, chordSize(1e-3, eps))};
  samples[1].outward.setZero();
  samples[1].cadIndex = 4;
  resolveAutomaticMinDelta(samples, p, 3);
  EXPECT_EQ(p.minDelta, 1000.0 * kMinDeltaFloor);
  EXPECT_EQ(p.minDeltaSetBy,
            "MaxDelta / 200, the floor (curvature radius 0.001 of curve 4 asks for less)");
  EXPECT_EQ(samples[1].delta, p.minDelta);
  p = automaticWithMax(20.0);
  samples = {faceSample(1.0, chordSize(1.0, eps) / 3.0)};
  resolveAutomaticMinDelta(samples, p, 3);
  EXPECT_EQ(p.minDeltaSetBy, "a thin wall at face 7");

  // A given MinDelta stays as it is.
  p = automaticWithMax(1000.0);
  p.minDelta = 3.0;
  samples = {faceSample(1.0, 3.0)};
  resolveAutomaticMinDelta(samples, p, 3);
  EXPECT_EQ(p.minDelta, 3.0);
  EXPECT_TRUE(p.minDeltaSetBy.empty());
}

// Part.makeCylinder(1, 400): MaxDelta 20, and MaxDelta / 20 = 1 is wider than the circle's
// curvature size chordSize(1, EPS) = 0.62 (2 pi / 1 = 6.3 segments on each end circle). The
// octree now takes MinDelta from the curvature: Gmsh integrates 1 / delta along each end circle,
// 2 pi / 0.62 = 10.06, and makes 10 or 11 segments.
TEST(AutomaticMinDelta, ALongCylindersCircleSetsItAndGetsItsSize) {
  MeshingOptions options;
  options.order = 1;
  const MeshResult r =
      runMeshPipeline(CadSource::brepText(test::brepText(test::cylinder(1.0, 400.0))), options);
  ASSERT_TRUE(r.sizing);
  const SizingParameters& used = r.sizing->octree->parameters();
  const double expected = chordSize(1.0, parameterDefault("eps"));
  EXPECT_NEAR(used.minDelta, expected, 1e-9 * expected);
  // (Its side and its end circles have the same curvature, 1 up to rounding: either may set it.)
  EXPECT_EQ(used.minDeltaSetBy.rfind("curvature radius 1 of ", 0), 0U) << used.minDeltaSetBy;
  EXPECT_EQ(used.maxDeltaSetBy, "bounding-box diagonal / 20");
  // Nodes per CAD curve; the end circles are the curves whose nodes share one z.
  std::map<int, std::set<long>> heights;
  std::map<int, int> nodes;
  for (std::size_t i = 0; i < r.mesh.numNodes(); ++i) {
    if (r.mesh.nodeCadDim[i] != 1) continue;
    const int edge = r.mesh.nodeCadIndex[i];
    ++nodes[edge];
    heights[edge].insert(std::lround(test::nodePoint(r.mesh, static_cast<std::int64_t>(i)).z()));
  }
  int circles = 0;
  for (const auto& [edge, z] : heights) {
    if (z.size() != 1) continue;  // the seam
    ++circles;
    EXPECT_GE(nodes[edge] + 1, 10) << "curve " << edge;  // + its one CAD vertex
  }
  EXPECT_EQ(circles, 2);
  const std::string report = meshReportJson(r, "cylinder");
  EXPECT_NE(report.find("\"min_delta_set_by\": \"curvature radius 1 of "), std::string::npos)
      << report;
}

// A thin ring (a torus of major radius 50, minor 0.02): every point of its surface asks for
// less than the floor (MaxDelta / 200 = 0.035), and at the floor its octree would need more
// than its 10^7 cells; MinDelta is doubled until it fits (0.071), and the record says why.
TEST(AutomaticMinDelta, IsRaisedUntilTheOctreeFits) {
  const CadModel cad = test::toModel(test::torus(50.0, 0.02));
  const SizingParameters requested = defaultSizing(cad);
  ASSERT_EQ(requested.minDelta, 0.0);
  const SizingResult r = runSizing(cad, requested, 2);
  const SizingParameters& used = r.octree->parameters();
  const double floor = kMinDeltaFloor * used.maxDelta;
  EXPECT_EQ(
      used.minDeltaSetBy.rfind("the sizing octree's cell limit (too many cells at MinDelta ", 0),
      0U)
      << used.minDeltaSetBy;
  EXPECT_GT(used.minDelta, floor);
  EXPECT_LE(used.minDelta, kMinDeltaCeiling * used.maxDelta);
  const double doublings = std::log2(used.minDelta / floor);
  EXPECT_NEAR(doublings, std::round(doublings), 1e-9);
  EXPECT_GT(r.prediction.elements, 0.0);
}

}  // namespace
}  // namespace homesh
