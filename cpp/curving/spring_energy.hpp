// Spacing of high-order nodes on a CAD entity: a spring energy evaluated through the entity's
// parametrisation, minimised over the nodes' parameters.
//
// Nodes carry k = 1 (a curve's t) or k = 2 (a surface's (u, v)) parameters. The energy is
//   E(x) = sum over springs s = (a, b, w) of  w * |r(x_a) - r(x_b)|^2,
// the discrete Dirichlet energy of the node graph on the CAD entity (DESIGN.md section 5: with
// w = 1 / (z_b - z_a) along a resolved edge its minimiser spaces the nodes nearly in arc length;
// over a triangle's lattice it spreads them evenly on the surface). Fixed nodes keep their
// parameters; free ones move by damped Gauss-Newton (Levenberg-Marquardt) steps that never raise E,
// clamped to optional per-parameter bounds. The minimiser promises a lower or equal energy, not a
// well-ordered result: callers check monotonicity and trimming themselves.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace homesh {

// r(x) and its derivatives dr/dx (first k columns used).
struct MappedPoint {
  Eigen::Vector3d point;
  Eigen::Matrix<double, 3, 2> jacobian;
};
using ParameterMap = std::function<MappedPoint(const double* x)>;

struct Spring {
  int a = 0, b = 0;
  double weight = 1.0;
};

struct SpringSystem {
  int paramDim = 1;                     // k: 1 or 2
  std::vector<double> params;           // k per node
  std::vector<char> fixed;              // per node
  std::vector<Eigen::Vector3d> pinned;  // per node; used for fixed nodes (e.g. a pole, where
                                        // r is the same for every u) instead of r(x)
  std::vector<Spring> springs;
  std::vector<double> lower, upper;  // k per node, or empty: no bounds

  int numNodes() const { return static_cast<int>(fixed.size()); }
};

struct SpringResult {
  double initialEnergy = 0.0, finalEnergy = 0.0;
  int iterations = 0;
};

// Lowers the energy of `system` in place (at most `maxIterations` accepted or rejected steps).
// Throws Error if the system's arrays disagree in size.
SpringResult minimiseSprings(SpringSystem& system, const ParameterMap& map, int maxIterations = 40);

}  // namespace homesh
