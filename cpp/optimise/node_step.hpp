// One Newton step on one node of the optimiser's working mesh: the node's patch (the quadrature
// points of its elements, node_patch.hpp) gathered from the cached F, its energy with exact
// gradient and Hessian, the Hessian shifted to be positive definite, and a backtracking Armijo
// line search that rejects the move if the energy does not decrease. A node with a locked
// direction steps in the plane perpendicular to it; a node sliding on the CAD steps in its
// parameters (cad_sliding.hpp), its boundary facets' term added once the mesh is proven valid
// (facet_energy.hpp). An accepted move updates the node's position and, by its rank-one change,
// F and J at every point of the patch.
//
// Steps of nodes that share no element may run at once on different threads (each with its
// own Patch): a step writes only its node, its elements' F and J, and its CAD state.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "cad/cad_model.hpp"
#include "optimise/cad_sliding.hpp"
#include "optimise/facet_energy.hpp"
#include "optimise/node_patch.hpp"
#include "optimise/optimiser.hpp"
#include "optimise/working_mesh.hpp"
#include "quality/bezier_jacobian.hpp"

namespace homesh::optimiser {

// The quadrature points of a node's elements (NodePatch), and where each element's run of
// points came from, to write an accepted move back. One per thread, reused from node to node.
template <int D>
struct Patch {
  struct Run {
    Block<D>* block;
    std::size_t element;
    std::size_t first;  // in `points`
  };
  NodePatch<D> points;
  std::vector<Run> runs;
  FacetEnergy::Patch facets;  // the node's boundary facets, when it slides (NodeStep's facets)
  std::size_t slides = 0, cadEvaluations = 0;  // sliding visits, CAD evaluations
};

template <int D>
class NodeStep {
 public:
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;

  // `lockedNormal`: per node the direction it may not move along (NaN: none), or empty; read at
  // every step, so it may be filled after construction.
  NodeStep(WorkingMesh<D>& mesh, CadSliding<D>& sliding, const OptimiserOptions& options,
           const std::vector<Vec>& lockedNormal)
      : mesh_(mesh), sliding_(sliding), options_(options), lockedNormal_(lockedNormal) {}

  // The boundary facets of the free sliding nodes (3D, with CAD and options.facetWeight or
  // fidelityWeight > 0); none otherwise. The term is off until setFacetsOn().
  void buildFacets(const std::vector<std::int64_t>& free, const CadModel* cad);
  // The facet term's fidelity targets (the CAD's foot points and normals) at the current
  // positions (FacetEnergy::refreshTargets).
  void refreshFacetTargets();
  bool hasFacets() const { return facetEnergy_ != nullptr; }
  bool hasFidelity() const { return hasFacets() && facetEnergy_->hasFidelity(); }
  // Whether the facet term has joined the whole mesh and its total energy (it waits for a
  // proven-valid mesh; untangling comes first).
  bool facetsOn() const { return facetsOn_; }
  void setFacetsOn(bool on) { facetsOn_ = on; }
  // Whether the node slides on the CAD (its steps are in the CAD's parameters).
  bool slides(std::int64_t node) const { return sliding_.parameters(node) != 0; }
  // Whether the node is a vertex of a boundary facet of the term (after buildFacets).
  bool touchesFacet(std::int64_t node) const;
  // The facet term's total at the current positions, 0 until it has joined (facetsOn()).
  double facetTotal();

  // The patch of a node: F, a and the weight at every quadrature point of its elements. Returns
  // the regularisation the patch needs (DESIGN.md section 6: sizeable only where it is inverted).
  double gather(std::int64_t node, Patch<D>& patch);

  // One Newton step on the node; returns the distance it moved (0: rejected).
  double visit(std::int64_t node, Patch<D>& patch);

  // The energy of the node's patch with the node at `coordinates` (its position, or its CAD
  // parameters where it slides), as a step assembles it (NodeEnergyProbe).
  NodeEnergy probe(std::int64_t node, const Eigen::VectorXd& coordinates, double eps);

 private:
  template <Functional Fn>
  double visitWith(std::int64_t node, Patch<D>& patch);
  template <Functional Fn>
  double slide(std::int64_t node, Patch<D>& patch, double eps, double e0, double magnitude,
               const Vec& grad, const Mat& hess);
  template <Functional Fn>
  double slideOn(const CadModel& cad, std::int64_t node, Patch<D>& patch, double eps,
                 double volumeEnergy, double magnitude, const Vec& volumeGrad,
                 const Mat& volumeHess);
  double facetAssemble(std::int64_t node, Vec& grad, Mat& hess, Patch<D>& patch,
                       double& size) const;

  WorkingMesh<D>& mesh_;
  CadSliding<D>& sliding_;
  const OptimiserOptions& options_;
  const std::vector<Vec>& lockedNormal_;
  // The boundary facets' term (OptimiserOptions::facetWeight, fidelityWeight); null without
  // them. facetsOn_: the steps add it (both parts), once the mesh is proven valid.
  std::unique_ptr<FacetEnergy> facetEnergy_;
  bool facetsOn_ = false;
};

extern template class NodeStep<2>;
extern template class NodeStep<3>;

}  // namespace homesh::optimiser
