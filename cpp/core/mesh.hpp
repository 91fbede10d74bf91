// The flat mesh that flows through the pipeline.
//
// Layout (kept flat so that stages, writers, bindings and a future MPI partitioner can share it):
//   - nodes: xyz[3*i .. 3*i+2] for node i (0-based).
//   - per node, where it lies on the CAD: nodeCadDim[i] in {0 vertex, 1 curve, 2 face, 3 solid},
//     nodeCadIndex[i] the 1-based index of that entity in TopExp::MapShapes order of its dimension
//     (FreeCAD's VertexN / EdgeN / FaceN / SolidN), nodeCadParam[2*i..2*i+1] its curve parameter t
//     (second slot NaN) or face parameters (u, v); NaN where there is no parameter (vertex, solid).
//     A mesh read from a file without CAD has nodeCadIndex 0 everywhere.
//   - elements in blocks of one cell type and order; connectivity is element-major with the node
//     order of Gmsh's convention for that type (see element/node_ordering.hpp), 0-based node ids.
//     Each element records the CAD entity it lies on (its solid for volume elements, its face for
//     boundary triangles, ...), 1-based like nodeCadIndex.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

struct ElementBlock {
  CellType type = CellType::Tetrahedron;
  int order = 1;
  std::vector<std::int64_t> nodes;   // size() == count() * nodesPerElement()
  std::vector<std::int32_t> entity;  // size() == count()
  // Hexahedra that are a macro boundary layer's cells (boundary_layer/layer_cells.hpp: each one's
  // wall is its face 0, 1, 2, 3); prisms and 2D quadrilaterals are told by their type alone.
  bool layerCells = false;

  int nodesPerElement() const { return cellNumNodes(type, order); }
  std::size_t count() const { return entity.size(); }
  const std::int64_t* element(std::size_t e) const {
    return nodes.data() + e * static_cast<std::size_t>(nodesPerElement());
  }
};

struct Mesh {
  // 3: volume mesh; 2: its elements are triangles (or quadrilaterals), in a plane or, for a
  // surface mesh, on the curved faces of a model without solids.
  int dim = 3;
  int order = 1;  // polynomial order of every block
  // For dim == 2: the unit normal of the mesh plane; 2D elements are oriented counter-clockwise
  // around it (positive Jacobian). Zero for a surface mesh (no plane): there each element's
  // Jacobian is measured along the normal of its own straight cell (cellNormal).
  std::array<double, 3> planeNormal{0.0, 0.0, 1.0};

  std::vector<double> xyz;
  std::vector<std::uint8_t> nodeCadDim;
  std::vector<std::int32_t> nodeCadIndex;
  std::vector<double> nodeCadParam;

  // Blocks whose cells have dimension `dim` (the elements), then those of lower dimension
  // (the boundary: triangles on CAD faces in 3D, lines on CAD curves in 2D).
  std::vector<ElementBlock> blocks;

  std::size_t numNodes() const { return xyz.size() / 3; }

  // Appends a node and returns its id.
  std::int64_t addNode(const double p[3], int cadDim, int cadIndex, double param0, double param1);

  // Number of cells of dimension `dim` (the elements the report counts).
  std::size_t numElements() const;

  // A 2D mesh whose elements lie on curved faces in 3D (planeNormal zero), not in one plane.
  bool isSurface() const {
    return dim == 2 && planeNormal[0] == 0.0 && planeNormal[1] == 0.0 && planeNormal[2] == 0.0;
  }

  // For dim == 2: the unit vector a 2D cell's Jacobian x_xi1 x x_xi2 is measured along: the
  // plane's normal, or in a surface mesh the unit normal of the straight cell through its
  // first three vertices (zero when they are collinear). `cell`: its node ids, Gmsh order.
  std::array<double, 3> cellNormal(const std::int64_t* cell) const;

  // Throws Error if array sizes disagree or a connectivity entry is out of range.
  void checkConsistency() const;
};

// The plane of a 2D mesh read from a file, for Mesh::planeNormal: when every node lies within
// `tolerance` times the mesh's bounding-box diagonal of one plane, its unit normal, oriented as
// most 2D cells' straight normals (their unit normals summed; a cell's own where they cancel,
// as on a closed shell); zero when the nodes leave every such plane (a surface mesh); nullopt
// when no 2D cell spans a plane.
std::optional<std::array<double, 3>> planeOfCells(const Mesh& mesh, double tolerance);

// The elements (cells of dimension mesh.dim) in block order, as (block, index in it): what
// per-element arrays (quality verdicts, region seeds) are indexed by.
std::vector<std::pair<const ElementBlock*, std::size_t>> elementsOf(const Mesh& mesh);

// Drops the nodes no element uses (a source's high-order nodes after an order change, a macro
// layer's inner nodes after its split) and renumbers the rest in their original order.
void compactNodes(Mesh& mesh);

}  // namespace homesh
