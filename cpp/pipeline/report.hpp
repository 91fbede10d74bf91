// JSON reports (schema in README.md), shared by the command line and the Python module.
#pragma once

#include <string>

#include "core/mesh.hpp"
#include "io/json_writer.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

// Appends "quality": {...} (scaled Jacobian and distortion with histograms, invalid and
// undecided counts, certified, per cell type) to an open JSON object.
void appendQuality(JsonWriter& json, const QualitySummary& quality);

// Appends "elements" (cells of the mesh dimension by type) and "boundary" (lower cells).
void appendCounts(JsonWriter& json, const Mesh& mesh);

// The report of `homesh mesh`: input, order, size, counts, quality, timings.
std::string meshReportJson(const MeshResult& result, const std::string& input);

// The report of `homesh quality`: input, order, counts, quality.
std::string qualityReportJson(const Mesh& mesh, const QualitySummary& quality,
                              const std::string& input);

}  // namespace homesh
