#include "cad/point_classifier.hpp"

#include <algorithm>
#include <iterator>

#include "core/format.hpp"

namespace homesh {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

std::string describePoint(const Eigen::Vector3d& p) {
  return "(" + formatNumber(p.x()) + ", " + formatNumber(p.y()) + ", " + formatNumber(p.z()) + ")";
}

CadPointClassifier::CadPointClassifier(const CadModel& cad, double tolerance)
    : cad_(cad), tol_(tolerance) {
  const int kSamples = 9;
  edgeBoxes_.resize(static_cast<std::size_t>(cad.numEdges()) + 1);
  faceBoxes_.resize(static_cast<std::size_t>(cad.numFaces()) + 1);
  vertexEdges_.resize(static_cast<std::size_t>(cad.numVertices()) + 1);
  edgeFaces_.resize(static_cast<std::size_t>(cad.numEdges()) + 1);
  for (int e = 1; e <= cad.numEdges(); ++e) {
    for (const int v : cad.subShapeIndices(1, e, 0)) vertexEdges_[v].push_back(e);
    if (cad.isDegenerated(e)) continue;
    const ParameterRange r = cad.edgeRange(e);
    for (int k = 0; k <= 2 * kSamples; ++k)
      edgeBoxes_[e].add(
          cad.evaluateCurve(e, r.first + (r.last - r.first) * k / (2 * kSamples)).point);
    edgeBoxes_[e].grow(0.25, tol_);
  }
  for (int f = 1; f <= cad.numFaces(); ++f) {
    for (const int e : cad.subShapeIndices(2, f, 1)) edgeFaces_[e].push_back(f);
    const SurfaceBounds b = cad.faceBounds(f);
    for (int i = 0; i <= kSamples; ++i)
      for (int j = 0; j <= kSamples; ++j)
        faceBoxes_[f].add(cad.evaluateSurface(f, b.uMin + (b.uMax - b.uMin) * i / kSamples,
                                              b.vMin + (b.vMax - b.vMin) * j / kSamples)
                              .point);
    faceBoxes_[f].grow(0.25, tol_);
  }
}

CadPlace CadPointClassifier::classify(const Eigen::Vector3d& p,
                                      std::pair<int, double>& nearestFace) const {
  CadPlace best;
  for (int v = 1; v <= cad_.numVertices(); ++v) {
    const Eigen::Vector3d q = cad_.vertexPoint(v);
    const double d = (q - p).norm();
    if (d <= tol_ + cad_.tolerance(0, v) && (best.dim < 0 || d < best.distance)) {
      best = CadPlace{0, v, kNaN, kNaN, q, d};
    }
  }
  if (best.dim >= 0) return best;
  for (int e = 1; e <= cad_.numEdges(); ++e) {
    if (cad_.isDegenerated(e) || !edgeBoxes_[e].contains(p)) continue;
    const CurveProjection c = cad_.projectOnCurve(e, p);
    if (c.distance <= tol_ + cad_.tolerance(1, e) && (best.dim < 0 || c.distance < best.distance)) {
      best = CadPlace{1, e, c.t, kNaN, c.point, c.distance};
    }
  }
  if (best.dim >= 0) return best;
  nearestFace = {0, std::numeric_limits<double>::infinity()};
  for (int f = 1; f <= cad_.numFaces(); ++f) {
    if (!faceBoxes_[f].contains(p)) continue;
    const SurfaceProjection s = cad_.projectOnSurface(f, p);
    if (s.distance < nearestFace.second) nearestFace = {f, s.distance};
    if (s.distance > tol_ + cad_.tolerance(2, f)) continue;
    if (!cad_.faceContains(f, cad_.wrapIntoPeriod(f, s.u, 0), cad_.wrapIntoPeriod(f, s.v, 1)))
      continue;
    if (best.dim < 0 || s.distance < best.distance)
      best = CadPlace{2, f, s.u, s.v, s.point, s.distance};
  }
  return best;
}

std::set<int> CadPointClassifier::facesOf(int dim, int index) const {
  std::set<int> out;
  if (dim == 2) out.insert(index);
  if (dim == 1) out.insert(edgeFaces_[index].begin(), edgeFaces_[index].end());
  if (dim == 0)
    for (const int e : vertexEdges_[index]) out.insert(edgeFaces_[e].begin(), edgeFaces_[e].end());
  return out;
}

std::set<int> CadPointClassifier::edgesOf(int dim, int index) const {
  std::set<int> out;
  if (dim == 1) out.insert(index);
  if (dim == 0) out.insert(vertexEdges_[index].begin(), vertexEdges_[index].end());
  return out;
}

int CadPointClassifier::sharedFace(const std::vector<std::pair<int, int>>& places,
                                   const Eigen::Vector3d& centre) const {
  if (places.empty()) return 0;
  std::set<int> common = facesOf(places[0].first, places[0].second);
  for (std::size_t k = 1; k < places.size() && !common.empty(); ++k) {
    const std::set<int> other = facesOf(places[k].first, places[k].second);
    std::set<int> both;
    std::set_intersection(common.begin(), common.end(), other.begin(), other.end(),
                          std::inserter(both, both.begin()));
    common = std::move(both);
  }
  if (common.size() < 2) return common.empty() ? 0 : *common.begin();
  int face = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (const int c : common) {
    const double d = cad_.projectOnSurface(c, centre).distance;
    if (d < nearest) nearest = d, face = c;
  }
  return face;
}

int CadPointClassifier::sharedEdge(std::pair<int, int> ea, std::pair<int, int> eb,
                                   const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const std::set<int> sa = edgesOf(ea.first, ea.second);
  const std::set<int> sb = edgesOf(eb.first, eb.second);
  std::vector<int> shared;
  std::set_intersection(sa.begin(), sa.end(), sb.begin(), sb.end(), std::back_inserter(shared));
  const Eigen::Vector3d mid = 0.5 * (a + b);
  int edge = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (const int e : shared) {
    if (cad_.isDegenerated(e)) continue;
    const double d = cad_.projectOnCurve(e, mid).distance;
    if (d < nearest) nearest = d, edge = e;
  }
  if (edge == 0 || nearest > 0.3 * (b - a).norm() + tol_) return 0;
  return edge;
}

}  // namespace homesh
