#include "optimise/sweep.hpp"

#include <omp.h>

#include <algorithm>
#include <optional>

#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "core/team_barrier.hpp"
#include "optimise/region_selection.hpp"
#include "optimise/work_partition.hpp"

namespace homesh::optimiser {

template <int D>
void Sweeper<D>::resetMarks() {
  marks_ = std::make_unique<std::atomic<std::uint8_t>[]>(mesh_.totalElements);
  active_ = std::make_unique<std::atomic<std::uint8_t>[]>(mesh_.mesh.numNodes());
  for (std::size_t i = 0; i < mesh_.totalElements; ++i) marks_[i].store(0);
  for (std::size_t i = 0; i < mesh_.mesh.numNodes(); ++i) active_[i].store(1);
}

// Whether the node's elements are all at least settledFloor_ (their certified values of the
// last evaluation: constant during a pass).
template <int D>
bool Sweeper<D>::settled(std::int64_t node) const {
  const std::vector<double>& scaled = quality_.scaled();
  for (std::size_t k = mesh_.incidenceStart[node]; k < mesh_.incidenceStart[node + 1]; ++k) {
    const double q = scaled[mesh_.globalIndex(mesh_.incidence[k])];
    if (!(q >= settledFloor_ && q > 0.0)) return false;
  }
  return true;
}

// After a node's visit: mark the elements it moved, and decide which nodes the next sweep
// visits. A node that did not move by more than activeTolerance of its element size (a settled
// one: settledTolerance, or settledSlidingTolerance on the CAD) rests until a node of one of its
// elements moves by more; a move that leaves the node resting wakes none of them either.
template <int D>
void Sweeper<D>::record(std::int64_t node, double relative) {
  const bool moved = relative > 0.0;
  const double settledBelow =
      step_.slides(node) ? options_.settledSlidingTolerance : options_.settledTolerance;
  const bool wakes =
      relative > options_.activeTolerance && (relative > settledBelow || !settled(node));
  // Loads before stores: the flags mostly hold their value already, and a store (even of the
  // same value) takes the cache line from the other threads working on neighbouring nodes.
  if (const std::uint8_t want = wakes ? 1 : 0;
      active_[node].load(std::memory_order_relaxed) != want)
    active_[node].store(want, std::memory_order_relaxed);
  if (!moved) return;
  constexpr std::uint8_t all = kStale | kDrifted | kEnergyStale;
  for (std::size_t k = mesh_.incidenceStart[node]; k < mesh_.incidenceStart[node + 1]; ++k) {
    const Incidence& inc = mesh_.incidence[k];
    std::atomic<std::uint8_t>& mark = marks_[mesh_.globalIndex(inc)];
    if ((mark.load(std::memory_order_relaxed) & all) != all)
      mark.fetch_or(all, std::memory_order_relaxed);
    if (!wakes) continue;
    const Block<D>& b = mesh_.blocks[inc.block];
    const std::int64_t* v = b.cells->element(inc.element);
    for (int j = 0; j < b.nodes; ++j)
      if (active_[v[j]].load(std::memory_order_relaxed) == 0)
        active_[v[j]].store(1, std::memory_order_relaxed);
  }
}

// One Newton step on each of `nodes` (grouped by colour and part: see groupByColourAndPart);
// with `onlyActive`, on those of them that are active (see record()). A colour group's nodes
// go to their part's thread first.
template <int D>
Moves Sweeper<D>::relax(const std::vector<std::int64_t>& nodes,
                        const std::vector<std::size_t>& starts, bool onlyActive) {
  const int parts = colouring_.parts();
  double moved = 0.0, relative = 0.0;
  std::size_t visits = 0, slides = 0, cadEvaluations = 0;
  FirstFailure failure;
  const auto colours = static_cast<std::int64_t>((starts.size() - 1) / parts);
  std::vector<OwnerFirstQueue> queues;
  queues.reserve(static_cast<std::size_t>(colours));
  for (std::int64_t c = 0; c < colours; ++c) {
    const auto first = starts.begin() + c * parts;
    queues.emplace_back(std::vector<std::size_t>(first, first + parts + 1), 8);
  }
  // A sweep of a large high-order mesh takes seconds: a cancel request (or the time limit) is
  // honoured between colour groups, asked once for the team by the thread that completes a
  // group's barrier, so that every thread leaves the loop together.
  const bool observed = observer_ != nullptr || budget_.limited();
  bool cancel = false;  // shared: written before a barrier releases, read after it
  const auto askToStop = [&] {
    if (!observed) return;
    try {
      cancel = (observer_ != nullptr && observer_->cancelRequested()) || budget_.overBudget();
    } catch (...) {  // an observer's own failure ends the sweep and is rethrown below
      failure.capture();
      cancel = true;
    }
  };
  std::optional<TeamBarrier> barrier;  // for the team OpenMP starts (it may be smaller)
#pragma omp parallel num_threads(options_.threads) reduction(max : moved, relative) \
    reduction(+ : visits, slides, cadEvaluations)
  {
    Patch<D> patch;
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
            const double d = step_.visit(nodes[i], patch);
            ++visits;
            moved = std::max(moved, d);
            relative = std::max(relative, d / mesh_.nodeSize[nodes[i]]);
            record(nodes[i], d / mesh_.nodeSize[nodes[i]]);
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
  // (Optimiser::run, settleInterrupted), from what its passes moved so far.
  if (cancel) {
    interrupted_.absolute = std::max(interrupted_.absolute, moved);
    interrupted_.relative = std::max(interrupted_.relative, relative);
    interrupted_.addCounts({moved, relative, visits, slides, cadEvaluations});
    throw CancelledError(budget_.spent() ? "time budget spent during an optimiser sweep"
                                         : "cancelled during an optimiser sweep");
  }
  return {moved, relative, visits, slides, cadEvaluations};
}

template <int D>
Moves Sweeper<D>::sweep() {
  interrupted_ = Moves{};
  // The elements within focusMargin of the worst still limit the mesh: they never settle.
  settledFloor_ = options_.settledQuality;
  if (settledFloor_ <= 1.0) {
    const std::vector<double>& scaled = quality_.scaled();
    const double worst = scaled.empty() ? 0.0 : *std::min_element(scaled.begin(), scaled.end());
    settledFloor_ = std::max(settledFloor_, worst + options_.focusMargin);
  }
  Moves moved = relax(free_, colouring_.colourStart(), true);
  interrupted_ = moved;  // a focused pass the limit stops adds its own
  writeBack();
  quality_.evaluate(take(kStale));
  if (options_.focusPasses > 0) {
    const std::vector<std::vector<std::int64_t>> groups =
        focusGroups(mesh_, quality_.scaled(), colouring_.colourOf(), colouring_.colours(),
                    options_.focusMargin);
    std::vector<std::size_t> starts;
    const std::vector<std::int64_t> focus = colouring_.groupByColourAndPart(groups, starts);
    for (int p = 0; p < options_.focusPasses; ++p) {
      moved.addCounts(relax(focus, starts, false));
      interrupted_ = moved;
    }
    writeBack();
    quality_.evaluate(take(kStale));  // the elements the focused passes changed
  }
  // Rounding accumulates in the incrementally updated F: refresh it from the nodes.
  mesh_.computeGradients(take(kDrifted), colouring_);
  return moved;
}

template <int D>
void Sweeper<D>::settleInterrupted() {
  writeBack();
  quality_.evaluate(take(kStale));
}

// The elements marked with `flag` (global indices, ascending); clears the mark.
template <int D>
std::vector<std::size_t> Sweeper<D>::take(std::uint8_t flag) {
  std::vector<std::size_t> list;
  for (std::size_t i = 0; i < mesh_.totalElements; ++i)
    if ((marks_[i].fetch_and(static_cast<std::uint8_t>(~flag), std::memory_order_relaxed) & flag) !=
        0)
      list.push_back(i);
  return list;
}

// The free nodes' equispaced positions into mesh.xyz, each node by its part's thread (free_ is
// grouped by colour, then part), which reads and writes its data in the sweeps. Every part is
// written whatever team OpenMP starts (fewer threads than asked, with OMP_THREAD_LIMIT or
// OMP_DYNAMIC): thread t takes parts t, t + team, ...
template <int D>
void Sweeper<D>::writeBack() {
  const auto parts = static_cast<std::size_t>(colouring_.parts());
  const std::vector<std::size_t>& colourStart = colouring_.colourStart();
  const std::size_t colours = (colourStart.size() - 1) / parts;
#pragma omp parallel num_threads(options_.threads)
  {
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    for (auto p = static_cast<std::size_t>(omp_get_thread_num()); p < parts; p += team)
      for (std::size_t c = 0; c < colours; ++c)
        for (std::size_t i = colourStart[c * parts + p]; i < colourStart[c * parts + p + 1]; ++i)
          mesh_.writeBack(free_[i]);
  }
}

template class Sweeper<2>;
template class Sweeper<3>;

}  // namespace homesh::optimiser
