// The linear meshes of one pipeline run: the first one and those of the repair rounds that
// refine. Each is Gmsh's mesh of the CAD (cells that curving would make flat at a vertex split
// at once: tangentEarSplits in pipeline/repair.hpp) or, with a boundary layer asked for, its
// surface with the macro layer grown on it. Every Gmsh run gets the smaller of the linear
// meshing time limit and what is left of the job's budget, its message naming which.
#pragma once

#include <optional>
#include <string>

#include "boundary_layer/boundary_layer.hpp"
#include "core/job_budget.hpp"
#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

class LinearStage {
 public:
  // `result` receives the CAD's tangent ears split and the notes; it must hold the CAD and
  // outlive the stage. Progress, cancel and notes go through `observer` and `result`.
  LinearStage(MeshResult& result, const MeshingOptions& options, JobBudget& budget,
              PipelineObserver* observer);

  // The options every linear mesh starts from; the sizing stage sets their sizes.
  LinearMeshOptions& baseOptions() { return base_; }
  const LinearMeshOptions& baseOptions() const { return base_; }

  // Sets `o`'s Gmsh time limit for `stage` ("linear", "repair 2") as above.
  void limitGmsh(LinearMeshOptions& o, const std::string& stage);
  // Whether the last Gmsh run's limit was what was left of the job's budget.
  bool gmshByBudget() const { return gmshByBudget_; }

  // The linear mesh from `o`, with its macro boundary layer when one is asked for. `clocked`:
  // timed as the stages "linear" (and "boundary_layer"); otherwise within the caller's `stage`
  // (a repair round). Throws as generateLinearMesh and growBoundaryLayer.
  Mesh make(LinearMeshOptions o, bool clocked, const std::string& stage);

  // How the last macro layer was grown (none without a boundary layer).
  const std::optional<BoundaryLayerRecord>& layer() const { return layer_; }

 private:
  // Splits the cells that curving would make flat at a vertex, whatever follows.
  void splitTangentEars(Mesh& mesh);

  MeshResult& result_;
  const MeshingOptions& options_;
  JobBudget& budget_;
  PipelineObserver* observer_;
  LinearMeshOptions base_;
  bool gmshByBudget_ = false;
  std::optional<BoundaryLayerRecord> layer_;
};

}  // namespace homesh
