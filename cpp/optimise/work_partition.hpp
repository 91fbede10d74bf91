// Owner-computes work split for the optimiser's threads (and, later, MPI ranks): every element
// belongs to one part, a spatially compact region of the mesh, and every phase of a sweep gives
// an element (a node) to its part's thread first. An element's cached deformation gradients
// are then written and read by one thread, except on the cut between parts (a node's visit
// updates all its elements) and where a thread helps another part, instead of moving between
// CPUs whenever another thread happens to take the element.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace homesh {

// Splits points (one per element: its centroid) with weights (the work each element costs)
// into `parts` sets by recursive coordinate bisection: each set is cut across its longest
// extent where floor(parts / 2) / parts of its weight lies below the cut, the two sides taking
// floor(parts / 2) parts and the rest, until one set is left per part. Each cut misses its
// share by at most half the largest single weight, so a part's weight is within that times the
// levels of cuts above it (ceil(log2(parts))) of the total / parts. Returns each point's part
// in [0, parts). Deterministic: ties are broken by index.
std::vector<int> bisectByCoordinates(const std::vector<std::array<double, 3>>& points,
                                     const std::vector<double>& weights, int parts);

// The owner of each node: the part that owns most of its elements (the lowest such part on a
// tie). Generic over the incidence storage: `partsOfNode(node, add)` calls add(part) once per
// element of the node.
template <class PartsOfNode>
std::vector<int> nodeOwners(std::size_t numNodes, int parts, PartsOfNode partsOfNode) {
  std::vector<int> owner(numNodes, 0);
  std::vector<int> count(static_cast<std::size_t>(parts), 0);
  for (std::size_t n = 0; n < numNodes; ++n) {
    std::fill(count.begin(), count.end(), 0);
    partsOfNode(n, [&](int p) { ++count[static_cast<std::size_t>(p)]; });
    int best = 0;
    for (int p = 1; p < parts; ++p)
      if (count[static_cast<std::size_t>(p)] > count[static_cast<std::size_t>(best)]) best = p;
    owner[n] = best;
  }
  return owner;
}

// Items grouped by part (part t's are [begin[t], begin[t + 1])), handed out in chunks (of at
// most `chunk` items, an eighth of what is left in the part near its end): a
// thread takes its own part's chunks first, from the front, and then helps the other parts with
// theirs, from the back, so the work stays with its owner where the parts are balanced and no
// thread idles where they are not. A part whose items are ordered from its interior to the cut
// (the optimiser's node groups) so hands its helpers the items whose data they share already.
// Safe to call next() from every thread at once; each item is handed out exactly once. A part
// holds fewer than 2^32 items.
class OwnerFirstQueue {
 public:
  OwnerFirstQueue(std::vector<std::size_t> begin, std::size_t chunk);

  // The next chunk [lo, hi) for the thread of part `part`; false when every item is taken.
  bool next(int part, std::size_t& lo, std::size_t& hi);

 private:
  // The part's items not handed out yet, [begin + front, begin + back), as front << 32 | back:
  // one word, so that the owner's and a helper's takes exclude each other.
  struct alignas(64) Cursor {  // one cache line each: parts take their own chunks unshared
    std::atomic<std::uint64_t> range{0};
  };
  bool take(std::size_t part, bool front, std::size_t& lo, std::size_t& hi);

  std::vector<std::size_t> begin_;
  std::size_t chunk_;
  std::unique_ptr<Cursor[]> cursors_;
};

// Stable grouping of `items` by part: returns the items reordered part by part (each part's in
// their given order) and fills `begin` with parts + 1 offsets.
template <class Item, class PartOf>
std::vector<Item> groupByPart(const std::vector<Item>& items, int parts, PartOf partOf,
                              std::vector<std::size_t>& begin) {
  begin.assign(static_cast<std::size_t>(parts) + 1, 0);
  for (const Item& item : items) ++begin[static_cast<std::size_t>(partOf(item)) + 1];
  for (std::size_t p = 0; p < static_cast<std::size_t>(parts); ++p) begin[p + 1] += begin[p];
  std::vector<std::size_t> fill(begin.begin(), begin.end() - 1);
  std::vector<Item> grouped(items.size());
  for (const Item& item : items) grouped[fill[static_cast<std::size_t>(partOf(item))]++] = item;
  return grouped;
}

}  // namespace homesh
