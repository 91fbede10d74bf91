#include "optimise/optimiser.hpp"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "core/parameters.hpp"
#include "core/spatial_order.hpp"
#include "core/thread_count.hpp"
#include "element/jacobian_sampler.hpp"
#include "element/reference_element.hpp"
#include "optimise/cad_sliding.hpp"
#include "optimise/certified_quality.hpp"
#include "optimise/node_colouring.hpp"
#include "optimise/node_step.hpp"
#include "optimise/region_selection.hpp"
#include "optimise/stop_rules.hpp"
#include "optimise/sweep.hpp"
#include "optimise/working_mesh.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

namespace {

using optimiser::CadSliding;
using optimiser::CertifiedQuality;
using optimiser::Clock;
using optimiser::EnergyRule;
using optimiser::FreeNodes;
using optimiser::Moves;
using optimiser::NodeColouring;
using optimiser::NodeStep;
using optimiser::Patch;
using optimiser::since;
using optimiser::Sweeper;
using optimiser::TimeBudget;
using optimiser::WorkingMesh;
namespace stop = optimiser::stop;

// The optimiser's run (optimiser.hpp): the set-up, in order, of the working mesh, the input's
// certified quality, the free nodes (region_selection.hpp), the boundary facets' term, the
// threads' parts and the colouring; then the sweeps (sweep.hpp) until a stop rule
// (stop_rules.hpp) holds, keeping the best acceptable state.
template <int D>
class Optimiser {
 public:
  // `order`: the renumbering `mesh` has been given (applied), whose original numbers the
  // sequential choices follow (working_mesh.hpp); null: the mesh's own numbers.
  Optimiser(Mesh& mesh, const OptimiserOptions& options, OptimiserObserver* observer,
            const CadModel* cad, const QualitySummary* startQuality = nullptr,
            const SpatialOrder* order = nullptr)
      : options_(options),
        observer_(observer),
        cad_(cad),
        startQuality_(startQuality),
        mesh_(mesh, cad == nullptr && !options.regionThreshold && options.regionSeed.empty(),
              order),
        colouring_(options.threads),
        quality_(mesh_, colouring_, options),
        sliding_(mesh_, cad),
        step_(mesh_, sliding_, options, free_.lockedNormal),
        sweeper_(mesh_, colouring_, free_.nodes, step_, quality_, options, observer, budget_) {}

  OptimiserResult run() {
    const auto t0 = Clock::now();
    budget_ = TimeBudget(options_.timeLimit, t0);
    result_.functional = options_.functional;
    mesh_.build();
    quality_.measureInput(startQuality_);  // certified quality of every element, before
    const IterationRecord before = quality_.summarise(0, 0.0, t0);
    const bool certified = before.invalid + before.undecided == 0;
    // An input certified valid takes the symmetric rule and fewer node samples
    // (working_mesh.hpp): the long cylinder of 1000 x 1 (66,899 order-4 tetrahedra) swept in
    // 31-32 s instead of 46 s, worst 0.638 against 0.627; the kept sweep is never worse than
    // such an input. Taken on every input (a trial), runs that untangle ended elsewhere: four
    // tests failed (a boundary layer's first height, repair rounds that must keep a flip).
    mesh_.buildSamples(certified ? EnergyRule::Symmetric : EnergyRule::Collapsed);
    result_.energyRule = mesh_.energyRule == EnergyRule::Symmetric ? "symmetric" : "collapsed";
    result_.worstBefore = before.worst;
    result_.invalidBefore = before.invalid;
    result_.undecidedBefore = before.undecided;
    result_.nodalWorstBefore = nodalScaledJacobian(mesh_.mesh, options_.threads);
    // A limit the set-up has already spent (on a large mesh: 288,036 order-4 tetrahedra took
    // 19 s to here) stops the run now, before the free nodes, colours and gradients, which cost
    // as much again (22 s there): the input is kept.
    if (budget_.overBudget()) return stoppedInSetup(before, t0);

    chooseFreeNodes();
    step_.buildFacets(free_.nodes, cad_);
    colouring_.partition(mesh_, free_.changed);
    colouring_.colour(mesh_, free_.nodes);
    result_.colours = colouring_.colours();
    mesh_.computeGradients(free_.changed, colouring_);
    sweeper_.resetMarks();
    result_.setupSeconds = since(t0);

    Kept best{before, {}, {}};
    // Before the energy: it counts the term.
    step_.setFacetsOn(certified);
    if (step_.facetsOn()) step_.refreshFacetTargets();
    best.record.energy = result_.energyBefore = totalEnergy();
    Mesh& mesh = mesh_.mesh;
    const std::vector<double> input = mesh.xyz, inputParam = mesh.nodeCadParam;
    result_.stopReason = free_.nodes.empty() ? stop::kNoFreeNodes : stop::kIterations;
    try {
      sweepUntilStopped(before, best, t0);
    } catch (...) {
      mesh.xyz = input;  // never leave a half-optimised mesh behind
      mesh.nodeCadParam = inputParam;
      throw;
    }
    result_.energyAfter = best.record.energy;
    mesh.xyz = best.xyz.empty() ? input : best.xyz;
    mesh.nodeCadParam = best.xyz.empty() ? inputParam : best.param;
    result_.keptIteration = best.record.iteration;
    result_.worstAfter = best.record.worst;
    result_.invalidAfter = best.record.invalid;
    result_.undecidedAfter = best.record.undecided;
    result_.nodalWorstAfter = nodalScaledJacobian(mesh, options_.threads);
    result_.seconds = since(t0);
    return result_;
  }

  // The set-up of run() without quality, with F at every element, for NodeEnergyProbe.
  void prepareProbe() {
    mesh_.build();
    mesh_.buildSamples(EnergyRule::Collapsed);
    chooseFreeNodes();
    step_.buildFacets(free_.nodes, cad_);
    step_.refreshFacetTargets();
    colouring_.partition(mesh_, free_.changed);
    free_.changed.resize(mesh_.totalElements);
    for (std::size_t i = 0; i < mesh_.totalElements; ++i) free_.changed[i] = i;
    energyOrder_ =
        optimiser::energyOrder(free_.changed, mesh_.totalElements, mesh_.callersElements);
    mesh_.computeGradients(free_.changed, colouring_);
  }

  bool isFree(std::int64_t node) const {
    // free_.nodes is sorted before colour()
    return std::binary_search(free_.nodes.begin(), free_.nodes.end(), node);
  }

  Eigen::VectorXd probeCoordinates(std::int64_t node) const {
    if (sliding_.parameters(node) == 0) return mesh_.position[node];
    return Eigen::Map<const Eigen::VectorXd>(&mesh_.mesh.nodeCadParam[2 * node],
                                             sliding_.parameters(node));
  }

  double probeRegularisation(std::int64_t node) {
    Patch<D> patch;
    return step_.gather(node, patch);
  }

  // The energy of the node's patch with the node at `coordinates`, as a sweep's step assembles
  // it.
  NodeEnergy probe(std::int64_t node, const Eigen::VectorXd& coordinates, double eps) {
    return step_.probe(node, coordinates, eps);
  }

 private:
  // The best state so far: its record and, unless it is the input (empty), its coordinates
  // and CAD parameters.
  struct Kept {
    IterationRecord record;
    std::vector<double> xyz, param;
  };

  // The free nodes (region_selection.hpp), the elements they change and the order the total
  // energy sums those in.
  void chooseFreeNodes() {
    free_ = optimiser::chooseFreeNodes(mesh_, quality_.scaled(), quality_.validity(), sliding_,
                                       options_);
    result_.regionElements = free_.regionElements;
    result_.freeNodes = free_.nodes.size();
    elementEnergy_.clear();  // totalEnergy computes every element's share again
    energyOrder_ =
        optimiser::energyOrder(free_.changed, mesh_.totalElements, mesh_.callersElements);
  }

  // The sweeps, until a stop rule holds (stop_rules.hpp) or maxIterations are done; `best`
  // follows the best acceptable state.
  void sweepUntilStopped(const IterationRecord& before, Kept& best, Clock::time_point t0) {
    IterationRecord previous = best.record;
    for (int it = 1; it <= options_.maxIterations && !free_.nodes.empty(); ++it) {
      if (observer_ != nullptr && observer_->cancelRequested()) {
        result_.cancelled = true;
        result_.stopReason = stop::kCancelled;
        break;
      }
      if (budget_.overBudget()) {
        result_.stopReason = stop::kTimeBudget;
        break;
      }
      // The fidelity targets follow the sweeps (a lagged model of the distance to the CAD): the
      // last record's energy is taken again against the new ones, so that the stop rules
      // compare a sweep's start and end under one model.
      if (it > 1 && step_.hasFidelity() && step_.facetsOn()) {
        step_.refreshFacetTargets();
        previous.energy = totalEnergy();
      }
      const auto s0 = Clock::now();
      Moves moved;
      try {
        moved = sweeper_.sweep();
      } catch (const CancelledError&) {  // asked between colour groups: the best is kept
        result_.cancelled = !budget_.spent();
        result_.stopReason = budget_.spent() ? stop::kTimeBudget : stop::kCancelled;
        if (budget_.spent()) keepPartialSweep(it, before, best, s0, t0);
        break;
      }
      result_.sweepSeconds += since(s0);
      IterationRecord record = sweepRecord(it, moved, t0);
      // The facet term joins once the mesh is proven valid: every node of a facet is visited
      // again (resting nodes too), and the sweep is not judged by the stop rules, whose energy
      // would compare totals with and without the term.
      const bool switching =
          !step_.facetsOn() && step_.hasFacets() && record.invalid + record.undecided == 0;
      if (switching) switchFacetsOn();
      record.energy = totalEnergy();
      finishSweep(record, before, best);
      const std::string reason =
          switching ? "" : optimiser::stopRule(result_.history, previous, before, options_);
      previous = record;
      if (!reason.empty()) {
        result_.converged = optimiser::converges(reason);
        result_.stopReason = reason;
        break;
      }
    }
  }

  // A sweep the time limit stopped between colour groups, finished as far as it got: the
  // nodes it moved are written back and the elements they changed certified, and the state is
  // recorded as sweep `it` (partial) and kept if acceptable and better than `best`.
  void keepPartialSweep(int it, const IterationRecord& before, Kept& best, Clock::time_point s0,
                        Clock::time_point t0) {
    sweeper_.settleInterrupted();
    result_.sweepSeconds += since(s0);
    IterationRecord record = sweepRecord(it, sweeper_.interrupted(), t0);
    record.partial = true;
    record.energy = totalEnergy();
    finishSweep(record, before, best);
  }

  // Sweep `record` into the history and to the observer; its state (the mesh) becomes `best`
  // where it is acceptable against the input and better than `best`.
  void finishSweep(const IterationRecord& record, const IterationRecord& before, Kept& best) {
    result_.history.push_back(record);
    result_.iterations = record.iteration;
    if (observer_ != nullptr) observer_->iterationFinished(record);
    if (optimiser::acceptable(record, before) && optimiser::better(record, best.record)) {
      best.record = record;
      best.xyz = mesh_.mesh.xyz;
      best.param = mesh_.mesh.nodeCadParam;
    }
  }

  // The result of a run stopped by its time limit during the set-up: the input, as evaluated
  // (its energy was not computed: NaN).
  OptimiserResult stoppedInSetup(const IterationRecord& before, Clock::time_point t0) {
    result_.stopReason = stop::kTimeBudget;
    result_.energyBefore = result_.energyAfter = std::numeric_limits<double>::quiet_NaN();
    result_.worstAfter = before.worst;
    result_.invalidAfter = before.invalid;
    result_.undecidedAfter = before.undecided;
    result_.nodalWorstAfter = result_.nodalWorstBefore;
    result_.setupSeconds = result_.seconds = since(t0);
    return result_;
  }

  // The record of sweep `it` from what it moved (added to the run's totals), its energy left to
  // the caller.
  IterationRecord sweepRecord(int it, const Moves& moved, Clock::time_point t0) {
    IterationRecord record = quality_.summarise(it, moved.absolute, t0);
    record.maxRelativeMove = moved.relative;
    record.visits = moved.visits;
    result_.visits += moved.visits;
    result_.slides += moved.slides;
    result_.cadEvaluations += moved.cadEvaluations;
    return record;
  }

  // The boundary facets' term joins: every node of a facet is visited in the next sweep.
  void switchFacetsOn() {
    step_.setFacetsOn(true);
    step_.refreshFacetTargets();  // at the positions the term starts from
    for (const std::int64_t node : free_.nodes)
      if (step_.touchesFacet(node)) sweeper_.wake(node);
  }

  // The energy of the elements that contain a free node (the others' is constant), from the
  // current F, with the regularisation of a valid patch. Each element's share is kept and
  // computed again only where its F changed since (the sweeper marks those): the total is the
  // same to the last bit as from every element afresh, and a late sweep that moves a few nodes
  // no longer pays for the whole mesh (0.12 s a sweep on the 66,899 order-4 tetrahedra of a
  // cylinder of radius 1 and length 1000, where such sweeps took 0.1 s).
  double totalEnergy() {
    std::vector<std::size_t> elements = sweeper_.takeChangedEnergy();  // global indices
    if (elementEnergy_.size() != free_.changed.size()) {
      elementEnergy_.assign(free_.changed.size(), 0.0);
      elements = free_.changed;
    }
    std::vector<std::size_t> stale(elements.size());  // their positions in free_.changed
    for (std::size_t k = 0; k < elements.size(); ++k)
      stale[k] = static_cast<std::size_t>(
          std::lower_bound(free_.changed.begin(), free_.changed.end(), elements[k]) -
          free_.changed.begin());
    functional_detail::dispatch(options_.functional, [&](auto fn) {
      colouring_.forEachOwned(elements, 64, [&](std::size_t k, int /*thread*/) {
        const auto [bi, e] = mesh_.locate(elements[k]);
        const optimiser::Block<D>& b = mesh_.blocks[bi];
        double sum = 0.0;
        for (int q = 0; q < b.points; ++q) {
          const std::size_t p = e * b.points + q;
          sum += b.weights[p] * energyDensity<D, decltype(fn)::value>(b.matrixF(e, q), 1e-10);
        }
        elementEnergy_[stale[k]] = sum;
      });
    });
    double total = 0.0;  // summed in order: the same for any thread count
    for (const std::size_t i : energyOrder_) total += elementEnergy_[i];
    total += step_.facetTotal();
    return total;
  }

  const OptimiserOptions& options_;
  OptimiserObserver* observer_;
  const CadModel* cad_;                 // null: boundary nodes stay fixed
  const QualitySummary* startQuality_;  // the input's quality, from the caller (may be null)
  TimeBudget budget_;                   // set at the start of run()
  WorkingMesh<D> mesh_;
  FreeNodes<D> free_;  // its nodes grouped by colour, then by part, once coloured
  std::vector<std::size_t> energyOrder_;  // positions in free_.changed, summed in this order
  std::vector<double> elementEnergy_;     // per position in free_.changed (totalEnergy)
  NodeColouring<D> colouring_;
  CertifiedQuality<D> quality_;
  CadSliding<D> sliding_;
  NodeStep<D> step_;
  Sweeper<D> sweeper_;
  OptimiserResult result_;
};

}  // namespace

namespace {

// The options with their thread count resolved once for the run (0: every core).
OptimiserOptions withThreadsResolved(OptimiserOptions options) {
  options.threads = threadsToUse(options.threads);
  return options;
}

}  // namespace

OptimiserResult optimiseMesh(Mesh& mesh, const OptimiserOptions& options,
                             OptimiserObserver* observer, const CadModel* cad,
                             const QualitySummary* startQuality) {
  options.validate();
  mesh.checkConsistency();
  if (mesh.isSurface())
    throw ParameterError(
        "the optimiser handles volume meshes and planar 2D meshes, not a surface mesh "
        "(triangles on curved faces in 3D)");
  if (mesh.dim != 2 && mesh.dim != 3)
    throw ParameterError("the optimiser needs a 2D or 3D mesh, got dimension " +
                         std::to_string(mesh.dim));
  OptimiserOptions local = withThreadsResolved(options);
  if (!options.spatialOrder)
    return mesh.dim == 3 ? Optimiser<3>(mesh, local, observer, cad, startQuality).run()
                         : Optimiser<2>(mesh, local, observer, cad, startQuality).run();
  // The sweeps run on the mesh renumbered along a space-filling curve (OptimiserOptions::
  // spatialOrder), with the per-node and per-element options and the caller's quality
  // renumbered alongside; the caller's numbering is restored whatever happens.
  const SpatialOrder order(mesh);
  local.fixedNodes = order.nodeValues(options.fixedNodes, 1);
  local.normalLocked = order.nodeValues(options.normalLocked, 3);
  local.regionSeed = order.elementValues(options.regionSeed);
  QualitySummary known;  // the arrays takeStartQuality() reads
  if (startQuality != nullptr) {
    known.scaledJacobian = order.elementValues(startQuality->scaledJacobian);
    known.scaledJacobianUpper = order.elementValues(startQuality->scaledJacobianUpper);
    known.validity = order.elementValues(startQuality->validity);
  }
  const QualitySummary* start = startQuality != nullptr ? &known : nullptr;
  order.apply(mesh);  // all or nothing (spatial_order.hpp)
  OptimiserResult result;
  try {
    result = mesh.dim == 3 ? Optimiser<3>(mesh, local, observer, cad, start, &order).run()
                           : Optimiser<2>(mesh, local, observer, cad, start, &order).run();
  } catch (...) {
    order.restore(mesh);  // the run left the input's coordinates: the caller's mesh as given
    throw;
  }
  order.restore(mesh);
  return result;
}

class NodeEnergyProbe::Impl {
 public:
  virtual ~Impl() = default;
  virtual bool isFree(std::int64_t node) const = 0;
  virtual Eigen::VectorXd coordinates(std::int64_t node) const = 0;
  virtual double regularisation(std::int64_t node) = 0;
  virtual NodeEnergy evaluate(std::int64_t node, const Eigen::VectorXd& coordinates,
                              double eps) = 0;
};

namespace {

template <int D>
class ProbeImpl : public NodeEnergyProbe::Impl {
 public:
  ProbeImpl(Mesh mesh, OptimiserOptions options, const CadModel* cad)
      : mesh_(std::move(mesh)),
        options_(withThreadsResolved(std::move(options))),
        optimiser_(mesh_, options_, nullptr, cad) {
    optimiser_.prepareProbe();
  }
  bool isFree(std::int64_t node) const override { return optimiser_.isFree(node); }
  Eigen::VectorXd coordinates(std::int64_t node) const override {
    return optimiser_.probeCoordinates(node);
  }
  double regularisation(std::int64_t node) override { return optimiser_.probeRegularisation(node); }
  NodeEnergy evaluate(std::int64_t node, const Eigen::VectorXd& coordinates, double eps) override {
    return optimiser_.probe(node, coordinates, eps);
  }

 private:
  Mesh mesh_;
  OptimiserOptions options_;
  Optimiser<D> optimiser_;
};

}  // namespace

NodeEnergyProbe::NodeEnergyProbe(const Mesh& mesh, const OptimiserOptions& options,
                                 const CadModel* cad) {
  options.validate();
  mesh.checkConsistency();
  if (mesh.dim == 3) {
    impl_ = std::make_unique<ProbeImpl<3>>(mesh, options, cad);
  } else if (mesh.dim == 2) {
    impl_ = std::make_unique<ProbeImpl<2>>(mesh, options, cad);
  } else {
    throw ParameterError("the optimiser needs a 2D or 3D mesh, got dimension " +
                         std::to_string(mesh.dim));
  }
  numNodes_ = mesh.numNodes();
}

NodeEnergyProbe::~NodeEnergyProbe() = default;

void NodeEnergyProbe::check(std::int64_t node) const {
  if (node < 0 || static_cast<std::size_t>(node) >= numNodes_)
    throw ParameterError("node " + std::to_string(node) + " is not in the mesh");
}

bool NodeEnergyProbe::isFree(std::int64_t node) const {
  check(node);
  return impl_->isFree(node);
}

Eigen::VectorXd NodeEnergyProbe::coordinates(std::int64_t node) const {
  check(node);
  return impl_->coordinates(node);
}

double NodeEnergyProbe::regularisation(std::int64_t node) const {
  check(node);
  return impl_->regularisation(node);
}

NodeEnergy NodeEnergyProbe::evaluate(std::int64_t node, const Eigen::VectorXd& coordinates,
                                     double eps) const {
  check(node);
  const Eigen::Index expected = impl_->coordinates(node).size();
  if (coordinates.size() != expected)
    throw ParameterError("node " + std::to_string(node) + " has " + std::to_string(expected) +
                         " coordinates, got " + std::to_string(coordinates.size()));
  return impl_->evaluate(node, coordinates, eps);
}

double nodalScaledJacobian(const Mesh& mesh, int threads) {
  double worst = 1.0;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim || block.count() == 0) continue;
    const ReferenceElement& ref = ReferenceElement::get(block.type, block.order);
    const JacobianSampler sampler(ref, ref.nodes());
    const int n = block.nodesPerElement();
    double blockWorst = 1.0;
    FirstFailure failure;
#pragma omp parallel for num_threads(threadsToUse(threads)) reduction(min : blockWorst)
    for (std::int64_t e = 0; e < static_cast<std::int64_t>(block.count()); ++e) {
      try {
        NodeCoordinates x(n, 3);
        const std::int64_t* v = block.element(static_cast<std::size_t>(e));
        for (int i = 0; i < n; ++i)
          for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * v[i] + c];
        Eigen::VectorXd j;
        const Eigen::Vector3d normal = cellNormal(mesh, v);
        sampler.jacobians(x, mesh.dim == 2 ? &normal : nullptr, j);
        const double hi = j.maxCoeff();
        blockWorst = std::min(blockWorst, hi > 0.0 ? j.minCoeff() / hi : -1.0);
      } catch (...) {
        failure.capture();
      }
    }
    failure.rethrow();
    worst = std::min(worst, blockWorst);
  }
  return worst;
}

}  // namespace homesh
