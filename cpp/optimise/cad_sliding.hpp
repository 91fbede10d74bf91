// The optimiser's nodes that slide on the CAD: which nodes do (a node on a CAD curve moves along
// it in t, in 3D a node on a CAD face moves on it in (u, v), CAD vertices stay), the points and
// second-order models (cad_local_model.hpp) of their curves and faces at given parameters, the
// model each node's last accepted step left, and the parameter ranges trial points are clamped
// to. OCCT's evaluators cache state, so every thread evaluates through its own copy of the model.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "cad/cad_model.hpp"
#include "optimise/cad_local_model.hpp"
#include "optimise/working_mesh.hpp"

namespace homesh::optimiser {

template <int D>
class CadSliding {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;

  // `cad`: the model the mesh's node records refer to; null: no node slides. `mesh` must be
  // built (its frame).
  CadSliding(const WorkingMesh<D>& mesh, const CadModel* cad) : mesh_(mesh), cad_(cad) {}

  // With CAD: nodes on a CAD curve (face, in 3D) slide and leave `boundary` (the fixed nodes),
  // CAD vertices join it; nodes without a CAD record keep the topological rule. Clones the model
  // once per thread where any node slides.
  void choose(std::vector<char>& boundary, int threads);

  // 1 for a node on a CAD curve, 2 on a CAD face (its parameter count), else 0.
  int parameters(std::int64_t node) const { return slide_[static_cast<std::size_t>(node)]; }

  // The CAD model of the calling thread (OCCT's evaluators cache state).
  const CadModel& threadCad() const;
  // One clone per thread (empty where no node slides).
  const std::vector<CadModel>& threadCads() const { return cadPerThread_; }

  // The point (in the frame) of a sliding node at parameters `param` (t, or (u, v)).
  Vec pointOn(const CadModel& cad, std::int64_t node, const double* param) const;

  // The second-order model of the node's curve (face) at parameters `param` (t, or (u, v)).
  LocalCadModel<D> localModel(const CadModel& cad, std::int64_t node, const double* param) const;

  // The model at the node's current parameters: the one its last accepted step left (the CAD
  // evaluation of that step gave the derivatives too), else a fresh evaluation, counted in
  // `evaluations`.
  const LocalCadModel<D>& currentModel(const CadModel& cad, std::int64_t node,
                                       std::size_t& evaluations);

  // Keeps `model` (evaluated at the node's new parameters) for the node's next visit.
  void keepModel(std::int64_t node, const LocalCadModel<D>& model) {
    cadModel_[static_cast<std::size_t>(cadSlot_[node])] = model;
  }

  // The parameters param + alpha step clamped to the node's curve range (face bounds); the
  // second stays param[1] on a curve.
  std::array<double, 2> trial(std::int64_t node, const double* param, double alpha,
                              const Eigen::VectorXd& step) const;

 private:
  const WorkingMesh<D>& mesh_;
  const CadModel* cad_;                 // null: boundary nodes stay fixed
  std::vector<CadModel> cadPerThread_;  // evaluation caches are per thread
  std::vector<std::uint8_t> slide_;     // per node: 1 on a CAD curve, 2 on a CAD face, else 0
  std::vector<std::int32_t> cadSlot_;   // per node: its index in cadModel_, -1 if it stays
  // per sliding node: its curve's (face's) model at the parameters it was built at
  std::vector<LocalCadModel<D>> cadModel_;
  std::map<int, ParameterRange> curveRange_;
  std::map<int, SurfaceBounds> faceRange_;
};

extern template class CadSliding<2>;
extern template class CadSliding<3>;

}  // namespace homesh::optimiser
