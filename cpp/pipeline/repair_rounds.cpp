#include "pipeline/repair_rounds.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/isolated_call.hpp"
#include "linear/cavity_remesh.hpp"
#include "linear/tet_flips.hpp"
#include "pipeline/job_messages.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/stage_clock.hpp"

namespace homesh {

namespace {

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

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One round in the making: where it starts and what it has done so far.
struct Round {
  std::string name;  // "repair 2"
  const CurvedState& from;
  bool fromBest;  // `from` is the best state (not the last round's, which was not kept)
  bool poor;      // every element of `from` is valid: only elements below kPoorElement are left
  bool follow;    // follows a poor split that left elements invalid: its plan splits those
  std::chrono::steady_clock::time_point start;
  std::size_t budgetEvents;  // the budget's cut and skipped stages before the round
  RepairRound record;
  RepairPlan plan;
  Mesh next;  // the round's linear mesh
};

// What a local remesh of the offenders' cavities came to.
enum class Remesh { NotRemeshed, Remeshed, RoundsEnded };

class RepairRounds {
 public:
  RepairRounds(CurvedState best, double firstSeconds, LinearStage& linear, MeshResult& result,
               const MeshingOptions& options, JobBudget& budget, PipelineObserver* observer)
      : result_(result),
        options_(options),
        budget_(budget),
        observer_(observer),
        linear_(linear),
        best_(std::move(best)),
        lastSeconds_(firstSeconds) {}

  CurvedState run() {
    for (int round = 1; round <= options_.repairRounds; ++round)
      if (!runRound(round)) break;
    return std::move(best_);
  }

 private:
  bool runRound(int round);
  std::optional<RepairPlan> followUpPlan() const;
  bool budgetCovers(int round, const std::string& name);
  void splitEdges(Round& r);
  void flipAway(Round& r, const std::vector<std::size_t>& cells, const char* instead);
  Remesh remeshLocally(Round& r, const std::vector<std::size_t>& cells, const char* instead,
                       StageClock& clock);
  bool refine(Round& r, StageClock& clock);
  void recordFailedRound(Round& r, const MeshingError& e, StageClock& clock);
  void curveAndKeep(Round& r, StageClock& clock);

  MeshResult& result_;
  const MeshingOptions& options_;
  JobBudget& budget_;
  PipelineObserver* observer_;
  LinearStage& linear_;
  CurvedState best_;
  // What a round repeats (the linear mesh, curving, optimiser and quality), measured: a round
  // starts only if what is left of the job's budget covers what the one before it took.
  double lastSeconds_;
  std::vector<RefinementSource> sources_;  // accumulated over the refine rounds
  std::optional<CurvedState> last_;        // the last round's state when it was not kept
  bool splitFailed_ = false;   // the last round split and made things worse: refine instead
  bool flipFailed_ = false;    // the last round flipped and made things worse: refine instead
  bool remeshFailed_ = false;  // the last round remeshed cavities and made things worse: refine
  // Flips and remeshes already tried on the best mesh (and not kept): not tried on it again
  // until a round is kept, so that a failed flip and a failed remesh cannot take turns for
  // every round (each flag alone only covers the round after it).
  bool flipTriedOnBest_ = false, remeshTriedOnBest_ = false;
  // Rounds for poor elements (every element valid) never refine: they try a split, a flip and a
  // remesh of the best mesh in turn, each once, and end when none is kept.
  bool splitTriedOnBest_ = false;
  // The last round split poor elements and left some invalid (not kept): the next round splits
  // those from its mesh, as a first round would after curving (the sphere in a box at size 1.2,
  // order 4: a poor split left 1 invalid, the split after it ended valid at 0.193, from 0.083;
  // OpenCASCADE's linkrods.step: 0.0106 -> 0.217 the same way).
  bool poorSplitLeftInvalid_ = false;
};

// After a poor split that left elements invalid: the split of those in its mesh (none when
// there is nothing to split: no refinement after poor rounds).
std::optional<RepairPlan> RepairRounds::followUpPlan() const {
  std::optional<RepairPlan> plan;
  if (poorSplitLeftInvalid_ && last_ && !options_.boundaryLayer) {
    plan = planRepair(last_->linear, last_->quality.validity, *result_.cad,
                      options_.optimiseIterations > 0);
    if (plan->splits.empty()) plan.reset();
  }
  return plan;
}

// Whether what is left of the job's budget covers the round; if not, the round is skipped and
// a note says why.
bool RepairRounds::budgetCovers(int round, const std::string& name) {
  if (!budget_.limited() || budget_.available() >= lastSeconds_) return true;
  budget_.skip(name);
  result_.notes.push_back(
      "repair rounds ended by " + jobLimitText(budget_) + ": " +
      formatSeconds(std::max(budget_.available(), 0.0)) + " s left before round " +
      std::to_string(round) + ", less than the " + formatSeconds(lastSeconds_) + " s " +
      (round == 1 ? std::string("the first linear mesh, curving and optimiser took")
                  : "round " + std::to_string(round - 1) + " took") +
      " (stopped: time budget)");
  return false;
}

// Local: only the cells around the split edges change; the rest wait for the next round.
void RepairRounds::splitEdges(Round& r) {
  r.next = r.from.linear;
  r.record.edgesSplit = applySplits(r.next, r.plan.splits, *result_.cad);
}

// Flagged cells with no edge to split (slivers with vertices inside, which the optimiser could
// not inflate) are flipped away where a flip makes better cells, judged where the optimiser left
// the vertices: local, where a refinement remeshes the whole model.
void RepairRounds::flipAway(Round& r, const std::vector<std::size_t>& cells, const char* instead) {
  r.next = r.from.linear;
  try {
    const FlipOutcome flipped =
        flipAwayCells(r.next, cells, curvedVertexPositions(r.from.linear, r.from.mesh));
    r.record.flips = flipped.flips;
    r.record.elements = flipped.cellsFlipped;
  } catch (const ParameterError& e) {  // a mesh the flips do not handle: refine instead
    result_.notes.push_back(r.name + ": no flips (" + e.what() + ")" + instead);
  }
  if (r.record.flips == 0) flipTriedOnBest_ = flipTriedOnBest_ || r.fromBest;
}

// Nothing to split or flip: the cavities around the offenders are meshed again and the rest of
// the mesh stays; where that fails, or made things worse the last time, the whole model is
// meshed again, finer around them, instead. A cavity keeps its boundary triangles, so only
// offenders with nothing to split get one: after a split that made things worse (edges on
// curved faces, whose triangles a finer boundary mesh halves) the whole model is refined
// (Motor-c.brep, 228 such offenders: a refine left 94, a remesh 209). Without the optimiser a
// cavity's new cells are curved as they come, on the same boundary triangles: only a finer
// boundary helps there too.
Remesh RepairRounds::remeshLocally(Round& r, const std::vector<std::size_t>& cells,
                                   const char* instead, StageClock& clock) {
  bool remeshed = false;
  r.record.elements = cells.size();
  r.next = r.from.linear;
  try {
    LinearMeshOptions o = linear_.baseOptions();
    linear_.limitGmsh(o, r.name);
    const CavityOutcome cavities = remeshCavities(r.next, cells, o);
    compactNodes(r.next);  // the removed cells' inner nodes (reuse matches cells by position)
    r.record.cavities = cavities.cavities;
    remeshed = cavities.cavities > 0;
  } catch (const ParameterError& e) {
    result_.notes.push_back(r.name + ": no local remesh (" + e.what() + ")" + instead);
  } catch (const MeshingError& e) {
    if (dynamic_cast<const BudgetExceeded*>(&e) != nullptr && linear_.gmshByBudget()) {
      // The budget ran out inside Gmsh: the rounds end, the best stays.
      r.record.action = r.poor ? "remesh poor" : "remesh";
      recordFailedRound(r, e, clock);
      return Remesh::RoundsEnded;
    }
    result_.notes.push_back(r.name + ": no local remesh (" + e.what() + ")" + instead);
  }
  if (!remeshed) r.next = Mesh();
  if (!remeshed) remeshTriedOnBest_ = remeshTriedOnBest_ || r.fromBest;
  return remeshed ? Remesh::Remeshed : Remesh::NotRemeshed;
}

// Nothing to split (or no split kept its cells positive): the whole model is meshed again with
// the size field capped around every offender. False when that mesh (or its layer) could not be
// made: the round is recorded as failed and the rounds end with the best mesh.
bool RepairRounds::refine(Round& r, StageClock& clock) {
  std::vector<RefinementSource> added =
      r.plan.splits.empty() ? r.plan.sources : r.plan.allSources;  // (splitFailed: every offender)
  // A round that refines around the same cell of the same mesh again (a refine that was not
  // kept, then a split that was not kept, both from the best state) would make the same mesh
  // again: its sphere asks for half the size the earlier one did, so repeats refine further
  // instead of cycling.
  for (RefinementSource& s : added)
    for (const RefinementSource& earlier : sources_)
      if (earlier.kind == s.kind && earlier.a == s.a && earlier.radius == s.radius)
        s.delta = std::min(s.delta, 0.5 * earlier.delta);
  r.record.action = "refine";
  r.record.elements = added.size();
  r.record.sources = added.size();
  sources_.insert(sources_.end(), added.begin(), added.end());
  const LinearMeshOptions& base = linear_.baseOptions();
  LinearMeshOptions refined = base;
  if (!refined.sizeField) {  // a uniform size: the constant field, capped
    const double size = base.size;
    refined.sizeField = [size](const Eigen::Vector3d&) { return size; };
    refined.maxSize = size;
    refined.minSize = size;
  }
  refined.sizeField = cappedSizeField(refined.sizeField, sources_);
  for (const RefinementSource& src : sources_)
    refined.minSize = std::min(refined.minSize, src.delta);
  try {
    r.next = linear_.make(refined, false, r.name);
  } catch (const MeshingError& e) {
    recordFailedRound(r, e, clock);
    return false;
  }
  return true;
}

// A Gmsh run of the round failed (or was stopped by the budget): the round is recorded with
// why, and the rounds end with the best mesh so far.
void RepairRounds::recordFailedRound(Round& r, const MeshingError& e, StageClock& clock) {
  r.record.failure = e.what();
  if (dynamic_cast<const BudgetExceeded*>(&e) != nullptr && linear_.gmshByBudget()) {
    budget_.cut(r.name);
    r.record.budgetStopped = true;
  }
  r.record.seconds = secondsSince(r.start);
  result_.rounds.push_back(r.record);
  clock.done();
}

// The round's linear mesh curved from its start state, recorded, and kept when it is better
// than the best; the flags that steer the next round follow from the outcome.
void RepairRounds::curveAndKeep(Round& r, StageClock& clock) {
  CurvedState state = curve(std::move(r.next), options_, *result_.cad, result_.timings, observer_,
                            false, budget_, r.name, &r.from, false, linear_.layer());
  RepairRound& record = r.record;
  record.budgetStopped =
      budget_.cutStages().size() + budget_.skippedStages().size() != r.budgetEvents;
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
  record.kept = state.betterThan(best_);
  splitFailed_ = !record.kept && (record.action == "split" || record.action == "split poor");
  poorSplitLeftInvalid_ = !record.kept && record.action == "split poor" && state.notValid() > 0;
  flipFailed_ = !record.kept && (record.action == "flip" || record.action == "flip poor");
  remeshFailed_ = !record.kept && (record.action == "remesh" || record.action == "remesh poor");
  if (record.kept) {
    flipTriedOnBest_ = remeshTriedOnBest_ = splitTriedOnBest_ = false;
    best_ = std::move(state);
    last_.reset();
  } else {
    if (r.fromBest) {
      flipTriedOnBest_ = flipTriedOnBest_ || flipFailed_;
      remeshTriedOnBest_ = remeshTriedOnBest_ || remeshFailed_;
      splitTriedOnBest_ = splitTriedOnBest_ || record.action == "split poor";
    }
    last_ = std::move(state);
  }
  record.seconds = secondsSince(r.start);
  lastSeconds_ = record.seconds;
  result_.rounds.push_back(record);
  clock.done();
}

// One round; false when the rounds end (before this round or with it).
bool RepairRounds::runRound(int round) {
  std::optional<RepairPlan> followPlan = followUpPlan();
  const bool follow = followPlan.has_value();
  const bool fromBest = !(last_ && (follow || (!splitFailed_ && !flipFailed_ && !remeshFailed_)));
  const CurvedState& from = fromBest ? best_ : *last_;
  const bool poor = from.notValid() == 0;  // only elements below kPoorElement are left
  if (poor && (!(from.quality.scaled.min < kPoorElement) || options_.boundaryLayer)) return false;
  const std::string name = "repair " + std::to_string(round);
  if (!budgetCovers(round, name)) return false;
  Round r{name,
          from,
          fromBest,
          poor,
          follow,
          std::chrono::steady_clock::now(),
          budget_.cutStages().size() + budget_.skippedStages().size(),
          {},
          {},
          {}};
  RepairRound& record = r.record;
  record.invalid = from.quality.invalid;
  record.undecided = from.quality.undecided;
  record.worst = from.quality.scaled.min;
  // Every flagged cell gets edges to split or a refinement sphere: the plan is never empty.
  // (A follow-up round starts from a mesh with invalid elements: its plan is the one above.)
  r.plan = follow ? std::move(*followPlan)
                  : planRepair(from.linear, repairTargets(from.quality, poor), *result_.cad,
                               options_.optimiseIterations > 0);
  if (!r.plan.splits.empty() && (!splitFailed_ || follow) && !(poor && splitTriedOnBest_) &&
      !options_.boundaryLayer)
    splitEdges(r);
  // A follow-up round whose splits all failed their checks: nothing else is tried from a mesh
  // that was not kept (a refine from it would remesh the model while the best is valid).
  if (follow && record.edgesSplit == 0) return false;
  const char* const instead = poor ? "" : "; refined instead";
  // Cells without a split are flipped or remeshed (poor elements whose split was not kept are
  // flipped the same way, all of them).
  const bool local = r.plan.splits.empty() || (poor && record.edgesSplit == 0);
  const std::vector<std::size_t>& localCells = poor ? r.plan.flagged : r.plan.unsplit;
  const bool localActions =
      !options_.boundaryLayer && options_.optimiseIterations > 0 && from.linear.dim == 3;
  const bool mayRemesh = local && !(fromBest && remeshTriedOnBest_) && localActions;
  if (local && !(fromBest && flipTriedOnBest_) && localActions) flipAway(r, localCells, instead);
  // A poor element is not worth a refinement (it remeshes the whole model and brings new
  // offenders elsewhere): with nothing local left to try there is no round (nor its stage).
  if (poor && record.edgesSplit == 0 && record.flips == 0 && !mayRemesh) return false;
  StageClock clock(name, result_.timings, observer_);
  bool remeshed = false;
  if (mayRemesh && record.edgesSplit == 0 && record.flips == 0) {
    const Remesh outcome = remeshLocally(r, localCells, instead, clock);
    if (outcome == Remesh::RoundsEnded) return false;
    remeshed = outcome == Remesh::Remeshed;
  }
  if (poor && record.edgesSplit == 0 && record.flips == 0 && !remeshed) {
    // The remesh was tried and made no cavity: recorded, and the rounds end (no refinement
    // for poor elements: see above).
    record.action = "remesh poor";
    record.failure = "no cavity around the poor elements could be meshed again";
    record.seconds = secondsSince(r.start);
    result_.rounds.push_back(record);
    clock.done();
    return false;
  }
  if (record.edgesSplit > 0) {
    record.action = poor ? "split poor" : "split";
    record.elements = r.plan.splitCells;
  } else if (record.flips > 0) {
    record.action = poor ? "flip poor" : "flip";
  } else if (remeshed) {
    record.action = poor ? "remesh poor" : "remesh";
  } else if (best_.notValid() == 0) {
    clock.done();  // (defensive: once the best is valid the rounds never refine)
    return false;
  } else if (!refine(r, clock)) {
    return false;
  }
  curveAndKeep(r, clock);
  return true;
}

}  // namespace

CurvedState runRepairRounds(CurvedState best, double firstSeconds, LinearStage& linear,
                            MeshResult& result, const MeshingOptions& options, JobBudget& budget,
                            PipelineObserver* observer) {
  return RepairRounds(std::move(best), firstSeconds, linear, result, options, budget, observer)
      .run();
}

}  // namespace homesh
