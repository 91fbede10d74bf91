// One Newton step of the optimiser (node_step.hpp): it lowers its patch's energy, keeps the
// cached F and J those of the moved nodes, steps perpendicular to a locked direction, and keeps
// a sliding node on the CAD.
#include "optimise/node_step.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "optimise/mesh_topology.hpp"
#include "optimise/node_colouring.hpp"
#include "optimiser_parts.hpp"

namespace homesh {
namespace {

using optimiser::CadSliding;
using optimiser::NodeColouring;
using optimiser::NodeStep;
using optimiser::Patch;
using optimiser::WorkingMesh;

// The set-up a sweep has: F computed at every element, the free nodes those inside the domain
// and, with CAD, those sliding on it.
struct Stepper {
  Mesh mesh;
  WorkingMesh<3> working;
  CadSliding<3> sliding;
  OptimiserOptions options;
  std::vector<Eigen::Vector3d> locked;
  NodeStep<3> step{working, sliding, options, locked};
  NodeColouring<3> owners{1};
  std::vector<std::int64_t> free;
  std::vector<std::size_t> all;

  Stepper(Mesh m, const CadModel* cad)
      : mesh(std::move(m)), working(mesh, cad == nullptr), sliding(working, cad) {
    working.build();
    working.buildSamples(optimiser::EnergyRule::Collapsed);
    std::vector<char> boundary = boundaryNodes(mesh.numNodes(), {working.blocks[0].cells});
    sliding.choose(boundary, 1);
    for (std::size_t n = 0; n < mesh.numNodes(); ++n)
      if (boundary[n] == 0) free.push_back(static_cast<std::int64_t>(n));
    all.resize(working.totalElements);
    std::iota(all.begin(), all.end(), std::size_t{0});
    working.computeGradients(all, owners);
  }
};

TEST(NodeStep, AStepLowersItsPatchsEnergyAndKeepsFAndJThoseOfTheNodes) {
  Stepper s(test::perturbedCube(), nullptr);
  Patch<3> patch;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < 40 && i < s.free.size(); ++i) {
    const std::int64_t node = s.free[i];
    const double eps = s.step.gather(node, patch);
    const Eigen::Vector3d before = s.working.position[node];
    const double e0 = s.step.probe(node, before, eps).value;
    const double d = s.step.visit(node, patch);
    EXPECT_NEAR(d, (s.working.position[node] - before).norm(), 1e-12 * d);
    if (d == 0.0) continue;
    ++moved;
    EXPECT_LT(s.step.probe(node, s.working.position[node], eps).value, e0) << node;
  }
  EXPECT_GT(moved, 20u);
  // The rank-one updates left F and J as the nodes now give them, to rounding.
  std::vector<double> F = s.working.blocks[0].F, J = s.working.blocks[0].J;
  s.working.computeGradients(s.all, s.owners);
  double worst = 0.0;
  for (std::size_t k = 0; k < F.size(); ++k)
    worst = std::max(worst, std::abs(F[k] - s.working.blocks[0].F[k]));
  for (std::size_t k = 0; k < J.size(); ++k)
    worst = std::max(worst, std::abs(J[k] - s.working.blocks[0].J[k]));
  EXPECT_LT(worst, 1e-12);
}

TEST(NodeStep, ALockedNodeStepsPerpendicularToItsDirection) {
  Stepper s(test::perturbedCube(), nullptr);
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  s.locked.assign(s.mesh.numNodes(), Eigen::Vector3d::Constant(std::nan("")));
  Patch<3> patch;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < 20 && i < s.free.size(); ++i) {
    const std::int64_t node = s.free[i];
    s.locked[node] = n;
    const Eigen::Vector3d before = s.working.position[node];
    if (s.step.visit(node, patch) == 0.0) continue;
    ++moved;
    const Eigen::Vector3d d = s.working.position[node] - before;
    EXPECT_LT(std::abs(d.dot(n)), 1e-15 * before.norm() + 1e-14 * d.norm()) << node;
  }
  EXPECT_GT(moved, 10u);
}

TEST(NodeStep, ASlidingNodeStaysOnTheCad) {
  const MeshResult& hole = test::holeOnCad();
  Stepper s(hole.mesh, hole.cad.get());
  Patch<3> patch;
  std::size_t moved = 0, faces = 0;
  for (const std::int64_t node : s.free) {
    if (s.sliding.parameters(node) != 2 || faces == 30) continue;
    ++faces;
    const double eps = s.step.gather(node, patch);
    const Eigen::Vector2d start(&s.mesh.nodeCadParam[2 * node]);
    const double e0 = s.step.probe(node, start, eps).value;
    if (s.step.visit(node, patch) == 0.0) continue;
    ++moved;
    const double* param = &s.mesh.nodeCadParam[2 * node];
    const Eigen::Vector3d on =
        hole.cad->evaluateSurface(s.mesh.nodeCadIndex[node], param[0], param[1]).point;
    EXPECT_EQ(s.working.position[node], on) << node;  // the CAD's own point, not the model's
    EXPECT_LT(s.step.probe(node, Eigen::Vector2d(param[0], param[1]), eps).value, e0);
  }
  EXPECT_GT(faces, 0u);
  EXPECT_GT(moved, 0u);
  EXPECT_LE(patch.slides, faces);
  EXPECT_GE(patch.slides, moved);
  EXPECT_GE(patch.cadEvaluations, moved);
}

}  // namespace
}  // namespace homesh
