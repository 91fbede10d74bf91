#include "optimise/facet_energy.hpp"

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "cad/face_apexes.hpp"
#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "core/vector_clones.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {

namespace {

// Whether the `count` nodes `v` are where `then` had them, to the last bit.
bool unmoved(const std::int64_t* v, int count, const std::vector<Eigen::Vector3d>& positions,
             const std::vector<Eigen::Vector3d>& then) {
  return std::all_of(v, v + count, [&](std::int64_t id) {
    const auto n = static_cast<std::size_t>(id);
    return positions[n] == then[n];
  });
}

}  // namespace

FacetEnergy::FacetEnergy(const Mesh& mesh, const std::vector<Vec>& positions,
                         const std::vector<std::uint8_t>& movable, double weight, double fidelity)
    : weight_(weight), fidelity_(fidelity) {
  if (mesh.dim != 3) return;
  for (const ElementBlock& cells : mesh.blocks) {
    if (cellDimension(cells.type) != 2 || cells.count() == 0) continue;
    Shape s;
    s.cells = &cells;
    s.nodes = cells.nodesPerElement();
    const ReferenceElement& ref = ReferenceElement::get(cells.type, cells.order);
    const ReferenceElement& lin = ReferenceElement::get(cells.type, 1);
    s.vertices = lin.numNodes();
    const QuadratureRule rule = quadratureRule(cells.type, 2 * cells.order);
    s.points = rule.size();
    s.weights = rule.weights;
    const Eigen::MatrixXd points = pointRows(rule);
    const auto tabulate = [&](const ReferenceElement& element, std::vector<double>& out) {
      const std::vector<Eigen::MatrixXd> grad = element.derivativesAt(points);
      out.resize(static_cast<std::size_t>(element.numNodes()) * s.points * 2);
      for (int n = 0; n < element.numNodes(); ++n)
        for (int q = 0; q < s.points; ++q)
          for (int k = 0; k < 2; ++k)
            out[(static_cast<std::size_t>(n) * s.points + q) * 2 + k] = grad[k](q, n);
    };
    std::vector<double> gradients;  // [node][point][2], as tabulate writes them
    tabulate(ref, gradients);
    s.byPoint.resize(gradients.size());
    for (int n = 0; n < s.nodes; ++n)
      for (int q = 0; q < s.points; ++q)
        for (int k = 0; k < 2; ++k)
          s.byPoint[(static_cast<std::size_t>(k) * s.nodes + n) * s.points + q] =
              gradients[(static_cast<std::size_t>(n) * s.points + q) * 2 + k];
    tabulate(lin, s.linear);
    const Eigen::MatrixXd values = ref.valuesAt(points);  // points x nodes
    s.values.resize(static_cast<std::size_t>(s.nodes) * s.points);
    for (int n = 0; n < s.nodes; ++n)
      for (int q = 0; q < s.points; ++q)
        s.values[static_cast<std::size_t>(n) * s.points + q] = values(q, n);
    const int shape = static_cast<int>(shapes_.size());
    for (std::size_t c = 0; c < cells.count(); ++c) {
      const std::int64_t* v = cells.element(c);
      bool moves = false;
      for (int n = 0; n < s.nodes && !moves; ++n)
        moves = movable[static_cast<std::size_t>(v[n])] != 0;
      if (!moves) continue;
      Facet f{shape, c, invW_.size()};
      // The ideal's area, for its size: sum of |det W| x weight over the points.
      double area = 0.0;
      for (int q = 0; q < s.points; ++q) {
        Eigen::Matrix<double, 3, 2> t = Eigen::Matrix<double, 3, 2>::Zero();
        for (int n = 0; n < s.vertices; ++n)
          for (int k = 0; k < 2; ++k)
            t.col(k) += positions[static_cast<std::size_t>(v[n])] *
                        s.linear[(static_cast<std::size_t>(n) * s.points + q) * 2 + k];
        const Vec normal = t.col(0).cross(t.col(1));
        const double det = normal.norm();
        // Zero area to rounding: |t0 x t1| within a few ulps of |t0| |t1|'s rounding.
        if (!(det > 1e-12 * t.col(0).norm() * t.col(1).norm()) || !(t.col(0).norm() > 0.0))
          throw ParameterError("boundary facet " + std::to_string(c) +
                               " of the face block (CAD face " + std::to_string(cells.entity[c]) +
                               ") has a degenerate straight-sided shape (zero area)");
        const Vec u1 = t.col(0).normalized();
        const Vec u2 = (normal / det).cross(u1);
        Eigen::Matrix2d w;
        w << u1.dot(t.col(0)), u1.dot(t.col(1)), u2.dot(t.col(0)), u2.dot(t.col(1));
        invW_.emplace_back(w.inverse());
        scale_.push_back(s.weights[static_cast<std::size_t>(q)] * std::abs(w.determinant()));
        area += scale_.back();
      }
      f.size = std::sqrt(area);
      facets_.push_back(f);
    }
    shapes_.push_back(std::move(s));
  }
  foot_.assign(scale_.size(), Vec::Zero());
  normal_.assign(scale_.size(), Vec::Zero());
  footParam_.assign(scale_.size(), {std::numeric_limits<double>::quiet_NaN(), 0.0});
  // Node -> facets.
  start_.assign(positions.size() + 1, 0);
  for (const Facet& f : facets_) {
    const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
    const std::int64_t* v = s.cells->element(f.cell);
    for (int n = 0; n < s.nodes; ++n)
      if (movable[static_cast<std::size_t>(v[n])] != 0)
        ++start_[static_cast<std::size_t>(v[n]) + 1];
  }
  for (std::size_t i = 0; i + 1 < start_.size(); ++i) start_[i + 1] += start_[i];
  incidence_.resize(start_.back());
  std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t fi = 0; fi < facets_.size(); ++fi) {
    const Shape& s = shapes_[static_cast<std::size_t>(facets_[fi].shape)];
    const std::int64_t* v = s.cells->element(facets_[fi].cell);
    for (int n = 0; n < s.nodes; ++n)
      if (movable[static_cast<std::size_t>(v[n])] != 0)
        incidence_[fill[static_cast<std::size_t>(v[n])]++] = {static_cast<std::uint32_t>(fi), n};
  }
}

HOMESH_VECTOR_CLONES double FacetEnergy::facetEnergy(const Facet& f,
                                                     const std::vector<Vec>& positions, int local,
                                                     Vec* g, Mat* h, Patch* patch,
                                                     double* size) const {
  const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
  const std::int64_t* v = s.cells->element(f.cell);
  const bool distortion = weight_ > 0.0, fidelity = fidelity_ > 0.0;
  // The tangents t = dx/dxi (and x) at every point first, node by node with the points innermost
  // (a loop that vectorises), summed over the nodes in their order as a point-by-point loop
  // would: [component][point] for t's first column, its second, then x.
  const auto points = static_cast<std::size_t>(s.points);
  thread_local std::vector<double> tx;
  tx.assign(9 * points, 0.0);
  for (int n = 0; n < s.nodes; ++n) {
    const Vec& xn = positions[static_cast<std::size_t>(v[n])];
    const double* d0 = &s.byPoint[static_cast<std::size_t>(n) * points];
    const double* d1 = &s.byPoint[(static_cast<std::size_t>(s.nodes) + n) * points];
    const double* l = &s.values[static_cast<std::size_t>(n) * points];
    for (int c = 0; c < 3; ++c) {
      const double xc = xn[c];
      double* t0 = &tx[static_cast<std::size_t>(c) * points];
      double* t1 = &tx[static_cast<std::size_t>(3 + c) * points];
#pragma omp simd
      for (std::size_t q = 0; q < points; ++q) {
        t0[q] += xc * d0[q];
        t1[q] += xc * d1[q];
      }
      if (!fidelity) continue;
      double* xq = &tx[static_cast<std::size_t>(6 + c) * points];
#pragma omp simd
      for (std::size_t q = 0; q < points; ++q) xq[q] += xc * l[q];
    }
  }
  double energy = 0.0;
  for (int q = 0; q < s.points; ++q) {
    const auto k = f.first + static_cast<std::size_t>(q);
    const auto uq = static_cast<std::size_t>(q);
    Eigen::Matrix<double, 3, 2> t;
    Vec x;
    for (int c = 0; c < 3; ++c) {
      t(c, 0) = tx[static_cast<std::size_t>(c) * points + uq];
      t(c, 1) = tx[static_cast<std::size_t>(3 + c) * points + uq];
      x[c] = tx[static_cast<std::size_t>(6 + c) * points + uq];
    }
    const Eigen::Matrix2d& invW = invW_[k];
    const Eigen::Matrix<double, 3, 2> m = t * invW;
    const Vec& normal = normal_[k];
    const bool follows = fidelity && normal.squaredNorm() > 0.0;
    const double rq = follows ? (x - foot_[k]).dot(normal) / f.size : 0.0;
    const double c1 = follows ? m.col(0).dot(normal) : 0.0;
    const double c2 = follows ? m.col(1).dot(normal) : 0.0;
    const double wd = scale_[k] * (weight_ * f.size), wf = scale_[k] * (fidelity_ * f.size);
    // rho(q) = q / (1 + q / s): q for small deviations, at most s for large ones (see the
    // header); rho' = 1 / bend^2, rho'' = -2 / (s bend^3).
    const double q0 = rq * rq + c1 * c1 + c2 * c2, bend = 1.0 + q0 / kFidelitySaturation;
    if (follows) energy += wf * q0 / bend;
    if (patch == nullptr) {
      if (distortion) energy += wd * facet_detail::density<double>(m.col(0), m.col(1));
      continue;
    }
    const auto at = static_cast<std::size_t>(local) * s.points + q;
    const Eigen::Vector2d a =
        invW.transpose() *
        Eigen::Vector2d(s.byPoint[at], s.byPoint[static_cast<std::size_t>(s.nodes) * points + at]);
    if (follows) {
      // W_f as a function of s = d . n: (r + l s)^2 + (c1 + a1 s)^2 + (c2 + a2 s)^2.
      const double l = s.values[at] / f.size;
      const double slope = 2.0 * (rq * l + c1 * a[0] + c2 * a[1]);
      const double curvature = 2.0 * (l * l + a[0] * a[0] + a[1] * a[1]);
      const double first = 1.0 / (bend * bend);
      const double second = -2.0 / (kFidelitySaturation * bend * bend * bend);
      *g += wf * first * slope * normal;
      *h += wf * (first * curvature + second * slope * slope) * normal * normal.transpose();
      if (size != nullptr) *size += wf * (rq * rq + c1 * c1 + c2 * c2);
      patch->normal.push_back(normal);
      patch->r.push_back(rq);
      patch->l.push_back(l);
      patch->c1.push_back(c1);
      patch->c2.push_back(c2);
      patch->b1.push_back(a[0]);
      patch->b2.push_back(a[1]);
      patch->wf.push_back(wf);
    }
    if (!distortion) continue;
    double value = 0.0;
    Vec gq;
    Mat hq;
    if (!facet_detail::derivatives<double>(m.col(0), m.col(1), a[0], a[1], value, gq, hq))
      return std::numeric_limits<double>::infinity();
    energy += wd * value;
    if (size != nullptr) *size += wd * (std::abs(value) + m.squaredNorm());
    *g += wd * gq;
    *h += wd * hq;
    patch->m1.emplace_back(m.col(0));
    patch->m2.emplace_back(m.col(1));
    patch->a1.push_back(a[0]);
    patch->a2.push_back(a[1]);
    patch->w.push_back(wd);
  }
  return energy;
}

void FacetEnergy::Patch::clear() {
  for (std::vector<Vec>* v : {&m1, &m2, &normal}) v->clear();
  for (std::vector<double>* v : {&a1, &a2, &w, &r, &l, &c1, &c2, &b1, &b2, &wf}) v->clear();
}

double FacetEnergy::assemble(std::int64_t node, const std::vector<Vec>& positions, Vec& g, Mat& h,
                             Patch& patch, double* size) const {
  patch.clear();
  const auto n = static_cast<std::size_t>(node);
  if (n + 1 >= start_.size()) return 0.0;
  Vec gs = Vec::Zero();
  Mat hs = Mat::Zero();
  double energy = 0.0;
  for (std::size_t k = start_[n]; k < start_[n + 1]; ++k) {
    energy += facetEnergy(facets_[incidence_[k].facet], positions, incidence_[k].local, &gs, &hs,
                          &patch, size);
    if (!std::isfinite(energy)) return energy;
  }
  g += gs;
  h += hs;
  return energy;
}

HOMESH_VECTOR_CLONES double FacetEnergy::energyAfter(const Patch& patch, const Vec& d) {
  double energy = 0.0;
  for (std::size_t i = 0; i < patch.w.size(); ++i)
    energy += patch.w[i] * facet_detail::density<double>(Vec(patch.m1[i] + patch.a1[i] * d),
                                                         Vec(patch.m2[i] + patch.a2[i] * d));
  for (std::size_t i = 0; i < patch.wf.size(); ++i) {
    const double s = patch.normal[i].dot(d);
    const double r = patch.r[i] + patch.l[i] * s, c1 = patch.c1[i] + patch.b1[i] * s,
                 c2 = patch.c2[i] + patch.b2[i] * s;
    const double q = r * r + c1 * c1 + c2 * c2;
    energy += patch.wf[i] * q / (1.0 + q / kFidelitySaturation);
  }
  return energy;
}

std::size_t FacetEnergy::dropApexFacets(const Mesh& mesh, const CadModel& cad) {
  std::map<std::pair<int, int>, bool> apex;  // (face, vertex): few vertices, each tested once
  std::size_t dropped = 0;
  for (Facet& f : facets_) {
    const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
    const std::int64_t* v = s.cells->element(f.cell);
    const int face = s.cells->entity[f.cell];
    if (face < 1 || face > cad.numFaces()) continue;
    for (int n = 0; n < s.vertices && f.followsCad; ++n) {
      const auto id = static_cast<std::size_t>(v[n]);
      if (mesh.nodeCadDim[id] != 0 || mesh.nodeCadIndex[id] < 1) continue;
      const std::pair<int, int> key{face, mesh.nodeCadIndex[id]};
      auto it = apex.find(key);
      if (it == apex.end()) it = apex.emplace(key, isFaceApex(cad, face, key.second)).first;
      if (it->second) f.followsCad = false;
    }
    if (!f.followsCad) {
      ++dropped;
      for (int q = 0; q < s.points; ++q)
        normal_[f.first + static_cast<std::size_t>(q)] = Vec::Zero();
      totalAt_.clear();  // total() computes every share again
    }
  }
  return dropped;
}

void FacetEnergy::refreshTargets(const std::vector<Vec>& positions, const Mesh& mesh,
                                 const std::vector<CadModel>& cads) {
  if (!(fidelity_ > 0.0) || cads.empty()) return;
  const auto count = static_cast<std::int64_t>(facets_.size());
  FirstFailure failure;
#pragma omp parallel for num_threads(static_cast <int>(cads.size())) schedule(dynamic, 16)
  for (std::int64_t fi = 0; fi < count; ++fi) {
    try {
      const CadModel& cad = cads[static_cast<std::size_t>(omp_get_thread_num())];
      const Facet& f = facets_[static_cast<std::size_t>(fi)];
      const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
      const std::int64_t* v = s.cells->element(f.cell);
      const int face = s.cells->entity[f.cell];
      if (face < 1 || face > cad.numFaces() || !f.followsCad) continue;
      if (!refreshedAt_.empty() && unmoved(v, s.nodes, positions, refreshedAt_) &&
          std::all_of(footParam_.begin() + static_cast<std::ptrdiff_t>(f.first),
                      footParam_.begin() + static_cast<std::ptrdiff_t>(f.first) + s.points,
                      [](const std::array<double, 2>& uv) { return std::isfinite(uv[0]); }))
        continue;  // unmoved since its targets were found
      if (!shareStale_.empty()) shareStale_[static_cast<std::size_t>(fi)] = 1;
      for (int q = 0; q < s.points; ++q) {
        const auto k = f.first + static_cast<std::size_t>(q);
        Vec x = Vec::Zero();
        double largest = -1.0;
        const bool first = !std::isfinite(footParam_[k][0]);
        std::optional<std::array<double, 2>> guess;
        if (!first) guess = footParam_[k];
        for (int n = 0; n < s.nodes; ++n) {
          const double l = s.values[static_cast<std::size_t>(n) * s.points + q];
          const auto id = static_cast<std::size_t>(v[n]);
          x += positions[id] * l;
          if (!first || l <= largest) continue;
          // First projection: from the face node whose basis function is largest here.
          if (mesh.nodeCadDim[id] == 2 && mesh.nodeCadIndex[id] == face) {
            largest = l;
            guess = std::array<double, 2>{mesh.nodeCadParam[2 * id], mesh.nodeCadParam[2 * id + 1]};
          }
        }
        // A point the CAD cannot project or evaluate drops out of the part (as a pole does)
        // rather than failing the run: the sliding steps leave such a node where it is too.
        try {
          const SurfaceProjection proj = cad.projectOnSurface(face, x, guess);
          const SurfaceDerivatives d = cad.evaluateSurface(face, proj.u, proj.v);
          // Undefined at a pole, as the report's measure (geometry_accuracy.hpp) has it.
          const std::optional<Vec> m = d.normalDirection();
          foot_[k] = proj.point;
          normal_[k] = m ? Vec(m->normalized()) : Vec::Zero();
          footParam_[k] = {proj.u, proj.v};
        } catch (const CadError&) {
          normal_[k] = Vec::Zero();
        }
      }
    } catch (...) {
      failure.capture();
    }
  }
  failure.rethrow();
  refreshedAt_ = positions;
}

double FacetEnergy::total(const std::vector<Vec>& positions) {
  if (totalAt_.empty()) {
    share_.assign(facets_.size(), 0.0);
    shareStale_.assign(facets_.size(), 1);
  }
  double energy = 0.0;
  for (std::size_t fi = 0; fi < facets_.size(); ++fi) {
    const Facet& f = facets_[fi];
    const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
    const std::int64_t* v = s.cells->element(f.cell);
    if (shareStale_[fi] != 0 || !unmoved(v, s.nodes, positions, totalAt_)) {
      share_[fi] = facetEnergy(f, positions, -1, nullptr, nullptr, nullptr);
      shareStale_[fi] = 0;
    }
    energy += share_[fi];
  }
  totalAt_ = positions;
  return energy;
}

}  // namespace homesh
