// Measure (volume, area) of curved elements: the integral of J over the reference element, with
// a quadrature rule exact for J's polynomial degree.
#pragma once

#include <vector>

#include "core/mesh.hpp"
#include "element/jacobian_sampler.hpp"

namespace homesh {

// Signed measure of one element (x: node coordinates, Gmsh order). For 2D cells with a normal,
// the signed area; without, the (unsigned) area of a curved surface triangle is approximated by
// a high-degree rule.
double elementMeasure(CellType type, int order, const NodeCoordinates& x,
                      const Eigen::Vector3d* normal);

// Per element of the mesh dimension, in block order.
std::vector<double> elementMeasures(const Mesh& mesh);

}  // namespace homesh
