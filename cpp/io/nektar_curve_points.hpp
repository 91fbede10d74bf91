// The curves of a Nektar++ geometry moved to the points HOMesh places nodes at (equispaced), from
// the points types Nektar++ and NekMesh write: edges and quadrilaterals at Gauss-Lobatto-Legendre
// points are resampled through their interpolating polynomial (exact: the same polynomial); a
// triangle at NodalTriElec points of an order with tabulated points is mapped by the matrix of
// nektar_expansion.hpp. A triangle's electrostatic or Fekete points otherwise have no closed
// form here: its curve is dropped, and the reader rebuilds its interior from its edges. Other
// points types are refused (IoError).
#pragma once

#include <string>

#include "io/nektar_sections.hpp"

namespace homesh::nektar {

// `order`: the curves' order (their edges' number of points less one).
void toEvenlySpaced(GeometrySections& g, int order, const std::string& path);

}  // namespace homesh::nektar
