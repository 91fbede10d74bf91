#include "io/gmsh_element_types.hpp"

#include <array>
#include <map>
#include <string>

#include "core/error.hpp"

namespace homesh {
namespace {

// Codes for orders 1..10; 0 where Gmsh has no element.
const std::map<CellType, std::array<int, 10>>& codeTable() {
  static const std::map<CellType, std::array<int, 10>> table = {
      {CellType::Line, {1, 8, 26, 27, 28, 62, 63, 64, 65, 66}},
      {CellType::Triangle, {2, 9, 21, 23, 25, 42, 43, 44, 45, 46}},
      {CellType::Quadrilateral, {3, 10, 36, 37, 38, 47, 48, 49, 50, 51}},
      {CellType::Tetrahedron, {4, 11, 29, 30, 31, 71, 72, 73, 74, 75}},
      {CellType::Prism, {6, 13, 90, 91, 106, 107, 108, 109, 110, 0}},
      {CellType::Hexahedron, {5, 12, 92, 93, 94, 95, 96, 97, 98, 0}},
      {CellType::Pyramid, {7, 14, 118, 119, 120, 121, 122, 123, 124, 0}},
  };
  return table;
}

}  // namespace

int gmshElementType(CellType type, int order) {
  const auto it = codeTable().find(type);
  const int code = (it == codeTable().end() || order < 1 || order > 10) ? 0 : it->second[order - 1];
  if (code == 0)
    throw ParameterError("Gmsh has no element type for a " + cellShortName(type) + " of order " +
                         std::to_string(order));
  return code;
}

std::optional<std::pair<CellType, int>> cellFromGmshType(int code) {
  for (const auto& [type, codes] : codeTable())
    for (int k = 0; k < 10; ++k)
      if (codes[k] == code && code != 0) return std::make_pair(type, k + 1);
  return std::nullopt;
}

}  // namespace homesh
