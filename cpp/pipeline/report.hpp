// JSON reports of the pipeline (fields in docs/report.md), shared by the command line and the
// Python module: `homesh mesh` (a mesh and its job's records) and `homesh predict` (a
// SizingResult), built on the quality report's parts (io/quality_report.hpp, included here for the
// callers of both).
#pragma once

#include <string>
#include <vector>

#include "io/json_writer.hpp"
#include "io/quality_report.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/stage_records.hpp"

namespace homesh {

// Appends "boundary_layer": the parameters, the macro heights grown, the first split layer's
// height, where the layer was shrunk (per face: smallest factor, where, how many wall nodes),
// the macro mesh's certified quality and the split's projections onto the CAD.
void appendBoundaryLayer(JsonWriter& json, const StageRecords& records);

// Appends "sizing": the parameters, the prediction and the octree's statistics.
void appendSizing(JsonWriter& json, const SizingResult& sizing);

// The report of `homesh predict`: input, dimension, "predicted_elements" and "sizing".
std::string predictReportJson(const SizingResult& sizing, const std::string& input);

// The report of `homesh mesh`: input, order, size, counts, "predicted_elements" and "sizing"
// (octree sizing), quality, optimiser, repair rounds, geometry, timings.
std::string meshReportJson(const CurvedMesh& curved, const StageRecords& records,
                           const std::string& input);
inline std::string meshReportJson(const MeshResult& result, const std::string& input) {
  return meshReportJson(result, result, input);
}

// Appends "rounds": one record per repair round (pipeline/repair.hpp), in order; [] when none ran.
void appendRepairRounds(JsonWriter& json, const std::vector<RepairRound>& rounds);

}  // namespace homesh
