// Orthogonal polynomial bases on the reference shapes, with gradients.
//
// Simplices: Dubiner / Koornwinder polynomials spanning P_order (total degree), their
// collapsed-coordinate factors evaluated in "scaled" form s^n P_n^{(a,0)}(X / s) by the
// three-term recurrence in (X, s), so every function is a polynomial in the Cartesian reference
// coordinates and is evaluated without the 0/0 of collapsed coordinates at the top vertices.
// Quadrilateral and hexahedron: tensor Legendre polynomials spanning Q_order. Prism: the
// triangle's basis times Legendre polynomials in z, spanning P_order(x, y) x P_order(z).
// Pyramid: Bergot, Cohen and Durufle's basis (as Gmsh's pyramids), rational where it must be for
// the base to be Q_order and the triangles P_order (x y / (1 - z) at order 1).
// The reference shapes are unit: simplices with vertices at the origin and the unit vectors,
// [0, 1]^d boxes, the unit triangle times [0, 1], the pyramid 0 <= x, y <= 1 - z.
#pragma once

#include <Eigen/Core>

#include "core/cell_type.hpp"

namespace homesh {

// Values (one per basis function) and gradients (functions x dim) at reference point xi.
// Throws ParameterError for unsupported shapes or a negative order.
void orthogonalBasis(CellType type, int order, const double* xi, Eigen::VectorXd& values,
                     Eigen::MatrixXd& gradients);

}  // namespace homesh
