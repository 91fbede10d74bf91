// The optimiser's certified quality (certified_quality.hpp): the input's measured or taken from
// the caller, and kept up to date for the elements a pass changed, with the worst value and the
// validity counts of evaluateQuality's full refinement.
#include "optimise/certified_quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "optimiser_parts.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {
namespace {

using optimiser::CertifiedQuality;
using optimiser::NodeColouring;
using optimiser::WorkingMesh;

struct Measured {
  Mesh mesh;
  WorkingMesh<3> working;
  NodeColouring<3> owners{2};
  OptimiserOptions options;
  CertifiedQuality<3> quality{working, owners, options};
  // `converting`: in the working node set's coordinates (where the caller's quality is ignored).
  explicit Measured(Mesh m, bool converting = false)
      : mesh(std::move(m)), working(mesh, converting) {
    working.build();
    working.buildSamples(optimiser::EnergyRule::Collapsed);
  }
};

TEST(CertifiedQuality, TheInputsWorstAndCountsAreEvaluateQualitys) {
  const Mesh& cube = test::perturbedCube();
  const QualitySummary full = evaluateQuality(cube);
  Measured m(cube);
  m.quality.measureInput(nullptr);
  const IterationRecord r = m.quality.summarise(0, 0.25, optimiser::Clock::now());
  EXPECT_EQ(r.iteration, 0);
  EXPECT_EQ(r.maxDisplacement, 0.25);
  EXPECT_EQ(r.worst, full.scaled.min);
  EXPECT_EQ(r.invalid, full.invalid);
  EXPECT_EQ(r.undecided, full.undecided);
  EXPECT_EQ(m.quality.validity(), full.validity);
  // Every element's certified lower bound (coarse away from the worst) is below the values of
  // J found.
  for (std::size_t e = 0; e < full.scaledJacobian.size(); ++e)
    EXPECT_LE(m.quality.scaled()[e], full.scaledJacobianUpper[e]) << e;
}

TEST(CertifiedQuality, TheCallersQualityIsTakenOnlyWhereItFits) {
  const Mesh& cube = test::perturbedCube();
  QualitySummary given = evaluateQuality(cube);
  given.scaledJacobian[7] = -0.5;  // recognisable: taken, not measured
  {
    Measured m(cube);
    m.quality.measureInput(&given);
    EXPECT_EQ(m.quality.summarise(0, 0.0, optimiser::Clock::now()).worst, -0.5);
  }
  {
    Measured m(cube, true);  // another mesh in the working set's coordinates: measured
    m.quality.measureInput(&given);
    EXPECT_GT(m.quality.summarise(0, 0.0, optimiser::Clock::now()).worst, 0.0);
  }
  given.validity.pop_back();  // not this mesh's: measured
  Measured m(cube);
  m.quality.measureInput(&given);
  EXPECT_GT(m.quality.summarise(0, 0.0, optimiser::Clock::now()).worst, 0.0);
}

// After a node moves, evaluating its elements gives what measuring the whole mesh gives.
TEST(CertifiedQuality, EvaluatingTheChangedElementsKeepsTheWholeMeshsVerdict) {
  Measured m(test::perturbedCube());
  m.quality.measureInput(nullptr);
  // Fold one element: its first edge node beyond the nearer end of its edge.
  const ElementBlock& tets = *m.working.blocks[0].cells;
  const std::int64_t* v = tets.element(5);
  const auto node = static_cast<std::size_t>(v[4]);
  const Eigen::Vector3d beyond =
      3.0 * test::nodePoint(m.mesh, v[0]) - 2.0 * test::nodePoint(m.mesh, v[4]);
  for (std::size_t c = 0; c < 3; ++c) m.mesh.xyz[3 * node + c] = beyond[c];
  std::vector<std::size_t> changed;
  for (std::size_t k = m.working.incidenceStart[node]; k < m.working.incidenceStart[node + 1]; ++k)
    changed.push_back(m.working.globalIndex(m.working.incidence[k]));
  m.quality.evaluate(changed);
  const QualitySummary full = evaluateQuality(m.mesh);
  ASSERT_GT(full.invalid, 0u);
  const IterationRecord r = m.quality.summarise(1, 0.0, optimiser::Clock::now());
  EXPECT_EQ(r.worst, full.scaled.min);
  EXPECT_EQ(r.invalid, full.invalid);
  EXPECT_EQ(r.undecided, full.undecided);
  EXPECT_EQ(m.quality.validity(), full.validity);
}

}  // namespace
}  // namespace homesh
