#include "io/quality_report.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

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

// The report of a mesh file: input, dimension, order, counts, quality, and the optimiser's
// record when there is one.
std::string fileReportJson(const Mesh& mesh, const QualitySummary& quality,
                           const OptimiserResult* optimiser, const std::string& input,
                           const std::vector<std::string>& notes,
                           const FileGeometry* geometry = nullptr) {
  JsonWriter json;
  json.beginObject();
  json.value("input", input);
  json.value("dimension", mesh.dim);
  json.value("order", mesh.order);
  json.value("nodes", mesh.numNodes());
  appendCounts(json, mesh);
  appendQuality(json, mesh, quality);
  if (optimiser != nullptr) appendOptimiser(json, *optimiser);
  if (geometry != nullptr) {
    json.value("cad", geometry->cad);
    appendGeometry(json, geometry->accuracy);
  }
  appendStrings(json, "notes", notes);
  json.endObject();
  return json.str();
}

}  // namespace

void appendStrings(JsonWriter& json, const std::string& key, const std::vector<std::string>& v) {
  json.beginArray(key);
  for (const std::string& text : v) json.value("", text);
  json.endArray();
}

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

std::string qualityReportJson(const Mesh& mesh, const QualitySummary& quality,
                              const std::string& input, const std::vector<std::string>& notes,
                              const FileGeometry* geometry) {
  return fileReportJson(mesh, quality, nullptr, input, notes, geometry);
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
  json.value("energy_rule", r.energyRule);
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

}  // namespace homesh
