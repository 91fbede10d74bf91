// The curving stages of the pipeline, from a linear mesh to a curved mesh and its quality:
// elevation (with continuation through kContinuationOrder above it), the optimiser (with the
// macro boundary layer fixed, then released in steps where elements stay invalid) and the
// certified quality check. The first mesh and every repair round go through curve(); a repair
// round passes the state it starts from, so that unchanged cells keep their curved nodes and
// the optimiser works only around what changed.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "boundary_layer/boundary_layer.hpp"
#include "boundary_layer/layer_split.hpp"
#include "cad/cad_model.hpp"
#include "core/job_budget.hpp"
#include "core/mesh.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

// A curved mesh and what the stages after the linear mesh found.
struct CurvedState {
  Mesh linear;
  Mesh mesh;
  QualitySummary quality;
  std::optional<OptimiserResult> optimiser;
  std::size_t reused = 0;  // elements that took their curved nodes from the round before
  std::optional<BoundaryLayerRecord> layer;  // how the linear mesh's macro layer was grown
  // How far the optimiser moved the macro layer around elements it could not make valid
  // otherwise (at the final order or, with continuation, at the low order).
  LayerRelease layerRelease = LayerRelease::None;
  // Above kContinuationOrder with the optimiser: the mesh of that order, optimised, that the
  // final order started from (empty otherwise).
  Mesh lowOrder;
  std::optional<OptimiserResult> lowOrderOptimiser;

  std::size_t notValid() const { return quality.invalid + quality.undecided; }
  // Fewer elements not proven valid, then the better worst scaled Jacobian.
  bool betterThan(const CurvedState& other) const {
    if (notValid() != other.notValid()) return notValid() < other.notValid();
    return quality.scaled.min > other.quality.scaled.min;
  }
};

// Elevation, optimiser and quality of a linear mesh. With `clocked`, each stage is timed
// under its own name; a repair round times them all as one stage instead. With `previous` (a
// repair round's starting state), the elements whose linear cell is unchanged take their
// curved nodes from it and the optimiser works only on the new elements, the ones not proven
// valid or poor, and a layer around them. Each optimiser run gets at most what is left of
// `budget` and is left out once it is spent (named with `round`, "repair 2", in the budget's
// record; "" before the rounds); the elevation keeps back (JobBudget::reserve) four times its
// measured time for the stages that always run. Throws ParameterError (memory), MeshingError,
// CadError or CancelledError. The prisms of `linear` are a macro boundary layer (wall 0-1-2,
// top 3-4-5: blended after elevation, kept while the rest is optimised) when options ask for a
// layer or `givenLayer` says a given mesh's stacks were agglomerated into them (layer_stacks.hpp);
// `layer`, the record of the layer grown in `linear`, becomes the state's (its columns
// lengthened at sharp edges shape the blend).
CurvedState curve(Mesh linear, const MeshingOptions& options, const CadModel& cad,
                  StageTimings& timings, PipelineObserver* observer, bool clocked,
                  JobBudget& budget, const std::string& round,
                  const CurvedState* previous = nullptr, bool givenLayer = false,
                  std::optional<BoundaryLayerRecord> layer = std::nullopt);

}  // namespace homesh
