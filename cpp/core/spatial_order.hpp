// A renumbering of a mesh along a space-filling curve, for the stages whose threads work on
// neighbouring elements: mesh generators number elements and high-order nodes by creation
// (Gmsh: by entity, then by edge and face), so elements next to each other in space are far
// apart in memory and every node visit of the optimiser touches cache lines scattered over its
// arrays; two CPUs working on such data lose much of the second CPU to memory traffic (the
// order-2 analysis in bench/results/history.md). Numbered along the curve, an element's neighbours
// and nodes sit a few entries away, and a thread's share of the mesh is a few contiguous runs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// The Morton (Z-order) key of a point in the box [low, high]: each coordinate scaled to 21 bits,
// their bits interleaved (x lowest). Points closer than the box's size / 2^21 may share a key;
// a degenerate axis (high == low, as z in a 2D mesh) contributes zeros.
std::uint64_t mortonKey(const double point[3], const double low[3], const double high[3]);

// The permutation, from a mesh's original numbering to the spatial one:
//  - within each block of dimension mesh.dim (the elements), the elements sorted by the Morton
//    key of their corner centroids (ties by original index); lower-dimensional blocks keep
//    their order;
//  - the nodes numbered by first use along those elements (block by block), so that an
//    element's nodes and its neighbours' have nearby numbers; nodes no element uses follow in
//    their original order.
// apply() renumbers a mesh in place, all or nothing (on an allocation failure the mesh is left as
// it was; meanwhile its arrays exist twice); restore() brings it (with whatever coordinates and CAD
// parameters it has been given meanwhile) back to the original numbering, so that callers
// never see the renumbering. The mesh must be consistent (Mesh::checkConsistency). Per-node and
// per-element arrays given alongside the mesh (options, known quality) are carried over with
// nodeValues() and elementValues().
class SpatialOrder {
 public:
  explicit SpatialOrder(const Mesh& mesh);

  void apply(Mesh& mesh) const;
  void restore(Mesh& mesh) const;

  // The original number of each node, and of each element (of dimension mesh.dim, in block
  // order), in the new numbering.
  const std::vector<std::int64_t>& originalNodes() const { return oldNode_; }
  const std::vector<std::size_t>& originalElements() const { return oldElement_; }
  // The inverses: the new number of each original node, and of each original element. Walking
  // them visits the renumbered mesh in the original order, without a sort.
  const std::vector<std::int64_t>& newNodes() const { return newNode_; }
  const std::vector<std::size_t>& newElements() const { return newElement_; }

  // `values` with `stride` entries per node, in the original numbering, renumbered; returned
  // unchanged when its size is not stride x the number of nodes (empty: none given; another
  // size is left to the consumer's own check, which names the option).
  template <class T>
  std::vector<T> nodeValues(const std::vector<T>& values, std::size_t stride) const {
    return values.size() == stride * oldNode_.size() ? gather(values, oldNode_, stride) : values;
  }

  // One value per element (the cells of dimension mesh.dim, in block order, as elementsOf()
  // lists them), in the original order, reordered; unchanged when the size does not match.
  template <class T>
  std::vector<T> elementValues(const std::vector<T>& values) const {
    if (values.size() != oldElement_.size()) return values;
    std::vector<T> out(values.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = values[oldElement_[i]];
    return out;
  }

 private:
  // Entry n of the result (`stride` values each) is entry from[n] of `values`.
  template <class T>
  static std::vector<T> gather(const std::vector<T>& values, const std::vector<std::int64_t>& from,
                               std::size_t stride) {
    std::vector<T> out(values.size());
    for (std::size_t n = 0; n < from.size(); ++n)
      for (std::size_t k = 0; k < stride; ++k)
        out[stride * n + k] = values[stride * static_cast<std::size_t>(from[n]) + k];
    return out;
  }

  // The node arrays gathered from `from` (new position -> source position), the blocks' node
  // ids mapped through `id` and their elements moved by blockOrder_, forwards or (`inverse`)
  // back.
  void renumber(Mesh& mesh, const std::vector<std::int64_t>& from,
                const std::vector<std::int64_t>& id, bool inverse) const;

  std::vector<std::int64_t> oldNode_;  // new node id -> original id
  std::vector<std::int64_t> newNode_;  // original node id -> new id
  // Per block: new position -> original position (empty for a block kept in its order).
  std::vector<std::vector<std::size_t>> blockOrder_;
  // The elements of dimension mesh.dim in block order: new index -> original index.
  std::vector<std::size_t> oldElement_;
  std::vector<std::size_t> newElement_;  // its inverse
};

}  // namespace homesh
