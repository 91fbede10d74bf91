// How the numbered sub-shapes of a model (FreeCAD's VertexN, EdgeN, FaceN, SolidN) became those
// of the model an OCCT operation made of it: per dimension, each original number's final
// numbers. An operation that keeps a sub-shape maps it to the final number of that same shape;
// one that splits it, to the numbers of its pieces; one that merges it with another (a face
// two solids now share), to the one number both have; one that removes it, to none. Built from
// the operation's history (OCCT's BRepTools_History: Modified and IsRemoved), so that what a
// user named by number in the model they see (boundary-layer faces, refinement curves, groups)
// is found in the model that is meshed. Maps of operations done one after the other compose
// (then): healing's sewing and fixes, leaving faces out, imprinting.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

class TopoDS_Shape;
class BRepTools_History;

namespace homesh {

class NumberingMap {
 public:
  // No model: every lookup fails. Use identity() or fromHistory().
  NumberingMap() = default;

  // Each number of `shape` to itself.
  static NumberingMap identity(const TopoDS_Shape& shape);

  // Numbers of `before` to those of `after`, as `history` records the operation that made
  // `after` from `before`'s sub-shapes; `operation` names it where it removed one ("removed 2
  // tiny or sliver faces"). With `matchTolerance` > 0, a sub-shape the history neither
  // removes nor finds in `after` (a shape-healing context rebuilds the faces around an edge it
  // replaced without recording them) is found by where it is: the one sub-shape of `after`
  // of its kind with the same position (vertex), or centre of mass and length or area
  // (edge, face, solid), to that distance; else it counts as removed.
  static NumberingMap fromHistory(const TopoDS_Shape& before, const TopoDS_Shape& after,
                                  const BRepTools_History& history,
                                  const std::string& operation = std::string(),
                                  double matchTolerance = 0.0);

  // This operation followed by `next` (whose original is this one's result): each original
  // number to `next`'s images of its images; a number removed says by which of the two.
  NumberingMap then(const NumberingMap& next) const;

  // The map as text, to keep it beside a mesh saved without its CAD (homesh's .npz): a line
  // "D ORIGINAL FINAL" per dimension, then one line per original number, its final numbers
  // separated by spaces, "|" and what removed it (empty for one kept). fromText reads it back;
  // throws ParameterError naming the line of text that is not so.
  std::string toText() const;
  static NumberingMap fromText(const std::string& text);

  // Whether any number maps to anything but itself alone (counts differ, or a number moved);
  // of dimension `dim` alone.
  bool changed() const;
  bool changed(int dim) const;

  // How many sub-shapes of dimension `dim` (0 vertices ... 3 solids) the original has, and
  // the final model.
  int originalCount(int dim) const;
  int finalCount(int dim) const;

  // The final numbers of original number `index` of dimension `dim`, ascending (empty: removed).
  // Throws ParameterError for a number the original does not have.
  const std::vector<int>& finalNumbers(int dim, int index) const;

  // The original numbers of dimension `dim` that became final number `index` (or one of its
  // pieces' numbers), ascending: to name a final sub-shape in the numbering a user knows.
  std::vector<int> originals(int dim, int index) const;

  // originals() as a user names them, for a message about final sub-shape `index` of the
  // model meshed: "Face7", "Face7 and Face9", "Face3, Face4 and Face8"; "" where the numbers of
  // dimension `dim` did not change (the final name is the user's), and "no numbered <kind>"
  // ("no numbered solid") for one no original became (or an index the final model lacks).
  std::string givenNames(int dim, int index) const;

  // What removed original number `index` of dimension `dim` ("" when it was not removed, or
  // the operation was not named).
  const std::string& removedBy(int dim, int index) const;

  // The final numbers of `indices` (original numbers of dimension `dim`), ascending, without
  // repeats. Throws ParameterError naming `what` and the first number that was removed, and
  // by what ("boundary-layer face 7: Face7 was removed by healing (removed 1 tiny or sliver
  // face)"): removedBy, else `operation`.
  std::vector<int> map(int dim, const std::vector<int>& indices, const std::string& what,
                       const std::string& operation) const;

  // The numbers that did not map to themselves alone, as (original, finals) pairs, ascending:
  // what a report lists.
  std::vector<std::pair<int, std::vector<int>>> changes(int dim) const;

 private:
  // images_[dim][index - 1]: the final numbers of original number `index`.
  std::array<std::vector<std::vector<int>>, 4> images_;
  // removedBy_[dim][index - 1]: the operation that removed it (empty: kept, or not named).
  std::array<std::vector<std::string>, 4> removedBy_;
  std::array<int, 4> finalCount_{};
};

}  // namespace homesh
