#include "pipeline/report.hpp"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "pipeline/mesh_pipeline.hpp"  // kContinuationOrder

namespace homesh {
namespace {

// `key`: every number of `numbering` that changed, original -> final numbers, per kind of
// sub-shape ({"faces": [{"from": 8, "to": [1]}, ...], ...}); none when `changed` is false.
void appendNumbering(JsonWriter& json, const char* key, const NumberingMap& numbering,
                     bool changed) {
  json.beginObject(key);
  static const char* kinds[] = {"vertices", "edges", "faces", "solids"};
  for (int dim = 0; dim < 4; ++dim) {
    json.beginArray(kinds[dim]);
    if (changed)
      for (const auto& [from, to] : numbering.changes(dim)) {
        json.beginObject();
        json.value("from", from);
        json.numbers("to", std::vector<std::size_t>(to.begin(), to.end()));
        json.endObject();
      }
    json.endArray();
  }
  json.endObject();
}

// "imprint" (inside "healing"): whether touching solids were imprinted on each other, the
// faces two solids now share (final FaceN, their SolidN) and every number that changed,
// original -> final, per kind of sub-shape (none when the model was not imprinted).
void appendImprint(JsonWriter& json, const ImprintRecord& r) {
  json.beginObject("imprint");
  json.value("enabled", r.enabled);
  json.value("solids", r.solids);
  json.value("touching", r.touching);  // solids whose boxes meet another's: the fuse's arguments
  json.value("joined", r.joined);      // solids the imprint changed
  json.value("imprinted", r.imprinted);
  json.value("warning", r.warning);
  json.value("overlap", r.overlap);             // solids that shared volume, cut where they overlap
  json.value("contact_edges", r.contactEdges);  // point and line contacts' edges taken out
  json.value("fuzzy", r.fuzzy);                 // the fuse's fuzzy value (0: none ran)
  json.beginArray("interfaces");
  for (const SolidInterface& i : r.interfaces) {
    json.beginObject();
    json.value("face", i.face);
    json.numbers("solids", std::vector<std::size_t>{static_cast<std::size_t>(i.solidA),
                                                    static_cast<std::size_t>(i.solidB)});
    json.endObject();
  }
  json.endArray();
  appendNumbering(json, "renumbered", r.numbering, r.imprinted);
  json.value("seconds", r.seconds);
  json.endObject();
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
  // Whether healing's steps (imprinting apart) numbered the faces or edges afresh.
  json.value("renumbered", h.renumbered);
  // The file's numbers to the meshed model's, through healing and imprinting: how the numbers
  // given (boundary-layer faces, groups, refinement curves) were mapped, and what the mesh's
  // FaceN groups were in the file.
  appendNumbering(json, "numbering", h.numbering, h.numbering.changed());
  json.value("faces_before", h.facesBefore);
  json.value("faces_after", h.facesAfter);
  json.value("solids_before", h.solidsBefore);
  json.value("solids_after", h.solidsAfter);
  json.value("seconds", h.seconds);
  appendImprint(json, h.imprint);
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

void appendSizing(JsonWriter& json, const SizingResult& sizing) {
  const SizingOctree& octree = *sizing.octree;
  const SizingParameters& p = octree.parameters();
  const OctreeStatistics& s = octree.statistics();
  const ElementCountPrediction& e = sizing.prediction;
  json.beginObject("sizing");
  json.value("method", "octree");
  json.value("min_delta", p.minDelta);
  json.value("min_delta_set_by", p.minDeltaSetBy.empty() ? "given" : p.minDeltaSetBy);
  json.value("max_delta", p.maxDelta);
  json.value("max_delta_set_by", p.maxDeltaSetBy.empty() ? "given" : p.maxDeltaSetBy);
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
  json.value("core_integral", e.coreIntegral);
  json.value("boundary_integral", e.boundaryIntegral);
  json.value("curve_integral", e.curveIntegral);
  json.value("convexity_integral", e.convexityIntegral);
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

namespace {

// The certified quality of a macro layer's mesh before its split.
void appendMacroQuality(JsonWriter& json, const StageRecords& records) {
  if (!records.macroQuality) return;
  json.value("macro_worst_scaled_jacobian", records.macroQuality->scaled.min);
  json.value("macro_invalid", records.macroQuality->invalid);
  json.value("macro_undecided", records.macroQuality->undecided);
}

}  // namespace

void appendBoundaryLayer(JsonWriter& json, const StageRecords& records) {
  const BoundaryLayerRecord& r = *records.boundaryLayer;
  json.beginObject("boundary_layer");
  json.numbers("faces",
               std::vector<std::size_t>(r.parameters.faces.begin(), r.parameters.faces.end()));
  json.numbers("solids",
               std::vector<std::size_t>(r.parameters.solids.begin(), r.parameters.solids.end()));
  json.value("thickness", r.parameters.thickness);
  json.value("layers", static_cast<std::size_t>(r.parameters.layers));
  json.value("progression", r.parameters.progression);
  json.beginObject("height");
  json.value("min", r.thicknessMin);
  json.value("max", r.thicknessMax);
  json.endObject();
  if (records.layerSplit) {  // measured on the split layer (layer_split.hpp)
    const LayerSplitStats& s = *records.layerSplit;
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
  for (const LayerShrink& s : r.shrunk()) {
    json.beginObject();
    json.value("face", static_cast<std::size_t>(s.face));
    json.numbers("where", std::vector<double>(s.where.begin(), s.where.end()));
    json.value("factor", s.factor);
    json.value("nodes", s.nodes);
    json.endObject();
  }
  json.endArray();
  json.beginArray("columns");  // every layer face: how much of it got the height asked
  for (const LayerShrink& s : r.faces) {
    json.beginObject();
    json.value("face", static_cast<std::size_t>(s.face));
    json.value("columns", s.columns);
    json.value("full_height", s.fullHeight());
    json.value("smallest_factor", s.factor);
    if (s.nodes > 0) json.numbers("where", std::vector<double>(s.where.begin(), s.where.end()));
    if (s.gap.across != 0) {  // the narrowest gap that held a column down
      json.beginObject("gap");
      json.value("width", s.gap.width);
      json.value("to", static_cast<std::size_t>(s.gap.across));
      json.numbers("where", std::vector<double>(s.gap.where.begin(), s.gap.where.end()));
      json.value("asked", s.gap.asked);
      json.value("room", s.gap.room);
      json.endObject();
    }
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
  appendMacroQuality(json, records);
  if (records.layerSplit) {
    json.value("split_projected_nodes", records.layerSplit->projected);
    json.value("split_max_projection", records.layerSplit->maxProjection);
    json.value("split_plain_columns", records.layerSplit->plainColumns);
  }
  json.value("seconds", r.seconds);
  json.endObject();
}

// A given mesh's boundary layer as recognised (layer_stacks.hpp) and as split.
void appendGivenLayers(JsonWriter& json, const StageRecords& records) {
  const LayerStacksRecord& r = *records.givenLayers;
  json.beginObject("given_layers");
  json.numbers("walls", std::vector<std::size_t>(r.walls.begin(), r.walls.end()));
  json.value("stacks", r.stacks);
  json.value("hexahedral_stacks", r.hexStacks);
  json.value("layers", static_cast<std::size_t>(r.layers));
  json.value("columns", r.columns);
  json.value("side_quadrilaterals", r.sidesMerged);
  json.numbers("levels", r.levels);
  json.value("level_spread", r.levelSpread);
  json.beginObject("given_first_height");
  json.value("min", r.firstHeightMin);
  json.value("max", r.firstHeightMax);
  json.endObject();
  if (records.layerSplit) {
    const LayerSplitStats& s = *records.layerSplit;
    json.beginObject("first_height");
    json.value("min", s.firstHeightMin);
    json.value("max", s.firstHeightMax);
    json.value("worst_deviation", s.firstHeightDeviation);
    json.value("points", s.firstHeightMeasured);
    json.endObject();
    json.value("split_plain_columns", s.plainColumns);
  }
  appendMacroQuality(json, records);
  json.endObject();
}

std::string meshReportJson(const CurvedMesh& curved, const StageRecords& records,
                           const std::string& input) {
  JsonWriter json;
  json.beginObject();
  json.value("input", input);
  if (curved.cad) {
    json.beginObject("cad");
    json.value("solids", curved.cad->numSolids());
    json.value("faces", curved.cad->numFaces());
    json.value("edges", curved.cad->numEdges());
    json.value("vertices", curved.cad->numVertices());
    json.value("diagonal", curved.cad->boundingDiagonal());
    json.endObject();
    appendHealing(json, records.healing);
  }
  json.value("dimension", curved.mesh.dim);
  json.value("order", curved.mesh.order);
  json.value("size", records.options.size.value_or(0.0));
  json.value("nodes", curved.mesh.numNodes());
  appendCounts(json, curved.mesh);
  json.value("tangent_ears_split", records.tangentEars);
  if (records.sizing) {
    json.value("predicted_elements",
               static_cast<std::size_t>(std::llround(records.sizing->prediction.elements)));
    appendSizing(json, *records.sizing);
  }
  appendQuality(json, curved.mesh, curved.quality);
  if (records.geometry) appendGeometry(json, *records.geometry);
  if (records.optimiser) appendOptimiser(json, *records.optimiser);
  if (records.lowOrderOptimiser)
    appendOptimiser(json, *records.lowOrderOptimiser,
                    "optimiser_order_" + std::to_string(kContinuationOrder));
  appendRepairRounds(json, records.rounds);
  if (records.boundaryFit) {
    json.beginObject("boundary_fit");
    json.value("triangles", records.boundaryFit->triangles);
    json.value("fitted", records.boundaryFit->fitted);
    json.value("tiers", records.boundaryFit->tiers);
    json.value("frozen_nodes", records.boundaryFit->frozenNodes);
    json.value("vertices_moved", records.boundaryFit->verticesMoved);
    json.value("remeasured_elements", records.boundaryFit->remeasured);
    json.value("stopped", records.boundaryFit->stopped);
    json.endObject();
  }
  if (records.boundaryLayer) appendBoundaryLayer(json, records);
  if (records.givenLayers) appendGivenLayers(json, records);
  appendStrings(json, "notes", records.notes);
  appendJob(json, records.job);
  json.beginObject("timings_s");
  for (const auto& [stage, s] : records.timings.seconds) json.value(stage, s);
  json.endObject();
  json.endObject();
  return json.str();
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
