// Distortion quality of curved elements against their straight-sided versions.
//
// With x(xi) the curved map and x_I(xi) the straight-sided one (through the vertices: affine for
// simplices, multilinear for quadrilaterals and hexahedra, linear x linear for prisms), the
// deformation gradient is F = (dx/dxi)(dx_I/dxi)^-1 and the pointwise quality is
// q = d J^(2/d) / |F|^2 with J = det F (Frobenius norm; d the dimension): 1 where the curved
// element is locally a rotation and uniform scaling of the straight one, towards 0 as it
// distorts, negative (same magnitude, sign of J) where it is inverted. An element's quality is
// the minimum over its nodes and the points of a quadrature rule of degree P (sampled, not
// certified).
#pragma once

#include <Eigen/Core>

#include "core/cell_type.hpp"
#include "element/jacobian_sampler.hpp"

namespace homesh {

// Quality at one point from the curved and straight Jacobian matrices, whose first `dim`
// columns are dx/dxi_k (the others are ignored); 2D cells are measured in their plane.
double distortionQuality(const Eigen::Matrix3d& curved, const Eigen::Matrix3d& straight, int dim);

// Minimum quality over the element's sample points (x: node coordinates in Gmsh order).
double elementDistortion(CellType type, int order, const NodeCoordinates& x);

}  // namespace homesh
