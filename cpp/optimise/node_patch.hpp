// The quadrature points around one node, stored structure-of-arrays, and the per-node energy
// kernels of the optimiser on them: the patch energy with its gradient and Hessian in the node's
// displacement, and the energy after a trial displacement (the optimiser applies an accepted
// one to its own F and J with the rank-one terms kept here).
//
// The formulas are functional.hpp's (W = psi(S, J_r), F(delta) = F + delta a^T); this file only
// lays the points out so the loops over them vectorise: one array per component of F, of a and
// of the rank-one terms, and the transcendental (log, cube root) in a loop of its own, since a
// libm call in a loop stops the compiler's vectoriser (the log is vector_log.hpp's, which
// vectorises). The kernels are compiled for AVX2 as well as for the baseline
// (core/vector_clones.hpp). The linear elastic W, quartic in delta, goes point by point through
// functional.hpp.
//
// Sums over points are vectorised reductions: their order differs from a plain loop's, so the
// results agree with functional.hpp's to rounding, not bit for bit (tests/cpp/optimise).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/vector_clones.hpp"
#include "optimise/functional.hpp"
#include "optimise/vector_log.hpp"

namespace homesh {

template <int D>
class NodePatch {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;

  // Component k of F is F(k % D, k / D) (Eigen's column-major order).
  static constexpr int kF = D * D;

  // The points of one element: F is read where the optimiser keeps it (component k of the
  // run's point j at F[k * stride + j]), not copied; the other arrays are the patch's own, from
  // index `first` on.
  struct Run {
    const double* F;
    std::size_t stride, first, count;
  };

  // Empties the patch and makes room for `points` points.
  void reset(std::size_t points) {
    n_ = 0;
    runs_.clear();
    if (points > capacity_) {
      capacity_ = points + points / 2;
      data_.assign(kColumns * capacity_, 0.0);
    }
  }
  // Appends `count` points (within reset's room) whose F is at `F` (see Run); returns the
  // index of the first.
  std::size_t append(std::size_t count, const double* F, std::size_t stride) {
    const std::size_t first = n_;
    runs_.push_back({F, stride, first, count});
    n_ += count;
    return first;
  }
  std::size_t size() const { return n_; }
  const std::vector<Run>& runs() const { return runs_; }

  double* a(int c) { return column(kFirstA + c); }
  const double* a(int c) const { return column(kFirstA + c); }
  double* weight() { return column(kWeight); }
  const double* weight() const { return column(kWeight); }
  // The rank-one terms of each point, filled by assemblePatch for patchEnergyAfter and the
  // move's update: |F|^2, det F, |a|^2, F a, cof(F) a.
  double* SF() { return column(kSF); }
  const double* SF() const { return column(kSF); }
  double* J() { return column(kJ); }
  const double* J() const { return column(kJ); }
  double* aa() { return column(kAA); }
  const double* aa() const { return column(kAA); }
  double* fa(int c) { return column(kFirstFA + c); }
  const double* fa(int c) const { return column(kFirstFA + c); }
  double* g(int c) { return column(kFirstG + c); }
  const double* g(int c) const { return column(kFirstG + c); }
  // Scratch for the kernels: J_r, its derivatives, and the transcendental of J_r.
  double* scratch(int s) { return column(kFirstScratch + s); }

  Mat matrixF(const Run& run, std::size_t j) const {
    Mat m;
    for (int k = 0; k < kF; ++k)
      m(k % D, k / D) = run.F[static_cast<std::size_t>(k) * run.stride + j];
    return m;
  }
  Vec vectorA(std::size_t i) const {
    Vec v;
    for (int c = 0; c < D; ++c) v[c] = a(c)[i];
    return v;
  }

  // F + delta a^T at every point, in a copy of F the patch owns from then on (the probe's trial
  // positions; the optimiser's own F is left as it is).
  void shift(const Vec& delta) {
    for (Run& run : runs_) {
      for (int k = 0; k < kF; ++k) {
        double* f = column(kFirstF + k) + run.first;
        const double* src = run.F + static_cast<std::size_t>(k) * run.stride;
        const double* ac = a(k / D) + run.first;
        const double dr = delta[k % D];
        for (std::size_t j = 0; j < run.count; ++j) f[j] = src[j] + dr * ac[j];
      }
      run.F = column(kFirstF) + run.first;
      run.stride = capacity_;
    }
  }

 private:
  static constexpr int kFirstF = 0, kFirstA = kF, kWeight = kFirstA + D, kSF = kWeight + 1,
                       kJ = kSF + 1, kAA = kJ + 1, kFirstFA = kAA + 1, kFirstG = kFirstFA + D,
                       kFirstScratch = kFirstG + D, kColumns = kFirstScratch + 4;
  double* column(int c) { return data_.data() + static_cast<std::size_t>(c) * capacity_; }
  const double* column(int c) const {
    return data_.data() + static_cast<std::size_t>(c) * capacity_;
  }

  std::vector<double> data_;  // [column][point]
  std::vector<Run> runs_;
  std::size_t n_ = 0, capacity_ = 0;
};

namespace patch_detail {

// J_r and its derivatives (functional.hpp's regularise) with the far case selected, not
// branched to, so the loop that calls it vectorises.
[[gnu::always_inline]] inline Regularised<double> regularised(double J, double eps) {
  const Regularised<double> far = regulariseFar(J, eps), near = regulariseNear(J, eps);
  const bool isFar = J > 1e9 * eps;
  Regularised<double> out;
  out.r = isFar ? far.r : near.r;
  out.dr = isFar ? far.dr : near.dr;
  out.ddr = isFar ? far.ddr : near.ddr;
  return out;
}

// The transcendental psi needs of r (functional.hpp's transcendentalOf) at n points; ln r by
// vectorLog, which vectorises (vector_log.hpp: within a unit in the last place of std::log).
template <int D, Functional Fn>
[[gnu::always_inline]] inline void transcendental(const double* r, double* t, std::size_t n) {
  if constexpr (Fn == Functional::Hyperelastic || Fn == Functional::LinearElastic) {
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) t[i] = vectorLog(r[i]);
  } else {
    for (std::size_t i = 0; i < n; ++i) t[i] = functional_detail::transcendentalOf<D, Fn>(r[i]);
  }
}

// psi and its derivatives (functional.hpp's psi) from r and t = transcendental(r); the values
// for !(r > 0) are the barrier's (infinite value, no derivatives), selected, not branched to.
template <int D, Functional Fn>
[[gnu::always_inline]] inline functional_detail::Psi<double> psiFrom(double S, double r, double t) {
  functional_detail::Psi<double> p = functional_detail::psiOf<D, Fn>(S, r, t);
  const bool ok = r > 0.0;
  p.v = ok ? p.v : std::numeric_limits<double>::infinity();
  p.s = ok ? p.s : 0.0;
  p.r = ok ? p.r : 0.0;
  p.sr = ok ? p.sr : 0.0;
  p.rr = ok ? p.rr : 0.0;
  return p;
}

// J_r (and its derivatives) at n points. A run whose every J is far from inversion, the common
// case, takes J_r = J without the square root and divisions of the general formula.
[[gnu::always_inline]] inline bool allFar(const double* J, std::size_t n, double eps) {
  double lowest = std::numeric_limits<double>::infinity();
#pragma omp simd reduction(min : lowest)
  for (std::size_t i = 0; i < n; ++i) lowest = std::min(lowest, J[i]);
  return lowest > 1e9 * eps;
}
[[gnu::always_inline]] inline void regulariseAll(const double* J, std::size_t n, double eps,
                                                 double* r, double* dr, double* ddr) {
  if (allFar(J, n, eps)) {
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      const Regularised<double> reg = regulariseFar(J[i], eps);
      r[i] = reg.r;
      dr[i] = reg.dr;
      ddr[i] = reg.ddr;
    }
    return;
  }
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const Regularised<double> reg = regularised(J[i], eps);
    r[i] = reg.r;
    dr[i] = reg.dr;
    ddr[i] = reg.ddr;
  }
}

// Pass 1 of assemblePatch, on one run: at every point |F|^2, J = det F, |a|^2, F a,
// g = cof(F) a, and J_r with its derivatives into r, dr, ddr.
template <int D>
[[gnu::always_inline]] inline void rankOneTerms(NodePatch<D>& p,
                                                const typename NodePatch<D>::Run& run, double eps,
                                                double* r, double* dr, double* ddr) {
  const std::size_t n = run.count, o = run.first, s = run.stride;
  double* SF = p.SF() + o;
  double* J = p.J() + o;
  double* aa = p.aa() + o;
  r += o;
  dr += o;
  ddr += o;
  if constexpr (D == 3) {
    const double *f00 = run.F, *f10 = f00 + s, *f20 = f10 + s, *f01 = f20 + s, *f11 = f01 + s,
                 *f21 = f11 + s, *f02 = f21 + s, *f12 = f02 + s, *f22 = f12 + s;
    const double *a0 = p.a(0) + o, *a1 = p.a(1) + o, *a2 = p.a(2) + o;
    double *fa0 = p.fa(0) + o, *fa1 = p.fa(1) + o, *fa2 = p.fa(2) + o, *g0 = p.g(0) + o,
           *g1 = p.g(1) + o, *g2 = p.g(2) + o;
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      const double x00 = f00[i], x10 = f10[i], x20 = f20[i], x01 = f01[i], x11 = f11[i],
                   x21 = f21[i], x02 = f02[i], x12 = f12[i], x22 = f22[i];
      // cof(r, c) = F(r1, c1) F(r2, c2) - F(r1, c2) F(r2, c1) with r1, r2 = r + 1, r + 2 mod 3.
      const double c00 = x11 * x22 - x12 * x21, c01 = x12 * x20 - x10 * x22,
                   c02 = x10 * x21 - x11 * x20;
      const double c10 = x21 * x02 - x22 * x01, c11 = x22 * x00 - x20 * x02,
                   c12 = x20 * x01 - x21 * x00;
      const double c20 = x01 * x12 - x02 * x11, c21 = x02 * x10 - x00 * x12,
                   c22 = x00 * x11 - x01 * x10;
      const double b0 = a0[i], b1 = a1[i], b2 = a2[i];
      const double det = x00 * c00 + x01 * c01 + x02 * c02;
      g0[i] = c00 * b0 + c01 * b1 + c02 * b2;
      g1[i] = c10 * b0 + c11 * b1 + c12 * b2;
      g2[i] = c20 * b0 + c21 * b1 + c22 * b2;
      fa0[i] = x00 * b0 + x01 * b1 + x02 * b2;
      fa1[i] = x10 * b0 + x11 * b1 + x12 * b2;
      fa2[i] = x20 * b0 + x21 * b1 + x22 * b2;
      aa[i] = b0 * b0 + b1 * b1 + b2 * b2;
      SF[i] = x00 * x00 + x10 * x10 + x20 * x20 + x01 * x01 + x11 * x11 + x21 * x21 + x02 * x02 +
              x12 * x12 + x22 * x22;
      J[i] = det;
    }
  } else {
    const double *f00 = run.F, *f10 = f00 + s, *f01 = f10 + s, *f11 = f01 + s;
    const double *a0 = p.a(0) + o, *a1 = p.a(1) + o;
    double *fa0 = p.fa(0) + o, *fa1 = p.fa(1) + o, *g0 = p.g(0) + o, *g1 = p.g(1) + o;
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      const double x00 = f00[i], x10 = f10[i], x01 = f01[i], x11 = f11[i];
      const double b0 = a0[i], b1 = a1[i];
      const double det = x00 * x11 - x01 * x10;
      g0[i] = x11 * b0 - x10 * b1;  // cof = [[F11, -F10], [-F01, F00]]
      g1[i] = -x01 * b0 + x00 * b1;
      fa0[i] = x00 * b0 + x01 * b1;
      fa1[i] = x10 * b0 + x11 * b1;
      aa[i] = b0 * b0 + b1 * b1;
      SF[i] = x00 * x00 + x10 * x10 + x01 * x01 + x11 * x11;
      J[i] = det;
    }
  }
  regulariseAll(J, n, eps, r, dr, ddr);
}

// What point i adds to the patch's sums, each times its weight: the energy, the size (|W| +
// |F|^2), the factors of dS, g g^T and (dS g^T + g dS^T) in the gradient and Hessian (psi_S,
// psi_J, psi_JJ, psi_SJ), and psi_S times S's second derivative 2 |a|^2 on the diagonal.
struct PointSums {
  double e, size, s, j, jj, sj, diag;
};
template <int D, Functional Fn>
[[gnu::always_inline]] inline PointSums pointSums(double w, double SF, double aa, double r,
                                                  double t, double dr, double ddr) {
  const functional_detail::Psi<double> ps = psiFrom<D, Fn>(SF, r, t);
  return {w * ps.v,           w * (std::abs(ps.v) + SF),          w * ps.s,
          w * ps.r * dr,      w * (ps.rr * dr * dr + ps.r * ddr), w * ps.sr * dr,
          w * ps.s * 2.0 * aa};
}

}  // namespace patch_detail

// The patch energy sum_i w_i W(F_i) and its gradient and Hessian in the node's displacement;
// fills the patch's rank-one terms. `magnitude`, if given, receives sum_i w_i (|W_i| + |F_i|^2).
template <int D, Functional Fn>
HOMESH_VECTOR_CLONES double assemblePatch(NodePatch<D>& p, double eps,
                                          Eigen::Matrix<double, D, 1>& grad,
                                          Eigen::Matrix<double, D, D>& hess,
                                          double* magnitude = nullptr) {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  if constexpr (Fn == Functional::LinearElastic) {
    // Quartic in delta: point by point through functional.hpp (of the rank-one terms only det F
    // and cof(F) a are kept, for applyPatchMove).
    double e0 = 0.0, size = 0.0;
    grad.setZero();
    hess.setZero();
    Vec g;
    Mat h;
    RankOneTerms<D, double> terms;
    for (const typename NodePatch<D>::Run& run : p.runs())
      for (std::size_t j = 0; j < run.count; ++j) {
        const std::size_t i = run.first + j;
        const Mat F = p.matrixF(run, j);
        const double w = p.weight()[i];
        const double v = energyDensityDerivatives<D, Fn>(F, p.vectorA(i), eps, g, h, &terms);
        p.J()[i] = terms.J;
        for (int c = 0; c < D; ++c) p.g(c)[i] = terms.g[c];
        e0 += w * v;
        size += w * (std::abs(v) + F.squaredNorm());
        grad += w * g;
        hess += w * h;
      }
    if (magnitude != nullptr) *magnitude = size;
    return e0;
  } else {
    const std::size_t n = p.size();
    double* rr = p.scratch(0);
    double* dr = p.scratch(1);
    double* ddr = p.scratch(2);
    double* tr = p.scratch(3);
    // Pass 1: the rank-one terms and J_r (written out per dimension: an inner loop or a local
    // array in the body stops GCC's if-conversion, and with it the vectoriser).
    for (const typename NodePatch<D>::Run& run : p.runs())
      patch_detail::rankOneTerms<D>(p, run, eps, rr, dr, ddr);
    patch_detail::transcendental<D, Fn>(rr, tr, n);
    // Pass 2: psi, and the sums.
    double e0 = 0.0, size = 0.0;
    double gs[D] = {}, hs[D][D] = {}, diag = 0.0;
    const double* w = p.weight();
    const double* SF = p.SF();
    const double* aa = p.aa();
    const double *fa[D], *g[D];
    for (int c = 0; c < D; ++c) {
      fa[c] = p.fa(c);
      g[c] = p.g(c);
    }
    // dS = 2 F a; the Hessian's psi_SJ term (dS g^T + g dS^T) vanishes for the elastic W.
    if constexpr (D == 3) {
      double g0 = 0, g1 = 0, g2 = 0, h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0;
#pragma omp simd reduction(+ : e0, size, g0, g1, g2, h00, h01, h02, h11, h12, h22, diag)
      for (std::size_t i = 0; i < n; ++i) {
        const patch_detail::PointSums t =
            patch_detail::pointSums<D, Fn>(w[i], SF[i], aa[i], rr[i], tr[i], dr[i], ddr[i]);
        const double d0 = 2.0 * fa[0][i], d1 = 2.0 * fa[1][i], d2 = 2.0 * fa[2][i];
        const double q0 = g[0][i], q1 = g[1][i], q2 = g[2][i];
        e0 += t.e;
        size += t.size;
        diag += t.diag;
        g0 += t.s * d0 + t.j * q0;
        g1 += t.s * d1 + t.j * q1;
        g2 += t.s * d2 + t.j * q2;
        h00 += t.jj * q0 * q0 + t.sj * 2.0 * d0 * q0;
        h01 += t.jj * q0 * q1 + t.sj * (d0 * q1 + q0 * d1);
        h02 += t.jj * q0 * q2 + t.sj * (d0 * q2 + q0 * d2);
        h11 += t.jj * q1 * q1 + t.sj * 2.0 * d1 * q1;
        h12 += t.jj * q1 * q2 + t.sj * (d1 * q2 + q1 * d2);
        h22 += t.jj * q2 * q2 + t.sj * 2.0 * d2 * q2;
      }
      gs[0] = g0;
      gs[1] = g1;
      gs[2] = g2;
      hs[0][0] = h00;
      hs[0][1] = h01;
      hs[0][2] = h02;
      hs[1][1] = h11;
      hs[1][2] = h12;
      hs[2][2] = h22;
    } else {
      double g0 = 0, g1 = 0, h00 = 0, h01 = 0, h11 = 0;
#pragma omp simd reduction(+ : e0, size, g0, g1, h00, h01, h11, diag)
      for (std::size_t i = 0; i < n; ++i) {
        const patch_detail::PointSums t =
            patch_detail::pointSums<D, Fn>(w[i], SF[i], aa[i], rr[i], tr[i], dr[i], ddr[i]);
        const double d0 = 2.0 * fa[0][i], d1 = 2.0 * fa[1][i];
        const double q0 = g[0][i], q1 = g[1][i];
        e0 += t.e;
        size += t.size;
        diag += t.diag;
        g0 += t.s * d0 + t.j * q0;
        g1 += t.s * d1 + t.j * q1;
        h00 += t.jj * q0 * q0 + t.sj * 2.0 * d0 * q0;
        h01 += t.jj * q0 * q1 + t.sj * (d0 * q1 + q0 * d1);
        h11 += t.jj * q1 * q1 + t.sj * 2.0 * d1 * q1;
      }
      gs[0] = g0;
      gs[1] = g1;
      hs[0][0] = h00;
      hs[0][1] = h01;
      hs[1][1] = h11;
    }
    for (int r = 0; r < D; ++r) {
      grad[r] = gs[r];
      for (int c = r; c < D; ++c) hess(r, c) = hess(c, r) = hs[r][c];
      hess(r, r) += diag;
    }
    if (magnitude != nullptr) *magnitude = size;
    return e0;
  }
}

// The patch energy with the node moved by d from where F has it (after assemblePatch, whose
// terms it reads). Infinite or NaN where a point inverts without regularisation.
template <int D, Functional Fn>
HOMESH_VECTOR_CLONES double patchEnergyAfter(NodePatch<D>& p, const Eigen::Matrix<double, D, 1>& d,
                                             double eps) {
  if constexpr (Fn == Functional::LinearElastic) {
    double e1 = 0.0;
    for (const typename NodePatch<D>::Run& run : p.runs())
      for (std::size_t j = 0; j < run.count; ++j) {
        const std::size_t i = run.first + j;
        const Eigen::Matrix<double, D, D> F = p.matrixF(run, j) + d * p.vectorA(i).transpose();
        e1 += p.weight()[i] * energyDensity<D, Fn>(F, eps);
      }
    return e1;
  } else {
    const std::size_t n = p.size();
    double* S = p.scratch(0);
    double* r = p.scratch(1);
    double* t = p.scratch(3);
    const double* SF = p.SF();
    const double* J = p.J();
    const double* aa = p.aa();
    const double *fa[D], *g[D];
    for (int c = 0; c < D; ++c) {
      fa[c] = p.fa(c);
      g[c] = p.g(c);
    }
    const double dd = d.squaredNorm();
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      double dfa = 0.0, dg = 0.0;
#pragma GCC unroll 3
      for (int c = 0; c < D; ++c) {
        dfa += d[c] * fa[c][i];
        dg += d[c] * g[c][i];
      }
      S[i] = SF[i] + 2.0 * dfa + dd * aa[i];
      r[i] = J[i] + dg;
    }
    if (!patch_detail::allFar(r, n, eps)) {
#pragma omp simd
      for (std::size_t i = 0; i < n; ++i) r[i] = patch_detail::regularised(r[i], eps).r;
    }
    patch_detail::transcendental<D, Fn>(r, t, n);
    const double* w = p.weight();
    double e1 = 0.0;
#pragma omp simd reduction(+ : e1)
    for (std::size_t i = 0; i < n; ++i)
      e1 += w[i] * patch_detail::psiFrom<D, Fn>(S[i], r[i], t[i]).v;
    return e1;
  }
}

}  // namespace homesh
