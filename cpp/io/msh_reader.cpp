#include "io/msh_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/gmsh_element_types.hpp"
#include "io/text_cursor.hpp"

namespace homesh {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A cursor over the whole file, for ASCII tokens and binary values alike.
class Cursor : public TextCursor {
 public:
  Cursor(std::string data, std::string path)
      : TextCursor(std::move(data)), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid MSH file: " + what + " (byte " +
                  std::to_string(pos_) + ")");
  }
  double real() {
    skipSpace();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(data_.c_str() + pos_, &end);
    if (end == data_.c_str() + pos_) fail("a number was expected");
    pos_ = static_cast<std::size_t>(end - data_.c_str());
    return v;
  }
  long long integer() {
    skipSpace();
    char* end = nullptr;
    const long long v = std::strtoll(data_.c_str() + pos_, &end, 10);
    if (end == data_.c_str() + pos_) fail("an integer was expected");
    pos_ = static_cast<std::size_t>(end - data_.c_str());
    return v;
  }
  template <class T>
  T binary() {
    if (pos_ + sizeof(T) > data_.size()) fail("the file ends inside binary data");
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  void expect(const std::string& keyword) {
    const std::string w = word();
    if (w != keyword) fail("'" + keyword + "' expected, found '" + w.substr(0, 40) + "'");
  }
  // After a block of binary data: exactly one newline, then the keyword. Skipping white space
  // here would let a block that is short by a byte or two pass, its last value made of the
  // newline.
  void expectAfterBinary(const std::string& keyword) {
    if (pos_ < data_.size() && data_[pos_] == '\n' &&
        data_.compare(pos_ + 1, keyword.size(), keyword) == 0) {
      pos_ += 1 + keyword.size();
      return;
    }
    fail("the binary data does not end where '" + keyword +
         "' should follow (a size or count disagrees with the data)");
  }
  // A node coordinate: a finite number.
  double coordinate(bool binary) {
    const double v = binary ? this->binary<double>() : real();
    if (!std::isfinite(v)) fail("a node coordinate is not a finite number");
    return v;
  }
  // Skips to the line after "$EndX" for an unknown section "$X".
  void skipSection(const std::string& name) {
    const std::string end = "$End" + name.substr(1);
    const std::size_t at = data_.find(end, pos_);
    if (at == std::string::npos) fail("section " + name + " is not closed");
    pos_ = at + end.size();
  }

 private:
  std::string path_;
};

struct RawElement {
  int gmshType;
  int dim, entity;
  std::size_t tag;
  std::vector<std::size_t> nodes;  // node tags
};

struct RawMesh {
  std::vector<std::size_t> nodeTags;
  std::vector<double> xyz;
  std::vector<int> nodeDim, nodeEntity;  // from MSH 4.1 node blocks; -1 if unknown
  std::vector<RawElement> elements;
};

void readNodes22(Cursor& c, bool binary, RawMesh& raw) {
  const long long n = c.integer();
  if (binary) c.endOfLine();
  for (long long i = 0; i < n; ++i) {
    std::size_t tag = 0;
    double x[3];
    if (binary) {
      tag = static_cast<std::size_t>(c.binary<int>());
    } else {
      tag = static_cast<std::size_t>(c.integer());
    }
    for (double& v : x) v = c.coordinate(binary);
    raw.nodeTags.push_back(tag);
    raw.xyz.insert(raw.xyz.end(), x, x + 3);
    raw.nodeDim.push_back(-1);
    raw.nodeEntity.push_back(-1);
  }
  binary ? c.expectAfterBinary("$EndNodes") : c.expect("$EndNodes");
}

int nodesOfType(Cursor& c, int type) {
  const auto cell = cellFromGmshType(type);
  if (!cell) {
    if (type == 15) return 1;  // a point
    c.fail("element type " + std::to_string(type) + " is not supported");
  }
  return cellNumNodes(cell->first, cell->second);
}

void readElements22(Cursor& c, bool binary, RawMesh& raw) {
  const long long n = c.integer();
  if (binary) {
    c.endOfLine();
    long long done = 0;
    while (done < n) {
      const int type = c.binary<int>(), count = c.binary<int>(), tags = c.binary<int>();
      const int nn = nodesOfType(c, type);
      for (int e = 0; e < count; ++e) {
        const auto number = static_cast<std::size_t>(c.binary<int>());
        int entity = 0;
        for (int t = 0; t < tags; ++t) {
          const int v = c.binary<int>();
          if (t == 1) entity = v;
        }
        RawElement el{type, 0, entity, number, {}};
        for (int k = 0; k < nn; ++k) el.nodes.push_back(static_cast<std::size_t>(c.binary<int>()));
        raw.elements.push_back(std::move(el));
      }
      done += count;
    }
  } else {
    for (long long i = 0; i < n; ++i) {
      const auto number = static_cast<std::size_t>(c.integer());
      const int type = static_cast<int>(c.integer());
      const int tags = static_cast<int>(c.integer());
      int entity = 0;
      for (int t = 0; t < tags; ++t) {
        const int v = static_cast<int>(c.integer());
        if (t == 1) entity = v;  // tags: physical, elementary, ...
      }
      const int nn = nodesOfType(c, type);
      RawElement el{type, 0, entity, number, {}};
      for (int k = 0; k < nn; ++k) el.nodes.push_back(static_cast<std::size_t>(c.integer()));
      raw.elements.push_back(std::move(el));
    }
  }
  binary ? c.expectAfterBinary("$EndElements") : c.expect("$EndElements");
}

// MSH 4.1 sizes: ints for dimensions, tags of entities and types; size_t for counts and tags of
// nodes and elements.
std::size_t size41(Cursor& c, bool binary) {
  return binary ? c.binary<std::uint64_t>() : static_cast<std::size_t>(c.integer());
}
int int41(Cursor& c, bool binary) {
  return binary ? c.binary<std::int32_t>() : static_cast<int>(c.integer());
}

void readNodes41(Cursor& c, bool binary, RawMesh& raw) {
  if (binary) c.endOfLine();
  const std::size_t blocks = size41(c, binary), total = size41(c, binary);
  size41(c, binary);  // min tag
  size41(c, binary);  // max tag
  for (std::size_t b = 0; b < blocks; ++b) {
    const int dim = int41(c, binary), entity = int41(c, binary), parametric = int41(c, binary);
    const std::size_t count = size41(c, binary);
    for (std::size_t i = 0; i < count; ++i) raw.nodeTags.push_back(size41(c, binary));
    for (std::size_t i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) raw.xyz.push_back(c.coordinate(binary));
      for (int k = 0; parametric != 0 && k < dim; ++k) {  // parametric coordinates: unused
        if (binary)
          c.binary<double>();
        else
          c.real();
      }
    }
    raw.nodeDim.insert(raw.nodeDim.end(), count, dim);
    raw.nodeEntity.insert(raw.nodeEntity.end(), count, entity);
  }
  if (raw.nodeTags.size() != total) c.fail("$Nodes announces " + std::to_string(total) + " nodes");
  binary ? c.expectAfterBinary("$EndNodes") : c.expect("$EndNodes");
}

void readElements41(Cursor& c, bool binary, RawMesh& raw) {
  if (binary) c.endOfLine();
  const std::size_t blocks = size41(c, binary);
  size41(c, binary);  // number of elements
  size41(c, binary);  // min tag
  size41(c, binary);  // max tag
  for (std::size_t b = 0; b < blocks; ++b) {
    const int dim = int41(c, binary), entity = int41(c, binary), type = int41(c, binary);
    const std::size_t count = size41(c, binary);
    const int nn = nodesOfType(c, type);
    for (std::size_t e = 0; e < count; ++e) {
      const std::size_t tag = size41(c, binary);
      RawElement el{type, dim, entity, tag, {}};
      for (int k = 0; k < nn; ++k) el.nodes.push_back(size41(c, binary));
      raw.elements.push_back(std::move(el));
    }
  }
  binary ? c.expectAfterBinary("$EndElements") : c.expect("$EndElements");
}

Mesh assemble(RawMesh& raw, const std::string& path) {
  Mesh mesh;
  // Nodes and elements in the order of their tags, whatever the file's grouping.
  std::vector<std::size_t> byTag(raw.nodeTags.size());
  for (std::size_t i = 0; i < byTag.size(); ++i) byTag[i] = i;
  std::sort(byTag.begin(), byTag.end(),
            [&](std::size_t a, std::size_t b) { return raw.nodeTags[a] < raw.nodeTags[b]; });
  std::unordered_map<std::size_t, std::int64_t> index;
  index.reserve(raw.nodeTags.size());
  for (std::size_t k = 0; k < byTag.size(); ++k)
    if (!index.emplace(raw.nodeTags[byTag[k]], static_cast<std::int64_t>(k)).second)
      throw IoError("'" + path + "': node " + std::to_string(raw.nodeTags[byTag[k]]) +
                    " appears twice");
  std::stable_sort(raw.elements.begin(), raw.elements.end(),
                   [](const RawElement& a, const RawElement& b) { return a.tag < b.tag; });
  // Blocks by (type, order), in the order first met; points are skipped.
  int dim = 0, order = 0;
  std::map<std::pair<CellType, int>, std::size_t> blockOf;
  for (const RawElement& el : raw.elements) {
    const auto cell = cellFromGmshType(el.gmshType);
    if (!cell) continue;
    dim = std::max(dim, cellDimension(cell->first));
    if (order != 0 && cell->second != order)
      throw IoError("'" + path + "' mixes elements of orders " + std::to_string(order) + " and " +
                    std::to_string(cell->second) + ", which HOMesh does not support");
    order = cell->second;
    auto [it, added] = blockOf.try_emplace(*cell, mesh.blocks.size());
    if (added) {
      ElementBlock block;
      block.type = cell->first;
      block.order = cell->second;
      mesh.blocks.push_back(block);
    }
    ElementBlock& block = mesh.blocks[it->second];
    for (const std::size_t tag : el.nodes) {
      const auto found = index.find(tag);
      if (found == index.end())
        throw IoError("'" + path + "': an element refers to node " + std::to_string(tag) +
                      ", which is not in $Nodes");
      block.nodes.push_back(found->second);
    }
    block.entity.push_back(el.entity);
  }
  if (dim < 2) throw IoError("'" + path + "' contains no 2D or 3D elements");
  // Cells of the mesh dimension first, then the boundary by decreasing dimension.
  std::stable_sort(mesh.blocks.begin(), mesh.blocks.end(),
                   [](const ElementBlock& a, const ElementBlock& b) {
                     return cellDimension(a.type) > cellDimension(b.type);
                   });
  mesh.dim = dim;
  mesh.order = order;
  const std::size_t n = raw.nodeTags.size();
  mesh.xyz.resize(3 * n);
  mesh.nodeCadDim.assign(n, static_cast<std::uint8_t>(dim));
  mesh.nodeCadIndex.assign(n, 0);
  mesh.nodeCadParam.assign(2 * n, kNaN);
  bool classified = false;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = byTag[k];
    for (int c = 0; c < 3; ++c) mesh.xyz[3 * k + c] = raw.xyz[3 * i + c];
    if (raw.nodeDim[i] >= 0) {
      mesh.nodeCadDim[k] = static_cast<std::uint8_t>(raw.nodeDim[i]);
      mesh.nodeCadIndex[k] = raw.nodeEntity[i];
      classified = true;
    }
  }
  if (!classified) {  // MSH 2.2: the lowest-dimensional element holding the node decides
    for (const ElementBlock& b : mesh.blocks) {
      const int d = cellDimension(b.type);
      for (std::size_t e = 0; e < b.count(); ++e)
        for (int k = 0; k < b.nodesPerElement(); ++k) {
          const std::int64_t id = b.element(e)[k];
          if (d < mesh.nodeCadDim[id] || (d == dim && mesh.nodeCadIndex[id] == 0)) {
            mesh.nodeCadDim[id] = static_cast<std::uint8_t>(d);
            mesh.nodeCadIndex[id] = b.entity[e];
          }
        }
    }
  }
  if (dim == 2) {  // the plane most elements agree with; none (a surface mesh) off it
    // (1e-5 of the mesh's size, as for FreeCAD's files: other tools write 7 digits, and a shell
    // flatter than that is measured along its plane as well as along its cells' own normals.)
    if (const auto normal = planeOfCells(mesh, 1e-5)) mesh.planeNormal = *normal;
  }
  mesh.checkConsistency();
  return mesh;
}

}  // namespace

Mesh readMsh(const std::string& path) {
  Cursor c(readFileBytes(path, "mesh file"), path);
  if (c.word() != "$MeshFormat") c.fail("it does not start with $MeshFormat");
  const std::string version = c.word();
  const long long fileType = c.integer();
  const long long dataSize = c.integer();
  const bool binary = fileType == 1;
  // MSH 2.0 and 2.1 (Netgen writes "2.000000") have 2.2's ASCII sections.
  const bool legacy =
      version == "2.2" ||
      (!binary && (version.rfind("2.0", 0) == 0 || version.rfind("2.1", 0) == 0 || version == "2"));
  if (!legacy && version != "4.1")
    c.fail("version " + version + " is not supported (use 2.2 or 4.1; ASCII 2.0 and 2.1 too)");
  if (dataSize != 8) c.fail("data size " + std::to_string(dataSize) + " is not supported");
  if (binary) {
    c.endOfLine();
    if (c.binary<int>() != 1) c.fail("binary data is not little-endian");
    c.expectAfterBinary("$EndMeshFormat");
  } else {
    c.expect("$EndMeshFormat");
  }
  RawMesh raw;
  bool nodes = false, elements = false;
  while (!c.atEnd()) {
    const std::string section = c.word();
    if (section == "$Nodes") {
      legacy ? readNodes22(c, binary, raw) : readNodes41(c, binary, raw);
      nodes = true;
    } else if (section == "$Elements") {
      legacy ? readElements22(c, binary, raw) : readElements41(c, binary, raw);
      elements = true;
    } else if (!section.empty() && section[0] == '$') {
      c.skipSection(section);
    } else {
      c.fail("unexpected '" + section.substr(0, 40) + "' between sections");
    }
  }
  if (!nodes || !elements) c.fail("$Nodes or $Elements is missing");
  return assemble(raw, path);
}

}  // namespace homesh
