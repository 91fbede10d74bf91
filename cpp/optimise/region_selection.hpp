// Which nodes the optimiser moves. Without CAD, free nodes are those not on the mesh's boundary
// (facets of exactly one element), not on an interface between elements of different entities
// and not on a lower-dimensional cell of the mesh (unless interfaces are free); with CAD, nodes
// on CAD curves and faces slide (cad_sliding.hpp); fixed nodes (OptimiserOptions::fixedNodes)
// stay. With a region threshold (or seed), only the nodes of elements below it (or seeded, or
// not proven valid), grown by regionLayers layers of neighbours, move. After each sweep the
// focused passes take the nodes of the elements near the mesh's worst.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "optimise/cad_sliding.hpp"
#include "optimise/optimiser.hpp"
#include "optimise/working_mesh.hpp"
#include "quality/bezier_jacobian.hpp"

namespace homesh::optimiser {

// Per element (global index), 1 where its nodes may move: every element, or those whose
// certified scaled Jacobian (`scaled`) is below options.regionThreshold, those options.regionSeed
// names and those not proven valid (`validity`), and options.regionLayers layers of neighbours
// (sharing a node) around them. Throws ParameterError for a seed of the wrong size.
template <int D>
std::vector<char> region(const WorkingMesh<D>& mesh, const std::vector<double>& scaled,
                         const std::vector<Validity>& validity, const OptimiserOptions& options);

template <int D>
struct FreeNodes {
  std::vector<std::int64_t> nodes;   // ascending
  std::vector<std::size_t> changed;  // the elements with a free node, ascending
  std::size_t regionElements = 0;    // elements in region()
  // Per node (in the frame), the direction it may not move along (OptimiserOptions::
  // normalLocked), NaN where it has none; empty without such options.
  std::vector<Eigen::Matrix<double, D, 1>> lockedNormal;
};

// The free nodes: in region(), not on the boundary or an interface (or lower-dimensional cell)
// unless options.freeInterfaces, sliding on the CAD where `sliding` says so (CAD vertices stay),
// not fixed by options.fixedNodes; with their locked directions. Throws ParameterError for
// per-node options of the wrong size.
template <int D>
FreeNodes<D> chooseFreeNodes(const WorkingMesh<D>& mesh, const std::vector<double>& scaled,
                             const std::vector<Validity>& validity, CadSliding<D>& sliding,
                             const OptimiserOptions& options);

// The positions in `changed` in the caller's order of their elements (callersElements: the
// element with the caller's number i; null: the order of `changed`), for summing the energy the
// same way whatever the numbering.
std::vector<std::size_t> energyOrder(const std::vector<std::size_t>& changed,
                                     std::size_t totalElements,
                                     const std::vector<std::size_t>* callersElements);

// The focused passes' nodes: the free nodes (colourOf >= 0) of the elements whose certified
// scaled Jacobian is within `margin` of the worst, grouped by their colour (of `colours`), each
// group in block order of first appearance.
template <int D>
std::vector<std::vector<std::int64_t>> focusGroups(const WorkingMesh<D>& mesh,
                                                   const std::vector<double>& scaled,
                                                   const std::vector<int>& colourOf,
                                                   std::size_t colours, double margin);

}  // namespace homesh::optimiser
