// CAD in, curved mesh out: the stages in order, with timings and progress.
//
//   CAD model -> linear mesh (Gmsh, uniform size) -> order elevation with boundary nodes on the
//   CAD -> [variational optimiser, nodes sliding on the CAD] -> quality.
//
// The command line, the Python module and the tests all drive meshing through this one entry
// point, so they validate parameters and report identically.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "io/mesh_writers.hpp"
#include "optimise/optimiser.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

inline constexpr int kMaxThreads = 1024;

struct MeshingOptions {
  int order = 4;               // polynomial order, 1..10
  std::optional<double> size;  // target edge length (> 0); unset: defaultMeshSize(cad)
  int threads = 1;             // threads the stages may use, 1..kMaxThreads
  int verbosity = 0;           // 0 silent; 1 Gmsh's warnings; 2 Gmsh's information
  // > 0: after elevation, at most this many sweeps of the variational optimiser (hyperelastic,
  // boundary nodes sliding on the CAD; optimise/optimiser.hpp), stopping earlier once the mesh
  // is proven valid and a sweep raises its worst scaled Jacobian by less than 0.001.
  int optimiseIterations = 0;

  // Throws ParameterError naming the offending parameter.
  void validate() const;
};

// A uniform size giving a coarse mesh: a twentieth of the bounding-box diagonal.
double defaultMeshSize(const CadModel& cad);

// Where the CAD comes from.
struct CadSource {
  enum class Kind { File, BrepText } kind = Kind::File;
  std::string value;  // a path, or BRep text
  std::string name;   // for BRep text: what to call it in messages (e.g. the FreeCAD label)
  static CadSource file(std::string path) { return {Kind::File, std::move(path), {}}; }
  static CadSource brepText(std::string text, std::string name = "the shape") {
    return {Kind::BrepText, std::move(text), std::move(name)};
  }
  CadModel load() const;
};

// Wall-clock seconds per stage, in the order the stages ran.
struct StageTimings {
  std::vector<std::pair<std::string, double>> seconds;
  void add(const std::string& stage, double s);
  double total() const;
};

// Receives progress; may ask to stop, which is honoured when a stage starts or ends (the run
// then throws CancelledError and returns nothing).
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  virtual void stageStarted(const std::string& /*stage*/) {}
  virtual void stageFinished(const std::string& /*stage*/, double /*seconds*/) {}
  virtual bool cancelRequested() { return false; }
};

struct MeshResult {
  std::shared_ptr<const CadModel> cad;
  Mesh mesh;
  QualitySummary quality;
  std::optional<OptimiserResult> optimiser;  // when the optimiser ran
  StageTimings timings;
  MeshingOptions options;
};

// Runs every stage. Throws ParameterError, IoError, CadError, MeshingError or CancelledError.
MeshResult runMeshPipeline(const CadSource& source, MeshingOptions options,
                           PipelineObserver* observer = nullptr);

// The per-cell quality fields written beside the mesh: scaled Jacobian and distortion (for
// boundary cells, their own measures: see quality/mesh_quality.hpp).
std::vector<CellField> qualityFields(const QualitySummary& quality);

// Writes the mesh to each path (format from the extension) and records the "output" timing.
// Writes the mesh and its quality fields to each path (format from the extension).
void writeMeshFiles(const MeshResult& result, const std::vector<std::string>& paths,
                    const WriteOptions& options = {});

// writeMeshFiles as the pipeline's last stage: records its "output" timing in the result.
void writeMeshOutputs(MeshResult& result, const std::vector<std::string>& paths,
                      const WriteOptions& options = {}, PipelineObserver* observer = nullptr);

}  // namespace homesh
