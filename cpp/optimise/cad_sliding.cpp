#include "optimise/cad_sliding.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace homesh::optimiser {

template <int D>
void CadSliding<D>::choose(std::vector<char>& boundary, int threads) {
  const Mesh& mesh = mesh_.mesh;
  slide_.assign(mesh.numNodes(), 0);
  if (cad_ == nullptr) return;
  for (std::size_t node = 0; node < mesh.numNodes(); ++node) {
    const int dim = mesh.nodeCadDim[node];
    const int index = mesh.nodeCadIndex[node];
    if (index <= 0) continue;
    const double p0 = mesh.nodeCadParam[2 * node], p1 = mesh.nodeCadParam[2 * node + 1];
    if (dim == 0) {
      boundary[node] = 1;
    } else if (dim == 1 && std::isfinite(p0) && index <= cad_->numEdges() &&
               !cad_->isDegenerated(index)) {
      slide_[node] = 1;
      boundary[node] = 0;
      if (curveRange_.count(index) == 0) curveRange_[index] = cad_->edgeRange(index);
    } else if (dim == 2 && D == 3 && std::isfinite(p0) && std::isfinite(p1) &&
               index <= cad_->numFaces()) {
      slide_[node] = 2;
      boundary[node] = 0;
      if (faceRange_.count(index) == 0) faceRange_[index] = cad_->faceBounds(index);
    }
  }
  cadSlot_.assign(mesh.numNodes(), -1);
  std::int32_t slots = 0;
  for (std::size_t node = 0; node < mesh.numNodes(); ++node)
    if (slide_[node] != 0) cadSlot_[node] = slots++;
  cadModel_.assign(static_cast<std::size_t>(slots), LocalCadModel<D>{});
  if (slots > 0)
    for (int t = 0; t < threads; ++t) cadPerThread_.push_back(cad_->clone());
}

template <int D>
const CadModel& CadSliding<D>::threadCad() const {
  return cadPerThread_[static_cast<std::size_t>(omp_get_thread_num())];
}

template <int D>
typename CadSliding<D>::Vec CadSliding<D>::pointOn(const CadModel& cad, std::int64_t node,
                                                   const double* param) const {
  const int entity = mesh_.mesh.nodeCadIndex[node];
  if (slide_[node] == 1) return mesh_.frame * cad.evaluateCurve(entity, param[0]).point;
  return mesh_.frame * cad.evaluateSurface(entity, param[0], param[1]).point;
}

template <int D>
LocalCadModel<D> CadSliding<D>::localModel(const CadModel& cad, std::int64_t node,
                                           const double* param) const {
  const int entity = mesh_.mesh.nodeCadIndex[node];
  LocalCadModel<D> m =
      slide_[node] == 1
          ? LocalCadModel<D>::curve(cad.evaluateCurve(entity, param[0]), mesh_.frame)
          : LocalCadModel<D>::surface(cad.evaluateSurface(entity, param[0], param[1]), mesh_.frame);
  m.at0[0] = param[0];
  m.at0[1] = slide_[node] == 1 ? 0.0 : param[1];
  return m;
}

template <int D>
const LocalCadModel<D>& CadSliding<D>::currentModel(const CadModel& cad, std::int64_t node,
                                                    std::size_t& evaluations) {
  const double* param = &mesh_.mesh.nodeCadParam[2 * node];
  LocalCadModel<D>& m = cadModel_[static_cast<std::size_t>(cadSlot_[node])];
  const bool current =
      m.parameters != 0 && m.at0[0] == param[0] && (slide_[node] == 1 || m.at0[1] == param[1]);
  if (!current) {
    m = localModel(cad, node, param);
    ++evaluations;
  }
  return m;
}

template <int D>
std::array<double, 2> CadSliding<D>::trial(std::int64_t node, const double* param, double alpha,
                                           const Eigen::VectorXd& step) const {
  const int entity = mesh_.mesh.nodeCadIndex[node];
  std::array<double, 2> trial = {param[0], param[1]};
  if (slide_[node] == 1) {
    const ParameterRange& r = curveRange_.at(entity);
    trial[0] = std::clamp(param[0] + alpha * step[0], r.first, r.last);
  } else {
    const SurfaceBounds& b = faceRange_.at(entity);
    trial[0] = std::clamp(param[0] + alpha * step[0], b.uMin, b.uMax);
    trial[1] = std::clamp(param[1] + alpha * step[1], b.vMin, b.vMax);
  }
  return trial;
}

template class CadSliding<2>;
template class CadSliding<3>;

}  // namespace homesh::optimiser
