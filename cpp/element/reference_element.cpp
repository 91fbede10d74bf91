#include "element/reference_element.hpp"

#include <Eigen/LU>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "element/simplex_basis.hpp"

namespace homesh {

namespace {
constexpr int kMaxOrder = 10;
}

const ReferenceElement& ReferenceElement::get(CellType type, int order) {
  static std::mutex mutex;
  static std::map<std::pair<CellType, int>, std::unique_ptr<ReferenceElement>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{type, order}];
  if (!slot) slot = std::make_unique<ReferenceElement>(type, order);
  return *slot;
}

ReferenceElement::ReferenceElement(CellType type, int order)
    : type_(type), order_(order), dim_(cellDimension(type)) {
  if (order < 1 || order > kMaxOrder)
    throw ParameterError("element order must be in 1.." + std::to_string(kMaxOrder) + ", got " +
                         std::to_string(order));
  lattice_ = simplexLattice(type, order, NodeConvention::Gmsh);
  const int n = numNodes();
  nodes_.resize(n, dim_);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < dim_; ++k) nodes_(i, k) = static_cast<double>(lattice_[i][k + 1]) / order;

  Eigen::MatrixXd vandermonde(n, n);
  Eigen::VectorXd psi;
  Eigen::MatrixXd dpsi;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd xi = nodes_.row(i).transpose();
    simplexBasis(type, order, xi.data(), psi, dpsi);
    vandermonde.row(i) = psi.transpose();
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(vandermonde);
  if (!lu.isInvertible())
    throw Error("reference element: singular Vandermonde matrix for " + cellShortName(type) +
                " of order " + std::to_string(order));
  inverseVandermonde_ = lu.inverse();
}

void ReferenceElement::evaluate(const double* xi, Eigen::VectorXd& values,
                                Eigen::MatrixXd& gradients) const {
  Eigen::VectorXd psi;
  Eigen::MatrixXd dpsi;
  simplexBasis(type_, order_, xi, psi, dpsi);
  values.noalias() = inverseVandermonde_.transpose() * psi;
  gradients.noalias() = inverseVandermonde_.transpose() * dpsi;
}

}  // namespace homesh
