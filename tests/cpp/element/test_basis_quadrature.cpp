// The nodal basis reproduces polynomials; quadrature integrates monomials exactly.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace {

double factorial(int n) {
  return std::tgamma(n + 1.0);
}

// Exact integral of x^a y^b z^c over the unit simplex of dimension dim.
double monomialIntegral(int dim, int a, int b, int c) {
  return factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + dim);
}

double monomial(const double* x, int dim, int a, int b, int c) {
  double v = std::pow(x[0], a);
  if (dim > 1) v *= std::pow(x[1], b);
  if (dim > 2) v *= std::pow(x[2], c);
  return v;
}

class SimplexShapes : public ::testing::TestWithParam<CellType> {};

TEST_P(SimplexShapes, QuadratureIsExactToItsDegree) {
  const CellType type = GetParam();
  const int dim = cellDimension(type);
  for (int degree = 0; degree <= 22; ++degree) {
    const QuadratureRule rule = simplexQuadrature(type, degree);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree && (dim > 1 || b == 0); ++b)
        for (int c = 0; a + b + c <= degree && (dim > 2 || c == 0); ++c) {
          double sum = 0.0;
          for (int q = 0; q < rule.size(); ++q)
            sum += rule.weights[q] *
                   monomial(&rule.points[static_cast<std::size_t>(q) * dim], dim, a, b, c);
          EXPECT_NEAR(sum, monomialIntegral(dim, a, b, c), 1e-13)
              << "degree " << degree << " monomial " << a << b << c;
        }
  }
}

TEST_P(SimplexShapes, BasisReproducesPolynomialsAndDerivatives) {
  const CellType type = GetParam();
  const int dim = cellDimension(type);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int p = 1; p <= 10; ++p) {
    const ReferenceElement& ref = ReferenceElement::get(type, p);
    Eigen::VectorXd values;
    Eigen::MatrixXd gradients;
    for (int trial = 0; trial < 5; ++trial) {
      double xi[3] = {uniform(rng), uniform(rng), uniform(rng)};
      double s = 0.0;
      for (int k = 0; k < dim; ++k) s += xi[k];
      if (s > 1.0)
        for (int k = 0; k < dim; ++k) xi[k] /= (s + 1e-3);
      ref.evaluate(xi, values, gradients);
      // Every monomial of total degree <= p, interpolated at the nodes.
      for (int a = 0; a <= p; ++a)
        for (int b = 0; a + b <= p && (dim > 1 || b == 0); ++b)
          for (int c = 0; a + b + c <= p && (dim > 2 || c == 0); ++c) {
            double f = 0.0, df[3] = {0.0, 0.0, 0.0};
            for (int n = 0; n < ref.numNodes(); ++n) {
              const Eigen::VectorXd node = ref.nodes().row(n).transpose();
              const double fn = monomial(node.data(), dim, a, b, c);
              f += values(n) * fn;
              for (int k = 0; k < dim; ++k) df[k] += gradients(n, k) * fn;
            }
            EXPECT_NEAR(f, monomial(xi, dim, a, b, c), 1e-10) << "order " << p;
            const int e[3] = {a, b, c};
            for (int k = 0; k < dim; ++k) {
              if (e[k] == 0) {
                EXPECT_NEAR(df[k], 0.0, 1e-9) << "order " << p;
                continue;
              }
              int ee[3] = {a, b, c};
              ee[k] -= 1;
              const double exact = e[k] * monomial(xi, dim, ee[0], ee[1], ee[2]);
              EXPECT_NEAR(df[k], exact, 1e-9) << "order " << p;
            }
          }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, SimplexShapes,
                         ::testing::Values(CellType::Line, CellType::Triangle,
                                           CellType::Tetrahedron));

}  // namespace
}  // namespace homesh
