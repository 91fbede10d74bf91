#include "pipeline/mesh_summary.hpp"

#include <cstdio>

#include "core/format.hpp"
#include "pipeline/report.hpp"

namespace homesh {

namespace {

// printf into a std::string (the lines are short; 512 bytes hold the longest).
template <class... Args>
std::string formatted(const char* format, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

std::string boundaryLayerLine(const StageRecords& records, int dim) {
  const BoundaryLayerRecord& b = *records.boundaryLayer;
  const LayerSplitStats& s = *records.layerSplit;
  const bool solid = dim == 3;
  std::size_t columns = 0, shrunk = 0;
  for (const LayerShrink& f : b.faces) {
    columns += f.columns;
    shrunk += f.nodes;
  }
  return formatted(
      "boundary layer: %zu macro %s split into %d layers, height %g to %g, first layer %g to %g "
      "(worst %.2f %% off); %.1f %% of the columns at full height (shrunk on %zu %s); macro "
      "mesh worst %.4f",
      b.cells, solid ? "prisms" : "quadrilaterals", b.parameters.layers, b.thicknessMin,
      b.thicknessMax, s.firstHeightMin, s.firstHeightMax, 100.0 * s.firstHeightDeviation,
      columns == 0 ? 100.0 : 100.0 * static_cast<double>(columns - shrunk) / columns,
      b.shrunk().size(), solid ? "faces" : "curves",
      records.macroQuality ? records.macroQuality->scaled.min : 0.0);
}

std::string givenLayersLine(const StageRecords& records) {
  const LayerStacksRecord& r = *records.givenLayers;
  std::string walls;
  for (const int f : r.walls) walls += (walls.empty() ? "Face" : ", Face") + std::to_string(f);
  std::string line = formatted(
      "given boundary layer: %zu stacks (%zu of prisms, %zu of hexahedra) of %d layers (%zu "
      "columns) on %s, curved as macro cells",
      r.stacks, r.stacks - r.hexStacks, r.hexStacks, r.layers, r.columns, walls.c_str());
  if (records.macroQuality) line += formatted(" (worst %.4f)", records.macroQuality->scaled.min);
  if (records.layerSplit)
    line += formatted("; split back: first layer %g to %g (given %g to %g, worst %.2f %% off)",
                      records.layerSplit->firstHeightMin, records.layerSplit->firstHeightMax,
                      r.firstHeightMin, r.firstHeightMax,
                      100.0 * records.layerSplit->firstHeightDeviation);
  return line;
}

std::string repairLine(std::size_t k, const RepairRound& r) {
  if (!r.failure.empty())
    return formatted("repair %zu: %s %zu elements failed: %s", k + 1, r.action.c_str(), r.elements,
                     r.failure.c_str());
  return formatted(
      "repair %zu: %zu invalid, %zu undecided, worst %.4f -> %s %zu elements -> %zu invalid, %zu "
      "undecided, worst %.4f (%zu elements, %zu reused)%s",
      k + 1, r.invalid, r.undecided, r.worst, r.action.c_str(), r.elements, r.invalidAfter,
      r.undecidedAfter, r.worstAfter, r.meshElements, r.reused, r.kept ? "" : ", not kept");
}

// "imprinted 2 touching solids: 1 interface (Face2: Solid1 | Solid2); ..."
std::string imprintLine(const ImprintRecord& r) {
  std::string line = "imprinted " + std::to_string(r.joined) +
                     " touching solids: " + std::to_string(r.interfaces.size()) +
                     (r.interfaces.size() == 1 ? " face shared" : " faces shared");
  for (std::size_t k = 0; k < r.interfaces.size() && k < 3; ++k) {
    const SolidInterface& i = r.interfaces[k];
    line += (k == 0 ? " (" : ", ") + cadEntityName(2, i.face) + ": " + cadEntityName(3, i.solidA) +
            " | " + cadEntityName(3, i.solidB);
  }
  if (r.interfaces.size() > 3) line += ", ...";
  if (!r.interfaces.empty()) line += ")";
  return line + "; faces and edges numbered afresh (the report's healing.imprint maps them)";
}

std::string listed(const std::vector<std::string>& stages) {
  return stages.empty() ? std::string("none") : joined(stages);
}

}  // namespace

std::string qualityHeadline(const Mesh& mesh, const QualitySummary& quality) {
  std::string line = formatted(
      "%zu nodes, %zu elements of order %d; scaled Jacobian min %.4f mean %.4f; ", mesh.numNodes(),
      mesh.numElements(), mesh.order, quality.scaled.min, quality.scaled.mean);
  if (quality.invalid + quality.undecided == 0) return line + "all elements proven valid";
  line += formatted("NOT VALID: %zu invalid, %zu undecided", quality.invalid, quality.undecided);
  const std::string where = notValidLocation(mesh, quality);
  return where.empty() ? line : line + " " + where;
}

std::vector<std::string> predictionLines(const SizingResult& s, int dim) {
  const OctreeStatistics& st = s.octree->statistics();
  const SizingParameters& p = s.octree->parameters();
  const auto setBy = [](const std::string& why) { return why.empty() ? "given" : why.c_str(); };
  return {formatted("sizing octree: MinDelta %g (%s), MaxDelta %g (%s), EPS %g, %zu sources; %zu "
                    "leaves (%zu inside, %zu boundary), depth %d, %zu boundary samples (%zu "
                    "curved, %zu on thin walls, %zu on curves of narrow faces), smallest size %g, "
                    "%.3f s",
                    p.minDelta, setBy(p.minDeltaSetBy), p.maxDelta, setBy(p.maxDeltaSetBy), p.eps,
                    p.sources.size(), st.leaves, st.insideLeaves, st.boundaryLeaves, st.maxLevel,
                    st.boundarySamples, st.sizedSamples, st.thinWallSamples, st.narrowFaceSamples,
                    st.smallestDelta, s.seconds),
          formatted("predicted %.0f %s (%s %g)", s.prediction.elements,
                    dim == 3 ? "tetrahedra" : "triangles",
                    dim == 3 ? "domain volume" : "domain area", s.prediction.domainMeasure)};
}

std::vector<std::string> meshSummaryLines(const CurvedMesh& curved, const StageRecords& records) {
  std::vector<std::string> lines;
  for (const std::string& action : records.healing.actions)
    lines.push_back("healed the CAD: " + action);
  if (records.healing.renumbered)
    lines.push_back(formatted(
        "note: healing numbered the faces and edges afresh (%d faces, were %d): numbers given "
        "(boundary-layer faces, groups, refinement curves) are the file's, mapped; the mesh's "
        "FaceN are the healed model's (the report's healing.numbering maps them)",
        records.healing.facesAfter, records.healing.facesBefore));
  if (const ImprintRecord& imprint = records.healing.imprint; imprint.imprinted)
    lines.push_back(imprintLine(imprint));
  for (const std::string& note : records.notes) lines.push_back("note: " + note);
  if (records.sizing)
    for (std::string& line : predictionLines(*records.sizing, curved.mesh.dim))
      lines.push_back(std::move(line));
  lines.push_back(qualityHeadline(curved.mesh, curved.quality));
  if (records.boundaryLayer && records.layerSplit)
    lines.push_back(boundaryLayerLine(records, curved.mesh.dim));
  if (records.givenLayers) lines.push_back(givenLayersLine(records));
  for (std::size_t k = 0; k < records.rounds.size(); ++k)
    lines.push_back(repairLine(k, records.rounds[k]));
  if (records.job.stopped())
    lines.push_back(formatted(
        "the job time limit of %g s stopped it (stopped: time budget): cut short: %s; left out: "
        "%s",
        records.job.timeLimit, listed(records.job.cut).c_str(),
        listed(records.job.skipped).c_str()));
  return lines;
}

}  // namespace homesh
