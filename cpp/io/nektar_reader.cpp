#include "io/nektar_reader.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "element/reference_element.hpp"
#include "io/nektar_curve_points.hpp"
#include "io/nektar_expansion.hpp"
#include "io/nektar_format.hpp"
#include "io/nektar_sections.hpp"
#include "io/xml_document.hpp"

namespace homesh {
namespace {

using Point = Eigen::Vector3d;
using Lattice = LatticePoint;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Gmsh-ordered nodes of every face (3D), by face id and by sorted vertex set.
struct FaceNodes {
  std::map<std::vector<int>, std::vector<std::int64_t>> byVertices;
  std::map<int, std::vector<std::int64_t>> byId;
};

// The entities the composites' names ("Solid3", "Face12", "Edge5") give.
struct CompositeEntities {
  std::map<std::pair<char, int>, int> ofElement;  // (letter, element id) -> entity
  std::map<int, int> ofBoundary;                  // face (3D) or edge (2D) id -> entity
};

// Assembles a Mesh from the sections nektar_sections.hpp reads: vertices from the edge loops
// as Nektar++ derives them, nodes from the curves, unknown nodes filled as Nektar++ builds them.
class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const { nektar::failGeometry(path_, what); }

  Mesh read();

 private:
  // Steps of read().
  void indexTopology();
  int curveOrder() const;
  CompositeEntities compositeEntities() const;
  FaceNodes faceNodes();
  void addElementBlocks(const CompositeEntities& entities, const FaceNodes& faces);
  void addBoundaryBlocks(const CompositeEntities& entities, const FaceNodes& faces);
  void setPlaneOrSurface();

  // Entities by id, failing with the id when one is missing.
  const std::array<int, 2>& edge(int id) const;
  const nektar::FaceRecord& face(int id) const;
  std::int64_t vertexNode(int id) const;
  const Point& vertexPoint(int id) const;

  // Topology.
  int common(int edgeA, int edgeB) const;  // the vertex two edges share
  int sharedEdge(int faceA, int faceB) const;
  int otherEnd(int edge, int vertex) const;
  std::vector<int> loopVertices(const std::vector<int>& edgeIds) const;
  std::vector<int> elementVertices(const nektar::ElementRecord& e) const;  // Gmsh local order

  // Nodes.
  std::int64_t newNode(const Point& p, bool known);
  std::int64_t edgeNode(int edgeId, int fromVertex, int t);
  int edgeBetween(int a, int b) const;
  std::vector<std::int64_t> interiorNodes(bool triangle, const nektar::CurveRecord* curve);
  std::vector<std::int64_t> polygonNodes(const std::vector<int>& own,
                                         const std::vector<std::int64_t>& interior);
  std::vector<std::int64_t> volumeNodes(
      CellType type, const std::vector<int>& v,
      const std::map<std::vector<int>, std::vector<std::int64_t>>& faceByVertices);
  void fill(CellType type, const std::vector<std::int64_t>& nodes);
  void fillTransfinite(CellType type, const ReferenceElement& ref,
                       const std::map<Lattice, std::int64_t>& at, const std::vector<int>& unknown);
  void fillExpansion(CellType type, const std::vector<std::int64_t>& nodes,
                     const std::vector<int>& unknown);

  std::string path_;
  int dim_ = 3;
  int order_ = 1;
  nektar::GeometrySections g_;

  Mesh mesh_;
  std::map<std::pair<int, int>, int> edgeOf_;  // (smaller, larger vertex) -> edge
  std::map<int, std::int64_t> vertexNode_;
  std::map<int, std::vector<std::int64_t>> edgeNodes_;
  std::vector<bool> known_;  // node position given by the file (else to be filled)
};

Mesh Reader::read() {
  const auto root = parseXml(readFileBytes(path_, "mesh file"), path_);
  g_ = nektar::readGeometrySections(*root, path_);
  dim_ = g_.dim;
  indexTopology();
  order_ = curveOrder();
  nektar::toEvenlySpaced(g_, order_, path_);
  mesh_.dim = dim_;
  mesh_.order = order_;
  for (const auto& [id, p] : g_.vertices) vertexNode_[id] = newNode(p, true);
  const CompositeEntities entities = compositeEntities();
  const FaceNodes faces = faceNodes();
  addElementBlocks(entities, faces);
  addBoundaryBlocks(entities, faces);
  for (const bool k : known_)
    if (!k) fail("some nodes could not be placed");
  setPlaneOrSurface();
  mesh_.checkConsistency();
  return std::move(mesh_);
}

// Edges by their vertex pair, and each face's vertices from its edge loop.
void Reader::indexTopology() {
  for (const auto& [id, ev] : g_.edges) edgeOf_[std::minmax(ev[0], ev[1])] = id;
  for (auto& [id, f] : g_.faces) f.vertices = loopVertices(f.edges);
}

// The order the curves carry (1 without curves); all curved edges must agree.
int Reader::curveOrder() const {
  int order = 1;
  if (!g_.edgeCurves.empty())
    order = static_cast<int>(g_.edgeCurves.begin()->second.points.size()) - 1;
  for (const auto& [id, c] : g_.edgeCurves)
    if (static_cast<int>(c.points.size()) != order + 1)
      fail("curved edges have different numbers of points");
  if (order < 1 || order > kMaxOrder) fail("curves of order " + std::to_string(order));
  return order;
}

CompositeEntities Reader::compositeEntities() const {
  CompositeEntities out;
  for (const nektar::CompositeRecord& c : g_.composites) {
    int index = 0;
    for (const char* prefix : {"Solid", "Face", "Edge"})
      if (c.name.rfind(prefix, 0) == 0) index = std::atoi(c.name.c_str() + std::strlen(prefix));
    for (const int id : c.ids) {
      if (c.letter == 'F' || (c.letter == 'E' && dim_ == 2))
        out.ofBoundary[id] = index;
      else
        out.ofElement[{c.letter, id}] = index;
    }
  }
  return out;
}

// Faces' interior nodes (from their curves, or to be filled), and the faces' Gmsh-ordered
// nodes keyed by their vertex set, for the elements to look up.
FaceNodes Reader::faceNodes() {
  FaceNodes out;
  for (const auto& [id, f] : g_.faces) {
    const auto curve = g_.faceCurves.find(id);
    const std::vector<std::int64_t> interior =
        interiorNodes(f.triangle, curve != g_.faceCurves.end() ? &curve->second : nullptr);
    std::vector<std::int64_t> nodes = polygonNodes(f.vertices, interior);
    fill(f.triangle ? CellType::Triangle : CellType::Quadrilateral, nodes);
    std::vector<int> key = f.vertices;
    std::sort(key.begin(), key.end());
    out.byVertices[key] = nodes;
    out.byId[id] = nodes;
  }
  return out;
}

// The elements, one block per cell type; their nodes take the element's entity.
void Reader::addElementBlocks(const CompositeEntities& entities, const FaceNodes& faces) {
  std::map<CellType, ElementBlock> blocks;
  for (const nektar::ElementRecord& e : g_.elements) {
    const std::vector<int> v = elementVertices(e);
    ElementBlock& block = blocks[e.type];
    block.type = e.type;
    block.order = order_;
    const auto entity = entities.ofElement.find({nektar::letter(e.type), e.id});
    block.entity.push_back(entity != entities.ofElement.end() ? entity->second : 0);
    std::vector<std::int64_t> nodes;
    if (dim_ == 2) {
      const auto curve = g_.faceCurves.find(e.id);
      nodes =
          polygonNodes(v, interiorNodes(e.type == CellType::Triangle,
                                        curve != g_.faceCurves.end() ? &curve->second : nullptr));
    } else {
      nodes = volumeNodes(e.type, v, faces.byVertices);
    }
    fill(e.type, nodes);
    block.nodes.insert(block.nodes.end(), nodes.begin(), nodes.end());
    for (const std::int64_t n : nodes) mesh_.nodeCadIndex[n] = block.entity.back();
  }
  for (auto& [type, block] : blocks) mesh_.blocks.push_back(std::move(block));
}

// Boundary cells: the faces (3D) or edges (2D) of the named boundary composites; their nodes
// take the boundary entity.
void Reader::addBoundaryBlocks(const CompositeEntities& entities, const FaceNodes& faces) {
  ElementBlock tris, quads, lines;
  tris.type = CellType::Triangle;
  quads.type = CellType::Quadrilateral;
  lines.type = CellType::Line;
  for (ElementBlock* b : {&tris, &quads, &lines}) b->order = order_;
  for (const auto& [id, entity] : entities.ofBoundary) {
    std::vector<std::int64_t> nodes;
    ElementBlock* block = &lines;
    if (dim_ == 3) {
      const auto it = faces.byId.find(id);
      if (it == faces.byId.end()) fail("composite refers to missing face " + std::to_string(id));
      nodes = it->second;
      block = face(id).triangle ? &tris : &quads;
    } else {
      const auto& ev = edge(id);
      nodes = {vertexNode(ev[0]), vertexNode(ev[1])};
      for (int t = 1; t < order_; ++t) nodes.push_back(edgeNode(id, ev[0], t));
    }
    block->nodes.insert(block->nodes.end(), nodes.begin(), nodes.end());
    block->entity.push_back(entity);
    for (const std::int64_t n : nodes) {
      mesh_.nodeCadDim[n] = static_cast<std::uint8_t>(dim_ - 1);
      mesh_.nodeCadIndex[n] = entity;
    }
  }
  for (ElementBlock* b : {&tris, &quads, &lines})
    if (b->count() > 0) mesh_.blocks.push_back(std::move(*b));
}

// A 2D mesh off one plane (a manifold in SPACE 3) is a surface mesh; one in a plane other than
// z = const is measured along that plane's normal; one in such a plane keeps the
// counter-clockwise convention around +z that Nektar++'s 2D elements follow.
void Reader::setPlaneOrSurface() {
  if (dim_ == 2)
    if (const auto normal = planeOfCells(mesh_, 1e-5))  // (as for MSH files)
      if (std::abs((*normal)[2]) < 1.0 - 1e-12) mesh_.planeNormal = *normal;
}

const std::array<int, 2>& Reader::edge(int id) const {
  const auto it = g_.edges.find(id);
  if (it == g_.edges.end()) fail("edge " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

const nektar::FaceRecord& Reader::face(int id) const {
  const auto it = g_.faces.find(id);
  if (it == g_.faces.end()) fail("face " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

const Point& Reader::vertexPoint(int id) const {
  const auto it = g_.vertices.find(id);
  if (it == g_.vertices.end()) fail("vertex " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

std::int64_t Reader::vertexNode(int id) const {
  const auto it = vertexNode_.find(id);
  if (it == vertexNode_.end()) fail("vertex " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

int Reader::common(int a, int b) const {
  const auto& ea = edge(a);
  const auto& eb = edge(b);
  for (const int v : ea)
    if (v == eb[0] || v == eb[1]) return v;
  fail("edges " + std::to_string(a) + " and " + std::to_string(b) + " do not meet");
}

int Reader::otherEnd(int edgeId, int vertex) const {
  const auto& e = edge(edgeId);
  if (e[0] == vertex) return e[1];
  if (e[1] == vertex) return e[0];
  fail("vertex " + std::to_string(vertex) + " is not on edge " + std::to_string(edgeId));
}

int Reader::sharedEdge(int faceA, int faceB) const {
  for (const int a : face(faceA).edges)
    for (const int b : face(faceB).edges)
      if (a == b) return a;
  fail("faces " + std::to_string(faceA) + " and " + std::to_string(faceB) + " share no edge");
}

// Vertex j of an edge loop: the vertex shared by edges j-1 and j.
std::vector<int> Reader::loopVertices(const std::vector<int>& e) const {
  std::vector<int> v;
  const int n = static_cast<int>(e.size());
  v.reserve(e.size());
  for (int j = 0; j < n; ++j) v.push_back(common(e[(j + n - 1) % n], e[j]));
  return v;
}

std::vector<int> Reader::elementVertices(const nektar::ElementRecord& e) const {
  const auto& f = e.ids;
  switch (e.type) {
    case CellType::Triangle:
    case CellType::Quadrilateral:
      return loopVertices(f);
    case CellType::Tetrahedron: {
      // As Nektar++: e0, e1, e2 are face 0's edges that start faces 1, 2, 3.
      const int e0 = face(f[1]).edges[0], e1 = face(f[2]).edges[0];
      const int e3 = sharedEdge(f[1], f[3]);
      const int v1 = common(e0, e1), v0 = otherEnd(e0, v1), v2 = otherEnd(e1, v1);
      return {v0, v1, v2, otherEnd(e3, v0)};
    }
    case CellType::Prism: {
      const int e0 = sharedEdge(f[0], f[1]), e1 = sharedEdge(f[0], f[2]);
      const int e2 = sharedEdge(f[0], f[3]), e4 = sharedEdge(f[1], f[4]);
      const int e8 = sharedEdge(f[2], f[4]);
      const int v1 = common(e0, e1), v0 = otherEnd(e0, v1), v2 = otherEnd(e1, v1);
      const int v3 = otherEnd(e2, v2), v4 = common(e8, e4), v5 = otherEnd(e8, v4);
      // Nektar++ builds each triangular face around the prism's apex vertices (4 and 5) and
      // refuses the element ("orientation of triangular face ... is inconsistent") unless each
      // apex is its triangle's own third vertex (the one its edge loop reaches last).
      if (face(f[1]).vertices.at(2) != v4 || face(f[3]).vertices.at(2) != v5)
        fail("prism " + std::to_string(e.id) + ": its apex vertices (" + std::to_string(v4) + ", " +
             std::to_string(v5) +
             ") are not the third vertices of its triangular faces, which Nektar++ refuses");
      // Nektar++ (v0..v5) to Gmsh: triangles (v4 v1 v0) and (v5 v2 v3).
      return {v4, v1, v0, v5, v2, v3};
    }
    case CellType::Pyramid: {
      // As PyrGeom: face 0 the base, faces 1..4 the triangles over its edges 0..3, in turn.
      const int e0 = sharedEdge(f[0], f[1]), e1 = sharedEdge(f[0], f[2]);
      const int e2 = sharedEdge(f[0], f[3]), e4 = sharedEdge(f[1], f[4]);
      const int v1 = common(e0, e1), v0 = otherEnd(e0, v1), v2 = otherEnd(e1, v1);
      const int v3 = otherEnd(e2, v2), v4 = otherEnd(e4, v0);
      // Nektar++ refuses a triangle whose collapsed vertex (its third) is not the apex.
      for (int k = 1; k <= 4; ++k)
        if (face(f[static_cast<std::size_t>(k)]).vertices.at(2) != v4)
          fail("pyramid " + std::to_string(e.id) + ": its apex (vertex " + std::to_string(v4) +
               ") is not the third vertex of its triangular face " +
               std::to_string(f[static_cast<std::size_t>(k)]) + ", which Nektar++ refuses");
      return {v0, v1, v2, v3, v4};  // (Gmsh's order is PyrGeom's)
    }
    case CellType::Hexahedron: {
      const int e0 = sharedEdge(f[0], f[1]), e1 = sharedEdge(f[0], f[2]);
      const int e2 = sharedEdge(f[0], f[3]);
      const int e8 = sharedEdge(f[5], f[1]), e9 = sharedEdge(f[5], f[2]);
      const int e10 = sharedEdge(f[5], f[3]);
      const int v1 = common(e0, e1), v0 = otherEnd(e0, v1), v2 = otherEnd(e1, v1);
      const int v3 = otherEnd(e2, v2), v5 = common(e8, e9), v4 = otherEnd(e8, v5);
      const int v6 = otherEnd(e9, v5), v7 = otherEnd(e10, v6);
      return {v0, v1, v2, v3, v4, v5, v6, v7};
    }
    default:
      fail("unsupported element");
  }
}

std::int64_t Reader::newNode(const Point& p, bool known) {
  const double xyz[3] = {p.x(), p.y(), p.z()};
  known_.push_back(known);
  return mesh_.addNode(xyz, dim_, 0, kNaN, kNaN);
}

// Interior node t (1..P-1) of `edge` counted from its end `fromVertex`.
std::int64_t Reader::edgeNode(int edgeId, int fromVertex, int t) {
  auto& nodes = edgeNodes_[edgeId];
  const auto& ev = edge(edgeId);
  if (nodes.empty()) {
    const auto curve = g_.edgeCurves.find(edgeId);
    const Point a = vertexPoint(ev[0]), b = vertexPoint(ev[1]);
    for (int k = 1; k < order_; ++k)
      nodes.push_back(newNode(curve != g_.edgeCurves.end() ? curve->second.points.at(k)
                                                           : Point(a + (b - a) * k / order_),
                              true));
  }
  return nodes.at(ev[0] == fromVertex ? t - 1 : order_ - t - 1);
}

int Reader::edgeBetween(int a, int b) const {
  const auto it = edgeOf_.find(std::minmax(a, b));
  if (it == edgeOf_.end())
    fail("no edge joins vertices " + std::to_string(a) + " and " + std::to_string(b));
  return it->second;
}

// Interior nodes of a face (or 2D element) in Nektar++'s order; `points` is its curve, if any.
std::vector<std::int64_t> Reader::interiorNodes(bool triangle, const nektar::CurveRecord* curve) {
  std::vector<std::int64_t> nodes;
  const int n = order_ + 1;
  const std::size_t expected =
      triangle ? static_cast<std::size_t>(n * (n + 1) / 2) : static_cast<std::size_t>(n * n);
  if (curve != nullptr && curve->points.size() != expected)
    fail(std::string("a curved ") + (triangle ? "triangle" : "quadrilateral") + " has " +
         std::to_string(curve->points.size()) + " points; order " + std::to_string(order_) +
         " needs " + std::to_string(expected));
  int k = 3 * order_;
  for (int i = 1; i < order_; ++i)
    for (int j = 1; j < order_; ++j) {
      if (triangle && i + j >= order_) continue;
      const int at = triangle ? k++ : i * n + j;
      nodes.push_back(curve != nullptr ? newNode(curve->points.at(at), true)
                                       : newNode(Point::Zero(), false));
    }
  return nodes;
}

// Nodes of a polygon (face or 2D element) in Gmsh order, given its vertices in the polygon's
// own Nektar++ order and its stored interior nodes.
std::vector<std::int64_t> Reader::polygonNodes(const std::vector<int>& own,
                                               const std::vector<std::int64_t>& interior) {
  const bool triangle = own.size() == 3;
  const CellType type = triangle ? CellType::Triangle : CellType::Quadrilateral;
  const ReferenceElement& ref = ReferenceElement::get(type, order_);
  std::map<Lattice, std::int64_t> at;
  const int nv = static_cast<int>(own.size());
  for (int k = 0; k < nv; ++k) at[ref.lattice()[k]] = vertexNode(own[k]);
  for (int k = 0; k < nv; ++k) {
    const Lattice& a = ref.lattice()[k];
    const Lattice& b = ref.lattice()[(k + 1) % nv];
    const int edge = edgeBetween(own[k], own[(k + 1) % nv]);
    for (int t = 1; t < order_; ++t) {
      Lattice l;
      for (int c = 0; c < 3; ++c) l[c] = a[c] + (b[c] - a[c]) / order_ * t;
      at[l] = edgeNode(edge, own[k], t);
    }
  }
  std::size_t k = 0;  // interior rows: i towards vertex 2 (3), j towards vertex 1
  for (int i = 1; i < order_; ++i)
    for (int j = 1; j < order_; ++j)
      if (!triangle || i + j < order_) at[{j, i, 0}] = interior.at(k++);
  std::vector<std::int64_t> nodes;
  for (const Lattice& l : ref.lattice()) nodes.push_back(at.at(l));
  return nodes;
}

// Fills nodes of unknown position as Nektar++ builds them: quadrilaterals and hexahedra by
// transfinite interpolation, triangles, tetrahedra and prisms by their modified basis with
// interior modes zero.
void Reader::fill(CellType type, const std::vector<std::int64_t>& nodes) {
  const ReferenceElement& ref = ReferenceElement::get(type, order_);
  std::map<Lattice, std::int64_t> at;
  std::vector<int> unknown;
  for (int n = 0; n < ref.numNodes(); ++n) {
    at[ref.lattice()[n]] = nodes[n];
    if (!known_[nodes[n]]) unknown.push_back(n);
  }
  if (unknown.empty()) return;
  if (type == CellType::Quadrilateral || type == CellType::Hexahedron)
    fillTransfinite(type, ref, at, unknown);
  else
    fillExpansion(type, nodes, unknown);
}

// A quadrilateral's (hexahedron's) unknown nodes by transfinite (Coons, Gordon-Hall)
// interpolation with linear blending of its edges (faces): exactly what Nektar++ builds, whose
// expansion of the map has no interior modes (its modes are products of 1D modes, the
// boundary ones those with a linear factor, so the map without interior modes is this blend).
void Reader::fillTransfinite(CellType type, const ReferenceElement& ref,
                             const std::map<Lattice, std::int64_t>& at,
                             const std::vector<int>& unknown) {
  const int p = order_;
  const int dims = type == CellType::Hexahedron ? 3 : 2;
  const auto x = [&](const Lattice& l) {
    return Point(Eigen::Map<const Point>(&mesh_.xyz[3 * at.at(l)]));
  };
  for (const int u : unknown) {
    const Lattice& l = ref.lattice()[u];
    // Sum over the subsets S of the axes (not empty) of (-1)^(|S|+1) times the blend that
    // takes the axes in S to their ends (weights 1 - t, t) and keeps the others.
    Point sum = Point::Zero();
    for (int mask = 1; mask < (1 << dims); ++mask) {
      const int size = __builtin_popcount(static_cast<unsigned>(mask));
      const double sign = size % 2 == 1 ? 1.0 : -1.0;
      for (int ends = 0; ends < (1 << dims); ++ends) {
        if ((ends & ~mask) != 0) continue;  // only the axes in S take an end
        Lattice m = l;
        double w = 1.0;
        for (int d = 0; d < dims; ++d) {
          if ((mask & (1 << d)) == 0) continue;
          const double t = double(l[static_cast<std::size_t>(d)]) / p;
          const bool high = (ends & (1 << d)) != 0;
          m[static_cast<std::size_t>(d)] = high ? p : 0;
          w *= high ? t : 1.0 - t;
        }
        if (w != 0.0) sum += sign * w * x(m);
      }
    }
    double* out = &mesh_.xyz[3 * at.at(l)];
    for (int c = 0; c < 3; ++c) out[c] = sum[c];
  }
  for (const int u : unknown) known_[at.at(ref.lattice()[u])] = true;
}

// A triangle's, tetrahedron's or prism's interior nodes as Nektar++ builds them: the modified
// basis's map whose boundary modes come from the edges (faces) and whose interior modes are zero
// (io/nektar_expansion).
void Reader::fillExpansion(CellType type, const std::vector<std::int64_t>& nodes,
                           const std::vector<int>& unknown) {
  const nektar::ExpansionInteriorMap& map = [&]() -> const nektar::ExpansionInteriorMap& {
    try {
      return nektar::interiorFromBoundary(type, order_);
    } catch (const MeshingError& e) {  // (curved pyramids above order 2)
      fail(cellShortName(type) + " of order " + std::to_string(order_) + ": " + e.what());
    }
  }();
  if (unknown != map.interior) fail("an element's faces are incomplete");
  Eigen::MatrixXd boundary(static_cast<Eigen::Index>(map.boundary.size()), 3);
  for (std::size_t k = 0; k < map.boundary.size(); ++k)
    boundary.row(static_cast<Eigen::Index>(k)) =
        Eigen::Map<const Eigen::RowVector3d>(&mesh_.xyz[3 * nodes[map.boundary[k]]]);
  const Eigen::MatrixXd interior = map.weights * boundary;
  for (std::size_t k = 0; k < map.interior.size(); ++k) {
    const std::int64_t node = nodes[map.interior[k]];
    for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] = interior(static_cast<Eigen::Index>(k), c);
    known_[node] = true;
  }
}

// Nodes of a 3D element in Gmsh order: vertices, edge nodes, the nodes of its faces (looked up
// by vertex set), and new interior nodes.
std::vector<std::int64_t> Reader::volumeNodes(
    CellType type, const std::vector<int>& v,
    const std::map<std::vector<int>, std::vector<std::int64_t>>& faceByVertices) {
  const ReferenceElement& ref = ReferenceElement::get(type, order_);
  const int nv = cellNumVertices(type);
  std::map<Lattice, std::int64_t> at;
  for (int k = 0; k < nv; ++k) at[ref.lattice()[k]] = vertexNode(v[k]);
  // Faces in Gmsh's local numbering: their nodes from the shared face, mapped by lattice.
  static const std::map<CellType, std::vector<std::vector<int>>> gmshFaces = {
      {CellType::Tetrahedron, {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}},
      {CellType::Prism, {{0, 1, 2}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}}},
      {CellType::Pyramid, {{0, 1, 2, 3}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}},
      {CellType::Hexahedron,
       {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}}};
  for (const std::vector<int>& local : gmshFaces.at(type)) {
    std::vector<int> key;
    key.reserve(local.size());
    for (const int k : local) key.push_back(v[k]);
    std::sort(key.begin(), key.end());
    const auto it = faceByVertices.find(key);
    if (it == faceByVertices.end()) fail("an element's face is missing from FACE");
    // The face's Gmsh-ordered nodes sit on its own lattice; map its vertices to ours.
    const std::vector<std::int64_t>& faceNodes = it->second;
    const bool triangle = local.size() == 3;
    const ReferenceElement& fref =
        ReferenceElement::get(triangle ? CellType::Triangle : CellType::Quadrilateral, order_);
    // The face's own vertices, as local vertices of this element (the first nodes are vertices).
    std::vector<Lattice> corner;
    for (std::size_t k = 0; k < local.size(); ++k) {
      const std::int64_t node = faceNodes[k];
      const int lv =
          static_cast<int>(std::find_if(local.begin(), local.end(),
                                        [&](int x) { return vertexNode(v[x]) == node; }) -
                           local.begin());
      corner.push_back(ref.lattice()[local.at(lv)]);
    }
    for (int n = 0; n < fref.numNodes(); ++n) {
      const Lattice& fl = fref.lattice()[n];  // (s, t) on the face's own lattice
      Lattice l;
      const Lattice& b = corner[1];
      const Lattice& c = corner[triangle ? 2 : 3];
      for (int k = 0; k < 3; ++k)
        l[k] = corner[0][k] + (b[k] - corner[0][k]) / order_ * fl[0] +
               (c[k] - corner[0][k]) / order_ * fl[1];
      at[l] = faceNodes[n];
    }
  }
  // Edges not on any face do not exist in 3D; the rest is interior.
  std::vector<std::int64_t> nodes;
  for (const Lattice& l : ref.lattice()) {
    const auto it = at.find(l);
    nodes.push_back(it != at.end() ? it->second : newNode(Point::Zero(), false));
  }
  return nodes;
}

}  // namespace

Mesh readNektarXml(const std::string& path) {
  try {
    return Reader(path).read();
  } catch (const std::out_of_range&) {
    // Checks above name the usual faults; this catches any inconsistency they do not foresee.
    throw IoError("'" + path +
                  "' is not a valid Nektar++ geometry: its entities do not fit "
                  "together (an id, count or face does not match the rest of the file)");
  }
}

}  // namespace homesh
