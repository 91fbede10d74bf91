#include "element/quadrature.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace homesh {

void gaussJacobi(int n, double alpha, double beta, std::vector<double>& x, std::vector<double>& w) {
  if (n < 1) throw ParameterError("Gauss-Jacobi rule needs at least one point");
  // Symmetric tridiagonal Jacobi matrix of the recurrence of the orthonormal Jacobi polynomials.
  Eigen::MatrixXd jm = Eigen::MatrixXd::Zero(n, n);
  const double ab = alpha + beta;
  for (int k = 0; k < n; ++k) {
    const double s = 2.0 * k + ab;
    jm(k, k) =
        (k == 0) ? (beta - alpha) / (ab + 2.0) : (beta * beta - alpha * alpha) / (s * (s + 2.0));
    if (k + 1 < n) {
      const double m = k + 1.0;
      const double t = 2.0 * m + ab;
      const double b = std::sqrt(4.0 * m * (m + alpha) * (m + beta) * (m + ab) /
                                 (t * t * (t + 1.0) * (t - 1.0)));
      jm(k, k + 1) = b;
      jm(k + 1, k) = b;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jm);
  const double mu0 = std::pow(2.0, ab + 1.0) * std::tgamma(alpha + 1.0) * std::tgamma(beta + 1.0) /
                     std::tgamma(ab + 2.0);
  x.resize(n);
  w.resize(n);
  for (int k = 0; k < n; ++k) {
    x[k] = eig.eigenvalues()(k);
    const double v0 = eig.eigenvectors()(0, k);
    w[k] = mu0 * v0 * v0;
  }
}

namespace {

// n-point Gauss-Jacobi rule for the weight (1-q)^alpha on [0, 1].
void unitGaussJacobi(int n, double alpha, std::vector<double>& q, std::vector<double>& w) {
  gaussJacobi(n, alpha, 0.0, q, w);
  const double scale = std::pow(0.5, alpha + 1.0);
  for (int k = 0; k < n; ++k) {
    q[k] = 0.5 * (q[k] + 1.0);
    w[k] *= scale;
  }
}

}  // namespace

QuadratureRule quadratureRule(CellType type, int degree) {
  if (degree < 0) throw ParameterError("quadrature degree must be >= 0");
  const int n = degree / 2 + 1;  // n-point Gauss rules are exact to degree 2n-1 >= degree
  QuadratureRule rule;
  rule.degree = degree;
  std::vector<double> p, wp, q, wq, r, wr;
  unitGaussJacobi(n, 0.0, p, wp);
  switch (type) {
    case CellType::Line:
      rule.dim = 1;
      rule.points = p;
      rule.weights = wp;
      return rule;
    case CellType::Triangle:
      // x = p (1 - q), y = q; the Jacobian (1 - q) is the Jacobi weight in q.
      rule.dim = 2;
      unitGaussJacobi(n, 1.0, q, wq);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          rule.points.push_back(p[i] * (1.0 - q[j]));
          rule.points.push_back(q[j]);
          rule.weights.push_back(wp[i] * wq[j]);
        }
      return rule;
    case CellType::Tetrahedron:
      // x = p (1-q)(1-r), y = q (1-r), z = r; Jacobian (1-q)(1-r)^2.
      rule.dim = 3;
      unitGaussJacobi(n, 1.0, q, wq);
      unitGaussJacobi(n, 2.0, r, wr);
      for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            rule.points.push_back(p[i] * (1.0 - q[j]) * (1.0 - r[k]));
            rule.points.push_back(q[j] * (1.0 - r[k]));
            rule.points.push_back(r[k]);
            rule.weights.push_back(wp[i] * wq[j] * wr[k]);
          }
      return rule;
    case CellType::Quadrilateral:
      rule.dim = 2;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          rule.points.insert(rule.points.end(), {p[i], p[j]});
          rule.weights.push_back(wp[i] * wp[j]);
        }
      return rule;
    case CellType::Hexahedron:
      rule.dim = 3;
      for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            rule.points.insert(rule.points.end(), {p[i], p[j], p[k]});
            rule.weights.push_back(wp[i] * wp[j] * wp[k]);
          }
      return rule;
    case CellType::Prism: {
      rule.dim = 3;
      const QuadratureRule tri = quadratureRule(CellType::Triangle, degree);
      for (int k = 0; k < n; ++k)
        for (int t = 0; t < tri.size(); ++t) {
          rule.points.insert(rule.points.end(),
                             {tri.points[2 * static_cast<std::size_t>(t)],
                              tri.points[2 * static_cast<std::size_t>(t) + 1], p[k]});
          rule.weights.push_back(tri.weights[t] * wp[k]);
        }
      return rule;
    }
    case CellType::Pyramid:
      // x = p (1 - r), y = q (1 - r), z = r; Jacobian (1 - r)^2, the Jacobi weight in r.
      rule.dim = 3;
      unitGaussJacobi(n, 2.0, r, wr);
      for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i) {
            rule.points.push_back(p[i] * (1.0 - r[k]));
            rule.points.push_back(p[j] * (1.0 - r[k]));
            rule.points.push_back(r[k]);
            rule.weights.push_back(wp[i] * wp[j] * wr[k]);
          }
      return rule;
    default:
      throw ParameterError("no quadrature rule for " + cellShortName(type));
  }
}

Eigen::MatrixXd pointRows(const QuadratureRule& rule, const Eigen::MatrixXd& after) {
  Eigen::MatrixXd rows(rule.size() + after.rows(), rule.dim);
  for (int q = 0; q < rule.size(); ++q)
    for (int k = 0; k < rule.dim; ++k)
      rows(q, k) = rule.points[static_cast<std::size_t>(q) * rule.dim + k];
  if (after.rows() > 0) rows.bottomRows(after.rows()) = after;
  return rows;
}

}  // namespace homesh
