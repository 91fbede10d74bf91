// Scaled Jacobian of curved elements, sampled.
//
// J(xi) = det(dx/dxi) is sampled at the points of a quadrature rule of degree 2P+2 and at the
// element's nodes; the element's scaled Jacobian is min J / max J over these samples (1 for a
// straight-sided simplex; <= 0 means invalid). An element whose sampled J is nowhere positive
// gets -1. For 2D meshes J = (dx/dxi x dx/deta) . n with n the mesh's plane normal.
// Boundary cells (triangles on CAD faces, lines on CAD curves) get the same ratio of their
// area (length) element |dx/dxi x dx/deta| (|dx/dxi|): how unevenly curving stretched them.
// Sampling can miss a negative J between samples; certified bounds come with the Bezier check.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// Derivatives of the nodal basis at the sample points of one reference element.
class JacobianSampler {
 public:
  JacobianSampler(CellType type, int order);
  int numSamples() const { return static_cast<int>(dxi_[0].rows()); }
  int numNodes() const { return static_cast<int>(dxi_[0].cols()); }
  // J at each sample for an element whose node coordinates are rows of `x` (numNodes x 3).
  // With `normal` (2D cells only) J is signed; without, it is the area or length element.
  void sample(const Eigen::Matrix<double, Eigen::Dynamic, 3>& x, const Eigen::Vector3d* normal,
              Eigen::VectorXd& jacobians) const;

 private:
  int dim_;
  std::vector<Eigen::MatrixXd> dxi_;  // one per reference direction: numSamples x numNodes
};

struct TypeQuality {
  std::size_t count = 0;
  std::size_t invalid = 0;
  double min = 1.0;
  double mean = 0.0;
};

struct QualitySummary {
  std::vector<double> scaledJacobian;          // per element of dimension mesh.dim, in block order
  std::vector<double> boundaryScaledJacobian;  // per lower-dimensional cell, in block order
  std::size_t invalid = 0;                     // elements with scaled Jacobian <= 0
  double min = 1.0;
  double mean = 0.0;
  std::map<CellType, TypeQuality> byType;
};

double scaledJacobian(double minJ, double maxJ);

// Throws Error for an empty mesh.
QualitySummary evaluateQuality(const Mesh& mesh);

}  // namespace homesh
