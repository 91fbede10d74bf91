// Certified bounds of the Jacobian determinant of curved elements (Bezier expansion).
//
// The Jacobian determinant J of a polynomial element is itself a polynomial: of total degree
// 2(P-1) on a triangle and 3(P-1) on a tetrahedron, of degree 2P-1 per variable on a
// quadrilateral and 3P-1 on a hexahedron, and of degree 3P-2 in (x, y) by 3P-1 in z on a prism.
// Its coefficients in the Bernstein (Bezier) basis of that space bound it from below and above,
// and the coefficients at the domain's corners are values of J. Where the bounds do not decide,
// the domain is subdivided (simplices into 2^d, boxes into 2^d, prisms into 8) and the
// coefficients recomputed on each part, best first, until the minimum and maximum of J are
// known to a relative tolerance (Johnen, Remacle, Geuzaine, "Geometrical validity of curvilinear
// finite elements", J. Comput. Phys. 2013). Sampling can miss a negative J between its points;
// this cannot.
//
// The coefficients are computed exactly from the geometry's own Bezier control points
// (differentiation and products of Bernstein polynomials, quality/bernstein.hpp), so they stay
// accurate at high order, where interpolating J at points would be ill conditioned.
#pragma once

#include <Eigen/Core>

#include "element/reference_element.hpp"
#include "quality/jacobian_sampler.hpp"

namespace homesh {

enum class Validity { Valid, Invalid, Undecided };

struct JacobianBounds {
  double minLower = 0.0, minUpper = 0.0;  // the minimum of J lies in [minLower, minUpper]
  double maxLower = 0.0, maxUpper = 0.0;  // the maximum of J lies in [maxLower, maxUpper]
  Validity validity = Validity::Undecided;
  bool certified = true;  // the bounds are proven (Bezier), not sampled

  // The certified scaled Jacobian: a lower bound of min J / max J, the ratio of the bounds
  // (what Gmsh's AnalyseMeshQuality reports as minJ/maxJ); -1 if J is nowhere positive.
  double scaledJacobian() const {
    if (maxLower <= 0.0) return -1.0;
    return minLower >= 0.0 ? minLower / maxUpper : minLower / maxLower;
  }
  // The estimate from values of J actually found: an upper bound of min J / max J.
  double scaledJacobianEstimate() const { return maxLower > 0.0 ? minUpper / maxLower : -1.0; }
};

// Bounds on J over the element with node coordinates x (Gmsh node order, equispaced nodes).
// `normal`: the plane normal for 2D cells. `tolerance`: the gap left between each bound and
// the extreme value found, relative to the largest |J| (Gmsh's AnalyseMeshQuality uses 1e-3).
JacobianBounds boundJacobian(CellType type, int order, const NodeCoordinates& x,
                             const Eigen::Vector3d* normal, double tolerance = 1e-3);

}  // namespace homesh
