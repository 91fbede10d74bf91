#include "optimise/facet_energy.hpp"

#include <Eigen/Dense>
#include <string>

#include "core/error.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {

FacetEnergy::FacetEnergy(const Mesh& mesh, const std::vector<Vec>& positions,
                         const std::vector<std::uint8_t>& movable, double weight) {
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
    tabulate(ref, s.gradients);
    tabulate(lin, s.linear);
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
      const std::size_t first = invW_.size();
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
      const double size = std::sqrt(area);
      for (std::size_t k = first; k < scale_.size(); ++k) scale_[k] *= weight * size;
      facets_.push_back(f);
    }
    shapes_.push_back(std::move(s));
  }
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

double FacetEnergy::facetEnergy(const Facet& f, const std::vector<Vec>& positions, int local,
                                Vec* g, Mat* h, Patch* patch, double* size) const {
  const Shape& s = shapes_[static_cast<std::size_t>(f.shape)];
  const std::int64_t* v = s.cells->element(f.cell);
  double energy = 0.0;
  for (int q = 0; q < s.points; ++q) {
    Eigen::Matrix<double, 3, 2> t = Eigen::Matrix<double, 3, 2>::Zero();
    for (int n = 0; n < s.nodes; ++n) {
      const double* dn = &s.gradients[(static_cast<std::size_t>(n) * s.points + q) * 2];
      t.col(0) += positions[static_cast<std::size_t>(v[n])] * dn[0];
      t.col(1) += positions[static_cast<std::size_t>(v[n])] * dn[1];
    }
    const Eigen::Matrix2d& invW = invW_[f.first + static_cast<std::size_t>(q)];
    const Eigen::Matrix<double, 3, 2> m = t * invW;
    const double w = scale_[f.first + static_cast<std::size_t>(q)];
    if (patch == nullptr) {
      energy += w * facet_detail::density<double>(m.col(0), m.col(1));
      continue;
    }
    const double* dn = &s.gradients[(static_cast<std::size_t>(local) * s.points + q) * 2];
    const Eigen::Vector2d a = invW.transpose() * Eigen::Vector2d(dn[0], dn[1]);
    double value = 0.0;
    Vec gq;
    Mat hq;
    if (!facet_detail::derivatives<double>(m.col(0), m.col(1), a[0], a[1], value, gq, hq))
      return std::numeric_limits<double>::infinity();
    energy += w * value;
    if (size != nullptr) *size += w * (std::abs(value) + m.squaredNorm());
    *g += w * gq;
    *h += w * hq;
    patch->m1.emplace_back(m.col(0));
    patch->m2.emplace_back(m.col(1));
    patch->a1.push_back(a[0]);
    patch->a2.push_back(a[1]);
    patch->w.push_back(w);
  }
  return energy;
}

double FacetEnergy::assemble(std::int64_t node, const std::vector<Vec>& positions, Vec& g, Mat& h,
                             Patch& patch, double* size) const {
  patch.m1.clear();
  patch.m2.clear();
  patch.a1.clear();
  patch.a2.clear();
  patch.w.clear();
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

double FacetEnergy::energyAfter(const Patch& patch, const Vec& d) {
  double energy = 0.0;
  for (std::size_t i = 0; i < patch.w.size(); ++i)
    energy += patch.w[i] * facet_detail::density<double>(Vec(patch.m1[i] + patch.a1[i] * d),
                                                         Vec(patch.m2[i] + patch.a2[i] * d));
  return energy;
}

double FacetEnergy::total(const std::vector<Vec>& positions) const {
  double energy = 0.0;
  for (const Facet& f : facets_) energy += facetEnergy(f, positions, -1, nullptr, nullptr, nullptr);
  return energy;
}

}  // namespace homesh
