// Element-count prediction from the sizing octree, before any mesh is made.
//
// A tetrahedral mesh has about 6.5 tetrahedra per interior node and 2.7 per boundary node (Gmsh
// 4.8's Delaunay meshes of the calibration shapes, within a few per cent), and where each kind
// of node goes is what the size field decides:
//  - boundary nodes follow the faces' triangles, which in turn follow the area over delta^2,
//    plus the triangles cut short along each face's boundary curves (a row per curve side);
//  - interior nodes fill only the core of the domain, the points farther than kCoreDepth
//    delta(x) from every wall: a wall thinner than about 1.5 delta has none (a plate, a thin
//    disc), and a section a few sizes across has fewer than its volume over delta^3 implies (a
//    pipe). A count from the whole volume misses both (it predicted a thin disc at 0.47 and a
//    bent pipe at 1.27 of what was made).
//  - a convex wall (a rod, a ball seen from inside) has fewer elements cut short beside it than
//    a flat one, and a concave wall (a hole in a box) more: the layer of depth t along a wall of
//    mean curvature H holds A t (1 - H t) of volume, not A t. Without this term narrow round
//    sections were predicted 15 to 20 % over and holes 10 to 17 % under;
//  - where the size changes, an element spans sizes from delta to delta + h |grad delta| and is
//    made to fit the smaller: graded regions get more elements than the field alone implies
//    (wings with a refinement line were 5 to 8 % under without this term).
// In 3D, therefore:
//
//   N = a * integral over the core of delta^-3
//     + b * integral over the boundary of delta^-2          (faces between solids count twice)
//     + e * sum over faces of the integral of delta^-1 along the face's boundary curves
//     + k * integral over the walls of clamp(-H delta, -0.5, 0.5) delta^-2   (-H > 0 convex)
//     + g * integral over the domain of |grad delta| delta^-3
//
// and in 2D (triangles), where the domain is a face:
//
//   N = a2 * integral over the domain of delta^-2 + b2 * integral over the boundary of delta^-1
//     + g2 * integral over the domain of |grad delta| delta^-2
//
// The densities are properties of the mesher (Gmsh with our size callback), fitted on shapes that
// are not the ones any acceptance checks (element_count.cpp says which). NekMesh counts the
// volume alone with the volume of a regular tetrahedron (a = 6 sqrt 2 = 8.5), which
// overestimates.
#pragma once

#include <string>

#include "core/parameters.hpp"

namespace homesh {

class CadModel;
class SizingOctree;

struct ElementCountPrediction {
  int dim = 3;
  double volumeIntegral = 0.0;    // integral of delta^-d over the domain
  double coreIntegral = 0.0;      // 3D: integral of delta^-3 over the core (see above)
  double boundaryIntegral = 0.0;  // integral of delta^(1-d) over the boundary (internal: twice)
  double curveIntegral = 0.0;     // 3D: sum over faces of the integral of 1 / delta on their curves
  // 3D: integral of clamp(-H delta, -0.5, 0.5) / delta^2 over the walls (not the faces between
  // solids), H the mean curvature against the outward normal: positive where they are convex.
  double convexityIntegral = 0.0;
  double gradientIntegral = 0.0;  // integral of |grad delta| delta^-d over the domain
  double domainMeasure = 0.0;     // volume (area) the octree classified inside
  double elements = 0.0;          // the predicted number of tetrahedra (triangles in 2D)
  // A surface mesh's (SizingOctree::surface): dim 2, elements its triangles, domainMeasure the
  // faces' area and volumeIntegral the integral of delta^-2 over them.
};

// How far from the walls, in sizes, the core of a 3D domain begins.
inline constexpr double kCoreDepth = 0.75;

// `tree` was built from `cad`. Uses up to `threads` threads. Throws CadError naming a curve
// OCCT cannot evaluate.
ElementCountPrediction predictElementCount(const SizingOctree& tree, const CadModel& cad,
                                           int threads = defaultOf<int>("threads"));

}  // namespace homesh
