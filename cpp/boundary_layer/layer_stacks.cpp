#include "boundary_layer/layer_stacks.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>

#include "linear/edge_split.hpp"

namespace homesh {
namespace {

using Tri = std::array<std::int64_t, 3>;

Tri sorted(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

// A volume cell: its block and index there.
struct CellRef {
  std::size_t block = 0, element = 0;
  bool operator<(const CellRef& o) const {
    return block != o.block ? block < o.block : element < o.element;
  }
  bool operator==(const CellRef& o) const { return block == o.block && element == o.element; }
};

// The triangular faces of each volume type, as local corners.
std::vector<std::array<int, 3>> triangleFaces(CellType type) {
  switch (type) {
    case CellType::Tetrahedron:
      return {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    case CellType::Prism:
      return {{0, 1, 2}, {3, 4, 5}};
    case CellType::Pyramid:
      return {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    default:
      return {};
  }
}

std::string prismName(const CellRef& c) {
  return "prism " + std::to_string(c.element + 1);
}

// One stack: its columns' nodes, wall (level 0) to top, for the wall triangle's three corners
// in an order that keeps the macro prism positive.
struct Stack {
  std::array<std::vector<std::int64_t>, 3> columns;
};

class Recogniser {
 public:
  explicit Recogniser(const Mesh& mesh) : mesh_(mesh) {
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
      const ElementBlock& block = mesh.blocks[b];
      if (cellDimension(block.type) == 3) {
        for (std::size_t e = 0; e < block.count(); ++e) {
          const std::int64_t* v = block.element(e);
          for (const auto& f : triangleFaces(block.type))
            faceCells_[sorted({v[f[0]], v[f[1]], v[f[2]]})].push_back({b, e});
          if (block.type == CellType::Prism) prisms_.push_back({b, e});
        }
      } else if (block.type == CellType::Triangle) {
        for (std::size_t e = 0; e < block.count(); ++e) {
          const std::int64_t* v = block.element(e);
          boundary_.emplace(sorted({v[0], v[1], v[2]}), block.entity[e]);
        }
      }
    }
  }

  bool hasPrisms() const { return !prisms_.empty(); }

  // The stacks, or nothing with the reason in `why`.
  std::optional<std::vector<Stack>> stacks(std::string& why) {
    std::vector<Stack> out;
    for (const CellRef& p : prisms_) {
      const std::int64_t* v = cell(p);
      const bool bottom = boundary_.count(sorted({v[0], v[1], v[2]})) != 0;
      const bool top = boundary_.count(sorted({v[3], v[4], v[5]})) != 0;
      if (bottom && top) {
        why = prismName(p) + " has both triangles on the boundary: it spans the domain";
        return std::nullopt;
      }
      if (!bottom && !top) continue;
      const auto wall = bottom ? Tri{v[0], v[1], v[2]} : Tri{v[3], v[5], v[4]};
      walls_.insert(boundary_.at(sorted(wall)));
      std::optional<Stack> s = climb(p, bottom, why);
      if (!s) return std::nullopt;
      out.push_back(std::move(*s));
    }
    for (const CellRef& p : prisms_)
      if (seen_.count(p) == 0) {
        why = prismName(p) + " is in no stack of prisms standing on the boundary";
        return std::nullopt;
      }
    return out;
  }

  const std::set<int>& walls() const { return walls_; }

 private:
  const std::int64_t* cell(const CellRef& c) const {
    return mesh_.blocks[c.block].element(c.element);
  }

  // The stack standing on prism `p`'s bottom (or top) triangle.
  std::optional<Stack> climb(CellRef p, bool fromBottom, std::string& why) {
    Stack s;
    const std::int64_t* v = cell(p);
    // Standing on the top triangle, its corners 3, 5, 4 (0, 2, 1 of the triangle) keep the
    // macro prism positive.
    const std::array<int, 3> order =
        fromBottom ? std::array<int, 3>{0, 1, 2} : std::array<int, 3>{3, 5, 4};
    for (int k = 0; k < 3; ++k) s.columns[k] = {v[order[k]]};
    for (;;) {
      if (!seen_.insert(p).second) {
        why = prismName(p) + " is in two stacks";
        return std::nullopt;
      }
      const std::int64_t* c = cell(p);
      // The next level: the vertex across the prism from each column's last node.
      for (auto& column : s.columns) {
        const int at = static_cast<int>(std::find(c, c + 6, column.back()) - c);
        column.push_back(c[at < 3 ? at + 3 : at - 3]);
      }
      const Tri far = sorted({s.columns[0].back(), s.columns[1].back(), s.columns[2].back()});
      if (boundary_.count(far) != 0) {
        why = "the column of prisms through " + prismName(p) +
              " reaches the boundary at both ends: it spans the domain";
        return std::nullopt;
      }
      const std::vector<CellRef>& across = faceCells_.at(far);
      const auto next =
          std::find_if(across.begin(), across.end(), [&](const CellRef& o) { return !(o == p); });
      if (next == across.end() || mesh_.blocks[next->block].type != CellType::Prism) return s;
      p = *next;
    }
  }

  const Mesh& mesh_;
  std::map<Tri, std::vector<CellRef>> faceCells_;
  std::map<Tri, int> boundary_;  // boundary triangle -> its CAD face
  std::vector<CellRef> prisms_;
  std::set<CellRef> seen_;
  std::set<int> walls_;
};

constexpr std::int64_t kInside = -1;

// Each column node's wall vertex and level, or nothing with the reason.
bool levelNodes(const std::vector<Stack>& stacks, std::size_t numNodes,
                std::vector<std::pair<std::int64_t, int>>& place, std::string& why) {
  place.assign(numNodes, {kInside, 0});
  for (const Stack& s : stacks)
    for (const auto& column : s.columns)
      for (std::size_t k = 0; k < column.size(); ++k) {
        auto& at = place[static_cast<std::size_t>(column[k])];
        const std::pair<std::int64_t, int> mine{column[0], static_cast<int>(k)};
        if (at.first != kInside && at != mine) {
          why = "node " + std::to_string(column[k] + 1) + " is in two columns of the layer";
          return false;
        }
        at = mine;
      }
  return true;
}

// Replaces the boundary cells of the layer's sides by macro ones: a side cell of the first
// layer (quadrilateral or line, with nodes at levels 0 and 1 of its columns) keeps its
// orientation with its level-1 nodes replaced by their columns' tops; those of the layers above
// go. Fails when another cell uses a node inside the layer.
bool mergeSides(Mesh& macro, const std::vector<std::pair<std::int64_t, int>>& place,
                const std::map<std::int64_t, std::int64_t>& topOf, int layers, std::size_t& merged,
                std::string& why) {
  for (ElementBlock& b : macro.blocks) {
    if (b.type == CellType::Prism) continue;
    const int nv = cellNumVertices(b.type);
    ElementBlock out;
    out.type = b.type;
    out.order = b.order;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      int inner = 0, low = std::numeric_limits<int>::max(), high = -1;
      for (int k = 0; k < nv; ++k) {
        const auto& [wall, level] = place[static_cast<std::size_t>(v[k])];
        if (wall == kInside) {
          low = -1;
          continue;
        }
        inner += level > 0 && level < layers ? 1 : 0;
        low = std::min(low, level);
        high = std::max(high, level);
      }
      const bool side = (b.type == CellType::Quadrilateral || b.type == CellType::Line) &&
                        low >= 0 && high == low + 1;
      if (inner > 0 && !side) {
        why = "a " + cellShortName(b.type) + " cell " + std::to_string(e + 1) +
              " uses a node inside the layer";
        return false;
      }
      if (side && low > 0) continue;  // (a side cell above the first layer)
      std::vector<std::int64_t> nodes(v, v + nv);
      if (side) {
        for (std::int64_t& n : nodes)
          if (place[static_cast<std::size_t>(n)].second == 1)
            n = topOf.at(place[static_cast<std::size_t>(n)].first);
        merged += b.type == CellType::Quadrilateral ? 1 : 0;
      }
      out.nodes.insert(out.nodes.end(), nodes.begin(), nodes.end());
      out.entity.push_back(b.entity[e]);
    }
    b = std::move(out);
  }
  return true;
}

}  // namespace

std::optional<LayerStacks> recogniseLayerStacks(const Mesh& mesh, std::string& why) {
  why.clear();
  Recogniser recogniser(mesh);
  if (!recogniser.hasPrisms()) return std::nullopt;
  std::optional<std::vector<Stack>> stacks = recogniser.stacks(why);
  if (!stacks) return std::nullopt;
  if (stacks->empty()) {
    why = "no prism stands on the boundary";
    return std::nullopt;
  }
  LayerStacks out;
  out.record.layers = static_cast<int>(stacks->front().columns[0].size()) - 1;
  for (const Stack& s : *stacks)
    if (static_cast<int>(s.columns[0].size()) - 1 != out.record.layers) {
      why = "its prism stacks have " + std::to_string(out.record.layers) + " and " +
            std::to_string(s.columns[0].size() - 1) + " layers";
      return std::nullopt;
    }
  std::vector<std::pair<std::int64_t, int>> place;
  if (!levelNodes(*stacks, mesh.numNodes(), place, why)) return std::nullopt;

  // Levels and first-layer heights, per column.
  std::map<std::int64_t, std::vector<std::int64_t>> columns;
  for (const Stack& s : *stacks)
    for (const auto& c : s.columns)
      if (const auto [it, fresh] = columns.emplace(c[0], c); !fresh && it->second != c) {
        why = "wall node " + std::to_string(c[0] + 1) + " has two columns of prisms";
        return std::nullopt;
      }
  const auto point = [&](std::int64_t n) { return nodePoint(mesh, n); };
  std::map<std::int64_t, std::int64_t> topOf;
  std::map<std::int64_t, std::vector<double>> fractions;
  out.record.levels.assign(static_cast<std::size_t>(out.record.layers) + 1, 0.0);
  for (const auto& [wall, c] : columns) {
    topOf[wall] = c.back();
    std::vector<double> f(c.size(), 0.0);
    for (std::size_t k = 1; k < c.size(); ++k)
      f[k] = f[k - 1] + (point(c[k]) - point(c[k - 1])).norm();
    for (double& x : f) x /= f.back();
    for (std::size_t k = 0; k < f.size(); ++k)
      out.record.levels[k] += f[k] / static_cast<double>(columns.size());
    fractions[wall] = std::move(f);
  }
  out.record.levels.back() = 1.0;
  for (const auto& [wall, f] : fractions)
    for (std::size_t k = 0; k < f.size(); ++k)
      out.record.levelSpread =
          std::max(out.record.levelSpread, std::abs(f[k] - out.record.levels[k]));

  // The macro mesh: one prism per stack, sides merged, inner nodes dropped.
  out.macro = mesh;
  ElementBlock macroPrisms;
  macroPrisms.type = CellType::Prism;
  for (const Stack& s : *stacks) {
    for (const auto& c : s.columns) macroPrisms.nodes.push_back(c.front());
    for (const auto& c : s.columns) macroPrisms.nodes.push_back(c.back());
    macroPrisms.entity.push_back(1);
  }
  std::vector<ElementBlock> blocks;
  for (ElementBlock& b : out.macro.blocks)
    if (b.type != CellType::Prism) blocks.push_back(std::move(b));
  const auto firstPrisms = std::find_if(mesh.blocks.begin(), mesh.blocks.end(),
                                        [](const auto& b) { return b.type == CellType::Prism; });
  // (Where the first prism block was, among the blocks kept before it.)
  const auto before = std::count_if(mesh.blocks.begin(), firstPrisms,
                                    [](const auto& b) { return b.type != CellType::Prism; });
  blocks.insert(blocks.begin() + before, std::move(macroPrisms));
  out.macro.blocks = std::move(blocks);
  if (!mergeSides(out.macro, place, topOf, out.record.layers, out.record.sidesMerged, why))
    return std::nullopt;

  // Heights per node, carried through the renumbering compactNodes does.
  std::vector<double> heights(mesh.numNodes(), std::numeric_limits<double>::quiet_NaN());
  out.record.firstHeightMin = std::numeric_limits<double>::infinity();
  for (const auto& [wall, c] : columns) {
    const double h = (point(c[1]) - point(c[0])).norm();
    heights[static_cast<std::size_t>(wall)] = h;
    out.record.firstHeightMin = std::min(out.record.firstHeightMin, h);
    out.record.firstHeightMax = std::max(out.record.firstHeightMax, h);
  }
  std::vector<char> used(mesh.numNodes(), 0);
  for (const ElementBlock& b : out.macro.blocks)
    for (const std::int64_t n : b.nodes) used[static_cast<std::size_t>(n)] = 1;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i] != 0) out.firstHeights.push_back(heights[i]);
  compactNodes(out.macro);
  out.macro.checkConsistency();
  out.record.stacks = stacks->size();
  out.record.columns = columns.size();
  out.record.walls = recogniser.walls();
  return out;
}

}  // namespace homesh
