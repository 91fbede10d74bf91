#include "io/vtk_cells.hpp"

#include <algorithm>
#include <cstddef>
#include <map>
#include <utility>

#include "core/error.hpp"
#include "element/node_ordering.hpp"

namespace homesh {
namespace {

// How HOMesh reads one VTK cell type with a given node count.
struct CellReading {
  bool skip = false;  // a vertex
  CellType type = CellType::Point;
  int order = 1;
  std::vector<int> fromFile;  // gmsh[k] = file[fromFile[k]]
};

struct TypeInfo {
  int code;
  const char* name;
  CellType type;    // Point: not read
  int order;        // 0: Lagrange (order from the node count)
  const char* why;  // for types not read
};

constexpr const char* kSerendipity = "a serendipity cell (not a complete Lagrange element)";

const TypeInfo kTypes[] = {
    {1, "VTK_VERTEX", CellType::Point, 1, nullptr},
    {2, "VTK_POLY_VERTEX", CellType::Point, 1, nullptr},
    {3, "VTK_LINE", CellType::Line, 1, nullptr},
    {4, "VTK_POLY_LINE", CellType::Point, 0, "a polyline"},
    {5, "VTK_TRIANGLE", CellType::Triangle, 1, nullptr},
    {6, "VTK_TRIANGLE_STRIP", CellType::Point, 0, "a strip of triangles"},
    {7, "VTK_POLYGON", CellType::Point, 0, "a polygon"},
    {8, "VTK_PIXEL", CellType::Point, 0, "a pixel (write it as VTK_QUAD)"},
    {9, "VTK_QUAD", CellType::Quadrilateral, 1, nullptr},
    {10, "VTK_TETRA", CellType::Tetrahedron, 1, nullptr},
    {11, "VTK_VOXEL", CellType::Point, 0, "a voxel (write it as VTK_HEXAHEDRON)"},
    {12, "VTK_HEXAHEDRON", CellType::Hexahedron, 1, nullptr},
    {13, "VTK_WEDGE", CellType::Prism, 1, nullptr},
    {14, "VTK_PYRAMID", CellType::Pyramid, 1, nullptr},
    {21, "VTK_QUADRATIC_EDGE", CellType::Line, 2, nullptr},
    {22, "VTK_QUADRATIC_TRIANGLE", CellType::Triangle, 2, nullptr},
    {23, "VTK_QUADRATIC_QUAD", CellType::Point, 0, kSerendipity},
    {24, "VTK_QUADRATIC_TETRA", CellType::Tetrahedron, 2, nullptr},
    {25, "VTK_QUADRATIC_HEXAHEDRON", CellType::Point, 0, kSerendipity},
    {26, "VTK_QUADRATIC_WEDGE", CellType::Point, 0, kSerendipity},
    {27, "VTK_QUADRATIC_PYRAMID", CellType::Point, 0, kSerendipity},
    {28, "VTK_BIQUADRATIC_QUAD", CellType::Quadrilateral, 2, nullptr},
    {29, "VTK_TRIQUADRATIC_HEXAHEDRON", CellType::Hexahedron, 2, nullptr},
    {30, "VTK_QUADRATIC_LINEAR_QUAD", CellType::Point, 0, kSerendipity},
    {31, "VTK_QUADRATIC_LINEAR_WEDGE", CellType::Point, 0, kSerendipity},
    {32, "VTK_BIQUADRATIC_QUADRATIC_WEDGE", CellType::Point, 0, "an 18-node wedge"},
    {33, "VTK_BIQUADRATIC_QUADRATIC_HEXAHEDRON", CellType::Point, 0, kSerendipity},
    {34, "VTK_BIQUADRATIC_TRIANGLE", CellType::Point, 0, "a 7-node triangle"},
    {35, "VTK_CUBIC_LINE", CellType::Point, 0, "a cubic line (write it as VTK_LAGRANGE_CURVE)"},
    {36, "VTK_QUADRATIC_POLYGON", CellType::Point, 0, "a polygon"},
    {42, "VTK_POLYHEDRON", CellType::Point, 0, "a polyhedron"},
    {68, "VTK_LAGRANGE_CURVE", CellType::Line, 0, nullptr},
    {69, "VTK_LAGRANGE_TRIANGLE", CellType::Triangle, 0, nullptr},
    {70, "VTK_LAGRANGE_QUADRILATERAL", CellType::Quadrilateral, 0, nullptr},
    {71, "VTK_LAGRANGE_TETRAHEDRON", CellType::Tetrahedron, 0, nullptr},
    {72, "VTK_LAGRANGE_HEXAHEDRON", CellType::Hexahedron, 0, nullptr},
    {73, "VTK_LAGRANGE_WEDGE", CellType::Prism, 0, nullptr},
    {74, "VTK_LAGRANGE_PYRAMID", CellType::Point, 0,
     "a Lagrange pyramid (VTK 9.1 has none to agree a node order with; a linear pyramid is read as "
     "a VTK_PYRAMID)"},
};

const TypeInfo* typeInfo(std::int64_t code) {
  for (const TypeInfo& t : kTypes)
    if (t.code == code) return &t;
  return nullptr;
}

std::string cellName(std::size_t cell) {
  return "cell " + std::to_string(cell);
}

CellReading reading(std::int64_t code, std::size_t nodes, bool hexVersion1,
                    const std::string& where, std::size_t cell) {
  const TypeInfo* info = typeInfo(code);
  const std::string prefix = where + ": " + cellName(cell) + " is ";
  if (info == nullptr)
    throw IoError(prefix + "of VTK type " + std::to_string(code) +
                  ", which HOMesh does not read (it reads lines, triangles, quadrilaterals, "
                  "tetrahedra, wedges and hexahedra: linear, quadratic Lagrange and "
                  "VTK_LAGRANGE_* cells)");
  const std::string name = std::string(info->name) + " (type " + std::to_string(code) + ")";
  if (info->why != nullptr)
    throw IoError(prefix + "a " + name + ", " + info->why +
                  ", which HOMesh does not read (it reads complete Lagrange lines, triangles, "
                  "quadrilaterals, tetrahedra, wedges and hexahedra)");
  CellReading r;
  if (info->type == CellType::Point) {
    r.skip = true;
    return r;
  }
  r.type = info->type;
  r.order = info->order;
  if (r.order == 0) {  // Lagrange: the order the node count gives
    for (int p = 1; p <= 10 && r.order == 0; ++p)
      if (static_cast<std::size_t>(cellNumNodes(r.type, p)) == nodes) r.order = p;
    if (r.order == 0)
      throw IoError(prefix + "a " + name + " of " + std::to_string(nodes) +
                    " nodes, which is no complete element of order 1 to 10");
  } else if (static_cast<std::size_t>(cellNumNodes(r.type, r.order)) != nodes) {
    throw IoError(prefix + "a " + name + " of " + std::to_string(nodes) + " nodes, " +
                  std::to_string(cellNumNodes(r.type, r.order)) + " expected");
  }
  if (code == 13) {  // VTK_WEDGE: its first triangle turns the other way round
    r.fromFile = {0, 2, 1, 3, 5, 4};
    return r;
  }
  if (code == 14) {  // VTK_PYRAMID: Gmsh's order
    r.fromFile = {0, 1, 2, 3, 4};
    return r;
  }
  const std::vector<int> perm = vtkPermutationFromGmsh(r.type, r.order, hexVersion1);
  r.fromFile.assign(perm.size(), 0);
  for (std::size_t i = 0; i < perm.size(); ++i)
    r.fromFile[static_cast<std::size_t>(perm[i])] = static_cast<int>(i);
  return r;
}

}  // namespace

std::uint8_t vtkLagrangeType(CellType type) {
  switch (type) {
    case CellType::Line:
      return 68;
    case CellType::Triangle:
      return 69;
    case CellType::Quadrilateral:
      return 70;
    case CellType::Tetrahedron:
      return 71;
    case CellType::Hexahedron:
      return 72;
    case CellType::Prism:
      return 73;
    default:
      throw ParameterError("no VTK Lagrange cell for " + cellShortName(type));
  }
}

std::vector<int> vtkPermutationFromGmsh(CellType type, int order, bool hexVersion1) {
  std::vector<int> perm = nodePermutationFromGmsh(type, order, NodeConvention::Vtk);
  if (type == CellType::Hexahedron && hexVersion1) {
    const auto perEdge = static_cast<std::ptrdiff_t>(order - 1);
    const auto edge10 = perm.begin() + 8 + 10 * perEdge;
    std::swap_ranges(edge10, edge10 + perEdge, edge10 + perEdge);
  }
  return perm;
}

void addVtkCells(ForeignMesh& mesh, const std::vector<std::int64_t>& connectivity,
                 const std::vector<std::int64_t>& offsets, const std::vector<std::int64_t>& types,
                 bool hexVersion1, std::int64_t firstPoint, const std::string& where) {
  if (offsets.size() != types.size())
    throw IoError(where + ": " + std::to_string(offsets.size()) + " cell offsets but " +
                  std::to_string(types.size()) + " cell types");
  const auto numPoints = static_cast<std::int64_t>(mesh.xyz.size() / 3) - firstPoint;
  std::map<std::pair<std::int64_t, std::size_t>, CellReading> readings;
  std::vector<std::int64_t> nodes;
  std::int64_t start = 0;
  for (std::size_t c = 0; c < types.size(); ++c) {
    const std::int64_t end = offsets[c];
    if (end < start || end > static_cast<std::int64_t>(connectivity.size()))
      throw IoError(where + ": " + cellName(c) + " has offset " + std::to_string(end) +
                    " outside [" + std::to_string(start) + ", " +
                    std::to_string(connectivity.size()) + "] (the connectivity's size)");
    const auto count = static_cast<std::size_t>(end - start);
    auto it = readings.find({types[c], count});
    if (it == readings.end())
      it = readings
               .emplace(std::make_pair(types[c], count),
                        reading(types[c], count, hexVersion1, where, c))
               .first;
    const CellReading& r = it->second;
    if (!r.skip) {
      nodes.clear();
      for (const int k : r.fromFile) {
        const std::int64_t id = connectivity[static_cast<std::size_t>(start + k)];
        if (id < 0 || id >= numPoints)
          throw IoError(where + ": " + cellName(c) + " refers to point " + std::to_string(id) +
                        ", outside the " + std::to_string(numPoints) + " points");
        nodes.push_back(firstPoint + id);
      }
      mesh.addCell(r.type, r.order, nodes.data(), 0);
    }
    start = end;
  }
}

}  // namespace homesh
