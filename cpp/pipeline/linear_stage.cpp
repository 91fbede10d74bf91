#include "pipeline/linear_stage.hpp"

#include "core/error.hpp"
#include "pipeline/job_messages.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/stage_clock.hpp"

namespace homesh {

namespace {

// Reports the linear mesher's Gmsh run done (before the mesh is read back and oriented) and
// stops there when asked.
std::function<void(int, int)> linearProgress(PipelineObserver* observer) {
  if (observer == nullptr) return {};
  return [observer](int dim, int of) {
    observer->stageProgress("linear", static_cast<double>(dim) / of,
                            dim == 3 ? "volumes meshed by Gmsh" : "surfaces meshed by Gmsh");
    if (observer->cancelRequested()) throw CancelledError("cancelled during the linear mesh");
  };
}

}  // namespace

LinearStage::LinearStage(MeshResult& result, const MeshingOptions& options, JobBudget& budget,
                         PipelineObserver* observer)
    : result_(result), options_(options), budget_(budget), observer_(observer) {
  base_.verbosity = options.verbosity;
  base_.dimensionDone = linearProgress(observer);
  if (observer != nullptr)
    base_.cancelRequested = [observer] { return observer->cancelRequested(); };
  base_.note = [&result](const std::string& note) { result.notes.push_back(note); };
  // Read when a message is written: a fallback that meshes the solids apart maps them anew.
  base_.givenNames = [&result](int dim, int index) {
    return result.healing.numbering.givenNames(dim, index);
  };
}

void LinearStage::limitGmsh(LinearMeshOptions& o, const std::string& stage) {
  o.timeLimit = budget_.stageLimit(options_.linearSeconds);
  gmshByBudget_ = budget_.binds(options_.linearSeconds);
  o.timeLimitName = gmshByBudget_ ? stage + " stage, what was left of the " +
                                        jobLimitName(budget_) + ": " + jobLimitSettings()
                                  : limitName("linear_seconds");
}

void LinearStage::splitTangentEars(Mesh& mesh) {
  for (const CurvedFaceEdge& ear : tangentEarSplits(mesh, *result_.cad)) {
    try {
      result_.tangentEars += applySplits(mesh, {ear}, *result_.cad);
    } catch (const MeshingError& e) {  // (not seen: a midpoint keeps positive cells so)
      result_.notes.push_back(std::string("a tangent ear was left as it is: ") + e.what());
    } catch (const CadError& e) {  // OCCT could not project its midpoint onto the face
      result_.notes.push_back(std::string("a tangent ear was left as it is: ") + e.what());
    }
  }
}

Mesh LinearStage::make(LinearMeshOptions o, bool clocked, const std::string& stage) {
  std::optional<StageClock> clock;
  if (clocked) clock.emplace("linear", result_.timings, observer_);
  limitGmsh(o, stage);
  Mesh mesh = generateLinearMesh(*result_.cad, o);
  if (!options_.boundaryLayer) {
    splitTangentEars(mesh);
    if (clocked) clock->done();
    return mesh;
  }
  if (clocked) clock->done();
  if (clocked) clock.emplace("boundary_layer", result_.timings, observer_);
  layer_.emplace();
  limitGmsh(o, clocked ? std::string("boundary_layer") : stage);
  mesh = growBoundaryLayer(mesh, *result_.cad, *options_.boundaryLayer, o, *layer_);
  if (clocked) clock->done();
  return mesh;
}

}  // namespace homesh
