// The sizing octree: sizes from curvature, grading, balance, classification, sources, and a
// query that many threads may use at once.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "io/octree_export.hpp"
#include "peer_data.hpp"
#include "sizing/element_count.hpp"
#include "sizing/sizing_octree.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

SizingParameters params(double minDelta, double maxDelta, double eps) {
  SizingParameters p;
  p.minDelta = minDelta;
  p.maxDelta = maxDelta;
  p.eps = eps;
  return p;
}

TEST(SizingOctree, ChordSizeIsTheChordOfTheSagitta) {
  // A chord of length c on a circle of radius R has sagitta R - sqrt(R^2 - c^2/4) = eps R.
  for (const double eps : {0.01, 0.1, 0.5, 1.0}) {
    const double c = chordSize(2.0, eps);
    // A closed form and its inverse: a few roundings of numbers <= 4 (~1e-15).
    EXPECT_NEAR(2.0 - std::sqrt(4.0 - c * c / 4.0), eps * 2.0, 1e-12);
  }
}

TEST(SizingOctree, SphereSurfaceGetsTheCurvatureSize) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  const SizingParameters p = params(0.01, 1.0, 0.02);
  const SizingOctree tree = SizingOctree::build(cad, p);
  const double expected = chordSize(1.0, 0.02);  // 0.398
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d x = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    // Corner averaging may raise the size by the gradation over half a leaf. Measured 1.00006
    // to 1.030 of the chord size: the lower bound is the formula (with 1e-3 for the samples'
    // curvature estimate), the upper one the gradation.
    EXPECT_GE(tree.delta(x), expected * 0.999);
    EXPECT_LE(tree.delta(x), expected * 1.25) << x.transpose();
  }
  // Far inside, the size grows by at most the gradation.
  EXPECT_LE(tree.delta(Eigen::Vector3d::Zero()), expected + 0.2 * 1.0 + 1e-9);
  EXPECT_GT(tree.delta(Eigen::Vector3d::Zero()), expected);
}

// Grading (0.2), 2:1 balance and a continuous query on the octree of a hemisphere of radius 0.25
// cut out of the floor of the box [-1, 3] x [-1, 1] x [0, 0.75] (metres), the layout of NekMesh's
// 3d_sphere case, with MinDelta 0.04, MaxDelta 0.2 and EPS 0.02.
void checkGradationAndBalance(const CadModel& cad) {
  const SizingOctree tree = SizingOctree::build(cad, params(0.04, 0.2, 0.02));
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < tree.numLeaves(); ++i) {
    const SizingOctree::Leaf a = tree.leaf(i);
    for (const std::size_t j : tree.leafNeighbours(i)) {
      const SizingOctree::Leaf b = tree.leaf(j);
      EXPECT_LE(std::abs(a.level - b.level), 1);
      EXPECT_LE(std::abs(a.delta - b.delta), 0.2 * (a.centre - b.centre).norm() + 1e-12);
      ++pairs;
    }
  }
  EXPECT_GT(pairs, tree.numLeaves());
  // The query is continuous, also across leaves of different sizes (hanging corners take the
  // larger leaf's value): finite differences stay near the gradation everywhere.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ux(-0.99, 2.99), uy(-0.99, 0.99), uz(0.01, 0.74);
  double steepest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d x(ux(rng), uy(rng), uz(rng));
    const Eigen::Vector3d h = 1e-7 * Eigen::Vector3d(uy(rng), uy(rng), uy(rng));
    steepest = std::max(steepest, std::abs(tree.delta(x + h) - tree.delta(x)) / h.norm());
  }
  // Edges graded by 0.2: at most 0.2 sqrt(3) = 0.35 inside a leaf, plus averaging (measured
  // 0.338). The difference quotient's rounding, eps delta / 1e-7 = 4e-10, is negligible.
  EXPECT_LT(steepest, 0.5);
  // No jump across a face between leaves, also of different levels: both sides agree.
  std::size_t facePoints = 0;
  double jump = 0.0;
  std::uniform_real_distribution<double> onFace(-0.999, 0.999);
  for (std::size_t i = 0; i < tree.numLeaves(); ++i) {
    const SizingOctree::Leaf a = tree.leaf(i);
    for (const std::size_t j : tree.leafNeighbours(i)) {
      const SizingOctree::Leaf b = tree.leaf(j);
      if (b.halfWidth < a.halfWidth) continue;  // walk from the smaller side
      const Eigen::Vector3d d = b.centre - a.centre;
      int axis = 0;
      d.cwiseAbs().maxCoeff(&axis);
      for (int r = 0; r < 4; ++r) {
        Eigen::Vector3d p = a.centre;
        for (int k = 0; k < 3; ++k)
          p[k] += k == axis ? (d[k] > 0 ? a.halfWidth : -a.halfWidth) : a.halfWidth * onFace(rng);
        const Eigen::Vector3d e = 1e-9 * a.halfWidth * Eigen::Vector3d::Unit(axis);
        const double inside = tree.delta(p - (d[axis] > 0 ? e : -e));
        const double across = tree.delta(p + (d[axis] > 0 ? e : -e));
        jump = std::max(jump, std::abs(inside - across) / std::min(inside, across));
        ++facePoints;
      }
    }
  }
  EXPECT_GT(facePoints, 10000u);
  // Across 2e-9 of a leaf the continuous field moves by < 0.5 * 2e-9 halfWidth / delta ~ 1e-9
  // relative, rounding by ~1e-16: a real jump (a hanging corner misinterpolated) is > 1e-3.
  EXPECT_LT(jump, 1e-5);
  // Sizes really vary: curvature near the sphere, MaxDelta far away. The exact sphere's chord
  // size is chordSize(0.25, 0.02) = 0.0995 (NekMesh's B-spline hemisphere, whose wiggles curve
  // more, gets 0.076); 0.11 lies between that and MaxDelta.
  EXPECT_LT(tree.statistics().smallestDelta, 0.11);
  // Far from the sphere the size is clamped to MaxDelta: exactly 0.2.
  EXPECT_DOUBLE_EQ(tree.delta(Eigen::Vector3d(2.9, 0.9, 0.7)), 0.2);
}

TEST(SizingOctree, GradationAndBalanceHoldBetweenNeighbours) {
  // The properties are geometric: OCCT's exact hemisphere in metres stands for NekMesh's.
  checkGradationAndBalance(test::toModel(test::hemisphereInBox(0.25)));
}

// The same on NekMesh's own 3d_sphere.stp (millimetres; its hemisphere two cubic B-spline faces).
TEST(SizingOctree, GradationAndBalanceHoldOnNekMeshSphereCase) {
  HOMESH_REQUIRE_PEER_FILES();
  checkGradationAndBalance(
      CadModel::fromFile(test::peerFile("meshgen/3d_sphere.stp")).scaled(0.001));
}

TEST(SizingOctree, QueryIsThreadSafe) {
  const CadModel cad = test::toModel(test::torus(2.0, 0.5));
  const SizingOctree tree = SizingOctree::build(cad, params(0.02, 0.5, 0.05));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Eigen::Vector3d> points(20011);  // prime: every walk below is a permutation
  for (auto& p : points) p = {u(rng), u(rng), 0.3 * u(rng)};
  std::vector<double> serial(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) serial[i] = tree.delta(points[i]);
  constexpr int kThreads = 8;
  std::vector<std::vector<double>> results(kThreads, std::vector<double>(points.size()));
  std::vector<std::thread> threads;
  threads.reserve(kThreads);
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      // Each thread walks the points in its own order.
      for (std::size_t k = 0; k < points.size(); ++k) {
        const std::size_t i = (k * (2 * t + 1) + t) % points.size();
        results[t][i] = tree.delta(points[i]);
      }
    });
  for (std::thread& t : threads) t.join();
  // The same function of the same point: bit for bit.
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(results[t], serial) << "thread " << t;
}

TEST(SizingOctree, ClassifiesTheDomainVolume) {
  // Box 4 x 4 x 2 with a through hole of radius 1: 32 - 2 pi.
  const CadModel boxHole =
      CadModel::fromFile(std::string(HOMESH_SOURCE_DIR) + "/tests/data/box_hole.step");
  // The measure's accuracy target is 2 % (1 % for the ball): sub-cells of boundary leaves
  // classified by their centres. Measured +0.39 %, +0.61 %, +1.69 % and -0.30 %; identical to 5
  // digits when the model is scaled by 1 +- 1e-12 (a sub-cell flips only when its centre lies
  // within rounding of the surface, and one flip moves the measure by < 0.1 %).
  for (const double size : {0.25, 0.5, 1.0}) {
    const SizingOctree tree = SizingOctree::build(boxHole, params(size, size, 0.1));
    EXPECT_NEAR(tree.domainMeasure(), 32.0 - 2.0 * M_PI, 0.02 * (32.0 - 2.0 * M_PI)) << size;
  }
  const CadModel ball = test::toModel(test::sphere(1.0));
  const SizingOctree tree = SizingOctree::build(ball, params(0.05, 0.3, 0.05));
  EXPECT_NEAR(tree.domainMeasure(), 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
  std::size_t inside = 0, boundary = 0, outside = 0;
  for (std::size_t i = 0; i < tree.numLeaves(); ++i) {
    const SizingOctree::Leaf l = tree.leaf(i);
    const double r = l.centre.norm(), reach = l.halfWidth * std::sqrt(3.0);
    if (l.location == SizingOctree::Location::Inside) {
      ++inside;
      EXPECT_LT(r - reach, 1.0);
    } else if (l.location == SizingOctree::Location::Outside) {
      ++outside;
      EXPECT_GT(r + reach, 1.0);
    } else {
      ++boundary;
      EXPECT_LT(std::abs(r - 1.0), 2.0 * reach);
    }
  }
  EXPECT_GT(inside, 0u);
  EXPECT_GT(boundary, 0u);
  EXPECT_GT(outside, 0u);
}

// A slender solid in a root cube thousands of times its volume: the large outside leaves next to
// it see, past the rim of its end faces, nearest samples on its side wall whose normals say
// nothing about their side; the vote must still find them outside (it once counted the whole
// cube as inside: a measure of 1.003 for a volume of 3.1e-4). The sizes are the automatic ones
// (MaxDelta the diagonal / 20, MinDelta a twentieth of that). Only the boundary leaves' sub-cells
// can err: by at most the surface area times half a sub-cell's diagonal, the bound asserted.
TEST(SizingOctree, ClassifiesASlenderSolid) {
  for (const double r : {0.01, 0.05}) {
    const double length = 1.0, diagonal = std::sqrt(length * length + 8.0 * r * r);
    const CadModel cad = test::toModel(test::cylinder(r, length));
    const SizingOctree tree =
        SizingOctree::build(cad, params(diagonal / 400.0, diagonal / 20.0, 0.05));
    double largestBoundary = 0.0;
    for (std::size_t i = 0; i < tree.numLeaves(); ++i)
      if (tree.leaf(i).location == SizingOctree::Location::Boundary)
        largestBoundary = std::max(largestBoundary, tree.leaf(i).halfWidth);
    const double subCellHalfDiagonal = std::sqrt(3.0) * largestBoundary / tree.subdivisions();
    const double area = 2.0 * M_PI * r * (r + length), volume = M_PI * r * r * length;
    EXPECT_NEAR(tree.domainMeasure(), volume, area * subCellHalfDiagonal)
        << "radius " << r << ": relative error bound " << area * subCellHalfDiagonal / volume;
  }
}

TEST(SizingOctree, SourcesRefineTheirRegion) {
  const CadModel cad = test::toModel(test::box(4.0, 4.0, 4.0));
  SizingParameters p = params(0.1, 1.0, 0.1);
  p.sources.push_back(RefinementSource::sphere({1.0, 1.0, 1.0}, 0.5, 0.05));
  p.sources.push_back(RefinementSource::segment({0.5, 3.0, 2.0}, {3.5, 3.0, 2.0}, 0.3, 0.08));
  p.sources.push_back(RefinementSource::box({2.5, 0.5, 0.5}, {3.5, 1.5, 1.5}, 0.2));
  const SizingOctree tree = SizingOctree::build(cad, p);
  // Inside a source the size is that source's delta itself (points well inside): exact.
  EXPECT_LE(tree.delta({1.0, 1.2, 1.1}), 0.05);
  EXPECT_LE(tree.delta({2.0, 3.1, 2.1}), 0.08);
  EXPECT_LE(tree.delta({3.0, 1.0, 1.4}), 0.2);
  // Graded away from the sphere source, and not refined far from every source.
  const double near = tree.delta({1.0, 1.0, 1.8}), far = tree.delta({1.0, 1.0, 3.5});
  EXPECT_LT(near, far);
  EXPECT_LE(near, 0.05 + 0.2 * 0.3 + 0.1);
  // Everywhere else the size grows away from the sources by the gradation (measured 0.686
  // against 0.668: the octree grades leaf by leaf, within a leaf width of the formula).
  EXPECT_NEAR(tree.delta({3.8, 0.2, 3.8}), 0.2 + 0.2 * std::sqrt(0.09 + 0.09 + 2.3 * 2.3), 0.15);
  // Refined leaves make the prediction grow.
  const double refined = predictElementCount(tree, cad).elements;
  const double plain =
      predictElementCount(SizingOctree::build(cad, params(0.1, 1.0, 0.1)), cad).elements;
  EXPECT_GT(refined, 1.5 * plain);  // measured 142x
}

TEST(SizingOctree, CurveSourceFollowsTheEdge) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 2.0));
  SizingParameters p = params(0.05, 0.5, 0.5);
  // The circle at z = 0: find its edge.
  int circle = 0;
  for (int e = 1; e <= cad.numEdges(); ++e)
    if (!cad.isDegenerated(e)) {
      const ParameterRange r = cad.edgeRange(e);
      const Eigen::Vector3d a = cad.evaluateCurve(e, r.first).point;
      const Eigen::Vector3d m = cad.evaluateCurve(e, 0.5 * (r.first + r.last)).point;
      if (std::abs(a.z()) < 1e-9 && std::abs(m.z()) < 1e-9) circle = e;
    }
  ASSERT_GT(circle, 0);
  p.sources.push_back(RefinementSource::curve(circle, 0.1, 0.02));
  const SizingOctree tree = SizingOctree::build(cad, p);
  for (int k = 0; k < 16; ++k) {
    const double t = 2.0 * M_PI * k / 16.0;
    EXPECT_LE(tree.delta({std::cos(t), std::sin(t), 0.0}), 0.02) << k;
  }
  EXPECT_GT(tree.delta({0.0, 0.0, 1.5}), 0.1);
  EXPECT_THROW(SizingOctree::build(cad,
                                   [&] {
                                     SizingParameters bad = params(0.05, 0.5, 0.5);
                                     bad.sources.push_back(RefinementSource::curve(99, 0.1, 0.02));
                                     return bad;
                                   }()),
               CadError);
}

TEST(SizingOctree, RejectsBadParameters) {
  const CadModel cad = test::toModel(test::box(1.0, 1.0, 1.0));
  EXPECT_THROW(SizingOctree::build(cad, params(-0.1, 1.0, 0.1)), ParameterError);
  EXPECT_NO_THROW(SizingOctree::build(cad, params(0.0, 1.0, 0.1)));  // 0: automatic
  EXPECT_THROW(SizingOctree::build(cad, params(0.5, 0.1, 0.1)), ParameterError);
  EXPECT_THROW(SizingOctree::build(cad, params(0.1, 1.0, 0.0)), ParameterError);
  EXPECT_THROW(SizingOctree::build(cad, params(0.1, 1.0, 1.5)), ParameterError);
  SizingParameters p = params(0.1, 1.0, 0.1);
  p.sources.push_back(RefinementSource::sphere({0, 0, 0}, -1.0, 0.1));
  try {
    SizingOctree::build(cad, p);
    FAIL();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("refinement source 1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos) << e.what();
  }
}

TEST(SizingOctree, LeavesExportToAMesh) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  const SizingOctree tree = SizingOctree::build(cad, params(0.05, 0.5, 0.05));
  const OctreeMesh m = octreeLeavesMesh(tree);
  const std::size_t notOutside = tree.statistics().insideLeaves + tree.statistics().boundaryLeaves;
  ASSERT_EQ(m.mesh.numElements(), notOutside);
  ASSERT_EQ(m.fields.size(), 4u);
  EXPECT_EQ(m.fields[0].name, "delta");
  // The hexahedra tile the leaves that are not outside: their volumes add up.
  double volume = 0.0;
  for (std::size_t i = 0; i < tree.numLeaves(); ++i) {
    const SizingOctree::Leaf l = tree.leaf(i);
    if (l.insideFraction > 0.0) volume += std::pow(2.0 * l.halfWidth, 3);
  }
  const ElementBlock& hexes = m.mesh.blocks[0];
  double fromMesh = 0.0;
  for (std::size_t e = 0; e < hexes.count(); ++e) {
    const std::int64_t* n = hexes.element(e);
    const Eigen::Vector3d a(&m.mesh.xyz[3 * n[0]]), b(&m.mesh.xyz[3 * n[6]]);
    fromMesh += std::abs((b - a).prod());
  }
  // Sums of the same cubes in two orders: <= n eps relative with n < 1e5 leaves.
  EXPECT_NEAR(fromMesh, volume, 1e-9 * volume);
}

}  // namespace
}  // namespace homesh
