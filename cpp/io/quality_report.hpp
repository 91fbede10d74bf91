// JSON reports of a mesh's quality (fields in docs/report.md): the parts every report shares
// (counts, certified quality, geometry against the CAD, the optimiser's record) and the whole
// reports of `homesh quality` and `homesh optimise`, which read a mesh file. The pipeline's
// reports (`homesh mesh`, `homesh predict`) add its own records (pipeline/report.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/json_writer.hpp"
#include "optimise/optimiser.hpp"
#include "quality/geometry_accuracy.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

// Appends the array `key` of strings (a report's "notes").
void appendStrings(JsonWriter& json, const std::string& key, const std::vector<std::string>& v);

// Appends "quality": {...} (scaled Jacobian and distortion with histograms, invalid and
// undecided counts, certified, per cell type, and the first kMaxFlaggedElements elements not
// proven valid) to an open JSON object.
inline constexpr std::size_t kMaxFlaggedElements = 100;
void appendQuality(JsonWriter& json, const Mesh& mesh, const QualitySummary& quality);

// Where the elements not proven valid lie on the CAD, for a message: "at Face12 (5 elements),
// Face40 (3), Edge7 (1), inside Solid1 (2)". An element counts at every CAD face its nodes lie
// on; one with no node on a face counts at the curves it touches, and one with neither inside its
// own entity (3D: solid; 2D: face). Entities with most elements come first, at most
// `maxEntities` named and the rest counted. Empty when every element is valid or the mesh has no
// CAD classification (read from a file).
std::string notValidLocation(const Mesh& mesh, const QualitySummary& quality,
                             std::size_t maxEntities = 6);

// "invalid", "undecided" or "valid".
const char* validityName(Validity v);

// Appends "elements" (cells of the mesh dimension by type) and "boundary" (lower cells).
void appendCounts(JsonWriter& json, const Mesh& mesh);

// Appends "geometry": the largest and mean distance of boundary sample points to their CAD entity
// (absolute and relative to the model's diagonal), the largest and mean angle between mesh and
// CAD normals, the sample counts and where the worst distance and angle were found.
void appendGeometry(JsonWriter& json, const GeometryAccuracy& geometry);

// A mesh file's geometry measured against a CAD file (`homesh quality --cad`).
struct FileGeometry {
  std::string cad;  // the CAD file's path
  GeometryAccuracy accuracy;
};

// The report of `homesh quality`: input, order, counts, quality, with `geometry` "cad" and
// "geometry", and "notes" (what reading the file changed, from readMesh).
std::string qualityReportJson(const Mesh& mesh, const QualitySummary& quality,
                              const std::string& input, const std::vector<std::string>& notes = {},
                              const FileGeometry* geometry = nullptr);

// Appends "optimiser": {functional, iterations, worst_before, worst_after, invalid_before,
// invalid_after, seconds, ...} with the per-sweep history.
void appendOptimiser(JsonWriter& json, const OptimiserResult& result,
                     const std::string& key = "optimiser");

// The report of `homesh optimise`: the quality report of the result plus "optimiser".
std::string optimiseReportJson(const Mesh& mesh, const QualitySummary& quality,
                               const OptimiserResult& result, const std::string& input,
                               const std::vector<std::string>& notes = {});

}  // namespace homesh
