#include "core/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace homesh {
namespace {

// The low 21 bits of v, spread to every third bit.
std::uint64_t spread(std::uint64_t v) {
  v &= 0x1fffffULL;
  v = (v | v << 32U) & 0x1f00000000ffffULL;
  v = (v | v << 16U) & 0x1f0000ff0000ffULL;
  v = (v | v << 8U) & 0x100f00f00f00f00fULL;
  v = (v | v << 4U) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2U) & 0x1249249249249249ULL;
  return v;
}

// Block `b` with its elements moved by `order` (new position -> original position; `inverse`:
// back) and its node ids mapped through `id`.
ElementBlock reorderedBlock(const ElementBlock& b, const std::vector<std::size_t>& order,
                            const std::vector<std::int64_t>& id, bool inverse) {
  const auto per = static_cast<std::size_t>(b.nodesPerElement());
  ElementBlock out;
  out.type = b.type;
  out.order = b.order;
  out.layerCells = b.layerCells;
  std::vector<std::int64_t>& nodes = out.nodes;
  std::vector<std::int32_t>& entity = out.entity;
  nodes.resize(b.nodes.size());
  entity.resize(b.entity.size());
  for (std::size_t k = 0; k < b.count(); ++k) {
    const std::size_t target = order.empty() ? k : (inverse ? order[k] : k);
    const std::size_t source = order.empty() ? k : (inverse ? k : order[k]);
    entity[target] = b.entity[source];
    for (std::size_t j = 0; j < per; ++j)
      nodes[target * per + j] = id[static_cast<std::size_t>(b.nodes[source * per + j])];
  }
  return out;
}

}  // namespace

std::uint64_t mortonKey(const double point[3], const double low[3], const double high[3]) {
  constexpr double cells = 2097151.0;  // 2^21 - 1
  std::uint64_t key = 0;
  for (int c = 0; c < 3; ++c) {
    const double extent = high[c] - low[c];
    double t = extent > 0.0 ? (point[c] - low[c]) / extent : 0.0;
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    key |= spread(static_cast<std::uint64_t>(t * cells)) << static_cast<unsigned>(c);
  }
  return key;
}

SpatialOrder::SpatialOrder(const Mesh& mesh) {
  const std::size_t numNodes = mesh.numNodes();
  double low[3], high[3];
  for (int c = 0; c < 3; ++c) {
    low[c] = std::numeric_limits<double>::infinity();
    high[c] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t n = 0; n < numNodes; ++n)
    for (int c = 0; c < 3; ++c) {
      low[c] = std::min(low[c], mesh.xyz[3 * n + c]);
      high[c] = std::max(high[c], mesh.xyz[3 * n + c]);
    }

  newNode_.assign(numNodes, -1);
  oldNode_.reserve(numNodes);
  blockOrder_.resize(mesh.blocks.size());
  std::size_t first = 0;  // the block's first element among those of dimension mesh.dim
  for (std::size_t bi = 0; bi < mesh.blocks.size(); ++bi) {
    const ElementBlock& b = mesh.blocks[bi];
    if (cellDimension(b.type) != mesh.dim) continue;
    const int corners = cellNumNodes(b.type, 1);  // Gmsh order: the corners come first
    std::vector<std::uint64_t> key(b.count());
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      double centroid[3] = {0.0, 0.0, 0.0};
      for (int k = 0; k < corners; ++k)
        for (int c = 0; c < 3; ++c) centroid[c] += mesh.xyz[3 * v[k] + c] / corners;
      key[e] = mortonKey(centroid, low, high);
    }
    std::vector<std::size_t>& order = blockOrder_[bi];
    order.resize(b.count());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t c) {
      return key[a] != key[c] ? key[a] < key[c] : a < c;
    });
    for (const std::size_t e : order) {
      oldElement_.push_back(first + e);
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < b.nodesPerElement(); ++k)
        if (newNode_[static_cast<std::size_t>(v[k])] < 0) {
          newNode_[static_cast<std::size_t>(v[k])] = static_cast<std::int64_t>(oldNode_.size());
          oldNode_.push_back(v[k]);
        }
    }
    first += b.count();
  }
  for (std::size_t n = 0; n < numNodes; ++n)
    if (newNode_[n] < 0) {
      newNode_[n] = static_cast<std::int64_t>(oldNode_.size());
      oldNode_.push_back(static_cast<std::int64_t>(n));
    }
  newElement_.resize(oldElement_.size());
  for (std::size_t i = 0; i < oldElement_.size(); ++i) newElement_[oldElement_[i]] = i;
}

void SpatialOrder::apply(Mesh& mesh) const {
  renumber(mesh, oldNode_, newNode_, false);
}

void SpatialOrder::restore(Mesh& mesh) const {
  renumber(mesh, newNode_, oldNode_, true);
}

void SpatialOrder::renumber(Mesh& mesh, const std::vector<std::int64_t>& from,
                            const std::vector<std::int64_t>& id, bool inverse) const {
  // Every new array first, then the moves (which cannot throw): an allocation failure leaves
  // the mesh as it was.
  std::vector<double> xyz = gather(mesh.xyz, from, 3);
  std::vector<std::uint8_t> cadDim = gather(mesh.nodeCadDim, from, 1);
  std::vector<std::int32_t> cadIndex = gather(mesh.nodeCadIndex, from, 1);
  std::vector<double> cadParam = gather(mesh.nodeCadParam, from, 2);
  std::vector<ElementBlock> blocks(mesh.blocks.size());
  for (std::size_t bi = 0; bi < blocks.size(); ++bi)
    blocks[bi] = reorderedBlock(mesh.blocks[bi], blockOrder_[bi], id, inverse);
  mesh.xyz = std::move(xyz);
  mesh.nodeCadDim = std::move(cadDim);
  mesh.nodeCadIndex = std::move(cadIndex);
  mesh.nodeCadParam = std::move(cadParam);
  mesh.blocks = std::move(blocks);
}

}  // namespace homesh
