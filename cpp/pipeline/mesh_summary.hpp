// The human-readable summary of a job, written from its records: the lines `homesh mesh` and
// `homesh predict` print, HighOrderMesh.summary() and repr() in Python, and the status line of
// a FreeCAD mesh object all come from here, so the three front ends say the same thing.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "pipeline/stage_records.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

// "1234 nodes, 567 elements of order 4; scaled Jacobian min 0.1234 mean 0.8765; all elements
// proven valid", or "...; NOT VALID: 3 invalid, 1 undecided at Face7 (3 elements), Face2 (1)"
// (where, for a mesh made from CAD: report.hpp's notValidLocation).
std::string qualityHeadline(const Mesh& mesh, const QualitySummary& quality);

// The sizing octree's parameters and statistics, and the predicted element count: two lines.
std::vector<std::string> predictionLines(const SizingResult& sizing, int dim);

// Everything a meshing job has to say, in order: what healing did, the notes, the sizing and
// prediction, the headline, the boundary layer, each repair round and the job's time budget.
std::vector<std::string> meshSummaryLines(const CurvedMesh& curved, const StageRecords& records);
inline std::vector<std::string> meshSummaryLines(const MeshResult& result) {
  return meshSummaryLines(result, result);
}

}  // namespace homesh
