// What each stage of a meshing job recorded (counts, timings, notes, the optimiser's history),
// apart from the mesh it hands on (pipeline/curved_mesh.hpp), and MeshResult, the two together.
// The report and the summaries (pipeline/report.hpp, pipeline/mesh_summary.hpp) are written
// from the records and the mesh.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "boundary_layer/layer_record.hpp"
#include "boundary_layer/layer_split.hpp"
#include "boundary_layer/layer_stacks.hpp"
#include "cad/cad_healing.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/boundary_fidelity.hpp"
#include "pipeline/curved_mesh.hpp"
#include "pipeline/meshing_options.hpp"
#include "pipeline/repair.hpp"
#include "quality/geometry_accuracy.hpp"
#include "quality/mesh_quality.hpp"
#include "sizing/element_count.hpp"
#include "sizing/sizing_octree.hpp"

namespace homesh {

// The sizing octree of a model and the element count it predicts.
struct SizingResult {
  std::shared_ptr<const SizingOctree> octree;
  ElementCountPrediction prediction;
  double seconds = 0.0;   // octree and prediction
  HealingRecord healing;  // runSizingStage: what the CAD check found and healing did
};

// Wall-clock seconds per stage, in the order the stages ran.
struct StageTimings {
  std::vector<std::pair<std::string, double>> seconds;
  void add(const std::string& stage, double s);
  double total() const;
};

// What a job's time budget (MeshingOptions::jobSeconds) did: the report's "job".
struct JobRecord {
  double timeLimit = 0.0;  // the budget, seconds (0: none)
  // The job's wall time: from the start of the pipeline to its end, plus the "output" stage
  // when writeMeshOutputs wrote the mesh.
  double seconds = 0.0;
  // What the budget kept back at the end for the stages that always run (JobBudget::reserve):
  // a job it stopped took at least timeLimit less this.
  double reserved = 0.0;
  std::vector<std::string> cut;      // stages the budget stopped early ("optimise", "repair 2")
  std::vector<std::string> skipped;  // stages it left out ("repair 3", "geometry")
  bool stopped() const { return !cut.empty() || !skipped.empty(); }
};

// Every stage's record of one job; a stage that did not run leaves its record empty.
struct StageRecords {
  std::optional<OptimiserResult> optimiser;  // when the optimiser ran
  // Above kContinuationOrder: the optimiser's run at that order that the mesh started from.
  std::optional<OptimiserResult> lowOrderOptimiser;
  std::optional<SizingResult> sizing;        // when the sizes came from the octree
  std::optional<GeometryAccuracy> geometry;  // boundary against the CAD (a mesh made from CAD)
  std::vector<RepairRound> rounds;           // the repair rounds run, in order
  // The boundary triangles fitted to their faces once the mesh was curved and repaired
  // (pipeline/boundary_fidelity.hpp): when the stage ran.
  std::optional<BoundaryFitRecord> boundaryFit;
  // Tangent ears split in the linear meshes Gmsh made, before curving (tangentEarSplits in
  // pipeline/repair.hpp), over the first mesh and the refine rounds' meshes.
  std::size_t tangentEars = 0;
  // With a boundary layer: how the macro layer of the kept mesh was grown, the certified
  // quality of its macro (unsplit) mesh, and how it was split.
  std::optional<BoundaryLayerRecord> boundaryLayer;
  std::optional<QualitySummary> macroQuality;
  std::optional<LayerSplitStats> layerSplit;
  // A given mesh's prism stacks, recognised and agglomerated (curveMeshOnCad; the split then
  // in layerSplit).
  std::optional<LayerStacksRecord> givenLayers;
  StageTimings timings;
  MeshingOptions options;
  HealingRecord healing;  // what the CAD check found and healing did
  // What a stage had to do otherwise than asked (Gmsh crashed and was run again another way;
  // the job's time budget ended the repair rounds).
  std::vector<std::string> notes;
  JobRecord job;
};

// A job's result: the curved mesh it hands on and what its stages recorded. Python keeps the two
// apart (HighOrderMesh.optimise copies both, the records with the new geometry measure).
struct MeshResult : CurvedMesh, StageRecords {};

}  // namespace homesh
