// Facts of the Nektar++ XML geometry format shared by its writer and reader (Nektar++ 5.x, as
// NekMesh writes it; see docs/nektar-format.md).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh::nektar {

// Binary records of the compressed ("B64Z-LittleEndian") sections: 64-bit fields, no padding.
struct Vertex {
  std::int64_t id;
  double x, y, z;
};
struct Edge {
  std::int64_t id, v0, v1;
};
template <int N>
struct Entity {  // a face (edge ids) or an element (face or edge ids)
  std::int64_t id;
  std::int64_t ids[N];
};
struct CurvedInfo {
  std::int64_t id, entityId, numPoints, pointSet, offset, pointsType;
};
static_assert(sizeof(Vertex) == 32 && sizeof(Edge) == 24 && sizeof(CurvedInfo) == 48,
              "Nektar++ records must be packed 64-bit fields");

inline constexpr const char* kCompressed = "B64Z-LittleEndian";

// Points types: names, and their values in Nektar++ 5.x's PointsType enumeration.
inline constexpr const char* kEvenlySpaced = "PolyEvenlySpaced";
inline constexpr const char* kTriEvenlySpaced = "NodalTriEvenlySpaced";
inline constexpr std::int64_t kEvenlySpacedId = 17;
inline constexpr std::int64_t kTriEvenlySpacedId = 24;
inline constexpr std::int64_t kGaussLobattoLegendreId = 4;
inline constexpr const char* kGaussLobattoLegendre = "GaussLobattoLegendre";
inline constexpr std::int64_t kTriElecId = 22;  // NodalTriElec, as NekMesh writes triangles
inline constexpr std::int64_t kTriFeketeId = 23;

// Element letters: 3D A (tetrahedron), R (prism), P (pyramid), H (hexahedron); faces and 2D
// elements T, Q.
char letter(CellType type);

// Local faces of the 3D elements in Nektar++ order, as local vertex indices of Nektar++'s own
// numbering (triangles have 3 entries). A pyramid's local vertices are Gmsh's: its faces are the
// base, then the triangles over base edges 01, 12, 32, 03 (PyrGeom derives its vertices from
// that order).
const std::vector<std::vector<int>>& localFaces(CellType type);

// Packs records into a compressed blob (zlib, then base64 zero-padded) and back.
std::string encode(const void* data, std::size_t bytes);
std::string decode(const std::string& text);

}  // namespace homesh::nektar
