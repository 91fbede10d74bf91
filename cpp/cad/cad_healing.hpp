// CAD healing before meshing: checks a model for what defeats a mesher and, where it finds
// something and healing is on, repairs it with OpenCASCADE's shape-healing tools.
//
// Checked: OCCT's validity analysis (BRepCheck), faces not joined into a closed solid (no solid,
// or a solid whose shell has free edges), edges shorter than the healing tolerance, and tiny
// or sliver faces. Repaired, in that order: sewing faces within the tolerance and making solids
// of the closed shells (BRepBuilderAPI_Sewing, ShapeFix_Solid), general fixes of wires, edges
// and orientation (ShapeFix_Shape), small edges and wire gaps (ShapeFix_Wireframe), small faces
// (ShapeFix_FixSmallFace). Tolerances follow the model's size: 1e-6 of its bounding-box
// diagonal for sewing and fixing, at most 1e-3 of it for what a fix may widen a tolerance to.
//
// Faces that end up in no solid (a loose shell beside solids, a shell sewing cannot close) are
// not meshed: the model is refused naming them, or, with HealingOptions::solidsOnly, left out
// and recorded (HealingRecord::leftOut), never dropped silently. Loose faces that all copy faces
// of the solids are left out and recorded without solidsOnly: nothing is lost.
//
// A model with nothing to heal is returned as it is: its FaceN numbering, which boundary layers
// and boundary groups refer to, is unchanged. A healed model's numbering is mapped from the
// original's through each step's history (HealingRecord::numbering, cad/numbering_map.hpp), so
// that what a user names by number in the file is found in the model meshed.
#pragma once

#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "cad/numbering_map.hpp"
#include "cad/solid_imprint.hpp"

namespace homesh {

// How messages name healing where it removed a number (a step's own words follow it).
inline constexpr const char* kHealingOperation = "healing";

struct HealingOptions {
  bool enabled = true;      // sew and fix what the check finds; false: check only (imprint apart)
  bool solidsOnly = false;  // faces in no solid are left out (recorded) instead of refused
  // A model without solids whose faces do not close is kept as faces (a surface mesh), sewn
  // into shells where that joins them, instead of refused.
  bool surface = false;
  // For batch runs over files nobody looked at: each model gets the one of the modes above
  // that fits it. With solids: solidsOnly, so faces in no solid are left out and recorded.
  // With no solid: its faces are sewn into solids if every shell closes (as without this
  // option), else they get a surface mesh, none left out. Planar faces in one plane stay a 2D
  // model. Without it an open shell is refused: a user who meant a solid hears so instead of
  // getting triangles.
  bool automatic = false;
  // Solids that touch are imprinted on each other (cad/solid_imprint.hpp), last, after healing.
  bool imprint = true;

  // Throws ParameterError for modes that exclude each other.
  void validate() const;
};

struct HealingRecord {
  bool enabled = true;
  double tolerance = 0.0;             // of the fixes (model units)
  std::vector<std::string> problems;  // what the check found, in words, entities named
  std::vector<std::string> actions;   // what healing did (empty: the model is unchanged)
  // Why sewing made no solids of the faces, when it was tried and did not ("closed 3 of 5
  // shells"); the refusal quotes it.
  std::string sewing;
  // Solids sewing made (or could make, when the model was refused for faces left over): what
  // HealingOptions::solidsOnly would keep; 0 when sewing was not tried or found a void.
  int sewnSolids = 0;
  // The faces left out because they are in no solid (HealingOptions::solidsOnly, or copies of
  // the solids' faces: leftOutCopies), in words: how many, where, and why ("17 faces in no
  // solid (they do not close: ...), within x ...").
  std::string leftOut;
  // Those faces all copy faces of the solids (the same box, area and centre): left out without
  // HealingOptions::solidsOnly, since nothing is lost.
  bool leftOutCopies = false;
  // The model is kept as faces for a surface mesh (HealingOptions::surface): in words, how
  // many faces and shells, and whether sewing joined them.
  std::string surface;
  // HealingOptions::automatic's choice, in words (empty without it).
  std::string automatic;
  // What the mesh user must know that healing does not change: solids that lie against each
  // other on faces of their own (coincident, not shared) and were not imprinted (imprinting
  // off, or not possible), whose meshes do not conform there.
  std::vector<std::string> warnings;
  // Touching solids imprinted on each other, last (HealingOptions::imprint): the interfaces
  // made and the numbering's map from the healed model to the one meshed.
  ImprintRecord imprint;
  int facesBefore = 0, facesAfter = 0;
  int solidsBefore = 0, solidsAfter = 0;
  double seconds = 0.0;
  // The model's numbers (VertexN ... SolidN) as read, to those of the model meshed: through
  // healing's steps (sewing, fixes, faces left out), then imprinting. Where a step removed a
  // number, it says which step.
  NumberingMap numbering;
  // Healing's steps (imprinting apart: imprint.numbering) numbered the faces or edges afresh.
  bool renumbered = false;
  bool changed() const { return !actions.empty(); }
  // What a user must read about the model meshed, one line each: the faces left out (solids
  // only, or copies) and the warnings. The pipeline's notes and `homesh predict` print these.
  std::vector<std::string> notes() const {
    std::vector<std::string> lines;
    if (!automatic.empty()) lines.push_back(automatic);
    if (!surface.empty()) lines.push_back(surface);
    if (!leftOut.empty())
      lines.push_back(std::string(leftOutCopies ? "" : "solids only: ") + "left out " + leftOut);
    lines.insert(lines.end(), warnings.begin(), warnings.end());
    return lines;
  }
};

// The model to mesh: `cad` itself when the check finds nothing (or healing is off), else the
// healed model (same source name), less the faces in no solid when `options.solidsOnly`; with
// `options.surface`, a model without solids that healing cannot close stays faces (sewn into
// shells where sewing joins them without losing a face). Fills `record`. Throws CadError when
// the model (healed or not) has a solid whose boundary is open, naming the solid and a free
// edge, when faces are in no solid (without solidsOnly), naming them, when it has no solid and
// no face, and when `options.surface` is asked of a model with solids. `options.automatic`
// chooses solidsOnly or surface for the model (see HealingOptions) and says which in
// `record.automatic`. Last, with `options.imprint`, touching solids are imprinted on each other
// (record.imprint).
CadModel healModel(CadModel cad, const HealingOptions& options, HealingRecord& record);

}  // namespace homesh
