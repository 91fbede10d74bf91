#include "io/nektar_sections.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "core/error.hpp"
#include "core/format.hpp"
#include "io/nektar_format.hpp"

namespace homesh::nektar {
namespace {

using Point = Eigen::Vector3d;

// The name of a Nektar++ 5.x PointsType value as a compressed CURVED record stores it.
std::string pointsTypeName(std::int64_t value) {
  switch (value) {
    case kEvenlySpacedId:
      return kEvenlySpaced;
    case kTriEvenlySpacedId:
      return kTriEvenlySpaced;
    case kGaussLobattoLegendreId:
      return kGaussLobattoLegendre;
    case kTriElecId:
      return "NodalTriElec";
    case kTriFeketeId:
      return "NodalTriFekete";
    default:
      return "points type " + std::to_string(value);
  }
}

// Reads the sections of one file into tables; every failure names the file (failGeometry).
class SectionReader {
 public:
  explicit SectionReader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const { failGeometry(path_, what); }

  GeometrySections read(const XmlElement& root);

 private:
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

  std::string path_;
  GeometrySections g_;
};

GeometrySections SectionReader::read(const XmlElement& root) {
  if (root.name != "NEKTAR") fail("the root element is <" + root.name + ">, not <NEKTAR>");
  const XmlElement* geometry = root.child("GEOMETRY");
  if (geometry == nullptr) fail("no <GEOMETRY>");
  const std::string dim = geometry->attribute("DIM", "3");
  if (dim != "2" && dim != "3") fail("DIM must be 2 or 3, not '" + excerpt(dim) + "'");
  g_.dim = dim == "2" ? 2 : 3;
  const auto section = [&](const char* name, bool required) {
    const XmlElement* s = geometry->child(name);
    if (s == nullptr && required) fail(std::string("no <") + name + ">");
    return s;
  };
  readVertices(*section("VERTEX", true));
  readEdges(*section("EDGE", true));
  if (g_.dim == 3) readFaces(*section("FACE", true));
  readElements(*section("ELEMENT", true));
  if (const XmlElement* c = section("CURVED", false)) readCurves(*c);
  if (const XmlElement* c = section("COMPOSITE", false)) readComposites(*c);
  if (g_.elements.empty()) fail("no elements");
  return std::move(g_);
}

int SectionReader::toId(long long value, const std::string& what) const {
  if (value < 0 || value > INT_MAX) fail(what + " is not a valid id: " + std::to_string(value));
  return static_cast<int>(value);
}

int SectionReader::idAttribute(const XmlElement& e, const char* key) const {
  const std::string text = e.attribute(key);
  long long v = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || v < 0 ||
      v > INT_MAX)
    fail("<" + e.name + "> has " + key + "=\"" + excerpt(text) + "\", not an id");
  return static_cast<int>(v);
}

std::vector<int> SectionReader::ids(const std::string& text, std::size_t count,
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
std::vector<int> SectionReader::parseIdList(const std::string& list, const std::string& where,
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

std::vector<double> SectionReader::numbers(const std::string& text,
                                           const std::string& where) const {
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
std::vector<Record> SectionReader::records(const XmlElement& e, bool tagged) const {
  if (tagged && !e.has("COMPRESSED"))
    fail("<" + e.name + "> is not compressed like the rest of the file");
  if (tagged && e.attribute("COMPRESSED") != kCompressed)
    fail("unsupported compression '" + excerpt(e.attribute("COMPRESSED")) + "'");
  std::string bytes;
  try {
    bytes = decode(e.text);
  } catch (const IoError& error) {
    fail("<" + e.name + ">: " + error.what());
  }
  std::vector<Record> out(bytes.size() / sizeof(Record));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(Record));
  return out;
}

void SectionReader::readVertices(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    for (const auto& v : records<Vertex>(section)) {
      const int id = toId(v.id, "a vertex record's id");
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        fail("vertex " + std::to_string(id) + " has a coordinate that is not finite");
      g_.vertices[id] = {v.x, v.y, v.z};
    }
    return;
  }
  for (const XmlElement* v : section.childrenNamed("V")) {
    const int id = idAttribute(*v);
    const std::vector<double> x = numbers(v->text, "vertex " + std::to_string(id));
    if (x.size() != 3) fail("vertex " + std::to_string(id) + " needs 3 coordinates");
    g_.vertices[id] = {x[0], x[1], x[2]};
  }
}

void SectionReader::readEdges(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    for (const auto& e : records<Edge>(section))
      g_.edges[toId(e.id, "an edge record's id")] = {toId(e.v0, "an edge's vertex"),
                                                     toId(e.v1, "an edge's vertex")};
    return;
  }
  for (const XmlElement* e : section.childrenNamed("E")) {
    const int id = idAttribute(*e);
    const std::vector<int> v = ids(e->text, 2, "edge " + std::to_string(id));
    g_.edges[id] = {v[0], v[1]};
  }
}

void SectionReader::readFaces(const XmlElement& section) {
  for (const auto& child : section.children) {
    const bool tri = child->name == "T";
    if (!tri && child->name != "Q") fail("unknown face <" + child->name + ">");
    const auto add = [&](int id, std::vector<int> edgeIds) {
      FaceRecord f;
      f.triangle = tri;
      f.edges = std::move(edgeIds);
      g_.faces[id] = f;
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
        take(records<Entity<3>>(*child));
      else
        take(records<Entity<4>>(*child));
    } else {
      const int id = idAttribute(*child);
      add(id, ids(child->text, tri ? 3 : 4, "face " + std::to_string(id)));
    }
  }
}

void SectionReader::readElements(const XmlElement& section) {
  for (const auto& child : section.children) {
    const std::string& tag = child->name;
    CellType type;
    int n = 0;
    if (g_.dim == 3 && tag == "A") {
      type = CellType::Tetrahedron;
      n = 4;
    } else if (g_.dim == 3 && tag == "R") {
      type = CellType::Prism;
      n = 5;
    } else if (g_.dim == 3 && tag == "P") {
      type = CellType::Pyramid;
      n = 5;
    } else if (g_.dim == 3 && tag == "H") {
      type = CellType::Hexahedron;
      n = 6;
    } else if (g_.dim == 2 && tag == "T") {
      type = CellType::Triangle;
      n = 3;
    } else if (g_.dim == 2 && tag == "Q") {
      type = CellType::Quadrilateral;
      n = 4;
    } else
      fail("element <" + tag + "> is not supported in a " + std::to_string(g_.dim) + "D mesh");
    const auto add = [&](int id, const std::vector<int>& ids) {
      g_.elements.push_back({type, id, ids});
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
      if (n == 3) take(records<Entity<3>>(*child));
      if (n == 4) take(records<Entity<4>>(*child));
      if (n == 5) take(records<Entity<5>>(*child));
      if (n == 6) take(records<Entity<6>>(*child));
    } else {
      const int id = idAttribute(*child);
      add(id, ids(child->text, static_cast<std::size_t>(n), "element " + std::to_string(id)));
    }
  }
  std::sort(g_.elements.begin(), g_.elements.end(),
            [](const ElementRecord& a, const ElementRecord& b) { return a.id < b.id; });
}

void SectionReader::readCurves(const XmlElement& section) {
  if (section.has("COMPRESSED")) {
    const XmlElement* data = section.child("DATAPOINTS");
    if (data == nullptr) fail("compressed CURVED without DATAPOINTS");
    const XmlElement* indexElement = data->child("INDEX");
    const XmlElement* pointsElement = data->child("POINTS");
    if (indexElement == nullptr || pointsElement == nullptr) fail("DATAPOINTS is incomplete");
    const auto index = records<std::int64_t>(*indexElement, false);
    const auto points = records<Vertex>(*pointsElement, false);
    for (const char* kind : {"E", "F"}) {
      const XmlElement* info = section.child(kind);
      if (info == nullptr) continue;
      for (const auto& c : records<CurvedInfo>(*info, false)) {
        const int entity = toId(c.entityId, "a curve's entity");
        const std::string what =
            std::string(kind[0] == 'E' ? "edge " : "face ") + std::to_string(entity) + "'s curve";
        if (c.numPoints < 0 || c.offset < 0 ||
            static_cast<std::uint64_t>(c.offset) + static_cast<std::uint64_t>(c.numPoints) >
                index.size())
          fail(what + " points outside DATAPOINTS/INDEX");
        CurveRecord curve;
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
        (kind[0] == 'E' ? g_.edgeCurves : g_.faceCurves)[entity] = curve;
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
    CurveRecord c;
    c.type = child->attribute("TYPE", kEvenlySpaced);
    for (std::size_t k = 0; k + 2 < v.size(); k += 3)
      c.points.emplace_back(v[k], v[k + 1], v[k + 2]);
    (edge ? g_.edgeCurves : g_.faceCurves)[entity] = c;
  }
}

void SectionReader::readComposites(const XmlElement& section) {
  for (const XmlElement* c : section.childrenNamed("C")) {
    std::stringstream ss(c->text);
    std::string token;
    while (ss >> token) {
      const std::size_t open = token.find('['), close = token.rfind(']');
      const std::string where = "composite " + excerpt(c->attribute("ID"));
      if (open == std::string::npos || close == std::string::npos || open == 0 || close < open)
        fail(where + " is malformed");
      const std::size_t entities =
          g_.vertices.size() + g_.edges.size() + g_.faces.size() + g_.elements.size();
      g_.composites.push_back(
          {c->attribute("NAME"), token[0],
           parseIdList(token.substr(open + 1, close - open - 1), where, entities + 1)});
    }
  }
}

}  // namespace

void failGeometry(const std::string& path, const std::string& what) {
  throw IoError("'" + path + "' is not a valid Nektar++ geometry: " + what);
}

GeometrySections readGeometrySections(const XmlElement& root, const std::string& path) {
  return SectionReader(path).read(root);
}

}  // namespace homesh::nektar
