// CAD in, curved mesh out: the stages in order, with timings and progress.
//
//   CAD model -> linear mesh (Gmsh, uniform size) -> order elevation with boundary nodes on the
//   CAD -> [variational optimiser, nodes sliding on the CAD] -> quality -> geometry (distance and
//   normal angle of the boundary to the CAD, quality/geometry_accuracy.hpp).
//
// The command line, the Python module and the tests all drive meshing through this one entry
// point, so they validate parameters and report identically.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "boundary_layer/boundary_layer.hpp"
#include "boundary_layer/layer_split.hpp"
#include "cad/cad_healing.hpp"
#include "cad/cad_model.hpp"
#include "cad/naca_aerofoil.hpp"
#include "core/mesh.hpp"
#include "core/parameters.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/curved_mesh.hpp"
#include "pipeline/meshing_options.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/stage_records.hpp"
#include "quality/geometry_accuracy.hpp"
#include "quality/mesh_quality.hpp"
#include "sizing/element_count.hpp"
#include "sizing/sizing_octree.hpp"

namespace homesh {

// With the optimiser, orders above this are first curved and optimised at this order, then
// raised (curving/order_elevation.hpp's changeOrder) and optimised again: the low order
// untangles the interior with a fraction of the nodes and a far better conditioned problem
// (equispaced nodes of order 8 couple strongly), and the high order only corrects it.
inline constexpr int kContinuationOrder = 4;

// A uniform size giving a coarse mesh: a twentieth of the bounding-box diagonal.
double defaultMeshSize(const CadModel& cad);

// Automatic sizing for a model given no sizes: MaxDelta = defaultMeshSize, MinDelta automatic
// (0: the sizing octree takes it from the shape, sizing/automatic_min_delta.hpp), EPS the
// parameter table's default.
SizingParameters defaultSizing(const CadModel& cad);

// `p` with an automatic (0) maxDelta set to defaultMeshSize (or minDelta if that is larger),
// saying so in maxDeltaSetBy; an automatic minDelta stays 0 for the octree to set.
SizingParameters completeSizing(SizingParameters p, const CadModel& cad);

// The sizes to use: `requested` completed, or defaultSizing when nothing was requested.
SizingParameters resolveSizing(const std::optional<SizingParameters>& requested,
                               const CadModel& cad);

// Throws ParameterError when `expected` (2 or 3, from a .mcf's MeshType) is set and the model
// gets the other kind of mesh (cad/model_dimension.hpp).
void checkMeshDimension(const CadModel& cad, std::optional<int> expected);

// The sizing octree of `params` and its element-count prediction. An automatic MinDelta is
// raised (toward MaxDelta / 20) while the octree would need more cells than it may have or the
// prediction exceeds kMaxPredictedElements, saying so in its minDeltaSetBy. Throws
// ParameterError (bad parameters, sizes the octree cannot hold, or a prediction above
// kMaxPredictedElements: sizes far too small for the model) or CadError.
inline constexpr double kMaxPredictedElements = 5e7;
SizingResult runSizing(const CadModel& cad, const SizingParameters& params,
                       int threads = defaultOf<int>("threads"));

// Bytes the stages after sizing are predicted to need for `elements` linear elements of
// dimension `dim` curved to `order`: a fixed 50 MB plus 160 bytes per element node (measured:
// 97 B at order 4 and 121 B at order 8 on a 37,139-tetrahedron box, peak resident memory, with
// margin for repair rounds that keep two meshes).
double predictedMemoryBytes(double elements, int order, int dim);

// Throws ParameterError before anything large is allocated when predictedMemoryBytes exceeds
// the memory the machine has available now, naming both figures.
void checkPredictedMemory(double elements, int order, int dim, const std::string& what);

// Where the CAD comes from.
struct CadSource {
  enum class Kind { File, BrepText, Naca } kind = Kind::File;
  std::string value;   // a path, or BRep text
  std::string name;    // for BRep text: what to call it in messages (e.g. the FreeCAD label)
  double scale = 1.0;  // applied after loading a file: 0.001 reads a STEP in metres (NekMesh)
  NacaDomain naca;     // for Kind::Naca
  static CadSource file(std::string path) {
    CadSource s;
    s.value = std::move(path);
    return s;
  }
  static CadSource brepText(std::string text, std::string name = "the shape") {
    CadSource s;
    s.kind = Kind::BrepText;
    s.value = std::move(text);
    s.name = std::move(name);
    return s;
  }
  static CadSource nacaDomain(NacaDomain d) {
    CadSource s;
    s.kind = Kind::Naca;
    s.naca = std::move(d);
    return s;
  }
  CadModel load() const;
};

// The sizing stage alone (`homesh predict`): loads (and heals, as runMeshPipeline) the CAD, checks
// given.expectedDimension, builds the octree from resolveSizing(given.sizing) on
// given.threads and predicts, and writes given.octreeOutput when set; numbers given in the
// model's own numbering are mapped as the pipeline maps them. Throws as runMeshPipeline's first
// stages.
SizingResult runSizingStage(const CadSource& source, const MeshingOptions& given);

// Receives progress; may ask to stop, which is honoured when a stage starts or ends, between
// the linear mesher's dimensions and between the optimiser's colour groups (the run then throws
// CancelledError and returns nothing). Every call comes from the thread that runs the pipeline;
// cancelRequested may be asked often and should be cheap.
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void stageStarted(const std::string& /*stage*/) {}
  // Within a stage: `fraction` of its work done (0..1, an estimate: the optimiser counts sweeps
  // against its most, and usually stops earlier) and what was just done, in words.
  virtual void stageProgress(const std::string& /*stage*/, double /*fraction*/,
                             const std::string& /*detail*/) {}
  virtual void stageFinished(const std::string& /*stage*/, double /*seconds*/) {}
  virtual bool cancelRequested() { return false; }
};

// Runs every stage: CAD, sizing, linear mesh, boundary layer (optional: "boundary_layer"),
// elevation, optimiser (optional), quality, then
// up to options.repairRounds repair rounds while an element is not proven valid (stages
// "repair 1", ...): each locates those elements in the linear mesh, splits or refines there
// (planRepair), and elevates, optimises and evaluates the new linear mesh; the next round works
// from that mesh, except after a split that made the mesh worse than the best: then it refines
// around the best mesh's offenders instead (always, with a boundary layer: its linear mesh and
// layer are made again). The result is the best mesh seen: fewest elements not
// proven valid, then the best worst scaled Jacobian (a round never makes the result worse); its
// boundary triangles are then fitted to their CAD faces ("boundary_fit",
// pipeline/boundary_fidelity.hpp: 3D, order 2 or more, options.fidelityWeight above 0); with
// a boundary layer, its macro prisms are then split ("split_layers") and the quality is that of
// the split mesh. With options.jobSeconds, each Gmsh and optimiser run gets at most what is
// left of that budget, a round starts only if what is left covers what the one before took
// (the first: the linear mesh, curving, optimiser and quality before it), the optimiser and
// "boundary_fit" and "geometry" are left out once it is spent, and result.job (with result.notes)
// says so; spent before the linear mesh is made, BudgetExceeded (core/isolated_call.hpp) names the
// stage. Throws ParameterError, IoError, CadError, MeshingError or CancelledError.
MeshResult runMeshPipeline(const CadSource& source, MeshingOptions options,
                           PipelineObserver* observer = nullptr);

// Curves a linear tetrahedral mesh made elsewhere (FreeCAD FEM's Gmsh or Netgen mesher) on the
// CAD it was made from: the mesh is put on the CAD (linear/cad_classification.hpp, stage
// "classify"), then elevated, optimised and evaluated as runMeshPipeline does ("high_order",
// "optimise", "quality", "boundary_fit", "geometry"; the optimiser, "boundary_fit" and "geometry"
// under options.jobSeconds as there). The mesh is the user's: no sizing, no linear meshing, no
// repair rounds and no boundary layer (ParameterError when one is asked for).
MeshResult curveMeshOnCad(const CadSource& source, const Mesh& linear, MeshingOptions options,
                          PipelineObserver* observer = nullptr);

// The parameter table's keys curveMeshOnCad's front ends take (`homesh curve`, homesh.curve),
// beside threads and verbosity, which each front end sets its own way.
inline constexpr std::array<const char*, 7> kCurveOptionKeys = {
    "order",           "optimise",    "optimise_seconds",  "facet_weight",
    "fidelity_weight", "job_seconds", "classify_tolerance"};

// `options` with its named groups' entities, given in the model's numbering as it was read,
// mapped to the meshed model's: healing and imprinting touching solids number faces and edges
// afresh (HealingRecord::numbering). Throws ParameterError naming a group's entity that healing
// or imprinting removed (and which step), or the model does not have.
WriteOptions inMeshedNumbering(WriteOptions options, const StageRecords& records, int meshDim);

// writeMeshFiles as the pipeline's last stage: records its "output" timing in the result; the
// groups mapped by inMeshedNumbering.
void writeMeshOutputs(MeshResult& result, const std::vector<std::string>& paths,
                      const WriteOptions& options = {}, PipelineObserver* observer = nullptr);

}  // namespace homesh
