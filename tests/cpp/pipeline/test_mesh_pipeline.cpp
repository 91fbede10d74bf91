// The pipeline end to end: stages, timings, report, parameter checks before CAD import, cancel.
#include <gtest/gtest.h>

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Compound.hxx>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "core/error.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

class CountingObserver : public PipelineObserver {
 public:
  explicit CountingObserver(int cancelAfter = -1) : cancelAfter_(cancelAfter) {}
  void stageStarted(const std::string& stage) override { started.push_back(stage); }
  void stageFinished(const std::string& /*stage*/, double seconds) override {
    EXPECT_GE(seconds, 0.0);
    ++finished;
  }
  bool cancelRequested() override { return cancelAfter_ >= 0 && finished >= cancelAfter_; }
  std::vector<std::string> started;
  int finished = 0;

 private:
  int cancelAfter_;
};

// The sphere in a box at `size`, order 4, optimised (2 threads), without and with a boundary
// term (`turnOn` sets it): both runs, their geometry measured, every element proven valid in
// both; prints the figures the callers' comments quote under `name`.
template <class TurnOn>
std::pair<MeshResult, MeshResult> withAndWithout(const char* name, double size, int repairRounds,
                                                 const TurnOn& turnOn) {
  const std::string sphereBox = std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step";
  MeshingOptions options;
  options.order = 4;
  options.size = size;
  options.optimiseIterations = 100;
  options.repairRounds = repairRounds;
  options.threads = 2;
  // The figures below were measured with the sphere and its box meshed apart on their two
  // sphere faces, as before touching solids were imprinted (cad/solid_imprint.hpp).
  options.imprint = false;
  options.fidelityWeight = 0.0;  // "without": no boundary term (the default has the fidelity's)
  std::pair<MeshResult, MeshResult> r{runMeshPipeline(CadSource::file(sphereBox), options), {}};
  turnOn(options);
  r.second = runMeshPipeline(CadSource::file(sphereBox), options);
  for (const MeshResult* m : {&r.first, &r.second}) {
    EXPECT_TRUE(m->geometry.has_value());
    EXPECT_EQ(m->quality.invalid + m->quality.undecided, 0U);
  }
  if (r.first.geometry && r.second.geometry)
    std::printf("%s: distance %.2e -> %.2e, angle %.2f -> %.2f deg, worst %.3f -> %.3f\n", name,
                r.first.geometry->maxDistance, r.second.geometry->maxDistance,
                r.first.geometry->maxAngleDeg, r.second.geometry->maxAngleDeg,
                r.first.quality.scaled.min, r.second.quality.scaled.min);
  return r;
}

// The optimiser's boundary-facet term (MeshingOptions::facetWeight) on the sphere in a box at
// size 0.8, order 4: curving leaves 20 elements invalid and the optimiser untangles them by
// sliding nodes along the sphere, which without the term bunches a facet's nodes and takes the
// curved surface 8.8e-3 off the sphere and 11 degrees off its normal (3.5e-5 and 0.08 degrees
// before the optimiser). With it (weight 1, joining once the mesh is valid) 2.0e-3 and 2.5
// degrees, and the worst element 0.450 instead of 0.261 (2026-11-28); the test asks for half
// the distance and angle, with every element proven valid in both runs.
TEST(MeshPipeline, TheFacetTermKeepsSlidingBoundaryNodesSpreadOnTheCad) {
  const auto [without, with] =
      withAndWithout("facet term", 0.8, 0, [](MeshingOptions& o) { o.facetWeight = 1.0; });
  ASSERT_TRUE(without.geometry && with.geometry);
  for (const MeshResult* r : {&without, &with}) {
    ASSERT_TRUE(r->optimiser.has_value());
    EXPECT_GT(r->optimiser->invalidBefore, 0U) << "the case no longer needs sliding to untangle";
  }
  EXPECT_LT(with.geometry->maxDistance, 0.5 * without.geometry->maxDistance);
  EXPECT_LT(with.geometry->maxAngleDeg, 0.5 * without.geometry->maxAngleDeg);
  EXPECT_GT(with.quality.scaled.min, 0.0);
}

// The optimiser's fidelity term (MeshingOptions::fidelityWeight), on by default, on the sphere
// in a box at size 0.8, order 4 (its sphere and box imprinted, as by default): the boundary
// nodes slide along the sphere to improve the elements, and without the term the curved surface
// between them ends 7.2e-4 of the diagonal off the sphere and 7.0 degrees off its normal; with
// the default weight, joining once the mesh is valid, 1.7e-4 and 1.6 degrees, the worst element
// 0.409 instead of 0.400 (2026-11-30). The test asks for a third of the distance and angle,
// every element proven valid both ways.
TEST(MeshPipeline, TheDefaultFidelityTermKeepsTheSurfaceBetweenSlidingNodesOnTheCad) {
  ASSERT_GT(MeshingOptions{}.fidelityWeight, 0.0) << "the term is on by default";
  const std::string sphereBox = std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step";
  MeshingOptions options;
  options.order = 4;
  options.size = 0.8;
  options.optimiseIterations = 100;
  options.threads = 2;
  const MeshResult with = runMeshPipeline(CadSource::file(sphereBox), options);
  options.fidelityWeight = 0.0;
  const MeshResult without = runMeshPipeline(CadSource::file(sphereBox), options);
  ASSERT_TRUE(without.geometry && with.geometry);
  std::printf("fidelity term: distance %.2e -> %.2e, angle %.2f -> %.2f deg, worst %.3f -> %.3f\n",
              without.geometry->maxDistance, with.geometry->maxDistance,
              without.geometry->maxAngleDeg, with.geometry->maxAngleDeg, without.quality.scaled.min,
              with.quality.scaled.min);
  for (const MeshResult* m : {&without, &with})
    EXPECT_EQ(m->quality.invalid + m->quality.undecided, 0U);
  EXPECT_LT(with.geometry->maxDistance, without.geometry->maxDistance / 3.0);
  EXPECT_LT(with.geometry->maxAngleDeg, without.geometry->maxAngleDeg / 3.0);
}

TEST(MeshPipeline, RunsEveryStageAndReports) {
  MeshingOptions options;
  options.order = 3;
  options.size = 0.5;
  CountingObserver observer;
  const MeshResult result =
      runMeshPipeline(CadSource::brepText(test::brepText(test::sphere(1.0))), options, &observer);
  EXPECT_EQ(observer.started,
            (std::vector<std::string>{"cad", "linear", "high_order", "quality", "boundary_fit",
                                      "geometry"}));
  EXPECT_EQ(result.mesh.order, 3);
  EXPECT_EQ(result.quality.scaledJacobian.size(), result.mesh.numElements());
  const std::string json = meshReportJson(result, "sphere");
  for (const char* key : {"\"order\": 3", "\"nodes\": ", "\"tet\": ", "\"invalid_elements\"",
                          "\"scaled_jacobian\"", "\"timings_s\"", "\"high_order\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  EXPECT_NE(json.find("\"tet\": " + std::to_string(result.mesh.numElements())), std::string::npos);
}

// Curved nodes of the mesh edges and triangles that cross a seam of a closed but not periodic
// B-spline surface (both seams of the NURBS torus) land on the surface, not on the far side of
// its parameter range: OpenCASCADE's Pump_TopCover.brep had nodes 84 mm (0.18 of its diagonal)
// off two revolved faces and 19 tetrahedra inverted before CadModel wrapped such seams.
TEST(MeshPipeline, CurvedNodesAcrossAClosedBSplineSeamLieOnTheSurface) {
  MeshingOptions options;
  options.order = 4;
  options.size = 0.5;
  options.repairRounds = 0;  // the placement itself is under test
  const MeshResult r =
      runMeshPipeline(CadSource::brepText(test::brepText(test::nurbsTorus(2.0, 0.5))), options);
  ASSERT_TRUE(r.geometry.has_value());
  // Order-4 interpolation of the tube (radius 0.5, chords of about 0.5, so 1 rad of arc) is
  // off by about r (h/r)^5 / (4^4 5!) ~ 1e-5 of the radius, 1e-6 of the diagonal (5.1); a node
  // placed across the seam wrongly is off by the tube's size, 0.1 of the diagonal.
  EXPECT_LT(r.geometry->maxDistanceRelative(), 1e-4);
}

TEST(MeshPipeline, DefaultSizingIsTheOctreeWithATwentiethOfTheDiagonal) {
  MeshingOptions options;
  options.order = 1;
  const MeshResult result =
      runMeshPipeline(CadSource::brepText(test::brepText(test::box(2, 2, 1))), options);
  EXPECT_FALSE(result.options.size.has_value());
  ASSERT_TRUE(result.options.sizing.has_value());
  EXPECT_NEAR(result.options.sizing->maxDelta, 3.0 / 20.0, 1e-12);
  EXPECT_EQ(result.options.sizing->maxDeltaSetBy, "bounding-box diagonal / 20");
  EXPECT_EQ(result.options.sizing->minDelta, 0.0);  // automatic: the octree sets it
  ASSERT_TRUE(result.sizing.has_value());
  // A box asks for no size of its own: MinDelta is MaxDelta / 20, as before shapes set it.
  const SizingParameters& used = result.sizing->octree->parameters();
  EXPECT_NEAR(used.minDelta, 3.0 / 400.0, 1e-12);
  EXPECT_EQ(used.minDeltaSetBy, "MaxDelta / 20 (no boundary asks for less)");
  EXPECT_GT(result.sizing->prediction.elements, 0.0);
}

TEST(MeshPipeline, BadParametersFailBeforeReadingTheCad) {
  MeshingOptions options;
  options.order = 0;
  // The file does not exist: the parameter error must come first.
  EXPECT_THROW(runMeshPipeline(CadSource::file("/nonexistent.step"), options), ParameterError);
  options.order = 2;
  options.size = -1.0;
  EXPECT_THROW(runMeshPipeline(CadSource::file("/nonexistent.step"), options), ParameterError);
  options.size = 1.0;
  EXPECT_THROW(runMeshPipeline(CadSource::file("/nonexistent.step"), options), IoError);
}

TEST(MeshPipeline, ObserverCanCancelBetweenStages) {
  MeshingOptions options;
  options.size = 0.5;
  CountingObserver observer(2);
  EXPECT_THROW(
      runMeshPipeline(CadSource::brepText(test::brepText(test::sphere(1.0))), options, &observer),
      CancelledError);
  EXPECT_EQ(observer.finished, 2);
}

// Progress within stages: the linear mesher reports Gmsh's run, the optimiser each sweep,
// with fractions that rise; a cancel asked during the optimiser's second sweep ends the run
// there (between colour groups), with CancelledError and no result.
class SweepObserver : public PipelineObserver {
 public:
  explicit SweepObserver(bool cancelInFirstSweep) : cancelInFirstSweep_(cancelInFirstSweep) {}
  void stageStarted(const std::string& stage) override { optimising = stage == "optimise"; }
  void stageProgress(const std::string& stage, double fraction,
                     const std::string& detail) override {
    events.emplace_back(stage, fraction, detail);
    if (stage == "optimise") ++sweeps;
  }
  // The optimiser asks once before each sweep and once per colour group inside it: from the
  // second question on (the first colour group of sweep 1), the answer is yes.
  bool cancelRequested() override {
    if (!cancelInFirstSweep_ || !optimising) return false;
    return ++askedWhileOptimising >= 2;
  }
  std::vector<std::tuple<std::string, double, std::string>> events;
  int sweeps = 0, askedWhileOptimising = 0;
  bool optimising = false;

 private:
  bool cancelInFirstSweep_;
};

TEST(MeshPipeline, StagesReportProgressAndCancelWithinTheOptimiser) {
  MeshingOptions options;
  options.order = 4;
  options.size = 0.5;
  options.optimiseIterations = 3;
  options.repairRounds = 0;
  const std::string brep = test::brepText(test::sphere(1.0));
  {
    SweepObserver observer(false);
    runMeshPipeline(CadSource::brepText(brep), options, &observer);
    std::vector<double> linear, optimise;
    for (const auto& [stage, fraction, detail] : observer.events) {
      EXPECT_FALSE(detail.empty());
      if (stage == "linear") linear.push_back(fraction);
      if (stage == "optimise") optimise.push_back(fraction);
    }
    // Gmsh's one run, done.
    EXPECT_EQ(linear, (std::vector<double>{1.0}));
    ASSERT_GE(optimise.size(), 1u);
    for (std::size_t i = 0; i < optimise.size(); ++i)
      EXPECT_DOUBLE_EQ(optimise[i], static_cast<double>(i + 1) / 3.0);  // sweep k of 3
  }
  {
    SweepObserver observer(true);
    EXPECT_THROW(runMeshPipeline(CadSource::brepText(brep), options, &observer), CancelledError);
    EXPECT_EQ(observer.sweeps, 0);  // stopped inside sweep 1, which never finished
    EXPECT_EQ(observer.askedWhileOptimising, 2);
  }
}

// A model of faces and no solid (the tube of a cylinder and the sphere's face beside it, kept
// apart) with `surface`: a surface mesh at order 4 whose every node lies on its CAD entity,
// certified valid, its triangles measured against the faces; the optimiser is left out and
// said so. Without `surface` the same model is refused, naming the option.
TEST(MeshPipeline, FacesWithoutASolidGetACertifiedSurfaceMesh) {
  TopoDS_Compound faces;
  BRep_Builder builder;
  builder.MakeCompound(faces);
  for (TopExp_Explorer f(test::cylinder(1.0, 2.0), TopAbs_FACE); f.More(); f.Next())
    if (!test::toModel(f.Current()).isPlanar(1)) builder.Add(faces, f.Current());
  for (TopExp_Explorer f(test::sphere(0.5), TopAbs_FACE); f.More(); f.Next())
    builder.Add(faces, f.Current());
  const std::string text = test::brepText(faces);
  MeshingOptions options;
  options.order = 4;
  options.size = 0.4;
  options.optimiseIterations = 5;
  EXPECT_THROW(runMeshPipeline(CadSource::brepText(text), options), CadError);
  options.surface = true;
  const MeshResult r = runMeshPipeline(CadSource::brepText(text), options);
  ASSERT_TRUE(r.mesh.isSurface());
  EXPECT_EQ(r.mesh.order, 4);
  EXPECT_FALSE(r.optimiser.has_value());
  const auto noted = [&r](const std::string& phrase) {
    return std::any_of(r.notes.begin(), r.notes.end(), [&phrase](const std::string& note) {
      return note.find(phrase) != std::string::npos;
    });
  };
  EXPECT_TRUE(noted("a surface mesh of its 2 faces")) << r.notes.front();
  EXPECT_TRUE(noted("the optimiser does not run on a surface mesh"));
  // Every element proven valid, its Jacobian measured along its straight triangle's normal.
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_GT(r.quality.scaled.min, 0.0);
  EXPECT_EQ(r.quality.scaledJacobian.size(), r.mesh.numElements());
  // Nodes on the CAD: evaluated there, so |(x, y)| = 1 on the tube and |x| = 0.5 on the sphere
  // up to rounding (1e-15); 1e-9 leaves room for OCCT's projection of the few nodes placement
  // hands to it.
  std::size_t onTube = 0, onSphere = 0;
  for (std::size_t i = 0; i < r.mesh.numNodes(); ++i) {
    const Eigen::Vector3d x = test::nodePoint(r.mesh, static_cast<std::int64_t>(i));
    if (std::abs(x.norm() - 0.5) < 1e-9) {
      ++onSphere;
    } else {
      ASSERT_NEAR(std::hypot(x.x(), x.y()), 1.0, 1e-9) << "node " << i;
      ++onTube;
    }
  }
  EXPECT_GT(onTube, 500U);
  EXPECT_GT(onSphere, 100U);
  // Between the nodes the order-4 triangles follow the faces to interpolation accuracy: on the
  // sphere of radius 0.5, chords of about 0.4 (0.8 rad of arc) miss it by about
  // r (h/r)^5 / (4^4 5!) = 5e-6, 1.5e-6 of the diagonal (3.5); as for the torus above, 1e-4
  // leaves room for the triangles distorted at the poles, and a triangle off its face would
  // be off by a chord's sagitta, 0.04 (1e-2 of the diagonal).
  ASSERT_TRUE(r.geometry.has_value());
  EXPECT_GT(r.geometry->samples, 10000U);
  EXPECT_LT(r.geometry->maxDistanceRelative(), 1e-4) << r.geometry->worstEntity;
  // The normals: the interpolant's slope error is about (h/r)^4 / (4^3 4!) = 3e-4 rad (0.02
  // degrees) on the sphere's regular triangles, measured 0.69 degrees at its poles, whose
  // triangles are distorted; a triangle left straight across 0.8 rad of arc would tilt by up to
  // 23 degrees. 5 degrees tells the two apart.
  EXPECT_LT(r.geometry->maxAngleDeg, 5.0);
}

}  // namespace
}  // namespace homesh

namespace homesh {
namespace {

// The optimiser inside the pipeline: boundary nodes slide on the CAD and stay on it, their
// recorded parameters follow them, and the worst element improves.
TEST(MeshPipeline, OptimiserSlidesBoundaryNodesOnTheCad) {
  for (const bool isSphere : {true, false}) {
    MeshingOptions options;
    options.order = 4;
    options.size = isSphere ? 0.5 : 0.4;
    options.threads = 2;
    options.optimiseIterations = 5;
    const TopoDS_Shape shape = isSphere ? test::sphere(1.0) : test::torus(2.0, 0.6);
    const MeshResult r = runMeshPipeline(CadSource::brepText(test::brepText(shape)), options);
    ASSERT_TRUE(r.optimiser.has_value());
    EXPECT_GE(r.optimiser->iterations, 1);  // may stop early once valid and stalled
    EXPECT_LE(r.optimiser->iterations, 5);
    std::printf("%s: worst %.4f -> %.4f, invalid %zu -> %zu\n", isSphere ? "sphere" : "torus",
                r.optimiser->worstBefore, r.optimiser->worstAfter, r.optimiser->invalidBefore,
                r.optimiser->invalidAfter);
    // Gmsh's linear mesh, and with it every quality figure, changes with the last bits of the
    // CAD: scaling the shape by 1 +- 1e-12 (bench/tolerance_sensitivity) gives the sphere
    // 200..212 elements and a gain of 0.12..0.28, the torus a gain of 0.021..0.038 (the torus
    // starts tangled in every variant). So only what holds for any mesh is checked: strictly
    // better, tangled elements untangled, nothing left invalid.
    EXPECT_GT(r.optimiser->worstAfter, r.optimiser->worstBefore);
    EXPECT_EQ(r.optimiser->invalidAfter, 0U);
    // The same certified bounds of the same mesh, computed again: identical.
    EXPECT_EQ(r.quality.scaled.min, r.optimiser->worstAfter);
    const Mesh& m = r.mesh;
    std::size_t onFaces = 0;
    for (std::size_t i = 0; i < m.numNodes(); ++i) {
      const Eigen::Vector3d x(m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]);
      if (m.nodeCadDim[i] == 2) {
        ++onFaces;
        const SurfaceDerivatives s = r.cad->evaluateSurface(
            m.nodeCadIndex[i], m.nodeCadParam[2 * i], m.nodeCadParam[2 * i + 1]);
        // The optimiser sets a sliding node to S(u, v) itself: equal up to rounding of |x| <= 3.
        ASSERT_LT((s.point - x).norm(), 1e-12) << "node " << i;
      } else if (m.nodeCadDim[i] == 1) {
        const CurveDerivatives c = r.cad->evaluateCurve(m.nodeCadIndex[i], m.nodeCadParam[2 * i]);
        ASSERT_LT((c.point - x).norm(), 1e-12) << "node " << i;
      }
      // Points of OCCT's sphere (seam and poles included): |x| = 1 to rounding; 1e-7 is slack.
      if (isSphere && m.nodeCadDim[i] < 3) {
        ASSERT_NEAR(x.norm(), 1.0, 1e-7);
      }
    }
    EXPECT_GT(onFaces, 500U);  // measured 1029..1061 (sphere) and 5589..5621 (torus)
    // A sliding visit evaluates the CAD once for its accepted step, whose derivatives are the
    // node's local model at its next visit; a fresh model (first visit, no move) and trials the
    // CAD rejects add the rest (measured 1.06..1.17 per visit on the NekMesh cases, sphere in a
    // box and bracket). Evaluating the derivatives at every visit costs at least 2.
    EXPECT_GT(r.optimiser->slides, 0U);
    EXPECT_LT(r.optimiser->cadEvaluations, 3 * r.optimiser->slides / 2);
    const std::string json = meshReportJson(r, "shape");
    EXPECT_NE(json.find("\"optimiser\""), std::string::npos);
  }
}

}  // namespace
}  // namespace homesh
