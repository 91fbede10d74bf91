// The repair rounds of the pipeline (stages "repair 1", ...): while elements are not proven
// valid, each round locates them in a linear mesh, changes that mesh around them and curves it
// again (pipeline/curve_stage.hpp). The repair actions are pipeline/repair.hpp's and linear/'s;
// this component decides which one a round takes and which mesh it starts from:
//
// - a split of the offenders' edges on curved faces; cells without such an edge are flipped
//   away (slivers with vertices inside) or, with the optimiser on a volume mesh, their cavities
//   are meshed again; otherwise, or after a local change that made the mesh worse, the whole
//   model is meshed again finer around the offenders (refine; always, with a boundary layer);
// - a round starts from the last round's mesh unless that made things worse: then from the best
//   mesh, whose failed flips and remeshes are not tried on it again until a round is kept;
// - once every element is valid, rounds go on for elements below 0.1 with local actions only,
//   each tried once on the best mesh, and end when none is kept;
// - the best mesh seen is kept: fewest elements not proven valid, then the best worst scaled
//   Jacobian, so a round never makes the result worse;
// - with the job's time budget a round starts only while what is left covers what the round
//   before took (the first: `firstSeconds`, the linear mesh and curving before it); a Gmsh run
//   the budget stops ends the rounds with the best mesh.
//
// Each round is recorded in result.rounds, what it could not do in result.notes.
#pragma once

#include "core/job_budget.hpp"
#include "pipeline/curve_stage.hpp"
#include "pipeline/linear_stage.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

// Up to options.repairRounds rounds from `best`, the first curved mesh; returns the best state
// seen. Throws CancelledError, and as curve() does.
CurvedState runRepairRounds(CurvedState best, double firstSeconds, LinearStage& linear,
                            MeshResult& result, const MeshingOptions& options, JobBudget& budget,
                            PipelineObserver* observer);

}  // namespace homesh
