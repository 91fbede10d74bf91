// The optimiser's stop rules (stop_rules.hpp), each made to fire: first as pure functions of
// made-up sweep records (where each fires and where it does not), then in whole runs whose
// result names the rule that stopped them. The time limit's other cases (between sweeps, part-way
// through a sweep) are in test_optimiser.cpp (ATimeLimitStopsWithTheBestStateSoFar,
// ATimeLimitPartWayThroughASweepKeepsWhatItMoved).
#include "optimise/stop_rules.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "optimise/optimiser.hpp"
#include "optimiser_parts.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {
namespace {

using optimiser::acceptable;
using optimiser::better;
using optimiser::stopRule;

IterationRecord record(int iteration, double worst, std::size_t invalid, double energy,
                       double relativeMove = 1.0) {
  IterationRecord r;
  r.iteration = iteration;
  r.worst = worst;
  r.invalid = invalid;
  r.energy = energy;
  r.maxRelativeMove = relativeMove;
  return r;
}

// No rule but the one a test sets up can fire: every tolerance 0, stall off.
OptimiserOptions quiet() {
  OptimiserOptions o;
  o.tolerance = 0.0;
  o.energyTolerance = 0.0;
  o.stall = 0.0;
  return o;
}

TEST(StopRules, DisplacementFiresOnceNoNodeMovesMoreThanTheTolerance) {
  OptimiserOptions o = quiet();
  o.tolerance = 1e-6;
  const IterationRecord input = record(0, 0.5, 0, 10.0);
  EXPECT_EQ(stopRule({record(1, 0.6, 0, 9.0, 1e-6)}, input, input, o), "displacement");
  EXPECT_EQ(stopRule({record(1, 0.6, 0, 9.0, 2e-6)}, input, input, o), "");
  // Whatever the mesh's validity: nothing moves any more.
  EXPECT_EQ(stopRule({record(1, -0.1, 3, 9.0, 0.0)}, input, input, o), "displacement");
}

TEST(StopRules, EnergyFiresOnlyOnAProvenValidMesh) {
  OptimiserOptions o = quiet();
  o.energyTolerance = 1e-3;
  const IterationRecord previous = record(0, 0.5, 0, 10.0);
  // A fall of 1e-4 of the energy: below the tolerance.
  EXPECT_EQ(stopRule({record(1, 0.6, 0, 10.0 / (1.0 + 1e-4))}, previous, previous, o), "energy");
  EXPECT_EQ(stopRule({record(1, 0.6, 0, 9.0)}, previous, previous, o), "");
  // An invalid (or undecided) mesh keeps going: untangling can follow a plateau of the energy.
  EXPECT_EQ(stopRule({record(1, -0.2, 1, 10.0)}, previous, previous, o), "");
  IterationRecord undecided = record(1, 0.6, 0, 10.0);
  undecided.undecided = 1;
  EXPECT_EQ(stopRule({undecided}, previous, previous, o), "");
  EXPECT_DOUBLE_EQ(optimiser::energyFall(record(1, 0.6, 0, 8.0), previous), 0.25);
}

// In stall mode a sweep that raised the worst by `stall` or more is progress whatever the
// energy did: where most nodes rest, the few around the worst element lower it by little.
TEST(StopRules, EnergyWaitsInStallModeWhileTheWorstStillRises) {
  OptimiserOptions o = quiet();
  o.energyTolerance = 1e-3;
  o.stall = 1e-3;
  o.stallEnergy = 0.0;  // the stalled rule itself stays quiet
  const IterationRecord previous = record(0, 0.5, 0, 10.0);
  const double flat = 10.0 / (1.0 + 1e-4);  // a fall below energyTolerance
  EXPECT_EQ(stopRule({record(1, 0.502, 0, flat)}, previous, previous, o), "");
  EXPECT_EQ(stopRule({record(1, 0.5005, 0, flat)}, previous, previous, o), "energy");
  EXPECT_EQ(stopRule({record(1, 0.4, 0, flat)}, previous, previous, o), "energy");
  o.stall = 0.0;  // without stall mode the energy alone decides
  EXPECT_EQ(stopRule({record(1, 0.502, 0, flat)}, previous, previous, o), "energy");
}

TEST(StopRules, StalledMeasuresTheLastSweepAgainstTheWindowsLowestWorst) {
  OptimiserOptions o = quiet();
  o.stall = 1e-3;
  o.stallEnergy = 0.05;
  o.stallWindow = 2;
  const IterationRecord input = record(0, 0.5, 0, 10.0);
  // Too few sweeps for the window, then the worst 0.5005 against the input's 0.5: stalled.
  std::vector<IterationRecord> h{record(1, 0.5002, 0, 9.9)};
  EXPECT_EQ(stopRule(h, input, input, o), "");
  h.push_back(record(2, 0.5005, 0, 9.8));
  EXPECT_EQ(stopRule(h, h[0], input, o), "stalled");
  // Not while the energy still falls by stallEnergy or more.
  h.back().energy = 9.0;
  EXPECT_EQ(stopRule(h, h[0], input, o), "");
  // The window's own dip counts: climbing back from 0.40 to 0.4005 is not progress past the
  // lowest (0.40), so it stalls; climbing to 0.41 is progress.
  h = {record(1, 0.6, 0, 9.9), record(2, 0.40, 0, 9.85), record(3, 0.4005, 0, 9.8)};
  EXPECT_EQ(stopRule(h, h[1], input, o), "stalled");
  h.back().worst = 0.41;
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  // Only on a proven-valid mesh, and only with a stall.
  h.back() = record(3, 0.4005, 1, 9.8);
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  h.back() = record(3, 0.4005, 0, 9.8);
  o.stall = 0.0;
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
}

TEST(StopRules, StuckNeedsAWholeWindowWithoutProgressOnAnInvalidMesh) {
  OptimiserOptions o = quiet();
  o.stall = 1e-3;
  o.stallEnergy = 0.05;
  o.stuckWindow = 2;
  const IterationRecord input = record(0, -0.3, 4, 100.0);
  std::vector<IterationRecord> h{record(1, -0.2, 3, 90.0), record(2, -0.2, 3, 89.9)};
  EXPECT_EQ(stopRule(h, h[0], input, o), "");  // not more sweeps than the window yet
  h.push_back(record(3, -0.1996, 3, 89.8));
  EXPECT_EQ(stopRule(h, h[1], input, o), "stuck");  // 3 -> 3 invalid, worst +0.0004
  h.back().invalid = 2;                             // an element became valid within the window
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  h.back() = record(3, -0.15, 3, 89.8);  // the worst rose by the stall or more
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  h.back() = record(3, -0.1996, 3, 80.0);  // the energy still falls by stallEnergy or more
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  h.back() = record(3, -0.1996, 3, 89.8);
  o.stall = 0.0;  // off without a stall
  EXPECT_EQ(stopRule(h, h[1], input, o), "");
  EXPECT_TRUE(optimiser::converges("stalled"));
  EXPECT_FALSE(optimiser::converges("stuck"));
}

TEST(StopRules, TheFirstRuleThatHoldsIsNamed) {
  OptimiserOptions o;
  o.tolerance = 1e-6;
  o.energyTolerance = 1e-3;
  o.stall = 1e-3;
  o.stallWindow = 1;
  const IterationRecord input = record(0, 0.5, 0, 10.0);
  // Displacement, energy and stall all hold: displacement comes first, then energy.
  std::vector<IterationRecord> h{record(1, 0.5, 0, 10.0, 0.0)};
  EXPECT_EQ(stopRule(h, input, input, o), "displacement");
  h.back().maxRelativeMove = 1.0;
  EXPECT_EQ(stopRule(h, input, input, o), "energy");
  o.energyTolerance = 0.0;
  EXPECT_EQ(stopRule(h, input, input, o), "stalled");
}

TEST(StopRules, TheStateKeptIsAcceptableAndBetter) {
  const IterationRecord input = record(0, 0.3, 2, 10.0);
  EXPECT_TRUE(acceptable(record(1, 0.3, 2, 11.0), input));
  EXPECT_FALSE(acceptable(record(1, 0.29, 0, 1.0), input));  // a lower worst value
  EXPECT_FALSE(acceptable(record(1, 0.5, 3, 1.0), input));   // more invalid elements
  // Fewer elements not proven valid first, then the worst value, then (a tie) the energy.
  EXPECT_TRUE(better(record(1, 0.1, 1, 20.0), input));
  EXPECT_TRUE(better(record(1, 0.31, 2, 20.0), input));
  EXPECT_TRUE(better(record(1, 0.3, 2, 9.0), input));
  EXPECT_FALSE(better(record(1, 0.3, 2, 10.0), input));
  IterationRecord undecided = record(1, 0.9, 0, 1.0);
  undecided.undecided = 3;
  EXPECT_FALSE(better(undecided, input));
}

TEST(StopRules, ATimeBudgetIsSpentOnceItsLimitHasPassedAndStaysSpent) {
  optimiser::TimeBudget none;
  EXPECT_FALSE(none.limited());
  EXPECT_FALSE(none.overBudget());
  const auto start = optimiser::Clock::now();
  optimiser::TimeBudget later(3600.0, start);
  EXPECT_FALSE(later.overBudget());
  EXPECT_FALSE(later.spent());
  optimiser::TimeBudget past(1e-3, start - std::chrono::seconds(1));
  EXPECT_FALSE(past.spent());  // asked by overBudget() only
  EXPECT_TRUE(past.overBudget());
  EXPECT_TRUE(past.spent());
}

// ---- Whole runs: the result names the rule that ended each. ----------------------------------

// A run of the perturbed cube (valid, every node off its optimum) with `options` on one thread.
OptimiserResult runCube(const OptimiserOptions& options, Mesh* out = nullptr,
                        OptimiserObserver* observer = nullptr) {
  Mesh mesh = test::perturbedCube();
  OptimiserResult r = optimiseMesh(mesh, options, observer);
  if (out != nullptr) *out = std::move(mesh);
  return r;
}

// The history matches the sweep count and its last record is the one the rule judged.
void expectHistory(const OptimiserResult& r, int sweeps) {
  EXPECT_EQ(r.iterations, sweeps);
  ASSERT_EQ(r.history.size(), static_cast<std::size_t>(sweeps));
  for (int i = 0; i < sweeps; ++i) EXPECT_EQ(r.history[i].iteration, i + 1);
}

TEST(OptimiserStops, DisplacementWhenNoNodeMovesMoreThanTheTolerance) {
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  o.tolerance = 1e9;  // any move is below it
  const OptimiserResult r = runCube(o);
  EXPECT_EQ(r.stopReason, "displacement");
  EXPECT_TRUE(r.converged);
  expectHistory(r, 1);
  EXPECT_LE(r.history.back().maxRelativeMove, o.tolerance);
}

TEST(OptimiserStops, EnergyWhenAValidMeshsEnergyFallsLessThanItsTolerance) {
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  o.energyTolerance = 1e9;
  const OptimiserResult r = runCube(o);
  EXPECT_EQ(r.stopReason, "energy");
  EXPECT_TRUE(r.converged);
  expectHistory(r, 1);
  EXPECT_EQ(r.history.back().invalid + r.history.back().undecided, 0u);
  EXPECT_LT(r.history.back().energy, r.energyBefore);
}

TEST(OptimiserStops, StalledWhenAValidMeshsWorstNoLongerRises) {
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  o.stall = 1e9;  // any rise of the worst is below it
  o.stallEnergy = 1e9;
  o.stallWindow = 2;
  const OptimiserResult r = runCube(o);
  EXPECT_EQ(r.stopReason, "stalled");
  EXPECT_TRUE(r.converged);
  expectHistory(r, 2);  // the first sweep the window allows
}

TEST(OptimiserStops, IterationsWhenMaxIterationsSweepsAreDone) {
  OptimiserOptions o = quiet();
  o.maxIterations = 2;
  const OptimiserResult r = runCube(o);
  EXPECT_EQ(r.stopReason, "iterations");
  EXPECT_FALSE(r.converged);
  expectHistory(r, 2);
}

TEST(OptimiserStops, NoFreeNodesBeforeAnySweep) {
  OptimiserOptions o = quiet();
  o.fixedNodes.assign(test::perturbedCube().numNodes(), 1);
  Mesh mesh;
  const OptimiserResult r = runCube(o, &mesh);
  EXPECT_EQ(r.stopReason, "no free nodes");
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.freeNodes, 0u);
  expectHistory(r, 0);
  EXPECT_EQ(mesh.xyz, test::perturbedCube().xyz);
}

// A mesh with elements that cannot become valid: one element inverted (a node beyond its
// nearest vertex folds the element's edge back) and every node of the elements around that node
// fixed, while the rest of the mesh moves. Its invalid count never falls: stuck.
TEST(OptimiserStops, StuckWhenAnInvalidMeshNoLongerImproves) {
  Mesh mesh = test::perturbedCube();
  const ElementBlock* tets = nullptr;
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Tetrahedron) tets = &b;
  ASSERT_NE(tets, nullptr);
  const std::size_t e = tets->count() / 2;
  const std::int64_t* v = tets->element(e);
  const std::int64_t moved = v[4];  // the first node after the vertices: on an edge
  std::int64_t nearest = v[0];
  for (int k = 1; k < 4; ++k)
    if ((test::nodePoint(mesh, v[k]) - test::nodePoint(mesh, moved)).norm() <
        (test::nodePoint(mesh, nearest) - test::nodePoint(mesh, moved)).norm())
      nearest = v[k];
  const Eigen::Vector3d beyond =
      2.0 * test::nodePoint(mesh, nearest) - test::nodePoint(mesh, moved);
  for (int c = 0; c < 3; ++c) mesh.xyz[3 * static_cast<std::size_t>(moved) + c] = beyond[c];
  const QualitySummary before = evaluateQuality(mesh);
  ASSERT_GT(before.invalid, 0u);

  OptimiserOptions o = quiet();
  o.maxIterations = 10;
  o.stall = 1e9;
  o.stallEnergy = 1e9;
  o.stuckWindow = 2;
  o.fixedNodes.assign(mesh.numNodes(), 0);
  for (std::size_t k = 0; k < tets->count(); ++k) {
    const std::int64_t* w = tets->element(k);
    if (std::find(w, w + tets->nodesPerElement(), moved) == w + tets->nodesPerElement()) continue;
    for (int j = 0; j < tets->nodesPerElement(); ++j)
      o.fixedNodes[static_cast<std::size_t>(w[j])] = 1;
  }
  const OptimiserResult r = optimiseMesh(mesh, o);
  EXPECT_EQ(r.stopReason, "stuck");
  EXPECT_FALSE(r.converged);
  expectHistory(r, 3);  // the first sweep after a whole window
  EXPECT_GT(r.history.back().maxRelativeMove, 0.0);
  EXPECT_GE(r.history.back().invalid, r.history.front().invalid);
  EXPECT_GT(r.invalidAfter, 0u);
}

TEST(OptimiserStops, CancelledBeforeASweep) {
  struct CancelAtOnce : OptimiserObserver {
    bool cancelRequested() override { return true; }
  } cancel;
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  Mesh mesh;
  const OptimiserResult r = runCube(o, &mesh, &cancel);
  EXPECT_EQ(r.stopReason, "cancelled");
  EXPECT_TRUE(r.cancelled);
  EXPECT_FALSE(r.converged);
  expectHistory(r, 0);
  EXPECT_EQ(mesh.xyz, test::perturbedCube().xyz);
}

// Asked again between the colour groups of a sweep: the half-done sweep is dropped.
TEST(OptimiserStops, CancelledDuringASweep) {
  struct CancelAtThirdAsk : OptimiserObserver {
    int asks = 0;
    bool cancelRequested() override { return ++asks == 3; }
  } cancel;
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  Mesh mesh;
  const OptimiserResult r = runCube(o, &mesh, &cancel);
  EXPECT_EQ(cancel.asks, 3);
  EXPECT_EQ(r.stopReason, "cancelled");
  EXPECT_TRUE(r.cancelled);
  expectHistory(r, 0);
  EXPECT_EQ(mesh.xyz, test::perturbedCube().xyz);
}

TEST(OptimiserStops, TimeBudgetSpentInTheSetUp) {
  OptimiserOptions o = quiet();
  o.maxIterations = 5;
  o.timeLimit = 1e-9;
  Mesh mesh;
  const OptimiserResult r = runCube(o, &mesh);
  EXPECT_EQ(r.stopReason, "time budget");
  EXPECT_FALSE(r.cancelled);
  EXPECT_FALSE(r.converged);
  expectHistory(r, 0);
  EXPECT_TRUE(std::isnan(r.energyBefore));
  EXPECT_EQ(mesh.xyz, test::perturbedCube().xyz);
}

// A job's time budget reaches the optimiser as its time limit (what is left of the budget when
// it starts): an observer holds the first optimiser sweep's progress report until the job's
// budget has passed, so the run stops at its next check, says "time budget", and the job
// records the optimiser as cut, however fast the machine.
TEST(OptimiserStops, TimeBudgetOfTheJobStopsThePipelinesOptimiser) {
  class HoldPastTheBudget : public PipelineObserver {
   public:
    explicit HoldPastTheBudget(double seconds) : seconds_(seconds) {}
    void stageStarted(const std::string& stage) override {
      if (stage == "cad") start_ = std::chrono::steady_clock::now();  // the budget's clock
    }
    void stageProgress(const std::string& stage, double /*fraction*/,
                       const std::string& /*detail*/) override {
      if (stage == "optimise" && !held) {
        held = true;
        std::this_thread::sleep_until(start_ + std::chrono::duration<double>(seconds_));
      }
    }
    bool held = false;

   private:
    double seconds_;
    std::chrono::steady_clock::time_point start_;
  };
  MeshingOptions options;
  options.order = 2;
  options.size = 1.2;
  options.optimiseIterations = 50;
  options.repairRounds = 0;
  options.jobSeconds = 3.0;
  HoldPastTheBudget hold(options.jobSeconds);
  const MeshResult result =
      runMeshPipeline(CadSource::file(std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step"),
                      options, &hold);
  ASSERT_TRUE(result.optimiser.has_value()) << "the job's budget was spent before the optimiser";
  EXPECT_TRUE(hold.held);
  EXPECT_EQ(result.optimiser->stopReason, "time budget");
  EXPECT_EQ(result.optimiser->iterations, 1);
  EXPECT_EQ(result.job.cut, std::vector<std::string>{"optimise"});
}

}  // namespace
}  // namespace homesh
