#include "io/nektar_writer.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "element/reference_element.hpp"
#include "io/atomic_file.hpp"
#include "io/nektar_format.hpp"

namespace homesh {
namespace {

using Point = Eigen::Vector3d;
using Lattice = LatticePoint;

// Lattice point a + (b - a) * s / p + (c - a) * t / p (exact: vertex coordinates are 0 or p).
Lattice combine(const Lattice& a, const Lattice& b, const Lattice& c, int s, int t, int p) {
  Lattice r;
  for (int k = 0; k < 3; ++k) r[k] = a[k] + (b[k] - a[k]) / p * s + (c[k] - a[k]) / p * t;
  return r;
}

struct Face {
  bool triangle = true;
  std::vector<int> vertices;  // the face's own vertex order (derived from its edges)
  std::vector<int> edges;
  std::vector<Point> points;  // all points in Nektar++'s order for the face
  bool curved = false;
};

struct Element {
  CellType type;
  int entity;
  std::vector<int> ids;       // faces (3D) or edges (2D), in local order
  std::vector<Point> points;  // 2D elements: all points, Nektar++'s face order
  bool curved = false;
};

class Builder {
 public:
  explicit Builder(const Mesh& mesh) : mesh_(mesh), p_(mesh.order) {
    for (const ElementBlock& block : mesh.blocks)
      if (block.order != p_) throw ParameterError("Nektar++ output needs one element order");
    numberVertices();
    for (const ElementBlock& block : mesh.blocks) {
      if (cellDimension(block.type) != mesh.dim) continue;
      const ReferenceElement& ref = ReferenceElement::get(block.type, p_);
      for (std::size_t e = 0; e < block.count(); ++e) addElement(block, e, ref);
    }
    for (const ElementBlock& block : mesh.blocks) {
      if (cellDimension(block.type) != mesh.dim - 1) continue;
      for (std::size_t e = 0; e < block.count(); ++e) addBoundary(block, e);
    }
    markCurved();
  }

  const Mesh& mesh_;
  int p_;
  std::vector<std::int64_t> vertexNode;
  std::map<std::int64_t, int> vertexOf;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::vector<Point>> edgePoints;  // from edges[i][0] to edges[i][1]
  std::vector<bool> edgeCurved;
  std::map<std::pair<int, int>, int> edgeOf;
  std::vector<Face> faces;
  std::map<std::vector<int>, int> faceOf;  // sorted vertex ids -> face
  std::vector<Element> elements;
  std::map<std::pair<char, int>, std::vector<int>> elementGroups;  // (letter, entity) -> ids
  std::map<int, std::vector<int>> boundaryGroups;                  // entity -> face/edge ids

 private:
  Point nodePoint(std::int64_t node) const {
    return {mesh_.xyz[3 * node], mesh_.xyz[3 * node + 1], mesh_.xyz[3 * node + 2]};
  }

  // Vertex ids, given before any element is added. Nektar++ builds a prism's triangular faces
  // around its apex vertices (4 and 5), and reads a shared triangle's own orientation (vertex
  // order by ascending id) only if each apex has the highest id of its triangle. Vertices
  // joined by a prism's edge between its triangles (a boundary layer's columns) are numbered
  // as one run, the runs in order of their smallest node: then the column of a prism holding
  // the highest id holds it in both triangles, and that column is the apex (addElement).
  // Other vertices are numbered in node order among the runs, but for pyramids (below).
  void numberVertices() {
    std::map<std::int64_t, std::int64_t> parent;  // union-find over vertex nodes
    const auto find = [&](std::int64_t n) {
      auto it = parent.try_emplace(n, n).first;
      while (it->second != it->first) it = parent.find(it->second);
      return it->first;
    };
    for (const ElementBlock& block : mesh_.blocks) {
      if (cellDimension(block.type) != mesh_.dim) continue;
      const int nv = cellNumVertices(block.type);
      for (std::size_t e = 0; e < block.count(); ++e) {
        const std::int64_t* nodes = block.element(e);
        for (int k = 0; k < nv; ++k) find(nodes[k]);
        if (block.type != CellType::Prism) continue;
        for (int k = 0; k < 3; ++k) {
          const std::int64_t a = find(nodes[k]), b = find(nodes[k + 3]);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
      }
    }
    std::map<std::int64_t, std::vector<std::int64_t>> runs;  // smallest node -> its run
    for (const auto& entry : parent) runs[find(entry.first)].push_back(entry.first);
    // A pyramid's apex is the collapsed vertex of its four triangles: its run comes after the
    // runs of its base (the runs otherwise in order of their smallest node).
    std::map<std::int64_t, std::set<std::int64_t>> after;  // run -> runs that must follow it
    std::map<std::int64_t, int> before;                    // run -> runs it must follow
    for (const ElementBlock& block : mesh_.blocks) {
      if (block.type != CellType::Pyramid || mesh_.dim != 3) continue;
      for (std::size_t e = 0; e < block.count(); ++e) {
        const std::int64_t* nodes = block.element(e);
        const std::int64_t apex = find(nodes[4]);
        for (int k = 0; k < 4; ++k) {
          const std::int64_t base = find(nodes[k]);
          if (base == apex)
            throw ParameterError(
                "Nektar++ XML: pyramid " + std::to_string(e + 1) +
                " has its apex in a prism column with a vertex of its base, so no numbering "
                "makes the apex its triangles' collapsed vertex");
          if (after[base].insert(apex).second) ++before[apex];
        }
      }
    }
    std::set<std::int64_t> ready;
    for (const auto& [root, nodes] : runs)
      if (before[root] == 0) ready.insert(root);
    std::size_t numbered = 0;
    while (!ready.empty()) {
      const std::int64_t root = *ready.begin();
      ready.erase(ready.begin());
      for (const std::int64_t n : runs.at(root)) vertex(n);
      ++numbered;
      for (const std::int64_t next : after[root])
        if (--before[next] == 0) ready.insert(next);
    }
    if (numbered != runs.size())
      throw ParameterError(
          "Nektar++ XML: the pyramids' apexes and bases form a cycle (an apex is in the base of "
          "a pyramid whose apex is in its base), so no numbering makes every apex its "
          "triangles' collapsed vertex");
  }

  int vertex(std::int64_t node) {
    const auto [it, added] = vertexOf.try_emplace(node, static_cast<int>(vertexNode.size()));
    if (added) vertexNode.push_back(node);
    return it->second;
  }

  // The element context needed to find the node at a lattice point.
  struct Context {
    const std::int64_t* nodes;
    const std::map<Lattice, int>* index;
    const std::vector<Lattice>* lattice;
    const std::vector<int>* vertexId;  // per local vertex
  };
  Point at(const Context& c, const Lattice& l) const { return nodePoint(c.nodes[c.index->at(l)]); }

  // Edge between local vertices la and lb of the element.
  int edge(const Context& c, int la, int lb) {
    int a = (*c.vertexId)[la], b = (*c.vertexId)[lb];
    if (a > b) {
      std::swap(a, b);
      std::swap(la, lb);
    }
    const auto [it, added] = edgeOf.try_emplace({a, b}, static_cast<int>(edges.size()));
    if (added) {
      edges.push_back({a, b});
      std::vector<Point> points;
      const Lattice& from = (*c.lattice)[la];
      const Lattice& to = (*c.lattice)[lb];
      for (int t = 0; t <= p_; ++t) points.push_back(at(c, combine(from, to, from, t, 0, p_)));
      edgePoints.push_back(std::move(points));
    }
    return it->second;
  }

  // Triangle face on local vertices (any order): own order by ascending vertex id.
  int triangle(const Context& c, std::array<int, 3> local) {
    std::sort(local.begin(), local.end(),
              [&](int x, int y) { return (*c.vertexId)[x] < (*c.vertexId)[y]; });
    std::vector<int> key{(*c.vertexId)[local[0]], (*c.vertexId)[local[1]], (*c.vertexId)[local[2]]};
    const auto [it, added] = faceOf.try_emplace(key, static_cast<int>(faces.size()));
    if (!added) return it->second;
    Face f;
    f.triangle = true;
    f.vertices = key;
    f.edges = {edge(c, local[0], local[1]), edge(c, local[1], local[2]),
               edge(c, local[0], local[2])};
    f.points = trianglePoints(c, local);
    faces.push_back(std::move(f));
    return it->second;
  }

  // Points of a triangle in Nektar++'s nodal order: vertices, edges a-b, b-c, c-a, interior rows.
  std::vector<Point> trianglePoints(const Context& c, const std::array<int, 3>& local) const {
    const Lattice& a = (*c.lattice)[local[0]];
    const Lattice& b = (*c.lattice)[local[1]];
    const Lattice& cc = (*c.lattice)[local[2]];
    std::vector<Point> pts{at(c, a), at(c, b), at(c, cc)};
    for (int t = 1; t < p_; ++t) pts.push_back(at(c, combine(a, b, cc, t, 0, p_)));
    for (int t = 1; t < p_; ++t) pts.push_back(at(c, combine(a, b, cc, p_ - t, t, p_)));
    for (int t = 1; t < p_; ++t) pts.push_back(at(c, combine(a, b, cc, 0, p_ - t, p_)));
    for (int i = 1; i < p_; ++i)
      for (int j = 1; i + j < p_; ++j) pts.push_back(at(c, combine(a, b, cc, j, i, p_)));
    return pts;
  }

  // Quadrilateral face on local vertices in cyclic order: own order from its smallest vertex id
  // towards the smaller neighbour.
  int quadrilateral(const Context& c, std::array<int, 4> local) {
    const auto id = [&](int l) { return (*c.vertexId)[l]; };
    int start = 0;
    for (int k = 1; k < 4; ++k)
      if (id(local[k]) < id(local[start])) start = k;
    std::array<int, 4> q;
    const bool forward = id(local[(start + 1) % 4]) < id(local[(start + 3) % 4]);
    for (int k = 0; k < 4; ++k) q[k] = local[(start + (forward ? k : 4 - k)) % 4];
    std::vector<int> key{id(q[0]), id(q[1]), id(q[2]), id(q[3])};
    std::sort(key.begin(), key.end());
    const auto [it, added] = faceOf.try_emplace(key, static_cast<int>(faces.size()));
    if (!added) return it->second;
    Face f;
    f.triangle = false;
    f.vertices = {id(q[0]), id(q[1]), id(q[2]), id(q[3])};
    f.edges = {edge(c, q[0], q[1]), edge(c, q[1], q[2]), edge(c, q[2], q[3]), edge(c, q[3], q[0])};
    f.points = quadrilateralPoints(c, q);
    faces.push_back(std::move(f));
    return it->second;
  }

  // n x n points, the q0 -> q1 direction fastest.
  std::vector<Point> quadrilateralPoints(const Context& c, const std::array<int, 4>& q) const {
    const Lattice& a = (*c.lattice)[q[0]];
    const Lattice& b = (*c.lattice)[q[1]];
    const Lattice& d = (*c.lattice)[q[3]];
    std::vector<Point> pts;
    for (int i = 0; i <= p_; ++i)
      for (int j = 0; j <= p_; ++j) pts.push_back(at(c, combine(a, b, d, j, i, p_)));
    return pts;
  }

  void addElement(const ElementBlock& block, std::size_t e, const ReferenceElement& ref) {
    static thread_local std::map<std::pair<CellType, int>, std::map<Lattice, int>> indices;
    auto& index = indices[{block.type, p_}];
    if (index.empty())
      for (int n = 0; n < ref.numNodes(); ++n) index[ref.lattice()[n]] = n;
    const std::int64_t* nodes = block.element(e);
    const int nv = cellNumVertices(block.type);
    std::vector<int> ids(nv);
    for (int k = 0; k < nv; ++k) ids[k] = vertex(nodes[k]);
    const Context c{nodes, &index, &ref.lattice(), &ids};
    Element el{block.type, block.entity[e], {}, {}, false};
    switch (block.type) {
      case CellType::Tetrahedron: {
        // Nektar++'s local vertices: by ascending id, the first two swapped for a positive
        // volume; faces (0,1,2) (0,1,3) (1,2,3) (0,2,3).
        std::array<int, 4> n{0, 1, 2, 3};
        std::sort(n.begin(), n.end(), [&](int x, int y) { return ids[x] < ids[y]; });
        const Point x0 = nodePoint(nodes[n[0]]);
        if ((nodePoint(nodes[n[1]]) - x0)
                .cross(nodePoint(nodes[n[2]]) - x0)
                .dot(nodePoint(nodes[n[3]]) - x0) < 0.0)
          std::swap(n[0], n[1]);
        for (const auto& f : nektar::localFaces(CellType::Tetrahedron))
          el.ids.push_back(triangle(c, {n[f[0]], n[f[1]], n[f[2]]}));
        break;
      }
      case CellType::Prism: {
        // The vertical edge with the highest vertex id becomes Nektar++'s apex (4, 5).
        int r = 0;
        for (int k = 1; k < 3; ++k)
          if (std::max(ids[k], ids[k + 3]) > std::max(ids[r], ids[r + 3])) r = k;
        const int n[6] = {(r + 2) % 3, (r + 1) % 3, (r + 1) % 3 + 3, (r + 2) % 3 + 3, r, r + 3};
        for (const auto& f : nektar::localFaces(CellType::Prism))
          el.ids.push_back(f.size() == 3 ? triangle(c, {n[f[0]], n[f[1]], n[f[2]]})
                                         : quadrilateral(c, {n[f[0]], n[f[1]], n[f[2]], n[f[3]]}));
        break;
      }
      case CellType::Hexahedron:
        for (const auto& f : nektar::localFaces(CellType::Hexahedron))
          el.ids.push_back(quadrilateral(c, {f[0], f[1], f[2], f[3]}));
        break;
      case CellType::Pyramid:
        // Nektar++'s PyrGeom takes its local vertices from the faces' order (the base, then the
        // triangles over base edges 01, 12, 32, 03: Gmsh's corners as they are) and each
        // triangle's collapsed vertex, its own third, must be the apex: the highest id of its
        // triangle (numberVertices), as the tetrahedra and prisms sharing it also need.
        for (const auto& f : nektar::localFaces(CellType::Pyramid))
          el.ids.push_back(f.size() == 3 ? triangle(c, {f[0], f[1], f[2]})
                                         : quadrilateral(c, {f[0], f[1], f[2], f[3]}));
        break;
      case CellType::Triangle:
        el.ids = {edge(c, 0, 1), edge(c, 1, 2), edge(c, 2, 0)};
        el.points = trianglePoints(c, {0, 1, 2});
        break;
      case CellType::Quadrilateral:
        el.ids = {edge(c, 0, 1), edge(c, 1, 2), edge(c, 2, 3), edge(c, 3, 0)};
        el.points = quadrilateralPoints(c, {0, 1, 2, 3});
        break;
      default:
        throw ParameterError("Nektar++ XML output has no " + cellShortName(block.type));
    }
    elementGroups[{nektar::letter(block.type), block.entity[e]}].push_back(
        static_cast<int>(elements.size()));
    elements.push_back(std::move(el));
  }

  void addBoundary(const ElementBlock& block, std::size_t e) {
    const std::int64_t* nodes = block.element(e);
    std::vector<int> key;
    for (int k = 0; k < cellNumVertices(block.type); ++k) {
      const auto it = vertexOf.find(nodes[k]);
      if (it == vertexOf.end()) return;  // not on any element (a free face or curve)
      key.push_back(it->second);
    }
    std::sort(key.begin(), key.end());
    int id = -1;
    if (block.type == CellType::Line) {
      const auto it = edgeOf.find({key[0], key[1]});
      if (it != edgeOf.end()) id = it->second;
    } else {
      const auto it = faceOf.find(key);
      if (it != faceOf.end()) id = it->second;
    }
    if (id >= 0) boundaryGroups[block.entity[e]].push_back(id);
  }

  // At order 2 and above every edge, face (3D) and element (2D) is written with its points, as
  // NekMesh does: the file then holds every node but the interior of 3D elements, bit for bit.
  void markCurved() {
    const bool curved = p_ > 1;
    edgeCurved.assign(edges.size(), curved);
    for (Face& f : faces) f.curved = curved;
    for (Element& el : elements) el.curved = curved && !el.points.empty();
  }
};

// "0-3,5,7-9": Nektar++'s compact id lists.
std::string idList(std::vector<int> ids) {
  std::sort(ids.begin(), ids.end());
  std::string out;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(ids[i]);
    if (j > i) out += '-' + std::to_string(ids[j]);
    i = j + 1;
  }
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

template <class Record>
std::string blob(const std::vector<Record>& records) {
  return nektar::encode(records.data(), records.size() * sizeof(Record));
}

std::string compressedTag(const char* name) {
  return std::string("<") + name + R"( COMPRESSED=")" + nektar::kCompressed + R"(" BITSIZE="64">)";
}

// Writes the entities of one 3D face kind or element kind with N ids each.
template <int N>
void writeEntities(std::ostream& os, char tag,
                   const std::vector<std::pair<int, std::vector<int>>>& items, bool compressed) {
  if (items.empty()) return;
  if (compressed) {
    std::vector<nektar::Entity<N>> records;
    for (const auto& [id, ids] : items) {
      nektar::Entity<N> r{id, {}};
      for (int k = 0; k < N; ++k) r.ids[k] = ids[k];
      records.push_back(r);
    }
    const char name[2] = {tag, '\0'};
    os << "      " << compressedTag(name) << blob(records) << "</" << tag << ">\n";
    return;
  }
  for (const auto& [id, ids] : items) {
    os << "      <" << tag << " ID=\"" << id << "\">";
    for (const int i : ids) os << i << ' ';
    os << "</" << tag << ">\n";
  }
}

void writeVerticesAndEdges(std::ostream& os, const Mesh& mesh, const Builder& b, bool compressed) {
  if (compressed) {
    std::vector<nektar::Vertex> vs;
    for (std::size_t i = 0; i < b.vertexNode.size(); ++i) {
      const double* x = &mesh.xyz[3 * b.vertexNode[i]];
      vs.push_back({static_cast<std::int64_t>(i), x[0], x[1], x[2]});
    }
    os << "    " << compressedTag("VERTEX") << blob(vs) << "</VERTEX>\n";
    std::vector<nektar::Edge> es;
    for (std::size_t i = 0; i < b.edges.size(); ++i)
      es.push_back({static_cast<std::int64_t>(i), b.edges[i][0], b.edges[i][1]});
    os << "    " << compressedTag("EDGE") << blob(es) << "</EDGE>\n";
    return;
  }
  os << "    <VERTEX>\n";
  for (std::size_t i = 0; i < b.vertexNode.size(); ++i) {
    const double* x = &mesh.xyz[3 * b.vertexNode[i]];
    os << "      <V ID=\"" << i << "\">" << number(x[0]) << ' ' << number(x[1]) << ' '
       << number(x[2]) << "</V>\n";
  }
  os << "    </VERTEX>\n    <EDGE>\n";
  for (std::size_t i = 0; i < b.edges.size(); ++i)
    os << "      <E ID=\"" << i << "\">" << b.edges[i][0] << ' ' << b.edges[i][1] << "</E>\n";
  os << "    </EDGE>\n";
}

// FACE (3D only): triangles, then quadrilaterals.
void writeFaces(std::ostream& os, const Builder& b, bool compressed) {
  std::vector<std::pair<int, std::vector<int>>> tris, quads;
  for (std::size_t i = 0; i < b.faces.size(); ++i)
    (b.faces[i].triangle ? tris : quads).emplace_back(static_cast<int>(i), b.faces[i].edges);
  os << "    <FACE>\n";
  writeEntities<3>(os, 'T', tris, compressed);
  writeEntities<4>(os, 'Q', quads, compressed);
  os << "    </FACE>\n";
}

// ELEMENT, by kind in Nektar++'s order.
void writeElements(std::ostream& os, const Builder& b, bool compressed) {
  os << "    <ELEMENT>\n";
  std::map<CellType, std::vector<std::pair<int, std::vector<int>>>> byType;
  for (std::size_t i = 0; i < b.elements.size(); ++i)
    byType[b.elements[i].type].emplace_back(static_cast<int>(i), b.elements[i].ids);
  writeEntities<6>(os, 'H', byType[CellType::Hexahedron], compressed);
  writeEntities<5>(os, 'R', byType[CellType::Prism], compressed);
  writeEntities<5>(os, 'P', byType[CellType::Pyramid], compressed);
  writeEntities<4>(os, 'A', byType[CellType::Tetrahedron], compressed);
  writeEntities<3>(os, 'T', byType[CellType::Triangle], compressed);
  writeEntities<4>(os, 'Q', byType[CellType::Quadrilateral], compressed);
  os << "    </ELEMENT>\n";
}

// One CURVED entry: an edge's, a face's (3D) or an element's (2D) points.
struct CurveEntry {
  bool edge;
  int entity;
  const std::vector<Point>* points;
  bool nodalTriangle;
};

// The curves in CURVED's order: edges, then faces (3D) or elements (2D).
std::vector<CurveEntry> curveEntries(const Builder& b) {
  std::vector<CurveEntry> curves;
  for (std::size_t i = 0; i < b.edges.size(); ++i)
    if (b.edgeCurved[i]) curves.push_back({true, static_cast<int>(i), &b.edgePoints[i], false});
  for (std::size_t i = 0; i < b.faces.size(); ++i)
    if (b.faces[i].curved)
      curves.push_back({false, static_cast<int>(i), &b.faces[i].points, b.faces[i].triangle});
  for (std::size_t i = 0; i < b.elements.size(); ++i)
    if (b.elements[i].curved)
      curves.push_back({false, static_cast<int>(i), &b.elements[i].points,
                        b.elements[i].type == CellType::Triangle});
  return curves;
}

// Compressed CURVED: the curves' records, the index of their points and the points.
void writeCompressedCurves(std::ostream& os, const std::vector<CurveEntry>& curves) {
  std::vector<nektar::CurvedInfo> edgeInfo, faceInfo;
  std::vector<std::int64_t> index;
  std::vector<nektar::Vertex> points;
  for (const CurveEntry& c : curves) {
    auto& info = c.edge ? edgeInfo : faceInfo;
    info.push_back({static_cast<std::int64_t>(info.size()), c.entity,
                    static_cast<std::int64_t>(c.points->size()), 0,
                    static_cast<std::int64_t>(index.size()),
                    c.nodalTriangle ? nektar::kTriEvenlySpacedId : nektar::kEvenlySpacedId});
    for (const Point& pt : *c.points) {
      index.push_back(static_cast<std::int64_t>(points.size()));
      points.push_back({static_cast<std::int64_t>(points.size()), pt.x(), pt.y(), pt.z()});
    }
  }
  os << "    " << compressedTag("CURVED") << "\n";
  if (!edgeInfo.empty()) os << "      <E>" << blob(edgeInfo) << "</E>\n";
  if (!faceInfo.empty()) os << "      <F>" << blob(faceInfo) << "</F>\n";
  os << "      <DATAPOINTS ID=\"0\">\n        <INDEX>" << blob(index)
     << "</INDEX>\n        <POINTS>" << blob(points) << "</POINTS>\n      </DATAPOINTS>\n";
  os << "    </CURVED>\n";
}

void writePlainCurves(std::ostream& os, const std::vector<CurveEntry>& curves) {
  os << "    <CURVED>\n";
  int id = 0;
  for (const CurveEntry& c : curves) {
    os << "      <" << (c.edge ? 'E' : 'F') << " ID=\"" << id++ << "\" "
       << (c.edge ? "EDGEID" : "FACEID") << "=\"" << c.entity << "\" NUMPOINTS=\""
       << c.points->size() << "\" TYPE=\""
       << (c.nodalTriangle ? nektar::kTriEvenlySpaced : nektar::kEvenlySpaced) << "\">";
    for (const Point& pt : *c.points)
      os << number(pt.x()) << ' ' << number(pt.y()) << ' ' << number(pt.z()) << "   ";
    os << "</" << (c.edge ? 'E' : 'F') << ">\n";
  }
  os << "    </CURVED>\n";
}

// COMPOSITE: elements by kind and CAD entity, then boundary groups. Returns the element
// composites' ids (the DOMAIN).
std::vector<int> writeComposites(std::ostream& os, const Mesh& mesh, const Builder& b,
                                 const std::vector<NamedGroup>& groups) {
  os << "    <COMPOSITE>\n";
  int composite = 0;
  std::vector<int> domain;
  for (const auto& [key, ids] : b.elementGroups) {
    domain.push_back(composite);
    os << "      <C ID=\"" << composite++ << "\" NAME=\"" << cadEntityName(mesh.dim, key.second)
       << "\"> " << key.first << '[' << idList(ids) << "] </C>\n";
  }
  // Boundary composites: one per named group (its entities' faces together), then one per
  // entity in no group.
  const char boundaryLetter = mesh.dim == 3 ? 'F' : 'E';
  std::set<int> grouped;
  for (const NamedGroup& g : groups) {
    std::vector<int> ids;
    for (const int entity : g.entities) {
      grouped.insert(entity);
      const auto it = b.boundaryGroups.find(entity);
      if (it != b.boundaryGroups.end()) ids.insert(ids.end(), it->second.begin(), it->second.end());
    }
    std::sort(ids.begin(), ids.end());
    os << "      <C ID=\"" << composite++ << "\" NAME=\"" << g.name << "\"> " << boundaryLetter
       << '[' << idList(ids) << "] </C>\n";
  }
  for (const auto& [entity, ids] : b.boundaryGroups) {
    if (grouped.count(entity) > 0) continue;
    os << "      <C ID=\"" << composite++ << "\" NAME=\"" << cadEntityName(mesh.dim - 1, entity)
       << "\"> " << boundaryLetter << '[' << idList(ids) << "] </C>\n";
  }
  os << "    </COMPOSITE>\n";
  return domain;
}

void writeExpansions(std::ostream& os, int order, const std::vector<int>& domain) {
  os << "  <EXPANSIONS>\n";
  for (const int c : domain)
    os << "    <E COMPOSITE=\"C[" << c << "]\" NUMMODES=\"" << order + 1
       << "\" TYPE=\"MODIFIED\" FIELDS=\"u\" />\n";
  os << "  </EXPANSIONS>\n";
}

}  // namespace

// Pyramids are written up to order 2, which leaves none of their nodes inside: above it
// Nektar++ rebuilds the interior from the faces in its own pyramid basis (ModifiedPyr_C), whose
// space is not our element's (Bergot's) from order 3 (nektar_expansion.hpp), so the file could
// not be certified as Nektar++ sees it, nor hold our element.
void checkNektarPyramids(const Mesh& mesh) {
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Pyramid && b.count() > 0 && b.order > 2)
      throw ParameterError("Nektar++ XML: pyramids are written up to order 2, these are of order " +
                           std::to_string(b.order) +
                           " (above it Nektar++'s pyramid space is not ours, so its geometry "
                           "could not be certified): write .msh");
}

void writeNektarXml(const Mesh& mesh, const std::string& path, bool compressed,
                    const std::vector<NamedGroup>& groups) {
  mesh.checkConsistency();
  checkNektarPyramids(mesh);
  const Builder b(mesh);
  AtomicFile file(path, false);
  std::ostream& os = file.stream();
  os << "<?xml version=\"1.0\" encoding=\"utf-8\" ?>\n<NEKTAR>\n";
  os << "  <GEOMETRY DIM=\"" << mesh.dim << "\" SPACE=\"3\">\n";
  writeVerticesAndEdges(os, mesh, b, compressed);
  if (mesh.dim == 3) writeFaces(os, b, compressed);
  writeElements(os, b, compressed);
  const std::vector<CurveEntry> curves = curveEntries(b);
  if (!curves.empty()) {
    if (compressed)
      writeCompressedCurves(os, curves);
    else
      writePlainCurves(os, curves);
  }
  const std::vector<int> domain = writeComposites(os, mesh, b, groups);
  os << "    <DOMAIN> C[" << idList(domain) << "] </DOMAIN>\n";
  os << "  </GEOMETRY>\n";
  writeExpansions(os, mesh.order, domain);
  os << "</NEKTAR>\n";
  file.commit();
}

}  // namespace homesh
