// The options of one meshing job, as the stages read them, and the one way to make them from an
// options mapping keyed as the parameter table (core/parameters.hpp), which every default and
// range here comes from.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "boundary_layer/layer_parameters.hpp"
#include "cad/cad_healing.hpp"
#include "core/parameters.hpp"
#include "sizing/sizing_parameters.hpp"

namespace homesh {

struct MeshingOptions {
  int order = defaultOf<int>("order");  // polynomial order
  // Sizes: a uniform target edge length (> 0), or the sizing octree (sizing/sizing_octree.hpp);
  // with neither, the octree with defaultSizing(cad).
  std::optional<double> size;
  std::optional<SizingParameters> sizing;   // 0 deltas: automatic (completeSizing)
  std::optional<int> expectedDimension;     // 2 or 3 (a .mcf's MeshType): checked on the CAD
  std::string octreeOutput;                 // when set: the octree's leaves, written after sizing
  int threads = defaultOf<int>("threads");  // threads the stages may use
  int verbosity = defaultOf<int>("verbosity");  // 0 silent; 1 Gmsh's warnings; 2 its information
  // > 0: after elevation, at most this many sweeps of the variational optimiser (hyperelastic,
  // boundary nodes sliding on the CAD; optimise/optimiser.hpp), stopping earlier once the mesh
  // is proven valid and no longer improving (OptimiserOptions: "energy", or "stalled" with
  // stall 0.001). 0: the optimiser is not asked for (an options mapping's `optimise: true`
  // stands for the table's default number of sweeps).
  int optimiseIterations = 0;
  double optimiseSeconds = defaultOf<double>("optimise_seconds");  // each run's limit (0: none)
  // The optimiser's boundary-facet term (OptimiserOptions::facetWeight).
  double facetWeight = defaultOf<double>("facet_weight");
  // The optimiser's fidelity term (OptimiserOptions::fidelityWeight).
  double fidelityWeight = defaultOf<double>("fidelity_weight");
  // Time limit of each Gmsh run of the linear mesher (0: none).
  double linearSeconds = defaultOf<double>("linear_seconds");
  // Wall-time budget of the whole job (0: none), from the start of runMeshPipeline
  // (core/job_budget.hpp): Gmsh and every optimiser run get at most what is left, repair rounds
  // stop when the last one would no longer fit, the geometry check is skipped once it is spent.
  double jobSeconds = defaultOf<double>("job_seconds");
  // How far a boundary node of a given linear mesh (curveMeshOnCad) may lie from the CAD,
  // relative to its bounding diagonal (linear/cad_classification.hpp).
  double classifyTolerance = defaultOf<double>("classify_tolerance");
  // Repair rounds (pipeline/repair.hpp) while elements are not proven valid, range in
  // core/parameters.hpp: each splits the offending linear cells' edges on curved faces (or refines
  // around them), then curves, optimises and checks again. 0: none.
  int repairRounds = defaultOf<int>("repair_rounds");
  // A macro boundary layer on these CAD faces (boundary_layer/boundary_layer.hpp), curved and
  // optimised with the rest and split into its thin layers last (boundary_layer/layer_split.hpp).
  std::optional<BoundaryLayerParameters> boundaryLayer;
  // CAD healing after loading (cad/cad_healing.hpp); false: the model is only checked (touching
  // solids are still imprinted, unless `imprint` is off).
  bool heal = defaultOf<bool>("heal");
  // Faces in no solid are left out (report: healing "left_out") instead of refusing the model.
  bool solidsOnly = defaultOf<bool>("solids_only");
  // A model without solids gets a surface mesh of its faces (triangles on the CAD, no volume;
  // the optimiser and boundary layers do not apply) instead of being refused.
  bool surface = defaultOf<bool>("surface");
  // Each model gets the mode that fits it (solidsOnly with solids, surface without), for batch
  // runs: HealingOptions::automatic.
  bool automatic = defaultOf<bool>("auto");
  // Touching solids imprinted on each other (cad/solid_imprint.hpp): one conforming mesh.
  bool imprint = defaultOf<bool>("imprint");
  HealingOptions healing() const { return {heal, solidsOnly, surface, automatic, imprint}; }

  // Throws ParameterError naming the offending parameter.
  void validate() const;

  // Sets the options a mapping keyed as the parameter table asks for (the Python keywords of
  // homesh.mesh; the table's group "boundary_layer" is the boundary layer's own) over these
  // (the defaults, or a NekMesh case's): each value checked once against the table (kind and
  // range, one message naming the parameter), then the whole by validate(). A number 0 where 0
  // is automatic leaves it automatic; min_delta, max_delta and eps set the sizing octree's
  // values (keeping the others these options had); a uniform size replaces the octree these
  // options had. Keys not in `allowed` (when given) are refused by name: a front end that has
  // no use for a parameter says so.
  void apply(const OptionMap& values, const std::vector<std::string>& allowed = {});
  // The defaults with `values` applied.
  static MeshingOptions fromMap(const OptionMap& values,
                                const std::vector<std::string>& allowed = {});
  // The table keys apply takes from a caller that has a use for `allowed` (empty: every key it
  // takes; the boundary layer's own it does not), in the table's order.
  static std::vector<std::string> keys(const std::vector<std::string>& allowed = {});
};

}  // namespace homesh
