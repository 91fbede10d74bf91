// Quadrature rules on the reference shapes (unit simplices; the line is [0, 1]).
//
// Simplex rules are collapsed (Stroud conical) products of Gauss-Jacobi rules, so a rule of any
// degree exists; the points lie strictly inside the element.
#pragma once

#include <vector>

#include "core/cell_type.hpp"

namespace homesh {

struct QuadratureRule {
  int dim = 0;
  int degree = 0;               // integrates every polynomial of this total degree exactly
  std::vector<double> points;   // dim * size(), point-major
  std::vector<double> weights;  // sum = reference volume (1, 1/2, 1/6)
  int size() const { return static_cast<int>(weights.size()); }
};

// Gauss-Jacobi rule with n points on [-1, 1] for the weight (1-x)^alpha (1+x)^beta (Golub-Welsch).
void gaussJacobi(int n, double alpha, double beta, std::vector<double>& x, std::vector<double>& w);

// A rule exact for polynomials of total degree `degree` on the reference Line, Triangle or
// Tetrahedron. Throws ParameterError for other shapes or degree < 0.
QuadratureRule simplexQuadrature(CellType type, int degree);

}  // namespace homesh
