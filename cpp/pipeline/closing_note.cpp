#include "pipeline/closing_note.hpp"

#include <cstdio>
#include <vector>

#include "cad/face_cusps.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "io/quality_report.hpp"
#include "pipeline/job_messages.hpp"
#include "pipeline/repair.hpp"

namespace homesh {

namespace {

// The cusps of the CAD, none where OCCT fails a query on the way (they only explain).
std::vector<FaceCusp> cadCusps(const CadModel& cad) {
  try {
    return findFaceCusps(cad);
  } catch (const CadError&) {
    return {};
  }
}

// The cusps of the CAD at which elements not proven valid have a corner, and how many such
// elements (elementsAtCusps): the CAD, not the mesher, keeps those from being proven valid.
// Empty when there are none.
std::string cuspText(const MeshResult& result) {
  if (!result.cad) return {};
  const std::vector<FaceCusp> cusps = cadCusps(*result.cad);
  const CuspElements at = elementsAtCusps(result.mesh, result.quality, cusps);
  if (at.elements.empty()) return {};
  const std::size_t n = at.elements.size();
  const std::size_t all = result.quality.invalid + result.quality.undecided;
  // "it has" for the one element, "all 8 have" for every one, "3 of them have" for some.
  std::string text =
      n == all ? (n == 1 ? std::string("; it has") : "; all " + std::to_string(n) + " have")
               : "; " + std::to_string(n) + " of them " + (n == 1 ? "has" : "have");
  text +=
      " a corner at a cusp of the CAD, where two edges of a face leave a vertex in the same "
      "direction (";
  int listed = 0;
  for (std::size_t c = 0; c < cusps.size(); ++c) {
    if (at.perCusp[c] == 0) continue;
    if (listed == 3) {
      text += ", ...";
      break;
    }
    const FaceCusp& cusp = cusps[c];
    text += std::string(listed++ == 0 ? "" : ", ") + "Face" + std::to_string(cusp.face) +
            " at Vertex" + std::to_string(cusp.vertex) + " between Edge" +
            std::to_string(cusp.edgeA) + " and Edge" + std::to_string(cusp.edgeB);
  }
  // (A Jacobian positive there rests on the edges' polynomials missing the CAD's tangents on
  // the right side: FreeCAD's I22 inductors end valid with some builds and not with others.)
  return text +
         "): a mesh that follows the CAD has a zero Jacobian there, and such an element is proven "
         "valid only where its polynomial edges miss the CAD's tangents on the right side";
}

}  // namespace

std::string notValidNote(const MeshResult& result, bool linearGiven) {
  const QualitySummary& q = result.quality;
  const std::size_t count = q.invalid + q.undecided;
  std::string text = std::to_string(count) + (count == 1 ? " element" : " elements") +
                     " not proven valid (" + std::to_string(q.invalid) + " invalid, " +
                     std::to_string(q.undecided) + " undecided)";
  const std::string where = notValidLocation(result.mesh, q);
  if (!where.empty()) text += " " + where;
  text += cuspText(result);
  if (result.mesh.isSurface())
    text += "; a surface mesh (no optimiser: its nodes are where curving put them on the faces)";
  else
    text += result.options.optimiseIterations == 0
                ? std::string(
                      "; the optimiser did not run (--optimise, Python optimise > 0, "
                      "FreeCAD OptimiserIterations > 0 may make them valid)")
                : std::string("; after the optimiser");
  if (linearGiven) return text + "; no repair rounds (the linear mesh was given)";
  if (result.rounds.empty())
    return text + (result.options.repairRounds == 0
                       ? "; no repair rounds (" + parameterText("repair_rounds") + " 0)"
                       : std::string("; no repair round ran"));
  text += "; " + std::to_string(result.rounds.size()) + " repair round" +
          (result.rounds.size() == 1 ? "" : "s") + " (";
  for (std::size_t k = 0; k < result.rounds.size(); ++k) {
    const RepairRound& r = result.rounds[k];
    text += (k == 0 ? "" : ", ") + r.action +
            (!r.failure.empty() ? " failed"
             : r.kept           ? ""
                                : " not kept");
  }
  text += ")";
  if (static_cast<int>(result.rounds.size()) == result.options.repairRounds)
    text += ", all that " + parameterText("repair_rounds") + " allows";
  return text;
}

std::vector<std::string> layerShortNotes(const BoundaryLayerRecord& layer, int dim) {
  std::vector<std::string> notes;
  for (const LayerShrink& f : layer.faces) {
    if (f.fullHeight() >= kFullLayerShare && f.factor >= 0.5) continue;
    char text[256];
    std::snprintf(text, sizeof text,
                  "the boundary layer on %s%d reaches its thickness on %.0f %% of its %zu columns; "
                  "the thinnest is %s of it, at (%g, %g, %g)",
                  dim == 3 ? "Face" : "Edge", f.face, 100.0 * f.fullHeight(), f.columns,
                  formatNumber(f.factor).c_str(), f.where[0], f.where[1], f.where[2]);
    notes.emplace_back(text);
    if (f.gap.across == 0) continue;
    std::snprintf(text, sizeof text,
                  "; %s%d is %s away along the layer's normal at (%g, %g, %g): room for %s of "
                  "the %s asked there",
                  dim == 3 ? "Face" : "Edge", f.gap.across, formatNumber(f.gap.width).c_str(),
                  f.gap.where[0], f.gap.where[1], f.gap.where[2], formatNumber(f.gap.room).c_str(),
                  formatNumber(f.gap.asked).c_str());
    notes.back() += text;
  }
  return notes;
}

}  // namespace homesh
