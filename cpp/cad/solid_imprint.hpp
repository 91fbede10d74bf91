// Solids that touch, made to share the faces, edges and vertices where they touch, so that one
// mesh conforms across them (conjugate heat transfer, multi-zone and rotating-zone CFD): OCCT's
// general fuse (BOPAlgo_Builder) with the touching solids as its arguments. A face of one solid
// lying on a face of another, wholly or in part, is split where they overlap, and the overlap
// becomes one face of both. Every solid stays a solid of its own, SolidN in the same order; the
// faces, edges and vertices are numbered afresh (FreeCAD's numbering of the result), and the
// record maps each original number to the final ones (the operation's history).
//
// Solids that share volume (they overlap, not only touch) are cut where they overlap: each
// overlap becomes a solid of its own, meshed once, so that no two elements cover one place; a
// solid and its copy become one solid. The record says so (overlap) and maps each original
// solid to its pieces. Not imprinted, with a warning: a fuse OCCT fails, or one that removes a
// solid; that model is meshed as it is, each solid with its own nodes where they touch. Where
// solids touch only at a point or along a line, the edges the fuse leaves inside their faces
// are taken out (ImprintRecord::contactEdges).
#pragma once

#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "cad/numbering_map.hpp"

namespace homesh {

// How messages name the operation (a number it removed, ...).
inline constexpr const char* kImprintOperation = "imprinting the touching solids";

// A face two solids share after imprinting (final numbers; solidA < solidB).
struct SolidInterface {
  int face = 0, solidA = 0, solidB = 0;
};

struct ImprintRecord {
  bool enabled = true;     // HealingOptions::imprint
  int solids = 0;          // in the model
  int touching = 0;        // solids whose bounding boxes meet another's: the fuse's arguments
  int joined = 0;          // solids the imprint changed: they now share faces, edges or vertices
  bool imprinted = false;  // the model changed: solids now share faces (or edges, vertices)
  std::vector<SolidInterface> interfaces;
  NumberingMap numbering;  // original numbers to final ones (identity when not imprinted)
  std::string warning;     // why touching solids were not imprinted ("" when they were)
  // Solids that shared volume and were cut where they overlap, with their pieces' final
  // numbers, in words ("" when none did).
  std::string overlap;
  // Edges the fuse left inside faces where solids touch at a point or along a line (balls on
  // their races), taken out (counted once per face they were in): they bound no face (nothing
  // to conform across) and Gmsh cannot mesh those shorter than its elements.
  int contactEdges = 0;
  // The fuzzy value the fuse used: the tolerance given, or a tenth of it where the first fuse
  // stretched a vertex's or edge's tolerance past ten times the value (0: no fuse ran).
  double fuzzy = 0.0;
  double seconds = 0.0;
};

// The model with its touching solids imprinted on each other (see above); `cad` itself when it
// has fewer than two solids, none touch, or imprinting is not possible (record.warning says
// why). `tolerance`: how far apart two faces may lie and still be one (model units; OCCT's fuzzy
// value). Fills `record` (its `enabled` as the caller set it).
CadModel imprintSolids(CadModel cad, double tolerance, ImprintRecord& record);

}  // namespace homesh
