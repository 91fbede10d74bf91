#include "io/nektar_reader.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/input_file.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "io/nektar_expansion.hpp"
#include "io/nektar_format.hpp"
#include "io/xml_document.hpp"

namespace homesh {
namespace {

using Point = Eigen::Vector3d;
using Lattice = LatticePoint;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Face {
  bool triangle = true;
  std::vector<int> edges;
  std::vector<int> vertices;  // own order, from the edge loop
};

struct Element {
  CellType type;
  int id;
  std::vector<int> ids;  // faces (3D) or edges (2D)
};

struct Curve {
  std::vector<Point> points;
  std::string type;  // Nektar++'s points type (PolyEvenlySpaced, GaussLobattoLegendre, ...)
};

// The name of a Nektar++ 5.x PointsType value as a compressed CURVED record stores it.
std::string pointsTypeName(std::int64_t value) {
  switch (value) {
    case nektar::kEvenlySpacedId:
      return nektar::kEvenlySpaced;
    case nektar::kTriEvenlySpacedId:
      return nektar::kTriEvenlySpaced;
    case nektar::kGaussLobattoLegendreId:
      return nektar::kGaussLobattoLegendre;
    case nektar::kTriElecId:
      return "NodalTriElec";
    case nektar::kTriFeketeId:
      return "NodalTriFekete";
    default:
      return "points type " + std::to_string(value);
  }
}

// The n Gauss-Lobatto-Legendre points on [0, 1] (the ends and the Gauss-Jacobi(1, 1) points).
std::vector<double> lobattoPoints(int n) {
  std::vector<double> x, w;
  if (n > 2) gaussJacobi(n - 2, 1.0, 1.0, x, w);
  std::vector<double> t{0.0};
  for (const double z : x) t.push_back(0.5 * (z + 1.0));
  t.push_back(1.0);
  return t;
}

// Values at `to` of the polynomial through (from[k], v[k]) (Lagrange form).
Point interpolate(const std::vector<double>& from, const std::vector<Point>& v, double to) {
  Point sum = Point::Zero();
  for (std::size_t k = 0; k < from.size(); ++k) {
    double l = 1.0;
    for (std::size_t j = 0; j < from.size(); ++j)
      if (j != k) l *= (to - from[j]) / (from[k] - from[j]);
    sum += l * v[k];
  }
  return sum;
}

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid Nektar++ geometry: " + what);
  }

  Mesh read();

 private:
  // Section parsing.
  void readVertices(const XmlElement& section);
  void readEdges(const XmlElement& section);
  void readFaces(const XmlElement& section);
  void readElements(const XmlElement& section);
  void readCurves(const XmlElement& section);
  void readComposites(const XmlElement& section);
  // Decodes a compressed blob; `tagged`: the element itself carries COMPRESSED (children of a
  // compressed CURVED do not).
  template <class Record>
  std::vector<Record> records(const XmlElement& e, bool tagged = true) const;
  std::vector<double> numbers(const std::string& text, const std::string& where) const;
  // Entity ids: from an attribute, from text, from a number read as text or from a record;
  // each must be an integer in 0..INT_MAX.
  int idAttribute(const XmlElement& e, const char* key = "ID") const;
  std::vector<int> ids(const std::string& text, std::size_t count, const std::string& where) const;
  int toId(long long value, const std::string& what) const;
  std::vector<int> parseIdList(const std::string& list, const std::string& where,
                               std::size_t limit) const;
  // Entities by id, failing with the id when one is missing.
  const std::array<int, 2>& edge(int id) const;
  const Face& face(int id) const;
  std::int64_t vertexNode(int id) const;
  const Point& vertexPoint(int id) const;

  // Topology.
  int common(int edgeA, int edgeB) const;  // the vertex two edges share
  int sharedEdge(int faceA, int faceB) const;
  int otherEnd(int edge, int vertex) const;
  std::vector<int> loopVertices(const std::vector<int>& edgeIds) const;
  std::vector<int> elementVertices(const Element& e) const;  // Gmsh local order

  // Nodes.
  std::int64_t newNode(const Point& p, bool known);
  std::int64_t edgeNode(int edgeId, int fromVertex, int t);
  int edgeBetween(int a, int b) const;
  std::vector<std::int64_t> interiorNodes(bool triangle, const Curve* curve);
  std::vector<std::int64_t> polygonNodes(const std::vector<int>& own,
                                         const std::vector<std::int64_t>& interior);
  std::vector<std::int64_t> volumeNodes(
      CellType type, const std::vector<int>& v,
      const std::map<std::vector<int>, std::vector<std::int64_t>>& faceByVertices);
  void fill(CellType type, const std::vector<std::int64_t>& nodes);
  void toEvenlySpaced();
  void fillTransfinite(CellType type, const ReferenceElement& ref,
                       const std::map<Lattice, std::int64_t>& at, const std::vector<int>& unknown);
  void fillExpansion(CellType type, const std::vector<std::int64_t>& nodes,
                     const std::vector<int>& unknown);

  std::string path_;
  int dim_ = 3;
  int order_ = 1;
  std::map<int, Point> vertices_;
  std::map<int, std::array<int, 2>> edges_;
  std::map<int, Face> faces_;
  std::vector<Element> elements_;
  std::map<int, Curve> edgeCurves_, faceCurves_;
  struct Composite {
    std::string name;
    char letter;
    std::vector<int> ids;
  };
  std::vector<Composite> composites_;

  Mesh mesh_;
  std::map<std::pair<int, int>, int> edgeOf_;  // (smaller, larger vertex) -> edge
  std::map<int, std::int64_t> vertexNode_;
  std::map<int, std::vector<std::int64_t>> edgeNodes_;
  std::vector<bool> known_;  // node position given by the file (else to be filled)
};

int Reader::toId(long long value, const std::string& what) const {
  if (value < 0 || value > INT_MAX) fail(what + " is not a valid id: " + std::to_string(value));
  return static_cast<int>(value);
}

int Reader::idAttribute(const XmlElement& e, const char* key) const {
  const std::string text = e.attribute(key);
  long long v = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || v < 0 ||
      v > INT_MAX)
    fail("<" + e.name + "> has " + key + "=\"" + excerpt(text) + "\", not an id");
  return static_cast<int>(v);
}

std::vector<int> Reader::ids(const std::string& text, std::size_t count,
                             const std::string& where) const {
  const std::vector<double> v = numbers(text, where);
  if (v.size() != count)
    fail(where + " needs " + std::to_string(count) + " ids, has " + std::to_string(v.size()));
  std::vector<int> out;
  out.reserve(v.size());
  for (const double x : v) {
    if (!(x >= 0.0 && x <= INT_MAX) || x != std::floor(x))
      fail(where + " has an id that is not one");
    out.push_back(static_cast<int>(x));
  }
  return out;
}

// "0-3,5,7-9": Nektar++'s compact id lists; `limit` bounds how many ids it may expand to.
std::vector<int> Reader::parseIdList(const std::string& list, const std::string& where,
                                     std::size_t limit) const {
  std::vector<int> out;
  std::stringstream ss(list);
  std::string part;
  const auto number = [&](const std::string& t) {
    long long v = -1;
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || error != std::errc() || end != t.data() + t.size() || v < 0 || v > INT_MAX)
      fail(where + " lists '" + excerpt(t) + "', not an id");
    return static_cast<int>(v);
  };
  while (std::getline(ss, part, ',')) {
    if (part.empty()) continue;
    const std::size_t dash = part.find('-');
    const int a = number(part.substr(0, dash));
    const int b = dash == std::string::npos ? a : number(part.substr(dash + 1));
    if (b < a) fail(where + " has the range " + excerpt(part) + ", which runs backwards");
    if (static_cast<std::size_t>(b - a) + out.size() >= limit)
      fail(where + " lists more ids than the file has entities");
    for (int i = a; i <= b; ++i) out.push_back(i);
  }
  return out;
}

const std::array<int, 2>& Reader::edge(int id) const {
  const auto it = edges_.find(id);
  if (it == edges_.end()) fail("edge " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

const Face& Reader::face(int id) const {
  const auto it = faces_.find(id);
  if (it == faces_.end()) fail("face " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

const Point& Reader::vertexPoint(int id) const {
  const auto it = vertices_.find(id);
  if (it == vertices_.end()) fail("vertex " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

std::int64_t Reader::vertexNode(int id) const {
  const auto it = vertexNode_.find(id);
  if (it == vertexNode_.end()) fail("vertex " + std::to_string(id) + " is referred to but missing");
  return it->second;
}

std::vector<double> Reader::numbers(const std::string& text, const std::string& where) const {
  std::vector<double> v;
  const char* p = text.c_str();
  char* end = nullptr;
  for (;;) {
    const double x = std::strtod(p, &end);
    if (end == p) break;
    if (!std::isfinite(x)) fail(where + " holds a number that is not finite");
    v.push_back(x);
    p = end;
  }
  while (*p != '\0' && std::isspace(static_cast<unsigned char>(*p)) != 0) ++p;
  if (*p != '\0') fail("unexpected text in " + where);
  return v;
}

template <class Record>
std::vector<Record> Reader::records(const XmlElement& e, bool tagged) const {
  if (tagged && !e.has("COMPRESSED"))
    fail("<" + e.name + "> is not compressed like the rest of the file");
  if (tagged && e.attribute("COMPRESSED") != nektar::kCompressed)
    fail("unsupported compression '" + excerpt(e.attribute("COMPRESSED")) + "'");
  std::string bytes;
  try {
    bytes = nektar::decode(e.text);
  } catch (const IoError& error) {
    fail("<" + e.name + ">: " + error.what());
  }
  std::vector<Record> out(bytes.size() / sizeof(Record));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(Record));
  return out;
}

void Reader::readVertices(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    for (const auto& v : records<nektar::Vertex>(section)) {
      const int id = toId(v.id, "a vertex record's id");
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        fail("vertex " + std::to_string(id) + " has a coordinate that is not finite");
      vertices_[id] = {v.x, v.y, v.z};
    }
    return;
  }
  for (const XmlElement* v : section.childrenNamed("V")) {
    const int id = idAttribute(*v);
    const std::vector<double> x = numbers(v->text, "vertex " + std::to_string(id));
    if (x.size() != 3) fail("vertex " + std::to_string(id) + " needs 3 coordinates");
    vertices_[id] = {x[0], x[1], x[2]};
  }
}

void Reader::readEdges(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    for (const auto& e : records<nektar::Edge>(section))
      edges_[toId(e.id, "an edge record's id")] = {toId(e.v0, "an edge's vertex"),
                                                   toId(e.v1, "an edge's vertex")};
    return;
  }
  for (const XmlElement* e : section.childrenNamed("E")) {
    const int id = idAttribute(*e);
    const std::vector<int> v = ids(e->text, 2, "edge " + std::to_string(id));
    edges_[id] = {v[0], v[1]};
  }
}

void Reader::readFaces(const XmlElement& section) {
  for (const auto& child : section.children) {
    const bool tri = child->name == "T";
    if (!tri && child->name != "Q") fail("unknown face <" + child->name + ">");
    const auto add = [&](int id, std::vector<int> edgeIds) {
      Face f;
      f.triangle = tri;
      f.edges = std::move(edgeIds);
      faces_[id] = f;
    };
    if (child->has("COMPRESSED")) {
      const auto take = [&](const auto& records) {
        for (const auto& r : records) {
          std::vector<int> edgeIds;
          for (const std::int64_t e : r.ids) edgeIds.push_back(toId(e, "a face's edge"));
          add(toId(r.id, "a face record's id"), edgeIds);
        }
      };
      if (tri)
        take(records<nektar::Entity<3>>(*child));
      else
        take(records<nektar::Entity<4>>(*child));
    } else {
      const int id = idAttribute(*child);
      add(id, ids(child->text, tri ? 3 : 4, "face " + std::to_string(id)));
    }
  }
}

void Reader::readElements(const XmlElement& section) {
  for (const auto& child : section.children) {
    const std::string& tag = child->name;
    CellType type;
    int n = 0;
    if (dim_ == 3 && tag == "A") {
      type = CellType::Tetrahedron;
      n = 4;
    } else if (dim_ == 3 && tag == "R") {
      type = CellType::Prism;
      n = 5;
    } else if (dim_ == 3 && tag == "H") {
      type = CellType::Hexahedron;
      n = 6;
    } else if (dim_ == 2 && tag == "T") {
      type = CellType::Triangle;
      n = 3;
    } else if (dim_ == 2 && tag == "Q") {
      type = CellType::Quadrilateral;
      n = 4;
    } else
      fail("element <" + tag + "> is not supported in a " + std::to_string(dim_) + "D mesh");
    const auto add = [&](int id, const std::vector<int>& ids) {
      elements_.push_back({type, id, ids});
    };
    if (child->has("COMPRESSED")) {
      const auto take = [&](const auto& recs) {
        for (const auto& r : recs) {
          std::vector<int> parts;
          for (const std::int64_t id : r.ids)
            parts.push_back(toId(id, "an element's face or edge"));
          add(toId(r.id, "an element record's id"), parts);
        }
      };
      if (n == 3) take(records<nektar::Entity<3>>(*child));
      if (n == 4) take(records<nektar::Entity<4>>(*child));
      if (n == 5) take(records<nektar::Entity<5>>(*child));
      if (n == 6) take(records<nektar::Entity<6>>(*child));
    } else {
      const int id = idAttribute(*child);
      add(id, ids(child->text, static_cast<std::size_t>(n), "element " + std::to_string(id)));
    }
  }
  std::sort(elements_.begin(), elements_.end(),
            [](const Element& a, const Element& b) { return a.id < b.id; });
}

void Reader::readCurves(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    const XmlElement* data = section.child("DATAPOINTS");
    if (data == nullptr) fail("compressed CURVED without DATAPOINTS");
    const XmlElement* indexElement = data->child("INDEX");
    const XmlElement* pointsElement = data->child("POINTS");
    if (indexElement == nullptr || pointsElement == nullptr) fail("DATAPOINTS is incomplete");
    const auto index = records<std::int64_t>(*indexElement, false);
    const auto points = records<nektar::Vertex>(*pointsElement, false);
    for (const char* kind : {"E", "F"}) {
      const XmlElement* info = section.child(kind);
      if (info == nullptr) continue;
      for (const auto& c : records<nektar::CurvedInfo>(*info, false)) {
        const int entity = toId(c.entityId, "a curve's entity");
        const std::string what =
            std::string(kind[0] == 'E' ? "edge " : "face ") + std::to_string(entity) + "'s curve";
        if (c.numPoints < 0 || c.offset < 0 ||
            static_cast<std::uint64_t>(c.offset) + static_cast<std::uint64_t>(c.numPoints) >
                index.size())
          fail(what + " points outside DATAPOINTS/INDEX");
        Curve curve;
        curve.type = pointsTypeName(c.pointsType);
        for (std::int64_t k = 0; k < c.numPoints; ++k) {
          const std::int64_t at = index[static_cast<std::size_t>(c.offset + k)];
          if (at < 0 || static_cast<std::uint64_t>(at) >= points.size())
            fail(what + " points outside DATAPOINTS/POINTS");
          const auto& v = points[static_cast<std::size_t>(at)];
          if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
            fail(what + " has a coordinate that is not finite");
          curve.points.emplace_back(v.x, v.y, v.z);
        }
        (kind[0] == 'E' ? edgeCurves_ : faceCurves_)[entity] = curve;
      }
    }
    return;
  }
  for (const auto& child : section.children) {
    const bool edge = child->name == "E";
    if (!edge && child->name != "F") fail("unknown curve <" + child->name + ">");
    const int entity = idAttribute(*child, edge ? "EDGEID" : "FACEID");
    const std::string what =
        std::string(edge ? "edge " : "face ") + std::to_string(entity) + "'s curve";
    const std::vector<double> v = numbers(child->text, what);
    if (v.size() % 3 != 0) fail(what + " has a point with fewer than 3 coordinates");
    Curve c;
    c.type = child->attribute("TYPE", nektar::kEvenlySpaced);
    for (std::size_t k = 0; k + 2 < v.size(); k += 3)
      c.points.emplace_back(v[k], v[k + 1], v[k + 2]);
    (edge ? edgeCurves_ : faceCurves_)[entity] = c;
  }
}

void Reader::readComposites(const XmlElement& section) {
  for (const XmlElement* c : section.childrenNamed("C")) {
    std::stringstream ss(c->text);
    std::string token;
    while (ss >> token) {
      const std::size_t open = token.find('['), close = token.rfind(']');
      const std::string where = "composite " + excerpt(c->attribute("ID"));
      if (open == std::string::npos || close == std::string::npos || open == 0 || close < open)
        fail(where + " is malformed");
      const std::size_t entities =
          vertices_.size() + edges_.size() + faces_.size() + elements_.size();
      composites_.push_back(
          {c->attribute("NAME"), token[0],
           parseIdList(token.substr(open + 1, close - open - 1), where, entities + 1)});
    }
  }
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

std::vector<int> Reader::elementVertices(const Element& e) const {
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
    const auto curve = edgeCurves_.find(edgeId);
    const Point a = vertexPoint(ev[0]), b = vertexPoint(ev[1]);
    for (int k = 1; k < order_; ++k)
      nodes.push_back(newNode(
          curve != edgeCurves_.end() ? curve->second.points.at(k) : Point(a + (b - a) * k / order_),
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
std::vector<std::int64_t> Reader::interiorNodes(bool triangle, const Curve* curve) {
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
  const nektar::ExpansionInteriorMap& map = nektar::interiorFromBoundary(type, order_);
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

// The curves' points at our node positions (equispaced), from the points types Nektar++ and
// NekMesh write: edges and quadrilaterals at Gauss-Lobatto-Legendre points are resampled
// through their interpolating polynomial (exact: the same polynomial). A triangle's
// electrostatic or Fekete interior points (NekMesh writes NodalTriElec) have no closed form
// here: its interior is rebuilt from its edges (fill) and the file's interior points are not
// used. Other points types are refused.
void Reader::toEvenlySpaced() {
  const std::size_t n = static_cast<std::size_t>(order_) + 1;
  std::vector<double> even(n);
  for (std::size_t k = 0; k < n; ++k) even[k] = double(k) / order_;
  const std::vector<double> lobatto = lobattoPoints(order_ + 1);
  // The polynomial through `v` at the GLL points, at the equispaced points.
  const auto resample = [&](const std::vector<Point>& v) {
    std::vector<Point> out;
    out.reserve(n);
    for (const double t : even) out.push_back(interpolate(lobatto, v, t));
    return out;
  };
  for (auto& [id, c] : edgeCurves_) {
    if (c.type == nektar::kEvenlySpaced) continue;
    if (c.type != nektar::kGaussLobattoLegendre)
      fail("edge " + std::to_string(id) + "'s curve has " + c.type + ", not supported");
    c.points = resample(c.points);
    c.type = nektar::kEvenlySpaced;
  }
  std::vector<int> dropped;
  for (auto& [id, c] : faceCurves_) {
    if (c.type == nektar::kEvenlySpaced || c.type == nektar::kTriEvenlySpaced) continue;
    const bool quad = c.points.size() == n * n;
    if (quad && c.type == nektar::kGaussLobattoLegendre) {
      std::vector<Point> rows;  // the first direction resampled, row by row
      rows.reserve(n * n);
      for (std::size_t i = 0; i < n; ++i) {
        const auto from = c.points.begin() + static_cast<std::ptrdiff_t>(i * n);
        const std::vector<Point> row =
            resample(std::vector<Point>(from, from + static_cast<std::ptrdiff_t>(n)));
        rows.insert(rows.end(), row.begin(), row.end());
      }
      std::vector<Point> out(n * n);
      for (std::size_t j = 0; j < n; ++j) {
        std::vector<Point> column;
        column.reserve(n);
        for (std::size_t i = 0; i < n; ++i) column.push_back(rows[i * n + j]);
        const std::vector<Point> resampled = resample(column);
        for (std::size_t i = 0; i < n; ++i) out[i * n + j] = resampled[i];
      }
      c.points = std::move(out);
      c.type = nektar::kEvenlySpaced;
    } else if (!quad && c.type == "NodalTriElec" && nektar::hasTriElecPoints(order_)) {
      const Eigen::MatrixXd& m = nektar::triElecToEvenlySpaced(order_);
      if (c.points.size() != static_cast<std::size_t>(m.rows()))
        fail("face " + std::to_string(id) + "'s curve has " + std::to_string(c.points.size()) +
             " points; a triangle of order " + std::to_string(order_) + " needs " +
             std::to_string(m.rows()));
      std::vector<Point> out(c.points.size(), Point::Zero());
      for (std::size_t r = 0; r < out.size(); ++r)
        for (std::size_t k = 0; k < out.size(); ++k)
          out[r] += m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) * c.points[k];
      c.points = std::move(out);
      c.type = nektar::kTriEvenlySpaced;
    } else if (!quad && (c.type == "NodalTriElec" || c.type == "NodalTriFekete")) {
      dropped.push_back(id);
    } else {
      fail("face " + std::to_string(id) + "'s curve has " + c.type + ", not supported");
    }
  }
  for (const int id : dropped) faceCurves_.erase(id);
}

Mesh Reader::read() {
  const auto root = parseXml(readFileBytes(path_, "mesh file"), path_);
  if (root->name != "NEKTAR") fail("the root element is <" + root->name + ">, not <NEKTAR>");
  const XmlElement* geometry = root->child("GEOMETRY");
  if (geometry == nullptr) fail("no <GEOMETRY>");
  const std::string dim = geometry->attribute("DIM", "3");
  if (dim != "2" && dim != "3") fail("DIM must be 2 or 3, not '" + excerpt(dim) + "'");
  dim_ = dim == "2" ? 2 : 3;
  const auto section = [&](const char* name, bool required) {
    const XmlElement* s = geometry->child(name);
    if (s == nullptr && required) fail(std::string("no <") + name + ">");
    return s;
  };
  readVertices(*section("VERTEX", true));
  readEdges(*section("EDGE", true));
  if (dim_ == 3) readFaces(*section("FACE", true));
  readElements(*section("ELEMENT", true));
  if (const XmlElement* c = section("CURVED", false)) readCurves(*c);
  if (const XmlElement* c = section("COMPOSITE", false)) readComposites(*c);
  if (elements_.empty()) fail("no elements");
  for (const auto& [id, ev] : edges_) edgeOf_[std::minmax(ev[0], ev[1])] = id;
  for (auto& [id, f] : faces_) f.vertices = loopVertices(f.edges);
  if (!edgeCurves_.empty())
    order_ = static_cast<int>(edgeCurves_.begin()->second.points.size()) - 1;
  for (const auto& [id, c] : edgeCurves_)
    if (static_cast<int>(c.points.size()) != order_ + 1)
      fail("curved edges have different numbers of points");
  if (order_ < 1 || order_ > kMaxOrder) fail("curves of order " + std::to_string(order_));
  toEvenlySpaced();
  mesh_.dim = dim_;
  mesh_.order = order_;
  for (const auto& [id, p] : vertices_) vertexNode_[id] = newNode(p, true);

  // Entities from the composites' names ("Solid3", "Face12", "Edge5").
  std::map<std::pair<char, int>, int> entityOf;
  std::map<int, int> boundaryEntity;  // face (3D) or edge (2D) id -> entity
  for (const Composite& c : composites_) {
    int index = 0;
    for (const char* prefix : {"Solid", "Face", "Edge"})
      if (c.name.rfind(prefix, 0) == 0) index = std::atoi(c.name.c_str() + std::strlen(prefix));
    for (const int id : c.ids) {
      if (c.letter == 'F' || (c.letter == 'E' && dim_ == 2))
        boundaryEntity[id] = index;
      else
        entityOf[{c.letter, id}] = index;
    }
  }

  // Faces' interior nodes (from their curves, or to be filled), and the faces' Gmsh-ordered
  // nodes keyed by their vertex set, for the elements to look up.
  std::map<std::vector<int>, std::vector<std::int64_t>> faceByVertices;
  std::map<int, std::vector<std::int64_t>> faceGmshNodes;
  for (const auto& [id, f] : faces_) {
    const auto curve = faceCurves_.find(id);
    const std::vector<std::int64_t> interior =
        interiorNodes(f.triangle, curve != faceCurves_.end() ? &curve->second : nullptr);
    std::vector<std::int64_t> nodes = polygonNodes(f.vertices, interior);
    fill(f.triangle ? CellType::Triangle : CellType::Quadrilateral, nodes);
    std::vector<int> key = f.vertices;
    std::sort(key.begin(), key.end());
    faceByVertices[key] = nodes;
    faceGmshNodes[id] = nodes;
  }

  std::map<CellType, ElementBlock> blocks;
  for (const Element& e : elements_) {
    const std::vector<int> v = elementVertices(e);
    ElementBlock& block = blocks[e.type];
    block.type = e.type;
    block.order = order_;
    block.entity.push_back(entityOf[{nektar::letter(e.type), e.id}]);
    std::vector<std::int64_t> nodes;
    if (dim_ == 2) {
      const auto curve = faceCurves_.find(e.id);
      nodes = polygonNodes(v, interiorNodes(e.type == CellType::Triangle,
                                            curve != faceCurves_.end() ? &curve->second : nullptr));
    } else {
      nodes = volumeNodes(e.type, v, faceByVertices);
    }
    fill(e.type, nodes);
    block.nodes.insert(block.nodes.end(), nodes.begin(), nodes.end());
    for (const std::int64_t n : nodes) mesh_.nodeCadIndex[n] = block.entity.back();
  }
  for (auto& [type, block] : blocks) mesh_.blocks.push_back(std::move(block));

  // Boundary cells: the faces (3D) or edges (2D) of the named boundary composites.
  ElementBlock tris, quads, lines;
  tris.type = CellType::Triangle;
  quads.type = CellType::Quadrilateral;
  lines.type = CellType::Line;
  for (ElementBlock* b : {&tris, &quads, &lines}) b->order = order_;
  for (const auto& [id, entity] : boundaryEntity) {
    std::vector<std::int64_t> nodes;
    ElementBlock* block = &lines;
    if (dim_ == 3) {
      const auto it = faceGmshNodes.find(id);
      if (it == faceGmshNodes.end()) fail("composite refers to missing face " + std::to_string(id));
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
  for (const bool k : known_)
    if (!k) fail("some nodes could not be placed");
  // A 2D mesh off one plane (a manifold in SPACE 3) is a surface mesh; one in a plane other than
  // z = const is measured along that plane's normal; one in such a plane keeps the
  // counter-clockwise convention around +z that Nektar++'s 2D elements follow.
  if (dim_ == 2)
    if (const auto normal = planeOfCells(mesh_, 1e-5))  // (as for MSH files)
      if (std::abs((*normal)[2]) < 1.0 - 1e-12) mesh_.planeNormal = *normal;
  mesh_.checkConsistency();
  return std::move(mesh_);
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
