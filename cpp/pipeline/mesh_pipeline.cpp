#include "pipeline/mesh_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

#include "boundary_layer/layer_blend.hpp"
#include "boundary_layer/layer_stacks.hpp"
#include "cad/model_dimension.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/isolated_call.hpp"
#include "core/job_budget.hpp"
#include "core/system_memory.hpp"
#include "io/octree_export.hpp"
#include "linear/cad_classification.hpp"
#include "pipeline/closing_note.hpp"
#include "pipeline/curve_stage.hpp"
#include "pipeline/job_messages.hpp"
#include "pipeline/linear_stage.hpp"
#include "pipeline/repair_rounds.hpp"
#include "pipeline/stage_clock.hpp"
#include "pipeline/straighten_invalid.hpp"
#include "quality/mesh_quality.hpp"
#include "sizing/automatic_min_delta.hpp"

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
  return completeSizing(SizingParameters{}, cad);
}

SizingParameters completeSizing(SizingParameters p, const CadModel& cad) {
  if (p.maxDelta == 0.0) {
    const double diagonal = defaultMeshSize(cad);
    p.maxDelta = std::max(diagonal, p.minDelta);
    p.maxDeltaSetBy = diagonal >= p.minDelta ? "bounding-box diagonal / 20" : "MinDelta";
  }
  // An automatic (0) minDelta stays so: the sizing octree sets it from the shape
  // (sizing/automatic_min_delta.hpp).
  return p;
}

SizingParameters resolveSizing(const std::optional<SizingParameters>& requested,
                               const CadModel& cad) {
  return completeSizing(requested.value_or(defaultSizing(cad)), cad);
}

namespace {

// Healing and imprinting number the model's faces and edges afresh: what the options name by
// number (a boundary layer's faces, its curves in a 2D model, refinement along CAD curves) is
// mapped from the model as read (`cad`: the model meshed), a face or curve split standing for
// all its pieces; a number they removed is refused, naming the step that removed it.
void mapToMeshedNumbering(const HealingRecord& healing, const CadModel& cad,
                          MeshingOptions& options) {
  const NumberingMap& numbering = healing.numbering;
  if (!numbering.changed()) return;
  const char* const operation = kHealingOperation;
  if (options.boundaryLayer) {
    Eigen::Vector3d normal;
    const bool planar = modelMeshDimension(cad, normal) == 2;
    options.boundaryLayer->faces =
        numbering.map(planar ? 1 : 2, options.boundaryLayer->faces,
                      planar ? "boundary-layer curve" : "boundary-layer face", operation);
    if (!planar)
      options.boundaryLayer->solids =
          numbering.map(3, options.boundaryLayer->solids, "boundary-layer solid", operation);
  }
  if (!options.sizing) return;
  std::vector<RefinementSource> sources;
  for (const RefinementSource& s : options.sizing->sources) {
    if (s.kind != RefinementSource::Kind::Curve) {
      sources.push_back(s);
      continue;
    }
    for (const int edge : numbering.map(1, {s.edge}, "refinement curve", operation)) {
      RefinementSource piece = s;
      piece.edge = edge;
      sources.push_back(piece);
    }
  }
  options.sizing->sources = std::move(sources);
}

}  // namespace

SizingResult runSizingStage(const CadSource& source, const MeshingOptions& given) {
  given.healing().validate();  // before the (possibly slow) CAD import
  HealingRecord healing;
  const CadModel cad = healModel(source.load(), given.healing(), healing);
  MeshingOptions options = given;
  mapToMeshedNumbering(healing, cad, options);
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

namespace {

// The octree and its prediction for `params` as given.
SizingResult buildSizing(const CadModel& cad, const SizingParameters& params, int threads) {
  SizingResult r;
  r.octree = std::make_shared<const SizingOctree>(SizingOctree::build(cad, params, threads));
  r.prediction = predictElementCount(*r.octree, cad, threads);
  return r;
}

}  // namespace

SizingResult runSizing(const CadModel& cad, const SizingParameters& params, int threads) {
  const auto start = std::chrono::steady_clock::now();
  // An automatic MinDelta the shape asked for is raised while the octree would need more cells
  // than it may have (doubled from the value it was built with) or the prediction exceeds the
  // element limit (the surface's count grows as 1 / MinDelta^2 where the smallest sizes
  // dominate it: that factor), at most to MaxDelta / 20, the automatic rule before. The record
  // keeps what the shape asked for first.
  const bool automatic = params.minDelta == 0.0;
  const double ceiling = kMinDeltaCeiling * params.maxDelta;
  SizingParameters p = params;
  SizingResult r;
  std::string asked;  // what set the automatic MinDelta before a limit raised it
  for (;;) {
    try {
      r = buildSizing(cad, p, threads);
    } catch (const OctreeTooLarge& e) {
      if (!automatic || e.sourceTooSmall || e.minDelta >= ceiling) throw;
      if (asked.empty()) asked = "too many cells at MinDelta " + formatNumber(e.minDelta);
      p.minDelta = std::min(ceiling, 2.0 * e.minDelta);
      p.minDeltaSetBy = "the sizing octree's cell limit (" + asked + ")";
      continue;
    }
    const SizingParameters& used = r.octree->parameters();
    if (!automatic || used.minDelta >= ceiling || !(r.prediction.elements > kMaxPredictedElements))
      break;
    if (asked.empty()) asked = used.minDeltaSetBy + " asks for " + formatNumber(used.minDelta);
    p.minDelta = std::min(
        ceiling, 1.25 * used.minDelta * std::sqrt(r.prediction.elements / kMaxPredictedElements));
    p.minDeltaSetBy = "the element limit (" + asked + ")";
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (r.prediction.elements > kMaxPredictedElements) {
    const SizingParameters& used = r.octree->parameters();
    std::ostringstream msg;
    msg.precision(3);
    msg << "the sizes (MinDelta " << used.minDelta << ", MaxDelta " << used.maxDelta << ", EPS "
        << used.eps << ") would make about " << r.prediction.elements << " elements for "
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

namespace {

// The "cad" stage: the model loaded and healed (what healing did in result.healing and notes).
void loadCad(MeshResult& result, const CadSource& source, const MeshingOptions& options,
             PipelineObserver* observer) {
  StageClock cad("cad", result.timings, observer);
  result.cad =
      std::make_shared<const CadModel>(healModel(source.load(), options.healing(), result.healing));
  cad.done();
  for (const std::string& note : result.healing.notes()) result.notes.push_back(note);
}

// The options checked against the model and completed for it: what the model cannot have
// refused, the sizes resolved (octree sizing unless a uniform size was given), and the
// optimiser left out on a surface mesh (with a note).
void fitOptionsToModel(MeshResult& result, MeshingOptions& options) {
  const CadModel& cad = *result.cad;
  if (options.boundaryLayer && isSurfaceModel(cad))  // (automatic mode's choice)
    throw ParameterError("a boundary layer needs a volume or planar mesh, and " + cad.sourceName() +
                         " has no solid: automatic mode (--auto) gives it a surface mesh");
  mapToMeshedNumbering(result.healing, cad, options);
  checkMeshDimension(cad, options.expectedDimension);
  if (!options.size) options.sizing = resolveSizing(options.sizing, cad);
  if (isSurfaceModel(cad) && options.optimiseIterations > 0) {
    options.optimiseIterations = 0;
    result.notes.emplace_back(
        "the optimiser does not run on a surface mesh: every node lies on the CAD, where "
        "curving placed it");
  }
}

// The "sizing" stage (octree sizing: the octree, its prediction checked against the memory
// available, the octree written when asked) and the linear mesh's sizes from it; with a uniform
// size, that size.
void sizeLinearMesh(MeshResult& result, const MeshingOptions& options, const JobBudget& budget,
                    PipelineObserver* observer, LinearMeshOptions& linearOptions,
                    const std::string& stage = "sizing") {
  if (!options.sizing) {
    linearOptions.size = *options.size;
    // (No memory prediction here: the bounding-box estimate of a uniform size is no measure of
    // it, a thin plate fills little of its box. The linear mesh made is checked instead.)
    return;
  }
  checkBudgetLeft(budget, stage, result.timings);
  StageClock sizing(stage, result.timings, observer);
  result.sizing = runSizing(*result.cad, *options.sizing, options.threads);
  if (!options.octreeOutput.empty()) writeOctree(*result.sizing->octree, options.octreeOutput);
  sizing.done();
  Eigen::Vector3d normal;  // (the plane of a 2D model)
  checkPredictedMemory(result.sizing->prediction.elements, options.order,
                       modelMeshDimension(*result.cad, normal),
                       "meshing " + result.cad->sourceName());
  const std::shared_ptr<const SizingOctree> held = result.sizing->octree;  // (sizes again)
  const SizingOctree& octree = *held;
  linearOptions.sizeField = [held](const Eigen::Vector3d& x) { return held->delta(x); };
  linearOptions.maxSize = options.sizing->maxDelta;
  linearOptions.minSize = octree.parameters().minDelta;
  for (const RefinementSource& src : octree.parameters().sources)
    linearOptions.minSize = std::min(linearOptions.minSize, src.delta);
}

// The result takes the curved mesh of `state` and what its stages found (its linear mesh stays).
void takeCurved(MeshResult& result, CurvedState& state) {
  result.mesh = std::move(state.mesh);
  result.quality = std::move(state.quality);
  result.optimiser = std::move(state.optimiser);
  result.lowOrderOptimiser = std::move(state.lowOrderOptimiser);
  result.boundaryLayer = std::move(state.layer);
  if (result.boundaryLayer) result.boundaryLayer->release = state.layerRelease;
}

// Splits of the boundary layer after the first that set more columns plain (each around the
// thin cells the one before left invalid or poor).
constexpr int kPlainSplitAttempts = 3;

// The "split_layers" stage: the macro layer of result.mesh split at the levels `z` (0 < ... <
// 1, one layer between each two); result.quality becomes the split mesh's, the macro mesh's kept
// as result.macroQuality. Split with the columns adjusted to `heights`; where that makes thin
// cells invalid, or worse than half the macro mesh's worst (the plain split, a sub-map of each
// macro cell, keeps that), their columns are split plain and the split made again.
void splitLayers(MeshResult& result, const std::vector<double>& z, LayerHeights heights,
                 int threads, PipelineObserver* observer) {
  StageClock split("split_layers", result.timings, observer);
  const Mesh macro = std::move(result.mesh);
  result.macroQuality = std::move(result.quality);
  const double poor = 0.5 * std::max(result.macroQuality->scaled.min, 0.0);
  const int layers = static_cast<int>(z.size()) - 1;
  LayerSplitStats stats;
  for (int attempt = 0;; ++attempt) {
    stats = LayerSplitStats();
    result.mesh = splitBoundaryLayer(macro, z, result.cad.get(), &stats, &heights);
    result.quality = evaluateQuality(result.mesh, threads);
    if (attempt == kPlainSplitAttempts) break;
    const std::size_t before = heights.plain.size();
    for (std::size_t e = 0; e < result.quality.validity.size(); ++e)
      if (result.quality.validity[e] != Validity::Valid || result.quality.scaledJacobian[e] < poor)
        keepColumnsPlain(macro, layers, e, heights);
    if (heights.plain.size() == before) break;  // none (left) in the layer
  }
  result.layerSplit = stats;
  split.done();
}

// The "boundary_fit" stage (pipeline/boundary_fidelity.hpp) on the kept mesh, with the fidelity
// term's weight above 0 (0 turns both off) and while the job's budget lasts.
void fitBoundary(MeshResult& result, JobBudget& budget, PipelineObserver* observer) {
  if (!(result.options.fidelityWeight > 0.0) || result.mesh.dim != 3 || result.mesh.order < 2)
    return;
  if (budget.spent()) {
    budget.skip("boundary_fit");
    return;
  }
  StageClock clock("boundary_fit", result.timings, observer);
  const auto stop = [&] {
    return (observer != nullptr && observer->cancelRequested()) || budget.spent();
  };
  result.boundaryFit =
      fitBoundaryFidelity(result.mesh, result.quality, *result.cad, result.options.threads, stop);
  if (result.boundaryFit->stopped && budget.spent()) budget.cut("boundary_fit");
  clock.done();
}

// The closing note, the geometry stage (left out once the job's budget is spent: it only
// measures), then the job's record.
void finishJob(MeshResult& result, JobBudget& budget, PipelineObserver* observer,
               bool linearGiven) {
  if (result.quality.invalid + result.quality.undecided > 0)
    result.notes.push_back(notValidNote(result, linearGiven));
  if (result.boundaryLayer)
    for (std::string& note : layerShortNotes(*result.boundaryLayer, result.mesh.dim))
      result.notes.push_back(std::move(note));
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

// The first straight-sided cell of `mesh` proven invalid by its certified quality: its
// Jacobian vanishes or changes sign (a flat pyramid whose apex lies in the mean plane of its
// twisted base, a hexahedron with a corner pushed inside it), so no curving of it can be valid
// and the optimiser cannot measure it. Cells are oriented (classifyOnCad), so a valid one has
// J > 0; an undecided one (J near zero somewhere, not proven negative) is left to the
// certificate of the curved mesh. Empty when there is none; counts are 1-based per block.
std::string firstInvalidCell(const Mesh& mesh, const char* what, int threads) {
  const QualitySummary quality = evaluateQuality(mesh, threads);
  const auto elements = elementsOf(mesh);
  for (std::size_t e = 0; e < elements.size(); ++e) {
    if (quality.validity[e] != Validity::Invalid) continue;
    const auto [block, i] = elements[e];
    const int corners = cellNumVertices(block->type);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < corners; ++k) centre += nodePoint(mesh, block->element(i)[k]);
    centre /= corners;
    std::ostringstream msg;
    msg << cellShortName(block->type) << " " << i + 1 << " of " << what << " (centre ("
        << centre.x() << ", " << centre.y() << ", " << centre.z()
        << ")) is not valid straight-sided (scaled Jacobian " << quality.scaledJacobian[e] << ")";
    return msg.str();
  }
  return {};
}

// The given mesh's stacks of prisms and hexahedra agglomerated (layer_stacks.hpp) when their
// macro cells are valid straight-sided (columns that bend or converge at a concave corner may
// make one that is not: the prisms' stacks are then tried alone, and the cells are otherwise
// curved as given, with a note saying why).
std::optional<LayerStacks> agglomerateLayer(const Mesh& onCad, MeshResult& result, int threads) {
  std::string why;
  std::optional<LayerStacks> stacks = recogniseLayerStacks(onCad, why);
  if (stacks) {
    why = firstInvalidCell(stacks->macro, "the macro layer", threads);
    if (!why.empty() && stacks->record.hexStacks > 0 &&
        stacks->record.hexStacks < stacks->record.stacks) {
      std::string prismsWhy;
      std::optional<LayerStacks> prisms = recogniseLayerStacks(onCad, prismsWhy, false);
      if (prisms && firstInvalidCell(prisms->macro, "the macro layer", threads).empty()) {
        prisms->hexahedraLeftOut = why;
        stacks = std::move(prisms);
        why.clear();
      }
    }
    if (!stacks->hexahedraLeftOut.empty())
      result.notes.push_back("the hexahedra were curved as given, not as a boundary layer: " +
                             stacks->hexahedraLeftOut);
    if (why.empty()) return stacks;
  }
  if (!why.empty())
    result.notes.push_back("the layer's cells were curved as given, not as a boundary layer: " +
                           why);
  return std::nullopt;
}

// The given mesh's elements left invalid (or undecided), straightened off the CAD
// (straighten_invalid.hpp), up to kStraightenRounds times (a round's moves may leave a neighbour
// invalid, which the next straightens); with a macro layer, its columns are then made straight
// again between wall and top (its split assumes them straight). The best round is kept, if it
// leaves fewer such elements; the note says how many it repaired.
void straightenWhereInvalid(CurvedState& state, MeshResult& result, bool layered, int threads,
                            JobBudget& budget, PipelineObserver* observer) {
  constexpr int kStraightenRounds = 3;
  const std::size_t before = state.quality.invalid + state.quality.undecided;
  if (before == 0) return;
  if (budget.spent()) {
    budget.skip("straighten");
    return;
  }
  StageClock clock("straighten", result.timings, observer);
  Mesh trial = state.mesh;
  QualitySummary quality = state.quality;
  for (int round = 0; round < kStraightenRounds; ++round) {
    if (quality.invalid + quality.undecided == 0 || (round > 0 && budget.spent())) break;
    if (straightenInvalidElements(trial, quality) == 0) break;
    if (layered) blendLayerInteriors(trial, result.cad.get(), false);
    quality = evaluateQuality(trial, threads);
    if (quality.invalid + quality.undecided < state.quality.invalid + state.quality.undecided) {
      state.mesh = trial;
      state.quality = quality;
    }
  }
  clock.done();
  const std::size_t after = state.quality.invalid + state.quality.undecided;
  if (after < before)
    result.notes.push_back(std::to_string(before - after) + " of " + std::to_string(before) +
                           " elements not proven valid after the optimiser were repaired by "
                           "straightening their nodes off the CAD");
}

// The first linear mesh. Where it cannot be made with the sizes an automatic MinDelta took from
// the shape (below MaxDelta / 20: OpenCASCADE's bottle, whose thread ends in faces of radius
// 0.024, failed in Gmsh with "a segment and a facet intersect" with both its surface
// algorithms), the sizes are made again with MinDelta = MaxDelta / 20, the automatic rule
// before (the stage "sizing again"), and the mesh again, with a note; a second failure is the
// error, naming the first too. A run stopped by its time budget, cancelled or out of memory is
// not tried again.
Mesh makeFirstLinearMeshAtSizes(MeshResult& result, const MeshingOptions& options,
                                JobBudget& budget, PipelineObserver* observer,
                                LinearStage& linear) {
  try {
    return linear.make(linear.baseOptions(), true, "linear");
  } catch (const MeshingError& failure) {
    if (endsTheJob(failure) || !result.sizing || !options.sizing || options.sizing->minDelta != 0.0)
      throw;
    const SizingParameters used = result.sizing->octree->parameters();
    const double ceiling = kMinDeltaCeiling * used.maxDelta;
    if (!(used.minDelta < ceiling)) throw;
    const std::string shape =
        "MinDelta " + formatNumber(used.minDelta) + " (" + used.minDeltaSetBy + ")";
    MeshingOptions coarser = options;
    coarser.sizing->minDelta = ceiling;
    coarser.sizing->minDeltaSetBy = "MaxDelta / 20, after the linear mesh failed at " + shape;
    result.notes.push_back(std::string(failure.what()) + "; the linear mesh was made again with " +
                           "MinDelta " + formatNumber(ceiling) + " (MaxDelta / 20) instead of " +
                           shape);
    try {
      checkBudgetLeft(budget, "linear", result.timings);
      sizeLinearMesh(result, coarser, budget, observer, linear.baseOptions(), "sizing again");
      return linear.make(linear.baseOptions(), true, "linear");
    } catch (const MeshingError& second) {
      if (endsTheJob(second)) throw;
      throw MeshingError(std::string(second.what()) + " (with MinDelta " + formatNumber(ceiling) +
                         ", MaxDelta / 20; with " + shape + ": " + failure.what() + ")");
    }
  }
}

// The front of the pipeline: the CAD loaded and healed, the options fitted to it, the sizes and
// the first linear mesh (`firstStart`: the budget's clock when that mesh was started).
// `linear` is made for `options`, which it refers to.
Mesh startPipeline(MeshResult& result, const CadSource& source, MeshingOptions& options,
                   JobBudget& budget, PipelineObserver* observer,
                   std::optional<LinearStage>& linear, double& firstStart) {
  loadCad(result, source, options, observer);
  fitOptionsToModel(result, options);
  result.options = options;
  linear.emplace(result, options, budget, observer);
  sizeLinearMesh(result, options, budget, observer, linear->baseOptions());
  checkBudgetLeft(budget, "linear", result.timings);
  firstStart = budget.elapsed();
  return makeFirstLinearMeshAtSizes(result, options, budget, observer, *linear);
}

// startPipeline; where Gmsh fails on a model whose touching solids were imprinted (4.8 aborts
// on OpenCASCADE's imprinted Axis_of_bearing.brep, which it meshes with the solids apart), the
// model is started again without imprinting, `options` then `given` less imprinting, with a
// note: a mesh that does not conform where the solids touch, said so, rather than none.
Mesh startWithImprintFallback(MeshResult& result, const CadSource& source,
                              const MeshingOptions& given, MeshingOptions& options,
                              JobBudget& budget, PipelineObserver* observer,
                              std::optional<LinearStage>& linear, double& firstStart) {
  try {
    return startPipeline(result, source, options, budget, observer, linear, firstStart);
  } catch (const MeshingError& failure) {
    if (endsTheJob(failure) || !result.healing.imprint.imprinted) throw;
    const std::string imprinted = failure.what();
    linear.reset();
    StageTimings timings = std::move(result.timings);  // (the time spent counts)
    result = MeshResult{};
    result.timings = std::move(timings);
    options = given;
    options.imprint = false;
    try {
      Mesh mesh = startPipeline(result, source, options, budget, observer, linear, firstStart);
      result.notes.push_back(
          "Gmsh could not mesh the model with its touching solids imprinted on each other (" +
          imprinted + "), so they were meshed apart: the mesh does not conform where they touch");
      return mesh;
    } catch (const MeshingError& second) {
      if (endsTheJob(second)) throw;
      throw MeshingError(std::string(second.what()) + " (meshed with the touching solids apart; " +
                         "with them imprinted: " + imprinted + ")");
    }
  }
}

}  // namespace

MeshResult runMeshPipeline(const CadSource& source, MeshingOptions options,
                           PipelineObserver* observer) {
  options.validate();  // before the (possibly slow) CAD import
  const MeshingOptions given = options;
  MeshResult result;
  JobBudget budget(options.jobSeconds);  // its clock starts here
  std::optional<LinearStage> stage;
  double firstStart = 0.0;
  Mesh linearMesh =
      startWithImprintFallback(result, source, given, options, budget, observer, stage, firstStart);
  LinearStage& linear = *stage;

  CurvedState first = curve(std::move(linearMesh), options, *result.cad, result.timings, observer,
                            true, budget, "", nullptr, false, linear.layer());
  // A repair round starts only if what is left of the budget covers what the one before took:
  // for the first, the linear mesh and curving just measured.
  CurvedState best = runRepairRounds(std::move(first), budget.elapsed() - firstStart, linear,
                                     result, options, budget, observer);
  takeCurved(result, best);
  fitBoundary(result, budget, observer);

  if (options.boundaryLayer) {
    LayerHeights heights{grownLayerHeights(best.linear), {}, {}, {}};
    if (result.boundaryLayer) heights.lengthened = result.boundaryLayer->lengthened;
    splitLayers(result, options.boundaryLayer->splitCoordinates(), std::move(heights),
                options.threads, observer);
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
  Mesh onCad = classifyOnCad(linear, *result.cad,
                             options.classifyTolerance * result.cad->boundingDiagonal());
  if (const std::string invalid = firstInvalidCell(onCad, "the given mesh", options.threads);
      !invalid.empty())
    throw MeshingError(invalid + ", so no curved cell made from it can be valid");
  std::optional<LayerStacks> stacks = agglomerateLayer(onCad, result, options.threads);
  if (stacks) {
    onCad = std::move(stacks->macro);
    result.givenLayers = stacks->record;
  }
  classify.done();
  CurvedState state = curve(std::move(onCad), options, *result.cad, result.timings, observer, true,
                            budget, "", nullptr, stacks.has_value());
  straightenWhereInvalid(state, result, stacks.has_value(), options.threads, budget, observer);
  result.mesh = std::move(state.mesh);
  result.quality = std::move(state.quality);
  fitBoundary(result, budget, observer);
  result.optimiser = std::move(state.optimiser);
  result.lowOrderOptimiser = std::move(state.lowOrderOptimiser);
  if (stacks && stacks->record.layers > 1) {
    // Each column's first level where its given first layer was: the splitter keeps the
    // height z_1 H* of a column grown to H*, so H* = h_1 / z_1.
    std::vector<double> grown = std::move(stacks->firstHeights);
    for (double& h : grown) h /= stacks->record.levels[1];
    splitLayers(result, stacks->record.levels,
                LayerHeights{std::move(grown), {}, {}, std::move(stacks->givenLevels)},
                options.threads, observer);
  }
  finishJob(result, budget, observer, true);
  return result;
}

WriteOptions inMeshedNumbering(WriteOptions options, const StageRecords& records, int meshDim) {
  const NumberingMap& numbering = records.healing.numbering;
  if (!numbering.changed()) return options;
  for (NamedGroup& g : options.groups)
    g.entities = numbering.map(meshDim - 1, g.entities, "boundary group '" + g.name + "': entity",
                               kHealingOperation);
  return options;
}

void writeMeshOutputs(MeshResult& result, const std::vector<std::string>& paths,
                      const WriteOptions& options, PipelineObserver* observer) {
  const WriteOptions mapped = inMeshedNumbering(options, result, result.mesh.dim);
  StageClock output("output", result.timings, observer);
  writeMeshFiles(result, paths, mapped);
  output.done();
  result.job.seconds += result.timings.seconds.back().second;  // the job ends with its output
}

}  // namespace homesh
