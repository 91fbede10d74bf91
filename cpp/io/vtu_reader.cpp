// The XML unstructured grid (.vtu). A binary data array is a header of UInt32 or UInt64 values
// (uncompressed: the byte count; compressed: the number of blocks, the block size, the size of
// the last block, then each block's compressed size), followed by the data. In base64 form the
// header and the data are encoded either as one stream or as two (VTK's compressed arrays,
// meshio): a header encoded alone ends in '=' where its size is not a multiple of 3 bytes, and
// where it is, both forms decode alike.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <string_view>
#include <utility>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/base64.hpp"
#include "io/foreign_mesh.hpp"
#include "io/vtk_cells.hpp"
#include "io/vtk_readers.hpp"
#include "io/xml_document.hpp"

namespace homesh {
namespace {

struct Encoding {
  std::size_t headerSize = 4;  // UInt32 or UInt64
  bool bigEndian = false;
  bool compressed = false;  // zlib
};

// One unsigned value of `size` bytes in the file's byte order.
std::uint64_t readUnsigned(const char* p, std::size_t size, bool bigEndian) {
  std::uint64_t v = 0;
  for (std::size_t k = 0; k < size; ++k) {
    const auto byte = static_cast<unsigned char>(p[bigEndian ? k : size - 1 - k]);
    v = (v << 8) | byte;
  }
  return v;
}

std::size_t base64Chars(std::size_t bytes) {
  return 4 * ((bytes + 2) / 3);
}

class VtuFile {
 public:
  VtuFile(std::string path, Encoding encoding) : path_(std::move(path)), enc_(encoding) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw IoError("'" + path_ + "' is not a valid VTU file: " + what);
  }

  // The values' bytes of a binary block (header and data) starting at bytes[0].
  std::string rawBlock(std::string_view bytes, const std::string& what) const {
    const std::size_t hs = enc_.headerSize;
    if (bytes.size() < hs) fail(what + ": the data ends inside its header");
    if (!enc_.compressed) {
      const std::uint64_t n = readUnsigned(bytes.data(), hs, enc_.bigEndian);
      if (n > bytes.size() - hs)
        fail(what + ": its header announces " + std::to_string(n) + " bytes, the data holds " +
             std::to_string(bytes.size() - hs));
      return std::string(bytes.substr(hs, n));
    }
    if (bytes.size() < 3 * hs) fail(what + ": the data ends inside its compression header");
    const std::uint64_t blocks = readUnsigned(bytes.data(), hs, enc_.bigEndian);
    const std::uint64_t blockSize = readUnsigned(bytes.data() + hs, hs, enc_.bigEndian);
    const std::uint64_t lastSize = readUnsigned(bytes.data() + 2 * hs, hs, enc_.bigEndian);
    if (blocks > (bytes.size() - 3 * hs) / hs)
      fail(what + ": its compression header announces " + std::to_string(blocks) +
           " blocks, more than the data can hold");
    if (blocks > 0 && blockSize > 0 && blocks - 1 > kMaxInflatedBytes / blockSize)
      fail(what + ": it would inflate to more than " + std::to_string(kMaxInflatedBytes >> 20) +
           " MiB");
    std::size_t at = (3 + blocks) * hs;
    std::string out;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::uint64_t size = readUnsigned(bytes.data() + (3 + b) * hs, hs, enc_.bigEndian);
      if (size > bytes.size() - at)
        fail(what + ": compressed block " + std::to_string(b + 1) + " runs past the data");
      const std::uint64_t expect = b + 1 == blocks && lastSize != 0 ? lastSize : blockSize;
      std::string block;
      try {
        block = zlibDecompress(std::string(bytes.substr(at, size)), expect);
      } catch (const IoError& e) {
        fail(what + ": compressed block " + std::to_string(b + 1) + ": " + e.what());
      }
      if (block.size() != expect)
        fail(what + ": compressed block " + std::to_string(b + 1) + " inflates to " +
             std::to_string(block.size()) + " bytes, its header says " + std::to_string(expect));
      out += block;
      at += size;
    }
    return out;
  }

  // The values' bytes of a base64 binary block whose text (white space removed) starts at b64[0]
  // and may run on past it (appended data).
  std::string base64Block(std::string_view b64, const std::string& what) const {
    const std::size_t hs = enc_.headerSize;
    const std::size_t prefix = (enc_.compressed ? 3 : 1) * hs;
    const std::string first = decode(b64, base64Chars(prefix), what);
    if (first.size() < prefix) fail(what + ": the data ends inside its header");
    std::size_t headerBytes = hs;
    if (enc_.compressed) {
      const std::uint64_t blocks = readUnsigned(first.data(), hs, enc_.bigEndian);
      if (blocks > b64.size() / hs) fail(what + ": its compression header is corrupt");
      headerBytes = (3 + blocks) * hs;
    }
    const std::size_t headerChars = base64Chars(headerBytes);
    const bool separate =
        headerBytes % 3 != 0 && b64.size() >= headerChars && b64[headerChars - 1] == '=';
    const std::string header = decode(b64, headerChars, what).substr(0, headerBytes);
    if (header.size() < headerBytes) fail(what + ": the data ends inside its header");
    std::uint64_t dataBytes = 0;
    if (enc_.compressed) {
      for (std::size_t b = 3; b < headerBytes / hs; ++b)
        dataBytes += readUnsigned(header.data() + b * hs, hs, enc_.bigEndian);
    } else {
      dataBytes = readUnsigned(header.data(), hs, enc_.bigEndian);
    }
    if (dataBytes > b64.size()) fail(what + ": its header announces more data than there is");
    std::string data;
    if (separate) {
      data = decode(b64.substr(headerChars), base64Chars(dataBytes), what);
    } else {
      data = decode(b64, base64Chars(headerBytes + dataBytes), what);
      data.erase(0, std::min(data.size(), headerBytes));
    }
    if (data.size() < dataBytes)
      fail(what + ": the data is shorter than its header announces (" +
           std::to_string(data.size()) + " of " + std::to_string(dataBytes) + " bytes)");
    data.resize(dataBytes);
    return rawBlock(header + data, what);
  }

 private:
  std::string decode(std::string_view b64, std::size_t chars, const std::string& what) const {
    try {
      return base64Decode(std::string(b64.substr(0, chars)));
    } catch (const IoError& e) {
      fail(what + ": " + e.what());
    }
  }

  std::string path_;
  Encoding enc_;
};

std::string withoutSpace(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text)
    if (std::isspace(static_cast<unsigned char>(c)) == 0) out += c;
  return out;
}

// The byte size of a VTK XML data type and whether it is floating point; 0 if unknown.
std::pair<std::size_t, bool> typeSize(const std::string& type) {
  static const std::pair<const char*, std::pair<std::size_t, bool>> kTypes[] = {
      {"Int8", {1, false}},   {"UInt8", {1, false}},  {"Int16", {2, false}}, {"UInt16", {2, false}},
      {"Int32", {4, false}},  {"UInt32", {4, false}}, {"Int64", {8, false}}, {"UInt64", {8, false}},
      {"Float32", {4, true}}, {"Float64", {8, true}}};
  for (const auto& [name, size] : kTypes)
    if (type == name) return size;
  return {0, false};
}

// Values of a binary array, as doubles (exact for integers below 2^53).
std::vector<double> binaryValues(const std::string& bytes, const std::string& type,
                                 bool bigEndian) {
  const auto [size, real] = typeSize(type);
  std::vector<double> out(bytes.size() / size);
  const bool isUnsigned = type[0] == 'U';
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint64_t u = readUnsigned(bytes.data() + i * size, size, bigEndian);
    if (real && size == 4) {
      float f = 0;
      const auto v = static_cast<std::uint32_t>(u);
      std::memcpy(&f, &v, 4);
      out[i] = f;
    } else if (real) {
      double d = 0;
      std::memcpy(&d, &u, 8);
      out[i] = d;
    } else if (isUnsigned || size == 8) {
      out[i] =
          isUnsigned ? static_cast<double>(u) : static_cast<double>(static_cast<std::int64_t>(u));
    } else {  // sign-extend
      const std::uint64_t sign = std::uint64_t{1} << (8 * size - 1);
      out[i] = static_cast<double>(static_cast<std::int64_t>((u ^ sign) - sign));
    }
  }
  return out;
}

class Piece {
 public:
  Piece(const VtuFile& file, std::string_view appended, bool appendedRaw, bool bigEndian,
        std::size_t index)
      : file_(file),
        appended_(appended),
        appendedRaw_(appendedRaw),
        bigEndian_(bigEndian),
        name_("Piece " + std::to_string(index + 1)) {}

  // The values of a DataArray, `components` per tuple.
  std::vector<double> values(const XmlElement& array, const std::string& what) const {
    const std::string type = array.attribute("type");
    const auto [size, real] = typeSize(type);
    const std::string label = name_ + ", DataArray " + what;
    if (size == 0) file_.fail(label + ": type " + quoteExcerpt(type) + " is not supported");
    const std::string format = array.attribute("format", "ascii");
    if (format == "ascii") {
      std::vector<double> out;
      std::istringstream in(array.text);
      std::string w;
      while (in >> w) {
        char* end = nullptr;
        const double v = real ? std::strtod(w.c_str(), &end)
                              : static_cast<double>(std::strtoll(w.c_str(), &end, 10));
        if (end != w.c_str() + w.size())
          file_.fail(label + ": value " + std::to_string(out.size() + 1) + " is " +
                     quoteExcerpt(w));
        out.push_back(v);
      }
      return out;
    }
    std::string bytes;
    if (format == "binary") {
      bytes = file_.base64Block(withoutSpace(array.text), label);
    } else if (format == "appended") {
      const std::string offsetText = array.attribute("offset");
      char* end = nullptr;
      const unsigned long long offset = std::strtoull(offsetText.c_str(), &end, 10);
      if (offsetText.empty() || end != offsetText.c_str() + offsetText.size() ||
          offset >= appended_.size())
        file_.fail(label + ": offset " + quoteExcerpt(offsetText) +
                   " is not inside the appended data (" + std::to_string(appended_.size()) +
                   (appendedRaw_ ? " bytes)" : " characters)"));
      bytes = appendedRaw_ ? file_.rawBlock(appended_.substr(offset), label)
                           : file_.base64Block(appended_.substr(offset), label);
    } else {
      file_.fail(label + ": format " + quoteExcerpt(format) + " is not ascii, binary or appended");
    }
    if (bytes.size() % size != 0)
      file_.fail(label + ": " + std::to_string(bytes.size()) + " bytes are not a whole number of " +
                 type + " values");
    return binaryValues(bytes, type, bigEndian_);
  }

  std::vector<std::int64_t> integers(const XmlElement& array, const std::string& what) const {
    const std::vector<double> v = values(array, what);
    std::vector<std::int64_t> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!(std::abs(v[i]) < 9.0e15) || v[i] != std::floor(v[i]))
        file_.fail(name_ + ", DataArray " + what + ": value " + std::to_string(i + 1) +
                   " is not an integer");
      out[i] = static_cast<std::int64_t>(v[i]);
    }
    return out;
  }

  const std::string& name() const { return name_; }

 private:
  const VtuFile& file_;
  std::string_view appended_;
  bool appendedRaw_;
  bool bigEndian_;
  std::string name_;
};

std::size_t countAttribute(const VtuFile& file, const XmlElement& piece, const char* key,
                           const std::string& where) {
  const std::string text = piece.attribute(key);
  char* end = nullptr;
  const unsigned long long n = std::strtoull(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || text[0] == '-')
    file.fail(where + ": " + key + " " + quoteExcerpt(text) + " is not a count");
  return static_cast<std::size_t>(n);
}

const XmlElement& namedArray(const VtuFile& file, const XmlElement& cells, const char* name,
                             const std::string& where) {
  for (const XmlElement* a : cells.childrenNamed("DataArray"))
    if (a->attribute("Name") == name) return *a;
  file.fail(where + ": <Cells> has no DataArray named '" + name + "'");
}

}  // namespace

Mesh readVtu(const std::string& path, std::vector<std::string>* notes) {
  const std::string text = readFileBytes(path, "mesh file");
  // Appended data need not be XML (raw bytes): cut it out before parsing.
  std::string xml = text;
  std::string_view appended;
  bool appendedRaw = false;
  const std::size_t open = text.find("<AppendedData");
  if (open != std::string::npos) {
    const std::size_t gt = text.find('>', open);
    const std::size_t close = text.rfind("</AppendedData>");
    if (gt == std::string::npos || close == std::string::npos || close < gt)
      throw IoError("'" + path + "' is not a valid VTU file: <AppendedData> is not closed");
    const std::size_t underscore = text.find('_', gt);
    if (underscore == std::string::npos || underscore > close)
      throw IoError("'" + path +
                    "' is not a valid VTU file: <AppendedData> does not start with "
                    "'_'");
    appended = std::string_view(text).substr(underscore + 1, close - underscore - 1);
    xml = text.substr(0, gt + 1) + text.substr(close);
  }
  const std::unique_ptr<XmlElement> root = parseXml(xml, path);
  if (const XmlElement* a = root->child("AppendedData"); a != nullptr) {
    const std::string encoding = a->attribute("encoding");
    if (encoding != "raw" && encoding != "base64")
      throw IoError("'" + path + "' is not a valid VTU file: <AppendedData> encoding " +
                    quoteExcerpt(encoding) + " is not raw or base64");
    appendedRaw = encoding == "raw";
  }
  Encoding enc;
  const VtuFile probe(path, enc);
  if (root->name != "VTKFile" || root->attribute("type") != "UnstructuredGrid")
    probe.fail("its root is not <VTKFile type=\"UnstructuredGrid\">");
  const std::string header = root->attribute("header_type", "UInt32");
  if (header != "UInt32" && header != "UInt64")
    probe.fail("header_type " + quoteExcerpt(header) + " is not UInt32 or UInt64");
  enc.headerSize = header == "UInt64" ? 8 : 4;
  const std::string order = root->attribute("byte_order", "LittleEndian");
  if (order != "LittleEndian" && order != "BigEndian")
    probe.fail("byte_order " + quoteExcerpt(order) + " is not LittleEndian or BigEndian");
  enc.bigEndian = order == "BigEndian";
  const std::string compressor = root->attribute("compressor");
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    probe.fail("compressor " + quoteExcerpt(compressor) +
               " is not supported (HOMesh reads vtkZLibDataCompressor)");
  enc.compressed = !compressor.empty();
  const double version = std::strtod(root->attribute("version", "0.1").c_str(), nullptr);
  const VtuFile file(path, enc);
  std::string appendedText;
  if (!appendedRaw && !appended.empty()) {
    appendedText = withoutSpace(appended);
    appended = appendedText;
  }

  const XmlElement* grid = root->child("UnstructuredGrid");
  if (grid == nullptr) file.fail("<UnstructuredGrid> is missing");
  const std::vector<const XmlElement*> pieces = grid->childrenNamed("Piece");
  if (pieces.empty()) file.fail("<UnstructuredGrid> has no <Piece>");
  ForeignMesh raw;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const Piece piece(file, appended, appendedRaw, enc.bigEndian, p);
    const std::string& where = piece.name();
    const std::size_t numPoints = countAttribute(file, *pieces[p], "NumberOfPoints", where);
    const std::size_t numCells = countAttribute(file, *pieces[p], "NumberOfCells", where);
    const XmlElement* points = pieces[p]->child("Points");
    const XmlElement* pointArray = points != nullptr ? points->child("DataArray") : nullptr;
    if (pointArray == nullptr) file.fail(where + ": <Points> with a DataArray is missing");
    if (pointArray->attribute("NumberOfComponents", "1") != "3")
      file.fail(where + ": the Points DataArray does not have 3 components");
    const std::vector<double> xyz = piece.values(*pointArray, "Points");
    if (xyz.size() != 3 * numPoints)
      file.fail(where + ": " + std::to_string(xyz.size()) + " point coordinates for " +
                std::to_string(numPoints) + " points");
    for (std::size_t i = 0; i < xyz.size(); ++i)
      if (!std::isfinite(xyz[i]))
        file.fail(where + ": point " + std::to_string(i / 3) +
                  " has a coordinate that is not finite");
    const auto firstPoint = static_cast<std::int64_t>(raw.xyz.size() / 3);
    raw.xyz.insert(raw.xyz.end(), xyz.begin(), xyz.end());
    const XmlElement* cells = pieces[p]->child("Cells");
    if (cells == nullptr) file.fail(where + ": <Cells> is missing");
    const std::vector<std::int64_t> types =
        piece.integers(namedArray(file, *cells, "types", where), "types");
    const std::vector<std::int64_t> offsets =
        piece.integers(namedArray(file, *cells, "offsets", where), "offsets");
    const std::vector<std::int64_t> connectivity =
        piece.integers(namedArray(file, *cells, "connectivity", where), "connectivity");
    if (types.size() != numCells || offsets.size() != numCells)
      file.fail(where + ": " + std::to_string(types.size()) + " cell types and " +
                std::to_string(offsets.size()) + " offsets for " + std::to_string(numCells) +
                " cells");
    std::string location = "'" + path + "'";
    location += ", " + where;
    addVtkCells(raw, connectivity, offsets, types, version < 2.2, firstPoint, location);
  }
  return assembleForeignMesh(std::move(raw), path, notes);
}

}  // namespace homesh
