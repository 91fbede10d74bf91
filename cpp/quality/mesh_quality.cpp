#include "quality/mesh_quality.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/thread_count.hpp"
#include "element/quadrature.hpp"
#include "quality/distortion.hpp"

namespace homesh {

void Histogram::add(double value) {
  if (value < 0.0 || std::isnan(value)) {  // invalid, or undefined (never a bin index)
    ++below;
  } else if (value > 1.0 + 1e-12) {
    ++above;
  } else {
    ++counts[std::min(kBins - 1, static_cast<int>(value * kBins))];
  }
}

namespace {

void accumulate(MeasureSummary& s, double value) {
  s.min = std::min(s.min, value);
  s.mean += value;
  s.histogram.add(value);
}

// An element's node coordinates, moved to the origin and scaled to unit size. Every measure
// here is invariant under translation and uniform scaling, and J's Bezier coefficients are
// products of three coordinate differences: at unit size they stay far inside double range
// whatever coordinates a file holds.
NodeCoordinates gather(const Mesh& mesh, const std::int64_t* nodes, int n) {
  NodeCoordinates x(n, 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * nodes[i] + c];
  const Eigen::RowVector3d origin = x.row(0);
  x.rowwise() -= origin;
  const double size = x.cwiseAbs().maxCoeff();
  if (size > 0.0 && std::isfinite(size)) x /= size;
  return x;
}

// Area (length) element ratio of a boundary cell, sampled at quadrature points and nodes.
double boundaryStretch(const JacobianSampler& sampler, const NodeCoordinates& x) {
  Eigen::VectorXd j;
  sampler.jacobians(x, nullptr, j);
  const double hi = j.maxCoeff();
  return hi > 0.0 ? j.minCoeff() / hi : -1.0;
}

JacobianSampler boundarySampler(CellType type, int order) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const QuadratureRule rule = quadratureRule(type, 2 * order + 2);
  return {ref, pointRows(rule, ref.nodes())};
}

// Where evaluateQuality may take an element's values from `known`: the source element of each
// element of `mesh` (global index, block order) when the two have the same type, order and
// node coordinates, and its values are finite; -1 otherwise.
std::vector<std::int64_t> unchangedSources(const Mesh& mesh, const KnownQuality& known) {
  const auto elements = elementsOf(mesh);
  std::vector<std::int64_t> out(elements.size(), -1);
  if (known.mesh == nullptr || known.quality == nullptr) return out;
  const auto earlier = elementsOf(*known.mesh);
  const QualitySummary& q = *known.quality;
  if (q.scaledJacobian.size() != earlier.size() || q.validity.size() != earlier.size() ||
      q.scaledJacobianUpper.size() != earlier.size() || q.distortion.size() != earlier.size())
    return out;
  if (!known.source.empty() && known.source.size() != elements.size()) return out;
  // (A 2D cell's Jacobian is measured along the plane's normal, or its own on a surface.)
  if (known.mesh->dim != mesh.dim || known.mesh->planeNormal != mesh.planeNormal) return out;
  const std::vector<double>& before = known.xyz != nullptr ? *known.xyz : known.mesh->xyz;
  if (before.size() != known.mesh->xyz.size()) return out;
  for (std::size_t g = 0; g < elements.size(); ++g) {
    const std::int64_t s = known.source.empty() ? static_cast<std::int64_t>(g) : known.source[g];
    if (s < 0 || static_cast<std::size_t>(s) >= earlier.size()) continue;
    const auto [b, e] = elements[g];
    const auto [sb, se] = earlier[static_cast<std::size_t>(s)];
    if (b->type != sb->type || b->order != sb->order) continue;
    const auto k = static_cast<std::size_t>(s);
    if (!std::isfinite(q.scaledJacobian[k]) || !std::isfinite(q.scaledJacobianUpper[k]) ||
        !std::isfinite(q.distortion[k]))
      continue;
    const std::int64_t* a = b->element(e);
    const std::int64_t* c = sb->element(se);
    // (Finite coordinates: the earlier bounds were certified; NaN input is measured again.)
    bool same = true;
    for (int i = 0; i < b->nodesPerElement() && same; ++i) {
      const double* x = &mesh.xyz[3 * a[i]];
      const double* y = &before[3 * c[i]];
      for (int d = 0; d < 3 && same; ++d) same = std::isfinite(x[d]) && x[d] == y[d];
    }
    if (same) out[g] = s;
  }
  return out;
}

}  // namespace

JacobianBounds elementJacobianBounds(const Mesh& mesh, const ElementBlock& block, std::size_t e,
                                     double tolerance) {
  const Eigen::Vector3d normal = cellNormal(mesh, block.element(e));
  return boundJacobian(block.type, block.order,
                       gather(mesh, block.element(e), block.nodesPerElement()),
                       mesh.dim == 2 ? &normal : nullptr, tolerance);
}

QualitySummary evaluateQuality(const Mesh& mesh, int threads, const KnownQuality* known) {
  QualitySummary summary;
  const std::vector<std::int64_t> from =
      known != nullptr ? unchangedSources(mesh, *known) : std::vector<std::int64_t>();
  const QualitySummary* earlier = known != nullptr ? known->quality : nullptr;
  std::size_t offset = 0;  // global index of the block's first element
  for (const ElementBlock& block : mesh.blocks) {
    const int n = block.nodesPerElement();
    if (block.count() == 0) continue;
    if (cellDimension(block.type) != mesh.dim) {
      const JacobianSampler sampler = boundarySampler(block.type, block.order);
      for (std::size_t e = 0; e < block.count(); ++e) {
        const NodeCoordinates x = gather(mesh, block.element(e), n);
        summary.boundaryScaledJacobian.push_back(boundaryStretch(sampler, x));
        summary.boundaryDistortion.push_back(
            block.type == CellType::Line ? 1.0 : elementDistortion(block.type, block.order, x));
      }
      continue;
    }
    // Elements are independent: evaluate them in parallel, then summarise in order.
    const auto count = static_cast<std::int64_t>(block.count());
    std::vector<double> scaled(block.count()), upper(block.count()), distortion(block.count());
    std::vector<Validity> validity(block.count());
    std::vector<char> certified(block.count(), 1);
    // Warm the shared tables once before the threads need them.
    const Eigen::Vector3d first = cellNormal(mesh, block.element(0));
    boundJacobian(block.type, block.order, gather(mesh, block.element(0), n),
                  mesh.dim == 2 ? &first : nullptr);
#pragma omp parallel for num_threads(threadsToUse(threads)) schedule(dynamic, 16)
    for (std::int64_t e = 0; e < count; ++e) {
      const std::int64_t source = from.empty() ? -1 : from[offset + static_cast<std::size_t>(e)];
      if (source >= 0 && earlier != nullptr) {  // unchanged: the values measured before
        const auto s = static_cast<std::size_t>(source);
        scaled[e] = earlier->scaledJacobian[s];
        upper[e] = earlier->scaledJacobianUpper[s];
        validity[e] = earlier->validity[s];
        distortion[e] = earlier->distortion[s];
        continue;
      }
      const std::int64_t* cell = block.element(static_cast<std::size_t>(e));
      const NodeCoordinates x = gather(mesh, cell, n);
      const Eigen::Vector3d normal = cellNormal(mesh, cell);
      const JacobianBounds bounds =
          boundJacobian(block.type, block.order, x, mesh.dim == 2 ? &normal : nullptr);
      scaled[e] = bounds.scaledJacobian();
      upper[e] = bounds.scaledJacobianEstimate();
      validity[e] = bounds.validity;
      certified[e] = bounds.certified ? 1 : 0;
      distortion[e] = elementDistortion(block.type, block.order, x);
    }
    for (std::size_t e = 0; e < block.count(); ++e)
      if (!from.empty() && from[offset + e] >= 0) ++summary.known;
    offset += block.count();
    TypeQuality& type = summary.byType[block.type];
    for (std::size_t e = 0; e < block.count(); ++e) {
      summary.scaledJacobian.push_back(scaled[e]);
      summary.scaledJacobianUpper.push_back(upper[e]);
      summary.distortion.push_back(distortion[e]);
      summary.validity.push_back(validity[e]);
      ++type.count;
      accumulate(type.scaledJacobian, scaled[e]);
      accumulate(type.distortion, distortion[e]);
      if (validity[e] == Validity::Invalid) ++type.invalid;
      if (validity[e] == Validity::Undecided) ++type.undecided;
      if (certified[e] == 0) summary.certified = false;
    }
  }
  if (summary.scaledJacobian.empty()) throw Error("quality: the mesh has no elements");
  for (auto& [cell, type] : summary.byType) {
    for (auto* m : {&type.scaledJacobian, &type.distortion}) {
      const MeasureSummary typeMeasure = *m;
      MeasureSummary& total =
          m == &type.scaledJacobian ? summary.scaled : summary.distortionSummary;
      total.min = std::min(total.min, typeMeasure.min);
      total.mean += typeMeasure.mean;  // still a sum here
      for (int k = 0; k < Histogram::kBins; ++k)
        total.histogram.counts[k] += typeMeasure.histogram.counts[k];
      total.histogram.below += typeMeasure.histogram.below;
      total.histogram.above += typeMeasure.histogram.above;
      m->mean /= static_cast<double>(type.count);
    }
    summary.invalid += type.invalid;
    summary.undecided += type.undecided;
  }
  const auto count = static_cast<double>(summary.scaledJacobian.size());
  summary.scaled.mean /= count;
  summary.distortionSummary.mean /= count;
  if (summary.undecided > 0) summary.certified = false;
  return summary;
}

std::vector<FlaggedElement> flaggedElements(const Mesh& mesh, const QualitySummary& quality,
                                            std::size_t limit) {
  std::vector<FlaggedElement> out;
  std::size_t index = 0;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim) continue;
    for (std::size_t e = 0; e < block.count(); ++e, ++index) {
      if (index >= quality.validity.size()) return out;
      const Validity v = quality.validity[index];
      if (v == Validity::Valid) continue;
      if (out.size() >= limit) return out;
      FlaggedElement f;
      f.index = index;
      f.type = block.type;
      f.entity = block.entity[e];
      f.validity = v;
      f.lower = quality.scaledJacobian[index];
      f.upper = quality.scaledJacobianUpper[index];
      const std::int64_t* nodes = block.element(e);
      for (int k = 0; k < block.nodesPerElement(); ++k) {
        const auto n = static_cast<std::size_t>(nodes[k]);
        if (n >= mesh.nodeCadIndex.size() || mesh.nodeCadIndex[n] <= 0) continue;
        if (mesh.nodeCadDim[n] == 2) f.cadFaces.push_back(mesh.nodeCadIndex[n]);
        if (mesh.nodeCadDim[n] == 1) f.cadCurves.push_back(mesh.nodeCadIndex[n]);
        if (mesh.nodeCadDim[n] == 0) f.cadVertices.push_back(mesh.nodeCadIndex[n]);
      }
      for (std::vector<int>* list : {&f.cadFaces, &f.cadCurves, &f.cadVertices}) {
        std::sort(list->begin(), list->end());
        list->erase(std::unique(list->begin(), list->end()), list->end());
      }
      out.push_back(std::move(f));
    }
  }
  return out;
}

}  // namespace homesh
