// The value a meshing job hands on: the curved mesh, the CAD its boundary nodes lie on and its
// certified quality. It is what the Python object holds and what the writers write; how the job
// made it (timings, the optimiser's history, the repair rounds) stays in its StageRecords
// (pipeline/stage_records.hpp), so a mesh read from a file or rebuilt from arrays is the same
// kind of value as one the pipeline made.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "io/mesh_writers.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

struct CurvedMesh {
  // The CAD the nodes' links (Mesh::nodeCadDim/Index/Param) refer to; null for a mesh read from a
  // file or rebuilt from arrays, whose links are kept but cannot be evaluated.
  std::shared_ptr<const CadModel> cad;
  Mesh mesh;
  QualitySummary quality;  // of `mesh`, as quality/mesh_quality.hpp certifies it
};

// The per-cell quality fields written beside the mesh: scaled Jacobian, distortion and the
// validity verdict (for boundary cells, their own measures: see quality/mesh_quality.hpp).
std::vector<CellField> qualityFields(const QualitySummary& quality);

// Writes the mesh and its quality fields to each path (format from the extension).
void writeMeshFiles(const CurvedMesh& curved, const std::vector<std::string>& paths,
                    const WriteOptions& options = {});

}  // namespace homesh
