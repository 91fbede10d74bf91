#include "element/reference_element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "element/cell_table_cache.hpp"
#include "element/orthogonal_basis.hpp"

namespace homesh {

const ReferenceElement& ReferenceElement::get(CellType type, int order, NodeSet set) {
  static CellTableCache<ReferenceElement, 2> cache;  // variants: the node sets
  return cache.get(
      type, order, [&] { return std::make_unique<ReferenceElement>(type, order, set); },
      static_cast<int>(set));
}

ReferenceElement::ReferenceElement(CellType type, int order, NodeSet set)
    : type_(type), order_(order), set_(set), dim_(cellDimension(type)) {
  if (order < 1 || order > kMaxOrder)
    throw ParameterError("element order must be in 1.." + std::to_string(kMaxOrder) + ", got " +
                         std::to_string(order));
  lattice_ = latticeOrder(type, order, NodeConvention::Gmsh);
  nodes_ = nodeCoordinates(type, order, set, lattice_);
  const int n = numNodes();
  Eigen::MatrixXd vandermonde(n, n);
  Eigen::VectorXd psi;
  Eigen::MatrixXd dpsi;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd xi = nodes_.row(i).transpose();
    orthogonalBasis(type, order, xi.data(), psi, dpsi);
    if (psi.size() != n)
      throw Error("reference element: basis size " + std::to_string(psi.size()) + " for " +
                  std::to_string(n) + " nodes of " + cellShortName(type));
    vandermonde.row(i) = psi.transpose();
  }
  // The orthogonal basis keeps V well conditioned; partial pivoting is enough and much faster
  // than full pivoting for the 1331 x 1331 matrix of the order-10 hexahedron.
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(vandermonde);
  if (!(std::abs(lu.determinant()) > 0.0))
    throw Error("reference element: singular Vandermonde matrix for " + cellShortName(type) +
                " of order " + std::to_string(order));
  inverseVandermonde_ = lu.inverse();
}

void ReferenceElement::evaluate(const double* xi, Eigen::VectorXd& values,
                                Eigen::MatrixXd& gradients) const {
  Eigen::VectorXd psi;
  Eigen::MatrixXd dpsi;
  orthogonalBasis(type_, order_, xi, psi, dpsi);
  values.noalias() = inverseVandermonde_.transpose() * psi;
  gradients.noalias() = inverseVandermonde_.transpose() * dpsi;
}

Eigen::MatrixXd ReferenceElement::modalCoefficients(const Eigen::MatrixXd& nodal) const {
  if (nodal.rows() != numNodes())
    throw Error("reference element: " + std::to_string(nodal.rows()) + " nodal rows for " +
                std::to_string(numNodes()) + " nodes");
  return inverseVandermonde_ * nodal;
}

Eigen::RowVectorXd ReferenceElement::interpolate(const Eigen::MatrixXd& modal, const double* xi,
                                                 Eigen::MatrixXd* derivatives) const {
  Eigen::VectorXd psi;
  Eigen::MatrixXd dpsi;
  orthogonalBasis(type_, order_, xi, psi, dpsi);
  if (derivatives != nullptr) derivatives->noalias() = dpsi.transpose() * modal;
  return psi.transpose() * modal;
}

Eigen::MatrixXd ReferenceElement::valuesAt(const Eigen::MatrixXd& points) const {
  Eigen::MatrixXd out(points.rows(), numNodes());
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::VectorXd xi = points.row(r).transpose();
    evaluate(xi.data(), values, gradients);
    out.row(r) = values.transpose();
  }
  return out;
}

std::vector<Eigen::MatrixXd> ReferenceElement::derivativesAt(const Eigen::MatrixXd& points) const {
  std::vector<Eigen::MatrixXd> out(static_cast<std::size_t>(dim_),
                                   Eigen::MatrixXd(points.rows(), numNodes()));
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::VectorXd xi = points.row(r).transpose();
    evaluate(xi.data(), values, gradients);
    for (int k = 0; k < dim_; ++k)
      out[static_cast<std::size_t>(k)].row(r) = gradients.col(k).transpose();
  }
  return out;
}

double ReferenceElement::lebesgueConstant(int samples) const {
  const std::vector<LatticePoint> lattice = samplingLattice(type_, samples);
  Eigen::MatrixXd points = nodeCoordinates(type_, samples, NodeSet::Equispaced, lattice);
  return valuesAt(points).cwiseAbs().rowwise().sum().maxCoeff();
}

std::vector<LatticePoint> samplingLattice(CellType type, int n) {
  std::vector<LatticePoint> points;
  const int dim = cellDimension(type);
  for (int k = 0; k <= (dim > 2 ? n : 0); ++k)
    for (int j = 0; j <= (dim > 1 ? n : 0); ++j)
      for (int i = 0; i <= n; ++i) {
        bool inside = true;
        if (type == CellType::Triangle || type == CellType::Prism) inside = i + j <= n;
        if (type == CellType::Tetrahedron) inside = i + j + k <= n;
        if (type == CellType::Pyramid) inside = std::max(i, j) + k <= n;
        if (inside) points.push_back({i, j, k});
      }
  return points;
}

}  // namespace homesh
