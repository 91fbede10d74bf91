// Who moves which node when: the optimiser's owner-computes split (one part per thread, by
// work_partition.hpp's recursive coordinate bisection, a node in the part of most of its
// elements), each node's distance from the cut between the parts, and the greedy colouring of
// the free nodes, grouped by colour and then by part. Two nodes of one colour never share an
// element, so the nodes of a colour move in parallel and colours in sequence: the result does
// not depend on the number of threads. forEachOwned runs a loop over elements with each element
// on its part's thread first.
#pragma once

#include <omp.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/first_failure.hpp"
#include "optimise/work_partition.hpp"
#include "optimise/working_mesh.hpp"

namespace homesh::optimiser {

template <int D>
class NodeColouring {
 public:
  explicit NodeColouring(int threads) : threads_(threads) {}

  // One part per thread, by recursive coordinate bisection of the elements' centroids weighted
  // by their energy points (elements not in `changed`, without a free node, weigh nothing: no
  // node visit or refresh of F touches them); a node belongs to the part of most of its elements.
  // With more than one part, measures each node's distance from the cut too.
  void partition(const WorkingMesh<D>& mesh, const std::vector<std::size_t>& changed);

  // Greedy colouring of `free` (sorted; visited in the caller's order where the mesh was
  // renumbered): two nodes sharing an element get different colours. Reorders `free` by colour,
  // then by part (groupByColourAndPart), and sets colourStart() and colourOf(). After partition.
  void colour(const WorkingMesh<D>& mesh, std::vector<std::int64_t>& free);

  // The nodes of each colour group, each group's ordered by part (stable) and, within a part,
  // from its interior to the cut; `starts` gets the ranges: colour c, part p is
  // [starts[c * parts() + p], starts[c * parts() + p + 1]).
  std::vector<std::int64_t> groupByColourAndPart(
      const std::vector<std::vector<std::int64_t>>& groups, std::vector<std::size_t>& starts) const;

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
#pragma omp parallel num_threads(threads_)
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

  int threads() const {
    return threads_;
  }
  int parts() const {
    return parts_;
  }
  const std::vector<int>& elementPart() const {
    return elementPart_;
  }  // per global element
  const std::vector<int>& nodePart() const {
    return nodePart_;
  }  // per node
  // Per node, with more than one part: its distance from the cut in element layers, 0 for a
  // node of an element whose nodes (or the element itself) belong to more than one part,
  // kFarFromCut beyond kFarFromCut - 1 (the search stops there: its cost stays with the cut's
  // neighbourhood).
  static constexpr std::uint8_t kFarFromCut = 3;
  const std::vector<std::uint8_t>& cutDistance() const {
    return cutDistance_;
  }
  // After colour(): the colour and part ranges of the free nodes (see groupByColourAndPart),
  // the colour of each node (-1 for nodes not free) and the number of colours.
  const std::vector<std::size_t>& colourStart() const {
    return colourStart_;
  }
  const std::vector<int>& colourOf() const {
    return colourOf_;
  }
  std::size_t colours() const {
    return colours_;
  }

 private:
  void measureCutDistance(const WorkingMesh<D>& mesh);

  int threads_ = 1;
  int parts_ = 1;
  std::vector<int> elementPart_;  // empty before partition()
  std::vector<int> nodePart_;
  std::vector<std::uint8_t> cutDistance_;
  std::vector<std::size_t> colourStart_;
  std::vector<int> colourOf_;
  std::size_t colours_ = 0;
};

extern template class NodeColouring<2>;
extern template class NodeColouring<3>;

}  // namespace homesh::optimiser
