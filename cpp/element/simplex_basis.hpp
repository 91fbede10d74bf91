// Orthogonal (Dubiner / Koornwinder) polynomial bases on the unit simplices, with gradients.
//
// The collapsed-coordinate factors are evaluated in their "scaled" form
// s^n P_n^{(a,0)}(X / s) by the three-term recurrence in (X, s), so every basis function is a
// polynomial in the Cartesian reference coordinates and is evaluated without the 0/0 singularity
// of collapsed coordinates at the top vertices. The space spanned is P_order (total degree).
#pragma once

#include <Eigen/Core>

#include "core/cell_type.hpp"

namespace homesh {

// Number of basis functions of total degree <= order in the shape's dimension.
int simplexBasisSize(CellType type, int order);

// Values (size n) and gradients (n x dim) of the basis at reference point xi (dim coordinates).
void simplexBasis(CellType type, int order, const double* xi, Eigen::VectorXd& values,
                  Eigen::MatrixXd& gradients);

}  // namespace homesh
