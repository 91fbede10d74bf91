// Polynomials in Bernstein (Bezier) form on the reference shapes, exactly.
//
// A space is a product of simplex factors, each with a dimension and a degree: a triangle is one
// 2D factor, a hexahedron three 1D factors, a prism a 2D factor times a 1D factor. A basis
// function is a product of one Bernstein polynomial per factor, named by a multi-index per
// factor (without its first barycentric entry). Differentiation and multiplication are exact
// operations on the coefficients, so the Bezier form of a Jacobian determinant is computed from
// the geometry's control points without any ill-conditioned interpolation.
#pragma once

#include <Eigen/Core>
#include <map>
#include <utility>
#include <vector>

namespace homesh {

using BernsteinFactors = std::vector<std::pair<int, int>>;  // (dimension, degree) per factor

class BernsteinSpace {
 public:
  explicit BernsteinSpace(BernsteinFactors factors);

  const BernsteinFactors& factors() const { return factors_; }
  int dim() const { return dim_; }
  int size() const { return static_cast<int>(indices_.size()); }

  // Value of basis function j at reference point x (dim() coordinates).
  double basis(int j, const double* x) const;
  // Whether basis function j is 1 at a corner of the shape (its coefficient is a value).
  bool isCorner(int j) const;
  // Position of basis function j on the shape (its multi-index / degree, per coordinate).
  Eigen::VectorXd point(int j) const;
  // The flattened stored multi-indices of basis function j, and the inverse lookup.
  const std::vector<int>& multiIndex(int j) const { return indices_[j]; }
  int indexOf(const std::vector<int>& flat) const;
  // Product over factors of the multinomial coefficients of basis function j.
  double multinomialWeight(int j) const;

  // d/dx_k: the derivative's coefficients (in derivativeSpace(k)) from ours.
  BernsteinFactors derivativeFactors(int k) const;
  Eigen::VectorXd derivative(int k, const Eigen::VectorXd& coeffs) const;

  // Coefficients of the product of a (in this space) and b (in `other`), in productSpace.
  static BernsteinFactors productFactors(const BernsteinFactors& a, const BernsteinFactors& b);
  Eigen::VectorXd multiply(const Eigen::VectorXd& a, const BernsteinSpace& other,
                           const Eigen::VectorXd& b) const;

  // The (a, b) -> c terms of the product of a function of this space (a) with one of `other`
  // (b) into productFactors' space (c): c += weight * a * b. Cached, thread-safe.
  struct ProductTerm {
    int a, b, c;
    double weight;
  };
  const std::vector<ProductTerm>& productTerms(const BernsteinSpace& other) const;

  // Splitting the domain at the midpoint of one edge of a factor's simplex (between its
  // barycentric slots i and j; slot 0 is the implicit first entry): every line of coefficients
  // parallel to the edge is a 1D Bernstein polynomial, subdivided by de Casteljau. `index`
  // holds the lines one after the other (line l from start[l] to start[l + 1]), each ordered by
  // increasing entry i.
  struct EdgeLines {
    int factor = 0, i = 0, j = 0;
    std::vector<int> start, index;
  };
  const std::vector<EdgeLines>& edgeLines() const { return edgeLines_; }
  // The coefficients on the two halves: `keepJ` where slot i became the edge's midpoint (the
  // half holding slot j's vertex), `keepI` where slot j did. Exact up to rounding (averages).
  static void bisect(const EdgeLines& edge, const double* coeffs, double* keepJ, double* keepI);

  // The shared space for some factors (cached, thread-safe).
  static const BernsteinSpace& get(const BernsteinFactors& factors);

 private:
  BernsteinFactors factors_;
  int dim_ = 0;
  std::vector<std::vector<int>> indices_;  // per function: flattened stored multi-indices
  std::map<std::vector<int>, int> position_;
  std::vector<EdgeLines> edgeLines_;
};

}  // namespace homesh
