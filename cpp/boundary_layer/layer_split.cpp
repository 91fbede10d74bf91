#include "boundary_layer/layer_split.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_splitter.hpp"
#include "element/element_map.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace layer_splitting {

Mesh LayerSplitter::run() {
  if (macro_.dim == 2) wallVertices_ = layerWall(macro_);  // (fans are 2D only)
  for (const ElementBlock& b : macro_.blocks) {
    fans_.push_back(mayHoldFans(macro_, b) ? fanTriangles(b, wallVertices_) : std::vector<char>());
    const std::vector<char>& fan = fans_.back();
    for (std::size_t e = 0; e < fan.size(); ++e)
      if (fan[e] != 0) fanCorners_.insert(b.element(e)[fanApex(b.element(e))]);
  }
  for (const ElementBlock& b : macro_.blocks)
    if (layerCell(b)) pairWallAndTop(b);
  forEachColumn(macro_, [this](std::int64_t, std::int64_t top, const Eigen::Vector3d& n) {
    normals_[top].add(n);
  });
  // The layer's cells first (they set their columns' levels, which the fans between them
  // share), then the fans; the blocks keep the macro mesh's order.
  std::vector<std::optional<ElementBlock>> split(macro_.blocks.size());
  for (std::size_t i = 0; i < macro_.blocks.size(); ++i)
    if (layerCell(macro_.blocks[i])) split[i] = splitCells(macro_.blocks[i]);
  for (std::size_t i = 0; i < macro_.blocks.size(); ++i) {
    const ElementBlock& b = macro_.blocks[i];
    if (layerCell(b) || b.type == CellType::Quadrilateral || b.type == CellType::Line) continue;
    const std::vector<char>& fan = fans_[i];
    split[i] = std::find(fan.begin(), fan.end(), 1) != fan.end() ? splitFans(b, fan) : b;
  }
  for (std::optional<ElementBlock>& b : split)
    if (b) out_.blocks.push_back(std::move(*b));
  // Faces, then curves: a node on both ends on its curve.
  for (const ElementBlock& b : macro_.blocks)
    if (b.type == CellType::Quadrilateral && !layerCell(b)) out_.blocks.push_back(splitSides(b));
  for (const ElementBlock& b : macro_.blocks)
    if (b.type == CellType::Line) out_.blocks.push_back(splitSides(b));
  compactNodes(out_);
  out_.checkConsistency();
  measureFirstLayer();
  stats_.plainColumns = plain_.size();
  return std::move(out_);
}

void LayerSplitter::pairWallAndTop(const ElementBlock& b) {
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* v = b.element(e);
    for (int k = 0; k < wallVertices(b); ++k) {
      const std::int64_t top = topVertex(b, v, k);
      height_[v[k]] =
          (Eigen::Vector3d(&macro_.xyz[3 * top]) - Eigen::Vector3d(&macro_.xyz[3 * v[k]])).norm();
      if (fanCorners_.count(v[k]) != 0) continue;
      const auto [it, fresh] = topOf_.emplace(v[k], top);
      if (!fresh && it->second != top)
        throw MeshingError("boundary-layer split: wall node " + std::to_string(v[k]) +
                           " has two top nodes");
    }
  }
}

ElementBlock LayerSplitter::splitCells(const ElementBlock& b) {
  const LayerShape shape = layerShape(b.type);
  const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
  const std::map<LatticePoint, int> index = latticeIndex(ref);
  const int nn = ref.numNodes();
  const int dim = ref.dim();
  const std::size_t across = shape.across;  // the lattice axis across the layer
  ElementBlock out;
  out.type = b.type;
  out.order = p_;
  out.layerCells = b.layerCells;
  out.nodes.resize(b.count() * static_cast<std::size_t>(n_) * static_cast<std::size_t>(nn));
  out.entity.resize(b.count() * static_cast<std::size_t>(n_));
  Eigen::MatrixXd points(nn, dim);
  for (std::size_t e = 0; e < b.count(); ++e) {
    bool corner = false;
    for (int k = 0; k < wallVertices(b); ++k)
      corner = corner || atCorner(topVertex(b, b.element(e), k));
    cellCorner_.push_back(corner ? 1 : 0);
  }
  for (int k = 0; k < n_; ++k) {
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      std::array<std::int64_t, 4> t{kNone, kNone, kNone, kNone};
      for (int w = 0; w < shape.walls; ++w) t[static_cast<std::size_t>(w)] = shape.top(v, w);
      // The k-th thin cell's nodes in the macro cell's reference element, on its columns' levels.
      for (int r = 0; r < nn; ++r) {
        const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
        const std::vector<double>& z = column(b, index, v, c).levels;
        const auto kk = static_cast<std::size_t>(k);
        for (std::size_t a = 0; a < across; ++a)
          points(r, static_cast<Eigen::Index>(a)) = double(c[a]) / p_;
        points(r, static_cast<Eigen::Index>(across)) = z[kk] + (z[kk + 1] - z[kk]) * c[across] / p_;
      }
      // The macro cell's map, made for the thin cell's first new node: a node then costs
      // O(nodes) (made once per thin cell, not kept for the block: O(nodes^2) each, far below the
      // nodes' own cost at order 6, and no block-sized store).
      std::optional<ElementMap> map;
      const std::size_t sub = e * static_cast<std::size_t>(n_) + static_cast<std::size_t>(k);
      out.entity[sub] = b.entity[e];
      for (int r = 0; r < nn; ++r) {
        const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
        const std::int64_t level = std::int64_t(k) * p_ + c[across];
        const std::array<int, 4> w = shape.latticeWeights(c, p_);
        const NodeKey key =
            makeKey({{{t[0], w[0]}, {t[1], w[1]}, {t[2], w[2]}, {t[3], w[3]}}}, level);
        std::int64_t id = 0;
        if (level == 0 || level == std::int64_t(n_) * p_) {
          LatticePoint m = c;
          m[across] = level == 0 ? 0 : p_;
          id = v[index.at(m)];
          nodes_.emplace(key, id);
        } else {
          const auto it = nodes_.find(key);
          if (it != nodes_.end()) {
            id = it->second;
          } else {
            if (!map) map.emplace(ref, macro_.xyz.data(), v);
            const Column& col = column(b, index, v, c);
            const Eigen::VectorXd xi = points.row(r).transpose();
            const Eigen::Vector3d p =
                map->position(xi.data()) +
                col.shift * col.shiftAt(points(r, static_cast<Eigen::Index>(across)));
            const double xyz[3] = {p(0), p(1), p(2)};
            id = out_.addNode(xyz, macro_.dim, b.entity[e], std::nan(""), std::nan(""));
            nodes_.emplace(key, id);
          }
        }
        out.nodes[sub * static_cast<std::size_t>(nn) + static_cast<std::size_t>(r)] = id;
      }
    }
  }
  (b.type == CellType::Hexahedron ? stats_.hexahedra : stats_.prisms) += b.count();
  return out;
}

}  // namespace layer_splitting

Mesh splitBoundaryLayer(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                        LayerSplitStats* stats, const LayerHeights* heights) {
  LayerSplitStats local;
  return layer_splitting::LayerSplitter(macro, z, cad, heights, stats != nullptr ? *stats : local)
      .run();
}

void keepColumnsPlain(const Mesh& macro, int layers, std::size_t element, LayerHeights& heights) {
  std::size_t base = 0;
  std::optional<std::set<std::int64_t>> wall;  // made at the first block that may hold fans
  for (const ElementBlock& b : macro.blocks) {
    if (cellDimension(b.type) != macro.dim) continue;
    if (isLayerCell(macro, b)) {
      const std::size_t count = b.count() * static_cast<std::size_t>(layers);
      if (element >= base + count) {
        base += count;
        continue;
      }
      const std::size_t e = (element - base) / static_cast<std::size_t>(layers);
      const ReferenceElement& ref = ReferenceElement::get(b.type, b.order);
      const std::size_t across = layerShape(b.type).across;
      for (int r = 0; r < ref.numNodes(); ++r)
        if (ref.lattice()[static_cast<std::size_t>(r)][across] == b.order)
          heights.plain.insert(b.element(e)[r]);
      return;
    }
    if (!mayHoldFans(macro, b)) {  // one element each
      if (element >= base + b.count()) {
        base += b.count();
        continue;
      }
      return;
    }
    if (!wall) wall = layerWall(macro);
    const std::vector<char> fan = fanTriangles(b, *wall);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::size_t count = fan[e] != 0 ? 2 * static_cast<std::size_t>(layers) - 1 : 1;
      if (element >= base + count) {
        base += count;
        continue;
      }
      if (fan[e] == 0) return;
      // Its two vertices off the wall are its columns' tops (the corner is on no column).
      for (int k = 0; k < 3; ++k)
        if (wall->count(b.element(e)[k]) == 0) heights.plain.insert(b.element(e)[k]);
      return;
    }
  }
}

std::vector<double> grownLayerHeights(const Mesh& linear) {
  std::vector<double> heights(linear.numNodes(), std::nan(""));
  for (const ElementBlock& b : linear.blocks) {
    if (!isLayerCell(linear, b)) continue;
    const LayerShape shape = layerShape(b.type);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < shape.walls; ++k) {
        const std::int64_t t = shape.top(v, k);
        heights[static_cast<std::size_t>(v[k])] =
            (Eigen::Vector3d(&linear.xyz[3 * static_cast<std::size_t>(t)]) -
             Eigen::Vector3d(&linear.xyz[3 * static_cast<std::size_t>(v[k])]))
                .norm();
      }
    }
  }
  return heights;
}

}  // namespace homesh
