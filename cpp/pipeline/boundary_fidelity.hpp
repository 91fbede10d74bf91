// The "boundary_fit" stage: once the mesh is curved, optimised and repaired, the nodes of its
// boundary triangles inside curved CAD faces move on them so that each triangle's surface follows
// the face's normal between its nodes (curving/face_fidelity_fit.hpp), in tiers from the largest
// normal angles down, and the elements they belong to are certified again after each: no element
// may end with a worse verdict (valid, undecided, invalid), nor any end more than 0.1 %
// (kWorstLoss) below the lower of its own value before the stage and the mesh's worst before. The
// moved nodes of an element that does are frozen where they were and the tier fitted again around
// them (a few rounds, then the tier is undone and the stage ends), so the mesh's verdict is never
// worse than the stage's input and its worst element at most 0.1 % lower (the certified measure's
// resolution): the trade for fidelity, made explicit. The stage ends once a triangle next to a
// frozen node keeps an angle at least as large as any left to fit (the volume holds the largest
// angle there); then rounds of vertex patches (corners moved with their star of triangles, the
// volume's nodes around dragged along) around the largest angles left, each patch kept only if
// its elements keep the same promise. The nodes of prisms, pyramids and hexahedra stay: a
// boundary layer's heights are measured from its wall, and the wall's triangles, having nothing
// to fit, neither join a tier nor count as held.
//
// Why a stage of its own, after the optimiser: the optimiser's untangling slides the boundary's
// nodes for the volume, and the facet and fidelity terms join only once the mesh is valid, where
// nodes of good elements rest; on the sphere in a box at orders 5 and 6 (size 0.8) its final run
// kept its input, so the boundary was the raise's placement. Fitting the placement before the
// optimiser instead changed the untangling's path and scattered the results (the largest normal
// angle 0.15 -> 2.4 degrees at order 5, 0.99 -> 1.46 at order 3 on size 1.2).
#pragma once

#include <cstddef>
#include <functional>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

struct BoundaryFitRecord {
  std::size_t triangles = 0;      // boundary triangles with interior nodes on one face
  std::size_t fitted = 0;         // those with a node moved
  std::size_t tiers = 0;          // tiers fitted and kept (largest angles first)
  std::size_t frozenNodes = 0;    // nodes the certification held where they were
  std::size_t verticesMoved = 0;  // vertex patches kept after the tiers (a vertex may count twice)
  std::size_t remeasured = 0;     // elements certified again
  bool stopped = false;           // ended by `stop` (a cancel, the job's time budget)
};

// The stage on `mesh` (3D, order 2 or more; otherwise nothing) whose certified quality is
// `quality`: both updated in place. Threads as evaluateQuality. `stop`, if given, is asked
// between tiers: true ends the stage with the tiers certified so far (record.stopped).
BoundaryFitRecord fitBoundaryFidelity(Mesh& mesh, QualitySummary& quality, const CadModel& cad,
                                      int threads, const std::function<bool()>& stop = {});

}  // namespace homesh
