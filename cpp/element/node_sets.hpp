// Reference positions of element nodes.
//
// Equispaced: lattice point / P, what Gmsh's and VTK's high-order files mean.
// Optimal: Gauss-Lobatto-Legendre points on lines and tensor shapes, Warburton's warp & blend
// points on triangles and tetrahedra (Warburton, "An explicit construction of interpolation
// nodes on the simplex", J. Eng. Math. 2006), triangle x GLL on prisms. Their edge nodes are the
// GLL points, the tetrahedron's face nodes are the triangle's (so triangles, tetrahedra and
// prisms conform), and the interpolation is well conditioned at high order (Lebesgue constant of
// the order-10 triangle below 10, against about 100 for equispaced nodes).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/cell_type.hpp"
#include "element/node_ordering.hpp"

namespace homesh {

enum class NodeSet { Equispaced, Optimal };

// The n + 1 Gauss-Lobatto-Legendre points on [0, 1], ascending.
std::vector<double> gllPoints(int n);

// Reference coordinates (rows, cellDimension(type) columns) of the nodes named by `lattice`
// for an element of the given order.
Eigen::MatrixXd nodeCoordinates(CellType type, int order, NodeSet set,
                                const std::vector<LatticePoint>& lattice);

}  // namespace homesh
