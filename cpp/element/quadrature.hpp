// Quadrature rules on the reference shapes (unit simplices, [0, 1]^d boxes, unit triangle x
// [0, 1] prism, pyramid 0 <= x, y <= 1 - z).
//
// Simplex and pyramid rules are collapsed (Stroud conical) products of Gauss-Jacobi rules and
// box rules tensor products of Gauss-Legendre rules, so a rule of any degree exists; the points
// lie strictly inside the element. The pyramid's rule of degree d also integrates exactly the
// rational functions of its basis (orthogonal_basis.hpp) of degree d.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

struct QuadratureRule {
  int dim = 0;
  int degree = 0;  // integrates every polynomial of this total degree exactly (boxes and
                   // prisms: of this degree in each variable)
  std::vector<double> points;   // dim * size(), point-major
  std::vector<double> weights;  // sum = reference volume (1, 1/2, 1/6, 1/3)
  int size() const { return static_cast<int>(weights.size()); }
};

// Gauss-Jacobi rule with n points on [-1, 1] for the weight (1-x)^alpha (1+x)^beta (Golub-Welsch).
void gaussJacobi(int n, double alpha, double beta, std::vector<double>& x, std::vector<double>& w);

// A rule exact to `degree` on the reference shape. Throws ParameterError for unsupported shapes
// or degree < 0.
QuadratureRule quadratureRule(CellType type, int degree);

// The rule's points as the rows of a matrix (size() x dim), followed by the rows of `after`
// (an element's nodes, where samplers take both; dim columns, or none).
Eigen::MatrixXd pointRows(const QuadratureRule& rule, const Eigen::MatrixXd& after = {});

}  // namespace homesh
