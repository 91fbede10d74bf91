#include "pipeline/mesh_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "boundary_layer/layer_blend.hpp"
#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_normals.hpp"
#include "cad/face_cusps.hpp"
#include "cad/model_dimension.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/isolated_call.hpp"
#include "core/job_budget.hpp"
#include "core/parameters.hpp"
#include "core/system_memory.hpp"
#include "curving/order_elevation.hpp"
#include "linear/cad_classification.hpp"
#include "linear/cavity_remesh.hpp"
#include "linear/linear_mesher.hpp"
#include "linear/tet_flips.hpp"
#include "pipeline/curved_reuse.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/report.hpp"
#include "sizing/octree_export.hpp"

namespace homesh {

double defaultMeshSize(const CadModel& cad) {
  return cad.boundingDiagonal() / 20.0;
}

CadModel CadSource::load() const {
  switch (kind) {
    case Kind::File: {
      CadModel cad = CadModel::fromFile(value);
      return scale == 1.0 ? std::move(cad) : cad.scaled(scale);
    }
    case Kind::BrepText:
      return CadModel::fromBrepText(value, name);
    case Kind::Naca:
      break;
  }
  return makeNacaDomain(naca);
}

SizingParameters defaultSizing(const CadModel& cad) {
  SizingParameters p;
  p.maxDelta = defaultMeshSize(cad);
  p.minDelta = p.maxDelta / 20.0;  // eps: the table's default (SizingParameters)
  return p;
}

SizingParameters completeSizing(SizingParameters p, const CadModel& cad) {
  if (p.maxDelta == 0.0) p.maxDelta = std::max(defaultMeshSize(cad), p.minDelta);
  if (p.minDelta == 0.0) p.minDelta = p.maxDelta / 20.0;
  return p;
}

SizingParameters resolveSizing(const std::optional<SizingParameters>& requested,
                               const CadModel& cad) {
  return completeSizing(requested.value_or(defaultSizing(cad)), cad);
}

namespace {

// Healing numbers a changed model's faces and edges afresh: a boundary layer's faces or a
// refinement along a CAD curve, given in the original numbering, could land elsewhere.
void checkRenumbering(const HealingRecord& healing, const MeshingOptions& options) {
  if (!healing.renumbered) return;
  std::string what;
  if (options.boundaryLayer) what = "the boundary layer";
  if (options.sizing)
    for (const RefinementSource& s : options.sizing->sources)
      if (s.kind == RefinementSource::Kind::Curve)
        what = "a refinement along CAD curve " + std::to_string(s.edge);
  if (what.empty()) return;
  if (healing.actions.empty())  // renumbered by leaving faces out alone
    throw ParameterError(
        "leaving out the faces in no solid (--solids-only, or --auto's choice of it) numbered "
        "the CAD's faces and edges afresh, and " +
        what +
        " is given in the original numbering: make a solid of those faces, or "
        "remove them, in the CAD file");
  throw ParameterError("healing changed the CAD (" + healing.actions.front() +
                       ") and the numbering of its faces and edges, and " + what +
                       " is given in the original numbering: repair the CAD file, or mesh "
                       "without healing (--no-heal, heal=False, Heal off)");
}

}  // namespace

SizingResult runSizingStage(const CadSource& source, const MeshingOptions& options) {
  options.healing().validate();  // before the (possibly slow) CAD import
  HealingRecord healing;
  const CadModel cad = healModel(source.load(), options.healing(), healing);
  checkRenumbering(healing, options);
  checkMeshDimension(cad, options.expectedDimension);
  SizingResult result = runSizing(cad, resolveSizing(options.sizing, cad), options.threads);
  result.healing = std::move(healing);
  if (!options.octreeOutput.empty()) writeOctree(*result.octree, options.octreeOutput);
  return result;
}

void checkMeshDimension(const CadModel& cad, std::optional<int> expected) {
  if (!expected) return;
  Eigen::Vector3d normal;
  const int dim = modelMeshDimension(cad, normal);
  if (dim != *expected)
    throw ParameterError("MeshType asks for a " + std::to_string(*expected) + "D mesh but " +
                         cad.sourceName() +
                         (dim == 3              ? " has solids (a 3D mesh)"
                          : isSurfaceModel(cad) ? " is faces without a solid (a surface mesh)"
                                                : " is planar faces (a 2D mesh)"));
}

SizingResult runSizing(const CadModel& cad, const SizingParameters& params, int threads) {
  const auto start = std::chrono::steady_clock::now();
  SizingResult r;
  r.octree = std::make_shared<const SizingOctree>(SizingOctree::build(cad, params, threads));
  r.prediction = predictElementCount(*r.octree, threads);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (r.prediction.elements > kMaxPredictedElements) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "the sizes (MinDelta " << params.minDelta << ", MaxDelta " << params.maxDelta << ", EPS "
        << params.eps << ") would make about " << r.prediction.elements << " elements for "
        << cad.sourceName() << ": too many (at most " << kMaxPredictedElements
        << "); use larger MinDelta, MaxDelta or EPS";
    throw ParameterError(msg.str());
  }
  return r;
}

double predictedMemoryBytes(double elements, int order, int dim) {
  const double p = order;
  const double nodesPerElement =
      dim == 3 ? (p + 1) * (p + 2) * (p + 3) / 6.0 : (p + 1) * (p + 2) / 2.0;
  return 50e6 + elements * nodesPerElement * 160.0;
}

void checkPredictedMemory(double elements, int order, int dim, const std::string& what) {
  const double need = predictedMemoryBytes(elements, order, dim);
  const auto have = static_cast<double>(availableMemoryBytes());
  if (have > 0.0 && need > have) {
    std::ostringstream msg;
    msg.precision(3);
    msg << what << " at order " << order << " (about " << elements
        << " elements) is predicted to need " << need / 1e9 << " GB of memory; the machine has "
        << have / 1e9 << " GB available: use larger sizes or a lower order";
    throw ParameterError(msg.str());
  }
}

void StageTimings::add(const std::string& stage, double s) {
  seconds.emplace_back(stage, s);
}

double StageTimings::total() const {
  double t = 0.0;
  for (const auto& [stage, s] : seconds) t += s;
  return t;
}

namespace {

class StageClock {
 public:
  StageClock(const std::string& stage, StageTimings& timings, PipelineObserver* observer)
      : stage_(stage), timings_(timings), observer_(observer) {
    if (observer_ != nullptr) {
      if (observer_->cancelRequested()) throw CancelledError("cancelled before " + stage);
      observer_->stageStarted(stage);
    }
    start_ = std::chrono::steady_clock::now();
  }
  void done() {
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    timings_.add(stage_, s);
    if (observer_ != nullptr) {
      observer_->stageFinished(stage_, s);
      if (observer_->cancelRequested()) throw CancelledError("cancelled after " + stage_);
    }
  }

 private:
  std::string stage_;
  StageTimings& timings_;
  PipelineObserver* observer_;
  std::chrono::steady_clock::time_point start_;
};

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

// Reports the linear mesher's Gmsh run done (before the mesh is read back and oriented) and
// stops there when asked.
std::function<void(int, int)> linearProgress(PipelineObserver* observer) {
  if (observer == nullptr) return {};
  return [observer](int dim, int of) {
    observer->stageProgress("linear", static_cast<double>(dim) / of,
                            dim == 3 ? "volumes meshed by Gmsh" : "surfaces meshed by Gmsh");
    if (observer->cancelRequested()) throw CancelledError("cancelled during the linear mesh");
  };
}

}  // namespace

namespace {

// A curved mesh and what the stages after the linear mesh found.
struct CurvedState {
  Mesh linear;
  Mesh mesh;
  QualitySummary quality;
  std::optional<OptimiserResult> optimiser;
  std::size_t reused = 0;  // elements that took their curved nodes from the round before
  std::optional<BoundaryLayerRecord> layer;  // how the linear mesh's macro layer was grown
  // How far the optimiser moved the macro layer around elements it could not make valid
  // otherwise (at the final order or, with continuation, at the low order).
  LayerRelease layerRelease = LayerRelease::None;
  // Above kContinuationOrder with the optimiser: the mesh of that order, optimised, that the
  // final order started from (empty otherwise).
  Mesh lowOrder;
  std::optional<OptimiserResult> lowOrderOptimiser;

  std::size_t notValid() const { return quality.invalid + quality.undecided; }
  bool betterThan(const CurvedState& other) const {
    if (notValid() != other.notValid()) return notValid() < other.notValid();
    return quality.scaled.min > other.quality.scaled.min;
  }
};

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

// Once every element is proven valid, repair rounds go on for elements whose certified scaled
// Jacobian is below this: slivers lying flat on a curved face and chords of one curved face, the
// same configurations as the invalid ones, milder. Those rounds only act locally (split, then
// flip, then remesh their cavities, each tried once on the best mesh; a refinement remeshes the
// whole model and brings new offenders elsewhere) and are kept only when the worst element
// improves with every element still valid. (OpenCASCADE's linkrods.step: 3 elements at 0.043 to
// 0.086, all four vertices on one cylinder.)
constexpr double kPoorElement = 0.1;

// The cells a repair round works on: those not proven valid or, with `poor` (none of those), the
// ones whose certified scaled Jacobian is below kPoorElement, marked Invalid.
std::vector<Validity> repairTargets(const QualitySummary& quality, bool poor) {
  if (!poor) return quality.validity;
  std::vector<Validity> flagged(quality.validity.size(), Validity::Valid);
  for (std::size_t e = 0; e < flagged.size(); ++e)
    if (quality.scaledJacobian[e] < kPoorElement) flagged[e] = Validity::Invalid;
  return flagged;
}

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

// Splits of the boundary layer after the first that set more columns plain (each around the
// thin cells the one before left invalid or poor).
constexpr int kPlainSplitAttempts = 3;

// Layers of neighbours around the elements still invalid with the macro layer fixed, whose nodes
// (the layer's included) a second optimiser run may move.
constexpr int kLayerReleaseLayers = 4;

// How to set a parameter: "--job-time-limit, Python job_seconds, FreeCAD JobTimeLimit".
std::string settingsOf(const char* key) {
  const ParameterDefinition& p = parameterDefinition(key);
  return std::string(p.option) + ", Python " + p.key + ", FreeCAD " + p.property;
}

// How messages name a time-limit parameter: "linear meshing time limit: --linear-time-limit,
// Python linear_seconds, FreeCAD LinearTimeLimit".
std::string limitName(const char* key) {
  return std::string(parameterDefinition(key).label) + ": " + settingsOf(key);
}

// "repair rounds (--repair-rounds, Python repair_rounds, FreeCAD RepairRounds)".
std::string parameterText(const char* key) {
  return std::string(parameterDefinition(key).label) + " (" + settingsOf(key) + ")";
}

// Seconds in messages: three digits are enough ("3.19 s").
std::string formatSeconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", s);
  return buf;
}

// "job time limit of 120 s", then how to set it: "--job-time-limit, Python job_seconds, FreeCAD
// JobTimeLimit".
std::string jobLimitName(const JobBudget& budget) {
  return std::string(parameterDefinition("job_seconds").label) + " of " +
         formatNumber(budget.seconds()) + " s";
}
std::string jobLimitSettings() {
  return settingsOf("job_seconds");
}

// "the job time limit of 120 s (--job-time-limit, Python job_seconds, FreeCAD JobTimeLimit)".
std::string jobLimitText(const JobBudget& budget) {
  return "the " + jobLimitName(budget) + " (" + jobLimitSettings() + ")";
}

// Before a stage that makes the first mesh: with the budget spent there is no mesh to keep, so
// the job fails naming the stage it did not reach and where the time went.
void checkBudgetLeft(const JobBudget& budget, const std::string& stage,
                     const StageTimings& timings) {
  if (!budget.spent()) return;
  std::string spent;
  for (const auto& [name, s] : timings.seconds)
    spent += (spent.empty() ? "" : ", ") + name + " " + formatSeconds(s) + " s";
  throw BudgetExceeded(jobLimitText(budget) + " was spent before the " + stage + " stage (" +
                       spent + "): no mesh was made");
}

OptimiserOptions pipelineOptimiserOptions(const MeshingOptions& options) {
  OptimiserOptions o;
  o.maxIterations = options.optimiseIterations;
  o.stall = 1e-3;                        // valid and no longer improving: stop early
  o.stuckWindow = kPipelineStuckWindow;  // not valid and not improving: repair rounds take over
  o.threads = options.threads;
  o.timeLimit = options.optimiseSeconds;
  o.facetWeight = options.facetWeight;
  return o;
}

// Elevation, optimiser and quality of a linear mesh. With `clocked`, each stage is timed
// under its own name; a repair round times them all as one stage instead. With `previous` (a
// repair round's starting state), the elements whose linear cell is unchanged take their
// curved nodes from it and the optimiser works only on the new elements, the ones not proven
// valid or poor, and kRepairRegionLayers layers around them. Each optimiser run gets at most
// what is left of `budget` and is left out once it is spent (named with `round`, "repair 2",
// in the budget's record; "" before the rounds).
CurvedState curve(Mesh linear, const MeshingOptions& options, const CadModel& cad,
                  StageTimings& timings, PipelineObserver* observer, bool clocked,
                  JobBudget& budget, const std::string& round,
                  const CurvedState* previous = nullptr) {
  CurvedState state;
  state.linear = std::move(linear);
  // Quadrilaterals (2D) and prisms are a macro boundary layer only when one was grown here;
  // otherwise (a mesh given to curveMeshOnCad, tetrahedra only today) the layer's fixing,
  // blending and wall spacing stay out of it.
  const bool layered = options.boundaryLayer.has_value();
  checkHighOrderMemory(state.linear, options.order);
  // For `mesh`, just elevated to `order`: takes the curved nodes of unchanged cells from
  // `before` (previous's mesh of that order, if any) and optimises the whole mesh, or only
  // around what changed.
  // At the final order in a repair round: the mesh's quality as the optimiser gets it (measured
  // only on the new elements, the others' taken from `previous`) and its coordinates then, from
  // which the closing check takes the elements the optimiser left alone.
  std::optional<QualitySummary> startQuality;
  std::vector<double> startXyz;
  const auto curveAt = [&](int order, Mesh& mesh, const Mesh* before, const char* stage) {
    std::vector<char> fresh;  // the optimiser's region seed: empty for the whole mesh
    if (before != nullptr) {
      CurvedReuse reuse = reuseCurvedNodes(previous->linear, *before, state.linear, mesh);
      if (order == options.order) state.reused = reuse.reused;
      if (reuse.reused > 0) {
        fresh = std::move(reuse.fresh);
        if (order == options.order) {
          const KnownQuality known{before, nullptr, &previous->quality, std::move(reuse.source)};
          startQuality = evaluateQuality(mesh, options.threads, &known);
          startXyz = mesh.xyz;
        }
      }
    }
    if (options.optimiseIterations <= 0) return std::optional<OptimiserResult>();
    const std::string where = round.empty() ? std::string(stage) : round + " " + stage;
    if (budget.spent()) {  // the mesh stays as curving left it
      budget.skip(where);
      return std::optional<OptimiserResult>();
    }
    std::optional<StageClock> clock;
    if (clocked) clock.emplace(stage, timings, observer);
    OptimiserOptions o = pipelineOptimiserOptions(options);
    // Each run under the smaller of its own limit and what is left of the job's budget.
    bool cut = false;
    const auto limit = [&](OptimiserOptions& run) {
      run.timeLimit = budget.stageLimit(options.optimiseSeconds);
      return budget.binds(options.optimiseSeconds);
    };
    const bool capped = limit(o);
    if (!fresh.empty()) {
      o.regionSeed = std::move(fresh);
      o.regionLayers = kRepairRegionLayers;
      o.regionThreshold = kRepairRegionThreshold;
    }
    // The macro layer keeps the shape its growth and blend gave it (its split then has the
    // heights asked for) while the rest adapts; only where elements stay invalid is it
    // released, around them, and its inner nodes blended again afterwards.
    if (layered) o.fixedNodes = layerNodes(mesh);
    OptimiserProgress cancel(observer, stage, o.maxIterations);
    std::optional<OptimiserResult> r = optimiseMesh(
        mesh, o, &cancel, &cad, order == options.order && startQuality ? &*startQuality : nullptr);
    if (r->cancelled) throw CancelledError("cancelled during optimise");
    cut = capped && r->stopReason == "time budget";
    // Released in steps, each only if elements are still not valid: the layer's top slides
    // parallel to the wall (its heights stay) with its nodes on the CAD (the layer's sides)
    // fixed, then with those sliding on their faces too, then the top moves freely.
    for (const LayerRelease step :
         {LayerRelease::Parallel, LayerRelease::Sides, LayerRelease::Free}) {
      if (o.fixedNodes.empty() || r->invalidAfter + r->undecidedAfter == 0) break;
      if (budget.spent()) {
        cut = true;  // the layer's release steps left out
        break;
      }
      OptimiserOptions around = o;
      const bool aroundCapped = limit(around);
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
      const OptimiserResult second = optimiseMesh(mesh, around, &cancel, &cad);
      if (second.cancelled) throw CancelledError("cancelled during optimise");
      cut = cut || (aroundCapped && second.stopReason == "time budget");
      blendLayerInteriors(mesh, &cad, false);
      r->iterations += second.iterations;
      r->history.insert(r->history.end(), second.history.begin(), second.history.end());
      r->invalidAfter = second.invalidAfter;
      r->undecidedAfter = second.undecidedAfter;
      r->worstAfter = second.worstAfter;
      r->nodalWorstAfter = second.nodalWorstAfter;
      r->energyAfter = second.energyAfter;
      r->stopReason = second.stopReason;
      r->seconds += second.seconds;
      r->sweepSeconds += second.sweepSeconds;
      r->visits += second.visits;
      r->slides += second.slides;
      r->cadEvaluations += second.cadEvaluations;
      state.layerRelease = std::max(state.layerRelease, step);
    }
    if (cut) budget.cut(where);
    if (clocked) clock->done();
    return r;
  };

  // The job's budget keeps back, for the quality check and the output that follow an optimiser
  // run whatever is left, kBudgetReserve times the elevation just timed.
  std::chrono::steady_clock::time_point elevationStart;
  const auto startElevation = [&] { elevationStart = std::chrono::steady_clock::now(); };
  // `scale`: how much more the final order's stages cost than the order just elevated to
  // (continuation elevates to kContinuationOrder first).
  const auto reserveAfterElevation = [&](double scale) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - elevationStart).count();
    budget.reserve(std::max(budget.reserved(), kBudgetReserve * scale * seconds));
  };
  std::optional<StageClock> clock;
  if (options.optimiseIterations > 0 && options.order > kContinuationOrder) {
    if (clocked) clock.emplace("high_order", timings, observer);
    startElevation();
    state.lowOrder = elevateOrder(state.linear, kContinuationOrder, &cad, nullptr, layered);
    if (layered) blendLayerInteriors(state.lowOrder, &cad);
    // Until the final order is made: scaled by the nodes per simplex of the two orders.
    const CellType simplex = state.linear.dim == 3 ? CellType::Tetrahedron : CellType::Triangle;
    reserveAfterElevation(static_cast<double>(cellNumNodes(simplex, options.order)) /
                          cellNumNodes(simplex, kContinuationOrder));
    if (clocked) clock->done();
    state.lowOrderOptimiser = curveAt(
        kContinuationOrder, state.lowOrder,
        previous != nullptr && previous->lowOrder.numNodes() > 0 ? &previous->lowOrder : nullptr,
        "optimise_low_order");
    if (clocked) clock.emplace("raise_order", timings, observer);
    startElevation();
    state.mesh = changeOrder(state.lowOrder, options.order, &cad, nullptr, layered);
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
    if (layered && state.layerRelease != LayerRelease::Free)
      blendLayerInteriors(state.mesh, &cad, /*tops=*/state.mesh.dim == 2);
    reserveAfterElevation(1.0);
  } else {
    if (clocked) clock.emplace("high_order", timings, observer);
    startElevation();
    state.mesh = elevateOrder(state.linear, options.order, &cad, nullptr, layered);
    if (layered) blendLayerInteriors(state.mesh, &cad);
    reserveAfterElevation(1.0);
  }
  if (clocked) clock->done();
  state.optimiser = curveAt(options.order, state.mesh,
                            previous != nullptr ? &previous->mesh : nullptr, "optimise");

  if (clocked) clock.emplace("quality", timings, observer);
  if (startQuality) {
    const KnownQuality known{&state.mesh, &startXyz, &*startQuality, {}};
    state.quality = evaluateQuality(state.mesh, options.threads, &known);
  } else {
    state.quality = evaluateQuality(state.mesh, options.threads);
  }
  if (clocked) clock->done();
  return state;
}

// The cusps of the CAD, none where OCCT fails a query on the way (they only explain).
std::vector<FaceCusp> cadCusps(const CadModel& cad) {
  try {
    return findFaceCusps(cad);
  } catch (const CadError&) {
    return {};
  }
}

// The cusps of the CAD at which elements not proven valid have a corner, and how many such
// elements (elementsAtCusps): the CAD, not the mesher, keeps those from being proven valid.
// Empty when there are none.
std::string cuspText(const MeshResult& result) {
  if (!result.cad) return {};
  const std::vector<FaceCusp> cusps = cadCusps(*result.cad);
  const CuspElements at = elementsAtCusps(result.mesh, result.quality, cusps);
  if (at.elements.empty()) return {};
  const std::size_t n = at.elements.size();
  const std::size_t all = result.quality.invalid + result.quality.undecided;
  // "it has" for the one element, "all 8 have" for every one, "3 of them have" for some.
  std::string text =
      n == all ? (n == 1 ? std::string("; it has") : "; all " + std::to_string(n) + " have")
               : "; " + std::to_string(n) + " of them " + (n == 1 ? "has" : "have");
  text +=
      " a corner at a cusp of the CAD, where two edges of a face leave a vertex in the same "
      "direction (";
  int listed = 0;
  for (std::size_t c = 0; c < cusps.size(); ++c) {
    if (at.perCusp[c] == 0) continue;
    if (listed == 3) {
      text += ", ...";
      break;
    }
    const FaceCusp& cusp = cusps[c];
    text += std::string(listed++ == 0 ? "" : ", ") + "Face" + std::to_string(cusp.face) +
            " at Vertex" + std::to_string(cusp.vertex) + " between Edge" +
            std::to_string(cusp.edgeA) + " and Edge" + std::to_string(cusp.edgeB);
  }
  // (A Jacobian positive there rests on the edges' polynomials missing the CAD's tangents on
  // the right side: FreeCAD's I22 inductors end valid with some builds and not with others.)
  return text +
         "): a mesh that follows the CAD has a zero Jacobian there, and such an element is proven "
         "valid only where its polynomial edges miss the CAD's tangents on the right side";
}

// The closing note of a mesh with elements not proven valid: how many, where on the CAD, and
// what was tried on them (the optimiser, the repair rounds and their actions), so that a one-line
// message names the stage that gave up and the entity. `linearGiven`: the caller gave the linear
// mesh (no repair rounds can remesh it).
std::string notValidNote(const MeshResult& result, bool linearGiven) {
  const QualitySummary& q = result.quality;
  const std::size_t count = q.invalid + q.undecided;
  std::string text = std::to_string(count) + (count == 1 ? " element" : " elements") +
                     " not proven valid (" + std::to_string(q.invalid) + " invalid, " +
                     std::to_string(q.undecided) + " undecided)";
  const std::string where = notValidLocation(result.mesh, q);
  if (!where.empty()) text += " " + where;
  text += cuspText(result);
  if (result.mesh.isSurface())
    text += "; a surface mesh (no optimiser: its nodes are where curving put them on the faces)";
  else
    text += result.options.optimiseIterations == 0
                ? std::string(
                      "; the optimiser did not run (--optimise, Python optimise > 0, "
                      "FreeCAD OptimiserIterations > 0 may make them valid)")
                : std::string("; after the optimiser");
  if (linearGiven) return text + "; no repair rounds (the linear mesh was given)";
  if (result.rounds.empty())
    return text + (result.options.repairRounds == 0
                       ? "; no repair rounds (" + parameterText("repair_rounds") + " 0)"
                       : std::string("; no repair round ran"));
  text += "; " + std::to_string(result.rounds.size()) + " repair round" +
          (result.rounds.size() == 1 ? "" : "s") + " (";
  for (std::size_t k = 0; k < result.rounds.size(); ++k) {
    const RepairRound& r = result.rounds[k];
    text += (k == 0 ? "" : ", ") + r.action +
            (!r.failure.empty() ? " failed"
             : r.kept           ? ""
                                : " not kept");
  }
  text += ")";
  if (static_cast<int>(result.rounds.size()) == result.options.repairRounds)
    text += ", all that " + parameterText("repair_rounds") + " allows";
  return text;
}

// The geometry stage (left out once the job's budget is spent: it only measures), then the
// job's record.
void finishJob(MeshResult& result, JobBudget& budget, PipelineObserver* observer,
               bool linearGiven) {
  if (result.quality.invalid + result.quality.undecided > 0)
    result.notes.push_back(notValidNote(result, linearGiven));
  if (budget.spent()) {
    budget.skip("geometry");
    result.notes.push_back("the boundary's distance to the CAD was not measured: " +
                           jobLimitText(budget) + " was spent (stopped: time budget)");
  } else {
    StageClock geometry("geometry", result.timings, observer);
    result.geometry = measureGeometryAccuracy(result.mesh, *result.cad, result.options.threads);
    geometry.done();
  }
  result.job.timeLimit = budget.seconds();
  result.job.seconds = budget.elapsed();
  result.job.reserved = budget.limited() ? budget.reserved() : 0.0;
  result.job.cut = budget.cutStages();
  result.job.skipped = budget.skippedStages();
}

}  // namespace

MeshResult runMeshPipeline(const CadSource& source, MeshingOptions options,
                           PipelineObserver* observer) {
  options.validate();  // before the (possibly slow) CAD import

  MeshResult result;
  JobBudget budget(options.jobSeconds);  // its clock starts here
  StageClock cad("cad", result.timings, observer);
  result.cad =
      std::make_shared<const CadModel>(healModel(source.load(), options.healing(), result.healing));
  cad.done();
  for (const std::string& note : result.healing.notes()) result.notes.push_back(note);
  if (options.boundaryLayer && isSurfaceModel(*result.cad))  // (automatic mode's choice)
    throw ParameterError("a boundary layer needs a volume or planar mesh, and " +
                         result.cad->sourceName() +
                         " has no solid: automatic mode (--auto) gives it a surface mesh");
  checkRenumbering(result.healing, options);
  checkMeshDimension(*result.cad, options.expectedDimension);
  if (!options.size) options.sizing = resolveSizing(options.sizing, *result.cad);
  if (isSurfaceModel(*result.cad) && options.optimiseIterations > 0) {
    options.optimiseIterations = 0;
    result.notes.emplace_back(
        "the optimiser does not run on a surface mesh: every node lies on the CAD, where "
        "curving placed it");
  }
  result.options = options;

  Eigen::Vector3d normal;  // (the plane of a 2D model)
  LinearMeshOptions linearOptions;
  linearOptions.verbosity = options.verbosity;
  linearOptions.dimensionDone = linearProgress(observer);
  if (observer != nullptr)
    linearOptions.cancelRequested = [observer] { return observer->cancelRequested(); };
  linearOptions.note = [&result](const std::string& note) { result.notes.push_back(note); };
  if (options.sizing) {
    checkBudgetLeft(budget, "sizing", result.timings);
    StageClock sizing("sizing", result.timings, observer);
    result.sizing = runSizing(*result.cad, *options.sizing, options.threads);
    if (!options.octreeOutput.empty()) writeOctree(*result.sizing->octree, options.octreeOutput);
    sizing.done();
    checkPredictedMemory(result.sizing->prediction.elements, options.order,
                         modelMeshDimension(*result.cad, normal),
                         "meshing " + result.cad->sourceName());
    const SizingOctree& octree = *result.sizing->octree;
    linearOptions.sizeField = [&octree](const Eigen::Vector3d& x) { return octree.delta(x); };
    linearOptions.maxSize = options.sizing->maxDelta;
    linearOptions.minSize = options.sizing->minDelta;
    for (const RefinementSource& src : octree.parameters().sources)
      linearOptions.minSize = std::min(linearOptions.minSize, src.delta);
  } else {
    linearOptions.size = *options.size;
    // (No memory prediction here: the bounding-box estimate of a uniform size is no measure of
    // it, a thin plate fills little of its box. The linear mesh made is checked instead.)
  }
  // Each Gmsh run (the linear mesh, the boundary layer's fill) under the smaller of
  // --linear-time-limit and what is left of the job's budget, its message naming which.
  bool gmshByBudget = false;  // the last Gmsh run's limit was the budget's rest
  const auto limitGmsh = [&](LinearMeshOptions& o, const std::string& stage) {
    o.timeLimit = budget.stageLimit(options.linearSeconds);
    gmshByBudget = budget.binds(options.linearSeconds);
    o.timeLimitName = gmshByBudget ? stage + " stage, what was left of the " +
                                         jobLimitName(budget) + ": " + jobLimitSettings()
                                   : limitName("linear_seconds");
  };
  // The linear mesh, with its macro boundary layer when one is asked for (timed as its own
  // stage the first time, `stage` "linear"; within the round in repair rounds, "repair K").
  std::optional<BoundaryLayerRecord> layer;
  const auto makeLinear = [&](LinearMeshOptions o, bool clocked, const std::string& stage) {
    std::optional<StageClock> clock;
    if (clocked) clock.emplace("linear", result.timings, observer);
    limitGmsh(o, stage);
    Mesh mesh = generateLinearMesh(*result.cad, o);
    if (!options.boundaryLayer) {
      // Cells that curving would make flat at a vertex, whatever follows: split now.
      for (const CurvedFaceEdge& ear : tangentEarSplits(mesh, *result.cad)) {
        try {
          result.tangentEars += applySplits(mesh, {ear}, *result.cad);
        } catch (const MeshingError& e) {  // (not seen: a midpoint keeps positive cells so)
          result.notes.push_back(std::string("a tangent ear was left as it is: ") + e.what());
        } catch (const CadError& e) {  // OCCT could not project its midpoint onto the face
          result.notes.push_back(std::string("a tangent ear was left as it is: ") + e.what());
        }
      }
      if (clocked) clock->done();
      return mesh;
    }
    if (clocked) clock->done();
    if (clocked) clock.emplace("boundary_layer", result.timings, observer);
    layer.emplace();
    limitGmsh(o, clocked ? std::string("boundary_layer") : stage);
    mesh = growBoundaryLayer(mesh, *result.cad, *options.boundaryLayer, o, *layer);
    if (clocked) clock->done();
    return mesh;
  };
  checkBudgetLeft(budget, "linear", result.timings);
  const double firstStart = budget.elapsed();
  Mesh linearMesh = makeLinear(linearOptions, true, "linear");

  CurvedState best = curve(std::move(linearMesh), options, *result.cad, result.timings, observer,
                           true, budget, "");
  best.layer = layer;
  // What a round repeats (the linear mesh, curving, optimiser and quality), measured: a round
  // starts only if what is left of the job's budget covers what the one before it took.
  double lastSeconds = budget.elapsed() - firstStart;
  // Repair rounds: each works from the previous round's mesh; the best state is kept.
  std::vector<RefinementSource> sources;  // accumulated over the refine rounds
  std::optional<CurvedState> last;        // the last round's state when it was not kept
  bool splitFailed = false;   // the last round split and made things worse: refine instead
  bool flipFailed = false;    // the last round flipped and made things worse: refine instead
  bool remeshFailed = false;  // the last round remeshed cavities and made things worse: refine
  // Flips and remeshes already tried on the best mesh (and not kept): not tried on it again
  // until a round is kept, so that a failed flip and a failed remesh cannot take turns for
  // every round (each flag alone only covers the round after it).
  bool flipTriedOnBest = false, remeshTriedOnBest = false;
  // Rounds for poor elements (every element valid) never refine: they try a split, a flip and a
  // remesh of the best mesh in turn, each once, and end when none is kept.
  bool splitTriedOnBest = false;
  // The last round split poor elements and left some invalid (not kept): the next round splits
  // those from its mesh, as a first round would after curving (the sphere in a box at size 1.2,
  // order 4: a poor split left 1 invalid, the split after it ended valid at 0.193, from 0.083;
  // OpenCASCADE's linkrods.step: 0.0106 -> 0.217 the same way).
  bool poorSplitLeftInvalid = false;
  for (int round = 1; round <= options.repairRounds; ++round) {
    // (Only where there is something to split: no refinement after poor rounds.)
    std::optional<RepairPlan> followPlan;
    if (poorSplitLeftInvalid && last && !options.boundaryLayer) {
      followPlan = planRepair(last->linear, last->quality.validity, *result.cad,
                              options.optimiseIterations > 0);
      if (followPlan->splits.empty()) followPlan.reset();
    }
    const bool follow = followPlan.has_value();
    const bool fromBest = !(last && (follow || (!splitFailed && !flipFailed && !remeshFailed)));
    const CurvedState& from = fromBest ? best : *last;
    const bool poor = from.notValid() == 0;  // only elements below kPoorElement are left
    if (poor && (!(from.quality.scaled.min < kPoorElement) || options.boundaryLayer)) break;
    const std::string name = "repair " + std::to_string(round);
    if (budget.limited() && budget.available() < lastSeconds) {
      budget.skip(name);
      result.notes.push_back(
          "repair rounds ended by " + jobLimitText(budget) + ": " +
          formatSeconds(std::max(budget.available(), 0.0)) + " s left before round " +
          std::to_string(round) + ", less than the " + formatSeconds(lastSeconds) + " s " +
          (round == 1 ? std::string("the first linear mesh, curving and optimiser took")
                      : "round " + std::to_string(round - 1) + " took") +
          " (stopped: time budget)");
      break;
    }
    const std::size_t budgetEvents = budget.cutStages().size() + budget.skippedStages().size();
    const auto start = std::chrono::steady_clock::now();
    RepairRound record;
    record.invalid = from.quality.invalid;
    record.undecided = from.quality.undecided;
    record.worst = from.quality.scaled.min;
    // Every flagged cell gets edges to split or a refinement sphere: the plan is never empty.
    // (A follow-up round starts from a mesh with invalid elements: its plan is the one above.)
    const RepairPlan plan = follow ? std::move(*followPlan)
                                   : planRepair(from.linear, repairTargets(from.quality, poor),
                                                *result.cad, options.optimiseIterations > 0);
    Mesh next;
    if (!plan.splits.empty() && (!splitFailed || follow) && !(poor && splitTriedOnBest) &&
        !options.boundaryLayer) {
      // Local: only the cells around the split edges change; the rest wait for the next round.
      next = from.linear;
      record.edgesSplit = applySplits(next, plan.splits, *result.cad);
    }
    // A follow-up round whose splits all failed their checks: nothing else is tried from a mesh
    // that was not kept (a refine from it would remesh the model while the best is valid).
    if (follow && record.edgesSplit == 0) break;
    const char* const instead = poor ? "" : "; refined instead";
    // Flagged cells with no edge to split (slivers with vertices inside, which the optimiser
    // could not inflate) are flipped away where a flip makes better cells, judged where the
    // optimiser left the vertices: local, where a refinement remeshes the whole model. Poor
    // elements whose split was not kept are flipped the same way (all of them).
    const bool local = plan.splits.empty() || (poor && record.edgesSplit == 0);
    const std::vector<std::size_t>& localCells = poor ? plan.flagged : plan.unsplit;
    const bool mayRemesh = local && !(fromBest && remeshTriedOnBest) && !options.boundaryLayer &&
                           options.optimiseIterations > 0 && from.linear.dim == 3;
    if (local && !(fromBest && flipTriedOnBest) && !options.boundaryLayer &&
        options.optimiseIterations > 0 && from.linear.dim == 3) {
      next = from.linear;
      try {
        const FlipOutcome flipped =
            flipAwayCells(next, localCells, curvedVertexPositions(from.linear, from.mesh));
        record.flips = flipped.flips;
        record.elements = flipped.cellsFlipped;
      } catch (const ParameterError& e) {  // a mesh the flips do not handle: refine instead
        result.notes.push_back(name + ": no flips (" + e.what() + ")" + instead);
      }
      if (record.flips == 0) flipTriedOnBest = flipTriedOnBest || fromBest;
    }
    // A poor element is not worth a refinement (it remeshes the whole model and brings new
    // offenders elsewhere): with nothing local left to try there is no round (nor its stage).
    if (poor && record.edgesSplit == 0 && record.flips == 0 && !mayRemesh) break;
    StageClock clock(name, result.timings, observer);
    // A Gmsh run of the round failed (or was stopped by the budget): the round is recorded with
    // why, and the rounds end with the best mesh so far.
    const auto recordFailedRound = [&](const MeshingError& e) {
      record.failure = e.what();
      if (dynamic_cast<const BudgetExceeded*>(&e) != nullptr && gmshByBudget) {
        budget.cut(name);
        record.budgetStopped = true;
      }
      record.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.rounds.push_back(record);
      clock.done();
    };
    // Nothing to split or flip: the cavities around the offenders are meshed again and the rest
    // of the mesh stays; where that fails, or made things worse the last time, the whole model
    // is meshed again, finer around them, instead. A cavity keeps its boundary triangles, so
    // only offenders with nothing to split get one: after a split that made things worse (edges
    // on curved faces, whose triangles a finer boundary mesh halves) the whole model is refined
    // (Motor-c.brep, 228 such offenders: a refine left 94, a remesh 209). Without the optimiser
    // a cavity's new cells are curved as they come, on the same boundary triangles: only a finer
    // boundary helps there too.
    bool remeshed = false;
    if (mayRemesh && record.edgesSplit == 0 && record.flips == 0) {
      const std::vector<std::size_t>& cells = localCells;
      record.elements = cells.size();
      next = from.linear;
      try {
        LinearMeshOptions o = linearOptions;
        limitGmsh(o, name);
        const CavityOutcome cavities = remeshCavities(next, cells, o);
        compactNodes(next);  // the removed cells' inner nodes (reuse matches cells by position)
        record.cavities = cavities.cavities;
        remeshed = cavities.cavities > 0;
      } catch (const ParameterError& e) {
        result.notes.push_back(name + ": no local remesh (" + e.what() + ")" + instead);
      } catch (const MeshingError& e) {
        if (dynamic_cast<const BudgetExceeded*>(&e) != nullptr && gmshByBudget) {
          // The budget ran out inside Gmsh: the rounds end, the best stays.
          record.action = poor ? "remesh poor" : "remesh";
          recordFailedRound(e);
          break;
        }
        result.notes.push_back(name + ": no local remesh (" + e.what() + ")" + instead);
      }
      if (!remeshed) next = Mesh();
      if (!remeshed) remeshTriedOnBest = remeshTriedOnBest || fromBest;
    }
    if (poor && record.edgesSplit == 0 && record.flips == 0 && !remeshed) {
      // The remesh was tried and made no cavity: recorded, and the rounds end (no refinement
      // for poor elements: see above).
      record.action = "remesh poor";
      record.failure = "no cavity around the poor elements could be meshed again";
      record.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      result.rounds.push_back(record);
      clock.done();
      break;
    }
    if (record.edgesSplit > 0) {
      record.action = poor ? "split poor" : "split";
      record.elements = plan.splitCells;
    } else if (record.flips > 0) {
      record.action = poor ? "flip poor" : "flip";
    } else if (remeshed) {
      record.action = poor ? "remesh poor" : "remesh";
    } else if (best.notValid() == 0) {
      clock.done();  // (defensive: once the best is valid the rounds never refine)
      break;
    } else {
      // Nothing to split (or no split kept its cells positive): refine around every offender.
      std::vector<RefinementSource> added =
          plan.splits.empty() ? plan.sources : plan.allSources;  // (splitFailed: every offender)
      // A round that refines around the same cell of the same mesh again (a refine that was not
      // kept, then a split that was not kept, both from the best state) would make the same
      // mesh again: its sphere asks for half the size the earlier one did, so repeats refine
      // further instead of cycling.
      for (RefinementSource& s : added)
        for (const RefinementSource& earlier : sources)
          if (earlier.kind == s.kind && earlier.a == s.a && earlier.radius == s.radius)
            s.delta = std::min(s.delta, 0.5 * earlier.delta);
      record.action = "refine";
      record.elements = added.size();
      record.sources = added.size();
      sources.insert(sources.end(), added.begin(), added.end());
      LinearMeshOptions refined = linearOptions;
      if (!refined.sizeField) {  // a uniform size: the constant field, capped
        const double size = linearOptions.size;
        refined.sizeField = [size](const Eigen::Vector3d&) { return size; };
        refined.maxSize = size;
        refined.minSize = size;
      }
      refined.sizeField = cappedSizeField(refined.sizeField, sources);
      for (const RefinementSource& src : sources)
        refined.minSize = std::min(refined.minSize, src.delta);
      try {
        next = makeLinear(refined, false, name);
      } catch (const MeshingError& e) {
        // The refined mesh (or its layer) could not be made: the rounds end, the best stays.
        recordFailedRound(e);
        break;
      }
    }
    CurvedState state = curve(std::move(next), options, *result.cad, result.timings, observer,
                              false, budget, name, &from);
    state.layer = layer;
    record.budgetStopped =
        budget.cutStages().size() + budget.skippedStages().size() != budgetEvents;
    record.reused = state.reused;
    record.invalidAfter = state.quality.invalid;
    record.undecidedAfter = state.quality.undecided;
    record.worstAfter = state.quality.scaled.min;
    record.meshElements = state.mesh.numElements();
    if (state.optimiser) {
      record.optimiserRegion = state.optimiser->regionElements;
      record.optimiserSweeps = state.optimiser->iterations;
      record.optimiserStopped = state.optimiser->stopReason;
      record.optimiserSeconds = state.optimiser->seconds;
    }
    record.kept = state.betterThan(best);
    splitFailed = !record.kept && (record.action == "split" || record.action == "split poor");
    poorSplitLeftInvalid = !record.kept && record.action == "split poor" && state.notValid() > 0;
    flipFailed = !record.kept && (record.action == "flip" || record.action == "flip poor");
    remeshFailed = !record.kept && (record.action == "remesh" || record.action == "remesh poor");
    if (record.kept) {
      flipTriedOnBest = remeshTriedOnBest = splitTriedOnBest = false;
      best = std::move(state);
      last.reset();
    } else {
      if (fromBest) {
        flipTriedOnBest = flipTriedOnBest || flipFailed;
        remeshTriedOnBest = remeshTriedOnBest || remeshFailed;
        splitTriedOnBest = splitTriedOnBest || record.action == "split poor";
      }
      last = std::move(state);
    }
    record.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    lastSeconds = record.seconds;
    result.rounds.push_back(record);
    clock.done();
  }

  result.mesh = std::move(best.mesh);
  result.quality = std::move(best.quality);
  result.optimiser = std::move(best.optimiser);
  result.lowOrderOptimiser = std::move(best.lowOrderOptimiser);
  result.boundaryLayer = std::move(best.layer);
  if (result.boundaryLayer) result.boundaryLayer->release = best.layerRelease;

  if (options.boundaryLayer) {
    StageClock split("split_layers", result.timings, observer);
    // Split with the columns adjusted to the grown heights; where that makes thin cells
    // invalid, or worse than half the macro mesh's worst (the plain split, a sub-map of each
    // macro cell, keeps that), their columns are split plain and the split made again.
    const Mesh macro = std::move(result.mesh);
    result.macroQuality = std::move(result.quality);
    const double poor = 0.5 * std::max(result.macroQuality->scaled.min, 0.0);
    const int layers = options.boundaryLayer->layers;
    LayerHeights heights{grownLayerHeights(best.linear), {}};
    LayerSplitStats stats;
    for (int attempt = 0;; ++attempt) {
      stats = LayerSplitStats();
      result.mesh = splitBoundaryLayer(macro, options.boundaryLayer->splitCoordinates(),
                                       result.cad.get(), &stats, &heights);
      result.quality = evaluateQuality(result.mesh, options.threads);
      if (attempt == kPlainSplitAttempts) break;
      const std::size_t before = heights.plain.size();
      for (std::size_t e = 0; e < result.quality.validity.size(); ++e)
        if (result.quality.validity[e] != Validity::Valid ||
            result.quality.scaledJacobian[e] < poor)
          keepColumnsPlain(macro, layers, e, heights);
      if (heights.plain.size() == before) break;  // none (left) in the layer
    }
    result.layerSplit = stats;
    split.done();
  }

  finishJob(result, budget, observer, false);
  return result;
}

MeshResult curveMeshOnCad(const CadSource& source, const Mesh& linear, MeshingOptions options,
                          PipelineObserver* observer) {
  options.validate();
  if (options.boundaryLayer)
    throw ParameterError("a boundary layer needs HOMesh's own linear mesh, not a given one");
  options.repairRounds = 0;  // repair regenerates the linear mesh: not this one
  options.size.reset();
  options.sizing.reset();
  MeshResult result;
  JobBudget budget(options.jobSeconds);
  StageClock cad("cad", result.timings, observer);
  result.cad = std::make_shared<const CadModel>(source.load());
  cad.done();
  result.options = options;
  StageClock classify("classify", result.timings, observer);
  Mesh onCad = classifyOnCad(linear, *result.cad);
  classify.done();
  CurvedState state =
      curve(std::move(onCad), options, *result.cad, result.timings, observer, true, budget, "");
  result.mesh = std::move(state.mesh);
  result.quality = std::move(state.quality);
  result.optimiser = std::move(state.optimiser);
  result.lowOrderOptimiser = std::move(state.lowOrderOptimiser);
  finishJob(result, budget, observer, true);
  return result;
}

std::vector<CellField> qualityFields(const QualitySummary& quality) {
  CellField scaled{"scaled_jacobian", quality.scaledJacobian};
  scaled.values.insert(scaled.values.end(), quality.boundaryScaledJacobian.begin(),
                       quality.boundaryScaledJacobian.end());
  CellField distortion{"distortion", quality.distortion};
  distortion.values.insert(distortion.values.end(), quality.boundaryDistortion.begin(),
                           quality.boundaryDistortion.end());
  // 1 proven valid, -1 invalid, 0 undecided; boundary cells have no verdict (NaN).
  CellField validity{"validity", {}};
  for (const Validity v : quality.validity)
    validity.values.push_back(v == Validity::Valid ? 1.0 : v == Validity::Invalid ? -1.0 : 0.0);
  validity.values.resize(scaled.values.size(), std::numeric_limits<double>::quiet_NaN());
  return {scaled, distortion, validity};
}

void writeMeshFiles(const MeshResult& result, const std::vector<std::string>& paths,
                    const WriteOptions& options) {
  const std::vector<CellField> fields = qualityFields(result.quality);
  for (const std::string& path : paths) writeMesh(result.mesh, path, fields, options);
}

void writeMeshOutputs(MeshResult& result, const std::vector<std::string>& paths,
                      const WriteOptions& options, PipelineObserver* observer) {
  StageClock output("output", result.timings, observer);
  writeMeshFiles(result, paths, options);
  output.done();
  result.job.seconds += result.timings.seconds.back().second;  // the job ends with its output
}

}  // namespace homesh
