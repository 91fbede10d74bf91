// Fully symmetric quadrature rules on the unit tetrahedron, with fewer points than
// the collapsed Gauss-Jacobi products of quadrature.hpp: every permutation of a few barycentric
// tuples, each orbit with one weight, all weights positive and all points strictly inside.
// The table comes from scripts/symmetric-quadrature.py, which solves the moment equations; the
// unit tests check each rule's exactness to its degree on every monomial.
//
// Tabulated: degree 5 (14 points; collapsed 27) and 7 (35; 64), where the optimiser's energy on
// order-3 and order-4 tetrahedra (degree 2P - 1) spends most of its time. (A triangle rule of
// degree 8 with 16 points, against 25, is another root of the same equations; it moved the
// sample points of the boundary layer's first-height check and of the facet energy nearer the
// triangles' edges, and is not used.)
#pragma once

#include <optional>

#include "core/cell_type.hpp"
#include "element/quadrature.hpp"

namespace homesh {

// The tabulated symmetric rule of the fewest points exact to at least `degree` on `type`, if
// there is one (its `degree` is the rule's own, which may exceed the one asked for).
std::optional<QuadratureRule> symmetricRule(CellType type, int degree);

}  // namespace homesh
