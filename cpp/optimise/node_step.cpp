#include "optimise/node_step.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/vector_clones.hpp"

namespace homesh::optimiser {

namespace {

// Armijo constant and the number of halvings before a move is rejected.
constexpr double kArmijo = 1e-3;
constexpr int kLineSearchSteps = 12;

// The Newton step -H^-1 g with H shifted to be positive definite (smallest eigenvalue at least
// 1e-8 of the largest), and its slope g . step; false when there is no descent direction.
template <class M, class V>
bool newtonStep(M h, const V& g, V& step, double& slope) {
  Eigen::SelfAdjointEigenSolver<M> eig;
  if constexpr (M::RowsAtCompileTime == Eigen::Dynamic) {
    eig.compute(h, Eigen::EigenvaluesOnly);
  } else {
    eig.computeDirect(h, Eigen::EigenvaluesOnly);
  }
  const double lmin = eig.eigenvalues().minCoeff();
  const double lmax = eig.eigenvalues().cwiseAbs().maxCoeff();
  if (!(lmax > 0.0)) return false;
  const double floor = 1e-8 * lmax;
  if (lmin < floor) h.diagonal().array() += floor - lmin;
  step = -h.ldlt().solve(g);
  slope = g.dot(step);
  return slope < 0.0 && step.allFinite();
}

// F += d a^T and, by the matrix determinant lemma, J += g . d at every point of the patch, in
// the blocks' own arrays.
template <int D>
HOMESH_VECTOR_CLONES void applyMove(Patch<D>& patch, const Eigen::Matrix<double, D, 1>& d) {
  const NodePatch<D>& pts = patch.points;
  for (const typename Patch<D>::Run& run : patch.runs) {
    Block<D>& b = *run.block;
    const auto n = static_cast<std::size_t>(b.points);
    for (int k = 0; k < D * D; ++k) {
      double* f = b.componentF(run.element, k);
      const double* a = pts.a(k / D) + run.first;
      const double dr = d[k % D];
      for (std::size_t q = 0; q < n; ++q) f[q] += dr * a[q];
    }
    double* J = &b.J[run.element * n];
    for (int c = 0; c < D; ++c) {
      const double* g = pts.g(c) + run.first;
      const double dc = d[c];
      for (std::size_t q = 0; q < n; ++q) J[q] += g[q] * dc;
    }
  }
}

// Whether a step whose quadratic model lowers the energy by -slope / 2 can show at all in the
// patch energy, a sum of pts.size() terms of total size `magnitude`: its rounding is about
// sqrt(n) u magnitude (random-walk model, u the unit roundoff), so a smaller decrease is
// noise and the Armijo test would only halve the step until it gives up.
bool resolvable(double slope, double magnitude, std::size_t points) {
  constexpr double u = std::numeric_limits<double>::epsilon() / 2.0;
  return -0.5 * slope > 4.0 * std::sqrt(static_cast<double>(points)) * u * magnitude;
}

// The facet term's energy of a patch after the node's move by d (3D only).
template <int D>
double facetAfter(const Patch<D>& patch, const Eigen::Matrix<double, D, 1>& d) {
  if constexpr (D == 3) {
    return FacetEnergy::energyAfter(patch.facets, d);
  } else {
    return 0.0;
  }
}

}  // namespace

template <int D>
void NodeStep<D>::buildFacets(const std::vector<std::int64_t>& free, const CadModel* cad) {
  facetEnergy_.reset();
  if constexpr (D == 3) {
    if (!(options_.facetWeight > 0.0 || options_.fidelityWeight > 0.0) || cad == nullptr) return;
    std::vector<std::uint8_t> movable(mesh_.mesh.numNodes(), 0);
    bool any = false;
    for (const std::int64_t node : free)
      if (sliding_.parameters(node) != 0) {
        movable[static_cast<std::size_t>(node)] = 1;
        any = true;
      }
    if (!any) return;
    facetEnergy_ = std::make_unique<FacetEnergy>(mesh_.mesh, mesh_.position, movable,
                                                 options_.facetWeight, options_.fidelityWeight);
    if (facetEnergy_->empty()) {
      facetEnergy_.reset();
      return;
    }
    if (options_.fidelityWeight > 0.0) facetEnergy_->dropApexFacets(mesh_.mesh, *cad);
  }
}

template <int D>
void NodeStep<D>::refreshFacetTargets() {
  if constexpr (D == 3) {
    if (facetEnergy_ != nullptr)
      facetEnergy_->refreshTargets(mesh_.position, mesh_.mesh, sliding_.threadCads());
  }
}

template <int D>
bool NodeStep<D>::touchesFacet(std::int64_t node) const {
  if constexpr (D == 3) {
    return facetEnergy_ != nullptr && facetEnergy_->touches(node);
  } else {
    return false;
  }
}

template <int D>
double NodeStep<D>::facetTotal() {
  if constexpr (D == 3) {
    if (facetsOn_ && hasFacets()) return facetEnergy_->total(mesh_.position);
  }
  return 0.0;
}

// The facet term of `node` added to grad and hess (facet_energy.hpp); fills patch.facets.
template <int D>
double NodeStep<D>::facetAssemble(std::int64_t node, Vec& grad, Mat& hess, Patch<D>& patch,
                                  double& size) const {
  if constexpr (D == 3) {
    return facetEnergy_->assemble(node, mesh_.position, grad, hess, patch.facets, &size);
  } else {
    return 0.0;
  }
}

template <int D>
HOMESH_VECTOR_CLONES double NodeStep<D>::gather(std::int64_t node, Patch<D>& patch) {
  std::size_t total = 0;
  for (std::size_t k = mesh_.incidenceStart[node]; k < mesh_.incidenceStart[node + 1]; ++k)
    total += static_cast<std::size_t>(mesh_.blocks[mesh_.incidence[k].block].points);
  NodePatch<D>& pts = patch.points;
  pts.reset(total);
  patch.runs.clear();
  double jmin = std::numeric_limits<double>::infinity();
  for (std::size_t k = mesh_.incidenceStart[node]; k < mesh_.incidenceStart[node + 1]; ++k) {
    const Incidence& inc = mesh_.incidence[k];
    Block<D>& b = mesh_.blocks[inc.block];
    const std::size_t e = inc.element;
    const auto n = static_cast<std::size_t>(b.points);
    const std::size_t first = pts.append(n, b.componentF(e, 0), n);
    patch.runs.push_back({&b, e, first});
    std::copy_n(&b.weights[e * n], n, pts.weight() + first);
    const double* J = &b.J[e * n];
    for (std::size_t q = 0; q < n; ++q) jmin = std::min(jmin, J[q]);
    // a = (dx_I/dxi)^-T grad_xi l_node at every point.
    const double* grad[D];
    for (int c = 0; c < D; ++c) grad[c] = b.gradient(inc.local, c);
    for (int r = 0; r < D; ++r) {
      double* a = pts.a(r) + first;
      if (b.affine) {
        const Mat& m = b.idealInvT[e];
        for (std::size_t q = 0; q < n; ++q) {
          double v = 0.0;
          for (int c = 0; c < D; ++c) v += m(r, c) * grad[c][q];
          a[q] = v;
        }
      } else {
        for (std::size_t q = 0; q < n; ++q) {
          const Mat& m = b.invT(e, static_cast<int>(q));
          double v = 0.0;
          for (int c = 0; c < D; ++c) v += m(r, c) * grad[c][q];
          a[q] = v;
        }
      }
    }
  }
  return jmin < 0.0 ? std::sqrt(1e-8 + 0.04 * jmin * jmin) : 1e-10;
}

template <int D>
double NodeStep<D>::visit(std::int64_t node, Patch<D>& patch) {
  return functional_detail::dispatch(
      options_.functional, [&](auto fn) { return visitWith<decltype(fn)::value>(node, patch); });
}

template <int D>
template <Functional Fn>
double NodeStep<D>::visitWith(std::int64_t node, Patch<D>& patch) {
  const double eps = gather(node, patch);
  Vec grad;
  Mat hess;
  double magnitude = 0.0;
  const double e0 = assemblePatch<D, Fn>(patch.points, eps, grad, hess, &magnitude);
  if (!std::isfinite(e0) || !grad.allFinite() || !hess.allFinite()) return 0.0;
  if (sliding_.parameters(node) != 0) return slide<Fn>(node, patch, eps, e0, magnitude, grad, hess);
  const std::size_t points = patch.points.size();
  Vec step;
  double slope = 0.0;
  if (!lockedNormal_.empty() && lockedNormal_[node].allFinite()) {
    // Newton in the plane perpendicular to the locked direction.
    const Vec n = lockedNormal_[node];
    Eigen::Matrix<double, D, D - 1> t;
    if constexpr (D == 2) {
      t.col(0) = Vec(-n(1), n(0));
    } else {
      const Vec a = std::abs(n(0)) < 0.9 ? Vec::UnitX() : Vec::UnitY();
      t.col(0) = n.cross(a).normalized();
      t.col(1) = n.cross(Vec(t.col(0)));
    }
    const Eigen::Matrix<double, D - 1, 1> g = t.transpose() * grad;
    Eigen::Matrix<double, D - 1, 1> s;
    if (!newtonStep(Eigen::Matrix<double, D - 1, D - 1>(t.transpose() * hess * t), g, s, slope) ||
        !resolvable(slope, magnitude, points))
      return 0.0;
    step = t * s;
  } else if (!newtonStep(hess, grad, step, slope) || !resolvable(slope, magnitude, points)) {
    return 0.0;
  }
  double alpha = 1.0;
  for (int ls = 0; ls < kLineSearchSteps; ++ls, alpha *= 0.5) {
    const Vec d = alpha * step;
    if (patchEnergyAfter<D, Fn>(patch.points, d, eps) <= e0 + kArmijo * alpha * slope) {
      mesh_.position[node] += d;
      applyMove(patch, d);
      return d.norm();
    }
  }
  return 0.0;
}

// A Newton step of a node on a CAD curve (face) in its parameter t ((u, v)), then a
// backtracking line search. The full step is evaluated on the CAD (it is accepted at about 98
// % of visits); the shorter trial points lie on the curve's (face's) second-order model at the
// node (cad_local_model.hpp), and the one the model accepts is evaluated on the CAD and kept if
// it passes the same test there. So the node never leaves the CAD, and the accepted
// evaluation's derivatives are the node's model for its next visit: about one CAD evaluation
// per visit. Where the model misled (its point passed, the CAD's did not), the search goes on
// with exact points.
template <int D>
template <Functional Fn>
double NodeStep<D>::slide(std::int64_t node, Patch<D>& patch, double eps, double e0,
                          double magnitude, const Vec& grad, const Mat& hess) {
  try {
    return slideOn<Fn>(sliding_.threadCad(), node, patch, eps, e0, magnitude, grad, hess);
  } catch (const CadError&) {
    return 0.0;  // the CAD cannot be evaluated there (a degenerate point): the node stays
  }
}

template <int D>
template <Functional Fn>
double NodeStep<D>::slideOn(const CadModel& cad, std::int64_t node, Patch<D>& patch, double eps,
                            double volumeEnergy, double magnitude, const Vec& volumeGrad,
                            const Mat& volumeHess) {
  double* param = &mesh_.mesh.nodeCadParam[2 * node];
  ++patch.slides;
  const LocalCadModel<D>& model = sliding_.currentModel(cad, node, patch.cadEvaluations);
  // The boundary facets' term joins the volume patch's once the mesh is valid (facetsOn_).
  double e0 = volumeEnergy;
  Vec grad = volumeGrad;
  Mat hess = volumeHess;
  const bool facets = facetsOn_ && hasFacets();
  if (facets) {
    double size = 0.0;
    const double ef = facetAssemble(node, grad, hess, patch, size);
    if (!std::isfinite(ef)) return 0.0;
    e0 += ef;
    magnitude += size;
  }
  const auto energyAfter = [&](const Vec& d) {
    const double e = patchEnergyAfter<D, Fn>(patch.points, d, eps);
    return facets ? e + facetAfter(patch, d) : e;
  };
  Eigen::VectorXd g;
  Eigen::MatrixXd h;
  model.chainRule(grad, hess, g, h);
  if (!g.allFinite() || !h.allFinite()) return 0.0;
  Eigen::VectorXd step;
  double slope = 0.0;
  if (!newtonStep(h, g, step, slope) || !resolvable(slope, magnitude, patch.points.size()))
    return 0.0;
  bool exact = false;  // set once the model has misled the search at this node
  // The model's error seen at the full step (the CAD's point is known there) and that step's
  // length in parameters: the error shrinks like the cube of the step (cad_local_model.hpp).
  double fullError = 0.0, fullStep = 0.0;
  double alpha = 1.0;
  for (int ls = 0; ls < kLineSearchSteps; ++ls, alpha *= 0.5) {
    const std::array<double, 2> trial = sliding_.trial(node, param, alpha, step);
    const double bound = e0 + kArmijo * alpha * slope;
    const double dp[2] = {trial[0] - param[0], trial[1] - param[1]};
    if (ls > 0 && !exact) {
      // Rejected on the model only when it misses the bound by more than the model's error
      // can change the energy: (|grad| + |hess| |d|) times twice the cubic scaling of the
      // error at the full step, so that borderline points are decided on the CAD.
      const Vec d = model.at(dp) - mesh_.position[node];
      const double r = std::min(1.0, std::hypot(dp[0], dp[1]) / fullStep);
      const double slack = (grad.norm() + hess.norm() * d.norm()) * 2.0 * fullError * r * r * r;
      if (!(energyAfter(d) <= bound + slack)) continue;
    }
    ++patch.cadEvaluations;
    LocalCadModel<D> next = sliding_.localModel(cad, node, trial.data());
    const Vec d = next.point - mesh_.position[node];
    if (energyAfter(d) <= bound) {
      mesh_.position[node] = next.point;
      param[0] = trial[0];
      param[1] = trial[1];
      applyMove(patch, d);
      sliding_.keepModel(node, next);
      return d.norm();
    }
    if (ls == 0) {
      fullError = (next.point - model.at(dp)).norm();
      fullStep = std::hypot(dp[0], dp[1]);
    }
    exact = ls > 0;
  }
  return 0.0;
}

template <int D>
NodeEnergy NodeStep<D>::probe(std::int64_t node, const Eigen::VectorXd& coordinates, double eps) {
  return functional_detail::dispatch(options_.functional, [&](auto fn) {
    Patch<D> patch;
    gather(node, patch);
    const int parameters = sliding_.parameters(node);
    Vec shift;
    if (parameters == 0) {
      shift = coordinates - mesh_.position[node];
    } else {
      const double param[2] = {coordinates[0], parameters == 2 ? coordinates[1] : 0.0};
      shift = sliding_.pointOn(sliding_.threadCad(), node, param) - mesh_.position[node];
    }
    Vec grad;
    Mat hess;
    NodeEnergy out;
    patch.points.shift(shift);
    out.value =
        assemblePatch<D, decltype(fn)::value>(patch.points, eps, grad, hess, &out.magnitude);
    if (parameters != 0 && hasFacets()) {  // as a step on a valid mesh has it
      const Vec kept = mesh_.position[node];
      mesh_.position[node] += shift;
      double size = 0.0;
      const double ef = facetAssemble(node, grad, hess, patch, size);
      mesh_.position[node] = kept;
      out.value += ef;
      out.magnitude += size;
    }
    if (parameters == 0) {
      out.gradient = grad;
      out.hessian = hess;
    } else {
      sliding_.localModel(sliding_.threadCad(), node, coordinates.data())
          .chainRule(grad, hess, out.gradient, out.hessian);
    }
    return out;
  });
}

template class NodeStep<2>;
template class NodeStep<3>;

}  // namespace homesh::optimiser
