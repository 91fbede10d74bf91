// The certified scaled Jacobian (quality/bezier_jacobian.hpp) of every element of the optimiser's
// working mesh, kept up to date after each pass for the elements whose nodes moved: the worst
// value and validity counts of each sweep's record, the focus set and the region are chosen
// from it.
//
// Bounds to kJacobianBoundTolerance cost subdivisions that only the elements near the worst
// need: every element is bounded to a coarse tolerance first (its validity is decided either
// way: boundJacobian subdivides until the sign is known), then refined only where its coarse
// lower bound is below every use of the value: the worst's upper bound plus focusMargin (the
// focused passes), and the region threshold. An element above both is neither the worst (its
// value is at least the worst's upper bound) nor in a focus or region set, with either bound; so
// the worst, the validity counts and every set chosen from the values are the same as with
// every element refined (a fifth of an order-6 sweep was this refinement).
#pragma once

#include <cstddef>
#include <vector>

#include "optimise/node_colouring.hpp"
#include "optimise/optimiser.hpp"
#include "optimise/stop_rules.hpp"
#include "optimise/working_mesh.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh::optimiser {

template <int D>
class CertifiedQuality {
 public:
  // Reads options.focusMargin and options.regionThreshold; evaluates on `owners`' threads.
  CertifiedQuality(const WorkingMesh<D>& mesh, const NodeColouring<D>& owners,
                   const OptimiserOptions& options)
      : mesh_(mesh), owners_(owners), options_(options) {}

  // Every element's quality, before the first sweep: `startQuality`'s where it fits (the caller's
  // evaluateQuality of the mesh, bounded to kJacobianBoundTolerance: every element as tight as
  // evaluate() makes the ones it refines; not in the working set's coordinates, where the input
  // is another mesh), else measured here. `startQuality` may be null.
  void measureInput(const QualitySummary* startQuality);

  // Certified quality of the given elements (global indices), refined where it matters.
  void evaluate(const std::vector<std::size_t>& elements);

  // The record of the current state: worst value, invalid and undecided counts, `moved` as its
  // displacement and the seconds since t0.
  IterationRecord summarise(int iteration, double moved, Clock::time_point t0) const;

  const std::vector<double>& scaled() const { return scaled_; }
  const std::vector<Validity>& validity() const { return validity_; }

 private:
  bool takeStartQuality(const QualitySummary* q);
  void bound(const std::vector<std::size_t>& elements, double tolerance);

  const WorkingMesh<D>& mesh_;
  const NodeColouring<D>& owners_;
  const OptimiserOptions& options_;
  std::vector<double> scaled_;    // certified lower bound of each element's scaled Jacobian
  std::vector<double> estimate_;  // and an upper bound (from values of J found)
  std::vector<char> tight_;       // scaled_ refined to kJacobianBoundTolerance (see evaluate)
  std::vector<Validity> validity_;
};

extern template class CertifiedQuality<2>;
extern template class CertifiedQuality<3>;

}  // namespace homesh::optimiser
