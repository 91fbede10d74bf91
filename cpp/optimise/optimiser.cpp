#include "optimise/optimiser.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <utility>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "core/parameters.hpp"
#include "core/spatial_order.hpp"
#include "core/team_barrier.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "optimise/cad_local_model.hpp"
#include "optimise/facet_energy.hpp"
#include "optimise/mesh_topology.hpp"
#include "optimise/node_patch.hpp"
#include "optimise/work_partition.hpp"
#include "quality/jacobian_sampler.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

void OptimiserOptions::validate() const {
  if (maxIterations < 0)
    throw ParameterError("maxiter must be >= 0, got " + std::to_string(maxIterations));
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw ParameterError("tolerance must be a finite number >= 0");
  if (!(energyTolerance >= 0.0) || !std::isfinite(energyTolerance))
    throw ParameterError("energy tolerance must be a finite number >= 0");
  if (!(timeLimit >= 0.0) || !std::isfinite(timeLimit))
    throw ParameterError("the optimiser's time limit must be a finite number of seconds >= 0");
  if (!(stall >= 0.0) || !std::isfinite(stall))
    throw ParameterError("stall must be a finite number >= 0");
  if (!(stallEnergy >= 0.0) || !std::isfinite(stallEnergy))
    throw ParameterError("stall energy must be a finite number >= 0");
  if (stallWindow < 1)
    throw ParameterError("stall window must be >= 1, got " + std::to_string(stallWindow));
  if (stuckWindow < 1)
    throw ParameterError("stuck window must be >= 1, got " + std::to_string(stuckWindow));
  if (!(activeTolerance >= 0.0) || !std::isfinite(activeTolerance))
    throw ParameterError("active tolerance must be a finite number >= 0");
  if (threads < 1 || threads > 1024)
    throw ParameterError("threads must be between 1 and 1024, got " + std::to_string(threads));
  if (regionThreshold && !(*regionThreshold > 0.0 && *regionThreshold <= 1.0))
    throw ParameterError("region threshold must be in (0, 1]");
  if (regionLayers < 0)
    throw ParameterError("region layers must be >= 0, got " + std::to_string(regionLayers));
  if (focusPasses < 0)
    throw ParameterError("focus passes must be >= 0, got " + std::to_string(focusPasses));
  if (!(focusMargin >= 0.0) || !std::isfinite(focusMargin))
    throw ParameterError("focus margin must be a finite number >= 0");
  checkParameter("facet_weight", facetWeight);
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Armijo constant and the number of halvings before a move is rejected.
constexpr double kArmijo = 1e-3;
constexpr int kLineSearchSteps = 12;
// The tolerance of the first, coarse Jacobian bounds of a sweep's quality check (evaluate()).
constexpr double kCoarseTolerance = 0.1;

// The optimiser moves the nodes of this set, converting from and to the mesh's equispaced nodes
// (the same polynomial map either way). Nodal Gauss-Seidel converges faster through the
// well-conditioned set (GLL, warp & blend): 0.716 against 0.693 worst scaled Jacobian after five
// sweeps on NekMesh's cube-sphere at order 4.
constexpr NodeSet kWorkingSet = NodeSet::Optimal;

// The energy's quadrature: exact to degree 2P - 1 (per variable on boxes), enough for the
// polynomial part of W on a straight-sided ideal element. (Higher degrees changed the worst
// value after five sweeps by less than 0.004; degree P + 1 halves the time but lost 0.18 of it
// on NekMesh's cube-sphere and left the sphere in a box tangled.)
//
// The energy also samples W at the element's own (equispaced) nodes, together weighted
// kNodeShare of the element's measure. A curved element's J is often lowest at its vertices and
// edges, where no interior quadrature point is: without these samples, sweeps at order 6 made
// the worst element of Gmsh's sphere in a box (MeshSizeMax 0.5, 2 907 tetrahedra) worse while
// the energy fell (0.436 -> 0.307 after two sweeps, 0.418 after five without focused passes,
// 0.542 with them) and left one element tangled at its nodes on the order-4 sphere in a box
// re-interpolated at order 6 (-0.437 after 20 sweeps); with them, 0.704 after five sweeps
// (NekMesh's varopti: 0.654) and the re-interpolated mesh valid (0.531). A larger share (0.03,
// 0.1: 0.800, 0.863) helps those meshes more but, with boundary nodes sliding on the CAD, left
// more coarse sphere-in-box meshes invalid after the repair rounds (2 and 3 of 9 test cases
// against 1).
constexpr double kNodeShare = 0.01;

QuadratureRule energySamples(CellType type, int order, const ReferenceElement& equispaced) {
  QuadratureRule rule = quadratureRule(type, std::max(1, 2 * order - 1));
  double measure = 0.0;
  for (const double w : rule.weights) measure += w;
  const Eigen::MatrixXd& nodes = equispaced.nodes();
  const double w = kNodeShare * measure / static_cast<double>(nodes.rows());
  for (Eigen::Index n = 0; n < nodes.rows(); ++n) {
    for (Eigen::Index c = 0; c < nodes.cols(); ++c) rule.points.push_back(nodes(n, c));
    rule.weights.push_back(w);
  }
  return rule;
}

template <int D>
struct Block {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  const ElementBlock* cells = nullptr;
  int nodes = 0, points = 0;
  bool affine = true;             // the ideal element's Jacobian is constant (simplices)
  std::vector<double> gradients;  // reference basis gradients, [node][direction][point]
  Eigen::MatrixXd gradientTable;  // the same as one matrix: [node][point x D + direction]
  std::vector<Mat> idealInvT;     // (dx_I/dxi)^-T per element (affine) or per element x point
  std::vector<double> weights;    // quadrature weight x |det dx_I/dxi|, per element x point
  // The deformation gradient, [element][component][point] (component k is F(k % D, k / D)): a
  // node's patch reads and updates an element's points one contiguous run per component.
  std::vector<double> F;
  std::vector<double> J;         // det F, per element x point (updated with F)
  Eigen::MatrixXd toWorking;     // equispaced node values -> working node values
  Eigen::MatrixXd toEquispaced;  // and back

  const Mat& invT(std::size_t e, int q) const {
    return idealInvT[affine ? e : e * points + static_cast<std::size_t>(q)];
  }
  double* componentF(std::size_t e, int k) {
    return &F[(e * D * D + static_cast<std::size_t>(k)) * static_cast<std::size_t>(points)];
  }
  const double* componentF(std::size_t e, int k) const {
    return &F[(e * D * D + static_cast<std::size_t>(k)) * static_cast<std::size_t>(points)];
  }
  Mat matrixF(std::size_t e, int q) const {
    Mat m;
    for (int k = 0; k < D * D; ++k) m(k % D, k / D) = componentF(e, k)[q];
    return m;
  }
  const double* gradient(int node, int direction) const {
    return &gradients[(static_cast<std::size_t>(node) * D + static_cast<std::size_t>(direction)) *
                      static_cast<std::size_t>(points)];
  }
};

struct Incidence {
  int block = 0;
  int local = 0;
  std::size_t element = 0;
};

template <int D>
class Optimiser {
 public:
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;

  // `order`: the renumbering `mesh` has been given (applied), whose original numbers the
  // sequential choices follow (see elementRank_); null: the mesh's own numbers.
  Optimiser(Mesh& mesh, const OptimiserOptions& options, OptimiserObserver* observer,
            const CadModel* cad, const QualitySummary* startQuality = nullptr,
            const SpatialOrder* order = nullptr)
      : mesh_(mesh),
        options_(options),
        observer_(observer),
        cad_(cad),
        startQuality_(startQuality),
        converting_(cad == nullptr && !options.regionThreshold && options.regionSeed.empty()),
        elementRank_(order != nullptr ? &order->originalElements() : nullptr),
        callersNodes_(order != nullptr ? &order->newNodes() : nullptr),
        callersElements_(order != nullptr ? &order->newElements() : nullptr) {}

  OptimiserResult run() {
    const auto t0 = Clock::now();
    runStart_ = t0;
    result_.functional = options_.functional;
    setFrame();
    buildBlocks();
    convertToWorkingSet();
    buildIncidence();

    // Certified quality of every element, before.
    scaled_.resize(totalElements_);
    estimate_.resize(totalElements_);
    tight_.assign(totalElements_, 0);
    validity_.resize(totalElements_);
    std::vector<std::size_t> all(totalElements_);
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    // Build the shared Bezier tables once before the threads need them.
    for (const Block<D>& b : blocks_) elementJacobianBounds(mesh_, *b.cells, 0);
    if (!takeStartQuality()) evaluate(all);
    const IterationRecord before = summarise(0, 0.0, t0);
    result_.worstBefore = before.worst;
    result_.invalidBefore = before.invalid;
    result_.undecidedBefore = before.undecided;
    result_.nodalWorstBefore = nodalScaledJacobian(mesh_, options_.threads);
    // A limit the set-up has already spent (on a large mesh: 288,036 order-4 tetrahedra took
    // 19 s to here) stops the run now, before the free nodes, colours and gradients, which cost
    // as much again (22 s there): the input is kept.
    if (overBudget()) return stoppedInSetup(before, t0);

    chooseFreeNodes();
    buildFacets();
    partition();
    colour();
    computeGradients();
    resetMarks();
    result_.setupSeconds = since(t0);

    IterationRecord best = before;
    facetsOn_ = before.invalid + before.undecided == 0;  // before the energy: it counts the term
    best.energy = result_.energyBefore = totalEnergy();
    std::vector<double> bestXyz, bestParam;  // empty: the input
    const std::vector<double> input = mesh_.xyz, inputParam = mesh_.nodeCadParam;
    result_.stopReason = free_.empty() ? "no free nodes" : "iterations";
    try {
      IterationRecord previous = best;
      for (int it = 1; it <= options_.maxIterations && !free_.empty(); ++it) {
        if (observer_ != nullptr && observer_->cancelRequested()) {
          result_.cancelled = true;
          result_.stopReason = "cancelled";
          break;
        }
        if (overBudget()) {
          result_.stopReason = "time budget";
          break;
        }
        const auto s0 = Clock::now();
        Moves moved;
        try {
          moved = sweep();
        } catch (const CancelledError&) {  // asked between colour groups: the best is kept
          result_.cancelled = !budgetSpent_;
          result_.stopReason = budgetSpent_ ? "time budget" : "cancelled";
          if (budgetSpent_) keepPartialSweep(it, before, best, bestXyz, bestParam, s0, t0);
          break;
        }
        result_.sweepSeconds += since(s0);
        IterationRecord record = sweepRecord(it, moved, t0);
        // The facet term joins once the mesh is proven valid: every node of a facet is visited
        // again (resting nodes too), and the sweep is not judged by the stop rules, whose energy
        // would compare totals with and without the term.
        const bool switching = !facetsOn_ && hasFacets() && record.invalid + record.undecided == 0;
        if (switching) switchFacetsOn();
        record.energy = totalEnergy();
        finishSweep(record, before, best, bestXyz, bestParam);
        const std::string reason = switching ? "" : stopRule(record, previous, before);
        previous = record;
        if (!reason.empty()) {
          result_.converged = reason != "stuck";
          result_.stopReason = reason;
          break;
        }
      }
    } catch (...) {
      mesh_.xyz = input;  // never leave a half-optimised mesh behind
      mesh_.nodeCadParam = inputParam;
      throw;
    }
    result_.energyAfter = best.energy;
    mesh_.xyz = bestXyz.empty() ? input : bestXyz;
    mesh_.nodeCadParam = bestXyz.empty() ? inputParam : bestParam;
    result_.keptIteration = best.iteration;
    result_.worstAfter = best.worst;
    result_.invalidAfter = best.invalid;
    result_.undecidedAfter = best.undecided;
    result_.nodalWorstAfter = nodalScaledJacobian(mesh_, options_.threads);
    result_.seconds = since(t0);
    return result_;
  }

  // A sweep the time limit stopped between colour groups, finished as far as it got: the
  // nodes it moved are written back and the elements they changed certified, and the state is
  // recorded as sweep `it` (partial) and kept if acceptable and better than `best`.
  void keepPartialSweep(int it, const IterationRecord& before, IterationRecord& best,
                        std::vector<double>& bestXyz, std::vector<double>& bestParam,
                        Clock::time_point s0, Clock::time_point t0) {
    writeBack();
    evaluate(take(kStale));
    result_.sweepSeconds += since(s0);
    IterationRecord record = sweepRecord(it, interrupted_, t0);
    record.partial = true;
    record.energy = totalEnergy();
    finishSweep(record, before, best, bestXyz, bestParam);
  }

  // Sweep `record` into the history and to the observer; its state (mesh_) becomes `best`
  // where it is acceptable against the input and better than `best`.
  void finishSweep(const IterationRecord& record, const IterationRecord& before,
                   IterationRecord& best, std::vector<double>& bestXyz,
                   std::vector<double>& bestParam) {
    result_.history.push_back(record);
    result_.iterations = record.iteration;
    if (observer_ != nullptr) observer_->iterationFinished(record);
    if (acceptable(record, before) && better(record, best)) {
      best = record;
      bestXyz = mesh_.xyz;
      bestParam = mesh_.nodeCadParam;
    }
  }

  // The result of a run stopped by its time limit during the set-up: the input, as evaluated
  // (its energy was not computed: NaN).
  OptimiserResult stoppedInSetup(const IterationRecord& before, Clock::time_point t0) {
    result_.stopReason = "time budget";
    result_.energyBefore = result_.energyAfter = std::numeric_limits<double>::quiet_NaN();
    result_.worstAfter = before.worst;
    result_.invalidAfter = before.invalid;
    result_.undecidedAfter = before.undecided;
    result_.nodalWorstAfter = result_.nodalWorstBefore;
    result_.setupSeconds = result_.seconds = since(t0);
    return result_;
  }

  // The setup of run() without quality, with F at every element, for NodeEnergyProbe.
  void prepareProbe() {
    setFrame();
    buildBlocks();
    convertToWorkingSet();
    buildIncidence();
    chooseFreeNodes();
    buildFacets();
    partition();
    changed_.resize(totalElements_);
    for (std::size_t i = 0; i < totalElements_; ++i) changed_[i] = i;
    setEnergyOrder();
    computeGradients();
  }

  bool isFree(std::int64_t node) const {
    return std::binary_search(free_.begin(), free_.end(), node);  // free_ sorted before colour()
  }

  Eigen::VectorXd probeCoordinates(std::int64_t node) const {
    if (slide_[node] == 0) return position_[node];
    return Eigen::Map<const Eigen::VectorXd>(&mesh_.nodeCadParam[2 * node], slide_[node]);
  }

  double probeRegularisation(std::int64_t node) {
    Patch patch;
    return gather(node, patch);
  }

  // The energy of the node's patch with the node at `coordinates`, as visitWith assembles it.
  NodeEnergy probe(std::int64_t node, const Eigen::VectorXd& coordinates, double eps) {
    return functional_detail::dispatch(options_.functional, [&](auto fn) {
      Patch patch;
      gather(node, patch);
      Vec shift;
      if (slide_[node] == 0) {
        shift = coordinates - position_[node];
      } else {
        const double param[2] = {coordinates[0], slide_[node] == 2 ? coordinates[1] : 0.0};
        shift = pointOn(threadCad(), node, param) - position_[node];
      }
      Vec grad;
      Mat hess;
      NodeEnergy out;
      patch.points.shift(shift);
      out.value =
          assemblePatch<D, decltype(fn)::value>(patch.points, eps, grad, hess, &out.magnitude);
      if (slide_[node] != 0 && hasFacets()) {  // as a sweep on a valid mesh has it
        const Vec kept = position_[node];
        position_[node] += shift;
        double size = 0.0;
        const double ef = facetAssemble(node, grad, hess, patch, size);
        position_[node] = kept;
        out.value += ef;
        out.magnitude += size;
      }
      if (slide_[node] == 0) {
        out.gradient = grad;
        out.hessian = hess;
      } else {
        localModel(threadCad(), node, coordinates.data())
            .chainRule(grad, hess, out.gradient, out.hessian);
      }
      return out;
    });
  }

 private:
  Mesh& mesh_;
  const OptimiserOptions& options_;
  OptimiserObserver* observer_;
  Clock::time_point runStart_;

  // Whether the run has taken options_.timeLimit seconds (never, without a limit).
  bool overBudget() {
    if (options_.timeLimit > 0.0 && since(runStart_) >= options_.timeLimit) budgetSpent_ = true;
    return budgetSpent_;
  }
  const CadModel* cad_;                 // null: boundary nodes stay fixed
  const QualitySummary* startQuality_;  // the input's quality, from the caller (may be null)
  // Without CAD the optimiser moves the nodes of the well-conditioned set (kWorkingSet). With
  // CAD it moves the mesh's own (equispaced) nodes, the ones that lie on the CAD, and so it does
  // with a region, where a fixed node of an element at the region's edge would otherwise change
  // its equispaced position with its free neighbours' working nodes.
  const bool converting_;
  bool budgetSpent_ = false;  // set by overBudget(), read after the threads joined
  // Owner-computes split (work_partition.hpp): one part per thread; every phase of a sweep hands
  // an element (a node) to its part's thread first (elementPart_, nodePart_ below).
  int parts_ = 1;
  // Where the mesh was renumbered for locality (optimiseMesh), the caller's numbering; null:
  // the mesh's own. The choices made in sequence follow the caller's numbers: the greedy
  // colouring visits the nodes in the caller's order, a node's elements are listed (and its
  // patch summed) in it, a node shared by elements takes its working position from the caller's
  // last one, and the total energy is summed in it. So the renumbering changes where data lies,
  // never a result, to the last bit.
  // elementRank_: the caller's number of each element (global index). callersNodes_,
  // callersElements_: the node (element) with the caller's number i, walked in order for the
  // caller's order without a sort.
  const std::vector<std::size_t>* elementRank_;
  const std::vector<std::int64_t>* callersNodes_;
  const std::vector<std::size_t>* callersElements_;
  std::vector<CadModel> cadPerThread_;  // evaluation caches are per thread
  std::vector<std::uint8_t> slide_;     // per node: 1 on a CAD curve, 2 on a CAD face, else 0
  std::vector<std::int32_t> cadSlot_;   // per node: its index in cadModel_, -1 if it stays
  // per sliding node: its curve's (face's) model at the parameters it was built at
  std::vector<LocalCadModel<D>> cadModel_;
  // The boundary facets' term (OptimiserOptions::facetWeight); null without it. facetsOn_: the
  // sweeps add it, once the mesh is proven valid.
  std::unique_ptr<FacetEnergy> facetEnergy_;
  bool facetsOn_ = false;
  std::map<int, ParameterRange> curveRange_;
  std::map<int, SurfaceBounds> faceRange_;
  OptimiserResult result_;

  Eigen::Matrix<double, D, 3> frame_;  // rows: the coordinate axes (in 2D, of the plane)
  std::vector<Vec> lockedNormal_;      // per node (in the frame), NaN where free; or empty
  std::vector<Vec> position_;          // node coordinates in the frame, of the working node set
  std::vector<Vec> start_;             // equispaced node coordinates last written to mesh_.xyz
  std::vector<Block<D>> blocks_;
  std::vector<std::size_t> blockOffset_;  // first global element index of each block
  std::size_t totalElements_ = 0;

  std::vector<std::size_t> incidenceStart_;
  std::vector<Incidence> incidence_;
  std::vector<double> nodeSize_;  // size of each node's smallest element (volume^(1/D))

  std::vector<double> scaled_;    // certified lower bound of each element's scaled Jacobian
  std::vector<double> estimate_;  // and an upper bound (from values of J found)
  std::vector<char> tight_;       // scaled_ refined to kJacobianBoundTolerance (see evaluate)
  std::vector<Validity> validity_;
  std::vector<std::size_t> changed_;      // elements with a free node
  std::vector<std::size_t> energyOrder_;  // see setEnergyOrder()
  // Per element: kStale = a node moved since its quality was last computed, kDrifted = since
  // its F was last computed from the nodes. Set by relax() (atomics: threads mark shared
  // elements), cleared by the sweep.
  static constexpr std::uint8_t kStale = 1, kDrifted = 2;
  std::unique_ptr<std::atomic<std::uint8_t>[]> marks_;
  // Per node: visit it in the next sweep (it or a neighbour moved by more than
  // options_.activeTolerance of its element size since its last visit).
  std::unique_ptr<std::atomic<std::uint8_t>[]> active_;
  std::vector<int> elementPart_;  // per global element
  std::vector<int> nodePart_;     // per node
  static constexpr std::uint8_t kFarFromCut = 3;
  std::vector<std::uint8_t> cutDistance_;  // per node, with more than one part (partition())
  std::vector<std::int64_t> free_;         // free nodes, grouped by colour, then by part
  std::vector<std::size_t> colourStart_;   // colour c, part p: [cs[c * parts_ + p], cs[.. + 1])
  std::vector<int> colourOf_;              // colour of each free node, -1 for fixed nodes

  void setFrame() {
    if constexpr (D == 3) {
      frame_.setIdentity();
    } else {
      const Eigen::Vector3d n =
          Eigen::Vector3d(mesh_.planeNormal[0], mesh_.planeNormal[1], mesh_.planeNormal[2])
              .normalized();
      Eigen::Vector3d t1 = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX().cross(n)
                                                 : Eigen::Vector3d::UnitY().cross(n);
      t1.normalize();
      frame_.row(0) = t1.transpose();
      frame_.row(1) = n.cross(t1).transpose();  // t1 x t2 = n: counter-clockwise is positive
    }
    position_.resize(mesh_.numNodes());
    for (std::size_t i = 0; i < mesh_.numNodes(); ++i)
      position_[i] =
          frame_ * Eigen::Vector3d(mesh_.xyz[3 * i], mesh_.xyz[3 * i + 1], mesh_.xyz[3 * i + 2]);
    start_ = position_;
  }

  void buildBlocks() {
    for (const ElementBlock& cells : mesh_.blocks) {
      if (cellDimension(cells.type) != D || cells.count() == 0) continue;
      if (cells.type == CellType::Pyramid)
        throw ParameterError("the optimiser does not support pyramids");
      Block<D> b;
      b.cells = &cells;
      b.nodes = cells.nodesPerElement();
      b.affine = cells.type == CellType::Triangle || cells.type == CellType::Tetrahedron;
      const ReferenceElement& ref = ReferenceElement::get(
          cells.type, cells.order, converting_ ? kWorkingSet : NodeSet::Equispaced);
      const ReferenceElement& equi = ReferenceElement::get(cells.type, cells.order);
      b.toWorking = equi.valuesAt(ref.nodes());
      b.toEquispaced = ref.valuesAt(equi.nodes());
      const ReferenceElement& lin = ReferenceElement::get(cells.type, 1);
      const QuadratureRule rule = energySamples(cells.type, cells.order, equi);
      b.points = rule.size();
      const Eigen::MatrixXd points = pointRows(rule);
      const std::vector<Eigen::MatrixXd> grad = ref.derivativesAt(points);
      const std::vector<Eigen::MatrixXd> linGrad = lin.derivativesAt(points);
      b.gradients.resize(static_cast<std::size_t>(b.points) * b.nodes * D);
      b.gradientTable.resize(b.nodes, static_cast<Eigen::Index>(b.points) * D);
      for (int q = 0; q < b.points; ++q)
        for (int n = 0; n < b.nodes; ++n)
          for (int k = 0; k < D; ++k) {
            const double g = grad[k](q, n);
            b.gradients[(static_cast<std::size_t>(n) * D + k) * b.points + q] = g;
            b.gradientTable(n, static_cast<Eigen::Index>(q) * D + k) = g;
          }
      const int nv = lin.numNodes();
      const std::size_t count = cells.count();
      const int idealPoints = b.affine ? 1 : b.points;
      b.idealInvT.resize(count * idealPoints);
      b.weights.resize(count * b.points);
      b.F.resize(count * D * D * b.points);
      b.J.resize(count * b.points);
      for (std::size_t e = 0; e < count; ++e) {
        const std::int64_t* v = cells.element(e);
        for (int q = 0; q < b.points; ++q) {
          Mat ideal = Mat::Zero();
          for (int n = 0; n < nv; ++n)
            for (int k = 0; k < D; ++k) ideal.col(k) += position_[v[n]] * linGrad[k](q, n);
          const double det = functional_detail::determinant<D>(ideal);
          if (q < idealPoints) {
            if (!(std::abs(det) > 0.0))
              throw ParameterError("element " + std::to_string(callersElement(totalElements_ + e)) +
                                   " (0-based, in block order)"
                                   " has a degenerate straight-sided shape (zero volume): "
                                   "the optimiser cannot measure its distortion");
            b.idealInvT[e * idealPoints + q] = ideal.inverse().transpose();
          }
          b.weights[e * b.points + q] = rule.weights[q] * std::abs(det);
        }
      }
      blockOffset_.push_back(totalElements_);
      totalElements_ += count;
      blocks_.push_back(std::move(b));
    }
    if (blocks_.empty())
      throw ParameterError("the mesh has no elements of dimension " + std::to_string(D) +
                           " to optimise");
  }

  // The caller's number of element `g` (global index), for messages.
  std::size_t callersElement(std::size_t g) const {
    return elementRank_ != nullptr ? (*elementRank_)[g] : g;
  }

  // f(block index, element in the block) for every element, in the caller's order (see
  // elementRank_).
  template <class F>
  void forEachElementInCallersOrder(F f) const {
    if (callersElements_ != nullptr) {
      for (const std::size_t g : *callersElements_) {
        const auto [bi, e] = locate(g);
        f(bi, e);
      }
      return;
    }
    for (std::size_t bi = 0; bi < blocks_.size(); ++bi)
      for (std::size_t e = 0; e < blocks_[bi].cells->count(); ++e) f(bi, e);
  }

  // The same polynomial maps through the working node set's nodes (shared nodes get the same
  // value from every element: the trace on a shared face depends on the face's nodes only).
  void convertToWorkingSet() {
    if (!converting_) return;
    std::vector<Vec> working = position_;
    forEachElementInCallersOrder([&](std::size_t bi, std::size_t e) {
      const Block<D>& b = blocks_[bi];
      const std::int64_t* v = b.cells->element(e);
      for (int i = 0; i < b.nodes; ++i) {
        Vec x = Vec::Zero();
        for (int j = 0; j < b.nodes; ++j) x += b.toWorking(i, j) * position_[v[j]];
        working[v[i]] = x;
      }
    });
    position_.swap(working);
  }

  void buildIncidence() {
    const std::size_t nn = mesh_.numNodes();
    incidenceStart_.assign(nn + 1, 0);
    for (const Block<D>& b : blocks_)
      for (const std::int64_t id : b.cells->nodes) ++incidenceStart_[id + 1];
    for (std::size_t i = 0; i < nn; ++i) incidenceStart_[i + 1] += incidenceStart_[i];
    incidence_.resize(incidenceStart_[nn]);
    // Filled in the caller's element order: each node's elements (and so its patch sums) in it.
    std::vector<std::size_t> fill(incidenceStart_.begin(), incidenceStart_.end() - 1);
    forEachElementInCallersOrder([&](std::size_t bi, std::size_t e) {
      const std::int64_t* v = blocks_[bi].cells->element(e);
      for (int k = 0; k < blocks_[bi].nodes; ++k)
        incidence_[fill[v[k]]++] = {static_cast<int>(bi), k, e};
    });
    nodeSize_.assign(nn, std::numeric_limits<double>::infinity());
    for (const Block<D>& b : blocks_)
      for (std::size_t e = 0; e < b.cells->count(); ++e) {
        double volume = 0.0;
        for (int q = 0; q < b.points; ++q) volume += b.weights[e * b.points + q];
        volume /= 1.0 + kNodeShare;  // the weights add up to (1 + kNodeShare) x the volume
        const double size = std::pow(volume, 1.0 / D);
        const std::int64_t* v = b.cells->element(e);
        for (int k = 0; k < b.nodes; ++k) nodeSize_[v[k]] = std::min(nodeSize_[v[k]], size);
      }
  }

  std::size_t globalIndex(const Incidence& inc) const {
    return blockOffset_[inc.block] + inc.element;
  }

  // The block and the element within it of global element g.
  std::pair<std::size_t, std::size_t> locate(std::size_t g) const {
    const auto bi = static_cast<std::size_t>(
        std::upper_bound(blockOffset_.begin(), blockOffset_.end(), g) - blockOffset_.begin() - 1);
    return {bi, g - blockOffset_[bi]};
  }

  // Elements whose nodes may move: all, or the poor (or seeded) ones and `regionLayers` layers
  // around them.
  std::vector<char> region() {
    std::vector<char> in(totalElements_, 1);
    const std::vector<char>& seed = options_.regionSeed;
    if (!options_.regionThreshold && seed.empty()) return in;
    if (!seed.empty() && seed.size() != totalElements_)
      throw ParameterError("the optimiser's region seed has " + std::to_string(seed.size()) +
                           " entries for " + std::to_string(totalElements_) + " elements");
    for (std::size_t i = 0; i < totalElements_; ++i)
      in[i] = (!seed.empty() && seed[i] != 0) ||
                      (options_.regionThreshold && scaled_[i] < *options_.regionThreshold) ||
                      validity_[i] != Validity::Valid
                  ? 1
                  : 0;
    for (int layer = 0; layer < options_.regionLayers; ++layer) {
      std::vector<char> grown = in;
      for (std::size_t node = 0; node + 1 < incidenceStart_.size(); ++node) {
        bool any = false;
        for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1] && !any; ++k)
          any = in[globalIndex(incidence_[k])] != 0;
        if (!any) continue;
        for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k)
          grown[globalIndex(incidence_[k])] = 1;
      }
      in.swap(grown);
    }
    return in;
  }

  void chooseFreeNodes() {
    std::vector<const ElementBlock*> cells;
    for (const Block<D>& b : blocks_) cells.push_back(b.cells);
    std::vector<char> boundary = boundaryNodes(mesh_.numNodes(), cells, !options_.freeInterfaces);
    // Nodes of lower-dimensional cells (boundary faces and curves a file names) stay too, unless
    // they are inside the domain and interfaces are free.
    if (!options_.freeInterfaces)
      for (const ElementBlock& lower : mesh_.blocks)
        if (cellDimension(lower.type) < D)
          for (const std::int64_t id : lower.nodes) boundary[id] = 1;
    const std::vector<char> in = region();
    result_.regionElements =
        static_cast<std::size_t>(std::count(in.begin(), in.end(), static_cast<char>(1)));
    chooseSlidingNodes(boundary);
    if (!options_.fixedNodes.empty()) {
      if (options_.fixedNodes.size() != mesh_.numNodes())
        throw ParameterError("the optimiser's fixed-node mask has " +
                             std::to_string(options_.fixedNodes.size()) + " entries for " +
                             std::to_string(mesh_.numNodes()) + " nodes");
      for (std::size_t node = 0; node < mesh_.numNodes(); ++node)
        if (options_.fixedNodes[node] != 0) boundary[node] = 1;
    }
    if (!options_.normalLocked.empty()) {
      if (options_.normalLocked.size() != 3 * mesh_.numNodes())
        throw ParameterError("the optimiser's locked normals have " +
                             std::to_string(options_.normalLocked.size()) + " entries for " +
                             std::to_string(mesh_.numNodes()) + " nodes (3 each)");
      lockedNormal_.assign(mesh_.numNodes(), Vec::Constant(std::nan("")));
      for (std::size_t node = 0; node < mesh_.numNodes(); ++node) {
        const Eigen::Vector3d n(&options_.normalLocked[3 * node]);
        const Vec local = frame_ * n;
        if (n.allFinite() && local.norm() > 0.0) lockedNormal_[node] = local.normalized();
      }
    }
    std::vector<char> touched(totalElements_, 0);  // the element contains a free node
    for (std::size_t node = 0; node < mesh_.numNodes(); ++node) {
      if (boundary[node] != 0 || incidenceStart_[node] == incidenceStart_[node + 1]) continue;
      bool inRegion = false;
      for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k)
        inRegion = inRegion || in[globalIndex(incidence_[k])] != 0;
      if (!inRegion) continue;
      free_.push_back(static_cast<std::int64_t>(node));
      for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k)
        touched[globalIndex(incidence_[k])] = 1;
    }
    result_.freeNodes = free_.size();
    for (std::size_t i = 0; i < totalElements_; ++i)
      if (touched[i] != 0) changed_.push_back(i);
    setEnergyOrder();
  }

  // The boundary facets of the free sliding nodes (facet_energy.hpp), in 3D with a facet weight.
  void buildFacets() {
    facetEnergy_.reset();
    if constexpr (D == 3) {
      if (!(options_.facetWeight > 0.0) || cad_ == nullptr) return;
      std::vector<std::uint8_t> movable(mesh_.numNodes(), 0);
      bool any = false;
      for (const std::int64_t node : free_)
        if (slide_[static_cast<std::size_t>(node)] != 0) {
          movable[static_cast<std::size_t>(node)] = 1;
          any = true;
        }
      if (!any) return;
      facetEnergy_ = std::make_unique<FacetEnergy>(mesh_, position_, movable, options_.facetWeight);
      if (facetEnergy_->empty()) facetEnergy_.reset();
    }
  }

  // With CAD: nodes on a CAD curve (face, in 3D) move along it in t ((u, v)), nodes inside the
  // domain move freely, CAD vertices stay; nodes without a CAD record keep the topological rule.
  void chooseSlidingNodes(std::vector<char>& boundary) {
    slide_.assign(mesh_.numNodes(), 0);
    if (cad_ == nullptr) return;
    for (std::size_t node = 0; node < mesh_.numNodes(); ++node) {
      const int dim = mesh_.nodeCadDim[node];
      const int index = mesh_.nodeCadIndex[node];
      if (index <= 0) continue;
      const double p0 = mesh_.nodeCadParam[2 * node], p1 = mesh_.nodeCadParam[2 * node + 1];
      if (dim == 0) {
        boundary[node] = 1;
      } else if (dim == 1 && std::isfinite(p0) && index <= cad_->numEdges() &&
                 !cad_->isDegenerated(index)) {
        slide_[node] = 1;
        boundary[node] = 0;
        if (curveRange_.count(index) == 0) curveRange_[index] = cad_->edgeRange(index);
      } else if (dim == 2 && D == 3 && std::isfinite(p0) && std::isfinite(p1) &&
                 index <= cad_->numFaces()) {
        slide_[node] = 2;
        boundary[node] = 0;
        if (faceRange_.count(index) == 0) faceRange_[index] = cad_->faceBounds(index);
      }
    }
    cadSlot_.assign(mesh_.numNodes(), -1);
    std::int32_t slots = 0;
    for (std::size_t node = 0; node < mesh_.numNodes(); ++node)
      if (slide_[node] != 0) cadSlot_[node] = slots++;
    cadModel_.assign(static_cast<std::size_t>(slots), LocalCadModel<D>{});
    if (slots > 0)
      for (int t = 0; t < options_.threads; ++t) cadPerThread_.push_back(cad_->clone());
  }

  // Greedy colouring of the free nodes: two nodes sharing an element get different colours.
  void colour() {
    std::vector<int> colourOf(mesh_.numNodes(), -1);
    colourOf_.assign(mesh_.numNodes(), -1);
    std::vector<std::size_t> stamp;  // stamp[c] == node + 1: colour c is taken by a neighbour
    int colours = 0;
    std::vector<std::int64_t> visit = free_;  // free_ is sorted (chooseFreeNodes)
    if (callersNodes_ != nullptr) {
      std::vector<char> isFree(mesh_.numNodes(), 0);
      for (const std::int64_t node : free_) isFree[static_cast<std::size_t>(node)] = 1;
      visit.clear();
      for (const std::int64_t node : *callersNodes_)
        if (isFree[static_cast<std::size_t>(node)] != 0) visit.push_back(node);
    }
    for (const std::int64_t node : visit) {
      for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k) {
        const Incidence& inc = incidence_[k];
        const std::int64_t* v = blocks_[inc.block].cells->element(inc.element);
        for (int j = 0; j < blocks_[inc.block].nodes; ++j)
          if (const int c = colourOf[v[j]]; c >= 0) stamp[c] = static_cast<std::size_t>(node) + 1;
      }
      int c = 0;
      while (c < colours && stamp[c] == static_cast<std::size_t>(node) + 1) ++c;
      if (c == colours) {
        ++colours;
        stamp.push_back(0);
      }
      colourOf[node] = c;
      colourOf_[node] = c;
    }
    std::vector<std::vector<std::int64_t>> groups(colours);
    for (const std::int64_t node : free_) groups[colourOf[node]].push_back(node);
    free_ = groupByColourAndPart(groups, colourStart_);
    result_.colours = static_cast<std::size_t>(colours);
  }

  // The nodes of each colour group, each group's ordered by part (stable); `starts` gets the
  // ranges: colour c, part p is [starts[c * parts_ + p], starts[c * parts_ + p + 1]).
  std::vector<std::int64_t> groupByColourAndPart(
      const std::vector<std::vector<std::int64_t>>& groups,
      std::vector<std::size_t>& starts) const {
    std::vector<std::int64_t> nodes;
    starts.assign(1, 0);
    std::vector<std::size_t> begin;
    for (const auto& g : groups) {
      std::vector<std::int64_t> byPart = groupByPart(
          g, parts_, [&](std::int64_t n) { return nodePart_[static_cast<std::size_t>(n)]; }, begin);
      // Each part's nodes from its interior to the cut: its thread takes them from the front,
      // a thread helping it from the back (OwnerFirstQueue), where the nodes' elements are the
      // ones the two threads share already. A colour's nodes share no element: their order
      // changes no result.
      if (parts_ > 1)
        for (std::size_t p = 0; p + 1 < begin.size(); ++p)
          std::stable_sort(byPart.begin() + static_cast<std::ptrdiff_t>(begin[p]),
                           byPart.begin() + static_cast<std::ptrdiff_t>(begin[p + 1]),
                           [&](std::int64_t a, std::int64_t b) {
                             return cutDistance_[static_cast<std::size_t>(a)] >
                                    cutDistance_[static_cast<std::size_t>(b)];
                           });
      const std::size_t base = nodes.size();
      nodes.insert(nodes.end(), byPart.begin(), byPart.end());
      for (std::size_t p = 1; p < begin.size(); ++p) starts.push_back(base + begin[p]);
    }
    return nodes;
  }

  // The positions in changed_ in the caller's order of their elements, for totalEnergy().
  void setEnergyOrder() {
    energyOrder_.resize(changed_.size());
    std::iota(energyOrder_.begin(), energyOrder_.end(), std::size_t{0});
    if (callersElements_ == nullptr) return;
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> position(totalElements_, kNone);  // in changed_
    for (std::size_t i = 0; i < changed_.size(); ++i) position[changed_[i]] = i;
    energyOrder_.clear();
    for (const std::size_t g : *callersElements_)
      if (position[g] != kNone) energyOrder_.push_back(position[g]);
  }

  // One part per thread, by recursive coordinate bisection of the elements' centroids weighted
  // by their energy points (elements without a free node weigh nothing: no node visit or
  // refresh of F touches them); a node belongs to the part of most of its elements.
  void partition() {
    parts_ = options_.threads;
    elementPart_.assign(totalElements_, 0);
    nodePart_.assign(mesh_.numNodes(), 0);
    if (parts_ == 1) return;
    std::vector<char> moves(totalElements_, 0);
    for (const std::size_t g : changed_) moves[g] = 1;
    std::vector<std::array<double, 3>> centroid(totalElements_);
    std::vector<double> weight(totalElements_, 0.0);
    for (std::size_t bi = 0; bi < blocks_.size(); ++bi) {
      const Block<D>& b = blocks_[bi];
      for (std::size_t e = 0; e < b.cells->count(); ++e) {
        const std::size_t g = blockOffset_[bi] + e;
        const std::int64_t* v = b.cells->element(e);
        std::array<double, 3> c{0.0, 0.0, 0.0};
        for (int k = 0; k < b.nodes; ++k)
          for (int i = 0; i < 3; ++i) c[i] += mesh_.xyz[3 * v[k] + i] / b.nodes;
        centroid[g] = c;
        if (moves[g] != 0) weight[g] = b.points;
      }
    }
    elementPart_ = bisectByCoordinates(centroid, weight, parts_);
    nodePart_ = nodeOwners(mesh_.numNodes(), parts_, [&](std::size_t n, auto add) {
      for (std::size_t k = incidenceStart_[n]; k < incidenceStart_[n + 1]; ++k)
        add(elementPart_[globalIndex(incidence_[k])]);
    });
    measureCutDistance();
  }

  // Each node's distance from the cut between the parts, in element layers: 0 for a node of an
  // element whose nodes (or the element itself) belong to more than one part, kFarFromCut
  // beyond kFarFromCut - 1 (the search stops there: its cost stays with the cut's
  // neighbourhood).
  void measureCutDistance() {
    cutDistance_.assign(mesh_.numNodes(), kFarFromCut);
    std::vector<std::int64_t> frontier, next;
    for (std::size_t bi = 0; bi < blocks_.size(); ++bi) {
      const Block<D>& b = blocks_[bi];
      for (std::size_t e = 0; e < b.cells->count(); ++e) {
        const std::int64_t* v = b.cells->element(e);
        bool mixed = elementPart_[blockOffset_[bi] + e] != nodePart_[v[0]];
        for (int k = 1; k < b.nodes && !mixed; ++k) mixed = nodePart_[v[k]] != nodePart_[v[0]];
        if (!mixed) continue;
        for (int k = 0; k < b.nodes; ++k)
          if (cutDistance_[v[k]] != 0) {
            cutDistance_[v[k]] = 0;
            frontier.push_back(v[k]);
          }
      }
    }
    // An element scanned once has every node at most at that layer: never scanned again (a
    // frontier node's elements are mostly another frontier node's too).
    std::vector<char> scanned(totalElements_, 0);
    for (std::uint8_t layer = 1; layer < kFarFromCut && !frontier.empty(); ++layer) {
      next.clear();
      for (const std::int64_t n : frontier)
        for (std::size_t k = incidenceStart_[n]; k < incidenceStart_[n + 1]; ++k) {
          if (std::exchange(scanned[globalIndex(incidence_[k])], 1) != 0) continue;
          const Block<D>& b = blocks_[incidence_[k].block];
          const std::int64_t* v = b.cells->element(incidence_[k].element);
          for (int j = 0; j < b.nodes; ++j)
            if (cutDistance_[v[j]] == kFarFromCut) {
              cutDistance_[v[j]] = layer;
              next.push_back(v[j]);
            }
        }
      frontier.swap(next);
    }
  }

  // body(i, thread) for every i < elements.size(), on the threads: element elements[i] goes to
  // its part's thread first (OwnerFirstQueue), where its F and nodes were last written; before
  // the partition exists (the input's quality), to any thread. The first exception is rethrown
  // after the loop.
  template <class Body>
  void forEachOwned(const std::vector<std::size_t>& elements, std::size_t chunk, Body body) const {
    std::vector<std::size_t> position(elements.size()), begin;
    for (std::size_t i = 0; i < position.size(); ++i) position[i] = i;
    const bool split = !elementPart_.empty();
    position = groupByPart(
        position, split ? parts_ : 1,
        [&](std::size_t i) { return split ? elementPart_[elements[i]] : 0; }, begin);
    OwnerFirstQueue queue(std::move(begin), chunk);
    FirstFailure failure;
#pragma omp parallel num_threads(options_.threads)
    {
      const int me = omp_get_thread_num();
      std::size_t lo = 0, hi = 0;
      while (queue.next(me, lo, hi))
        for (std::size_t k = lo; k < hi; ++k) {
          try {
            body(position[k], me);
          } catch (...) {
            failure.capture();
          }
        }
    }
    failure.rethrow();
  }

  // F and J at every quadrature point of the given elements (global indices; by default every
  // element that contains a free node): one matrix product per element (its node coordinates
  // times the tabulated basis gradients).
  void computeGradients() {
    computeGradients(changed_);
  }
  void computeGradients(const std::vector<std::size_t>& elements) {
    // One cache line or more per thread: resizing writes a matrix's header, and headers of two
    // threads in one line would move it between the CPUs at every element.
    struct alignas(64) Scratch {
      Eigen::Matrix<double, D, Eigen::Dynamic> x, dx;
    };
    std::vector<Scratch> scratch(static_cast<std::size_t>(options_.threads));
    forEachOwned(elements, 16, [&](std::size_t i, int thread) {
      auto& x = scratch[static_cast<std::size_t>(thread)].x;
      auto& dx = scratch[static_cast<std::size_t>(thread)].dx;
      const auto [bi, e] = locate(elements[i]);
      Block<D>& b = blocks_[bi];
      const std::int64_t* v = b.cells->element(e);
      x.resize(D, b.nodes);
      for (int n = 0; n < b.nodes; ++n) x.col(n) = position_[v[n]];
      dx.noalias() = x * b.gradientTable;
      for (int q = 0; q < b.points; ++q) {
        const Mat F =
            dx.template middleCols<D>(static_cast<Eigen::Index>(q) * D) * b.invT(e, q).transpose();
        for (int k = 0; k < D * D; ++k) b.componentF(e, k)[q] = F(k % D, k / D);
        b.J[e * b.points + q] = functional_detail::determinant<D>(F);
      }
    });
  }

  // The quadrature points of a node's elements (NodePatch), and where each element's run of
  // points came from, to write an accepted move back.
  struct Patch {
    struct Run {
      Block<D>* block;
      std::size_t element;
      std::size_t first;  // in `points`
    };
    NodePatch<D> points;
    std::vector<Run> runs;
    FacetEnergy::Patch facets;  // the node's boundary facets, when it slides (facetEnergy_)
    std::size_t slides = 0, cadEvaluations = 0;  // sliding visits, CAD evaluations
  };

  // The Newton step -H^-1 g with H shifted to be positive definite (smallest eigenvalue at least
  // 1e-8 of the largest), and its slope g . step; false when there is no descent direction.
  template <class M, class V>
  static bool newtonStep(M h, const V& g, V& step, double& slope) {
    Eigen::SelfAdjointEigenSolver<M> eig;
    if constexpr (M::RowsAtCompileTime == Eigen::Dynamic) {
      eig.compute(h, Eigen::EigenvaluesOnly);
    } else {
      eig.computeDirect(h, Eigen::EigenvaluesOnly);
    }
    const double lmin = eig.eigenvalues().minCoeff();
    const double lmax = eig.eigenvalues().cwiseAbs().maxCoeff();
    if (!(lmax > 0.0)) return false;
    const double floor = 1e-8 * lmax;
    if (lmin < floor) h.diagonal().array() += floor - lmin;
    step = -h.ldlt().solve(g);
    slope = g.dot(step);
    return slope < 0.0 && step.allFinite();
  }

  // F += d a^T and, by the matrix determinant lemma, J += g . d at every point of the patch, in
  // the blocks' own arrays.
  static void applyMove(Patch& patch, const Vec& d) {
    const NodePatch<D>& pts = patch.points;
    for (const typename Patch::Run& run : patch.runs) {
      Block<D>& b = *run.block;
      const auto n = static_cast<std::size_t>(b.points);
      for (int k = 0; k < D * D; ++k) {
        double* f = b.componentF(run.element, k);
        const double* a = pts.a(k / D) + run.first;
        const double dr = d[k % D];
        for (std::size_t q = 0; q < n; ++q) f[q] += dr * a[q];
      }
      double* J = &b.J[run.element * n];
      for (int c = 0; c < D; ++c) {
        const double* g = pts.g(c) + run.first;
        const double dc = d[c];
        for (std::size_t q = 0; q < n; ++q) J[q] += g[q] * dc;
      }
    }
  }

  // The patch of a node: F, a and the weight at every quadrature point of its elements. Returns
  // the regularisation the patch needs (DESIGN.md section 6: sizeable only where it is inverted).
  double gather(std::int64_t node, Patch& patch) {
    std::size_t total = 0;
    for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k)
      total += static_cast<std::size_t>(blocks_[incidence_[k].block].points);
    NodePatch<D>& pts = patch.points;
    pts.reset(total);
    patch.runs.clear();
    double jmin = std::numeric_limits<double>::infinity();
    for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k) {
      const Incidence& inc = incidence_[k];
      Block<D>& b = blocks_[inc.block];
      const std::size_t e = inc.element;
      const auto n = static_cast<std::size_t>(b.points);
      const std::size_t first = pts.append(n, b.componentF(e, 0), n);
      patch.runs.push_back({&b, e, first});
      std::copy_n(&b.weights[e * n], n, pts.weight() + first);
      const double* J = &b.J[e * n];
      for (std::size_t q = 0; q < n; ++q) jmin = std::min(jmin, J[q]);
      // a = (dx_I/dxi)^-T grad_xi l_node at every point.
      const double* grad[D];
      for (int c = 0; c < D; ++c) grad[c] = b.gradient(inc.local, c);
      for (int r = 0; r < D; ++r) {
        double* a = pts.a(r) + first;
        if (b.affine) {
          const Mat& m = b.idealInvT[e];
          for (std::size_t q = 0; q < n; ++q) {
            double v = 0.0;
            for (int c = 0; c < D; ++c) v += m(r, c) * grad[c][q];
            a[q] = v;
          }
        } else {
          for (std::size_t q = 0; q < n; ++q) {
            const Mat& m = b.invT(e, static_cast<int>(q));
            double v = 0.0;
            for (int c = 0; c < D; ++c) v += m(r, c) * grad[c][q];
            a[q] = v;
          }
        }
      }
    }
    return jmin < 0.0 ? std::sqrt(1e-8 + 0.04 * jmin * jmin) : 1e-10;
  }

  // Whether a step whose quadratic model lowers the energy by -slope / 2 can show at all in the
  // patch energy, a sum of pts.size() terms of total size `magnitude`: its rounding is about
  // sqrt(n) u magnitude (random-walk model, u the unit roundoff), so a smaller decrease is
  // noise and the Armijo test would only halve the step until it gives up.
  static bool resolvable(double slope, double magnitude, std::size_t points) {
    constexpr double u = std::numeric_limits<double>::epsilon() / 2.0;
    return -0.5 * slope > 4.0 * std::sqrt(static_cast<double>(points)) * u * magnitude;
  }

  // One Newton step on one node; returns the distance it moved.
  double visit(std::int64_t node, Patch& patch) {
    return functional_detail::dispatch(
        options_.functional, [&](auto fn) { return visitWith<decltype(fn)::value>(node, patch); });
  }

  template <Functional Fn>
  double visitWith(std::int64_t node, Patch& patch) {
    const double eps = gather(node, patch);
    Vec grad;
    Mat hess;
    double magnitude = 0.0;
    const double e0 = assemblePatch<D, Fn>(patch.points, eps, grad, hess, &magnitude);
    if (!std::isfinite(e0) || !grad.allFinite() || !hess.allFinite()) return 0.0;
    if (slide_[node] != 0) return slide<Fn>(node, patch, eps, e0, magnitude, grad, hess);
    const std::size_t points = patch.points.size();
    Vec step;
    double slope = 0.0;
    if (!lockedNormal_.empty() && lockedNormal_[node].allFinite()) {
      // Newton in the plane perpendicular to the locked direction.
      const Vec n = lockedNormal_[node];
      Eigen::Matrix<double, D, D - 1> t;
      if constexpr (D == 2) {
        t.col(0) = Vec(-n(1), n(0));
      } else {
        const Vec a = std::abs(n(0)) < 0.9 ? Vec::UnitX() : Vec::UnitY();
        t.col(0) = n.cross(a).normalized();
        t.col(1) = n.cross(Vec(t.col(0)));
      }
      const Eigen::Matrix<double, D - 1, 1> g = t.transpose() * grad;
      Eigen::Matrix<double, D - 1, 1> s;
      if (!newtonStep(Eigen::Matrix<double, D - 1, D - 1>(t.transpose() * hess * t), g, s, slope) ||
          !resolvable(slope, magnitude, points))
        return 0.0;
      step = t * s;
    } else if (!newtonStep(hess, grad, step, slope) || !resolvable(slope, magnitude, points)) {
      return 0.0;
    }
    double alpha = 1.0;
    for (int ls = 0; ls < kLineSearchSteps; ++ls, alpha *= 0.5) {
      const Vec d = alpha * step;
      if (patchEnergyAfter<D, Fn>(patch.points, d, eps) <= e0 + kArmijo * alpha * slope) {
        position_[node] += d;
        applyMove(patch, d);
        return d.norm();
      }
    }
    return 0.0;
  }

  // The CAD model of the calling thread (OCCT's evaluators cache state).
  const CadModel& threadCad() const {
    return cadPerThread_[static_cast<std::size_t>(omp_get_thread_num())];
  }

  // The point (in the frame) of a sliding node at parameters `param` (t, or (u, v)).
  Vec pointOn(const CadModel& cad, std::int64_t node, const double* param) const {
    const int entity = mesh_.nodeCadIndex[node];
    if (slide_[node] == 1) return frame_ * cad.evaluateCurve(entity, param[0]).point;
    return frame_ * cad.evaluateSurface(entity, param[0], param[1]).point;
  }

  // The second-order model of the node's curve (face) at parameters `param` (t, or (u, v)).
  LocalCadModel<D> localModel(const CadModel& cad, std::int64_t node, const double* param) const {
    const int entity = mesh_.nodeCadIndex[node];
    LocalCadModel<D> m =
        slide_[node] == 1
            ? LocalCadModel<D>::curve(cad.evaluateCurve(entity, param[0]), frame_)
            : LocalCadModel<D>::surface(cad.evaluateSurface(entity, param[0], param[1]), frame_);
    m.at0[0] = param[0];
    m.at0[1] = slide_[node] == 1 ? 0.0 : param[1];
    return m;
  }

  // The model at the node's current parameters: the one its last accepted step left (the CAD
  // evaluation of that step gave the derivatives too), else a fresh evaluation. Counts the
  // evaluations in `patch`.
  const LocalCadModel<D>& currentModel(const CadModel& cad, std::int64_t node, Patch& patch) {
    const double* param = &mesh_.nodeCadParam[2 * node];
    LocalCadModel<D>& m = cadModel_[static_cast<std::size_t>(cadSlot_[node])];
    const bool current =
        m.parameters != 0 && m.at0[0] == param[0] && (slide_[node] == 1 || m.at0[1] == param[1]);
    if (!current) {
      m = localModel(cad, node, param);
      ++patch.cadEvaluations;
    }
    return m;
  }

  // A Newton step of a node on a CAD curve (face) in its parameter t ((u, v)), then a
  // backtracking line search. The full step is evaluated on the CAD (it is accepted at about 98
  // % of visits); the shorter trial points lie on the curve's (face's) second-order model at the
  // node (cad_local_model.hpp), and the one the model accepts is evaluated on the CAD and kept if
  // it passes the same test there. So the node never leaves the CAD, and the accepted
  // evaluation's derivatives are the node's model for its next visit: about one CAD evaluation
  // per visit. Where the model misled (its point passed, the CAD's did not), the search goes on
  // with exact points.
  template <Functional Fn>
  double slide(std::int64_t node, Patch& patch, double eps, double e0, double magnitude,
               const Vec& grad, const Mat& hess) {
    try {
      return slideOn<Fn>(threadCad(), node, patch, eps, e0, magnitude, grad, hess);
    } catch (const CadError&) {
      return 0.0;  // the CAD cannot be evaluated there (a degenerate point): the node stays
    }
  }

  bool hasFacets() const {
    return facetEnergy_ != nullptr;
  }
  void switchFacetsOn() {
    facetsOn_ = true;
    if constexpr (D == 3)
      for (const std::int64_t node : free_)
        if (facetEnergy_->touches(node)) active_[node].store(1, std::memory_order_relaxed);
  }
  // The facet term of `node` added to grad and hess (facet_energy.hpp); fills patch.facets.
  double facetAssemble(std::int64_t node, Vec& grad, Mat& hess, Patch& patch, double& size) const {
    if constexpr (D == 3) {
      return facetEnergy_->assemble(node, position_, grad, hess, patch.facets, &size);
    } else {
      return 0.0;
    }
  }
  static double facetAfter(const Patch& patch, const Vec& d) {
    if constexpr (D == 3) {
      return FacetEnergy::energyAfter(patch.facets, d);
    } else {
      return 0.0;
    }
  }

  template <Functional Fn>
  double slideOn(const CadModel& cad, std::int64_t node, Patch& patch, double eps,
                 double volumeEnergy, double magnitude, const Vec& volumeGrad,
                 const Mat& volumeHess) {
    double* param = &mesh_.nodeCadParam[2 * node];
    const int entity = mesh_.nodeCadIndex[node];
    ++patch.slides;
    const LocalCadModel<D>& model = currentModel(cad, node, patch);
    // The boundary facets' term joins the volume patch's once the mesh is valid (facetsOn_).
    double e0 = volumeEnergy;
    Vec grad = volumeGrad;
    Mat hess = volumeHess;
    const bool facets = facetsOn_ && hasFacets();
    if (facets) {
      double size = 0.0;
      const double ef = facetAssemble(node, grad, hess, patch, size);
      if (!std::isfinite(ef)) return 0.0;
      e0 += ef;
      magnitude += size;
    }
    const auto energyAfter = [&](const Vec& d) {
      const double e = patchEnergyAfter<D, Fn>(patch.points, d, eps);
      return facets ? e + facetAfter(patch, d) : e;
    };
    Eigen::VectorXd g;
    Eigen::MatrixXd h;
    model.chainRule(grad, hess, g, h);
    if (!g.allFinite() || !h.allFinite()) return 0.0;
    Eigen::VectorXd step;
    double slope = 0.0;
    if (!newtonStep(h, g, step, slope) || !resolvable(slope, magnitude, patch.points.size()))
      return 0.0;
    bool exact = false;  // set once the model has misled the search at this node
    // The model's error seen at the full step (the CAD's point is known there) and that step's
    // length in parameters: the error shrinks like the cube of the step (cad_local_model.hpp).
    double fullError = 0.0, fullStep = 0.0;
    double alpha = 1.0;
    for (int ls = 0; ls < kLineSearchSteps; ++ls, alpha *= 0.5) {
      double trial[2] = {param[0], param[1]};
      if (slide_[node] == 1) {
        const ParameterRange& r = curveRange_.at(entity);
        trial[0] = std::clamp(param[0] + alpha * step[0], r.first, r.last);
      } else {
        const SurfaceBounds& b = faceRange_.at(entity);
        trial[0] = std::clamp(param[0] + alpha * step[0], b.uMin, b.uMax);
        trial[1] = std::clamp(param[1] + alpha * step[1], b.vMin, b.vMax);
      }
      const double bound = e0 + kArmijo * alpha * slope;
      const double dp[2] = {trial[0] - param[0], trial[1] - param[1]};
      if (ls > 0 && !exact) {
        // Rejected on the model only when it misses the bound by more than the model's error
        // can change the energy: (|grad| + |hess| |d|) times twice the cubic scaling of the
        // error at the full step, so that borderline points are decided on the CAD.
        const Vec d = model.at(dp) - position_[node];
        const double r = std::min(1.0, std::hypot(dp[0], dp[1]) / fullStep);
        const double slack = (grad.norm() + hess.norm() * d.norm()) * 2.0 * fullError * r * r * r;
        if (!(energyAfter(d) <= bound + slack)) continue;
      }
      ++patch.cadEvaluations;
      LocalCadModel<D> next = localModel(cad, node, trial);
      const Vec d = next.point - position_[node];
      if (energyAfter(d) <= bound) {
        position_[node] = next.point;
        param[0] = trial[0];
        param[1] = trial[1];
        applyMove(patch, d);
        cadModel_[static_cast<std::size_t>(cadSlot_[node])] = next;
        return d.norm();
      }
      if (ls == 0) {
        fullError = (next.point - model.at(dp)).norm();
        fullStep = std::hypot(dp[0], dp[1]);
      }
      exact = ls > 0;
    }
    return 0.0;
  }

  // The largest node move of a pass, absolute and relative to the node's element size, and the
  // number of nodes visited.
  struct Moves {
    double absolute = 0.0, relative = 0.0;
    std::size_t visits = 0;
    std::size_t slides = 0, cadEvaluations = 0;  // see Patch
    // Adds another pass's counts (not its moves: a sweep's displacement is its first pass's).
    void addCounts(const Moves& m) {
      visits += m.visits;
      slides += m.slides;
      cadEvaluations += m.cadEvaluations;
    }
  };
  // What the current sweep's passes moved before the time limit stopped one (relax(), read by
  // keepPartialSweep()).
  Moves interrupted_;

  // The record of sweep `it` from what it moved (added to the run's totals), its energy left to
  // the caller.
  IterationRecord sweepRecord(int it, const Moves& moved, Clock::time_point t0) {
    IterationRecord record = summarise(it, moved.absolute, t0);
    record.maxRelativeMove = moved.relative;
    record.visits = moved.visits;
    result_.visits += moved.visits;
    result_.slides += moved.slides;
    result_.cadEvaluations += moved.cadEvaluations;
    return record;
  }

  // After a node's visit: mark the elements it moved, and decide which nodes the next sweep
  // visits. A node that did not move by more than activeTolerance of its element size rests
  // until a node of one of its elements moves by more; a node is never marked by another of its
  // own colour (they share no element), so the result does not depend on the thread count.
  void record(std::int64_t node, double relative) {
    const bool moved = relative > 0.0;
    const bool wakes = relative > options_.activeTolerance;
    // Loads before stores: the flags mostly hold their value already, and a store (even of the
    // same value) takes the cache line from the other threads working on neighbouring nodes.
    if (const std::uint8_t want = wakes ? 1 : 0;
        active_[node].load(std::memory_order_relaxed) != want)
      active_[node].store(want, std::memory_order_relaxed);
    if (!moved) return;
    constexpr std::uint8_t both = kStale | kDrifted;
    for (std::size_t k = incidenceStart_[node]; k < incidenceStart_[node + 1]; ++k) {
      const Incidence& inc = incidence_[k];
      std::atomic<std::uint8_t>& mark = marks_[globalIndex(inc)];
      if ((mark.load(std::memory_order_relaxed) & both) != both)
        mark.fetch_or(both, std::memory_order_relaxed);
      if (!wakes) continue;
      const Block<D>& b = blocks_[inc.block];
      const std::int64_t* v = b.cells->element(inc.element);
      for (int j = 0; j < b.nodes; ++j)
        if (active_[v[j]].load(std::memory_order_relaxed) == 0)
          active_[v[j]].store(1, std::memory_order_relaxed);
    }
  }

  // One Newton step on each of `nodes` (grouped by colour and part: see groupByColourAndPart);
  // with `onlyActive`, on those of them that are active (see record()). A colour group's nodes
  // go to their part's thread first.
  Moves relax(const std::vector<std::int64_t>& nodes, const std::vector<std::size_t>& starts,
              bool onlyActive) {
    double moved = 0.0, relative = 0.0;
    std::size_t visits = 0, slides = 0, cadEvaluations = 0;
    FirstFailure failure;
    const auto colours = static_cast<std::int64_t>((starts.size() - 1) / parts_);
    std::vector<OwnerFirstQueue> queues;
    queues.reserve(static_cast<std::size_t>(colours));
    for (std::int64_t c = 0; c < colours; ++c) {
      const auto first = starts.begin() + c * parts_;
      queues.emplace_back(std::vector<std::size_t>(first, first + parts_ + 1), 8);
    }
    // A sweep of a large high-order mesh takes seconds: a cancel request (or the time limit) is
    // honoured between colour groups, asked once for the team by the thread that completes a
    // group's barrier, so that every thread leaves the loop together.
    const bool observed = observer_ != nullptr || options_.timeLimit > 0.0;
    bool cancel = false;  // shared: written before a barrier releases, read after it
    const auto askToStop = [&] {
      if (!observed) return;
      try {
        cancel = (observer_ != nullptr && observer_->cancelRequested()) || overBudget();
      } catch (...) {  // an observer's own failure ends the sweep and is rethrown below
        failure.capture();
        cancel = true;
      }
    };
    std::optional<TeamBarrier> barrier;  // for the team OpenMP starts (it may be smaller)
#pragma omp parallel num_threads(options_.threads) reduction(max : moved, relative) \
    reduction(+ : visits, slides, cadEvaluations)
    {
      Patch patch;
      const int me = omp_get_thread_num();
#pragma omp single
      {
        barrier.emplace(omp_get_num_threads());
        askToStop();
      }
      for (std::int64_t c = 0; c < colours && !cancel; ++c) {
        std::size_t lo = 0, hi = 0;
        while (queues[static_cast<std::size_t>(c)].next(me, lo, hi))
          for (std::size_t i = lo; i < hi; ++i) {
            try {
              if (onlyActive && active_[nodes[i]].load(std::memory_order_relaxed) == 0) continue;
              const double d = visit(nodes[i], patch);
              ++visits;
              moved = std::max(moved, d);
              relative = std::max(relative, d / nodeSize_[nodes[i]]);
              record(nodes[i], d / nodeSize_[nodes[i]]);
            } catch (...) {
              failure.capture();
            }
          }
        // The colour's moves reach every thread before the next colour starts; a colour
        // group is short (about a millisecond at order 2), so a thread that waits longer than
        // the barrier's brief spin sleeps instead of holding a core another thread needs.
        barrier->arriveAndWait([&] {
          if (c + 1 < colours) askToStop();
        });
      }
      slides += patch.slides;
      cadEvaluations += patch.cadEvaluations;
    }
    failure.rethrow();
    // A cancelled sweep is dropped; one the time limit stopped is finished as far as it got
    // (run(), keepPartialSweep), from what its passes moved so far.
    if (cancel) {
      interrupted_.absolute = std::max(interrupted_.absolute, moved);
      interrupted_.relative = std::max(interrupted_.relative, relative);
      interrupted_.addCounts({moved, relative, visits, slides, cadEvaluations});
      throw CancelledError(budgetSpent_ ? "time budget spent during an optimiser sweep"
                                        : "cancelled during an optimiser sweep");
    }
    return {moved, relative, visits, slides, cadEvaluations};
  }

  // One iteration: a Newton step on every free node, then `focusPasses` more on the nodes of
  // the elements within `focusMargin` of the worst scaled Jacobian. The worst elements limit
  // the mesh; a global sweep moves them only as fast as Gauss-Seidel spreads the change, and the
  // focused passes cost a fraction of a sweep (on NekMesh's cube-sphere at order 4, two passes
  // take the worst value after five iterations from 0.714 to 0.757 for 25 % more time).
  // Leaves mesh_.xyz and the certified quality up to date.
  Moves sweep() {
    interrupted_ = Moves{};
    Moves moved = relax(free_, colourStart_, true);
    interrupted_ = moved;  // a focused pass the limit stops adds its own
    writeBack();
    evaluate(take(kStale));
    if (options_.focusPasses > 0) {
      const double worst = *std::min_element(scaled_.begin(), scaled_.end());
      std::vector<std::vector<std::int64_t>> groups(result_.colours);
      std::vector<char> seen(mesh_.numNodes(), 0);
      for (std::size_t bi = 0; bi < blocks_.size(); ++bi) {
        const Block<D>& b = blocks_[bi];
        for (std::size_t e = 0; e < b.cells->count(); ++e) {
          if (!(scaled_[blockOffset_[bi] + e] < worst + options_.focusMargin)) continue;
          const std::int64_t* v = b.cells->element(e);
          for (int k = 0; k < b.nodes; ++k)
            if (colourOf_[v[k]] >= 0 && seen[v[k]] == 0) {
              seen[v[k]] = 1;
              groups[colourOf_[v[k]]].push_back(v[k]);
            }
        }
      }
      std::vector<std::size_t> starts;
      const std::vector<std::int64_t> focus = groupByColourAndPart(groups, starts);
      for (int p = 0; p < options_.focusPasses; ++p) {
        moved.addCounts(relax(focus, starts, false));
        interrupted_ = moved;
      }
      writeBack();
      evaluate(take(kStale));  // the elements the focused passes changed
    }
    // Rounding accumulates in the incrementally updated F: refresh it from the nodes.
    computeGradients(take(kDrifted));
    return moved;
  }

  // The elements marked with `flag` (global indices, ascending); clears the mark.
  std::vector<std::size_t> take(std::uint8_t flag) {
    std::vector<std::size_t> list;
    for (std::size_t i = 0; i < totalElements_; ++i)
      if ((marks_[i].fetch_and(static_cast<std::uint8_t>(~flag), std::memory_order_relaxed) &
           flag) != 0)
        list.push_back(i);
    return list;
  }

  // Every element unmarked, every free node active: the state before the first sweep.
  void resetMarks() {
    marks_ = std::make_unique<std::atomic<std::uint8_t>[]>(totalElements_);
    active_ = std::make_unique<std::atomic<std::uint8_t>[]>(mesh_.numNodes());
    for (std::size_t i = 0; i < totalElements_; ++i) marks_[i].store(0);
    for (std::size_t i = 0; i < mesh_.numNodes(); ++i) active_[i].store(1);
  }

  // The free nodes' equispaced positions into mesh_.xyz (in 2D only their in-plane part moves),
  // each node by its part's thread (free_ is grouped by colour, then part), which reads and
  // writes its data in the sweeps. Every part is written whatever team OpenMP starts (fewer
  // threads than asked, with OMP_THREAD_LIMIT or OMP_DYNAMIC): thread t takes parts t,
  // t + team, ...
  void writeBack() {
    const auto parts = static_cast<std::size_t>(parts_);
    const std::size_t colours = (colourStart_.size() - 1) / parts;
#pragma omp parallel num_threads(options_.threads)
    {
      const auto team = static_cast<std::size_t>(omp_get_num_threads());
      for (auto p = static_cast<std::size_t>(omp_get_thread_num()); p < parts; p += team)
        for (std::size_t c = 0; c < colours; ++c)
          for (std::size_t i = colourStart_[c * parts + p]; i < colourStart_[c * parts + p + 1];
               ++i)
            writeBack(free_[i]);
    }
  }

  void writeBack(std::int64_t node) {
    Vec x = position_[node];
    if (converting_) {
      const Incidence& inc = incidence_[incidenceStart_[node]];
      const Block<D>& b = blocks_[inc.block];
      const std::int64_t* v = b.cells->element(inc.element);
      x.setZero();
      for (int j = 0; j < b.nodes; ++j) x += b.toEquispaced(inc.local, j) * position_[v[j]];
    } else if constexpr (D == 3) {
      for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] = x[c];  // exactly the CAD point
      start_[node] = x;
      return;
    }
    const Eigen::Vector3d d = frame_.transpose() * (x - start_[node]);
    for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] += d[c];
    start_[node] = x;
  }

  // The caller's quality of the input (evaluateQuality's, bounded to kJacobianBoundTolerance:
  // every element as tight as evaluate() makes the ones it refines), when it fits; false to
  // measure it here. (In the working set's coordinates the input is another mesh.)
  bool takeStartQuality() {
    const QualitySummary* q = startQuality_;
    if (q == nullptr || converting_ || q->scaledJacobian.size() != totalElements_ ||
        q->scaledJacobianUpper.size() != totalElements_ || q->validity.size() != totalElements_)
      return false;
    scaled_ = q->scaledJacobian;
    estimate_ = q->scaledJacobianUpper;
    validity_ = q->validity;
    tight_.assign(totalElements_, 1);
    return true;
  }

  // Certified quality of the given elements (global indices) into scaled_ and validity_.
  //
  // Bounds to kJacobianBoundTolerance cost subdivisions that only the elements near the worst
  // need: every element is bounded to kCoarseTolerance first (its validity is decided either
  // way: boundJacobian subdivides until the sign is known), then refined only where its coarse
  // lower bound is below every use of the value: the worst's upper bound plus focusMargin (the
  // focused passes), and the region threshold. An element above both is neither the worst
  // (its value is at least the worst's upper bound) nor in a focus or region set, with either
  // bound; so the worst, the validity counts and every set chosen from scaled_ are the same as
  // with every element refined (a fifth of an order-6 sweep was this refinement).
  void evaluate(const std::vector<std::size_t>& elements) {
    bound(elements, kCoarseTolerance);
    for (const std::size_t i : elements) tight_[i] = 0;
    double threshold = *std::min_element(estimate_.begin(), estimate_.end()) + options_.focusMargin;
    if (options_.regionThreshold) threshold = std::max(threshold, *options_.regionThreshold);
    std::vector<std::size_t> refine;
    for (std::size_t i = 0; i < totalElements_; ++i)
      if (tight_[i] == 0 && !(scaled_[i] >= threshold)) refine.push_back(i);
    bound(refine, kJacobianBoundTolerance);
    for (const std::size_t i : refine) tight_[i] = 1;
  }

  void bound(const std::vector<std::size_t>& elements, double tolerance) {
    forEachOwned(elements, 16, [&](std::size_t i, int /*thread*/) {
      const std::size_t g = elements[i];
      const auto [bi, e] = locate(g);
      const JacobianBounds bounds = elementJacobianBounds(mesh_, *blocks_[bi].cells, e, tolerance);
      scaled_[g] = bounds.scaledJacobian();
      estimate_[g] = bounds.scaledJacobianEstimate();
      validity_[g] = bounds.validity;
    });
  }

  IterationRecord summarise(int iteration, double moved, Clock::time_point t0) const {
    IterationRecord r;
    r.iteration = iteration;
    r.worst = *std::min_element(scaled_.begin(), scaled_.end());
    for (const Validity v : validity_) {
      if (v == Validity::Invalid) ++r.invalid;
      if (v == Validity::Undecided) ++r.undecided;
    }
    r.maxDisplacement = moved;
    r.seconds = since(t0);
    return r;
  }

  // The first stop rule that holds after a sweep (OptimiserOptions), or "".
  std::string stopRule(const IterationRecord& r, const IterationRecord& previous,
                       const IterationRecord& input) const {
    if (r.maxRelativeMove <= options_.tolerance) return "displacement";
    const bool valid = r.invalid + r.undecided == 0;
    const double fall = (previous.energy - r.energy) / std::max(std::abs(r.energy), 1e-300);
    if (valid && fall < options_.energyTolerance) return "energy";
    if (options_.stall > 0.0 && valid && fall < options_.stallEnergy) {
      const auto n = static_cast<int>(result_.history.size());  // r is the last entry
      // The lowest worst of the state before the window and the window's earlier sweeps: the
      // last sweep measured against it, not only against the state before, so that climbing
      // back from a dip inside the window (a sweep that lowers the worst while it lowers the
      // energy elsewhere) is not a stall.
      double low = n > options_.stallWindow ? result_.history[n - 1 - options_.stallWindow].worst
                                            : input.worst;
      for (int k = std::max(0, n - options_.stallWindow); k < n - 1; ++k)
        low = std::min(low, result_.history[k].worst);
      if (n >= options_.stallWindow && r.worst - low < options_.stall) return "stalled";
    }
    // Invalid and stuck: over the last stuckWindow sweeps no element became proven valid and the
    // worst value did not rise by `stall`; what is left is for a repair round, not more sweeps.
    if (options_.stall > 0.0 && !valid && fall < options_.stallEnergy) {
      const auto n = static_cast<int>(result_.history.size());
      if (n > options_.stuckWindow) {
        const IterationRecord& then = result_.history[n - 1 - options_.stuckWindow];
        if (r.invalid + r.undecided >= then.invalid + then.undecided &&
            r.worst - then.worst < options_.stall)
          return "stuck";
      }
    }
    return "";
  }

  // The energy of the elements that contain a free node (the others' is constant), from the
  // current F, with the regularisation of a valid patch.
  double totalEnergy() const {
    std::vector<double> energy(changed_.size());  // summed in order: the same for any thread count
    functional_detail::dispatch(options_.functional, [&](auto fn) {
      forEachOwned(changed_, 64, [&](std::size_t i, int /*thread*/) {
        const auto [bi, e] = locate(changed_[i]);
        const Block<D>& b = blocks_[bi];
        double sum = 0.0;
        for (int q = 0; q < b.points; ++q) {
          const std::size_t p = e * b.points + q;
          sum += b.weights[p] * energyDensity<D, decltype(fn)::value>(b.matrixF(e, q), 1e-10);
        }
        energy[i] = sum;
      });
    });
    double total = 0.0;
    for (const std::size_t i : energyOrder_) total += energy[i];
    if constexpr (D == 3) {
      if (facetsOn_ && hasFacets()) total += facetEnergy_->total(position_);
    }
    return total;
  }

  // No worse than the input in worst value and in invalid count.
  static bool acceptable(const IterationRecord& r, const IterationRecord& input) {
    return r.invalid <= input.invalid && r.worst >= input.worst;
  }
  // Fewer elements not proven valid first, then the better worst value, then, with the worst
  // value unchanged to the last bit (the worst element's nodes did not move: fixed, or not
  // reached before the time limit), the lower energy: the rest of the mesh improved. Two such
  // records have the facet term alike: it joins at the first proven-valid record, and every
  // record before it has elements not proven valid.
  static bool better(const IterationRecord& r, const IterationRecord& than) {
    const std::size_t a = r.invalid + r.undecided, b = than.invalid + than.undecided;
    if (a != b) return a < b;
    if (r.worst != than.worst) return r.worst > than.worst;
    return r.energy < than.energy;
  }
};

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
  if (!options.spatialOrder)
    return mesh.dim == 3 ? Optimiser<3>(mesh, options, observer, cad, startQuality).run()
                         : Optimiser<2>(mesh, options, observer, cad, startQuality).run();
  // The sweeps run on the mesh renumbered along a space-filling curve (OptimiserOptions::
  // spatialOrder), with the per-node and per-element options and the caller's quality
  // renumbered alongside; the caller's numbering is restored whatever happens.
  const SpatialOrder order(mesh);
  OptimiserOptions local = options;
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
        options_(std::move(options)),
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
#pragma omp parallel for num_threads(threads) reduction(min : blockWorst)
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
