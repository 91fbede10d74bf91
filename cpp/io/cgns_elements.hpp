// CGNS's element types (SIDS ElementType_t) as HOMesh reads and writes them: the complete
// Lagrange types of orders 1 to 4, their node order (element/node_ordering.hpp, Cgns), and why
// the others are not read.
//
// HOMesh reads and writes a CGNS element as the equispaced Lagrange element its figures number
// (uniform nodes on every edge, face and level; what a permutation of Gmsh's nodes gives). The
// SIDS's notes put a few order-4 nodes elsewhere (TETRA_35's face nodes at centroids of
// sub-triangles, PYRA_55's interior on lines from the apex); those positions are not used.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

// Throws ParameterError unless 1 <= order <= 4 ("CGNS names elements up to order 4").
void checkCgnsOrder(int order);

// The CGNS ElementType_t code of a complete element. Throws ParameterError above order 4
// ("CGNS names elements up to order 4") or for a shape CGNS has not (a point is NODE, 2).
int cgnsElementType(CellType type, int order);

// What HOMesh makes of a CGNS element type.
struct CgnsTypeReading {
  CellType type = CellType::Point;  // Point: not read (see `why`; empty for NODE, skipped)
  int order = 0;
  std::string why;  // why it is not read ("an incomplete (serendipity) element", ...)
};
CgnsTypeReading cgnsTypeReading(int code);

// The SIDS's name of a type code ("TETRA_35"), or "type N" for a code outside the table.
std::string cgnsTypeName(int code);

// The lock every use of the CGNS library (and its HDF5) in this process holds: the library is
// not thread-safe, and a reader forks a child while holding it, so that no other thread is
// inside the library (holding its locks) when the child starts.
std::unique_lock<std::mutex> holdCgnsLibrary();

// perm[i] = index, in Gmsh order, of the i-th node of the CGNS element.
std::vector<int> cgnsPermutationFromGmsh(CellType type, int order);

}  // namespace homesh
