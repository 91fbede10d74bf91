// Element-count prediction from the sizing octree, before any mesh is made.
//
// A simplex mesh that follows the size field delta has, per unit volume (area in 2D), about
// volumeDensity / delta^d elements, and the boundary adds a layer whose count per unit area
// (length) scales with 1 / delta^(d-1): boundary elements are cut short by the surface, so
// there are more of them than the volume alone implies. The prediction integrates both terms
// over the octree's domain and boundary facets:
//
//   N = a_d * integral over the domain of delta^-d
//     + b_d * integral over the boundary of delta^(1-d)     (internal faces count twice)
//     + g_d * integral over the domain of |grad delta| delta^-d
//
// The last term counts the extra elements a mesher makes where the size changes: an element
// spans sizes from delta to delta + h |grad delta| and is made to fit the smaller. a_d, b_d and
// g_d are properties of the mesher (Gmsh with our size callback), measured once on meshes that
// are not the ones the acceptance checks; see element_count.cpp. NekMesh uses the first term
// alone with the volume of a regular tetrahedron (a_3 = 6 sqrt 2 = 8.5), which overestimates.
#pragma once

#include <string>

#include "core/parameters.hpp"

namespace homesh {

class SizingOctree;

struct ElementCountPrediction {
  int dim = 3;
  double volumeIntegral = 0.0;    // integral of delta^-d over the domain
  double boundaryIntegral = 0.0;  // integral of delta^(1-d) over the boundary (internal: twice)
  double gradientIntegral = 0.0;  // integral of |grad delta| delta^-d over the domain
  double domainMeasure = 0.0;     // volume (area) the octree classified inside
  double elements = 0.0;          // the predicted number of tetrahedra (triangles in 2D)
  // A surface mesh's (SizingOctree::surface): dim 2, elements its triangles, domainMeasure the
  // faces' area and volumeIntegral the integral of delta^-2 over them.
};

// Uses up to `threads` threads.
ElementCountPrediction predictElementCount(const SizingOctree& tree,
                                           int threads = defaultOf<int>("threads"));

}  // namespace homesh
