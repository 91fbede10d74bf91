// The variational optimiser: moves the free nodes of a curved mesh to minimise an energy that
// measures how far each element is from its straight-sided (ideal) shape (DESIGN.md section 6;
// the functionals are in optimise/functional.hpp).
//
// Each sweep (iteration) visits every active free node once and takes one Newton step on that
// node alone (the node's energy is a function of its 2 or 3 coordinates; gradient and Hessian
// are exact), then `focusPasses` more steps on the nodes of the worst elements only. Every node
// is active in the first sweep; later, a node is active once it or a node of one of its elements
// moved by more than `activeTolerance` of its element size since its last visit
// (`settledTolerance`, or `settledSlidingTolerance` on the CAD, for a node whose own elements
// are all at least `settledQuality`: see optimiser_options.hpp). Per point the
// deformation gradient F and J = det F are kept and updated by the rank-one change of each
// accepted move, so a Newton step costs O(quadrature points of the node's elements). Each step
// shifts the Hessian to be positive definite and uses a backtracking Armijo line search that
// rejects the move if the energy does not decrease. Nodes are coloured so that two nodes of
// one colour never share an element; the nodes of a colour are moved in parallel, colours in
// sequence, so the result does not depend on the number of threads.
//
// Without CAD, free nodes are those not on the mesh's boundary (faces in 3D, edges in 2D, of
// exactly one element), not on an interface between elements of different entities and not on a
// lower-dimensional cell of the mesh; the others stay fixed. With a region threshold (or seed),
// only the nodes of elements whose scaled Jacobian is below it (or that the seed names), grown
// by `regionLayers` layers of neighbours, move.
//
// Never worse: after every sweep the certified scaled Jacobian (quality/bezier_jacobian.hpp)
// of every element that can have changed is recomputed; the state kept at the end is the best
// one seen among those whose worst value and invalid count are no worse than the input's (the
// input itself if no sweep qualifies), and the result says which sweep it was. Best: fewer
// elements not proven valid, then a higher worst value, then, the worst value the same to the
// last bit (its element's nodes did not move), a lower energy.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/mesh.hpp"
#include "core/parameters.hpp"
#include "optimise/functional.hpp"
#include "optimise/optimiser_options.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

class CadModel;

// The state after one sweep.
struct IterationRecord {
  int iteration = 0;
  double worst = 0.0;  // certified scaled Jacobian, mesh-wide minimum
  std::size_t invalid = 0;
  std::size_t undecided = 0;
  double maxDisplacement = 0.0;  // largest node move of the sweep
  double maxRelativeMove = 0.0;  // largest node move / the size of the node's smallest element
  std::size_t visits = 0;        // Newton steps tried (active nodes, then focused passes)
  double energy = 0.0;           // total energy of the elements with a free node, after
  double seconds = 0.0;          // since the optimiser started
  bool partial = false;          // stopped by the time limit part-way (OptimiserOptions)
};

struct OptimiserResult {
  Functional functional = Functional::Hyperelastic;
  int iterations = 0;      // sweeps done
  bool converged = false;  // stopped by "displacement", "energy" or "stalled"
  // Which rule ended the run: "displacement", "energy", "stalled", "stuck", "iterations",
  // "time budget", "cancelled",
  // or "no free nodes" (see OptimiserOptions).
  std::string stopReason;
  double energyBefore = 0.0, energyAfter = 0.0;  // of the input and of the state kept
  bool cancelled = false;
  int keptIteration = 0;                       // the sweep whose state was returned (0: the input)
  double worstBefore = 0.0, worstAfter = 0.0;  // certified scaled Jacobian
  // min J / max J over each element's nodes, mesh-wide minimum: the measure NekMesh reports.
  double nodalWorstBefore = 0.0, nodalWorstAfter = 0.0;
  std::size_t invalidBefore = 0, invalidAfter = 0;
  std::size_t undecidedBefore = 0, undecidedAfter = 0;
  std::size_t freeNodes = 0, colours = 0, regionElements = 0;
  // The energy's samples (working_mesh.hpp's EnergyRule): "symmetric" where an input
  // certified valid holds tetrahedra of order 3 or 4, else "collapsed".
  std::string energyRule;
  std::size_t visits = 0;  // Newton steps tried in all sweeps (node updates)
  // Visits of nodes sliding on the CAD, and the CAD evaluations they made: the full Newton step
  // and the shorter trial points the local model accepted (cad_local_model.hpp), plus a fresh
  // model where the node's last accepted evaluation is not at its parameters (first visit).
  std::size_t slides = 0, cadEvaluations = 0;
  double setupSeconds = 0.0;  // colouring, ideal elements, initial quality
  double sweepSeconds = 0.0;  // the sweeps with their focused passes and quality checks
  double seconds = 0.0;       // everything, including the quality checks
  std::vector<IterationRecord> history;
};

// Receives the state after each sweep; may ask to stop (the best state so far is kept), which
// is honoured between colour groups of a sweep, so within a fraction of one.
class OptimiserObserver {
 public:
  virtual ~OptimiserObserver() = default;
  virtual void iterationFinished(const IterationRecord& /*record*/) {}
  virtual bool cancelRequested() { return false; }
};

// Optimises `mesh` in place. Supports triangles and quadrilaterals (dim 2) and tetrahedra,
// prisms and hexahedra (dim 3) of orders 1..10. With `cad` (the model the mesh's node records
// refer to), nodes on a CAD curve slide along it in t and, in 3D, nodes on a CAD face slide on
// it in (u, v), staying exactly on the CAD (their parameters are updated); CAD vertices stay.
// `startQuality`, when the caller has it: evaluateQuality of `mesh` as given (a repair round
// has it for all but its new elements); the set-up then takes the elements' certified quality
// from it instead of measuring the whole mesh. Ignored where its size does not match.
// While it runs, `mesh` is renumbered (OptimiserOptions::spatialOrder): an observer reading it
// sees the internal numbering; the caller's is restored before it returns or throws.
// Throws ParameterError for bad options or unsupported cells.
OptimiserResult optimiseMesh(Mesh& mesh, const OptimiserOptions& options,
                             OptimiserObserver* observer = nullptr, const CadModel* cad = nullptr,
                             const QualitySummary* startQuality = nullptr);

// The optimiser's energy around one node as a function of that node's own coordinates, for the
// derivative tests: the same setup, patch assembly, regularisation and chain rule through the
// CAD as the sweeps (nothing is written for the tests alone). The coordinates are (x, y[, z]) in
// the optimiser's frame for a node that moves freely (positions of the working node set when
// the optimiser converts to it: without CAD and without a region), t for a node sliding on a
// CAD curve and (u, v) for one sliding on a CAD face. The patch is every element around the
// node; the other nodes stay where the mesh has them.
struct NodeEnergy {
  double value = 0.0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
  // Sum over the patch's points of weight x (|W| + |F|^2): the size of the terms the energy
  // adds up, so that c u magnitude bounds its rounding (u the unit roundoff).
  double magnitude = 0.0;
};

class NodeEnergyProbe {
 public:
  // Throws as optimiseMesh for bad options or cells.
  NodeEnergyProbe(const Mesh& mesh, const OptimiserOptions& options, const CadModel* cad = nullptr);
  ~NodeEnergyProbe();
  NodeEnergyProbe(const NodeEnergyProbe&) = delete;
  NodeEnergyProbe& operator=(const NodeEnergyProbe&) = delete;

  // Whether the sweeps move the node (any node can be probed).
  bool isFree(std::int64_t node) const;
  Eigen::VectorXd coordinates(std::int64_t node) const;
  // The regularisation eps the sweeps use for the node's patch as it is.
  double regularisation(std::int64_t node) const;
  // Energy, gradient and Hessian with the node at `coordinates`. Throws ParameterError for a
  // node outside the mesh or a coordinate count that does not match.
  NodeEnergy evaluate(std::int64_t node, const Eigen::VectorXd& coordinates, double eps) const;

  class Impl;

 private:
  void check(std::int64_t node) const;
  std::unique_ptr<Impl> impl_;
  std::size_t numNodes_ = 0;
};

// min over the mesh of (min J / max J over each element's nodes).
double nodalScaledJacobian(const Mesh& mesh, int threads = defaultOf<int>("threads"));

}  // namespace homesh
