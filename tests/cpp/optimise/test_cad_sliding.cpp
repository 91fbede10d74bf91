// The optimiser's nodes that slide on the CAD (cad_sliding.hpp): which nodes slide, their points
// and local models, the model a step leaves for the next visit, and the clamped trial
// parameters.
#include "optimise/cad_sliding.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "optimiser_parts.hpp"

namespace homesh {
namespace {

using optimiser::CadSliding;
using optimiser::WorkingMesh;

struct Hole {
  const MeshResult& source = test::holeOnCad();
  Mesh mesh = source.mesh;
  WorkingMesh<3> working{mesh, false};
  CadSliding<3> sliding{working, source.cad.get()};
  std::vector<char> boundary;
  Hole() {
    working.build();
    working.buildSamples(optimiser::EnergyRule::Collapsed);
    boundary.assign(mesh.numNodes(), 1);  // every node fixed before the CAD's say
    sliding.choose(boundary, 2);
  }
  // The first node on a CAD entity of dimension `dim` (-1 if none).
  std::int64_t firstOn(int dim) const {
    for (std::size_t n = 0; n < mesh.numNodes(); ++n)
      if (mesh.nodeCadDim[n] == dim && mesh.nodeCadIndex[n] > 0)
        return static_cast<std::int64_t>(n);
    return -1;
  }
};

TEST(CadSliding, NodesOnCurvesAndFacesSlideAndVerticesStay) {
  Hole h;
  std::size_t curves = 0, faces = 0;
  for (std::size_t n = 0; n < h.mesh.numNodes(); ++n) {
    const auto node = static_cast<std::int64_t>(n);
    if (h.mesh.nodeCadIndex[n] <= 0) {
      EXPECT_EQ(h.sliding.parameters(node), 0);
      EXPECT_EQ(h.boundary[n], 1);  // no CAD record: the topological rule's verdict stands
      continue;
    }
    switch (h.mesh.nodeCadDim[n]) {
      case 0:
        EXPECT_EQ(h.sliding.parameters(node), 0);
        EXPECT_EQ(h.boundary[n], 1);
        break;
      case 1:
        curves += h.sliding.parameters(node) == 1 ? 1 : 0;
        EXPECT_EQ(h.boundary[n], h.sliding.parameters(node) == 1 ? 0 : 1);
        break;
      case 2:
        EXPECT_EQ(h.sliding.parameters(node), 2);
        EXPECT_EQ(h.boundary[n], 0);
        ++faces;
        break;
      default:  // inside the volume: not the CAD's business
        EXPECT_EQ(h.sliding.parameters(node), 0);
        EXPECT_EQ(h.boundary[n], 1);
    }
  }
  EXPECT_GT(curves, 0u);
  EXPECT_GT(faces, 0u);
  // Without a model nothing slides and the boundary is left as it was.
  std::vector<char> boundary(h.mesh.numNodes(), 1);
  CadSliding<3> none(h.working, nullptr);
  none.choose(boundary, 1);
  for (std::size_t n = 0; n < h.mesh.numNodes(); ++n) {
    EXPECT_EQ(none.parameters(static_cast<std::int64_t>(n)), 0);
    EXPECT_EQ(boundary[n], 1);
  }
}

TEST(CadSliding, PointsAndModelsAreTheCadsAtTheGivenParameters) {
  Hole h;
  const CadModel& cad = *h.source.cad;
  for (const int dim : {1, 2}) {
    SCOPED_TRACE(dim);
    const std::int64_t node = h.firstOn(dim);
    ASSERT_GE(node, 0);
    const double* param = &h.mesh.nodeCadParam[2 * node];
    const int entity = h.mesh.nodeCadIndex[node];
    const Eigen::Vector3d point = dim == 1 ? cad.evaluateCurve(entity, param[0]).point
                                           : cad.evaluateSurface(entity, param[0], param[1]).point;
    const Eigen::Vector3d on = h.sliding.pointOn(h.sliding.threadCad(), node, param);
    EXPECT_EQ(on, point);                                     // the frame is the identity in 3D
    EXPECT_LT((on - h.working.position[node]).norm(), 1e-7);  // the mesh's node is on the CAD
    const LocalCadModel<3> m = h.sliding.localModel(h.sliding.threadCad(), node, param);
    EXPECT_EQ(m.parameters, dim);
    EXPECT_EQ(m.point, point);
    EXPECT_EQ(m.at0[0], param[0]);
    EXPECT_EQ(m.at0[1], dim == 1 ? 0.0 : param[1]);
  }
}

// The model is evaluated once and then reused while the node's parameters are those it was
// built at; a step keeps the model of its accepted point for the next visit.
TEST(CadSliding, TheCurrentModelIsReusedUntilTheParametersChange) {
  Hole h;
  const std::int64_t node = h.firstOn(2);
  ASSERT_GE(node, 0);
  const CadModel& cad = h.sliding.threadCad();
  std::size_t evaluations = 0;
  const Eigen::Vector3d first = h.sliding.currentModel(cad, node, evaluations).point;
  EXPECT_EQ(evaluations, 1u);
  EXPECT_EQ(h.sliding.currentModel(cad, node, evaluations).point, first);
  EXPECT_EQ(evaluations, 1u);
  double* param = &h.mesh.nodeCadParam[2 * node];
  const double moved[2] = {param[0] + 1e-3, param[1]};
  const LocalCadModel<3> next = h.sliding.localModel(cad, node, moved);
  param[0] = moved[0];
  h.sliding.keepModel(node, next);
  EXPECT_EQ(h.sliding.currentModel(cad, node, evaluations).point, next.point);
  EXPECT_EQ(evaluations, 1u);
  param[1] += 1e-3;  // moved without a kept model: evaluated afresh
  h.sliding.currentModel(cad, node, evaluations);
  EXPECT_EQ(evaluations, 2u);
}

TEST(CadSliding, TrialParametersStayInTheCurvesRangeAndTheFacesBounds) {
  Hole h;
  const CadModel& cad = *h.source.cad;
  for (const int dim : {1, 2}) {
    SCOPED_TRACE(dim);
    const std::int64_t node = h.firstOn(dim);
    ASSERT_GE(node, 0);
    const double* param = &h.mesh.nodeCadParam[2 * node];
    const int entity = h.mesh.nodeCadIndex[node];
    Eigen::VectorXd step = Eigen::VectorXd::Constant(dim, 1e6);
    const std::array<double, 2> far = h.sliding.trial(node, param, 1.0, step);
    const std::array<double, 2> back = h.sliding.trial(node, param, 1.0, -step);
    const std::array<double, 2> small = h.sliding.trial(node, param, 0.5, step * 1e-12);
    EXPECT_LE(std::abs(small[0] - param[0]), 1e-6);  // a small step is not clamped away
    if (dim == 1) {
      const ParameterRange r = cad.edgeRange(entity);
      EXPECT_EQ(far[0], r.last);
      EXPECT_EQ(back[0], r.first);
      // unused on a curve (NaN in the mesh's record), left as it was
      EXPECT_TRUE(far[1] == param[1] || (std::isnan(far[1]) && std::isnan(param[1])));
    } else {
      const SurfaceBounds b = cad.faceBounds(entity);
      EXPECT_EQ(far[0], b.uMax);
      EXPECT_EQ(far[1], b.vMax);
      EXPECT_EQ(back[0], b.uMin);
      EXPECT_EQ(back[1], b.vMin);
    }
  }
}

}  // namespace
}  // namespace homesh
