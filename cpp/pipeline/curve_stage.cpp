#include "pipeline/curve_stage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "boundary_layer/layer_blend.hpp"
#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_normals.hpp"
#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "pipeline/curved_reuse.hpp"
#include "pipeline/stage_clock.hpp"

namespace homesh {

namespace {

// What the job's budget keeps back for what runs after an optimiser run stopped by it (the
// optimiser's own closing check of the mesh it keeps, the quality check, the output), in
// multiples of the elevation's time: the quality check and output took 1.2 and 2.7 times the
// elevation at order 4 on MODERN_Refrigerator_1_opened.brep (1.7 s; quality 1.2 s, output 0.9 s)
// and the sphere in a box (0.3 s; quality 0.6 s, slower where elements are poor and their bounds
// are refined, output 0.2 s), and the optimiser's closing check about as long as the quality
// check. Without it a job stopped by its budget overran it by those (3.7 s of 360 on the
// refrigerator; 0.9 s of 3 on the sphere).
constexpr double kBudgetReserve = 4.0;

// Sweeps without fewer invalid elements after which the optimiser gives the mesh to the repair
// rounds (the optimiser alone waits 10).
constexpr int kPipelineStuckWindow = 5;

// Nodes whose elements are all at least this good (and 0.05 above the worst) rest below 1e-2 of
// their element size inside the domain and below 3e-3 on the CAD, rather than 1e-3
// (OptimiserOptions::settledQuality). The inside alone, against no such rule, on twelve cases
// (NekMesh's 3d_sphere at orders 4 and 6, 3d_bl_cyl, T106 and the aerofoil, the sphere in a box
// at sizes 1.2 and 0.8, the bracket, OpenCASCADE's bottle, a long, a thin and a bent cylinder):
// the same verdicts, worst values within 0.006, the largest normal angles within 0.14 degrees,
// 1.03x to 2.1x fewer node visits (the long cylinder 9.6 to 6.7 million). On the CAD too
// (with the energy stop rule waiting while the worst still rises, stop_rules.hpp, without which
// the bottle stopped at 0.170 with its worst still rising): the same verdicts, worst values
// within 0.006 (the bottle 0.192 -> 0.186, the sphere in a box +0.004), the largest normal angles
// within 0.19 degrees (the thin cylinder 0.97 -> 1.16, the bracket 0.78 -> 0.88), and the long
// cylinder 69 -> 44 s, the bottle 61 -> 45 s, the thin and bent ones 1.7x faster. Resting them
// below 1e-2 too took the long cylinder to 39 s but its normal angle 1.05 -> 1.24 degrees and
// the bracket's 0.78 -> 2.15.
constexpr double kPipelineSettledQuality = 0.7;
constexpr double kPipelineSettledSlidingTolerance = 3e-3;

// Layers of neighbours around a repair round's new elements that the optimiser moves too. One
// layer (every element sharing a node) already frees the nodes around a new element. Four made
// regions of 79,000 to 106,000 of Motor-c.brep's 200,000 order-4 elements around some 400
// seeds, so that each round's optimiser ran into its 40 s limit after one or two sweeps and the
// job's 360 s ended after 4 rounds with 39 invalid. With one layer the regions had 400 to 9,400
// elements and took 8 to 60 sweeps; on the 23 corpus files that took over 60 s or were not
// valid (bench/results/corpus.md, 2026-11-25 seventh session) every valid file stayed valid,
// most 5 to 55 % faster, and those not valid kept fewer invalid elements (Motor-c 39 -> 1,
// Bottom 27 -> 2, Top 27 -> 7, MODERN_Sink_1 111 -> 8), except I22_2_5_16 (1 -> 3, all at
// cusps of the CAD).
constexpr int kRepairRegionLayers = 1;
// Poor elements below this certified scaled Jacobian join the region too.
constexpr double kRepairRegionThreshold = 0.2;

// Layers of neighbours around the elements still invalid with the macro layer fixed, whose nodes
// (the layer's included) a second optimiser run may move.
constexpr int kLayerReleaseLayers = 4;

// The prediction again on the linear mesh made (its real element count), before elevation
// allocates the high-order nodes.
void checkHighOrderMemory(const Mesh& linear, int order) {
  checkPredictedMemory(static_cast<double>(linear.numElements()), order, linear.dim,
                       "curving the linear mesh");
}

// Forwards the pipeline's cancel request to the optimiser (checked between colour groups) and
// reports each sweep as progress of `stage`.
class OptimiserProgress : public OptimiserObserver {
 public:
  OptimiserProgress(PipelineObserver* observer, std::string stage, int maxIterations)
      : observer_(observer), stage_(std::move(stage)), maxIterations_(maxIterations) {}
  bool cancelRequested() override { return observer_ != nullptr && observer_->cancelRequested(); }
  void iterationFinished(const IterationRecord& r) override {
    if (observer_ == nullptr) return;
    std::ostringstream detail;
    detail.precision(3);
    detail << stage_ << " sweep " << r.iteration << ": worst scaled Jacobian " << r.worst << ", "
           << r.invalid << " invalid";
    observer_->stageProgress(stage_, static_cast<double>(r.iteration) / maxIterations_,
                             detail.str());
  }

 private:
  PipelineObserver* observer_;
  std::string stage_;
  int maxIterations_;
};

// The nodes of a macro boundary layer's prisms (2D: quadrilaterals and the fans' triangles;
// empty when there are none).
std::vector<char> layerNodes(const Mesh& mesh) {
  std::vector<char> fixed;
  for (const ElementBlock& b : mesh.blocks) {
    if (!isLayerCell(mesh, b)) continue;
    fixed.resize(mesh.numNodes(), 0);
    for (const std::int64_t id : b.nodes) fixed[static_cast<std::size_t>(id)] = 1;
  }
  if (fixed.empty()) return fixed;
  for (const ElementBlock& b : mesh.blocks) {
    const std::vector<char> fan = layerFanTriangles(mesh, b);
    const auto n = static_cast<std::size_t>(b.nodesPerElement());
    for (std::size_t e = 0; e < b.count(); ++e)
      if (fan[e] != 0)
        for (std::size_t i = 0; i < n; ++i) fixed[static_cast<std::size_t>(b.element(e)[i])] = 1;
  }
  return fixed;
}

OptimiserOptions pipelineOptimiserOptions(const MeshingOptions& options) {
  OptimiserOptions o;
  o.maxIterations = options.optimiseIterations;
  o.stall = 1e-3;  // valid and no longer improving: stop early
  // Nodes of good elements rest sooner, unless the facet term is on: it moves the boundary's
  // nodes to spread them, and its small moves (with the inside's that follow them) are that
  // work. The fidelity term, which joins with it once the mesh is valid, lets them rest: on
  // the sphere in a box at sizes 1.2 to 0.6, orders 2 to 6, weight 2, the largest normal angle
  // within 0.8 degrees of the run without resting (1.2, order 5: 1.41 -> 2.23; 6: 0.01 ->
  // 0.48), the worst element within 0.016, and at size 0.6, order 6, 17.0 -> 7.8 s.
  if (options.facetWeight <= 0.0) {
    o.settledQuality = kPipelineSettledQuality;
    o.settledSlidingTolerance = kPipelineSettledSlidingTolerance;
  }
  o.stuckWindow = kPipelineStuckWindow;  // not valid and not improving: repair rounds take over
  o.threads = options.threads;
  o.timeLimit = options.optimiseSeconds;
  o.facetWeight = options.facetWeight;
  o.fidelityWeight = options.fidelityWeight;
  return o;
}

// Sets a run's limit to the smaller of its own and what is left of the job's budget; true when
// the budget's is the smaller.
bool limitByBudget(OptimiserOptions& run, const MeshingOptions& options, const JobBudget& budget) {
  run.timeLimit = budget.stageLimit(options.optimiseSeconds);
  return budget.binds(options.optimiseSeconds);
}

// A later optimiser run's record added to the first's: the final state is the later run's.
void appendRun(OptimiserResult& r, const OptimiserResult& second) {
  r.iterations += second.iterations;
  r.history.insert(r.history.end(), second.history.begin(), second.history.end());
  r.invalidAfter = second.invalidAfter;
  r.undecidedAfter = second.undecidedAfter;
  r.worstAfter = second.worstAfter;
  r.nodalWorstAfter = second.nodalWorstAfter;
  r.energyAfter = second.energyAfter;
  r.stopReason = second.stopReason;
  r.seconds += second.seconds;
  r.sweepSeconds += second.sweepSeconds;
  r.visits += second.visits;
  r.slides += second.slides;
  r.cadEvaluations += second.cadEvaluations;
}

// One call of curve(): its inputs, the state it builds, and what the stages pass on.
struct CurveRun {
  const MeshingOptions& options;
  const CadModel& cad;
  StageTimings& timings;
  PipelineObserver* observer;
  bool clocked;
  JobBudget& budget;
  const std::string& round;
  const CurvedState* previous;
  // Quadrilaterals (2D) and prisms are a macro boundary layer only when one was grown here;
  // otherwise (a mesh given to curveMeshOnCad without recognised stacks) the layer's fixing,
  // blending and wall spacing stay out of it.
  bool layered;
  CurvedState state;
  // At the final order in a repair round: the mesh's quality as the optimiser gets it (measured
  // only on the new elements, the others' taken from `previous`) and its coordinates then, from
  // which the closing check takes the elements the optimiser left alone.
  std::optional<QualitySummary> startQuality;
  std::vector<double> startXyz;
  std::chrono::steady_clock::time_point elevationStart;

  // Starts `stage`'s clock when each stage is timed under its own name.
  void startClock(std::optional<StageClock>& clock, const char* stage) const {
    if (clocked) clock.emplace(stage, timings, observer);
  }
};

// The job's budget keeps back, for the quality check and the output that follow an optimiser
// run whatever is left, kBudgetReserve times the elevation just timed. `scale`: how much more
// the final order's stages cost than the order just elevated to (continuation elevates to
// kContinuationOrder first).
void reserveAfterElevation(CurveRun& run, double scale) {
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run.elevationStart).count();
  run.budget.reserve(std::max(run.budget.reserved(), kBudgetReserve * scale * seconds));
}

// For `mesh`, just elevated to `order`: takes the curved nodes of unchanged cells from `before`
// (previous's mesh of that order) and returns the optimiser's region seed (the new cells; empty
// for the whole mesh). At the final order it measures the start quality (run.startQuality).
std::vector<char> reusePrevious(CurveRun& run, int order, Mesh& mesh, const Mesh& before) {
  CurvedReuse reuse = reuseCurvedNodes(run.previous->linear, before, run.state.linear, mesh);
  const bool final = order == run.options.order;
  if (final) run.state.reused = reuse.reused;
  if (reuse.reused == 0) return {};
  if (final) {
    const KnownQuality known{&before, nullptr, &run.previous->quality, std::move(reuse.source)};
    run.startQuality = evaluateQuality(mesh, run.options.threads, &known);
    run.startXyz = mesh.xyz;
  }
  return std::move(reuse.fresh);
}

// The macro layer keeps the shape its growth and blend gave it while the rest adapts; where
// elements stay invalid after `o`'s run (`r`), it is released in steps, each only if elements
// are still not valid: the layer's top slides parallel to the wall (its heights stay) with its
// nodes on the CAD (the layer's sides) fixed, then with those sliding on their faces too, then
// the top moves freely; its inner nodes are blended again after each. Returns whether the
// budget stopped a step or left steps out.
bool releaseLayer(CurveRun& run, Mesh& mesh, const OptimiserOptions& o, OptimiserResult& r,
                  OptimiserProgress& cancel) {
  bool cut = false;
  for (const LayerRelease step :
       {LayerRelease::Parallel, LayerRelease::Sides, LayerRelease::Free}) {
    if (o.fixedNodes.empty() || r.invalidAfter + r.undecidedAfter == 0) break;
    if (run.budget.spent()) return true;  // the layer's release steps left out
    OptimiserOptions around = o;
    const bool aroundCapped = limitByBudget(around, run.options, run.budget);
    around.fixedNodes.clear();
    if (step != LayerRelease::Free) around.normalLocked = layerTopNormals(mesh);
    if (step == LayerRelease::Parallel) {
      around.fixedNodes.assign(mesh.numNodes(), 0);
      for (std::size_t i = 0; i < mesh.numNodes(); ++i)
        if (std::isfinite(around.normalLocked[3 * i]) && mesh.nodeCadDim[i] < mesh.dim)
          around.fixedNodes[i] = 1;
    }
    around.regionSeed.assign(mesh.numElements(), 0);  // the elements not valid ...
    around.regionLayers = kLayerReleaseLayers;        // ... and their neighbours
    const OptimiserResult second = optimiseMesh(mesh, around, &cancel, &run.cad);
    if (second.cancelled) throw CancelledError("cancelled during optimise");
    cut = cut || (aroundCapped && second.stopReason == "time budget");
    blendLayerInteriors(mesh, &run.cad, false);
    appendRun(r, second);
    run.state.layerRelease = std::max(run.state.layerRelease, step);
  }
  return cut;
}

// The optimiser on `mesh`, just elevated to `order` (after the reuse of `before`'s curved nodes
// in a repair round), timed as `stage`; nothing when the optimiser is off, and left out (the mesh
// stays as curving left it) once the job's budget is spent.
std::optional<OptimiserResult> optimiseAt(CurveRun& run, int order, Mesh& mesh, const Mesh* before,
                                          const char* stage) {
  std::vector<char> fresh;  // the optimiser's region seed: empty for the whole mesh
  if (before != nullptr) fresh = reusePrevious(run, order, mesh, *before);
  const MeshingOptions& options = run.options;
  if (options.optimiseIterations <= 0) return std::nullopt;
  const std::string where = run.round.empty() ? std::string(stage) : run.round + " " + stage;
  if (run.budget.spent()) {
    run.budget.skip(where);
    return std::nullopt;
  }
  std::optional<StageClock> clock;
  run.startClock(clock, stage);
  OptimiserOptions o = pipelineOptimiserOptions(options);
  // Each run under the smaller of its own limit and what is left of the job's budget.
  const bool capped = limitByBudget(o, options, run.budget);
  if (!fresh.empty()) {
    o.regionSeed = std::move(fresh);
    o.regionLayers = kRepairRegionLayers;
    o.regionThreshold = kRepairRegionThreshold;
  }
  // The macro layer keeps the shape its growth and blend gave it (its split then has the
  // heights asked for) while the rest adapts; only where elements stay invalid is it released.
  if (run.layered) o.fixedNodes = layerNodes(mesh);
  OptimiserProgress cancel(run.observer, stage, o.maxIterations);
  const QualitySummary* start =
      order == options.order && run.startQuality ? &*run.startQuality : nullptr;
  std::optional<OptimiserResult> r = optimiseMesh(mesh, o, &cancel, &run.cad, start);
  if (r->cancelled) throw CancelledError("cancelled during optimise");
  bool cut = capped && r->stopReason == "time budget";
  cut = releaseLayer(run, mesh, o, *r, cancel) || cut;
  if (cut) run.budget.cut(where);
  if (clock) clock->done();
  return r;
}

// The layer's columns at sharp edges and corners (blendLayerInteriors), if any.
const std::set<std::int64_t>* sharpColumns(const CurveRun& run) {
  return run.state.layer ? &run.state.layer->sharpColumns : nullptr;
}

// Above kContinuationOrder with the optimiser: elevation to that order ("high_order"), the
// optimiser there ("optimise_low_order"), then the raise to the final order ("raise_order").
void elevateThroughContinuation(CurveRun& run) {
  const MeshingOptions& options = run.options;
  CurvedState& state = run.state;
  std::optional<StageClock> clock;
  run.startClock(clock, "high_order");
  run.elevationStart = std::chrono::steady_clock::now();
  state.lowOrder = elevateOrder(state.linear, kContinuationOrder, &run.cad, nullptr, run.layered);
  if (run.layered) blendLayerInteriors(state.lowOrder, &run.cad, true, sharpColumns(run));
  // Until the final order is made: scaled by the nodes per simplex of the two orders.
  const CellType simplex = state.linear.dim == 3 ? CellType::Tetrahedron : CellType::Triangle;
  reserveAfterElevation(run, static_cast<double>(cellNumNodes(simplex, options.order)) /
                                 cellNumNodes(simplex, kContinuationOrder));
  if (clock) clock->done();
  const CurvedState* previous = run.previous;
  state.lowOrderOptimiser = optimiseAt(
      run, kContinuationOrder, state.lowOrder,
      previous != nullptr && previous->lowOrder.numNodes() > 0 ? &previous->lowOrder : nullptr,
      "optimise_low_order");
  run.startClock(clock, "raise_order");
  run.elevationStart = std::chrono::steady_clock::now();
  state.mesh = changeOrder(state.lowOrder, options.order, &run.cad, nullptr, run.layered);
  // The raised wall lies on the CAD at the full order while the layer's top is the low
  // order's, raised: around a coarse wall (the NACA's nose, T106's edges) the heights follow
  // the low order's wall (57 % off at the NACA's nose at order 6). In 2D the top is placed
  // parallel to the raised wall again (0.04 % there), unless the low order had to let the top
  // move freely (placing it back would undo that); in 3D that forced the cylinder's layer
  // free at three times the time, so 3D keeps the raised top but places the nodes between
  // wall and top again, straight between the raised wall and the top (raised, the low
  // order's optimised positions bend the columns, and the split's levels assume straight
  // ones): the cylinder's first layer 47 % -> 16 % off at order 6, 63 % -> 16 % at order 8,
  // and its worst element 0.23 -> 0.35 and 0.09 -> 0.33, for the same time. (The 16 % left
  // was the top's edges on the end faces, which the raise placed afresh, straight; it keeps
  // their shape now, and the first layer is within 0.01 %.)
  if (run.layered && state.layerRelease != LayerRelease::Free)
    blendLayerInteriors(state.mesh, &run.cad, /*tops=*/state.mesh.dim == 2, sharpColumns(run));
  reserveAfterElevation(run, 1.0);
  if (clock) clock->done();
}

// Elevation straight to the final order ("high_order").
void elevateDirectly(CurveRun& run) {
  std::optional<StageClock> clock;
  run.startClock(clock, "high_order");
  run.elevationStart = std::chrono::steady_clock::now();
  run.state.mesh =
      elevateOrder(run.state.linear, run.options.order, &run.cad, nullptr, run.layered);
  if (run.layered) blendLayerInteriors(run.state.mesh, &run.cad, true, sharpColumns(run));
  reserveAfterElevation(run, 1.0);
  if (clock) clock->done();
}

// The certified quality of the curved mesh ("quality"); in a repair round only the elements
// whose nodes changed since the optimiser's start are measured again.
void evaluateCurved(CurveRun& run) {
  std::optional<StageClock> clock;
  run.startClock(clock, "quality");
  CurvedState& state = run.state;
  if (run.startQuality) {
    const KnownQuality known{&state.mesh, &run.startXyz, &*run.startQuality, {}};
    state.quality = evaluateQuality(state.mesh, run.options.threads, &known);
  } else {
    state.quality = evaluateQuality(state.mesh, run.options.threads);
  }
  if (clock) clock->done();
}

}  // namespace

CurvedState curve(Mesh linear, const MeshingOptions& options, const CadModel& cad,
                  StageTimings& timings, PipelineObserver* observer, bool clocked,
                  JobBudget& budget, const std::string& round, const CurvedState* previous,
                  bool givenLayer, std::optional<BoundaryLayerRecord> layer) {
  CurveRun run{options,  cad,      timings,
               observer, clocked,  budget,
               round,    previous, options.boundaryLayer.has_value() || givenLayer,
               {},       {},       {},
               {}};
  run.state.linear = std::move(linear);
  run.state.layer = std::move(layer);
  checkHighOrderMemory(run.state.linear, options.order);
  if (options.optimiseIterations > 0 && options.order > kContinuationOrder)
    elevateThroughContinuation(run);
  else
    elevateDirectly(run);
  run.state.optimiser = optimiseAt(run, options.order, run.state.mesh,
                                   previous != nullptr ? &previous->mesh : nullptr, "optimise");
  evaluateCurved(run);
  return std::move(run.state);
}

}  // namespace homesh
