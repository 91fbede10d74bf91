#include "io/nektar_format.hpp"

#include "core/error.hpp"
#include "io/base64.hpp"

namespace homesh::nektar {

char letter(CellType type) {
  switch (type) {
    case CellType::Tetrahedron:
      return 'A';
    case CellType::Prism:
      return 'R';
    case CellType::Hexahedron:
      return 'H';
    case CellType::Pyramid:
      return 'P';
    case CellType::Triangle:
      return 'T';
    case CellType::Quadrilateral:
      return 'Q';
    default:
      throw ParameterError("Nektar++ XML has no element for a " + cellShortName(type));
  }
}

const std::vector<std::vector<int>>& localFaces(CellType type) {
  static const std::vector<std::vector<int>> tet{{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}};
  static const std::vector<std::vector<int>> prism{
      {0, 1, 2, 3}, {0, 1, 4}, {1, 2, 5, 4}, {3, 2, 5}, {0, 3, 5, 4}};
  static const std::vector<std::vector<int>> hex{{0, 1, 2, 3}, {0, 1, 5, 4}, {1, 2, 6, 5},
                                                 {3, 2, 6, 7}, {0, 3, 7, 4}, {4, 5, 6, 7}};
  static const std::vector<std::vector<int>> pyramid{
      {0, 1, 2, 3}, {0, 1, 4}, {1, 2, 4}, {3, 2, 4}, {0, 3, 4}};
  switch (type) {
    case CellType::Tetrahedron:
      return tet;
    case CellType::Prism:
      return prism;
    case CellType::Hexahedron:
      return hex;
    case CellType::Pyramid:
      return pyramid;
    default:
      throw ParameterError("no Nektar++ faces for a " + cellShortName(type));
  }
}

std::string encode(const void* data, std::size_t bytes) {
  const std::string compressed = zlibCompress(std::string(static_cast<const char*>(data), bytes));
  return base64EncodeZeroPadded(compressed.data(), compressed.size());
}

std::string decode(const std::string& text) {
  return zlibDecompress(base64Decode(text));
}

}  // namespace homesh::nektar
