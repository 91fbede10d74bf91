// Certified bounds of the Jacobian determinant of curved elements (Bezier expansion).
//
// The Jacobian determinant J of a polynomial element is itself a polynomial: of total degree
// 2(P-1) on a triangle and 3(P-1) on a tetrahedron, of degree 2P-1 per variable on a
// quadrilateral and 3P-1 on a hexahedron, and of degree 3P-2 in (x, y) by 3P-1 in z on a prism.
// A pyramid's J, rational in its own coordinates, is a polynomial in collapsed ones (u, v, z) on
// the unit cube, x = u (1 - z) and y = v (1 - z): of degree 3P-1 in u and v by 3P-3 in z, whose
// top face holds J's limits at the apex from every direction (bezier_jacobian.cpp says why).
// Its coefficients in the Bernstein (Bezier) basis of that space bound it from below and above,
// and the coefficients at the domain's corners are values of J. Where the bounds do not decide,
// the domain is subdivided, best first, until the minimum and maximum of J are known to a
// relative tolerance (the scheme of Johnen, Remacle, Geuzaine, "Geometrical validity of
// curvilinear finite elements", J. Comput. Phys. 2013). Sampling can miss a negative J between
// its points; this cannot.
//
// The coefficients on the whole element are computed exactly from the geometry's own Bezier
// control points (differentiation and products of Bernstein polynomials, quality/bernstein.hpp),
// so they stay accurate at high order, where interpolating J at points would be ill conditioned
// (a pyramid's control points are its geometry interpolated at the cube's equispaced points).
// A subdivision is a longest-edge bisection of the part, done on J's coefficients alone by
// de Casteljau's algorithm (averages only, so the child bounds stay exact up to rounding): it
// costs a few hundred additions where re-evaluating the geometry on 2^d children would cost tens
// of thousands of operations. See bench/quality_throughput.cpp for the speed against Gmsh.
#pragma once

#include <Eigen/Core>

#include "element/jacobian_sampler.hpp"
#include "element/reference_element.hpp"

namespace homesh {

// Valid: J > 0 everywhere, proven. Invalid: a value J < 0 was found, or J is proven below 1e-10
// of the element's size to the power d everywhere (a flat element). Undecided: neither, within
// the subdivision budget or because rounding hides the sign (high-order elements whose
// interior nodes oscillate have Bezier coefficients far larger than J), or the element has
// non-finite coordinates; never counted as valid.
enum class Validity { Valid, Invalid, Undecided };

// The bounds include a bound on the floating-point rounding of the computation (from the
// tables' norms, the element's size and Higham's gamma_n), so they hold for the exact J.
struct JacobianBounds {
  double minLower = 0.0, minUpper = 0.0;  // the minimum of J lies in [minLower, minUpper]
  double maxLower = 0.0, maxUpper = 0.0;  // the maximum of J lies in [maxLower, maxUpper]
  Validity validity = Validity::Undecided;
  bool certified = true;  // the bounds are proven (false only for non-finite input: NaN)

  // The certified scaled Jacobian: a lower bound of min J / max J, the ratio of the bounds
  // (what Gmsh's AnalyseMeshQuality reports as minJ/maxJ); -1 when no clearly positive value of
  // J was found (the element is inverted or flat wherever it was probed).
  double scaledJacobian() const {
    if (maxLower <= 0.0) return -1.0;
    return minLower >= 0.0 ? minLower / maxUpper : minLower / maxLower;
  }
  // From values of J actually found: an upper bound of min J / max J (with the certified
  // lower bound above, the interval that holds it).
  double scaledJacobianEstimate() const {
    if (maxLower <= 0.0) return -1.0;
    return minUpper >= 0.0 ? minUpper / maxLower : minUpper / maxUpper;
  }
};

// Gmsh's AnalyseMeshQuality refines its bounds to the same relative tolerance.
constexpr double kJacobianBoundTolerance = 1e-3;

// Bounds on J over the element with node coordinates x (Gmsh node order, equispaced nodes).
// `normal`: the plane normal for 2D cells. `tolerance`: the gap left between each bound and
// the extreme value found, relative to the largest |J|.
JacobianBounds boundJacobian(CellType type, int order, const NodeCoordinates& x,
                             const Eigen::Vector3d* normal,
                             double tolerance = kJacobianBoundTolerance);

}  // namespace homesh
