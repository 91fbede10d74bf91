// Element shapes known to the core, and the counts that follow from shape and order.
#pragma once

#include <string>

namespace homesh {

enum class CellType {
  Point,
  Line,
  Triangle,
  Quadrilateral,
  Tetrahedron,
  Prism,
  Pyramid,
  Hexahedron
};

// Topological dimension of the shape (0 for a point, 3 for a tetrahedron).
int cellDimension(CellType type);

// Number of corner vertices.
int cellNumVertices(CellType type);

// Number of nodes of a complete Lagrange element of the given order (order >= 1; a point has 1).
// Throws ParameterError for shapes the element library does not support yet.
int cellNumNodes(CellType type, int order);

// Short name used in reports and on the command line: "tet", "tri", "line", ...
std::string cellShortName(CellType type);

}  // namespace homesh
