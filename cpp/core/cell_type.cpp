#include "core/cell_type.hpp"

#include "core/error.hpp"

namespace homesh {

int cellDimension(CellType type) {
  switch (type) {
    case CellType::Point:
      return 0;
    case CellType::Line:
      return 1;
    case CellType::Triangle:
    case CellType::Quadrilateral:
      return 2;
    case CellType::Tetrahedron:
    case CellType::Prism:
    case CellType::Pyramid:
    case CellType::Hexahedron:
      return 3;
  }
  throw Error("cellDimension: unknown cell type");
}

int cellNumVertices(CellType type) {
  switch (type) {
    case CellType::Point:
      return 1;
    case CellType::Line:
      return 2;
    case CellType::Triangle:
      return 3;
    case CellType::Quadrilateral:
    case CellType::Tetrahedron:
      return 4;
    case CellType::Pyramid:
      return 5;
    case CellType::Prism:
      return 6;
    case CellType::Hexahedron:
      return 8;
  }
  throw Error("cellNumVertices: unknown cell type");
}

int cellNumNodes(CellType type, int order) {
  if (order < 1) throw ParameterError("element order must be >= 1, got " + std::to_string(order));
  const int p = order;
  switch (type) {
    case CellType::Point:
      return 1;
    case CellType::Line:
      return p + 1;
    case CellType::Triangle:
      return (p + 1) * (p + 2) / 2;
    case CellType::Quadrilateral:
      return (p + 1) * (p + 1);
    case CellType::Tetrahedron:
      return (p + 1) * (p + 2) * (p + 3) / 6;
    case CellType::Prism:
      return (p + 1) * (p + 1) * (p + 2) / 2;
    case CellType::Pyramid:
      return (p + 1) * (p + 2) * (2 * p + 3) / 6;
    case CellType::Hexahedron:
      return (p + 1) * (p + 1) * (p + 1);
  }
  throw Error("cellNumNodes: unknown cell type");
}

std::string cellShortName(CellType type) {
  switch (type) {
    case CellType::Point:
      return "point";
    case CellType::Line:
      return "line";
    case CellType::Triangle:
      return "tri";
    case CellType::Quadrilateral:
      return "quad";
    case CellType::Tetrahedron:
      return "tet";
    case CellType::Prism:
      return "prism";
    case CellType::Pyramid:
      return "pyramid";
    case CellType::Hexahedron:
      return "hex";
  }
  throw Error("cellShortName: unknown cell type");
}

}  // namespace homesh
