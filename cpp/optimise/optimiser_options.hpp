// What one run of the variational optimiser (optimise/optimiser.hpp) is asked to do: its
// functional, stop rules, region, threads and constraints. The user-facing ones take their
// defaults and ranges from the parameter table (core/parameters.hpp) and are set from an options
// mapping keyed as that table by apply(), the one place a front end's values enter.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/parameters.hpp"
#include "optimise/functional.hpp"

namespace homesh {

struct OptimiserOptions {
  Functional functional = static_cast<Functional>(defaultOf<int>("functional"));
  int maxIterations = defaultOf<int>("optimise");  // sweeps
  // Stop rules, checked after every sweep in this order (the result names the one that ended
  // the run):
  //  "displacement": no node moved by more than `tolerance` times the size of its smallest
  //    element (its straight-sided volume to the power 1/d);
  //  "energy": every element is proven valid and the sweep lowered the total energy by less
  //    than `energyTolerance` of it (an invalid mesh keeps going: untangling can follow a
  //    plateau of the energy); with `stall` > 0, only if the sweep also raised the worst scaled
  //    Jacobian by less than `stall` (where most nodes rest, the few moving around the worst
  //    element lower the total energy by little while they still raise the worst);
  //  "stalled" (only with `stall` > 0): every element is proven valid, the last sweep's worst
  //    scaled Jacobian is less than `stall` above its lowest value in the state before the last
  //    `stallWindow` sweeps and in those sweeps, and the last sweep lowered the energy by less
  //    than `stallEnergy` of it: the worst element no longer improves and the rest only slowly
  //    (a single sweep can lower the worst value while it lowers the energy elsewhere, hence
  //    the window, and the worst climbing back from such a dip is still improving);
  //  "stuck" (only with `stall` > 0): elements are not proven valid, and over the last
  //    `stuckWindow` sweeps their count did not fall, the worst scaled Jacobian rose by less
  //    than `stall` and the last sweep lowered the energy by less than `stallEnergy`: more
  //    sweeps will not make the mesh valid (the pipeline's repair rounds take over);
  //  "iterations": maxIterations sweeps done;
  //  "time budget" (only with `timeLimit` > 0): the run has taken `timeLimit` seconds, set-up
  //    included; checked once in the set-up (after the input's certified quality: the input is
  //    then kept and its energy not computed, NaN), after every sweep and between a sweep's
  //    colour groups; the best state so far is kept, as for every rule. A sweep the limit
  //    stops between its colour groups is finished as far as it got: the elements its nodes
  //    changed are certified (past the limit, one evaluation of them) and it counts as a sweep,
  //    marked `partial`, kept where it is acceptable and better, so that a run whose first
  //    sweep outlasts the limit is not lost (a cancel request drops the half-done sweep).
  double tolerance = defaultOf<double>("tolerance");
  double timeLimit = defaultOf<double>("optimise_seconds");  // seconds, 0: none
  double energyTolerance = 1e-5;
  double stall = 0.0;
  double stallEnergy = 0.05;
  int stallWindow = 3;
  int stuckWindow = 10;
  // A sweep visits a node only if it or a node of one of its elements moved, since its last
  // visit, by more than this times the size of its smallest element (the first sweep visits
  // every free node). 0 visits every node that moved at all, or has a neighbour that did: a
  // node whose step was exactly zero, in a patch where nothing moved, still rests. 1e-3
  // against 1e-4: on nine test cases (sphere in a box, NekMesh's 3d_sphere, 3d_bl_cyl, T106)
  // the same validity verdicts, worst values within 0.007, and 1.2x to 2.5x less time.
  double activeTolerance = 1e-3;
  // With settledQuality <= 1: a node whose elements all have a certified scaled Jacobian of at
  // least settledQuality, and more than focusMargin above the mesh's worst at the sweep's start,
  // rests below settledTolerance of its element size instead (settledSlidingTolerance for a
  // node sliding on the CAD), and its moves below that wake no neighbour. Such elements no
  // longer limit the mesh, and polishing them costs most of a run over a mesh that is valid from
  // the start. A node on the CAD has a tolerance of its own because its small moves are the
  // boundary's fidelity: the pipeline rests it below 3e-3 where the inside rests below 1e-2
  // (pipeline/curve_stage.cpp). Off by default (`homesh optimise` has no settled rule); the
  // pipeline uses 0.7. The values are the elements' certified lower bounds, refined only near
  // the worst and the region threshold (certified_quality.hpp), so an element somewhat above
  // settledQuality may not count as settled, and a run given the caller's start quality (every
  // bound refined) may settle one that a run measuring its own does not.
  double settledQuality = 2.0;
  double settledTolerance = 1e-2;
  double settledSlidingTolerance = 1e-3;
  int threads = defaultOf<int>("threads");
  // Work only around elements whose certified scaled Jacobian is below this (in (0, 1]).
  std::optional<double> regionThreshold;
  // Work only around these elements (1 per element in block order, as Mesh::blocks lists the
  // cells of dimension mesh.dim) and those not proven valid; empty: no such restriction. With
  // regionThreshold too, the region is the union.
  std::vector<char> regionSeed;
  int regionLayers =
      defaultOf<int>("region_layers");  // layers of neighbours (sharing a node) added to the region
  // After each sweep, this many extra Newton steps on the nodes of the elements whose scaled
  // Jacobian is within focusMargin of the mesh's worst (see optimise/sweep.hpp).
  int focusPasses = defaultOf<int>("focus");
  double focusMargin = 0.05;
  // Let the nodes on internal interfaces (between elements of different entities, and on
  // lower-dimensional cells inside the domain) move too, as NekMesh does for a mesh without
  // CAD: this can untangle elements with two faces on a curved interface, but the interface
  // no longer follows its geometry exactly.
  bool freeInterfaces = defaultOf<bool>("free_interfaces");
  // Nodes that stay where they are (1 per node; empty: none), whatever their kind: a macro
  // boundary layer keeps the shape its growth gave it (boundary_layer/boundary_layer.hpp).
  std::vector<char> fixedNodes;
  // Nodes that move only perpendicular to a direction (3 values per node, NaN for a node
  // without one; empty: none): a macro boundary layer's top, released around invalid
  // elements, slides parallel to its wall and keeps its height above it. Applies to nodes
  // inside the domain (a node sliding on the CAD keeps its own constraint), exactly where the
  // optimiser moves the mesh's own nodes (with CAD or a region, as the pipeline's release has);
  // without, it moves its working node set's (GLL) nodes, and the written ones follow them.
  std::vector<double> normalLocked;
  // Run the sweeps on the mesh renumbered along a space-filling curve (core/spatial_order.hpp),
  // the caller's numbering restored after: only where the data lies changes, never a result (to
  // the last bit; the optimiser's tests compare). On Gmsh's numbering, an order-2 sweep of the
  // order-sweep benchmark got 1.25x from two threads where the machine allowed 1.9x.
  bool spatialOrder = true;
  // Weight of the boundary facets' distortion inside their own surface (optimise/
  // facet_energy.hpp) in the energy of the nodes sliding on the CAD (3D, with CAD; 0: none).
  // Sliding keeps the nodes on the CAD but lets a facet's nodes bunch up, and its polynomial
  // surface then leaves the CAD between them; this term keeps their spacing. It joins once the
  // mesh is proven valid (the input, or after a sweep; its nodes are then all visited again, the
  // stop rules skip that sweep, and the reported energy includes the term from then on):
  // untangling comes first.
  double facetWeight = defaultOf<double>("facet_weight");
  // Weight of the boundary facets' fidelity to the CAD (facet_energy.hpp: distance off the
  // CAD's tangent plane and the angle between the normals, at the facets' quadrature points)
  // in the same energy, at a sliding node once its elements are proven valid (the total
  // energy counts it once the whole mesh is). The sliding nodes are otherwise free to move
  // along the CAD however the volume prefers, and the surface between them leaves it.
  double fidelityWeight = defaultOf<double>("fidelity_weight");

  // Throws ParameterError naming the offending option.
  void validate() const;

  // Sets the options a mapping keyed as the parameter table asks for (keys(): the optimiser's
  // sweeps, time limit, facet and fidelity weights, threads and the table's group "optimiser"),
  // each value checked once against the table, then the whole by validate(). A region of 0 is no
  // region; region layers without a region are refused. Any other key is refused by name.
  void apply(const OptionMap& values);
  // The table keys apply takes, in the table's order.
  static std::vector<std::string> keys();
};

}  // namespace homesh
