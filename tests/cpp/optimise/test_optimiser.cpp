// The optimiser: boundary detection, order change, options, and NekMesh's own regression cases
// (the derivative checks are in test_derivatives.cpp). NekMesh's meshes are another project's
// data (../shared, peer_data.hpp) and may be absent: its regression cases then skip, each with a
// sibling on a mesh made here, and the generic tests run on meshes made here, and on NekMesh's
// too when they are there.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <utility>

#include "core/error.hpp"
#include "core/spatial_order.hpp"
#include "curving/order_elevation.hpp"
#include "element/reference_element.hpp"
#include "gmsh_hybrid_box.hpp"
#include "io/mesh_readers.hpp"
#include "optimise/mesh_topology.hpp"
#include "optimise/optimiser.hpp"
#include "peer_data.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/bezier_jacobian.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

const Functional kAll[] = {Functional::LinearElastic, Functional::Hyperelastic, Functional::Winslow,
                           Functional::Distortion};

TEST(Functional, NamesRoundTripAndUnknownNamesAreRefused) {
  for (const Functional f : kAll) EXPECT_EQ(parseFunctional(functionalName(f)), f);
  EXPECT_EQ(parseFunctional("Linear-Elastic"), Functional::LinearElastic);
  EXPECT_THROW(parseFunctional("elastic"), ParameterError);
}

Mesh twoTetrahedra(int entityOfSecond) {
  Mesh m;
  const double p[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (const auto& q : p) m.addNode(q, 3, 1, NAN, NAN);
  ElementBlock b;
  b.type = CellType::Tetrahedron;
  b.nodes = {0, 1, 2, 3, 1, 2, 3, 4};
  b.entity = {1, entityOfSecond};
  // The second must be positively oriented: (2-1) x (3-1) . (4-1) > 0.
  m.blocks.push_back(b);
  return m;
}

std::string peer(const char* name) {
  return test::peerFile(std::string("optimiser/") + name);
}

// The pipeline's mesh of `source` at `order`, not optimised.
Mesh pipelineMesh(const CadSource& source, int order, double size) {
  MeshingOptions meshing;
  meshing.order = order;
  meshing.size = size;
  return runMeshPipeline(source, meshing).mesh;
}

// A 2 x 2 x 2 cube with a spherical cavity of radius 0.5 (faceted), tetrahedra of order 4, as
// NekMesh's varopti_cube_sphere, made once. The pipeline's curved mesh of so coarse a model is
// not valid before optimisation, so this is Gmsh's linear mesh raised to order 4 with each node
// inside the domain moved by a pseudo-random vector, each coordinate up to 1 % of the smallest
// height of the node's elements: curved elements and no node at its optimum (a straight-sided
// patch is the optimiser's ideal: its nodes would never move). An order-4 Jacobian changes by
// about p^2 = 16 times a node's relative move, so the elements stay valid (a test checks that
// they are proven so). The boundary is left straight; the optimiser given no CAD keeps it.
const Mesh& madeCubeSphere() {
  static const Mesh mesh = [] {
    const TopoDS_Shape cube = BRepPrimAPI_MakeBox(gp_Pnt(-1, -1, -1), 2.0, 2.0, 2.0).Shape();
    const TopoDS_Shape cavity = BRepAlgoAPI_Cut(cube, test::sphere(0.5)).Shape();
    Mesh m =
        elevateOrder(pipelineMesh(CadSource::brepText(test::brepText(cavity)), 1, 0.6), 4, nullptr);
    const ElementBlock& tets = m.blocks[0];
    std::vector<double> h(m.numNodes(), HUGE_VAL);
    for (std::size_t e = 0; e < tets.count(); ++e) {
      const std::int64_t* t = tets.element(e);
      // Its smallest height: three times its volume over its largest face.
      const Eigen::Vector3d p[4] = {test::nodePoint(m, t[0]), test::nodePoint(m, t[1]),
                                    test::nodePoint(m, t[2]), test::nodePoint(m, t[3])};
      double face = 0.0;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d &a = p[(k + 1) % 4], &b = p[(k + 2) % 4], &c = p[(k + 3) % 4];
        face = std::max(face, 0.5 * (b - a).cross(c - a).norm());
      }
      const double shortest = 3.0 * std::fabs(test::tetVolume(m, t)) / face;
      for (int k = 0; k < tets.nodesPerElement(); ++k)
        h[static_cast<std::size_t>(t[k])] = std::min(h[static_cast<std::size_t>(t[k])], shortest);
    }
    const std::vector<char> boundary = boundaryNodes(m.numNodes(), {&tets});
    std::mt19937_64 rng(44);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const double amplitude = 0.01;
    for (std::size_t i = 0; i < m.numNodes(); ++i)
      for (int c = 0; c < 3; ++c) {
        const double r = unit(rng);  // drawn for every node: the same stream whatever is fixed
        if (boundary[i] == 0) m.xyz[3 * i + static_cast<std::size_t>(c)] += amplitude * h[i] * r;
      }
    return m;
  }();
  return mesh;
}

// A NACA 0012 aerofoil at 15 degrees in a box at order 3, 2D, as NekMesh's varopti_naca.
const Mesh& madeNaca() {
  static const Mesh mesh =
      pipelineMesh(CadSource::nacaDomain({"0012", -1.0, -2.0, 3.0, 2.0, 15.0}), 3, 0.4);
  return mesh;
}

struct Input {
  std::string name;
  Mesh mesh;
};

// The 3D inputs of the generic tests: the cube-sphere made here, and NekMesh's when there.
std::vector<Input> cubeSpheres() {
  std::vector<Input> inputs{{"made cube-sphere", madeCubeSphere()}};
  if (test::havePeerFiles())
    inputs.push_back({"NekMesh's cube-sphere", readMesh(peer("varopti_cube_sphere.msh"))});
  return inputs;
}

// The 2D inputs likewise.
std::vector<Input> nacas() {
  std::vector<Input> inputs{{"made NACA", madeNaca()}};
  if (test::havePeerFiles())
    inputs.push_back({"NekMesh's NACA", readMesh(peer("varopti_naca.msh"))});
  return inputs;
}

// A region threshold that selects some elements but not all on any mesh: the certified scaled
// Jacobian a tenth of the elements lie below (a fixed figure such as 0.5 selects none on a good
// mesh).
double lowTenth(const Mesh& mesh) {
  std::vector<double> q = evaluateQuality(mesh).scaledJacobian;
  std::nth_element(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(q.size() / 10), q.end());
  return q[q.size() / 10];
}

TEST(MeshTopology, BoundaryAndInterfaceNodes) {
  for (const int order : {1, 3}) {
    Mesh lin = twoTetrahedra(1);
    const Mesh m = order == 1 ? lin : elevateOrder(lin, order, nullptr);
    const std::vector<const ElementBlock*> blocks{m.blocks.data()};
    const std::vector<char> b = boundaryNodes(m.numNodes(), blocks);
    // Every node of two tets glued on one face is on the outer boundary except the nodes
    // strictly inside the shared face and inside each tet.
    std::size_t inner = 0;
    for (const char c : b) inner += c == 0 ? 1 : 0;
    const std::size_t faceInterior = order == 3 ? 1 : 0;  // one face node at P3, no cell node
    EXPECT_EQ(inner, faceInterior) << "order " << order;
  }
  Mesh two = elevateOrder(twoTetrahedra(2), 3, nullptr);
  const std::vector<const ElementBlock*> blocks{two.blocks.data()};
  const std::vector<char> withInterfaces = boundaryNodes(two.numNodes(), blocks, true);
  const std::vector<char> without = boundaryNodes(two.numNodes(), blocks, false);
  std::size_t a = 0, c = 0;
  for (std::size_t i = 0; i < two.numNodes(); ++i) {
    a += withInterfaces[i] == 0 ? 1 : 0;
    c += without[i] == 0 ? 1 : 0;
  }
  EXPECT_EQ(a, 0U);  // the shared face separates two entities: its node is fixed
  EXPECT_EQ(c, 1U);
}

TEST(ChangeOrder, RaisingKeepsTheGeometryAndLoweringInterpolatesIt) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    const Mesh& p4 = in.mesh;
    ASSERT_EQ(p4.order, 4);
    const Mesh p3 = changeOrder(p4, 3, nullptr);
    EXPECT_EQ(p3.order, 3);
    ASSERT_EQ(p3.numElements(), p4.numElements());
    // Lowering interpolates at the new nodes: every element keeps its corners' coordinates.
    const ElementBlock &tets4 = p4.blocks[0], &tets3 = p3.blocks[0];
    ASSERT_EQ(tets4.type, CellType::Tetrahedron);
    ASSERT_EQ(tets3.count(), tets4.count());
    for (std::size_t e = 0; e < tets4.count(); ++e)
      for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(p3.xyz[3 * tets3.element(e)[k] + c], p4.xyz[3 * tets4.element(e)[k] + c])
              << "element " << e << " corner " << k;
    // Raising P3 to P6 represents the same polynomial map: the volumes agree.
    const Mesh p6 = changeOrder(p3, 6, nullptr);
    const QualitySummary q3 = evaluateQuality(p3), q6 = evaluateQuality(p6);
    // Both are certified lower bounds of the same min J / max J, each refined until its min and
    // max bounds are within kJacobianBoundTolerance (1e-3) of values found: they differ by at
    // most twice that (the P3 -> P6 map itself is exact up to rounding, ~1e-15).
    EXPECT_NEAR(q3.scaled.min, q6.scaled.min, 2 * kJacobianBoundTolerance);
    EXPECT_EQ(q6.invalid, 0U);
  }
}

// The inputs made here are what the generic tests need: proven valid, curved (not every
// element at its ideal), with a boundary.
TEST(Optimiser, TheMadeInputsAreValidAndCurved) {
  for (const Mesh* m : {&madeCubeSphere(), &madeNaca()}) {
    const QualitySummary q = evaluateQuality(*m);
    EXPECT_EQ(q.invalid + q.undecided, 0U) << m->dim << "D";
    EXPECT_LT(q.scaled.min, 0.9) << m->dim << "D";
    std::size_t fixed = 0;
    std::vector<const ElementBlock*> cells{m->blocks.data()};
    for (const char c : boundaryNodes(m->numNodes(), cells)) fixed += c != 0 ? 1 : 0;
    EXPECT_GT(fixed, 0U) << m->dim << "D";
    EXPECT_LT(fixed, m->numNodes()) << m->dim << "D";
  }
}

// NekMesh's regression test: varopti:hyperelastic:maxiter=5:nq=4 expects 0.6664 (+-2e-2) at
// the nodes; we require at least 0.666 (the peer's figure) and report the certified value beside
// it. The thresholds below are peers' figures, not ours: we measure 0.6916 at the nodes and
// 0.6886 certified, and bench/tolerance_sensitivity shows them moving by 2e-11 when the input
// coordinates change by 1e-12 relative or the run uses 1 thread instead of 2 (the optimiser's
// sweeps are deterministic given the input), 1e9 times less than the margin.
TEST(OptimiserPeer, CubeSphereOrder3FiveIterations) {
  HOMESH_REQUIRE_PEER_FILES();
  Mesh mesh = changeOrder(readMesh(peer("varopti_cube_sphere.msh")), 3, nullptr);
  OptimiserOptions options;
  options.maxIterations = 5;
  options.threads = 2;
  const OptimiserResult r = optimiseMesh(mesh, options);
  EXPECT_EQ(r.iterations, 5);
  EXPECT_GE(r.nodalWorstAfter, 0.666);
  EXPECT_GE(r.worstAfter, 0.666);
  EXPECT_EQ(r.invalidAfter, 0U);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_NEAR(q.scaled.min, r.worstAfter, 1e-12);  // the same bounds of the same mesh
  std::printf(
      "cube-sphere P3, 5 iterations: worst at nodes %.4f, certified %.4f (NekMesh 0.6664)\n",
      r.nodalWorstAfter, r.worstAfter);
}

TEST(OptimiserPeer, NacaLinearElasticFiveIterations) {
  HOMESH_REQUIRE_PEER_FILES();
  Mesh mesh = readMesh(peer("varopti_naca.msh"));
  ASSERT_EQ(mesh.dim, 2);
  const std::vector<double> before = mesh.xyz;
  OptimiserOptions options;
  options.functional = Functional::LinearElastic;
  options.maxIterations = 5;
  const OptimiserResult r = optimiseMesh(mesh, options);
  // NekMesh's .tst: 0.872585 (+-5e-3). Ours: 0.8841, moving by 6e-12 with the last bits.
  EXPECT_GE(r.nodalWorstAfter, 0.8726);
  EXPECT_GT(r.worstAfter, r.worstBefore);
  // The mesh stays in its plane.
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    EXPECT_EQ(mesh.xyz[3 * i + 2], before[3 * i + 2]);
  std::printf("naca P3, 5 iterations: worst at nodes %.4f, certified %.4f (NekMesh 0.8726)\n",
              r.nodalWorstAfter, r.worstAfter);
}

TEST(OptimiserPeer, CubeSphereOrder4ConvergesAbove0757AndKeepsTheBoundary) {
  HOMESH_REQUIRE_PEER_FILES();
  Mesh mesh = readMesh(peer("varopti_cube_sphere.msh"));
  const Mesh input = mesh;
  OptimiserOptions options;
  options.maxIterations = 60;
  options.threads = 2;
  const OptimiserResult r = optimiseMesh(mesh, options);
  // NekMesh's converged figure on this mesh, 0.7571 (bench/README.md). Ours: 0.7618 certified,
  // 0.7619 at the nodes, moving by 6e-12 with the input's last bits or the thread count.
  EXPECT_GE(r.worstAfter, 0.757);
  EXPECT_GE(r.nodalWorstAfter, 0.757);
  // Nodes on the boundary (the cube's faces and the sphere) did not move.
  std::vector<const ElementBlock*> cells;
  for (const ElementBlock& b : input.blocks)
    if (cellDimension(b.type) == 3) cells.push_back(&b);
  const std::vector<char> boundary = boundaryNodes(input.numNodes(), cells);
  std::size_t fixed = 0;
  for (std::size_t i = 0; i < input.numNodes(); ++i)
    if (boundary[i] != 0) {
      ++fixed;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(mesh.xyz[3 * i + c], input.xyz[3 * i + c]);
    }
  EXPECT_GT(fixed, 1000U);
}

// The siblings of NekMesh's three cases, on the meshes made here: the same runs and the same
// kinds of checks, with bounds that hold for any mesh in place of NekMesh's figures. For each
// element, min J / max J over its nodes (NekMesh's measure) is at least the ratio over the whole
// element, and the certified value is a lower bound of that: the nodal worst is never below the
// certified one.
TEST(Optimiser, CubeSphereOrder3FiveIterationsImprovesTheMadeMesh) {
  Mesh mesh = changeOrder(madeCubeSphere(), 3, nullptr);
  OptimiserOptions options;
  options.maxIterations = 5;
  options.threads = 2;
  const OptimiserResult r = optimiseMesh(mesh, options);
  EXPECT_TRUE(r.converged || r.stopReason == "iterations") << r.stopReason;
  EXPECT_LE(r.iterations, 5);
  EXPECT_EQ(r.history.size(), static_cast<std::size_t>(r.iterations));
  EXPECT_EQ(r.invalidBefore, 0U);
  EXPECT_EQ(r.invalidAfter, 0U);
  EXPECT_GT(r.worstAfter, r.worstBefore);
  EXPECT_GE(r.nodalWorstAfter, r.worstAfter);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_NEAR(q.scaled.min, r.worstAfter, 1e-12);  // the same bounds of the same mesh
}

TEST(Optimiser, NacaLinearElasticFiveIterationsImprovesTheMadeMeshInItsPlane) {
  Mesh mesh = madeNaca();
  ASSERT_EQ(mesh.dim, 2);
  ASSERT_EQ(mesh.order, 3);
  const std::vector<double> before = mesh.xyz;
  OptimiserOptions options;
  options.functional = Functional::LinearElastic;
  options.maxIterations = 5;
  const OptimiserResult r = optimiseMesh(mesh, options);
  EXPECT_EQ(r.energyRule, "collapsed");  // valid, but triangles have no symmetric rule here
  EXPECT_EQ(r.invalidAfter, 0U);
  EXPECT_GT(r.worstAfter, r.worstBefore);
  EXPECT_GE(r.nodalWorstAfter, r.worstAfter);
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    EXPECT_EQ(mesh.xyz[3 * i + 2], before[3 * i + 2]);
}

TEST(Optimiser, CubeSphereOrder4ConvergesAndKeepsTheBoundaryOfTheMadeMesh) {
  const Mesh& input = madeCubeSphere();
  Mesh mesh = input;
  OptimiserOptions options;
  options.maxIterations = 60;
  options.threads = 2;
  const OptimiserResult r = optimiseMesh(mesh, options);
  EXPECT_TRUE(r.converged) << r.stopReason;
  EXPECT_EQ(r.energyRule, "symmetric");  // the input is certified valid
  EXPECT_EQ(r.invalidAfter, 0U);
  EXPECT_GT(r.worstAfter, r.worstBefore);
  EXPECT_GE(r.nodalWorstAfter, r.worstAfter);
  // The nodes on the boundary did not move, and they are exactly the nodes of the pipeline's
  // boundary triangles (found here from the tetrahedra alone).
  std::vector<const ElementBlock*> cells;
  std::vector<char> onTriangles(input.numNodes(), 0);
  for (const ElementBlock& b : input.blocks) {
    if (cellDimension(b.type) == 3) cells.push_back(&b);
    if (b.type == CellType::Triangle)
      for (const std::int64_t n : b.nodes) onTriangles[static_cast<std::size_t>(n)] = 1;
  }
  const std::vector<char> boundary = boundaryNodes(input.numNodes(), cells);
  std::size_t fixed = 0;
  for (std::size_t i = 0; i < input.numNodes(); ++i) {
    EXPECT_EQ(boundary[i] != 0, onTriangles[i] != 0) << "node " << i;
    if (boundary[i] != 0) {
      ++fixed;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(mesh.xyz[3 * i + c], input.xyz[3 * i + c]);
    }
  }
  EXPECT_GT(fixed, 0U);
  EXPECT_LT(fixed, input.numNodes());
}

// A hybrid mesh as Gmsh makes it (gmsh_hybrid_box.hpp: pyramids on the unit box's faces,
// tetrahedra inside) at order 4. The nodes inside each pyramid
// moved at random tangle most of them (23 of 36); the optimiser, on the mesh's own equispaced nodes
// (pyramids have no optimal set), makes every element certified valid again (worst 0.28) and
// leaves the boundary where it was. (Moved by up to 30 % of the spacing, 4 of 32 tangled
// pyramids stay invalid: the optimiser stalls, as it can on any badly tangled element.)
TEST(Optimiser, UntanglesThePyramidsOfAHybridMesh) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "hybrid.msh").string();
  test::writeGmshHybridBox({{4, path}});
  const Mesh input = readMesh(path);
  std::vector<const ElementBlock*> cells;
  const ElementBlock* pyramids = nullptr;
  for (const ElementBlock& b : input.blocks)
    if (cellDimension(b.type) == 3) {
      cells.push_back(&b);
      if (b.type == CellType::Pyramid) pyramids = &b;
    }
  ASSERT_NE(pyramids, nullptr);
  ASSERT_GT(pyramids->count(), 10U);
  ASSERT_EQ(evaluateQuality(input).invalid, 0U);
  const std::vector<char> boundary = boundaryNodes(input.numNodes(), cells);
  // The nodes inside each pyramid (order 4: five, a pyramid of order 1 one lattice step in),
  // which no other element holds, move at random by up to 20 % of the pyramid's node spacing
  // (its shortest edge / 4) along each axis: nothing else changes.
  std::vector<int> uses(input.numNodes(), 0);
  for (const ElementBlock* b : cells)
    for (const std::int64_t n : b->nodes) ++uses[static_cast<std::size_t>(n)];
  Mesh mesh = input;
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::set<std::int64_t> moved;
  for (std::size_t e = 0; e < pyramids->count(); ++e) {
    const std::int64_t* v = pyramids->element(e);
    double shortest = std::numeric_limits<double>::infinity();
    for (const auto& [a, b] :
         {std::pair{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}) {
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c)
        d2 += std::pow(input.xyz[3 * static_cast<std::size_t>(v[a]) + c] -
                           input.xyz[3 * static_cast<std::size_t>(v[b]) + c],
                       2);
      shortest = std::min(shortest, std::sqrt(d2));
    }
    for (int k = 0; k < pyramids->nodesPerElement(); ++k)
      if (uses[static_cast<std::size_t>(v[k])] == 1 &&
          boundary[static_cast<std::size_t>(v[k])] == 0 && moved.insert(v[k]).second)
        for (int c = 0; c < 3; ++c)
          mesh.xyz[3 * static_cast<std::size_t>(v[k]) + c] += 0.2 * shortest / 4.0 * u(rng);
  }
  ASSERT_EQ(moved.size(), 5 * pyramids->count());
  OptimiserOptions options;
  options.threads = 2;
  const OptimiserResult r = optimiseMesh(mesh, options);
  EXPECT_GT(r.invalidBefore, 0U);
  EXPECT_EQ(r.energyRule, "collapsed");  // not the symmetric rule on a tangled input
  EXPECT_EQ(r.invalidAfter, 0U);
  EXPECT_EQ(r.undecidedAfter, 0U);
  EXPECT_GT(r.worstAfter, 0.0);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid, 0U);
  EXPECT_TRUE(q.certified);
  for (std::size_t i = 0; i < input.numNodes(); ++i) {
    if (boundary[i] == 0) continue;
    for (int c = 0; c < 3; ++c) ASSERT_EQ(mesh.xyz[3 * i + c], input.xyz[3 * i + c]);
  }
}

TEST(Optimiser, ResultDoesNotDependOnTheNumberOfThreads) {
  for (const Input& in : cubeSpheres()) {
    Mesh a = in.mesh, b = in.mesh, c = in.mesh;
    OptimiserOptions options;
    options.maxIterations = 3;
    options.threads = 1;
    optimiseMesh(a, options);
    options.threads = 2;
    optimiseMesh(b, options);
    options.threads = 3;  // three parts of unequal shape: threads help each other's parts
    optimiseMesh(c, options);
    // Exact by design: nodes of one colour share no element, so each node's Newton step reads
    // the same data whichever thread computes it (the only reduction is a max), and the energy
    // is summed per element in one order.
    EXPECT_NE(a.xyz, in.mesh.xyz) << in.name;  // something moved
    EXPECT_EQ(a.xyz, b.xyz) << in.name;
    EXPECT_EQ(a.xyz, c.xyz) << in.name;
  }
}

// OpenMP may start fewer threads than asked (OMP_THREAD_LIMIT, OMP_DYNAMIC, or, as here, a call
// from inside another parallel region, where nested regions get one thread): every phase still
// covers every part, so the result is that of one thread.
TEST(Optimiser, ATeamSmallerThanAskedGivesTheSameResult) {
  for (const Input& in : cubeSpheres()) {
    const Mesh& input = in.mesh;
    Mesh one = input, nested = input;
    OptimiserOptions options;
    options.maxIterations = 2;
    options.threads = 1;
    optimiseMesh(one, options);
    options.threads = 3;  // three parts, one thread to write them
    int team = 0;
#pragma omp parallel num_threads(2)
    {
#pragma omp single
      {
#pragma omp parallel num_threads(3)
        {
#pragma omp single
          team = omp_get_num_threads();
        }
        optimiseMesh(nested, options);
      }
    }
    ASSERT_EQ(team, 1) << "nested regions run in parallel here: the test shows nothing";
    EXPECT_EQ(one.xyz, nested.xyz) << in.name;
    EXPECT_NE(one.xyz, input.xyz) << in.name;
  }
}

// The same in 2D and in region mode, where only some elements carry weight in the threads'
// partition (work_partition.hpp), so the parts' node counts differ most.
TEST(Optimiser, ResultDoesNotDependOnTheNumberOfThreadsIn2DAndInARegion) {
  std::vector<std::pair<Input, OptimiserOptions>> cases;
  OptimiserOptions plain;
  plain.functional = Functional::LinearElastic;
  plain.maxIterations = 3;
  for (Input& in : nacas()) cases.emplace_back(std::move(in), plain);
  for (Input& in : cubeSpheres()) {
    OptimiserOptions region;
    region.maxIterations = 2;
    region.regionThreshold = lowTenth(in.mesh);
    region.regionLayers = 1;
    cases.emplace_back(std::move(in), region);
  }
  for (const auto& [in, base] : cases) {
    Mesh one = in.mesh, three = in.mesh;
    OptimiserOptions options = base;
    options.threads = 1;
    const OptimiserResult r = optimiseMesh(one, options);
    options.threads = 3;
    optimiseMesh(three, options);
    EXPECT_EQ(one.xyz, three.xyz) << in.name;
    EXPECT_NE(one.xyz, in.mesh.xyz) << in.name;  // something moved
    if (base.regionThreshold) {
      EXPECT_LT(r.regionElements, in.mesh.numElements()) << in.name;
    }
  }
}

// With the boundary facets' term (OptimiserOptions::facetWeight) too: a sliding node's term reads
// the other nodes of its facets, which share a volume element with it and so have other colours.
TEST(Optimiser, ResultDoesNotDependOnTheNumberOfThreadsWithTheFacetTerm) {
  MeshingOptions meshing;
  meshing.order = 3;
  meshing.size = 1.0;
  const MeshResult hole =
      runMeshPipeline(CadSource::brepText(test::brepText(test::boxWithHole())), meshing);
  Mesh one = hole.mesh, three = hole.mesh, off = hole.mesh;
  OptimiserOptions options;
  options.maxIterations = 3;
  options.facetWeight = 1.0;
  options.threads = 1;
  optimiseMesh(one, options, nullptr, hole.cad.get());
  options.threads = 3;
  optimiseMesh(three, options, nullptr, hole.cad.get());
  EXPECT_EQ(one.xyz, three.xyz);
  EXPECT_EQ(std::memcmp(one.nodeCadParam.data(), three.nodeCadParam.data(),
                        one.nodeCadParam.size() * sizeof(double)),
            0);
  options.facetWeight = 0.0;
  optimiseMesh(off, options, nullptr, hole.cad.get());
  EXPECT_NE(one.xyz, off.xyz) << "the facet term changed nothing";
}

// The box with a hole at order 3, size 1, curved and not optimised, with its CAD: nodes that
// slide.
MeshResult curvedBoxWithHole() {
  MeshingOptions meshing;
  meshing.order = 3;
  meshing.size = 1.0;
  return runMeshPipeline(CadSource::brepText(test::brepText(test::boxWithHole())), meshing);
}

// The sweeps run on the mesh renumbered along a space-filling curve (OptimiserOptions::
// spatialOrder), for locality only: every choice made in sequence follows the caller's numbers,
// so the result is the one without the renumbering, bit for bit: in 3D and 2D, with the mesh's
// working node set (no CAD, no region), in a region with per-element seeds, fixed and locked
// nodes (renumbered alongside) and the caller's quality, and sliding on the CAD; on 1 to 3
// threads. The caller's connectivity is untouched.
TEST(Optimiser, TheSpatialOrderChangesNoResult) {
  struct Case {
    std::string name;
    Mesh mesh;
    OptimiserOptions options;
    const CadModel* cad = nullptr;
    bool quality = false;
  };
  std::vector<Case> cases;
  OptimiserOptions plain;
  plain.maxIterations = 3;
  plain.threads = 2;
  for (const Input& in : cubeSpheres()) {
    const Mesh& cube = in.mesh;
    cases.push_back({in.name + ", working set", cube, plain});
    OptimiserOptions region = plain;
    region.threads = 3;
    region.regionThreshold = std::max(lowTenth(cube), 0.6);
    region.regionLayers = 1;
    region.regionSeed.assign(cube.numElements(), 0);
    for (std::size_t i = 0; i < region.regionSeed.size(); i += 40) region.regionSeed[i] = 1;
    region.fixedNodes.assign(cube.numNodes(), 0);
    region.normalLocked.assign(3 * cube.numNodes(), std::nan(""));
    for (std::size_t i = 0; i < cube.numNodes(); i += 50) region.fixedNodes[i] = 1;
    for (std::size_t i = 1; i < cube.numNodes(); i += 7)
      for (int d = 0; d < 3; ++d)
        region.normalLocked[3 * i + static_cast<std::size_t>(d)] = d == 2 ? 1.0 : 0.0;
    cases.push_back({in.name + ", region", cube, region, nullptr, true});
    // The tetrahedra in two blocks with an empty one between (global element indices across
    // blocks), in a region seeded by element.
    Mesh split = cube;
    for (std::size_t bi = 0; bi < split.blocks.size(); ++bi) {
      ElementBlock& b = split.blocks[bi];
      if (cellDimension(b.type) != 3) continue;
      const std::size_t half = b.count() / 2;
      const auto cut =
          static_cast<std::ptrdiff_t>(half * static_cast<std::size_t>(b.nodesPerElement()));
      ElementBlock empty, second;
      empty.type = second.type = b.type;
      empty.order = second.order = b.order;
      second.nodes.assign(b.nodes.begin() + cut, b.nodes.end());
      second.entity.assign(b.entity.begin() + static_cast<std::ptrdiff_t>(half), b.entity.end());
      b.nodes.resize(static_cast<std::size_t>(cut));
      b.entity.resize(half);
      const auto at = split.blocks.begin() + static_cast<std::ptrdiff_t>(bi) + 1;
      split.blocks.insert(split.blocks.insert(at, second), empty);
      break;
    }
    ASSERT_EQ(split.numElements(), cube.numElements());
    OptimiserOptions seeded = plain;
    seeded.regionSeed.assign(cube.numElements(), 0);
    for (std::size_t i = 3; i < seeded.regionSeed.size(); i += 30) seeded.regionSeed[i] = 1;
    seeded.regionLayers = 1;
    cases.push_back({in.name + " in three blocks, seeded region", split, seeded, nullptr, true});
  }
  OptimiserOptions naca = plain;
  naca.functional = Functional::LinearElastic;
  naca.threads = 1;
  for (const Input& in : nacas()) cases.push_back({in.name + " 2D", in.mesh, naca});
  const MeshResult hole = curvedBoxWithHole();
  cases.push_back({"box with a hole, sliding on the CAD", hole.mesh, plain, hole.cad.get()});
  OptimiserOptions facets = plain;
  facets.facetWeight = 1.0;
  cases.push_back({"box with a hole, sliding, facet term", hole.mesh, facets, hole.cad.get()});
  for (Case& c : cases) {
    // The renumbering is not the identity: the test compares two different storage orders.
    const SpatialOrder order(c.mesh);
    std::vector<std::int64_t> identity(c.mesh.numNodes());
    std::iota(identity.begin(), identity.end(), 0);
    EXPECT_NE(order.originalNodes(), identity) << c.name;
    const QualitySummary quality = evaluateQuality(c.mesh);
    const QualitySummary* start = c.quality ? &quality : nullptr;
    Mesh spatial = c.mesh, own = c.mesh;
    OptimiserOptions options = c.options;
    const OptimiserResult a = optimiseMesh(spatial, options, nullptr, c.cad, start);
    options.spatialOrder = false;
    const OptimiserResult b = optimiseMesh(own, options, nullptr, c.cad, start);
    EXPECT_NE(spatial.xyz, c.mesh.xyz) << c.name;  // something moved
    EXPECT_EQ(spatial.xyz, own.xyz) << c.name;
    // Bit for bit (NaN where a node has no parameter).
    EXPECT_EQ(spatial.nodeCadParam.size(), own.nodeCadParam.size());
    EXPECT_EQ(std::memcmp(spatial.nodeCadParam.data(), own.nodeCadParam.data(),
                          own.nodeCadParam.size() * sizeof(double)),
              0)
        << c.name;
    EXPECT_EQ(a.worstAfter, b.worstAfter) << c.name;
    EXPECT_EQ(a.energyAfter, b.energyAfter) << c.name;
    EXPECT_EQ(a.visits, b.visits) << c.name;
    EXPECT_EQ(a.colours, b.colours) << c.name;
    EXPECT_EQ(a.regionElements, b.regionElements) << c.name;
    EXPECT_EQ(a.iterations, b.iterations) << c.name;
    for (std::size_t bi = 0; bi < c.mesh.blocks.size(); ++bi) {
      EXPECT_EQ(spatial.blocks[bi].nodes, c.mesh.blocks[bi].nodes) << c.name;
      EXPECT_EQ(spatial.blocks[bi].entity, c.mesh.blocks[bi].entity) << c.name;
    }
    EXPECT_EQ(spatial.nodeCadIndex, c.mesh.nodeCadIndex) << c.name;
  }
}

// A run that throws leaves the caller's mesh as given, in the caller's numbering, and its
// messages name elements by the caller's numbers.
TEST(Optimiser, AFailedRunLeavesTheCallersMeshAndNumbers) {
  const Mesh& cube = madeCubeSphere();
  Mesh mesh = cube;
  OptimiserOptions options;
  options.fixedNodes.assign(5, 1);  // wrong size: refused inside the run
  EXPECT_THROW(optimiseMesh(mesh, options), ParameterError);
  EXPECT_EQ(mesh.xyz, cube.xyz);
  for (std::size_t bi = 0; bi < cube.blocks.size(); ++bi)
    EXPECT_EQ(mesh.blocks[bi].nodes, cube.blocks[bi].nodes);
  // A flat tetrahedron (its four corners in z = 0) as element 2 of three, after two sound ones.
  Mesh flat = twoTetrahedra(1);
  const double corner[3] = {1.0, 1.0, 0.0};
  flat.addNode(corner, 3, 1, NAN, NAN);
  flat.blocks[0].nodes.insert(flat.blocks[0].nodes.end(), {0, 1, 2, 5});
  flat.blocks[0].entity.push_back(1);
  const Mesh given = flat;
  ASSERT_NE(SpatialOrder(flat).originalElements(), (std::vector<std::size_t>{0, 1, 2}));
  try {
    optimiseMesh(flat, OptimiserOptions());
    ADD_FAILURE() << "a flat element was accepted";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("element 2 (0-based"), std::string::npos) << e.what();
  }
  EXPECT_EQ(flat.xyz, given.xyz);
  EXPECT_EQ(flat.blocks[0].nodes, given.blocks[0].nodes);
}

// Six sweeps each (no energy rule), without focused passes, on 2 threads: the runs the
// resting and settled tests compare.
OptimiserOptions sixPlainSweeps() {
  OptimiserOptions options;
  options.maxIterations = 6;
  options.focusPasses = 0;
  options.threads = 2;
  options.energyTolerance = 0.0;
  return options;
}

TEST(Optimiser, RestingNodesAreVisitedOnlyWhenTheirNeighboursMove) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    Mesh every = in.mesh, active = in.mesh;
    OptimiserOptions options = sixPlainSweeps();
    // Every free node in every sweep, where each moves in each (a node whose step is exactly
    // zero rests until a neighbour moves: on a straight-sided patch, hence the made mesh's
    // perturbation).
    options.activeTolerance = 0.0;
    const OptimiserResult all = optimiseMesh(every, options);
    options.activeTolerance = OptimiserOptions().activeTolerance;  // the default, 1e-3
    const OptimiserResult some = optimiseMesh(active, options);
    ASSERT_EQ(all.history.size(), 6U);
    ASSERT_EQ(some.history.size(), 6U);
    for (const IterationRecord& h : all.history) EXPECT_EQ(h.visits, all.freeNodes);
    EXPECT_EQ(some.history.front().visits, some.freeNodes);  // the first sweep visits every node
    // Later sweeps skip the nodes that rest (few on these small meshes, where every node is in
    // or next to a curved element).
    EXPECT_LT(some.history.back().visits, some.freeNodes);
    EXPECT_LT(some.visits, all.visits);
    std::size_t sum = 0;
    for (const IterationRecord& h : some.history) sum += h.visits;
    EXPECT_EQ(sum, some.visits);
    // Skipping nodes whose moves would be below 1e-3 of their element still improves the mesh.
    EXPECT_GT(some.worstAfter, some.worstBefore);
    EXPECT_EQ(some.invalidAfter, 0U);
    std::printf("%s P4, 6 sweeps: %zu node visits (every node: %zu), worst %.4f (%.4f)\n",
                in.name.c_str(), some.visits, all.visits, some.worstAfter, all.worstAfter);
  }
}

// A node inside the domain whose elements are all good (settledQuality) rests below the larger
// settledTolerance. These meshes have no CAD, so every free node is inside the domain: with
// settledQuality 0 every node whose elements are valid and more than focusMargin above the
// worst settles, and the run visits fewer nodes than with the rule off (and may end early,
// nothing left to move), still improving the mesh; the rule's two values are checked.
TEST(Optimiser, SettledNodesRestBelowTheLargerTolerance) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    Mesh off = in.mesh, on = in.mesh;
    OptimiserOptions options = sixPlainSweeps();
    options.tolerance = 0.0;       // (settled, a sweep may move nothing)
    options.settledQuality = 2.0;  // none settles (the default)
    const OptimiserResult plain = optimiseMesh(off, options);
    options.settledQuality = 0.0;  // every node of valid elements away from the worst does
    const OptimiserResult settled = optimiseMesh(on, options);
    ASSERT_EQ(plain.history.size(), 6U);
    // Up to six: a run whose nodes all rest moves nothing and ends ("displacement").
    ASSERT_LE(settled.history.size(), 6U);
    if (settled.history.size() < 6U) {
      EXPECT_EQ(settled.stopReason, "displacement");
      EXPECT_EQ(settled.history.back().maxRelativeMove, 0.0);
    }
    EXPECT_EQ(settled.history.front().visits, plain.history.front().visits);  // the first: all
    EXPECT_LT(settled.visits, plain.visits);
    EXPECT_GT(settled.worstAfter, settled.worstBefore);
    EXPECT_EQ(settled.invalidAfter, 0U);
    std::printf(
        "%s P4: %zu node visits in %zu sweeps settled (%zu in 6 without), worst %.4f "
        "(%.4f)\n",
        in.name.c_str(), settled.visits, settled.history.size(), plain.visits, settled.worstAfter,
        plain.worstAfter);
  }
  OptimiserOptions bad;
  bad.settledQuality = 0.7;
  bad.settledTolerance = 0.5 * bad.activeTolerance;
  EXPECT_THROW(bad.validate(), ParameterError);
  bad = OptimiserOptions();
  bad.settledQuality = 0.7;
  bad.settledSlidingTolerance = 0.5 * bad.activeTolerance;
  EXPECT_THROW(bad.validate(), ParameterError);
  bad = OptimiserOptions();
  bad.settledQuality = NAN;
  EXPECT_THROW(bad.validate(), ParameterError);
}

// A settled node that slides on the CAD rests below settledSlidingTolerance: on the curved box
// with a hole, not optimised, with every node of valid elements away from the worst settled,
// a larger tolerance for the sliding ones leaves fewer of their visits (the first sweep visits
// every node either way) and still improves the mesh.
TEST(Optimiser, SettledNodesOnTheCadRestBelowTheirOwnTolerance) {
  const MeshResult hole = curvedBoxWithHole();
  OptimiserOptions options = sixPlainSweeps();
  options.tolerance = 0.0;
  options.settledQuality = 0.0;
  options.settledSlidingTolerance = options.activeTolerance;  // as inside a node's own move
  Mesh tight = hole.mesh, loose = hole.mesh;
  const OptimiserResult a = optimiseMesh(tight, options, nullptr, hole.cad.get());
  options.settledSlidingTolerance = 1e-2;
  const OptimiserResult b = optimiseMesh(loose, options, nullptr, hole.cad.get());
  ASSERT_GT(a.slides, 0U);
  EXPECT_EQ(a.history.front().visits, b.history.front().visits);
  EXPECT_LT(b.slides, a.slides);
  EXPECT_GT(b.worstAfter, b.worstBefore);
  EXPECT_EQ(b.invalidAfter, 0U);
  std::printf("box with a hole P3: %zu sliding visits settled below 1e-2 (%zu below 1e-3)\n",
              b.slides, a.slides);
}

// A time limit ends the run with "time budget" and the best state so far: a limit far below
// the set-up stops it there, after the input's quality, and keeps the input exactly (its
// energy not computed); a limit of a few sweeps stops between sweeps, at the first check past
// the limit, never worse than the input. Where the limit falls is made independent of the
// machine's speed: an observer holds the run after its second sweep until the limit has passed.
TEST(Optimiser, ATimeLimitStopsWithTheBestStateSoFar) {
  const Mesh& input = madeCubeSphere();
  OptimiserOptions options;
  options.maxIterations = 1000;
  options.threads = 2;
  options.timeLimit = 1e-6;
  Mesh mesh = input;
  const OptimiserResult tiny = optimiseMesh(mesh, options);
  EXPECT_EQ(tiny.stopReason, "time budget");
  EXPECT_FALSE(tiny.cancelled);
  EXPECT_EQ(tiny.iterations, 0);
  EXPECT_EQ(tiny.keptIteration, 0);
  EXPECT_EQ(mesh.xyz, input.xyz);
  EXPECT_TRUE(tiny.history.empty());
  EXPECT_EQ(tiny.freeNodes, 0u);  // stopped before choosing them
  EXPECT_TRUE(std::isnan(tiny.energyBefore) && std::isnan(tiny.energyAfter));
  EXPECT_EQ(tiny.worstAfter, tiny.worstBefore);
  EXPECT_EQ(tiny.invalidAfter, tiny.invalidBefore);
  EXPECT_EQ(tiny.undecidedAfter, tiny.undecidedBefore);
  EXPECT_EQ(tiny.nodalWorstAfter, tiny.nodalWorstBefore);
  EXPECT_GT(tiny.nodalWorstBefore, 0.0);  // the input was evaluated (a valid mesh)

  // Sleeps, after sweep `holdAfter`, until the run's own clock (IterationRecord::seconds, from
  // the same start as the limit) is past `limit`.
  struct HoldAfter : OptimiserObserver {
    int holdAfter = 2;
    double limit = 0.0;
    bool heldInTime = false;  // sweep holdAfter ended before the limit
    void iterationFinished(const IterationRecord& r) override {
      if (r.iteration != holdAfter) return;
      heldInTime = r.seconds < limit;
      const double wait = std::max(0.0, limit - r.seconds) + 0.01;
      std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    }
  } hold;
  // No other rule may end it first: every node in every sweep, no displacement or energy rule.
  options.tolerance = 0.0;
  options.energyTolerance = 0.0;
  options.activeTolerance = 0.0;
  options.timeLimit = hold.limit = 0.5;
  mesh = input;
  const OptimiserResult some = optimiseMesh(mesh, options, &hold);
  EXPECT_EQ(some.stopReason, "time budget");
  EXPECT_FALSE(some.cancelled);
  // Stopped at the first check past the limit: the next sweep's start. On a machine so slow that
  // the limit passed before, the run stopped earlier (and may end with a partial sweep).
  EXPECT_LE(some.iterations, hold.holdAfter);
  if (hold.heldInTime) {
    EXPECT_EQ(some.iterations, hold.holdAfter);
    for (const IterationRecord& h : some.history) EXPECT_FALSE(h.partial);
  }
  ASSERT_EQ(some.history.size(), static_cast<std::size_t>(some.iterations));
  for (std::size_t i = 0; i < some.history.size(); ++i)
    EXPECT_EQ(some.history[i].iteration, static_cast<int>(i) + 1);
  // The state kept is the best record, never worse than the input, and it is what the mesh holds.
  EXPECT_GE(some.worstAfter, some.worstBefore);
  EXPECT_LE(some.invalidAfter, some.invalidBefore);
  ASSERT_GE(some.keptIteration, 0);
  ASSERT_LE(some.keptIteration, some.iterations);
  if (some.keptIteration > 0) {
    const IterationRecord& kept = some.history[static_cast<std::size_t>(some.keptIteration - 1)];
    EXPECT_EQ(some.worstAfter, kept.worst);
    EXPECT_EQ(some.energyAfter, kept.energy);
    for (const IterationRecord& h : some.history) {
      if (h.invalid + h.undecided == 0) {
        EXPECT_LE(h.worst, kept.worst) << "sweep " << h.iteration;
      }
    }
    EXPECT_NE(mesh.xyz, input.xyz);
  } else {
    EXPECT_EQ(mesh.xyz, input.xyz);
  }
  EXPECT_NEAR(evaluateQuality(mesh).scaled.min, some.worstAfter, 1e-12);  // the same bounds
  options.timeLimit = -1.0;
  EXPECT_THROW(optimiseMesh(mesh, options), ParameterError);
}

// With the worst element's nodes all fixed its value cannot change, so every sweep ties with the
// input on the worst value: the state kept is then the one of lowest energy, not the input.
TEST(Optimiser, ATieOnTheWorstValueKeepsTheLowerEnergy) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    const Mesh& input = in.mesh;
    const QualitySummary quality = evaluateQuality(input);
    const ElementBlock& tets = input.blocks[0];
    ASSERT_EQ(tets.count(), input.numElements());
    const auto worst = static_cast<std::size_t>(
        std::min_element(quality.scaledJacobian.begin(), quality.scaledJacobian.end()) -
        quality.scaledJacobian.begin());
    OptimiserOptions options;
    options.maxIterations = 3;
    options.fixedNodes.assign(input.numNodes(), 0);
    for (int k = 0; k < tets.nodesPerElement(); ++k) options.fixedNodes[tets.element(worst)[k]] = 1;
    Mesh mesh = input;
    const OptimiserResult r = optimiseMesh(mesh, options);
    EXPECT_EQ(r.worstAfter, r.worstBefore);
    EXPECT_EQ(r.worstAfter, quality.scaled.min);
    EXPECT_EQ(r.invalidAfter, 0U);
    EXPECT_GE(r.keptIteration, 1);
    EXPECT_LT(r.energyAfter, r.energyBefore);
    EXPECT_NE(mesh.xyz, input.xyz);
    // The kept state is the lowest-energy record among those that tie.
    for (const IterationRecord& h : r.history) {
      if (h.worst == r.worstAfter && h.invalid + h.undecided == 0) {
        EXPECT_GE(h.energy, r.energyAfter);
      }
    }
    for (int k = 0; k < tets.nodesPerElement(); ++k) {
      const auto n = static_cast<std::size_t>(tets.element(worst)[k]);
      for (std::size_t d = 0; d < 3; ++d) EXPECT_EQ(mesh.xyz[3 * n + d], input.xyz[3 * n + d]);
    }
  }
}

// The time limit stopping the first sweep part-way keeps what that sweep moved, once certified:
// an observer holds the run at the colour group nine tenths of the way through the sweep until
// the limit has passed (cancelRequested is asked before each sweep and at each colour group).
// One thread, so the same nodes move every time.
TEST(Optimiser, ATimeLimitPartWayThroughASweepKeepsWhatItMoved) {
  const Mesh& input = madeCubeSphere();
  OptimiserOptions options;
  options.maxIterations = 1;
  options.threads = 1;
  options.focusPasses = 0;
  Mesh whole = input;
  const OptimiserResult full = optimiseMesh(whole, options);
  ASSERT_EQ(full.iterations, 1);
  ASSERT_GT(full.colours, 10u);

  struct HoldAt : OptimiserObserver {
    int call = 0, holdAt = 0;
    bool cancelRequested() override {
      if (++call == holdAt) std::this_thread::sleep_for(std::chrono::milliseconds(1100));
      return false;
    }
  } hold;
  hold.holdAt = 1 + static_cast<int>(full.colours * 9 / 10);
  options.maxIterations = 5;
  options.timeLimit = 1.0;
  Mesh mesh = input;
  const OptimiserResult part = optimiseMesh(mesh, options, &hold);
  EXPECT_EQ(part.stopReason, "time budget");
  EXPECT_FALSE(part.cancelled);
  ASSERT_EQ(part.iterations, 1);
  ASSERT_EQ(part.history.size(), 1u);
  const IterationRecord& r = part.history.front();
  EXPECT_TRUE(r.partial);
  EXPECT_GT(r.visits, 0u);
  EXPECT_LT(r.visits, full.visits);  // the last tenth of the colour groups was not visited
  // Certified like a whole sweep, and kept, as it beats the input; the returned mesh is
  // proven valid by the quality check too.
  EXPECT_GT(r.worst, part.worstBefore);
  EXPECT_EQ(part.keptIteration, 1);
  EXPECT_EQ(part.worstAfter, r.worst);
  EXPECT_EQ(part.invalidAfter, 0u);
  EXPECT_NE(mesh.xyz, input.xyz);
  const QualitySummary after = evaluateQuality(mesh);
  EXPECT_GT(*std::min_element(after.scaledJacobian.begin(), after.scaledJacobian.end()), 0.0);
  // A cancel request instead drops the half-done sweep.
  struct CancelAt : OptimiserObserver {
    int call = 0, at = 0;
    bool cancelRequested() override { return ++call == at; }
  } cancel;
  cancel.at = hold.holdAt;
  options.timeLimit = 0.0;
  mesh = input;
  const OptimiserResult cancelled = optimiseMesh(mesh, options, &cancel);
  EXPECT_TRUE(cancelled.cancelled);
  EXPECT_TRUE(cancelled.history.empty());
  EXPECT_EQ(mesh.xyz, input.xyz);
}

TEST(Optimiser, NeverReturnsAWorseMesh) {
  // An optimal mesh (a single straight tetrahedron has no free node; two glued ones one face
  // node at P3): any run must return it no worse.
  Mesh mesh = elevateOrder(twoTetrahedra(1), 3, nullptr);
  const QualitySummary before = evaluateQuality(mesh);
  OptimiserOptions options;
  options.maxIterations = 10;
  for (const Functional f : kAll) {
    options.functional = f;
    Mesh m = mesh;
    const OptimiserResult r = optimiseMesh(m, options);
    EXPECT_GE(r.worstAfter, r.worstBefore);
    EXPECT_LE(r.invalidAfter, r.invalidBefore);
    EXPECT_GE(evaluateQuality(m).scaled.min, before.scaled.min);
  }
}

TEST(Optimiser, RegionRestrictsTheMovingNodes) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    const Mesh& input = in.mesh;
    Mesh mesh = input;
    OptimiserOptions options;
    options.maxIterations = 2;
    options.regionThreshold = lowTenth(input);
    options.regionLayers = 1;
    const OptimiserResult r = optimiseMesh(mesh, options);
    // Only the free nodes move (no fixed node at the region's edge changes with its neighbours).
    std::size_t moved = 0;
    for (std::size_t i = 0; i < mesh.xyz.size(); i += 3)
      moved += mesh.xyz[i] != input.xyz[i] || mesh.xyz[i + 1] != input.xyz[i + 1] ||
                       mesh.xyz[i + 2] != input.xyz[i + 2]
                   ? 1
                   : 0;
    EXPECT_GT(moved, 0U);
    EXPECT_LE(moved, r.freeNodes);
    EXPECT_GT(r.regionElements, 0U);
    EXPECT_LT(r.regionElements, mesh.numElements());
    EXPECT_GT(r.worstAfter, r.worstBefore);
    Mesh all = input;
    options.regionThreshold.reset();
    EXPECT_GT(optimiseMesh(all, options).freeNodes, r.freeNodes);
  }
}

// A caller's quality of the input (a repair round's, measured only where the mesh changed) stands
// in for the set-up's own measurement: the same region, the same sweeps, the same nodes. A
// quality summary of another mesh (wrong size) is ignored.
TEST(Optimiser, TheCallersQualityOfTheInputGivesTheSameRun) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    const Mesh& input = in.mesh;
    OptimiserOptions options;
    options.maxIterations = 3;
    options.regionThreshold = lowTenth(input);
    options.regionLayers = 1;
    Mesh measured = input, given = input, other = input;
    const OptimiserResult a = optimiseMesh(measured, options);
    const QualitySummary quality = evaluateQuality(input);
    const OptimiserResult b = optimiseMesh(given, options, nullptr, nullptr, &quality);
    EXPECT_EQ(measured.xyz, given.xyz);
    EXPECT_NE(given.xyz, input.xyz);
    EXPECT_EQ(a.regionElements, b.regionElements);
    EXPECT_EQ(a.visits, b.visits);
    EXPECT_EQ(a.worstBefore, quality.scaled.min);
    EXPECT_EQ(b.worstBefore, quality.scaled.min);
    EXPECT_EQ(a.worstAfter, b.worstAfter);
    // It is what the set-up uses: every element marked below the region threshold puts every
    // element in the region.
    QualitySummary poor = quality;
    poor.scaledJacobian.assign(poor.scaledJacobian.size(), *options.regionThreshold / 2);
    Mesh copy = input;
    EXPECT_EQ(optimiseMesh(copy, options, nullptr, nullptr, &poor).regionElements,
              input.numElements());
    EXPECT_LT(a.regionElements, input.numElements());
    QualitySummary wrong = quality;
    wrong.scaledJacobian.pop_back();
    optimiseMesh(other, options, nullptr, nullptr, &wrong);
    EXPECT_EQ(other.xyz, measured.xyz);
  }
}

// A boundary layer's top released around invalid elements slides parallel to its wall: a node
// with a locked direction moves only perpendicular to it (to rounding), the rest as before.
TEST(Optimiser, LockedNodesMoveOnlyPerpendicularToTheirDirection) {
  for (const Input& in : cubeSpheres()) {
    SCOPED_TRACE(in.name);
    const Mesh& input = in.mesh;
    Mesh mesh = input;
    OptimiserOptions options;
    options.maxIterations = 3;
    options.regionThreshold = 1.0;  // every element: the optimiser works on the mesh's own nodes
    options.normalLocked.assign(3 * mesh.numNodes(), std::nan(""));
    const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
    for (std::size_t i = 0; i < mesh.numNodes(); i += 2)  // every other node
      for (int d = 0; d < 3; ++d) options.normalLocked[3 * i + static_cast<std::size_t>(d)] = n(d);
    const OptimiserResult r = optimiseMesh(mesh, options);
    std::size_t lockedMoved = 0, freeMoved = 0;
    double worstAlong = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
      const Eigen::Vector3d move =
          Eigen::Vector3d(&mesh.xyz[3 * i]) - Eigen::Vector3d(&input.xyz[3 * i]);
      if (move.isZero(0.0)) continue;
      scale = std::max(scale, Eigen::Vector3d(&input.xyz[3 * i]).norm());
      if (i % 2 == 0) {
        ++lockedMoved;
        worstAlong = std::max(worstAlong, std::fabs(move.dot(n)));
      } else {
        ++freeMoved;
      }
    }
    // Both kinds move: a tenth of the free nodes each at least (half of them are locked).
    EXPECT_GT(lockedMoved, r.freeNodes / 10);
    EXPECT_GT(freeMoved, r.freeNodes / 10);
    // Each accepted step is t s with t perpendicular to n: its component along n is rounding of
    // the coordinates (a few units of 1e-16 of their size per step, three sweeps plus focus).
    EXPECT_LE(worstAlong, 1e-13 * scale);
    EXPECT_EQ(r.invalidAfter, 0U);
    EXPECT_GT(r.worstAfter, r.worstBefore);
    options.normalLocked.resize(5);
    Mesh again = input;
    EXPECT_THROW(optimiseMesh(again, options), ParameterError);
  }
}

TEST(Optimiser, BadOptionsAreRefused) {
  Mesh mesh = elevateOrder(twoTetrahedra(1), 2, nullptr);
  OptimiserOptions options;
  options.maxIterations = -1;
  EXPECT_THROW(optimiseMesh(mesh, options), ParameterError);
  options = {};
  options.threads = -1;  // (0 is every core)
  EXPECT_THROW(optimiseMesh(mesh, options), ParameterError);
  options = {};
  options.regionThreshold = 1.5;
  EXPECT_THROW(optimiseMesh(mesh, options), ParameterError);
}

// An element whose straight-sided shape is flat (its fourth vertex in the plane of the other
// three) has no ideal to measure distortion against: refused naming it, after the input's
// quality is measured (the samples are built then) and before any node moves.
TEST(Optimiser, AFlatStraightSidedElementIsRefusedByNumber) {
  Mesh mesh = twoTetrahedra(1);
  mesh.xyz[3 * 4] = 0.5, mesh.xyz[3 * 4 + 1] = 0.5, mesh.xyz[3 * 4 + 2] = 0.0;  // x + y + z = 1
  mesh = elevateOrder(mesh, 2, nullptr);
  const std::vector<double> before = mesh.xyz;
  try {
    optimiseMesh(mesh, OptimiserOptions{});
    FAIL() << "a flat element was optimised";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("element 1 "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zero volume"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mesh.xyz, before);
}

}  // namespace
}  // namespace homesh
