#include "curving/order_elevation.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "core/error.hpp"
#include "curving/curve_node_placement.hpp"
#include "curving/face_node_placement.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A node by its support: the global vertices with a non-zero weight in the straight-sided
// (multi)linear map, sorted by vertex, with those weights as integers over kScale(P) = P^3.
// The weight a point gives each vertex of the edge, face or cell it lies in is intrinsic (the
// same from every cell that has the point, whatever its local orientation or shape: a
// triangle face weights its vertices alike from a tetrahedron and from a prism, a
// quadrilateral face alike from the two hexahedra on it), so equal keys mean one node.
constexpr int kMaxSupport = 8;

struct NodeKey {
  std::array<std::int64_t, kMaxSupport> vertex{};
  std::array<int, kMaxSupport> index{};  // weight x P^3
  int size = 0;
  bool operator==(const NodeKey& o) const {
    return size == o.size && vertex == o.vertex && index == o.index;
  }
};

struct NodeKeyHash {
  std::size_t operator()(const NodeKey& k) const {
    auto h = static_cast<std::size_t>(k.size);
    for (int i = 0; i < k.size; ++i) {
      h = h * 1000003u ^ static_cast<std::size_t>(k.vertex[i]);
      h = h * 1000003u ^ static_cast<std::size_t>(k.index[i]);
    }
    return h;
  }
};

int cube(int p) {
  return p * p * p;
}

// The node ids by key. Keys of edge and triangle nodes (support 2 or 3, almost every new node)
// are packed into 128 bits and kept in an open-addressing table: one probe of a flat array
// instead of a bucket list of heap nodes (the lookups were the largest single cost of a run
// on OpenCASCADE's bottle). Other keys (quadrilateral faces and cell interiors) and vertex ids
// of 2^32 or more go to a hash map. The ids are the same as with one map: the caller numbers a
// node when its key is first seen.
class NodeIndex {
 public:
  // The id of `key`, or `fresh` (then stored for it) when it is new; `inserted` says which.
  std::int64_t findOrInsert(const NodeKey& key, std::int64_t fresh, bool& inserted) {
    std::uint64_t lo = 0, hi = 0;
    if (!pack(key, lo, hi)) {
      const auto [it, added] = other_.try_emplace(key, fresh);
      inserted = added;
      return it->second;
    }
    if (2 * (used_ + 1) > slots_.size()) grow();
    Slot& slot = probe(slots_, lo, hi);
    inserted = slot.hi == 0;
    if (inserted) {
      slot = {lo, hi, fresh};
      ++used_;
    }
    return slot.id;
  }

  // Starts loading the slot `key` would probe first: a lookup in a table of a million nodes
  // waits on memory, and an element's keys fetched together wait once (the elevation of 67,000
  // order-4 tetrahedra spent half its time on that wait).
  void prefetch(const NodeKey& key) const {
    std::uint64_t lo = 0, hi = 0;
    if (slots_.empty() || !pack(key, lo, hi)) return;
    __builtin_prefetch(&slots_[mix(lo ^ mix(hi)) & (slots_.size() - 1)]);
  }

  // Every (key, id), the packed ones decoded (vertex 0's weight is P^3 less the others').
  template <class Fn>
  void forEach(int order, Fn&& fn) const {
    for (const Slot& slot : slots_)
      if (slot.hi != 0) fn(unpack(slot.lo, slot.hi, cube(order)), slot.id);
    for (const auto& [key, id] : other_) fn(key, id);
  }

 private:
  struct Slot {
    std::uint64_t lo = 0, hi = 0;  // hi == 0: empty (a packed key's size, 2 or 3, is in hi)
    std::int64_t id = 0;
  };

  // lo: vertex 0 | vertex 1 << 32; hi: size | index 1 << 2 | index 2 << 12 | vertex 2 << 22.
  static bool pack(const NodeKey& key, std::uint64_t& lo, std::uint64_t& hi) {
    if (key.size != 2 && key.size != 3) return false;
    constexpr std::int64_t kVertexLimit = std::int64_t{1} << 32;
    for (int i = 0; i < key.size; ++i)
      if (key.vertex[i] < 0 || key.vertex[i] >= kVertexLimit || key.index[i] < 0 ||
          key.index[i] >= 1024)
        return false;
    const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v); };
    lo = u(key.vertex[0]) | u(key.vertex[1]) << 32;
    hi = u(key.size) | u(key.index[1]) << 2;
    if (key.size == 3) hi |= u(key.index[2]) << 12 | u(key.vertex[2]) << 22;
    return true;
  }

  static NodeKey unpack(std::uint64_t lo, std::uint64_t hi, int total) {
    NodeKey key;
    key.size = static_cast<int>(hi & 3U);
    key.vertex[0] = static_cast<std::int64_t>(lo & 0xffffffffU);
    key.vertex[1] = static_cast<std::int64_t>(lo >> 32);
    key.index[1] = static_cast<int>((hi >> 2) & 1023U);
    if (key.size == 3) {
      key.index[2] = static_cast<int>((hi >> 12) & 1023U);
      key.vertex[2] = static_cast<std::int64_t>(hi >> 22);
    }
    key.index[0] = total - key.index[1] - key.index[2];
    return key;
  }

  static std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  }

  // The slot holding (lo, hi), or the empty one where it would go (linear probing; the table
  // is at most half full, so an empty slot exists).
  static Slot& probe(std::vector<Slot>& slots, std::uint64_t lo, std::uint64_t hi) {
    const std::size_t mask = slots.size() - 1;
    std::size_t i = mix(lo ^ mix(hi)) & mask;
    while (slots[i].hi != 0 && (slots[i].lo != lo || slots[i].hi != hi)) i = (i + 1) & mask;
    return slots[i];
  }

  void grow() {
    std::vector<Slot> bigger(std::max<std::size_t>(1024, 2 * slots_.size()));
    for (const Slot& slot : slots_)
      if (slot.hi != 0) probe(bigger, slot.lo, slot.hi) = slot;
    slots_.swap(bigger);
  }

  std::vector<Slot> slots_;  // size a power of two
  std::size_t used_ = 0;
  std::unordered_map<NodeKey, std::int64_t, NodeKeyHash> other_;
};

// The vertex weights x P^3 of lattice point c of an order-P cell (node_ordering.hpp's lattice:
// quadrilateral corners (0,0) (P,0) (P,P) (0,P); prism triangle at k = 0 then k = P;
// hexahedron quadrilateral at k = 0 then k = P; pyramid square at k = 0, apex (0,0,P)).
std::array<int, kMaxSupport> vertexWeights(CellType type, const LatticePoint& c, int p) {
  std::array<int, kMaxSupport> w{};
  const int i = c[0], j = c[1], k = c[2];
  switch (type) {
    case CellType::Line:
      w[0] = (p - i) * p * p;
      w[1] = i * p * p;
      break;
    case CellType::Triangle:
    case CellType::Tetrahedron: {
      const std::array<int, 4> a = simplexBarycentric(c, cellDimension(type), p);
      for (int v = 0; v < cellNumVertices(type); ++v) w[v] = a[v] * p * p;
      break;
    }
    case CellType::Quadrilateral:
      w = {(p - i) * (p - j) * p, i * (p - j) * p, i * j * p, (p - i) * j * p};
      break;
    case CellType::Prism: {
      const int t[3] = {p - i - j, i, j};
      for (int v = 0; v < 3; ++v) {
        w[v] = t[v] * (p - k) * p;
        w[v + 3] = t[v] * k * p;
      }
      break;
    }
    case CellType::Hexahedron: {
      const int q[4] = {(p - i) * (p - j), i * (p - j), i * j, (p - i) * j};
      for (int v = 0; v < 4; ++v) {
        w[v] = q[v] * (p - k);
        w[v + 4] = q[v] * k;
      }
      break;
    }
    case CellType::Pyramid: {
      // Level k is a square of side s = p - k (lattice: apex above corner 0). On the faces the
      // straight-sided (order-1) pyramid's weights are integers over p^3 (a triangle face's its
      // barycentric weights, the base's the quadrilateral's), so neighbours key those nodes
      // alike. Inside, they are rational (x y / (1 - z)): the key is then only a code, one to one
      // with (i, j, k) (k, then i from a1 + a2, then j), and the node's position comes from the
      // element's own map (elevateBlock).
      const int s = p - k;
      if (s == 0) {
        w[4] = p * p * p;
        break;
      }
      const int base[4] = {(s - i) * (s - j), i * (s - j), i * j, (s - i) * j};
      const bool inside = k > 0 && i > 0 && j > 0 && i < s && j < s;
      for (int v = 0; v < 4; ++v) w[v] = inside ? base[v] * p : base[v] * p * p / s;
      w[4] = k * p * p;
      break;
    }
    default:
      throw ParameterError("changing the order does not support " + cellShortName(type));
  }
  return w;
}

using EdgeKey = std::array<std::int64_t, 2>;
using FaceKey = std::array<std::int64_t, 3>;
using QuadKey = std::array<std::int64_t, 4>;

template <std::size_t N>
std::array<std::int64_t, N> sorted(std::array<std::int64_t, N> a) {
  std::sort(a.begin(), a.end());
  return a;
}

// Which CAD entity the edges and faces of the linear mesh lie on.
struct BoundaryClassification {
  std::map<EdgeKey, int> edgeCurve;      // edge on a CAD curve
  std::map<EdgeKey, int> edgeFace;       // edge inside a CAD face
  std::map<FaceKey, int> faceFace;       // triangle on a CAD face (3D)
  std::map<QuadKey, int> quadFace;       // quadrilateral on a CAD face (3D)
  std::map<QuadKey, QuadKey> quadCycle;  // its vertices in cyclic order, by the sorted key

  explicit BoundaryClassification(const Mesh& linear) {
    for (const ElementBlock& block : linear.blocks) {
      const bool triangles = block.type == CellType::Triangle;
      const bool quads = block.type == CellType::Quadrilateral;
      for (std::size_t e = 0; e < block.count(); ++e) {
        const std::int64_t* v = block.element(e);
        if (block.type == CellType::Line) {
          edgeCurve[sorted<2>({v[0], v[1]})] = block.entity[e];
        } else if (triangles || quads) {
          // In 2D the cells themselves are the face's cells; in 3D the boundary cells.
          if (linear.dim == 3 && triangles)
            faceFace[sorted<3>({v[0], v[1], v[2]})] = block.entity[e];
          if (linear.dim == 3 && quads) {
            quadFace[sorted<4>({v[0], v[1], v[2], v[3]})] = block.entity[e];
            quadCycle[sorted<4>({v[0], v[1], v[2], v[3]})] = {v[0], v[1], v[2], v[3]};
          }
          const int n = triangles ? 3 : 4;
          for (int k = 0; k < n; ++k)
            edgeFace.emplace(sorted<2>({v[k], v[(k + 1) % n]}), block.entity[e]);
        }
      }
    }
  }
};

struct Elevator {
  const Mesh& linear;
  const int order;
  const BoundaryClassification classes;
  Mesh out;
  NodeIndex ids;

  Elevator(const Mesh& lin, int p) : linear(lin), order(p), classes(lin) {
    out.dim = lin.dim;
    out.order = p;
    out.planeNormal = lin.planeNormal;
    out.xyz = lin.xyz;
    out.nodeCadDim = lin.nodeCadDim;
    out.nodeCadIndex = lin.nodeCadIndex;
    out.nodeCadParam = lin.nodeCadParam;
  }

  // CAD dimension and index of a new node with support `key`, inside element of `block`.
  std::pair<int, int> classify(const NodeKey& key, CellType cell, int cellEntity) const {
    const int cellDim = cellDimension(cell);
    if (key.size == 2) {
      const EdgeKey edge{key.vertex[0], key.vertex[1]};
      if (auto it = classes.edgeCurve.find(edge); it != classes.edgeCurve.end())
        return {1, it->second};
      if (auto it = classes.edgeFace.find(edge); it != classes.edgeFace.end())
        return {2, it->second};
    } else if (key.size == 3 && linear.dim == 3) {
      const FaceKey face{key.vertex[0], key.vertex[1], key.vertex[2]};
      if (auto it = classes.faceFace.find(face); it != classes.faceFace.end())
        return {2, it->second};
    } else if (key.size == 4 && linear.dim == 3) {  // a quadrilateral face (or a cell interior)
      const QuadKey face{key.vertex[0], key.vertex[1], key.vertex[2], key.vertex[3]};
      if (auto it = classes.quadFace.find(face); it != classes.quadFace.end())
        return {2, it->second};
    }
    return {cellDim, cellEntity};
  }

  // `curved`: the position from the source element's own map (null: on the straight element).
  std::int64_t node(const NodeKey& key, CellType cell, int cellEntity, const double* curved) {
    if (key.size == 1) return key.vertex[0];
    bool inserted = false;
    const std::int64_t id =
        ids.findOrInsert(key, static_cast<std::int64_t>(out.numNodes()), inserted);
    if (!inserted) return id;
    double p[3] = {0.0, 0.0, 0.0};
    if (curved != nullptr) {
      std::copy(curved, curved + 3, p);
    } else {
      for (int i = 0; i < key.size; ++i)
        for (int c = 0; c < 3; ++c)
          p[c] +=
              linear.xyz[3 * key.vertex[i] + c] * key.index[i] / static_cast<double>(cube(order));
    }
    const auto [dim, entity] = classify(key, cell, cellEntity);
    out.addNode(p, dim, entity, kNaN, kNaN);  // its index is `id`, the node count before
    return id;
  }

  void elevateBlock(const ElementBlock& block) {
    const ReferenceElement& ref = ReferenceElement::get(block.type, order);
    const int nv = cellNumVertices(block.type);
    ElementBlock high;
    high.type = block.type;
    high.order = order;
    high.layerCells = block.layerCells;
    high.entity = block.entity;
    high.nodes.reserve(block.count() * ref.numNodes());
    // A curved source, or a pyramid (whose straight-sided map is rational inside: vertexWeights):
    // its basis at the new nodes (new nodes x source nodes).
    const bool curvedSource = block.order > 1 || block.type == CellType::Pyramid;
    Eigen::MatrixXd interpolation;
    if (curvedSource)
      interpolation = ReferenceElement::get(block.type, block.order).valuesAt(ref.nodes());
    const int sourceNodes = block.nodesPerElement();
    // An element's keys first, their slots fetched together, then looked up in order.
    std::vector<NodeKey> keys(static_cast<std::size_t>(ref.numNodes()));
    std::vector<std::array<double, 3>> curved(keys.size());
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      for (int r = 0; r < ref.numNodes(); ++r) {
        const auto ur = static_cast<std::size_t>(r);
        const LatticePoint& point = ref.lattice()[ur];
        curved[ur] = {0.0, 0.0, 0.0};
        if (curvedSource)
          for (int j = 0; j < sourceNodes; ++j)
            for (int c = 0; c < 3; ++c)
              curved[ur][c] += interpolation(r, j) * linear.xyz[3 * v[j] + c];
        const std::array<int, kMaxSupport> a = vertexWeights(block.type, point, order);
        std::array<std::pair<std::int64_t, int>, kMaxSupport> support{};
        int n = 0;
        for (int k = 0; k < nv; ++k)
          if (a[k] > 0) support[n++] = {v[k], a[k]};
        for (int i = 1; i < n; ++i)  // insertion sort of at most 8 entries
          for (int j = i; j > 0 && support[j] < support[j - 1]; --j)
            std::swap(support[j], support[j - 1]);
        NodeKey& key = keys[ur];
        key = NodeKey{};
        key.size = n;
        for (int i = 0; i < n; ++i) {
          key.vertex[i] = support[i].first;
          key.index[i] = support[i].second;
        }
        ids.prefetch(key);
      }
      for (std::size_t r = 0; r < keys.size(); ++r)
        high.nodes.push_back(
            node(keys[r], block.type, block.entity[e], curvedSource ? curved[r].data() : nullptr));
    }
    out.blocks.push_back(std::move(high));
  }
};

// Moves node `id`, which lies on a CAD curve or face, onto it by closest-point projection from
// where it is, with its parameters there.
void projectNode(Mesh& mesh, std::int64_t id, const CadModel& cad) {
  const int entity = mesh.nodeCadIndex[id];
  double* x = &mesh.xyz[3 * id];
  const Eigen::Vector3d from(x[0], x[1], x[2]);
  if (mesh.nodeCadDim[id] == 1) {
    const CurveProjection proj = cad.projectOnCurve(entity, from);
    mesh.nodeCadParam[2 * id] = proj.t;
    for (int c = 0; c < 3; ++c) x[c] = proj.point[c];
  } else {
    const SurfaceProjection proj = cad.projectOnSurface(entity, from);
    mesh.nodeCadParam[2 * id] = proj.u;
    mesh.nodeCadParam[2 * id + 1] = proj.v;
    for (int c = 0; c < 3; ++c) x[c] = proj.point[c];
  }
}

// Moves the nodes created by elevation (ids >= firstNew) that lie on a CAD curve or face and
// that `placed` does not mark onto it by closest-point projection (the last resort).
void projectNewNodes(Mesh& mesh, std::size_t firstNew, const CadModel& cad,
                     const std::vector<char>& placed) {
  for (auto id = static_cast<std::int64_t>(firstNew);
       id < static_cast<std::int64_t>(mesh.numNodes()); ++id) {
    const int dim = static_cast<int>(mesh.nodeCadDim[id]);
    if ((dim == 1 || dim == 2) && placed[id] == 0) projectNode(mesh, id, cad);
  }
}

// The high-order nodes on the wall of a 2D layer cell are spaced as their images on the offset
// curve at this fraction of the cell's height, not in arc length. Around a wall curved more
// tightly than the layer is thick (T106's edges, radius about 0.005 under up to 0.053)
// arc-length nodes bunch the top's nodes where the wall turns fastest: the parallel top then
// swings between them (with the layer fixed, T106's order-4 cells at both edges were invalid,
// min J / max J -0.25 and -0.16). Spaced on the offset, the nodes share the turn evenly.
// NekMesh's 2D cases with 2 and 4 layers at orders 2, 3, 4, 6: every fraction from 0.2 to 0.5
// gives valid meshes with the first layer within 4 %; the worst element moves between 0.03 and
// 0.10 with it, with no trend; 0.25 gave the best, 0.103 (arc length: 0.039, and 10.6 %).
constexpr double kLayerSpacingHeight = 0.25;
// The offset's height is lowered where its speed would fall below this fraction of the wall's
// (it folds, or nearly, on a concave wall of radius under the offset height: T106's splines
// have concave wiggles beside both edges), and dropped if that leaves less than this fraction
// of it.
constexpr double kOffsetFold = 0.05;

// Places the new nodes on the CAD: edges on curves by arc-length spacing in t, edges inside
// faces by the same spacing in (u, v), triangle interiors by a relaxed lattice in (u, v)
// (curve_node_placement.hpp, face_node_placement.hpp); whatever fails its checks is projected.
class BoundaryPlacer {
 public:
  // `raise`: the source mesh is already curved (changeOrder), so what its shape says is kept
  // where a fresh placement would lose it (see keptTops_).
  BoundaryPlacer(Elevator& elevator, std::size_t firstNew, const CadModel& cad, CurvingStats& stats,
                 bool layer, bool raise = false)
      : mesh_(elevator.out),
        order_(elevator.order),
        cad_(cad),
        stats_(stats),
        placed_(elevator.out.numNodes(), 0),
        firstNew_(firstNew) {
    const auto p = static_cast<std::size_t>(order_);
    elevator.ids.forEach(order_, [&](const NodeKey& key, std::int64_t id) {
      if (static_cast<std::size_t>(id) < firstNew_) return;
      // Edges inside a 3D domain are not placed: only those on a CAD curve or face are kept.
      if (key.size == 2 && (mesh_.nodeCadDim[id] == 1 || mesh_.nodeCadDim[id] == 2)) {
        auto& nodes = edges_[{key.vertex[0], key.vertex[1]}];
        if (nodes.empty()) {
          nodes.assign(p + 1, -1);
          nodes.front() = key.vertex[0];
          nodes.back() = key.vertex[1];
        }
        // index[1] / P^2 steps from vertex[0]
        nodes[static_cast<std::size_t>(key.index[1] / (order_ * order_))] = id;
      } else if (key.size == 3 && mesh_.nodeCadDim[id] == 2) {
        auto& nodes = triangles_[{key.vertex[0], key.vertex[1], key.vertex[2]}];
        if (nodes.empty()) nodes.assign((p + 1) * (p + 2) / 2, -1);
        const int scale = order_ * order_;
        nodes[static_cast<std::size_t>(
            latticeIndex(order_, key.index[1] / scale, key.index[2] / scale))] = id;
      } else if (key.size == 4 && mesh_.nodeCadDim[id] == 2) {
        const QuadKey sortedKey{key.vertex[0], key.vertex[1], key.vertex[2], key.vertex[3]};
        const auto cycle = elevator.classes.quadCycle.find(sortedKey);
        if (cycle == elevator.classes.quadCycle.end()) return;
        auto& nodes = quads_[cycle->second];
        if (nodes.empty()) nodes.assign((p + 1) * (p + 1), -1);
        // Weights (P-i)(P-j)P, i(P-j)P, ijP, (P-i)jP of the corners in cyclic order.
        const NodeKey& support = key;  // (a structured binding cannot be captured in C++17)
        const auto weight = [&support](std::int64_t vertex) {
          for (int k = 0; k < 4; ++k)
            if (support.vertex[k] == vertex) return support.index[k];
          return 0;
        };
        const QuadKey& c = cycle->second;
        const int scale = order_ * order_;
        const int i = (weight(c[1]) + weight(c[2])) / scale;
        const int j = (weight(c[2]) + weight(c[3])) / scale;
        nodes[quadIndex(order_, i, j)] = id;
      }
    });
    if (layer && mesh_.dim == 2)
      for (const ElementBlock& b : mesh_.blocks) {
        if (!isLayerCell(mesh_, b)) continue;
        for (std::size_t e = 0; e < b.count(); ++e) {
          const std::int64_t* v = b.element(e);  // wall 0, 1; tops 3, 2
          wallTops_[{std::min(v[0], v[1]), std::max(v[0], v[1])}] =
              v[0] < v[1] ? std::array<std::int64_t, 2>{v[3], v[2]}
                          : std::array<std::int64_t, 2>{v[2], v[3]};
        }
      }
    if (layer && raise && mesh_.dim == 3)
      for (const ElementBlock& b : mesh_.blocks) {
        if (!isLayerCell(mesh_, b)) continue;
        const LayerShape shape = layerShape(b.type);
        for (std::size_t e = 0; e < b.count(); ++e) {
          const std::int64_t* v = b.element(e);  // the tops' cycle (layer_cells.hpp)
          for (int k = 0; k < shape.walls; ++k) {
            const std::int64_t i = shape.top(v, k), j = shape.top(v, (k + 1) % shape.walls);
            keptTops_.insert({std::min(i, j), std::max(i, j)});
          }
        }
      }
  }

  void run() {
    const std::vector<double> z = equispacedPositions(order_);
    for (const auto& [edge, nodes] : edges_)
      if (mesh_.nodeCadDim[nodes[1]] == 1) placeCurveEdge(nodes, z);
    for (const auto& [edge, nodes] : edges_) {
      if (mesh_.nodeCadDim[nodes[1]] != 2) continue;
      if (keptTops_.count(edge) != 0) {
        projectEdge(nodes);
      } else {
        placeFaceEdge(nodes, z);
      }
    }
    for (const auto& [tri, nodes] : triangles_) placeTriangle(tri, nodes);
    for (const auto& [quad, nodes] : quads_) placeQuadrilateral(quad, nodes);
    projectNewNodes(mesh_, firstNew_, cad_, placed_);
  }

 private:
  Mesh& mesh_;
  const int order_;
  const CadModel& cad_;
  CurvingStats& stats_;
  std::vector<char> placed_;
  const std::size_t firstNew_;
  std::map<EdgeKey, std::vector<std::int64_t>> edges_;
  std::map<FaceKey, std::vector<std::int64_t>> triangles_;
  std::map<QuadKey, std::vector<std::int64_t>> quads_;  // by corners in cyclic order
  // Raising a 3D layer: the edges of the layer's top (those on a CAD face: on the layer's
  // sides) keep the source's shape, projected. Placed afresh on the face between their ends,
  // they ran straight where the source had them parallel to the wall: on the cylinder's end
  // faces (3d_bl_cyl, from order 4 to 6) the top sagged to 0.018 above a wall 0.04 below it,
  // and the first layer, split there, was 16 % thin.
  std::set<EdgeKey> keptTops_;
  std::map<int, FaceChart> charts_;
  std::map<std::pair<std::int64_t, std::int64_t>, std::array<std::int64_t, 2>> wallTops_;

  const FaceChart& chart(int face) {
    auto it = charts_.find(face);
    if (it == charts_.end()) it = charts_.try_emplace(face, cad_, face).first;
    return it->second;
  }

  Eigen::Vector3d point(std::int64_t node) const {
    return {mesh_.xyz[3 * node], mesh_.xyz[3 * node + 1], mesh_.xyz[3 * node + 2]};
  }

  void setCurveNode(std::int64_t node, int curve, double t) {
    const Eigen::Vector3d x = cad_.evaluateCurve(curve, t).point;
    for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] = x[c];
    mesh_.nodeCadParam[2 * node] = t;
    mesh_.nodeCadParam[2 * node + 1] = kNaN;
    placed_[node] = 1;
  }

  void setFaceNode(std::int64_t node, const FaceChart& chart, const FaceParameter& uv) {
    const Eigen::Vector3d x = chart.point(uv);
    const FaceParameter stored = chart.wrap(uv);
    for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] = x[c];
    mesh_.nodeCadParam[2 * node] = stored[0];
    mesh_.nodeCadParam[2 * node + 1] = stored[1];
    placed_[node] = 1;
  }

  // The edge's new nodes where the source mesh's map put them, projected onto their face (each
  // from where it is: a raised edge is within the source's interpolation error of the face).
  void projectEdge(const std::vector<std::int64_t>& nodes) {
    for (std::size_t i = 1; i + 1 < nodes.size(); ++i) {
      projectNode(mesh_, nodes[i], cad_);
      placed_[static_cast<std::size_t>(nodes[i])] = 1;
    }
  }

  void placeCurveEdge(const std::vector<std::int64_t>& nodes, const std::vector<double>& z) {
    const int curve = mesh_.nodeCadIndex[nodes[1]];
    if (cad_.isDegenerated(curve)) return;
    const std::int64_t a = nodes.front(), b = nodes.back();
    // The other end's own parameter (or a point a third along the edge) tells which end of a
    // closed curve a vertex is.
    const auto hint = [&](std::int64_t from, std::int64_t to) -> double {
      if (mesh_.nodeCadDim[to] == 1 && mesh_.nodeCadIndex[to] == curve &&
          std::isfinite(mesh_.nodeCadParam[2 * to]))
        return mesh_.nodeCadParam[2 * to];
      return cad_.projectOnCurve(curve, (2.0 * point(from) + point(to)) / 3.0).t;
    };
    const double ta = nodeCurveParameter(cad_, mesh_, a, curve, hint(a, b));
    const double tb = nodeCurveParameter(cad_, mesh_, b, curve, hint(b, a));
    if (!(ta != tb)) return;  // a degenerate span: projection decides
    const CurvePlacement placement =
        placeOnCurve(cad_, curve, ta, tb, z, layerOffset(a, b, curve, ta, tb, z));
    ++stats_.curveEdges;
    if (!placement.optimised) ++stats_.curveEdgesAtStart;
    for (std::size_t i = 1; i + 1 < nodes.size(); ++i)
      setCurveNode(nodes[i], curve, placement.t[i]);
  }

  // For the wall edge (a, b) of a 2D layer cell: the offset curve at a quarter of the cell's
  // height, on the layer's side, whose spacing the edge's nodes then follow (std::nullopt for
  // any other edge, or where that offset folds: a concave wall tighter than the height).
  std::optional<CurveOffset> layerOffset(std::int64_t a, std::int64_t b, int curve, double ta,
                                         double tb, const std::vector<double>& z) const {
    const auto found = wallTops_.find({std::min(a, b), std::max(a, b)});
    if (found == wallTops_.end()) return std::nullopt;
    const std::int64_t topA = found->second[a < b ? 0 : 1], topB = found->second[a < b ? 1 : 0];
    const Eigen::Vector3d climbA = point(topA) - point(a), climbB = point(topB) - point(b);
    CurveOffset offset;
    offset.planeNormal =
        Eigen::Vector3d(mesh_.planeNormal[0], mesh_.planeNormal[1], mesh_.planeNormal[2]);
    const CurveDerivatives start = cad_.evaluateCurve(curve, ta);
    const double side = start.d1.cross(offset.planeNormal).dot(climbA) > 0.0 ? 1.0 : -1.0;
    offset.height = side * kLayerSpacingHeight * 0.5 * (climbA.norm() + climbB.norm());
    // Folding: the offset's speed along c' is linear in the height, 1 + s (r - 1) at a fraction
    // s of it (r: at the full height). Lowered until it is at least kOffsetFold at the nodes'
    // starting parameters (a concave stretch tighter than the height, or a wiggle in a spline).
    double fraction = 1.0;
    for (const double s : z) {
      const CurveDerivatives c = cad_.evaluateCurve(curve, ta + s * (tb - ta));
      const std::optional<CurveDerivatives> o = offsetCurve(c, offset);
      if (!o) return std::nullopt;
      const double r = o->d1.dot(c.d1) / c.d1.squaredNorm();
      if (r < kOffsetFold) fraction = std::min(fraction, (1.0 - kOffsetFold) / (1.0 - r));
    }
    if (!(fraction > kOffsetFold)) return std::nullopt;
    offset.height *= fraction;
    return offset;
  }

  void placeFaceEdge(const std::vector<std::int64_t>& nodes, const std::vector<double>& z) {
    const FaceChart& ch = chart(mesh_.nodeCadIndex[nodes[1]]);
    const std::int64_t a = nodes.front(), b = nodes.back();
    const FaceParameter ua = nodeFaceParameter(ch, mesh_, a, std::nullopt);
    const FaceParameter ub = nodeFaceParameter(ch, mesh_, b, ua);
    const auto ends = edgeEnds(ch, ua, ub);
    const FaceEdgePlacement placement =
        placeOnFaceEdge(ch, ends[0], ends[1], point(a), point(b), z);
    ++stats_.faceEdges;
    if (!placement.valid) {
      ++stats_.faceEdgesProjected;
      return;
    }
    if (!placement.optimised) ++stats_.faceEdgesAtStart;
    for (std::size_t i = 1; i + 1 < nodes.size(); ++i) setFaceNode(nodes[i], ch, placement.uv[i]);
  }

  void placeTriangle(const FaceKey& tri, std::vector<std::int64_t> nodes) {
    const int p = order_;
    const FaceChart& ch = chart(mesh_.nodeCadIndex[nodes[latticeIndex(p, 1, 1)]]);
    // Corners and edge nodes into the lattice: corner 0, 1, 2 = tri[0], tri[1], tri[2].
    nodes[latticeIndex(p, 0, 0)] = tri[0];
    nodes[latticeIndex(p, p, 0)] = tri[1];
    nodes[latticeIndex(p, 0, p)] = tri[2];
    const auto edgeNodes = [&](std::int64_t v, std::int64_t w) -> const std::vector<std::int64_t>* {
      const auto it = edges_.find({v, w});  // v < w: the list runs from v to w
      return it == edges_.end() ? nullptr : &it->second;
    };
    const auto* e01 = edgeNodes(tri[0], tri[1]);
    const auto* e02 = edgeNodes(tri[0], tri[2]);
    const auto* e12 = edgeNodes(tri[1], tri[2]);
    if (e01 == nullptr || e02 == nullptr || e12 == nullptr) return;
    for (int k = 1; k < p; ++k) {
      nodes[latticeIndex(p, k, 0)] = (*e01)[k];
      nodes[latticeIndex(p, 0, k)] = (*e02)[k];
      nodes[latticeIndex(p, p - k, k)] = (*e12)[k];
    }
    ++stats_.faceInteriors;
    // One chart for the whole lattice, next to a corner that is not a pole.
    std::array<FaceParameter, 3> corner;
    std::array<bool, 3> pole{};
    const int cornerIndex[3] = {latticeIndex(p, 0, 0), latticeIndex(p, p, 0),
                                latticeIndex(p, 0, p)};
    for (int c = 0; c < 3; ++c) {
      corner[c] = nodeFaceParameter(ch, mesh_, nodes[cornerIndex[c]], std::nullopt);
      const auto s = ch.singular(corner[c]);
      pole[c] = s[0] || s[1];
    }
    int ref = 0;
    while (ref < 2 && pole[ref]) ++ref;
    std::vector<FaceParameter> uv(nodes.size());
    std::vector<Eigen::Vector3d> x(nodes.size());
    for (int j = 0; j <= p; ++j)
      for (int i = 0; i + j <= p; ++i) {
        const int k = latticeIndex(p, i, j);
        x[k] = point(nodes[k]);
        const bool interior = i >= 1 && j >= 1 && i + j < p;
        if (!interior)
          uv[k] = ch.unwrapNear(nodeFaceParameter(ch, mesh_, nodes[k], corner[ref]), corner[ref]);
      }
    const TrianglePlacement placement = placeTriangleInterior(ch, p, uv, x);
    if (!placement.valid) {
      ++stats_.faceInteriorsProjected;
      return;
    }
    if (!placement.relaxed) ++stats_.faceInteriorsAtStart;
    for (int j = 1; j < p; ++j)
      for (int i = 1; i + j < p; ++i) {
        const int k = latticeIndex(p, i, j);
        setFaceNode(nodes[k], ch, placement.uv[k]);
      }
  }

  // Node (i, j) of an order-P quadrilateral's lattice, row by row.
  static std::size_t quadIndex(int p, int i, int j) {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(p + 1) +
           static_cast<std::size_t>(i);
  }

  // A quadrilateral on a CAD face, corners c in cyclic order, node (i, j) at nodes[j (P+1) + i]:
  // its interior nodes at the transfinite (Coons) interpolation in (u, v) of its four placed
  // edges, kept when every lattice cell keeps one orientation in (u, v) and every node lies
  // inside the face's trimming (else they are projected, as before).
  void placeQuadrilateral(const QuadKey& c, std::vector<std::int64_t> nodes) {
    const int p = order_;
    const auto at = [p](int i, int j) { return quadIndex(p, i, j); };
    nodes[at(0, 0)] = c[0];
    nodes[at(p, 0)] = c[1];
    nodes[at(p, p)] = c[2];
    nodes[at(0, p)] = c[3];
    // The node k steps from corner a along edge (a, b) (the lists run from the smaller id).
    const auto edgeNode = [&](std::int64_t a, std::int64_t b, int k) -> std::int64_t {
      const auto it = edges_.find({std::min(a, b), std::max(a, b)});
      if (it == edges_.end()) return -1;
      return it->second[static_cast<std::size_t>(a < b ? k : p - k)];
    };
    for (int k = 1; k < p; ++k) {
      nodes[at(k, 0)] = edgeNode(c[0], c[1], k);
      nodes[at(p, k)] = edgeNode(c[1], c[2], k);
      nodes[at(k, p)] = edgeNode(c[3], c[2], k);
      nodes[at(0, k)] = edgeNode(c[0], c[3], k);
    }
    for (int k = 0; k <= p; ++k)
      for (const std::size_t b : {at(k, 0), at(p, k), at(k, p), at(0, k)})
        if (nodes[b] < 0) return;
    ++stats_.quadInteriors;
    const FaceChart& ch = chart(mesh_.nodeCadIndex[nodes[at(1, 1)]]);
    std::array<FaceParameter, 4> corner;
    int ref = -1;
    bool pole = false;
    for (int k = 0; k < 4; ++k) {
      corner[k] = nodeFaceParameter(ch, mesh_, c[k], std::nullopt);
      const auto s = ch.singular(corner[k]);
      pole = pole || s[0] || s[1];
      if (ref < 0 && !s[0] && !s[1]) ref = k;
    }
    if (pole) {
      // At a pole u is arbitrary: the (u, v) patch would take the corner's u for both edges
      // meeting there (on a sphere's pole quadrilateral it put the centre node near a side, and
      // the hexahedron on it was invalid).
      ++stats_.quadInteriorsProjected;
      placeByPositions(nodes);
      return;
    }
    std::vector<FaceParameter> uv(nodes.size());
    for (int k = 0; k <= p; ++k)
      for (const std::size_t b : {at(k, 0), at(p, k), at(k, p), at(0, k)})
        uv[b] = ch.unwrapNear(nodeFaceParameter(ch, mesh_, nodes[b], corner[ref]), corner[ref]);
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i)
        for (std::size_t d = 0; d < 2; ++d)
          uv[at(i, j)][d] = coons(p, i, j, [&](int a, int b) { return uv[at(a, b)][d]; });
    if (!unflipped(uv, p)) {
      ++stats_.quadInteriorsProjected;
      return;
    }
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i)
        if (!ch.contains(uv[at(i, j)])) {
          ++stats_.quadInteriorsProjected;
          return;
        }
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) setFaceNode(nodes[at(i, j)], ch, uv[at(i, j)]);
  }

  // A quadrilateral's interior nodes (lattice as placeQuadrilateral's) at the transfinite
  // interpolation of its edges' positions, each projected onto its face from there.
  void placeByPositions(const std::vector<std::int64_t>& nodes) {
    const int p = order_;
    for (int j = 1; j < p; ++j)
      for (int i = 1; i < p; ++i) {
        const std::int64_t node = nodes[quadIndex(p, i, j)];
        for (int d = 0; d < 3; ++d)
          mesh_.xyz[3 * node + d] = coons(
              p, i, j, [&](int a, int b) { return mesh_.xyz[3 * nodes[quadIndex(p, a, b)] + d]; });
        projectNode(mesh_, node, cad_);
        placed_[static_cast<std::size_t>(node)] = 1;
      }
  }

  // The transfinite (Coons) interpolation at lattice point (i, j) of an order-P quadrilateral of
  // the values f(a, b) on its four edges (one coordinate).
  template <class F>
  static double coons(int p, int i, int j, const F& f) {
    const double s = static_cast<double>(i) / p, t = static_cast<double>(j) / p;
    return (1 - t) * f(i, 0) + t * f(i, p) + (1 - s) * f(0, j) + s * f(p, j) -
           ((1 - s) * (1 - t) * f(0, 0) + s * (1 - t) * f(p, 0) + s * t * f(p, p) +
            (1 - s) * t * f(0, p));
  }

  // Whether every cell of a (P+1) x (P+1) lattice in (u, v) has the same, non-zero orientation.
  static bool unflipped(const std::vector<FaceParameter>& uv, int p) {
    int sign = 0;
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < p; ++i) {
        const FaceParameter& o = uv[quadIndex(p, i, j)];
        const FaceParameter& a = uv[quadIndex(p, i + 1, j)];
        const FaceParameter& b = uv[quadIndex(p, i, j + 1)];
        const double cross = (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
        if (!std::isfinite(cross) || cross == 0.0) return false;
        const int here = cross > 0.0 ? 1 : -1;
        if (sign != 0 && here != sign) return false;
        sign = here;
      }
    return true;
  }
};

}  // namespace

Mesh changeOrder(const Mesh& mesh, int order, const CadModel* cad, CurvingStats* stats,
                 bool layer) {
  if (order < 1 || order > 10)
    throw ParameterError("order must be between 1 and 10, got " + std::to_string(order));
  Elevator elevator(mesh, order);
  for (const ElementBlock& block : mesh.blocks) elevator.elevateBlock(block);
  CurvingStats local;
  if (cad != nullptr)
    BoundaryPlacer(elevator, mesh.numNodes(), *cad, stats != nullptr ? *stats : local, layer,
                   /*raise=*/true)
        .run();
  compactNodes(elevator.out);
  elevator.out.checkConsistency();
  return std::move(elevator.out);
}

Mesh elevateOrder(const Mesh& linear, int order, const CadModel* cad, CurvingStats* stats,
                  bool layer) {
  if (linear.order != 1)
    throw ParameterError("order elevation needs a linear mesh, got order " +
                         std::to_string(linear.order));
  if (order < 1 || order > 10)
    throw ParameterError("order must be between 1 and 10, got " + std::to_string(order));
  Elevator elevator(linear, order);
  for (const ElementBlock& block : linear.blocks) elevator.elevateBlock(block);
  CurvingStats local;
  if (cad != nullptr)
    BoundaryPlacer(elevator, linear.numNodes(), *cad, stats != nullptr ? *stats : local, layer)
        .run();
  elevator.out.checkConsistency();
  return std::move(elevator.out);
}

}  // namespace homesh
