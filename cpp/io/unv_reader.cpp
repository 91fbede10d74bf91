#include "io/unv_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/foreign_mesh.hpp"

namespace homesh {
namespace {

// What an FE descriptor id says about the cell.
enum class Family { Beam, Triangle, Quadrilateral, Tetrahedron, Wedge, Brick, Mass, Unknown };

// The FE descriptor ids of I-DEAS (universal file format, dataset 2412) HOMesh knows.
constexpr std::pair<int, Family> kDescriptors[] = {
    {11, Family::Beam},          {21, Family::Beam},          {22, Family::Beam},
    {23, Family::Beam},          {24, Family::Beam},          {41, Family::Triangle},
    {42, Family::Triangle},      {43, Family::Triangle},      {51, Family::Triangle},
    {52, Family::Triangle},      {53, Family::Triangle},      {61, Family::Triangle},
    {62, Family::Triangle},      {63, Family::Triangle},      {72, Family::Triangle},
    {73, Family::Triangle},      {74, Family::Triangle},      {81, Family::Triangle},
    {82, Family::Triangle},      {91, Family::Triangle},      {92, Family::Triangle},
    {93, Family::Triangle},      {44, Family::Quadrilateral}, {45, Family::Quadrilateral},
    {46, Family::Quadrilateral}, {54, Family::Quadrilateral}, {55, Family::Quadrilateral},
    {56, Family::Quadrilateral}, {64, Family::Quadrilateral}, {65, Family::Quadrilateral},
    {66, Family::Quadrilateral}, {71, Family::Quadrilateral}, {75, Family::Quadrilateral},
    {76, Family::Quadrilateral}, {84, Family::Quadrilateral}, {85, Family::Quadrilateral},
    {94, Family::Quadrilateral}, {95, Family::Quadrilateral}, {96, Family::Quadrilateral},
    {111, Family::Tetrahedron},  {118, Family::Tetrahedron},  {112, Family::Wedge},
    {113, Family::Wedge},        {114, Family::Wedge},        {115, Family::Brick},
    {116, Family::Brick},        {117, Family::Brick},        {161, Family::Mass}};

Family familyOf(long long descriptor) {
  for (const auto& [id, family] : kDescriptors)
    if (id == descriptor) return family;
  return Family::Unknown;
}

const char* familyName(Family f) {
  switch (f) {
    case Family::Beam:
      return "beam";
    case Family::Triangle:
      return "triangle";
    case Family::Quadrilateral:
      return "quadrilateral";
    case Family::Tetrahedron:
      return "tetrahedron";
    case Family::Wedge:
      return "wedge";
    case Family::Brick:
      return "brick";
    default:
      return "cell";
  }
}

// A cell HOMesh reads: its shape and order, and gmsh[k] = file[fromFile[k]].
struct UnvShape {
  CellType type;
  int order;
  std::vector<int> fromFile;
};

std::optional<UnvShape> shapeOf(Family family, long long nodes) {
  switch (family) {
    case Family::Beam:
      if (nodes == 2) return UnvShape{CellType::Line, 1, {0, 1}};
      if (nodes == 3) return UnvShape{CellType::Line, 2, {0, 2, 1}};
      break;
    case Family::Triangle:
      if (nodes == 3) return UnvShape{CellType::Triangle, 1, {0, 1, 2}};
      if (nodes == 6) return UnvShape{CellType::Triangle, 2, {0, 2, 4, 1, 3, 5}};
      break;
    case Family::Quadrilateral:
      if (nodes == 4) return UnvShape{CellType::Quadrilateral, 1, {0, 1, 2, 3}};
      break;
    case Family::Tetrahedron:
      if (nodes == 4) return UnvShape{CellType::Tetrahedron, 1, {0, 1, 2, 3}};
      // File: c0 m01 c1 m12 c2 m20 m03 m13 m23 c3. Gmsh: c0 c1 c2 c3 m01 m12 m20 m03 m23 m13.
      if (nodes == 10) return UnvShape{CellType::Tetrahedron, 2, {0, 2, 4, 9, 1, 3, 5, 6, 8, 7}};
      break;
    case Family::Wedge:
      if (nodes == 6) return UnvShape{CellType::Prism, 1, {0, 1, 2, 3, 4, 5}};
      break;
    case Family::Brick:
      if (nodes == 8) return UnvShape{CellType::Hexahedron, 1, {0, 1, 2, 3, 4, 5, 6, 7}};
      break;
    default:
      break;
  }
  return std::nullopt;
}

bool isDelimiter(std::string_view line) {
  const auto first = line.find_first_not_of(" \t");
  if (first == std::string_view::npos) return false;
  const auto last = line.find_last_not_of(" \t");
  return line.substr(first, last - first + 1) == "-1";
}

std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

class UnvFile {
 public:
  UnvFile(std::string text, std::string path) : text_(std::move(text)), path_(std::move(path)) {
    std::size_t start = 0;
    while (start < text_.size()) {
      std::size_t end = text_.find('\n', start);
      if (end == std::string::npos) end = text_.size();
      std::string_view line(text_.data() + start, end - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      lines_.push_back(line);
      start = end + 1;
    }
  }

  std::size_t size() const { return lines_.size(); }
  std::string_view line(std::size_t i) const { return lines_[i]; }

  // Line i is numbered i + 1 in messages.
  [[noreturn]] void fail(std::size_t i, const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid UNV file: line " + std::to_string(i + 1) + ": " +
                  what);
  }
  [[noreturn]] void failFile(const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid UNV file: " + what);
  }

  // Exactly `count` integers on line i (count 0: at least one, all read).
  std::vector<long long> integers(std::size_t i, std::size_t count, const char* what) const {
    const std::vector<std::string_view> t = tokens(lines_[i]);
    if ((count == 0 && t.empty()) || (count != 0 && t.size() != count))
      fail(i, std::string(what) + ": " +
                  (count == 0 ? std::string("integers") : std::to_string(count) + " integers") +
                  " expected, found " + quoteExcerpt(lines_[i]));
    std::vector<long long> out;
    for (const std::string_view s : t) {
      long long v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc() || end != s.data() + s.size())
        fail(i, std::string(what) + ": " + quoteExcerpt(s) + " is not an integer");
      out.push_back(v);
    }
    return out;
  }

  // Three finite coordinates on line i (Fortran's D exponents accepted).
  void coordinates(std::size_t i, long long label, double out[3]) const {
    const std::vector<std::string_view> t = tokens(lines_[i]);
    if (t.size() != 3)
      fail(i, "node " + std::to_string(label) + ": 3 coordinates expected, found " +
                  quoteExcerpt(lines_[i]));
    for (int k = 0; k < 3; ++k) {
      std::string s(t[static_cast<std::size_t>(k)]);
      std::replace(s.begin(), s.end(), 'D', 'E');
      std::replace(s.begin(), s.end(), 'd', 'e');
      char* end = nullptr;
      out[k] = std::strtod(s.c_str(), &end);
      if (end != s.c_str() + s.size())
        fail(i, "node " + std::to_string(label) + ": " + quoteExcerpt(t[k]) + " is not a number");
      if (!std::isfinite(out[k]))
        fail(i, "node " + std::to_string(label) + " has a coordinate that is not finite");
    }
  }

 private:
  std::string text_;
  std::string path_;
  std::vector<std::string_view> lines_;
};

struct RawCell {
  UnvShape shape;
  long long label;
  std::size_t line;
  std::vector<long long> nodes;  // labels, in the file's order
};

struct UnvData {
  std::vector<double> xyz;
  std::vector<std::int64_t> labels;
  std::unordered_map<long long, std::int64_t> index;  // node label -> id
  std::vector<RawCell> cells;
  bool nodes = false, elements = false;
};

// Dataset 2411, lines [begin, end): per node a record line (label, export and displacement
// coordinate systems, colour) and a line of three coordinates.
void readNodes(const UnvFile& f, std::size_t begin, std::size_t end, UnvData& d) {
  d.nodes = true;
  for (std::size_t i = begin; i < end; i += 2) {
    const long long label =
        f.integers(i, 4, "node record (label, 2 coordinate systems, colour)")[0];
    if (i + 1 >= end) f.fail(i, "node " + std::to_string(label) + " has no coordinate line");
    double x[3];
    f.coordinates(i + 1, label, x);
    const auto id = static_cast<std::int64_t>(d.labels.size());
    if (!d.index.emplace(label, id).second)
      f.fail(i, "node " + std::to_string(label) + " is defined twice");
    d.labels.push_back(label);
    d.xyz.insert(d.xyz.end(), x, x + 3);
  }
}

// Dataset 2412: per element a record line (label, FE descriptor, physical and material property
// tables, colour, node count), for beams a line (orientation node, cross sections), then the
// node labels, 8 a line.
void readElements(const UnvFile& f, std::size_t begin, std::size_t end, UnvData& d) {
  d.elements = true;
  std::size_t i = begin;
  while (i < end) {
    const std::vector<long long> r =
        f.integers(i, 6, "element record (label, FE descriptor, 2 tables, colour, node count)");
    const long long label = r[0], descriptor = r[1], count = r[5];
    const std::size_t record = i;
    const std::string name = "element " + std::to_string(label);
    const Family family = familyOf(descriptor);
    if (family == Family::Unknown)
      f.fail(i, name + " has FE descriptor " + std::to_string(descriptor) +
                    ", which HOMesh does not know (it reads rods, beams, triangles, "
                    "quadrilaterals, tetrahedra, wedges, bricks and lumped masses)");
    const std::optional<UnvShape> shape = shapeOf(family, count);
    if (!shape && family != Family::Mass) {
      const bool incomplete = (family == Family::Quadrilateral && (count == 8 || count == 12)) ||
                              (family == Family::Triangle && count == 9) ||
                              (family == Family::Wedge && (count == 15 || count == 24)) ||
                              (family == Family::Brick && (count == 20 || count == 32));
      f.fail(i, name + " (FE descriptor " + std::to_string(descriptor) + ", a " +
                    familyName(family) + ") has " + std::to_string(count) + " nodes: " +
                    (incomplete ? "serendipity and cubic cells are not supported; HOMesh reads "
                                  "complete Lagrange cells (lines, triangles, tetrahedra of "
                                  "order 1 or 2; linear quadrilaterals, wedges and bricks)"
                                : "not a node count of this cell"));
    }
    if (family == Family::Mass && count != 1)
      f.fail(i, name + " (a lumped mass) has " + std::to_string(count) + " nodes, 1 expected");
    ++i;
    if (family == Family::Beam) {
      if (i >= end) f.fail(record, name + " (a beam) has no orientation line");
      f.integers(i, 3, "beam orientation (node, 2 cross sections)");
      ++i;
    }
    RawCell cell{shape.value_or(UnvShape{CellType::Point, 1, {0}}), label, record, {}};
    while (static_cast<long long>(cell.nodes.size()) < count) {
      if (i >= end)
        f.fail(record, name + " lists " + std::to_string(cell.nodes.size()) + " of its " +
                           std::to_string(count) + " nodes before the dataset ends");
      const std::size_t want = std::min<std::size_t>(8, count - cell.nodes.size());
      const std::vector<long long> ids = f.integers(i, want, "node labels (8 a line)");
      cell.nodes.insert(cell.nodes.end(), ids.begin(), ids.end());
      ++i;
    }
    if (family != Family::Mass) d.cells.push_back(std::move(cell));
  }
}

}  // namespace

Mesh readUnv(const std::string& path, std::vector<std::string>* notes) {
  const UnvFile f(readFileBytes(path, "mesh file"), path);
  UnvData d;
  std::size_t i = 0;
  while (i < f.size()) {
    if (tokens(f.line(i)).empty()) {
      ++i;
      continue;
    }
    if (!isDelimiter(f.line(i)))
      f.fail(i, "'-1' expected (the start of a dataset), found " + quoteExcerpt(f.line(i)));
    const std::size_t header = i + 1;
    if (header >= f.size()) f.fail(i, "the file ends after a dataset's opening '-1'");
    const std::vector<std::string_view> t = tokens(f.line(header));
    long long dataset = 0;
    const auto [ptr, ec] = t.empty()
                               ? std::from_chars_result{nullptr, std::errc::invalid_argument}
                               : std::from_chars(t[0].data(), t[0].data() + t[0].size(), dataset);
    if (ec != std::errc())
      f.fail(header, "a dataset number expected, found " + quoteExcerpt(f.line(header)));
    if (ptr != t[0].data() + t[0].size())
      f.fail(header, "dataset " + std::to_string(dataset) +
                         " is binary, which HOMesh does not read (write the file as ASCII)");
    std::size_t end = header + 1;
    while (end < f.size() && !isDelimiter(f.line(end))) ++end;
    if (end >= f.size())
      f.fail(i, "dataset " + std::to_string(dataset) +
                    " is not closed by '-1' (the file is truncated)");
    if (dataset == 2411) readNodes(f, header + 1, end, d);
    if (dataset == 2412) readElements(f, header + 1, end, d);
    i = end + 1;
  }
  if (!d.nodes) f.failFile("it has no nodes (dataset 2411)");
  if (!d.elements) f.failFile("it has no elements (dataset 2412)");

  ForeignMesh raw;
  raw.xyz = std::move(d.xyz);
  raw.labels = std::move(d.labels);
  std::vector<std::int64_t> nodes;
  for (const RawCell& c : d.cells) {
    nodes.clear();
    for (const int k : c.shape.fromFile) {
      const long long label = c.nodes[static_cast<std::size_t>(k)];
      const auto found = d.index.find(label);
      if (found == d.index.end())
        f.fail(c.line, "element " + std::to_string(c.label) + " refers to node " +
                           std::to_string(label) + ", which dataset 2411 does not define");
      nodes.push_back(found->second);
    }
    raw.addCell(c.shape.type, c.shape.order, nodes.data(), 0);
  }
  return assembleForeignMesh(std::move(raw), path, notes);
}

}  // namespace homesh
