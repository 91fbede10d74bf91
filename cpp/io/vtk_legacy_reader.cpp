// The legacy VTK format (.vtk): a header of five lines (version, title, ASCII or BINARY, DATASET
// UNSTRUCTURED_GRID), then keyword sections. Binary values are big-endian.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <utility>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/foreign_mesh.hpp"
#include "io/text_cursor.hpp"
#include "io/vtk_cells.hpp"
#include "io/vtk_readers.hpp"

namespace homesh {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The byte size of a legacy data type, and whether it is a floating-point type; 0 if unknown.
std::pair<std::size_t, bool> typeSize(const std::string& type) {
  static const std::pair<const char*, std::pair<std::size_t, bool>> kTypes[] = {
      {"bit", {0, false}},           {"char", {1, false}},           {"unsigned_char", {1, false}},
      {"short", {2, false}},         {"unsigned_short", {2, false}}, {"int", {4, false}},
      {"unsigned_int", {4, false}},  {"long", {8, false}},           {"unsigned_long", {8, false}},
      {"vtkidtype", {8, false}},     {"vtktypeint8", {1, false}},    {"vtktypeuint8", {1, false}},
      {"vtktypeint16", {2, false}},  {"vtktypeuint16", {2, false}},  {"vtktypeint32", {4, false}},
      {"vtktypeuint32", {4, false}}, {"vtktypeint64", {8, false}},   {"vtktypeuint64", {8, false}},
      {"float", {4, true}},          {"double", {8, true}},          {"vtktypefloat32", {4, true}},
      {"vtktypefloat64", {8, true}}};
  const std::string t = lower(type);
  for (const auto& [name, size] : kTypes)
    if (t == name) return size;
  return {0, false};
}

class Cursor : public TextCursor {
 public:
  Cursor(std::string data, std::string path)
      : TextCursor(std::move(data)), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid VTK file: line " + std::to_string(line_) + ": " +
                  what);
  }
  long long integer(const std::string& what) {
    const std::string w = word();
    char* end = nullptr;
    const long long v = std::strtoll(w.c_str(), &end, 10);
    if (w.empty() || end != w.c_str() + w.size())
      fail(what + " expected, found " + quoteExcerpt(w));
    return v;
  }
  // A count of values that must still fit in the file, `bytes` (at least) each.
  std::size_t count(const std::string& what, std::size_t bytes) {
    const long long v = integer(what);
    if (v < 0 || static_cast<unsigned long long>(v) > (data_.size() - pos_) / bytes)
      fail(what + " " + std::to_string(v) + " is more than the rest of the file holds");
    return static_cast<std::size_t>(v);
  }
  // `n` values of a legacy type, as doubles (exact for integers below 2^53).
  std::vector<double> values(std::size_t n, const std::string& type, bool binary,
                             const std::string& what) {
    const auto [size, real] = typeSize(type);
    if (size == 0) fail(what + ": data type " + quoteExcerpt(type) + " is not supported");
    std::vector<double> out(n);
    if (!binary) {
      for (std::size_t i = 0; i < n; ++i) {
        const std::string w = word();
        char* end = nullptr;
        out[i] = real ? std::strtod(w.c_str(), &end)
                      : static_cast<double>(std::strtoll(w.c_str(), &end, 10));
        if (w.empty() || end != w.c_str() + w.size())
          fail(what + ": value " + std::to_string(i + 1) + " of " + std::to_string(n) + " is " +
               (w.empty() ? std::string("missing (the file ends)") : quoteExcerpt(w)));
      }
      return out;
    }
    if (n > (data_.size() - pos_) / size)
      fail(what + ": the file ends inside its " + std::to_string(n) + " binary values");
    const std::string t = lower(type);
    const bool isUnsigned =
        t.find("unsigned") != std::string::npos || t.find("uint") != std::string::npos;
    for (std::size_t i = 0; i < n; ++i) {
      unsigned char b[8];
      for (std::size_t k = 0; k < size; ++k)  // big-endian
        b[k] = static_cast<unsigned char>(data_[pos_ + i * size + size - 1 - k]);
      out[i] = decode(b, size, real, isUnsigned);
    }
    pos_ += n * size;
    return out;
  }

 private:
  // One value from its bytes in the machine's (little-endian) order.
  static double decode(const unsigned char* b, std::size_t size, bool real, bool isUnsigned) {
    if (real) {
      if (size == 4) {
        float f = 0;
        std::memcpy(&f, b, 4);
        return f;
      }
      double d = 0;
      std::memcpy(&d, b, 8);
      return d;
    }
    switch (size) {
      case 1:
        return isUnsigned ? static_cast<double>(b[0])
                          : static_cast<double>(static_cast<std::int8_t>(b[0]));
      case 2: {
        std::uint16_t u = 0;
        std::memcpy(&u, b, 2);
        return isUnsigned ? u : static_cast<double>(static_cast<std::int16_t>(u));
      }
      case 4: {
        std::uint32_t u = 0;
        std::memcpy(&u, b, 4);
        return isUnsigned ? u : static_cast<double>(static_cast<std::int32_t>(u));
      }
      default: {
        std::uint64_t u = 0;
        std::memcpy(&u, b, 8);
        return isUnsigned ? static_cast<double>(u)
                          : static_cast<double>(static_cast<std::int64_t>(u));
      }
    }
  }

  std::string path_;
};

std::vector<std::int64_t> integers(const std::vector<double>& v, Cursor& c,
                                   const std::string& what) {
  std::vector<std::int64_t> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(std::abs(v[i]) < 9.0e15) || v[i] != std::floor(v[i]))
      c.fail(what + ": value " + std::to_string(i + 1) + " is not an integer");
    out[i] = static_cast<std::int64_t>(v[i]);
  }
  return out;
}

// Skips a METADATA block (its keyword read): lines up to an empty one.
void skipMetadata(Cursor& c) {
  c.restOfLine();
  while (!c.atEnd()) {
    std::string line = c.restOfLine();
    if (line.find_first_not_of(" \t") == std::string::npos) return;
  }
}

// Skips "FIELD name n" and its n arrays ("name components tuples type", values).
void skipField(Cursor& c, bool binary) {
  c.word();  // its name
  const std::size_t arrays = c.count("a FIELD's array count", 1);
  for (std::size_t a = 0; a < arrays; ++a) {
    const std::string name = c.word();
    const std::size_t components = c.count("FIELD array " + name + "'s component count", 1);
    const std::size_t tuples = c.count("FIELD array " + name + "'s tuple count", 1);
    const std::string type = c.word();
    if (components != 0 && tuples > SIZE_MAX / components)
      c.fail("FIELD array " + name + " is too large");
    if (binary) c.endOfLine();
    c.values(components * tuples, type, binary, "FIELD array " + name);
    if (lower(c.peekWord()) == "metadata") {  // VTK 9 writes one after an array
      c.word();
      skipMetadata(c);
    }
  }
}

}  // namespace

Mesh readLegacyVtk(const std::string& path, std::vector<std::string>* notes) {
  Cursor c(readFileBytes(path, "mesh file"), path);
  const std::string version = c.restOfLine();
  const std::string prefix = "# vtk DataFile Version ";
  if (version.compare(0, prefix.size(), prefix) != 0)
    c.fail("it does not start with '" + prefix + "...' (found " + quoteExcerpt(version) + ")");
  const double versionNumber = std::strtod(version.c_str() + prefix.size(), nullptr);
  c.restOfLine();  // the title
  const std::string format = lower(c.word());
  if (format != "ascii" && format != "binary")
    c.fail("ASCII or BINARY expected, found " + quoteExcerpt(format));
  const bool binary = format == "binary";
  if (lower(c.word()) != "dataset") c.fail("DATASET expected");
  const std::string dataset = c.word();
  if (lower(dataset) != "unstructured_grid")
    c.fail("DATASET " + quoteExcerpt(dataset) + ": HOMesh reads UNSTRUCTURED_GRID only");

  ForeignMesh raw;
  std::vector<std::int64_t> connectivity, offsets, types;
  bool points = false, cells = false, cellTypes = false;
  while (!c.atEnd()) {
    const std::string keyword = lower(c.word());
    if (keyword == "points") {
      const std::size_t n = c.count("the number of POINTS", binary ? 3 : 6);
      const std::string type = c.word();
      if (binary) c.endOfLine();
      raw.xyz = c.values(3 * n, type, binary, "POINTS");
      for (std::size_t i = 0; i < raw.xyz.size(); ++i)
        if (!std::isfinite(raw.xyz[i]))
          c.fail("POINTS: point " + std::to_string(i / 3) + " has a coordinate that is not finite");
      points = true;
    } else if (keyword == "cells" && versionNumber >= 5.0) {
      const std::size_t n = c.count("the number of CELLS offsets", 1);
      const std::size_t size = c.count("the CELLS connectivity size", 1);
      if (lower(c.word()) != "offsets") c.fail("OFFSETS expected after CELLS");
      std::string type = c.word();
      if (binary) c.endOfLine();
      offsets = integers(c.values(n, type, binary, "OFFSETS"), c, "OFFSETS");
      if (lower(c.word()) != "connectivity") c.fail("CONNECTIVITY expected after OFFSETS");
      type = c.word();
      if (binary) c.endOfLine();
      connectivity = integers(c.values(size, type, binary, "CONNECTIVITY"), c, "CONNECTIVITY");
      if (offsets.empty() || offsets.front() != 0)
        c.fail("OFFSETS must start at 0 (one more offset than cells)");
      offsets.erase(offsets.begin());
      cells = true;
    } else if (keyword == "cells") {
      const std::size_t n = c.count("the number of CELLS", 1);
      const std::size_t size = c.count("the size of the CELLS list", binary ? 4 : 2);
      if (binary) c.endOfLine();
      const std::vector<std::int64_t> list =
          integers(c.values(size, "int", binary, "CELLS"), c, "CELLS");
      std::size_t at = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (at >= list.size() || list[at] < 0 ||
            static_cast<std::size_t>(list[at]) > list.size() - at - 1)
          c.fail("CELLS: cell " + std::to_string(k) + " runs past the list's " +
                 std::to_string(size) + " values");
        const auto count = static_cast<std::size_t>(list[at]);
        connectivity.insert(connectivity.end(), list.begin() + static_cast<std::ptrdiff_t>(at + 1),
                            list.begin() + static_cast<std::ptrdiff_t>(at + 1 + count));
        offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
        at += count + 1;
      }
      if (at != list.size())
        c.fail("CELLS: the " + std::to_string(n) + " cells use " + std::to_string(at) + " of its " +
               std::to_string(size) + " values");
      cells = true;
    } else if (keyword == "cell_types") {
      const std::size_t n = c.count("the number of CELL_TYPES", binary ? 4 : 2);
      if (binary) c.endOfLine();
      types = integers(c.values(n, "int", binary, "CELL_TYPES"), c, "CELL_TYPES");
      cellTypes = true;
    } else if (keyword == "metadata") {
      skipMetadata(c);
    } else if (keyword == "field") {
      skipField(c, binary);
    } else if (keyword == "point_data" || keyword == "cell_data") {
      break;  // data on the grid: not read
    } else {
      c.fail("unexpected " + quoteExcerpt(keyword) +
             " (POINTS, CELLS, CELL_TYPES, POINT_DATA or CELL_DATA expected)");
    }
  }
  if (!points || !cells || !cellTypes)
    c.fail(std::string("the file ends without ") + (!points  ? "POINTS"
                                                    : !cells ? "CELLS"
                                                             : "CELL_TYPES"));
  addVtkCells(raw, connectivity, offsets, types, versionNumber < 5.1, 0, "'" + path + "'");
  return assembleForeignMesh(std::move(raw), path, notes);
}

}  // namespace homesh
