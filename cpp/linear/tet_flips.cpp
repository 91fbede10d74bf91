#include "linear/tet_flips.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "linear/edge_split.hpp"

namespace homesh {
namespace {

using Tet = std::array<std::int64_t, 4>;
using Triangle = std::array<int, 3>;  // ring positions

// Every triangulation of the polygons in `open` (intervals [a, b] of ring positions, each
// closed by its chord (a, b)), each appended to `stack` in turn and written to `out`: a polygon
// takes a triangle (a, k, b) on its chord, which leaves the polygons [a, k] and [k, b].
void triangulate(std::vector<std::pair<int, int>>& open, std::vector<Triangle>& stack,
                 std::vector<std::vector<Triangle>>& out) {
  if (open.empty()) {
    out.push_back(stack);
    return;
  }
  const auto [a, b] = open.back();
  open.pop_back();
  if (b - a < 2) {  // a side of the polygon: nothing inside it
    triangulate(open, stack, out);
  } else {
    for (int k = a + 1; k < b; ++k) {
      stack.push_back({a, k, b});
      open.emplace_back(a, k);
      open.emplace_back(k, b);
      triangulate(open, stack, out);
      open.pop_back();
      open.pop_back();
      stack.pop_back();
    }
  }
  open.emplace_back(a, b);
}

// The triangulations of a convex polygon with vertices 0 .. n-1.
std::vector<std::vector<Triangle>> triangulations(int n) {
  std::vector<std::vector<Triangle>> out;
  std::vector<Triangle> stack;
  std::vector<std::pair<int, int>> open{{0, n - 1}};
  triangulate(open, stack, out);
  return out;
}

constexpr int kMaxRing = 7;  // 42 triangulations of the ring at most

// Whether the permutation taking (0, 1, 2, 3) to `order` is even.
bool evenPermutation(std::array<int, 4> order) {
  int swaps = 0;
  for (int i = 0; i < 4; ++i)
    while (order[static_cast<std::size_t>(i)] != i) {
      std::swap(order[static_cast<std::size_t>(i)],
                order[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])]);
      ++swaps;
    }
  return swaps % 2 == 0;
}

int slot(const Tet& t, std::int64_t v) {
  for (int k = 0; k < 4; ++k)
    if (t[static_cast<std::size_t>(k)] == v) return k;
  return -1;
}

// Whether (a, b, c, d), a reordering of t's vertices, keeps t's (positive) orientation.
bool sameOrientation(const Tet& t, std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d) {
  return evenPermutation({slot(t, a), slot(t, b), slot(t, c), slot(t, d)});
}

// The mesh's tetrahedra, which of them are still there, the cells around every node, and what
// a flip must leave alone (boundary nodes, edges and faces).
class TetTopology {
 public:
  TetTopology(const Mesh& mesh, const ElementBlock& block, const std::vector<double>& xyz)
      : mesh_(mesh),
        xyz_(xyz),
        aroundNode_(mesh.numNodes()),
        faces_(mesh.numNodes()),
        boundaryEdges_(boundaryEdges(mesh)) {
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      add({v[0], v[1], v[2], v[3]}, block.entity[e]);
    }
    for (const ElementBlock& b : mesh.blocks) {
      if (cellDimension(b.type) != 2) continue;
      const int nv = cellNumVertices(b.type);
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        for (int k = 0; k < nv; ++k) {
          auto& faces = faces_[static_cast<std::size_t>(v[k])];
          if (std::find(faces.begin(), faces.end(), b.entity[e]) == faces.end())
            faces.push_back(b.entity[e]);
        }
        if (nv == 3) {
          std::array<std::int64_t, 3> f{v[0], v[1], v[2]};
          std::sort(f.begin(), f.end());
          boundaryFaces_.insert(f);
        }
      }
    }
  }

  std::size_t add(const Tet& t, std::int32_t entity) {
    const std::size_t id = tets_.size();
    tets_.push_back(t);
    entity_.push_back(entity);
    alive_.push_back(1);
    for (const std::int64_t v : t) aroundNode_[static_cast<std::size_t>(v)].push_back(id);
    return id;
  }
  void remove(std::size_t id) {
    alive_[id] = 0;
    for (const std::int64_t v : tets_[id]) {
      auto& list = aroundNode_[static_cast<std::size_t>(v)];
      list.erase(std::find(list.begin(), list.end(), id));
    }
  }

  // The live cells that have every node of `nodes`.
  std::vector<std::size_t> cellsWith(std::initializer_list<std::int64_t> nodes) const {
    std::vector<std::size_t> out;
    const std::int64_t first = *nodes.begin();
    for (const std::size_t c : aroundNode_[static_cast<std::size_t>(first)]) {
      bool all = true;
      for (const std::int64_t v : nodes) all = all && slot(tets_[c], v) >= 0;
      if (all) out.push_back(c);
    }
    return out;
  }

  // Whether a flip may add the edge (a, b): not an edge yet, and not a chord of one CAD face
  // (ends on a common face: on a curved face curving cannot follow it, on a planar one it would
  // lie in the boundary). Ends on the boundary of different faces are allowed: across a thin wall
  // every edge joins two boundary nodes.
  bool newEdgeAllowed(std::int64_t a, std::int64_t b) const {
    return !onOneFace({a, b}) && cellsWith({a, b}).empty();
  }
  // Whether a flip may add the interior face (a, b, c): its vertices not all on one CAD face
  // (a 3-2 flip adds a face whose edges all exist, so the edge rule does not see it).
  bool newFaceAllowed(std::int64_t a, std::int64_t b, std::int64_t c) const {
    return !onOneFace({a, b, c});
  }
  bool boundaryEdge(std::int64_t a, std::int64_t b) const {
    return boundaryEdges_.count(meshEdge(a, b)) != 0;
  }
  bool boundaryFace(std::array<std::int64_t, 3> f) const {
    std::sort(f.begin(), f.end());
    return boundaryFaces_.count(f) != 0;
  }

  double shape(const Tet& t) const {
    return tetShape(point(t[0]), point(t[1]), point(t[2]), point(t[3]));
  }
  // A new cell must be positive at the mesh's own coordinates too: the linear mesh stays a mesh.
  bool positiveInMesh(const Tet& t) const { return simplexVolume(mesh_, t.data()) > 0.0; }

  const Tet& tet(std::size_t id) const { return tets_[id]; }
  std::int32_t entity(std::size_t id) const { return entity_[id]; }
  bool alive(std::size_t id) const { return alive_[id] != 0; }
  std::size_t size() const { return tets_.size(); }

 private:
  // Whether some boundary face holds every node of `nodes`.
  bool onOneFace(std::initializer_list<std::int64_t> nodes) const {
    const auto& first = faces_[static_cast<std::size_t>(*nodes.begin())];
    return std::any_of(first.begin(), first.end(), [&](std::int32_t f) {
      return std::all_of(nodes.begin(), nodes.end(), [&](std::int64_t v) {
        const auto& faces = faces_[static_cast<std::size_t>(v)];
        return std::find(faces.begin(), faces.end(), f) != faces.end();
      });
    });
  }
  Eigen::Vector3d point(std::int64_t v) const {
    const std::size_t i = 3 * static_cast<std::size_t>(v);
    return {xyz_[i], xyz_[i + 1], xyz_[i + 2]};
  }

  const Mesh& mesh_;
  const std::vector<double>& xyz_;
  std::vector<Tet> tets_;
  std::vector<std::int32_t> entity_;
  std::vector<char> alive_;
  std::vector<std::vector<std::size_t>> aroundNode_;
  std::vector<std::vector<std::int32_t>> faces_;  // per node, the boundary faces it lies on
  std::set<MeshEdge> boundaryEdges_;
  std::set<std::array<std::int64_t, 3>> boundaryFaces_;
};

// A candidate flip: the cells it removes and those it makes.
struct Flip {
  std::vector<std::size_t> removed;
  std::vector<Tet> made;
  double worstMade = -std::numeric_limits<double>::infinity();
  double worstRemoved = std::numeric_limits<double>::infinity();
};

// The cells around an interior edge (a, b), all of one solid, whose other vertices form one
// ring r_0 .. r_{n-1} oriented so that (a, b, r_i, r_{i+1}) is positive; empty otherwise.
std::vector<std::int64_t> ringAround(const TetTopology& topo, std::int64_t a, std::int64_t b,
                                     const std::vector<std::size_t>& around) {
  const std::size_t n = around.size();
  if (n < 3 || n > static_cast<std::size_t>(kMaxRing)) return {};
  std::vector<std::pair<std::int64_t, std::int64_t>> step;  // r_i -> r_{i+1}, one per cell
  for (const std::size_t c : around) {
    if (topo.entity(c) != topo.entity(around.front())) return {};
    const Tet& t = topo.tet(c);
    std::array<std::int64_t, 2> other{};
    int k = 0;
    for (const std::int64_t v : t)
      if (v != a && v != b) other[static_cast<std::size_t>(k++)] = v;
    if (sameOrientation(t, a, b, other[0], other[1])) {
      step.emplace_back(other[0], other[1]);
    } else {
      step.emplace_back(other[1], other[0]);
    }
  }
  std::vector<std::int64_t> ring{step.front().first};
  while (ring.size() <= n) {
    const auto next = std::find_if(step.begin(), step.end(),
                                   [&](const auto& s) { return s.first == ring.back(); });
    if (next == step.end()) return {};
    if (next->second == ring.front()) break;
    ring.push_back(next->second);
  }
  if (ring.size() != n) return {};  // not one closed ring: the edge is not interior
  return ring;
}

// The best edge removal of the interior edge (a, b) (rings of up to kMaxRing cells).
std::optional<Flip> bestEdgeRemoval(const TetTopology& topo, std::int64_t a, std::int64_t b,
                                    const std::vector<std::vector<std::vector<Triangle>>>& tables) {
  if (topo.boundaryEdge(a, b)) return std::nullopt;
  const std::vector<std::size_t> around = topo.cellsWith({a, b});
  const std::vector<std::int64_t> ring = ringAround(topo, a, b, around);
  if (ring.empty()) return std::nullopt;
  const int n = static_cast<int>(ring.size());
  Flip best;
  best.removed = around;
  for (const std::size_t c : around)
    best.worstRemoved = std::min(best.worstRemoved, topo.shape(topo.tet(c)));
  bool found = false;
  for (const std::vector<Triangle>& tris : tables[static_cast<std::size_t>(n)]) {
    bool allowed = true;
    for (const Triangle& t : tris) {
      allowed = allowed && topo.newFaceAllowed(ring[static_cast<std::size_t>(t[0])],
                                               ring[static_cast<std::size_t>(t[1])],
                                               ring[static_cast<std::size_t>(t[2])]);
      for (int s = 0; s < 3 && allowed; ++s) {
        const int i = t[static_cast<std::size_t>(s)], j = t[static_cast<std::size_t>((s + 1) % 3)];
        const int gap = std::abs(i - j);
        if (gap != 1 && gap != n - 1)  // a diagonal of the ring: a new edge
          allowed = topo.newEdgeAllowed(ring[static_cast<std::size_t>(i)],
                                        ring[static_cast<std::size_t>(j)]);
      }
    }
    if (!allowed) continue;
    std::vector<Tet> made;
    double worst = std::numeric_limits<double>::infinity();
    for (const Triangle& t : tris) {
      const std::int64_t ri = ring[static_cast<std::size_t>(t[0])];
      const std::int64_t rj = ring[static_cast<std::size_t>(t[1])];
      const std::int64_t rk = ring[static_cast<std::size_t>(t[2])];
      made.push_back({a, ri, rj, rk});
      made.push_back({b, rk, rj, ri});
      worst = std::min({worst, topo.shape(made[made.size() - 2]), topo.shape(made.back())});
    }
    const bool positive =
        std::all_of(made.begin(), made.end(), [&](const Tet& m) { return topo.positiveInMesh(m); });
    if (positive && (!found || worst > best.worstMade)) {
      best.made = std::move(made);
      best.worstMade = worst;
      found = true;
    }
  }
  if (!found) return std::nullopt;
  return best;
}

// The 2-3 flip of cell `c`'s face opposite its vertex `p`, if that face is interior.
std::optional<Flip> faceRemoval(const TetTopology& topo, std::size_t c, int p) {
  const Tet& t = topo.tet(c);
  std::array<std::int64_t, 3> f{};
  int k = 0;
  for (int i = 0; i < 4; ++i)
    if (i != p) f[static_cast<std::size_t>(k++)] = t[static_cast<std::size_t>(i)];
  if (topo.boundaryFace(f)) return std::nullopt;
  const std::int64_t apex = t[static_cast<std::size_t>(p)];
  // (f0, f1, f2, apex) positive: the face turns counter-clockwise seen from the apex.
  if (!sameOrientation(t, f[0], f[1], f[2], apex)) std::swap(f[1], f[2]);
  std::optional<std::size_t> other;
  for (const std::size_t d : topo.cellsWith({f[0], f[1], f[2]}))
    if (d != c) other = d;
  if (!other || topo.entity(*other) != topo.entity(c)) return std::nullopt;
  std::int64_t opposite = -1;
  for (const std::int64_t v : topo.tet(*other))
    if (v != f[0] && v != f[1] && v != f[2]) opposite = v;
  if (!topo.newEdgeAllowed(apex, opposite)) return std::nullopt;
  Flip flip;
  flip.removed = {c, *other};
  flip.worstRemoved = std::min(topo.shape(t), topo.shape(topo.tet(*other)));
  // Around the new edge (apex, opposite) the ring is (f0, f2, f1): (apex, opposite, r_i, r_i+1)
  // is positive for each of the three.
  flip.made = {
      {apex, opposite, f[0], f[2]}, {apex, opposite, f[2], f[1]}, {apex, opposite, f[1], f[0]}};
  flip.worstMade = std::numeric_limits<double>::infinity();
  for (const Tet& m : flip.made) {
    if (!topo.positiveInMesh(m)) return std::nullopt;
    flip.worstMade = std::min(flip.worstMade, topo.shape(m));
  }
  return flip;
}

}  // namespace

double tetShape(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                const Eigen::Vector3d& p3) {
  const Eigen::Vector3d e1 = p1 - p0, e2 = p2 - p0, e3 = p3 - p0;
  const double det = e1.cross(e2).dot(e3);  // 6 V
  const double squares = e1.squaredNorm() + e2.squaredNorm() + e3.squaredNorm() +
                         (p2 - p1).squaredNorm() + (p3 - p1).squaredNorm() +
                         (p3 - p2).squaredNorm();
  const double rms = std::sqrt(squares / 6.0);
  if (!(rms > 0.0)) return 0.0;
  return std::sqrt(2.0) * det / (rms * rms * rms);
}

FlipOutcome flipAwayCells(Mesh& mesh, const std::vector<std::size_t>& cells,
                          const std::vector<double>& positions) {
  ElementBlock* block = tetrahedronBlock(mesh, "flips");
  if (block == nullptr) return {};
  if (!positions.empty() && positions.size() != mesh.xyz.size())
    throw ParameterError("flips: " + std::to_string(positions.size()) + " position values for " +
                         std::to_string(mesh.numNodes()) + " nodes");
  for (const std::size_t c : cells)
    if (c >= block->count())
      throw ParameterError("flips: cell " + std::to_string(c) + " of a mesh of " +
                           std::to_string(block->count()) + " tetrahedra");

  TetTopology topo(mesh, *block, positions.empty() ? mesh.xyz : positions);
  const std::size_t original = topo.size();
  std::vector<std::vector<std::vector<Triangle>>> tables(kMaxRing + 1);
  for (int n = 3; n <= kMaxRing; ++n) tables[static_cast<std::size_t>(n)] = triangulations(n);

  FlipOutcome outcome;
  std::vector<char> changed(original, 0), asked(original, 0);
  for (const std::size_t c : cells) asked[c] = 1;
  for (const std::size_t c : cells) {
    if (changed[c] != 0) continue;  // an earlier flip took it away
    const Tet t = topo.tet(c);
    std::optional<Flip> best;
    // Among the flips that pass the gain test, the one whose worst new cell is best.
    const auto consider = [&best](std::optional<Flip> f) {
      if (!f || !(f->worstMade > 0.0) || !(f->worstMade > f->worstRemoved + kFlipShapeGain)) return;
      if (!best || f->worstMade > best->worstMade) best = std::move(f);
    };
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        consider(bestEdgeRemoval(topo, t[static_cast<std::size_t>(i)],
                                 t[static_cast<std::size_t>(j)], tables));
    for (int p = 0; p < 4; ++p) consider(faceRemoval(topo, c, p));
    if (!best) continue;
    const std::int32_t entity = topo.entity(c);
    for (const std::size_t r : best->removed) {
      topo.remove(r);
      if (r >= original) continue;
      changed[r] = 1;
      if (asked[r] != 0) ++outcome.cellsFlipped;
    }
    for (const Tet& m : best->made) topo.add(m, entity);
    ++outcome.flips;
  }
  if (outcome.flips == 0) return outcome;

  // The cells that stay, in their order, then the new ones.
  std::vector<std::int64_t> nodes;
  std::vector<std::int32_t> entity;
  nodes.reserve(4 * topo.size());
  for (std::size_t id = 0; id < topo.size(); ++id) {
    if (!topo.alive(id)) continue;
    nodes.insert(nodes.end(), topo.tet(id).begin(), topo.tet(id).end());
    entity.push_back(topo.entity(id));
  }
  block->nodes = std::move(nodes);
  block->entity = std::move(entity);
  return outcome;
}

}  // namespace homesh
