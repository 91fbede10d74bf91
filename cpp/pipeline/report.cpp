#include "pipeline/report.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cad/cad_model.hpp"
#include "quality/bezier_jacobian.hpp"

namespace homesh {
namespace {

const char* kElementKeys[] = {"tet", "prism", "pyramid", "hex", "tri", "quad"};

void appendMeasure(JsonWriter& json, const std::string& key, const MeasureSummary& m,
                   bool histogram) {
  json.beginObject(key);
  json.value("min", m.min);
  json.value("mean", m.mean);
  if (histogram) {
    json.beginObject("histogram");
    std::vector<double> edges;
    for (int k = 0; k <= Histogram::kBins; ++k)
      edges.push_back(static_cast<double>(k) / Histogram::kBins);
    json.numbers("edges", edges);
    json.numbers("counts",
                 std::vector<std::size_t>(m.histogram.counts.begin(), m.histogram.counts.end()));
    json.value("below_zero", m.histogram.below);
    json.endObject();
  }
  json.endObject();
}

void appendStrings(JsonWriter& json, const std::string& key, const std::vector<std::string>& v) {
  json.beginArray(key);
  for (const std::string& text : v) json.value("", text);
  json.endArray();
}

void appendHealing(JsonWriter& json, const HealingRecord& h) {
  json.beginObject("healing");
  json.value("enabled", h.enabled);
  json.value("tolerance", h.tolerance);
  appendStrings(json, "problems", h.problems);
  appendStrings(json, "actions", h.actions);
  appendStrings(json, "warnings", h.warnings);
  // The faces in no solid that were not meshed (solids only, or copies of the solids' faces),
  // in words; empty: none.
  json.value("left_out", h.leftOut);
  // The model was kept as faces for a surface mesh (--surface), in words; empty: it was not.
  json.value("surface", h.surface);
  // Automatic mode's choice (--auto), in words; empty: not asked for, or nothing to choose.
  json.value("automatic", h.automatic);
  // Face numbers (boundary layers, groups) are the healed model's when it was renumbered.
  json.value("renumbered", h.renumbered);
  json.value("faces_before", h.facesBefore);
  json.value("faces_after", h.facesAfter);
  json.value("solids_before", h.solidsBefore);
  json.value("solids_after", h.solidsAfter);
  json.value("seconds", h.seconds);
  json.endObject();
}

// "job": the time budget, the wall time, and what the budget stopped early or left out.
void appendJob(JsonWriter& json, const JobRecord& job) {
  json.beginObject("job");
  json.value("time_limit", job.timeLimit);
  json.value("seconds", job.seconds);
  json.value("reserved", job.reserved);
  json.value("stopped", std::string(job.stopped() ? "time budget" : "finished"));
  appendStrings(json, "cut", job.cut);
  appendStrings(json, "skipped", job.skipped);
  json.endObject();
}

}  // namespace

void appendCounts(JsonWriter& json, const Mesh& mesh) {
  std::map<std::string, std::size_t> elements, boundary;
  for (const char* key : kElementKeys) elements[key] = 0;
  for (const ElementBlock& block : mesh.blocks)
    (cellDimension(block.type) == mesh.dim ? elements : boundary)[cellShortName(block.type)] +=
        block.count();
  json.beginObject("elements");
  for (const char* key : kElementKeys) json.value(key, elements[key]);
  json.endObject();
  json.beginObject("boundary");
  for (const auto& [name, count] : boundary) json.value(name, count);
  json.endObject();
}

std::string notValidLocation(const Mesh& mesh, const QualitySummary& quality,
                             std::size_t maxEntities) {
  const std::size_t flagged = quality.invalid + quality.undecided;
  if (flagged == 0) return {};
  // (dimension, index) -> elements there; ordered by count below.
  std::map<std::pair<int, int>, std::size_t> count;
  bool classified = false;
  for (const FlaggedElement& f : flaggedElements(mesh, quality, flagged)) {
    // The boundary's entities (3D: faces, then curves; 2D: curves), else the element's own.
    const bool solid = mesh.dim == 3;
    const std::vector<int>& first = solid ? f.cadFaces : f.cadCurves;
    const std::vector<int> none;
    const std::vector<int>& second = solid ? f.cadCurves : none;
    const int firstDim = solid ? 2 : 1;
    for (int e : first) ++count[{firstDim, e}];
    if (first.empty())
      for (int e : second) ++count[{1, e}];
    if (first.empty() && second.empty() && f.entity > 0) ++count[{mesh.dim, -f.entity}];
  }
  // A mesh made from CAD has classified nodes (a mesh read from a file has none).
  for (std::size_t n = 0; n < mesh.nodeCadIndex.size() && !classified; ++n)
    classified = mesh.nodeCadIndex[n] > 0;
  if (!classified) return {};
  std::vector<std::pair<std::pair<int, int>, std::size_t>> order(count.begin(), count.end());
  // Most elements first; then boundary entities of the higher dimension, then inside.
  const auto rank = [](const std::pair<int, int>& e) { return e.second < 0 ? 3 : 3 - e.first; };
  std::stable_sort(order.begin(), order.end(), [&rank](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : rank(a.first) < rank(b.first);
  });
  std::string text = "at";
  for (std::size_t k = 0; k < order.size() && k < maxEntities; ++k) {
    const auto [dim, index] = order[k].first;
    text += std::string(k == 0 ? " " : ", ") + (index < 0 ? "inside " : "") +
            cadEntityName(dim, std::abs(index)) + " (" + std::to_string(order[k].second) +
            (k == 0 ? (order[k].second == 1 ? " element)" : " elements)") : ")");
  }
  if (order.size() > maxEntities)
    text += " and " + std::to_string(order.size() - maxEntities) + " more entities";
  return text;
}

const char* validityName(Validity v) {
  switch (v) {
    case Validity::Valid:
      return "valid";
    case Validity::Invalid:
      return "invalid";
    default:
      return "undecided";
  }
}

void appendQuality(JsonWriter& json, const Mesh& mesh, const QualitySummary& q) {
  json.beginObject("quality");
  appendMeasure(json, "scaled_jacobian", q.scaled, true);
  appendMeasure(json, "distortion", q.distortionSummary, true);
  json.value("invalid_elements", q.invalid);
  json.value("undecided_elements", q.undecided);
  json.value("certified", q.certified);
  char method[200];
  std::snprintf(method, sizeof method,
                "scaled Jacobian min J / max J from Bezier bounds refined to %g relative; "
                "distortion d J^(2/d) / |F|^2 against the straight-sided element, sampled",
                kJacobianBoundTolerance);
  json.value("method", method);
  json.beginObject("by_type");
  for (const auto& [type, t] : q.byType) {
    json.beginObject(cellShortName(type));
    json.value("count", t.count);
    json.value("invalid_elements", t.invalid);
    json.value("undecided_elements", t.undecided);
    appendMeasure(json, "scaled_jacobian", t.scaledJacobian, false);
    appendMeasure(json, "distortion", t.distortion, false);
    json.endObject();
  }
  json.endObject();
  const std::string where = notValidLocation(mesh, q);
  if (!where.empty()) json.value("where", where);
  // Where the problems are: element index, type, CAD entity, verdict, and the interval that
  // holds its min J / max J.
  json.beginArray("flagged_elements");
  for (const FlaggedElement& f : flaggedElements(mesh, q, kMaxFlaggedElements)) {
    json.beginObject();
    json.value("element", f.index);
    json.value("type", cellShortName(f.type));
    json.value("entity", f.entity);
    json.value("verdict", validityName(f.validity));
    json.numbers("scaled_jacobian", std::vector<double>{f.lower, f.upper});
    json.numbers("cad_faces", std::vector<std::size_t>(f.cadFaces.begin(), f.cadFaces.end()));
    json.numbers("cad_curves", std::vector<std::size_t>(f.cadCurves.begin(), f.cadCurves.end()));
    json.endObject();
  }
  json.endArray();
  json.endObject();
}

void appendGeometry(JsonWriter& json, const GeometryAccuracy& g) {
  json.beginObject("geometry");
  json.value("max_distance", g.maxDistance);
  json.value("max_distance_relative", g.maxDistanceRelative());
  json.value("mean_distance_relative", g.meanDistanceRelative());
  json.value("max_normal_angle_deg", g.maxAngleDeg);
  json.value("mean_normal_angle_deg", g.meanAngleDeg);
  json.value("samples", g.samples);
  json.value("angle_samples", g.angleSamples);
  json.value("undefined_normals", g.undefinedNormals);
  json.value("diagonal", g.diagonal);
  json.value("worst_entity", g.worstEntity);
  if (!g.worstEntity.empty())
    json.numbers("worst_point",
                 std::vector<double>{g.worstPoint.x(), g.worstPoint.y(), g.worstPoint.z()});
  json.value("worst_angle_entity", g.worstAngleEntity);
  if (!g.worstAngleEntity.empty())
    json.numbers(
        "worst_angle_point",
        std::vector<double>{g.worstAnglePoint.x(), g.worstAnglePoint.y(), g.worstAnglePoint.z()});
  json.value("method",
             "boundary cells sampled at quadrature points of degree 2P+2 and at their nodes, "
             "projected on their CAD face or curve; angle between mesh and CAD normals (2D: "
             "tangents), unsigned");
  json.endObject();
}

void appendSizing(JsonWriter& json, const SizingResult& sizing) {
  const SizingOctree& octree = *sizing.octree;
  const SizingParameters& p = octree.parameters();
  const OctreeStatistics& s = octree.statistics();
  const ElementCountPrediction& e = sizing.prediction;
  json.beginObject("sizing");
  json.value("method", "octree");
  json.value("min_delta", p.minDelta);
  json.value("max_delta", p.maxDelta);
  json.value("eps", p.eps);
  json.value("gradation", p.gradation);
  json.value("thin_wall", p.thinWall);
  json.value("narrow_face", p.narrowFace);
  json.beginArray("sources");
  for (const RefinementSource& src : p.sources) json.value("", src.describe());
  json.endArray();
  json.value("predicted_elements", static_cast<std::size_t>(std::llround(e.elements)));
  json.value("domain_measure", e.domainMeasure);
  json.value("volume_integral", e.volumeIntegral);
  json.value("boundary_integral", e.boundaryIntegral);
  json.value("gradient_integral", e.gradientIntegral);
  json.beginObject("octree");
  json.value("leaves", s.leaves);
  json.value("inside_leaves", s.insideLeaves);
  json.value("boundary_leaves", s.boundaryLeaves);
  json.value("outside_leaves", s.outsideLeaves);
  json.value("max_level", s.maxLevel);
  json.value("boundary_samples", s.boundarySamples);
  json.value("curvature_samples", s.sizedSamples);
  json.value("thin_wall_samples", s.thinWallSamples);
  json.value("narrow_face_samples", s.narrowFaceSamples);
  json.value("smallest_delta", s.smallestDelta);
  json.endObject();
  json.value("seconds", sizing.seconds);
  json.endObject();
}

std::string predictReportJson(const SizingResult& sizing, const std::string& input) {
  JsonWriter json;
  json.beginObject();
  json.value("input", input);
  json.value("dimension", sizing.prediction.dim);  // of the mesh: 2 for a surface mesh
  json.value("predicted_elements",
             static_cast<std::size_t>(std::llround(sizing.prediction.elements)));
  appendSizing(json, sizing);
  appendHealing(json, sizing.healing);
  json.endObject();
  return json.str();
}

void appendBoundaryLayer(JsonWriter& json, const MeshResult& result) {
  const BoundaryLayerRecord& r = *result.boundaryLayer;
  json.beginObject("boundary_layer");
  json.numbers("faces",
               std::vector<std::size_t>(r.parameters.faces.begin(), r.parameters.faces.end()));
  json.value("thickness", r.parameters.thickness);
  json.value("layers", static_cast<std::size_t>(r.parameters.layers));
  json.value("progression", r.parameters.progression);
  json.beginObject("height");
  json.value("min", r.thicknessMin);
  json.value("max", r.thicknessMax);
  json.endObject();
  if (result.layerSplit) {  // measured on the split layer (layer_split.hpp)
    const LayerSplitStats& s = *result.layerSplit;
    json.beginObject("first_height");
    json.value("min", s.firstHeightMin);
    json.value("max", s.firstHeightMax);
    json.value("worst_deviation", s.firstHeightDeviation);
    json.value("corner_cells", s.cornerCells);
    json.value("worst_deviation_at_corners", s.firstHeightCornerDeviation);
    json.value("points", s.firstHeightMeasured);
    json.value("points_off_normal", s.firstHeightOffNormal);
    json.endObject();
  }
  json.beginArray("shrunk");
  for (const LayerShrink& s : r.shrunk) {
    json.beginObject();
    json.value("face", static_cast<std::size_t>(s.face));
    json.numbers("where", std::vector<double>(s.where.begin(), s.where.end()));
    json.value("factor", s.factor);
    json.value("nodes", s.nodes);
    json.endObject();
  }
  json.endArray();
  json.value("macro_cells", r.cells);
  json.value("fan_triangles", r.fanTriangles);
  json.value("wall_splits", r.wallSplits);
  json.value("side_quadrilaterals", r.sideQuadrilaterals);
  json.value("wall_nodes", r.wallNodes);
  json.value("shrink_passes", static_cast<std::size_t>(r.shrinkPasses));
  json.value("released_around_invalid", r.release != LayerRelease::None);
  json.value("release", std::string(layerReleaseName(r.release)));
  if (result.macroQuality) {
    json.value("macro_worst_scaled_jacobian", result.macroQuality->scaled.min);
    json.value("macro_invalid", result.macroQuality->invalid);
    json.value("macro_undecided", result.macroQuality->undecided);
  }
  if (result.layerSplit) {
    json.value("split_projected_nodes", result.layerSplit->projected);
    json.value("split_max_projection", result.layerSplit->maxProjection);
    json.value("split_plain_columns", result.layerSplit->plainColumns);
  }
  json.value("seconds", r.seconds);
  json.endObject();
}

std::string meshReportJson(const MeshResult& result, const std::string& input) {
  JsonWriter json;
  json.beginObject();
  json.value("input", input);
  if (result.cad) {
    json.beginObject("cad");
    json.value("solids", result.cad->numSolids());
    json.value("faces", result.cad->numFaces());
    json.value("edges", result.cad->numEdges());
    json.value("vertices", result.cad->numVertices());
    json.value("diagonal", result.cad->boundingDiagonal());
    json.endObject();
    appendHealing(json, result.healing);
  }
  json.value("dimension", result.mesh.dim);
  json.value("order", result.mesh.order);
  json.value("size", result.options.size.value_or(0.0));
  json.value("nodes", result.mesh.numNodes());
  appendCounts(json, result.mesh);
  json.value("tangent_ears_split", result.tangentEars);
  if (result.sizing) {
    json.value("predicted_elements",
               static_cast<std::size_t>(std::llround(result.sizing->prediction.elements)));
    appendSizing(json, *result.sizing);
  }
  appendQuality(json, result.mesh, result.quality);
  if (result.geometry) appendGeometry(json, *result.geometry);
  if (result.optimiser) appendOptimiser(json, *result.optimiser);
  if (result.lowOrderOptimiser)
    appendOptimiser(json, *result.lowOrderOptimiser,
                    "optimiser_order_" + std::to_string(kContinuationOrder));
  appendRepairRounds(json, result.rounds);
  if (result.boundaryLayer) appendBoundaryLayer(json, result);
  appendStrings(json, "notes", result.notes);
  appendJob(json, result.job);
  json.beginObject("timings_s");
  for (const auto& [stage, s] : result.timings.seconds) json.value(stage, s);
  json.endObject();
  json.endObject();
  return json.str();
}

namespace {

// The report of a mesh file: input, dimension, order, counts, quality, and the optimiser's
// record when there is one.
std::string fileReportJson(const Mesh& mesh, const QualitySummary& quality,
                           const OptimiserResult* optimiser, const std::string& input,
                           const std::vector<std::string>& notes) {
  JsonWriter json;
  json.beginObject();
  json.value("input", input);
  json.value("dimension", mesh.dim);
  json.value("order", mesh.order);
  json.value("nodes", mesh.numNodes());
  appendCounts(json, mesh);
  appendQuality(json, mesh, quality);
  if (optimiser != nullptr) appendOptimiser(json, *optimiser);
  appendStrings(json, "notes", notes);
  json.endObject();
  return json.str();
}

}  // namespace

std::string qualityReportJson(const Mesh& mesh, const QualitySummary& quality,
                              const std::string& input, const std::vector<std::string>& notes) {
  return fileReportJson(mesh, quality, nullptr, input, notes);
}

void appendOptimiser(JsonWriter& json, const OptimiserResult& r, const std::string& key) {
  json.beginObject(key);
  json.value("functional", functionalName(r.functional));
  json.value("iterations", r.iterations);
  json.value("converged", r.converged);
  json.value("stopped", r.stopReason);
  json.value("cancelled", r.cancelled);
  json.value("kept_iteration", r.keptIteration);
  json.value("worst_before", r.worstBefore);
  json.value("worst_after", r.worstAfter);
  json.value("invalid_before", r.invalidBefore);
  json.value("invalid_after", r.invalidAfter);
  json.value("undecided_before", r.undecidedBefore);
  json.value("undecided_after", r.undecidedAfter);
  json.value("nodal_worst_before", r.nodalWorstBefore);
  json.value("nodal_worst_after", r.nodalWorstAfter);
  json.value("energy_before", r.energyBefore);
  json.value("energy_after", r.energyAfter);
  json.value("free_nodes", r.freeNodes);
  json.value("node_visits", r.visits);
  json.value("sliding_visits", r.slides);
  json.value("cad_evaluations", r.cadEvaluations);
  json.value("colours", r.colours);
  json.value("region_elements", r.regionElements);
  json.value("seconds", r.seconds);
  json.value("setup_seconds", r.setupSeconds);
  json.value("sweep_seconds", r.sweepSeconds);
  json.beginArray("history");
  for (const IterationRecord& h : r.history) {
    json.beginObject();
    json.value("iteration", h.iteration);
    json.value("worst", h.worst);
    json.value("invalid", h.invalid);
    json.value("undecided", h.undecided);
    json.value("max_displacement", h.maxDisplacement);
    json.value("max_relative_move", h.maxRelativeMove);
    json.value("visits", h.visits);
    json.value("energy", h.energy);
    json.value("seconds", h.seconds);
    if (h.partial) json.value("partial", true);
    json.endObject();
  }
  json.endArray();
  json.endObject();
}

std::string optimiseReportJson(const Mesh& mesh, const QualitySummary& quality,
                               const OptimiserResult& result, const std::string& input,
                               const std::vector<std::string>& notes) {
  return fileReportJson(mesh, quality, &result, input, notes);
}

void appendRepairRounds(JsonWriter& json, const std::vector<RepairRound>& rounds) {
  json.beginArray("rounds");
  for (const RepairRound& r : rounds) {
    json.beginObject();
    json.value("invalid", r.invalid);
    json.value("undecided", r.undecided);
    json.value("action", r.action);
    json.value("elements", r.elements);
    json.value("edges_split", r.edgesSplit);
    json.value("flips", r.flips);
    json.value("refinement_spheres", r.sources);
    json.value("cavities", r.cavities);
    json.value("invalid_after", r.invalidAfter);
    json.value("undecided_after", r.undecidedAfter);
    json.value("worst", r.worst);
    json.value("worst_after", r.worstAfter);
    json.value("mesh_elements", r.meshElements);
    json.value("reused_elements", r.reused);
    json.value("kept", r.kept);
    if (!r.failure.empty()) json.value("failure", r.failure);
    if (r.budgetStopped) json.value("stopped", std::string("time budget"));
    if (!r.optimiserStopped.empty()) {
      json.beginObject("optimiser");
      json.value("region_elements", r.optimiserRegion);
      json.value("sweeps", static_cast<std::size_t>(r.optimiserSweeps));
      json.value("stopped", r.optimiserStopped);
      json.value("seconds", r.optimiserSeconds);
      json.endObject();
    }
    json.value("seconds", r.seconds);
    json.endObject();
  }
  json.endArray();
}

}  // namespace homesh
