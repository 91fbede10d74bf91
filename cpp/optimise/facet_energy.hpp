// The distortion of a 3D mesh's boundary facets within their own surface, an energy term for the
// nodes that slide on the CAD.
//
// Why: a node sliding on a CAD face stays on it, but the volume energy alone lets the nodes of a
// boundary facet bunch up along the face, and the facet's polynomial surface between them then
// leaves the CAD (on the sphere in a box at --size 0.8, order 4: 3.5e-5 from the sphere after
// curving, 8.8e-3 and 11 degrees off its normal after the optimiser). This term measures how far
// each facet's map from its straight-sided (ideal) shape is from a rigid motion, inside the
// surface only: with T = dx/dxi (3 x 2) at a point of the facet and W the ideal facet's 2 x 2
// Jacobian in the plane of its vertices, M = T W^-1 and C = M^T M (the surface metric against
// the ideal's),
//   W_s = (mu/2) (tr C - 2) - mu ln J_s + (K/2) (ln J_s)^2,   J_s = sqrt(det C),
// the hyperelastic density of functional.hpp in two dimensions. It is zero for a facet that is
// its straight shape moved rigidly, and grows with its nodes' bunching and with its shearing and
// stretching in the surface; bending out of the ideal's plane (the curving onto the CAD) costs
// only the stretching it brings. Moving node n by d changes M by d a^T, a = W^-T grad_xi l_n.
//
// The fidelity part measures what the spacing only prevents: how far the facet's surface leaves
// the CAD between its nodes. At each point, with p the point's foot on the CAD face and n the
// CAD's unit normal there (targets, refreshed by refreshTargets: once per sweep),
//   W_f = ((x - p) . n / h)^2 + |M^T n|^2,
// h the ideal facet's size: the distance off the CAD's tangent plane relative to the facet, and
// the squared sine of the angle between the facet's tangent plane and the CAD's (for a facet
// the shape of its ideal), the two quantities the report's geometry measures. Moving node n by
// d changes x by l_n d and M^T n by a (d . n), so W_f is a quadratic in d . n with exact
// derivatives; a tangential slide of a node enters through the other points' normals, which
// differ from its own by the curvature times their distance: the bump the slide makes in the
// interpolant between the nodes. The targets are the last sweep's, a Taylor (lagged) model of
// the distance as Gmsh's and NekMesh's fidelity terms use.
//
// A point enters as rho(W_f) = W_f / (1 + W_f / s), s = sin^2(30 degrees): W_f where the facet
// is within some degrees of the CAD, at most s where it is far off. A point 30 to 90 degrees
// off is no small slide away: the face turns faster than any facet can (the thread of
// OpenCASCADE's bottle, radius of curvature 0.024 under elements ten times larger, where the
// quadratic pulled its facets' nodes until the worst element fell from 0.123 to 0.012; an apex:
// those facets are left out, dropApexFacets), or its foot has left the trimmed face. On the sphere
// in a box, sizes 0.6 to 1.2, orders 2 to 6, the largest normal angle changed by at most 0.3
// degrees against the plain quadratic.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "optimise/functional.hpp"

namespace homesh {

namespace facet_detail {

// W_s at one point from the columns m1, m2 of M; infinite where the facet is degenerate
// (det C <= 0). Templated on the scalar for the derivative tests (AutoDiffScalar).
template <class T>
[[gnu::always_inline]] inline T density(const Eigen::Matrix<T, 3, 1>& m1,
                                        const Eigen::Matrix<T, 3, 1>& m2) {
  using std::log;
  const T c11 = m1.dot(m1), c22 = m2.dot(m2), c12 = m1.dot(m2);
  const T det = c11 * c22 - c12 * c12;
  if (!(det > 0.0)) return T(std::numeric_limits<double>::infinity());
  const T l = 0.5 * log(det);  // ln J_s
  using functional_detail::kBulk;
  using functional_detail::kMu;
  return 0.5 * kMu * (c11 + c22 - 2.0) - kMu * l + 0.5 * kBulk * l * l;
}

// W_s with its gradient and Hessian in d, for M(d) = [m1 + a1 d, m2 + a2 d] at d = 0 (exact:
// det C is a quartic in d and its derivatives below are its own). Returns false (and leaves g,
// h alone) where the facet is degenerate.
template <class T>
[[gnu::always_inline]] inline bool derivatives(const Eigen::Matrix<T, 3, 1>& m1,
                                               const Eigen::Matrix<T, 3, 1>& m2, T a1, T a2,
                                               T& value, Eigen::Matrix<T, 3, 1>& g,
                                               Eigen::Matrix<T, 3, 3>& h) {
  using std::log;
  using V = Eigen::Matrix<T, 3, 1>;
  using M3 = Eigen::Matrix<T, 3, 3>;
  const T c11 = m1.dot(m1), c22 = m2.dot(m2), c12 = m1.dot(m2);
  const T det = c11 * c22 - c12 * c12;
  if (!(det > 0.0)) return false;
  const T l = 0.5 * log(det);
  using functional_detail::kBulk;
  using functional_detail::kMu;
  value = 0.5 * kMu * (c11 + c22 - 2.0) - kMu * l + 0.5 * kBulk * l * l;
  const V d11 = 2.0 * a1 * m1, d22 = 2.0 * a2 * m2, d12 = a2 * m1 + a1 * m2;
  const V dDet = c22 * d11 + c11 * d22 - 2.0 * c12 * d12;
  const M3 ddDet =
      (2.0 * c22 * a1 * a1 + 2.0 * c11 * a2 * a2 - 4.0 * c12 * a1 * a2) * M3::Identity() +
      d11 * d22.transpose() + d22 * d11.transpose() - 2.0 * d12 * d12.transpose();
  const V dl = dDet / (2.0 * det);
  const M3 ddl = ddDet / (2.0 * det) - dDet * dDet.transpose() / (2.0 * det * det);
  const T factor = kBulk * l - kMu;  // dW_s / d ln J_s
  g = kMu * (a1 * m1 + a2 * m2) + factor * dl;
  h = kMu * (a1 * a1 + a2 * a2) * M3::Identity() + factor * ddl + kBulk * dl * dl.transpose();
  return true;
}

}  // namespace facet_detail

// s above: the fidelity part's largest contribution per point, relative to its weight.
inline constexpr double kFidelitySaturation = 0.25;

// The boundary facets around the movable nodes of a 3D mesh, with their ideal shapes and
// quadrature, and the facet energy of one node's facets (as the optimiser's node patch: value,
// gradient and Hessian at the node's position, then values after trial moves).

class FacetEnergy {
 public:
  using Vec = Eigen::Vector3d;
  using Mat = Eigen::Matrix3d;

  // The facets are the cells of `mesh`'s 2D blocks (triangles, quadrilaterals) with at least
  // one node where movable[node] != 0; their ideal shapes are their straight-sided cells at
  // `positions` (in the optimiser's frame, which is the model's in 3D; the start of the run).
  // Each point's weight is `weight` (the distortion's; `fidelity` for the fidelity part) x its
  // quadrature weight x the ideal's area element x the ideal facet's size (sqrt of its area),
  // so that the term scales as the volume energy of the elements below it. The fidelity part
  // is off until refreshTargets(). Throws ParameterError for a facet whose straight cell is
  // degenerate.
  FacetEnergy(const Mesh& mesh, const std::vector<Vec>& positions,
              const std::vector<std::uint8_t>& movable, double weight, double fidelity = 0.0);

  // Leaves out of the fidelity part every facet with a corner at an apex of its CAD face
  // (cad/face_apexes.hpp: a cone's tip), where no facet follows the face's normal; the
  // distortion part keeps them. Returns how many.
  std::size_t dropApexFacets(const Mesh& mesh, const CadModel& cad);

  bool empty() const { return facets_.empty(); }
  std::size_t size() const { return facets_.size(); }

  // The points of one node's facets, filled by assemble() and read by energyAfter().
  struct Patch {
    std::vector<Vec> m1, m2;  // M's columns at the node's current position
    std::vector<double> a1, a2, w;
    // The fidelity part's points: the CAD normal, (x - p) . n / h, l_n / h, M^T n, a, weight.
    std::vector<Vec> normal;
    std::vector<double> r, l, c1, c2, b1, b2, wf;
    void clear();
  };

  // The fidelity part's targets at `positions` (model coordinates in 3D): every point of every
  // facet projected onto its CAD face, starting from its last foot (first: from the facet's
  // node on that face whose basis function is largest there), on one thread per model in
  // `cads` (clones of one model). A point where the CAD's normal is undefined (a pole), or
  // that the CAD cannot project, drops out of the part. A facet none of whose nodes moved since
  // the last refresh keeps its targets: found again from themselves, they would not change
  // beyond the projection's tolerance (and late sweeps move few nodes: on a cylinder of radius 1
  // and length 1000 at order 4, the refresh took 0.4 s a sweep where the sweep took 0.1 s).
  // Nothing without a fidelity weight.
  void refreshTargets(const std::vector<Vec>& positions, const Mesh& mesh,
                      const std::vector<CadModel>& cads);
  bool hasFidelity() const { return fidelity_ > 0.0; }

  // The energy of `node`'s facets at `positions`, with its gradient and Hessian in the node's
  // displacement (added to g and h); fills `patch`. Infinite (g, h untouched) where a facet is
  // degenerate. 0 for a node on no facet. `size`, if given, receives the size of the terms the
  // energy sums, sum w (|W_s| + tr C), for rounding estimates (the energy itself is near 0 close
  // to the ideal while its terms are not).
  double assemble(std::int64_t node, const std::vector<Vec>& positions, Vec& g, Mat& h,
                  Patch& patch, double* size = nullptr) const;
  // Whether `node` is on a facet (a movable node of one).
  bool touches(std::int64_t node) const {
    const auto n = static_cast<std::size_t>(node);
    return n + 1 < start_.size() && start_[n + 1] > start_[n];
  }
  // The same energy with the node moved by d from where assemble() had it.
  static double energyAfter(const Patch& patch, const Vec& d);
  // The energy of every facet at `positions`, summed in facet order. Each facet's share is kept
  // and computed again only where one of its nodes moved or its targets changed since: the
  // same total to the last bit, without a pass over every facet after a sweep that moved few.
  double total(const std::vector<Vec>& positions);

 private:
  struct Shape {  // one facet cell type and order
    const ElementBlock* cells;
    int nodes = 0, points = 0;
    std::vector<double> values;   // [node][point]
    std::vector<double> byPoint;  // basis gradients, [2][node][point]: loops over points vectorise
    std::vector<double> weights;  // quadrature weights
    std::vector<double> linear;   // the linear cell's basis gradients: [vertex][point][2]
    int vertices = 0;
  };
  struct Facet {
    int shape = 0;
    std::size_t cell = 0;
    std::size_t first = 0;   // its points' ideal data in invW_ and scale_
    double size = 0.0;       // the ideal's sqrt(area), h
    bool followsCad = true;  // false: left out of the fidelity part (dropApexFacets)
  };
  struct Incidence {
    std::uint32_t facet;
    int local;
  };
  // The energy of one facet (node `local` moved by nothing), and with derivatives in that
  // node's displacement when `patch` is given.
  double facetEnergy(const Facet& f, const std::vector<Vec>& positions, int local, Vec* g, Mat* h,
                     Patch* patch, double* size = nullptr) const;

  std::vector<Shape> shapes_;
  std::vector<Facet> facets_;
  std::vector<Eigen::Matrix2d> invW_;  // per facet point: W^-1
  std::vector<double> scale_;          // per facet point: quadrature weight x |det W|
  double weight_ = 0.0, fidelity_ = 0.0;
  // The fidelity part's targets per facet point: the foot on the CAD, the unit normal there
  // (zero: undefined, or not refreshed yet) and its face parameters (NaN: none yet).
  std::vector<Vec> foot_, normal_;
  std::vector<std::array<double, 2>> footParam_;
  std::vector<Vec> refreshedAt_;  // per node: its position at the last refresh (empty: none)
  // total()'s shares: per facet its energy and whether its targets changed since (1: compute
  // again), per node its position at the last total (empty: none).
  std::vector<double> share_;
  std::vector<char> shareStale_;
  std::vector<Vec> totalAt_;
  std::vector<std::size_t> start_;  // per node: its facets in incidence_
  std::vector<Incidence> incidence_;
};

}  // namespace homesh
