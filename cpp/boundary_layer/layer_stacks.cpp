#include "boundary_layer/layer_stacks.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>

#include "boundary_layer/layer_cells.hpp"
#include "linear/cad_classification.hpp"
#include "linear/edge_split.hpp"

namespace homesh {
namespace {

// A face of a volume cell or of the boundary, as its sorted vertices (a triangle's fourth is
// kNoVertex).
using FaceKey = std::array<std::int64_t, 4>;
constexpr std::int64_t kNoVertex = -1;

template <class Vertices>
FaceKey faceKey(const Vertices& vertices, std::size_t n) {
  FaceKey k{kNoVertex, kNoVertex, kNoVertex, kNoVertex};
  for (std::size_t i = 0; i < n; ++i) k[i] = vertices[i];
  std::sort(k.begin(), k.end());
  return k;
}

// A volume cell: its block and index there.
struct CellRef {
  std::size_t block = 0, element = 0;
  bool operator<(const CellRef& o) const {
    return block != o.block ? block < o.block : element < o.element;
  }
  bool operator==(const CellRef& o) const { return block == o.block && element == o.element; }
};

// A way through a layer cell: from the face `wall` to the opposite face `top`, wall[k] below
// top[k]. Each wall is ordered so that its normal (right-handed) points into the cell: the cell
// (wall, top) is then positive, as layer_cells.hpp orders a macro cell.
struct Climb {
  std::array<int, 4> wall, top;  // (a prism's fourth entries are unused)
};

const std::vector<Climb>& climbs(CellType type) {
  static const std::vector<Climb> prism{{{0, 1, 2, -1}, {3, 4, 5, -1}},
                                        {{3, 5, 4, -1}, {0, 2, 1, -1}}};
  static const std::vector<Climb> hexahedron{
      {{0, 1, 2, 3}, {4, 5, 6, 7}}, {{4, 7, 6, 5}, {0, 3, 2, 1}}, {{0, 4, 5, 1}, {3, 7, 6, 2}},
      {{3, 2, 6, 7}, {0, 1, 5, 4}}, {{0, 3, 7, 4}, {1, 2, 6, 5}}, {{1, 5, 6, 2}, {0, 4, 7, 3}}};
  return type == CellType::Prism ? prism : hexahedron;
}

std::size_t wallSize(CellType type) {
  return type == CellType::Prism ? 3 : 4;
}

std::string cellName(CellType type, const CellRef& c) {
  return (type == CellType::Prism ? "prism " : "hexahedron ") + std::to_string(c.element + 1);
}

// One stack: its cells, wall to top, and its columns' nodes, wall (level 0) to top, for the
// wall face's corners in an order that keeps the macro cell positive.
struct Stack {
  CellType type = CellType::Prism;
  std::vector<std::vector<std::int64_t>> columns;
  std::vector<CellRef> cells;
  int wall = 0;  // the CAD face it stands on
};

// How a climb ended: a stack, at the boundary again, back at a cell it passed, or at a cell that
// ends no stack of its type (a hexahedral stack ends at a pyramid).
enum class ClimbEnd { Stack, Spans, Loops, Blocked };

class Recogniser {
 public:
  explicit Recogniser(const Mesh& mesh) : mesh_(mesh) {
    for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
      const ElementBlock& block = mesh.blocks[b];
      if (cellDimension(block.type) == 3) {
        for (std::size_t e = 0; e < block.count(); ++e) {
          const std::int64_t* v = block.element(e);
          for (const std::vector<int>& f : cellFaceCorners(block.type)) {
            std::array<std::int64_t, 4> corners{};
            for (std::size_t i = 0; i < f.size(); ++i) corners[i] = v[f[i]];
            faceCells_[faceKey(corners, f.size())].push_back({b, e});
          }
          if (block.type == CellType::Prism) prisms_.push_back({b, e});
          if (block.type == CellType::Hexahedron) hexahedra_.push_back({b, e});
        }
      } else if (block.type == CellType::Triangle || block.type == CellType::Quadrilateral) {
        const auto n = static_cast<std::size_t>(cellNumVertices(block.type));
        for (std::size_t e = 0; e < block.count(); ++e)
          boundary_.emplace(faceKey(block.element(e), n), block.entity[e]);
      }
    }
  }

  bool hasPrisms() const { return !prisms_.empty(); }

  // The prisms' stacks, or nothing with the reason in `why`: every prism must be in one.
  std::optional<std::vector<Stack>> prismStacks(std::string& why) {
    std::vector<Stack> out;
    std::set<CellRef> seen;
    const std::vector<Climb>& ways = climbs(CellType::Prism);
    for (const CellRef& p : prisms_) {
      const bool bottom = onBoundary(p, ways[0]), top = onBoundary(p, ways[1]);
      if (bottom && top) {
        why = cellName(CellType::Prism, p) +
              " has both triangles on the boundary: it spans the domain";
        return std::nullopt;
      }
      if (!bottom && !top) continue;
      Stack s;
      CellRef last;
      const ClimbEnd end = climb(p, bottom ? ways[0] : ways[1], s, last);
      if (end == ClimbEnd::Spans) {
        why = "the column of prisms through " + cellName(CellType::Prism, last) +
              " reaches the boundary at both ends: it spans the domain";
        return std::nullopt;
      }
      for (const CellRef& c : s.cells)
        if (!seen.insert(c).second || end == ClimbEnd::Loops) {
          why = cellName(CellType::Prism, c) + " is in two stacks";
          return std::nullopt;
        }
      out.push_back(std::move(s));
    }
    for (const CellRef& p : prisms_)
      if (seen.count(p) == 0) {
        why = cellName(CellType::Prism, p) + " is in no stack of prisms standing on the boundary";
        return std::nullopt;
      }
    return out;
  }

  // The hexahedra's stacks: the climbs from every boundary face of a hexahedron that end at a
  // pyramid. Nothing, with the reason in `why`, when a hexahedron is in two of them.
  std::optional<std::vector<Stack>> hexahedralStacks(std::string& why) {
    std::vector<Stack> out;
    std::map<CellRef, int> owner;  // hexahedron -> the CAD face of the stack it is in
    for (const CellRef& h : hexahedra_)
      for (const Climb& way : climbs(CellType::Hexahedron)) {
        if (!onBoundary(h, way)) continue;
        Stack s;
        CellRef last;
        if (climb(h, way, s, last) != ClimbEnd::Stack) continue;
        for (const CellRef& c : s.cells)
          if (const auto [it, fresh] = owner.emplace(c, s.wall); !fresh) {
            why = cellName(CellType::Hexahedron, c) + " is in two stacks of hexahedra, on Face" +
                  std::to_string(it->second) + " and Face" + std::to_string(s.wall);
            return std::nullopt;
          }
        out.push_back(std::move(s));
      }
    return out;
  }

 private:
  const std::int64_t* cell(const CellRef& c) const {
    return mesh_.blocks[c.block].element(c.element);
  }
  CellType type(const CellRef& c) const { return mesh_.blocks[c.block].type; }

  // The face of cell c that `way` starts from.
  FaceKey wallOf(const CellRef& c, const Climb& way) const {
    const std::int64_t* v = cell(c);
    std::array<std::int64_t, 4> corners{};
    const std::size_t n = wallSize(type(c));
    for (std::size_t i = 0; i < n; ++i) corners[i] = v[way.wall[i]];
    return faceKey(corners, n);
  }
  bool onBoundary(const CellRef& c, const Climb& way) const {
    return boundary_.count(wallOf(c, way)) != 0;
  }

  // The climb from cell c's face way.wall outwards through cells of c's type, each entered by
  // the face the one before left by: its cells and columns in `s`, the last cell in `last`.
  ClimbEnd climb(CellRef c, const Climb& way, Stack& s, CellRef& last) const {
    const CellType t = type(c);
    const std::size_t n = wallSize(t);
    s.type = t;
    s.wall = boundary_.at(wallOf(c, way));
    s.columns.assign(n, {});
    for (std::size_t k = 0; k < n; ++k) s.columns[k] = {cell(c)[way.wall[k]]};
    std::set<CellRef> passed;
    for (;;) {
      last = c;
      if (!passed.insert(c).second) return ClimbEnd::Loops;
      s.cells.push_back(c);
      const std::int64_t* v = cell(c);
      std::array<std::int64_t, 4> ends{};
      for (std::size_t k = 0; k < n; ++k) ends[k] = s.columns[k].back();
      const FaceKey in = faceKey(ends, n);
      const auto through = std::find_if(climbs(t).begin(), climbs(t).end(),
                                        [&](const Climb& w) { return wallOf(c, w) == in; });
      // (The face the climb entered by is one of c's: the one before shares it.)
      for (auto& column : s.columns) {
        const auto at = static_cast<std::size_t>(
            std::find(through->wall.begin(), through->wall.begin() + static_cast<long>(n),
                      std::find(v, v + cellNumVertices(t), column.back()) - v) -
            through->wall.begin());
        column.push_back(v[through->top[at]]);
      }
      for (std::size_t k = 0; k < n; ++k) ends[k] = s.columns[k].back();
      const FaceKey far = faceKey(ends, n);
      if (boundary_.count(far) != 0) return ClimbEnd::Spans;
      const std::vector<CellRef>& across = faceCells_.at(far);
      const auto next =
          std::find_if(across.begin(), across.end(), [&](const CellRef& o) { return !(o == c); });
      if (next != across.end() && type(*next) == t) {
        c = *next;
        continue;
      }
      // A prism stack ends at a tetrahedron or pyramid; a hexahedral one at a pyramid.
      const bool stack =
          t == CellType::Prism || (next != across.end() && type(*next) == CellType::Pyramid);
      return stack ? ClimbEnd::Stack : ClimbEnd::Blocked;
    }
  }

  const Mesh& mesh_;
  std::map<FaceKey, std::vector<CellRef>> faceCells_;
  std::map<FaceKey, int> boundary_;  // boundary triangle or quadrilateral -> its CAD face
  std::vector<CellRef> prisms_, hexahedra_;
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
    if (isLayerCell(macro, b)) continue;
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

// The given blocks with the stacks' cells replaced by macro cells, the hexahedra's marked as
// layer cells: each type's macro block where the first block of that type was, the cells of that
// type in no stack kept after it. (One pass over the given blocks: `stacks` name cells by their
// given block index.)
void replaceByMacroCells(std::vector<ElementBlock>& blocks, const std::vector<Stack>& stacks) {
  std::map<CellType, ElementBlock> macro;
  std::set<std::pair<std::size_t, std::size_t>> inStacks;
  for (const Stack& s : stacks) {
    ElementBlock& m = macro[s.type];
    m.type = s.type;
    m.layerCells = s.type == CellType::Hexahedron;
    for (const auto& c : s.columns) m.nodes.push_back(c.front());
    for (const auto& c : s.columns) m.nodes.push_back(c.back());
    m.entity.push_back(1);
    for (const CellRef& c : s.cells) inStacks.insert({c.block, c.element});
  }
  std::vector<ElementBlock> out;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    ElementBlock& block = blocks[b];
    const auto m = macro.find(block.type);
    if (m == macro.end()) {
      out.push_back(std::move(block));
      continue;
    }
    if (m->second.count() > 0) {
      out.push_back(std::move(m->second));
      m->second = ElementBlock{};
    }
    ElementBlock kept;
    kept.type = block.type;
    kept.order = block.order;
    const auto per = static_cast<std::size_t>(block.nodesPerElement());
    for (std::size_t e = 0; e < block.count(); ++e) {
      if (inStacks.count({b, e}) != 0) continue;
      kept.nodes.insert(kept.nodes.end(), block.element(e), block.element(e) + per);
      kept.entity.push_back(block.entity[e]);
    }
    if (kept.count() > 0) out.push_back(std::move(kept));
  }
  blocks = std::move(out);
}

// Each column's node fractions along it (levelNodes has checked that a wall node has one
// column), by wall node: their mean over the columns in `record.levels`, its spread in
// `record.levelSpread`.
std::map<std::int64_t, std::vector<double>> meanLevels(
    const Mesh& mesh, const std::map<std::int64_t, std::vector<std::int64_t>>& columns,
    LayerStacksRecord& record) {
  std::map<std::int64_t, std::vector<double>> fractions;
  record.levels.assign(static_cast<std::size_t>(record.layers) + 1, 0.0);
  for (const auto& [wall, c] : columns) {
    std::vector<double> f(c.size(), 0.0);
    for (std::size_t k = 1; k < c.size(); ++k)
      f[k] = f[k - 1] + (nodePoint(mesh, c[k]) - nodePoint(mesh, c[k - 1])).norm();
    for (double& x : f) x /= f.back();
    for (std::size_t k = 0; k < f.size(); ++k)
      record.levels[k] += f[k] / static_cast<double>(columns.size());
    fractions[wall] = std::move(f);
  }
  record.levels.back() = 1.0;
  for (const auto& [wall, f] : fractions)
    for (std::size_t k = 0; k < f.size(); ++k)
      record.levelSpread = std::max(record.levelSpread, std::abs(f[k] - record.levels[k]));
  return fractions;
}

// The stacks (prisms' and hexahedra's, not empty) agglomerated, or nothing with the reason.
std::optional<LayerStacks> agglomerate(const Mesh& mesh, const std::vector<Stack>& stacks,
                                       std::string& why) {
  LayerStacks out;
  out.record.layers = static_cast<int>(stacks.front().columns[0].size()) - 1;
  for (const Stack& s : stacks)
    if (static_cast<int>(s.columns[0].size()) - 1 != out.record.layers) {
      why = "its stacks have " + std::to_string(out.record.layers) + " and " +
            std::to_string(s.columns[0].size() - 1) + " layers";
      return std::nullopt;
    }
  std::vector<std::pair<std::int64_t, int>> place;
  if (!levelNodes(stacks, mesh.numNodes(), place, why)) return std::nullopt;
  std::map<std::int64_t, std::vector<std::int64_t>> columns;
  std::map<std::int64_t, std::int64_t> topOf;
  for (const Stack& s : stacks) {
    for (const auto& c : s.columns) {
      if (const auto [it, fresh] = columns.emplace(c[0], c); !fresh && it->second != c) {
        why = "wall node " + std::to_string(c[0] + 1) + " has two columns of cells";
        return std::nullopt;
      }
      topOf[c[0]] = c.back();
    }
    out.record.walls.insert(s.wall);
    out.record.hexStacks += s.type == CellType::Hexahedron ? 1 : 0;
  }
  std::map<std::int64_t, std::vector<double>> fractions = meanLevels(mesh, columns, out.record);

  // The macro mesh: one cell per stack, sides merged, inner nodes dropped.
  out.macro = mesh;
  replaceByMacroCells(out.macro.blocks, stacks);
  if (!mergeSides(out.macro, place, topOf, out.record.layers, out.record.sidesMerged, why))
    return std::nullopt;

  // Heights per node, carried through the renumbering compactNodes does.
  std::vector<double> heights(mesh.numNodes(), std::numeric_limits<double>::quiet_NaN());
  out.record.firstHeightMin = std::numeric_limits<double>::infinity();
  for (const auto& [wall, c] : columns) {
    const double h = (nodePoint(mesh, c[1]) - nodePoint(mesh, c[0])).norm();
    heights[static_cast<std::size_t>(wall)] = h;
    out.record.firstHeightMin = std::min(out.record.firstHeightMin, h);
    out.record.firstHeightMax = std::max(out.record.firstHeightMax, h);
  }
  std::vector<char> used(mesh.numNodes(), 0);
  for (const ElementBlock& b : out.macro.blocks)
    for (const std::int64_t n : b.nodes) used[static_cast<std::size_t>(n)] = 1;
  for (std::size_t i = 0; i < used.size(); ++i) {
    if (used[i] == 0) continue;
    out.firstHeights.push_back(heights[i]);
    const auto f = fractions.find(static_cast<std::int64_t>(i));
    out.givenLevels.push_back(f != fractions.end() ? std::move(f->second) : std::vector<double>());
  }
  compactNodes(out.macro);
  out.macro.checkConsistency();
  out.record.stacks = stacks.size();
  out.record.columns = columns.size();
  return out;
}

}  // namespace

std::optional<LayerStacks> recogniseLayerStacks(const Mesh& mesh, std::string& why,
                                                bool hexahedra) {
  why.clear();
  Recogniser recogniser(mesh);
  std::vector<Stack> prisms;
  if (recogniser.hasPrisms()) {
    std::optional<std::vector<Stack>> found = recogniser.prismStacks(why);
    if (!found) return std::nullopt;
    prisms = std::move(*found);
  }
  // With the hexahedra's stacks where there are any, else (or where they fail) without.
  std::string hexahedraWhy;
  const std::optional<std::vector<Stack>> hexahedral =
      hexahedra ? recogniser.hexahedralStacks(hexahedraWhy) : std::vector<Stack>();
  if (hexahedral && !hexahedral->empty()) {
    std::vector<Stack> all = prisms;
    all.insert(all.end(), hexahedral->begin(), hexahedral->end());
    if (std::optional<LayerStacks> out = agglomerate(mesh, all, hexahedraWhy)) return out;
  }
  if (prisms.empty()) {
    why = hexahedraWhy;
    return std::nullopt;
  }
  std::optional<LayerStacks> out = agglomerate(mesh, prisms, why);
  if (out) out->hexahedraLeftOut = hexahedraWhy;
  return out;
}

}  // namespace homesh
