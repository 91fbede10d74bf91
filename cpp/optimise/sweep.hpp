// One sweep (iteration) of the optimiser: a Newton step (node_step.hpp) on every active free
// node, colour group by colour group, each group's nodes in parallel on their parts' threads
// (node_colouring.hpp), then `focusPasses` more steps on the nodes of the worst elements
// (region_selection.hpp's focusGroups). After each pass the moved nodes are written back to the
// mesh and the elements they changed certified (certified_quality.hpp); at the end F is refreshed
// from the nodes where the rank-one updates drifted.
//
// Every node is active in the first sweep; later, a node is active once it or a node of one of
// its elements moved by more than options.activeTolerance of its element size since its last
// visit (options.settledTolerance for a node whose own elements are all at least
// options.settledQuality and above the worst plus options.focusMargin, or
// options.settledSlidingTolerance where such a node slides on the CAD). A node is never marked
// by another of its own colour (they share no element), so the result does not depend on the
// thread count.
//
// A cancel request (OptimiserObserver) or the time limit is honoured between colour groups: the
// sweep then throws CancelledError, and what its passes moved so far stays in interrupted().
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "optimise/certified_quality.hpp"
#include "optimise/node_colouring.hpp"
#include "optimise/node_step.hpp"
#include "optimise/optimiser.hpp"
#include "optimise/stop_rules.hpp"
#include "optimise/working_mesh.hpp"

namespace homesh::optimiser {

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

template <int D>
class Sweeper {
 public:
  // `free`: the free nodes as NodeColouring::colour grouped them. `observer` may be null.
  Sweeper(WorkingMesh<D>& mesh, const NodeColouring<D>& colouring,
          const std::vector<std::int64_t>& free, NodeStep<D>& step, CertifiedQuality<D>& quality,
          const OptimiserOptions& options, OptimiserObserver* observer, TimeBudget& budget)
      : mesh_(mesh),
        colouring_(colouring),
        free_(free),
        step_(step),
        quality_(quality),
        options_(options),
        observer_(observer),
        budget_(budget) {}

  // Every element unmarked, every free node active: the state before the first sweep.
  void resetMarks();

  // One iteration: a Newton step on every active free node, then `focusPasses` more on the nodes
  // of the elements within `focusMargin` of the worst scaled Jacobian. The worst elements limit
  // the mesh; a global sweep moves them only as fast as Gauss-Seidel spreads the change, and the
  // focused passes cost a fraction of a sweep (on NekMesh's cube-sphere at order 4, two passes
  // take the worst value after five iterations from 0.714 to 0.757 for 25 % more time).
  // Leaves mesh.xyz and the certified quality up to date. Throws CancelledError when stopped
  // between colour groups.
  Moves sweep();

  // What the current sweep's passes moved before a cancel request or the time limit stopped
  // one.
  const Moves& interrupted() const { return interrupted_; }
  // A sweep the time limit stopped, finished as far as it got: the nodes it moved written back
  // and the elements they changed certified.
  void settleInterrupted();

  // Makes the node active for the next sweep.
  void wake(std::int64_t node) { active_[node].store(1, std::memory_order_relaxed); }

  // The elements whose F changed since the last call (global indices, ascending), and clears
  // that mark: their energy is out of date.
  std::vector<std::size_t> takeChangedEnergy() { return take(kEnergyStale); }

 private:
  // Per element: kStale = a node moved since its quality was last computed, kDrifted = since
  // its F was last computed from the nodes, kEnergyStale = since takeChangedEnergy(). Set by
  // record() (atomics: threads mark shared elements), cleared by take().
  static constexpr std::uint8_t kStale = 1, kDrifted = 2, kEnergyStale = 4;

  void record(std::int64_t node, double relative);
  bool settled(std::int64_t node) const;
  Moves relax(const std::vector<std::int64_t>& nodes, const std::vector<std::size_t>& starts,
              bool onlyActive);
  std::vector<std::size_t> take(std::uint8_t flag);
  void writeBack();

  WorkingMesh<D>& mesh_;
  const NodeColouring<D>& colouring_;
  const std::vector<std::int64_t>& free_;
  NodeStep<D>& step_;
  CertifiedQuality<D>& quality_;
  const OptimiserOptions& options_;
  OptimiserObserver* observer_;
  TimeBudget& budget_;
  std::unique_ptr<std::atomic<std::uint8_t>[]> marks_;
  // Per node: visit it in the next sweep (it or a neighbour moved by more than
  // options_.activeTolerance of its element size since its last visit).
  std::unique_ptr<std::atomic<std::uint8_t>[]> active_;
  // The quality at and above which an element counts as settled in this sweep:
  // options.settledQuality, or the worst plus options.focusMargin where that is higher.
  double settledFloor_ = 2.0;
  Moves interrupted_;
};

extern template class Sweeper<2>;
extern template class Sweeper<3>;

}  // namespace homesh::optimiser
