// Repair rounds: the edge split alone (volumes, orientation, no chord left on a curved face) and
// the pipeline on the sphere in a box, which curving alone leaves invalid.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <gp_Circ.hxx>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <thread>

#include "core/error.hpp"
#include "core/isolated_call.hpp"
#include "core/parameters.hpp"
#include "curving/order_elevation.hpp"
#include "linear/edge_split.hpp"
#include "linear/linear_mesher.hpp"
#include "pipeline/curved_reuse.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/repair.hpp"
#include "pipeline/report.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

const std::string kSphereBox = std::string(HOMESH_SOURCE_DIR) + "/examples/sphere_box.step";

std::vector<double> cellVolumes(const Mesh& mesh) {
  std::vector<double> v;
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Tetrahedron)
      for (std::size_t e = 0; e < b.count(); ++e) v.push_back(simplexVolume(mesh, b.element(e)));
  return v;
}

std::size_t countTriangles(const Mesh& mesh) {
  std::size_t n = 0;
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Triangle) n += b.count();
  return n;
}

// Every cell's interior chords on a curved face.
std::vector<CurvedFaceEdge> allChords(const Mesh& mesh, const CadModel& cad) {
  const CurvedFaceEdges finder(mesh, cad);
  std::vector<CurvedFaceEdge> chords;
  std::set<MeshEdge> seen;
  for (std::size_t c = 0; c < mesh.numElements(); ++c)
    for (const CurvedFaceEdge& e : finder.interior(c))
      if (seen.insert(e.edge).second) chords.push_back(e);
  return chords;
}

// The octahedron inscribed in the unit sphere, cut into four tetrahedra around its axis: the axis
// is an interior edge whose ends both lie on the sphere (each tetrahedron has two faces on it).
Mesh octahedronAroundItsAxis() {
  Mesh mesh;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double p[6][3] = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  for (const auto& x : p) mesh.addNode(x, 2, 1, nan, nan);
  ElementBlock tets, tris;
  tris.type = CellType::Triangle;
  for (std::int64_t k = 0; k < 4; ++k) {
    const std::int64_t a = 2 + k, b = 2 + (k + 1) % 4;
    std::vector<std::int64_t> t{0, 1, a, b};
    if (simplexVolume(mesh, t.data()) < 0.0) std::swap(t[2], t[3]);
    tets.nodes.insert(tets.nodes.end(), t.begin(), t.end());
    tets.entity.push_back(1);
    for (const std::int64_t pole : {0, 1}) {
      tris.nodes.insert(tris.nodes.end(), {pole, a, b});
      tris.entity.push_back(1);
    }
  }
  mesh.blocks = {tets, tris};
  mesh.checkConsistency();
  return mesh;
}

TEST(EdgeSplit, SplittingTheChordsOfABallKeepsVolumesAndLeavesNoChord) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  ASSERT_EQ(cad.numFaces(), 1);
  Mesh mesh = octahedronAroundItsAxis();
  const std::vector<CurvedFaceEdge> chords = allChords(mesh, cad);
  ASSERT_EQ(chords.size(), 1u);  // the axis
  const std::vector<double> before = cellVolumes(mesh);
  const double total = std::accumulate(before.begin(), before.end(), 0.0);
  const std::size_t triangles = countTriangles(mesh);

  EXPECT_EQ(applySplits(mesh, chords, cad), chords.size());
  const std::vector<double> after = cellVolumes(mesh);
  EXPECT_GT(after.size(), before.size());
  for (const double v : after) EXPECT_GT(v, 0.0);
  // Inside a convex ball every chord's midpoint is on the ball's side, so the new nodes are the
  // midpoints and each cell is halved exactly: the total changes only by rounding, a few
  // ulps of each cell's determinant (|v| <= 1, a handful of cells): 1e-14 relative.
  EXPECT_NEAR(std::accumulate(after.begin(), after.end(), 0.0), total, 1e-14 * total);
  EXPECT_EQ(after.size(), 8u);
  EXPECT_EQ(countTriangles(mesh), triangles);  // interior splits leave the boundary alone
  EXPECT_TRUE(allChords(mesh, cad).empty());
  mesh.checkConsistency();
}

TEST(TangentEars, TheOctahedronsAxisIsItsOnlyEarAndSplittingItLeavesNone) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  Mesh mesh = octahedronAroundItsAxis();
  // Each tetrahedron has two faces on the sphere, sharing its equator edge: the far edge of
  // all four is the axis (poles 0 and 1).
  const std::vector<CurvedFaceEdge> ears = tangentEarSplits(mesh, cad);
  ASSERT_EQ(ears.size(), 1u);
  EXPECT_EQ(ears[0].edge, meshEdge(0, 1));
  EXPECT_EQ(ears[0].entity, 1);
  EXPECT_FALSE(ears[0].boundary);
  EXPECT_EQ(applySplits(mesh, ears, cad), 1u);
  EXPECT_TRUE(tangentEarSplits(mesh, cad).empty());  // each half has one face on the sphere
  EXPECT_EQ(cellVolumes(mesh).size(), 8u);

  // On a plane two faces of a cell cannot share an edge without the cell being flat: a box's
  // cells have no ear, and a mesh with cells other than simplices gets none either.
  const CadModel box = test::toModel(test::box(1, 1, 1));
  LinearMeshOptions o;
  o.size = 0.5;
  const Mesh boxMesh = generateLinearMesh(box, o);
  EXPECT_TRUE(tangentEarSplits(boxMesh, box).empty());
}

TEST(TangentEars, AHexagonInADiskHasThreeEarsIn2D) {
  const gp_Circ circle(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0);
  const CadModel cad = test::toModel(
      BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle))).Face());
  ASSERT_EQ(cad.numEdges(), 1);
  // The hexagon inscribed in the unit circle, cut into three ears (two sides on the circle
  // each) around the triangle of every other vertex.
  Mesh mesh;
  mesh.dim = 2;
  mesh.planeNormal = {0.0, 0.0, 1.0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < 6; ++k) {
    const double a = k * M_PI / 3.0;
    const double x[3] = {std::cos(a), std::sin(a), 0.0};
    mesh.addNode(x, 1, 1, a, nan);
  }
  ElementBlock tris, lines;
  tris.type = CellType::Triangle;
  lines.type = CellType::Line;
  for (const std::int64_t k : {0, 2, 4}) {
    tris.nodes.insert(tris.nodes.end(), {k, k + 1, (k + 2) % 6});
    tris.entity.push_back(1);
  }
  tris.nodes.insert(tris.nodes.end(), {0, 2, 4});
  tris.entity.push_back(1);
  for (std::int64_t k = 0; k < 6; ++k) {
    lines.nodes.insert(lines.nodes.end(), {k, (k + 1) % 6});
    lines.entity.push_back(1);
  }
  mesh.blocks = {tris, lines};
  mesh.checkConsistency();
  const std::vector<CurvedFaceEdge> ears = tangentEarSplits(mesh, cad);
  std::set<MeshEdge> edges;
  for (const CurvedFaceEdge& e : ears) edges.insert(e.edge);
  EXPECT_EQ(edges, (std::set<MeshEdge>{meshEdge(0, 2), meshEdge(2, 4), meshEdge(0, 4)}));
  EXPECT_EQ(applySplits(mesh, ears, cad), 3u);
  EXPECT_TRUE(tangentEarSplits(mesh, cad).empty());
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Triangle) continue;
    EXPECT_EQ(b.count(), 10u);  // each split halves its ear and the middle triangle around it
    for (std::size_t e = 0; e < b.count(); ++e) {
      EXPECT_GT(simplexVolume(mesh, b.element(e)), 0.0);
    }
  }
}

TEST(EdgeSplit, MidpointHalvesEveryCellAroundTheEdge) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(0.4));
  const std::set<MeshEdge> boundary = boundaryEdges(mesh);
  // The first interior edge of the cells.
  MeshEdge edge{-1, -1};
  const ElementBlock& tets = mesh.blocks.front();
  for (std::size_t e = 0; e < tets.count() && edge[0] < 0; ++e)
    for (int i = 0; i < 4 && edge[0] < 0; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const std::int64_t a = tets.element(e)[i], b = tets.element(e)[j];
        const MeshEdge candidate = a < b ? MeshEdge{a, b} : MeshEdge{b, a};
        if (boundary.count(candidate) == 0) {
          edge = candidate;
          break;
        }
      }
  ASSERT_GE(edge[0], 0);
  const std::vector<double> before = cellVolumes(mesh);
  const std::size_t nodes = mesh.numNodes();
  const Eigen::Vector3d a(&mesh.xyz[3 * edge[0]]), b(&mesh.xyz[3 * edge[1]]);
  ASSERT_TRUE(splitInteriorEdge(mesh, edge, 0.5 * (a + b)));
  EXPECT_EQ(mesh.numNodes(), nodes + 1);
  EXPECT_EQ(mesh.nodeCadDim.back(), 3);
  const std::vector<double> after = cellVolumes(mesh);
  // Each cell around the edge kept its slot with half its volume; its other half was appended.
  // Halving is exact up to the determinant's rounding (a few ulps of |v|, v <= 1): 1e-15.
  std::size_t halved = 0;
  for (std::size_t k = 0; k < before.size(); ++k)
    if (std::abs(after[k] - before[k]) > 1e-15) {
      EXPECT_NEAR(after[k], 0.5 * before[k], 1e-15);
      ++halved;
    }
  EXPECT_EQ(after.size(), before.size() + halved);
  EXPECT_GE(halved, 3u);  // an interior edge has at least three cells around it
  // Splitting a boundary edge as if it were interior is refused; so is a point that would turn
  // a cell inside out (far beyond the edge), leaving the mesh unchanged.
  const MeshEdge onBoundary = *boundary.begin();
  EXPECT_THROW(splitInteriorEdge(mesh, onBoundary, Eigen::Vector3d::Zero()), ParameterError);
  // Beyond a on the line through the new edge (a, m): the half that keeps a turns over.
  const auto m = static_cast<std::int64_t>(mesh.numNodes() - 1);
  const Eigen::Vector3d mid(&mesh.xyz[3 * m]);
  EXPECT_FALSE(splitInteriorEdge(mesh, {edge[0], m}, a + 5.0 * (a - mid)));
  EXPECT_EQ(cellVolumes(mesh).size(), after.size());
  EXPECT_EQ(mesh.numNodes(), nodes + 1);
}

// The first edge of the first tetrahedron that is on no boundary triangle.
MeshEdge firstInteriorEdge(const Mesh& mesh) {
  const std::set<MeshEdge> boundary = boundaryEdges(mesh);
  const ElementBlock& tets = mesh.blocks.front();
  for (std::size_t e = 0; e < tets.count(); ++e)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const MeshEdge edge = meshEdge(tets.element(e)[i], tets.element(e)[j]);
        if (boundary.count(edge) == 0) return edge;
      }
  return {-1, -1};
}

// A cell whose four vertices all lie on the boundary has no node the optimiser can move off the
// CAD; with the optimiser to follow, the plan splits its longest interior edge (a new node
// inside the solid), where before it only asked for refinement (on a box's planar faces there is no
// curved-face edge to split). A cell with a vertex inside still gets a refinement sphere.
TEST(RepairPlan, ACellWithEveryVertexOnTheBoundaryGetsItsLongestInteriorEdgeSplit) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(0.5));
  const std::set<MeshEdge> boundary = boundaryEdges(mesh);
  std::vector<char> onBoundary(mesh.numNodes(), 0);
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Triangle)
      for (const std::int64_t n : b.nodes) onBoundary[static_cast<std::size_t>(n)] = 1;
  const ElementBlock& tets = mesh.blocks.front();
  ASSERT_EQ(tets.type, CellType::Tetrahedron);
  std::optional<std::size_t> allOn, inner;
  MeshEdge expected{-1, -1};
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const std::int64_t* v = tets.element(e);
    int on = 0;
    for (int i = 0; i < 4; ++i) on += onBoundary[static_cast<std::size_t>(v[i])];
    if (on < 4) {
      if (!inner) inner = e;
      continue;
    }
    double longest = 0.0;
    MeshEdge edge{-1, -1};
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        if (boundary.count(meshEdge(v[i], v[j])) > 0) continue;
        const double l = (nodePoint(mesh, v[i]) - nodePoint(mesh, v[j])).norm();
        if (l > longest) {
          longest = l;
          edge = meshEdge(v[i], v[j]);
        }
      }
    if (edge[0] >= 0 && !allOn) {
      allOn = e;
      expected = edge;
    }
  }
  ASSERT_TRUE(allOn.has_value());
  ASSERT_TRUE(inner.has_value());

  std::vector<Validity> validity(tets.count(), Validity::Valid);
  validity[*allOn] = Validity::Invalid;
  validity[*inner] = Validity::Invalid;
  // Without the optimiser after it, the midpoint would stay where it is: refinement instead.
  const RepairPlan still = planRepair(mesh, validity, cad, false);
  EXPECT_TRUE(still.splits.empty());
  EXPECT_EQ(still.refineCells, 2u);
  EXPECT_EQ(still.unsplit,
            (std::vector<std::size_t>{std::min(*allOn, *inner), std::max(*allOn, *inner)}));
  const RepairPlan plan = planRepair(mesh, validity, cad, true);
  ASSERT_EQ(plan.splits.size(), 1u);
  EXPECT_EQ(plan.splits[0].edge, expected);
  EXPECT_EQ(plan.splits[0].entity, 0);
  EXPECT_FALSE(plan.splits[0].boundary);
  EXPECT_EQ(plan.splitCells, 1u);
  EXPECT_EQ(plan.refineCells, 1u);                            // the cell with a vertex inside
  EXPECT_EQ(plan.unsplit, std::vector<std::size_t>{*inner});  // what a round may flip

  const std::size_t nodes = mesh.numNodes(), triangles = countTriangles(mesh);
  EXPECT_EQ(applySplits(mesh, plan.splits, cad), 1u);
  ASSERT_EQ(mesh.numNodes(), nodes + 1);
  EXPECT_EQ(mesh.nodeCadDim.back(), 3);  // the new node is inside the solid
  const Eigen::Vector3d mid = 0.5 * (nodePoint(mesh, expected[0]) + nodePoint(mesh, expected[1]));
  EXPECT_EQ(nodePoint(mesh, static_cast<std::int64_t>(nodes)), mid);
  EXPECT_EQ(countTriangles(mesh), triangles);
  for (const double v : cellVolumes(mesh)) EXPECT_GT(v, 0.0);
  mesh.checkConsistency();
}

// A repair round's split changes the cells around one edge; every other element must come back
// with its old curved nodes (here marked by a shift the new elevation cannot reproduce), and
// only the split cells are fresh.
// In 2D a triangle whose vertices all lie on the boundary, on two CAD curves meeting at its
// corner, gets its longest edge on a curve split, not the chord between the curves: its
// Jacobian at the corner is set by the curved edges there (gmsh-doc's fragment_numbering.step
// stayed invalid at two cusps with the chord, and was valid in two rounds with the curve
// split). The unit square cut along its diagonal; the triangle at corner 0 is flagged.
TEST(RepairPlan, In2DACornerTriangleGetsAnEdgeOnACurveSplitNotTheChord) {
  BRepBuilderAPI_MakePolygon square(gp_Pnt(0, 0, 0), gp_Pnt(1, 0, 0), gp_Pnt(1, 1, 0),
                                    gp_Pnt(0, 1, 0), Standard_True);
  const CadModel cad = test::toModel(BRepBuilderAPI_MakeFace(square.Wire()).Face());
  ASSERT_EQ(cad.numEdges(), 4);
  Mesh mesh;
  mesh.dim = 2;
  mesh.planeNormal = {0.0, 0.0, 1.0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (int k = 0; k < 4; ++k) mesh.addNode(corners[k], 0, k + 1, nan, nan);
  ElementBlock tris, lines;
  tris.type = CellType::Triangle;
  lines.type = CellType::Line;
  tris.nodes = {3, 0, 1, 1, 2, 3};
  tris.entity = {1, 1};
  for (std::int64_t k = 0; k < 4; ++k) {
    lines.nodes.insert(lines.nodes.end(), {k, (k + 1) % 4});
    lines.entity.push_back(static_cast<int>(k) + 1);
  }
  mesh.blocks = {tris, lines};
  mesh.checkConsistency();
  const RepairPlan plan = planRepair(mesh, {Validity::Invalid, Validity::Valid}, cad, true);
  ASSERT_EQ(plan.splits.size(), 1u);
  // Edges 3-0 (curve 4) and 0-1 (curve 1) are equally long; the first of the cell's is taken.
  EXPECT_EQ(plan.splits[0].edge, meshEdge(0, 3));
  EXPECT_EQ(plan.splits[0].entity, 4);
  EXPECT_TRUE(plan.splits[0].boundary);
  EXPECT_EQ(plan.splitCells, 1u);
}

TEST(CurvedReuse, UnchangedCellsKeepTheirCurvedNodesAndOnlySplitCellsAreFresh) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh oldLinear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.4));
  Mesh oldCurved = elevateOrder(oldLinear, 3, &cad);
  for (std::size_t i = 0; i < oldCurved.numNodes(); ++i)
    if (oldCurved.nodeCadDim[i] == 3) oldCurved.xyz[3 * i] += 1e-3 * static_cast<double>(i % 7 + 1);

  Mesh newLinear = oldLinear;
  const MeshEdge edge = firstInteriorEdge(newLinear);
  ASSERT_GE(edge[0], 0);
  const Eigen::Vector3d a = nodePoint(newLinear, edge[0]), b = nodePoint(newLinear, edge[1]);
  ASSERT_TRUE(splitInteriorEdge(newLinear, edge, 0.5 * (a + b)));
  const std::size_t added = newLinear.numElements() - oldLinear.numElements();
  ASSERT_GE(added, 3u);  // an interior edge has at least three cells around it
  Mesh newCurved = elevateOrder(newLinear, 3, &cad);
  const Mesh elevated = newCurved;

  const CurvedReuse reuse = reuseCurvedNodes(oldLinear, oldCurved, newLinear, newCurved);
  ASSERT_EQ(reuse.fresh.size(), newLinear.numElements());
  // Each cell around the edge kept its slot (changed) and its other half was appended.
  EXPECT_EQ(reuse.reused, oldLinear.numElements() - added);
  EXPECT_EQ(std::count(reuse.fresh.begin(), reuse.fresh.end(), 1),
            static_cast<std::ptrdiff_t>(2 * added));
  const ElementBlock& before = oldCurved.blocks.front();
  const ElementBlock& after = newCurved.blocks.front();
  std::set<std::int64_t> reusedNodes;
  for (std::size_t e = 0; e < after.count(); ++e) {
    if (reuse.fresh[e] != 0) continue;
    ASSERT_LT(e, before.count());  // unchanged cells keep their slots
    for (int k = 0; k < after.nodesPerElement(); ++k) {
      reusedNodes.insert(after.element(e)[k]);
      for (int c = 0; c < 3; ++c)  // copied, so equal bit for bit
        EXPECT_EQ(newCurved.xyz[3 * after.element(e)[k] + c],
                  oldCurved.xyz[3 * before.element(e)[k] + c]);
    }
  }
  // The nodes of fresh elements that no reused element shares keep the new elevation.
  for (std::size_t e = 0; e < after.count(); ++e)
    for (int k = 0; k < after.nodesPerElement() && reuse.fresh[e] != 0; ++k) {
      const std::int64_t n = after.element(e)[k];
      if (reusedNodes.count(n) == 0) {
        EXPECT_EQ(newCurved.xyz[3 * n], elevated.xyz[3 * n]);
      }
    }

  const Mesh otherOrder = elevateOrder(newLinear, 2, &cad);
  Mesh target = otherOrder;
  EXPECT_THROW(reuseCurvedNodes(oldLinear, oldCurved, newLinear, target), ParameterError);
  EXPECT_THROW(reuseCurvedNodes(newLinear, oldCurved, newLinear, newCurved), ParameterError);
}

// Where flips judge shapes: every linear node where the curved mesh's elements have their
// vertices (the optimiser moves interior vertices too), the other coordinates unchanged.
TEST(CurvedVertexPositions, AreTheCurvedElementsVertices) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh linear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.4));
  Mesh curved = elevateOrder(linear, 3, &cad);
  for (std::size_t i = 0; i < curved.numNodes(); ++i)
    if (curved.nodeCadDim[i] == 3) curved.xyz[3 * i + 1] += 1e-2 * static_cast<double>(i % 5 + 1);
  const std::vector<double> positions = curvedVertexPositions(linear, curved);
  ASSERT_EQ(positions.size(), linear.xyz.size());
  const ElementBlock& cells = linear.blocks.front();
  const ElementBlock& elements = curved.blocks.front();
  ASSERT_EQ(cells.type, CellType::Tetrahedron);
  std::size_t moved = 0;
  for (std::size_t e = 0; e < cells.count(); ++e)
    for (int k = 0; k < 4; ++k) {
      const std::int64_t n = cells.element(e)[k], m = elements.element(e)[k];
      for (int c = 0; c < 3; ++c) EXPECT_EQ(positions[3 * n + c], curved.xyz[3 * m + c]);
      moved += positions[3 * n + 1] != linear.xyz[3 * n + 1] ? 1 : 0;
    }
  EXPECT_GT(moved, 0u);  // the box at 0.4 has interior vertices
  const Mesh coarser = generateLinearMesh(cad, LinearMeshOptions::uniform(0.8));
  EXPECT_THROW(curvedVertexPositions(coarser, curved), ParameterError);
}

// The sphere in a box at size 1.2, order 4: curving and 20 optimiser sweeps leave invalid
// elements (tetrahedra outside the sphere with an edge or a face on it); repair rounds must end
// with every element proven valid, by local changes (a few more elements, not a finer mesh).
TEST(RepairRounds, SphereInBoxEndsProvenValid) {
  MeshingOptions options;
  options.imprint = false;       // (the rounds below were chosen on the two solids meshed apart,
  options.fidelityWeight = 0.0;  // without the fidelity term, which once the mesh is valid moves
                                 // the boundary of each round's region: fewer values carry over)
  options.order = 4;
  options.size = 1.2;
  options.optimiseIterations = 20;
  options.repairRounds = 0;
  const MeshResult without = runMeshPipeline(CadSource::file(kSphereBox), options);
  ASSERT_GT(without.quality.invalid + without.quality.undecided, 0u)
      << "the case no longer needs repair: choose a coarser one";
  EXPECT_TRUE(without.rounds.empty());
  // Where they are: each flagged element names the CAD faces its nodes lie on, and those nodes
  // do lie on them (to the projection's 1e-9 of the diagonal, far below the mesh's size); the
  // closing note gives the count, the faces and what was tried.
  const double diagonal = without.cad->boundingDiagonal();
  std::vector<const std::int64_t*> cells;  // the volume elements, in the verdicts' order
  for (const ElementBlock& b : without.mesh.blocks)
    if (cellDimension(b.type) == 3)
      for (std::size_t e = 0; e < b.count(); ++e) cells.push_back(b.element(e));
  const int nodesPerCell = cellNumNodes(CellType::Tetrahedron, without.mesh.order);
  const std::size_t flagged = without.quality.invalid + without.quality.undecided;
  for (const FlaggedElement& f : flaggedElements(without.mesh, without.quality, flagged)) {
    ASSERT_FALSE(f.cadFaces.empty() && f.cadCurves.empty()) << "element " << f.index;
    for (int face : f.cadFaces) {
      ASSERT_GE(face, 1);
      ASSERT_LE(face, without.cad->numFaces());
      std::size_t on = 0;
      for (int k = 0; k < nodesPerCell; ++k) {
        const auto n = static_cast<std::size_t>(cells[f.index][k]);
        if (without.mesh.nodeCadDim[n] != 2 || without.mesh.nodeCadIndex[n] != face) continue;
        const Eigen::Vector3d x(&without.mesh.xyz[3 * n]);
        EXPECT_LT(without.cad->projectOnSurface(face, x).distance, 1e-7 * diagonal);
        ++on;
      }
      EXPECT_GT(on, 0u);
    }
  }
  const std::string note =
      std::to_string(flagged) + (flagged == 1 ? " element" : " elements") + " not proven valid";
  const auto closing = std::find_if(without.notes.begin(), without.notes.end(),
                                    [&](auto& n) { return n.rfind(note, 0) == 0; });
  ASSERT_NE(closing, without.notes.end());
  EXPECT_NE(closing->find(" at Face"), std::string::npos) << *closing;
  EXPECT_NE(closing->find(
                "repair rounds (--repair-rounds, Python repair_rounds, FreeCAD RepairRounds) 0"),
            std::string::npos)
      << *closing;

  options.repairRounds = 3;
  const MeshResult result = runMeshPipeline(CadSource::file(kSphereBox), options);
  ASSERT_GE(result.rounds.size(), 1u);
  EXPECT_EQ(result.quality.invalid, 0u);
  EXPECT_EQ(result.quality.undecided, 0u);
  EXPECT_GT(result.quality.scaled.min, 0.0);
  EXPECT_EQ(result.rounds.front().invalid, without.quality.invalid);
  // A round measures only the elements it changed and takes the others' values from the round
  // before (KnownQuality): exactly what measuring the whole mesh gives.
  std::size_t reused = 0;
  for (const RepairRound& r : result.rounds) reused += r.reused;
  EXPECT_GT(reused, 0u);
  // (The kept mesh is a round's, whose check took most values from the round before.)
  EXPECT_GT(result.quality.known, result.mesh.numElements() / 2);
  const QualitySummary whole = evaluateQuality(result.mesh);
  EXPECT_EQ(whole.known, 0u);
  EXPECT_EQ(result.quality.scaledJacobian, whole.scaledJacobian);
  EXPECT_EQ(result.quality.scaledJacobianUpper, whole.scaledJacobianUpper);
  EXPECT_EQ(result.quality.distortion, whole.distortion);
  EXPECT_EQ(result.quality.validity, whole.validity);
  EXPECT_EQ(result.quality.scaled.min, whole.scaled.min);
  // Splits add a few elements; a refinement round regenerates the mesh with smaller sizes
  // around the offending elements (397 -> 644 tetrahedra measured): bounded, not a blow-up.
  EXPECT_LT(result.mesh.numElements(), without.mesh.numElements() * 2);
  bool timed = false;
  for (const auto& [stage, s] : result.timings.seconds) timed = timed || stage == "repair 1";
  EXPECT_TRUE(timed);
  const std::string json = meshReportJson(result, "sphere_box");
  const std::size_t rounds = json.find("\"rounds\": [");
  ASSERT_NE(rounds, std::string::npos);
  EXPECT_EQ(json.find("\"invalid\": " + std::to_string(without.quality.invalid), rounds),
            json.find("\"invalid\"", rounds));
  EXPECT_NE(json.find("\"action\": \"", rounds), std::string::npos);
}

// Order 8 on the same coarse sphere in a box: curved and optimised at order 4 first, raised,
// then optimised at order 8 (measured: 32 elements left invalid after 26 sweeps when order 8
// was optimised from the straight interior). The result must be proven valid; Gmsh's own
// verdict on the written file is checked by tests/python/test_repair_rounds.py.
TEST(RepairRounds, OrderEightStartsFromTheOptimisedOrderFourMeshAndEndsProvenValid) {
  MeshingOptions options;
  options.order = 8;
  options.size = 1.2;
  options.optimiseIterations = 30;
  options.threads = 2;
  const MeshResult result = runMeshPipeline(CadSource::file(kSphereBox), options);
  ASSERT_TRUE(result.lowOrderOptimiser.has_value());
  ASSERT_TRUE(result.optimiser.has_value());
  EXPECT_EQ(result.mesh.order, 8);
  // The order-8 optimiser starts from the raised order-4 mesh: far less tangled than the
  // straight interior (83 invalid elements, worst -5.8 measured) and its energy far lower.
  EXPECT_LT(result.optimiser->invalidBefore, 20u);
  EXPECT_EQ(result.quality.invalid, 0u);
  EXPECT_EQ(result.quality.undecided, 0u);
  EXPECT_GT(result.quality.scaled.min, 0.0);
  std::set<std::string> stages;
  for (const auto& [stage, s] : result.timings.seconds) stages.insert(stage);
  EXPECT_EQ(stages.count("optimise_low_order"), 1u);
  EXPECT_EQ(stages.count("raise_order"), 1u);
  EXPECT_NE(meshReportJson(result, "sphere_box").find("\"optimiser_order_4\": {"),
            std::string::npos);

  options.order = kContinuationOrder;  // no continuation at or below order 4
  options.optimiseIterations = 2;
  options.repairRounds = 0;
  EXPECT_FALSE(runMeshPipeline(CadSource::file(kSphereBox), options).lowOrderOptimiser);
}

// Spends the job's budget while the first pass curves: at the end of "high_order" it sleeps
// until `seconds` have passed since the job began (the budget's clock starts just before the
// "cad" stage), so every stage after it finds the budget spent, however fast the machine is.
class BudgetBurner : public PipelineObserver {
 public:
  explicit BudgetBurner(double seconds) : seconds_(seconds) {}
  void stageStarted(const std::string& stage) override {
    if (stage == "cad") start_ = std::chrono::steady_clock::now();
    started.push_back(stage);
  }
  void stageFinished(const std::string& stage, double /*seconds*/) override {
    if (stage == "high_order")
      std::this_thread::sleep_until(start_ + std::chrono::duration<double>(seconds_));
  }
  std::vector<std::string> started;

 private:
  double seconds_;
  std::chrono::steady_clock::time_point start_;
};

// The sphere in a box needs a repair round (above). With the job's budget spent once it is
// curved, the optimiser, the round and the geometry check are left out, the report says so
// ("stopped": "time budget", what was skipped, why the rounds ended), and the curved mesh is
// still the result, with its invalid elements counted: nothing is lost.
TEST(RepairRounds, ASpentJobBudgetEndsTheJobWithTheMeshSoFar) {
  MeshingOptions options;
  options.order = 4;
  options.size = 1.2;
  options.optimiseIterations = 20;
  options.repairRounds = 3;
  options.jobSeconds = 2.0;
  BudgetBurner burner(options.jobSeconds);
  const MeshResult result = runMeshPipeline(CadSource::file(kSphereBox), options, &burner);
  ASSERT_GT(result.mesh.numElements(), 0u);
  EXPECT_EQ(result.quality.validity.size(), result.mesh.numElements());
  // Curving alone leaves this case invalid; neither the optimiser nor a round ran.
  EXPECT_GT(result.quality.invalid + result.quality.undecided, 0u);
  EXPECT_FALSE(result.optimiser.has_value());
  EXPECT_TRUE(result.rounds.empty());
  EXPECT_FALSE(result.geometry.has_value());
  EXPECT_FALSE(result.boundaryFit.has_value());
  for (const char* stage : {"optimise", "repair 1", "boundary_fit", "geometry"}) {
    EXPECT_EQ(std::count(burner.started.begin(), burner.started.end(), stage), 0) << stage;
  }
  EXPECT_EQ(result.job.timeLimit, 2.0);
  EXPECT_TRUE(result.job.cut.empty());
  EXPECT_EQ(result.job.skipped,
            (std::vector<std::string>{"optimise", "repair 1", "boundary_fit", "geometry"}));
  // The burner held the job until its budget was spent; how long the stages after it took is
  // the machine's business, not a property of the code, and is not asserted.
  EXPECT_GE(result.job.seconds, 2.0);
  const auto noted = [&result](const std::string& text) {
    return std::any_of(result.notes.begin(), result.notes.end(),
                       [&text](const std::string& n) { return n.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(noted("repair rounds ended by the job time limit of 2 s (--job-time-limit"));
  EXPECT_TRUE(noted("before round 1"));
  EXPECT_TRUE(noted("the boundary's distance to the CAD was not measured"));
  const std::string json = meshReportJson(result, "sphere_box");
  const std::size_t job = json.find("\"job\": {");
  ASSERT_NE(job, std::string::npos);
  EXPECT_NE(json.find("\"stopped\": \"time budget\"", job), std::string::npos);
  const std::size_t skipped = json.find("\"skipped\": [", job);
  ASSERT_NE(skipped, std::string::npos) << json.substr(job, 300);
  EXPECT_LT(json.find("\"repair 1\"", skipped), json.find(']', skipped)) << json.substr(job, 300);
}

// Spent before there is a mesh: one error naming the stage not reached and where the time went.
TEST(RepairRounds, AJobBudgetSpentBeforeTheLinearMeshIsAnErrorNamingTheStage) {
  MeshingOptions options;
  options.order = 2;
  options.size = 1.2;
  options.jobSeconds = 1e-9;
  try {
    runMeshPipeline(CadSource::file(kSphereBox), options);
    FAIL() << "a spent budget gave a mesh";
  } catch (const BudgetExceeded& e) {
    const std::string message = e.what();
    for (const char* part :
         {"the job time limit of", "--job-time-limit", "Python job_seconds", "FreeCAD JobTimeLimit",
          "was spent before the linear stage (cad ", "no mesh was made"}) {
      EXPECT_NE(message.find(part), std::string::npos) << part << " in: " << message;
    }
  }
  options.size.reset();  // octree sizes: the sizing stage comes first
  try {
    runMeshPipeline(CadSource::file(kSphereBox), options);
    FAIL() << "a spent budget gave a mesh";
  } catch (const BudgetExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("before the sizing stage"), std::string::npos) << e.what();
  }
}

TEST(RepairRounds, JobBudgetIsValidated) {
  MeshingOptions options;
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN()}) {
    options.jobSeconds = bad;
    try {
      options.validate();
      FAIL() << bad << " accepted";
    } catch (const ParameterError& e) {
      EXPECT_NE(std::string(e.what()).find("job time limit must be a number >= 0"),
                std::string::npos)
          << e.what();
    }
  }
  options.jobSeconds = 0.0;
  EXPECT_NO_THROW(options.validate());
}

TEST(RepairRounds, RoundsAreValidated) {
  MeshingOptions options;
  options.repairRounds = -1;
  EXPECT_THROW(options.validate(), ParameterError);
  options.repairRounds = static_cast<int>(parameterDefinition("repair_rounds").max) + 1;
  EXPECT_THROW(options.validate(), ParameterError);
  options.repairRounds = 0;
  EXPECT_NO_THROW(options.validate());
}

}  // namespace
}  // namespace homesh

namespace homesh {
namespace {

// The prism over a region with a cusp (test::cuspPrism) at order 3, curved without the
// optimiser: at the cusp the arc's curved edge leaves the vertex along the segment, while the
// straight edges the bottom and top faces' triangles have inside the corner leave it at an
// angle, so the triangle between such an edge and the arc is inverted next to the vertex. The
// elements that have that corner are found at each cusp, and the closing note names the cusps.
TEST(CuspElements, TheElementsWithACornerAtACuspAreFoundAndNamed) {
  MeshingOptions options;
  options.order = 3;
  options.repairRounds = 0;  // what curving leaves is under test
  const MeshResult r =
      runMeshPipeline(CadSource::brepText(test::brepText(test::cuspPrism())), options);
  const std::vector<FaceCusp> cusps = findFaceCusps(*r.cad);
  ASSERT_EQ(cusps.size(), 2u);
  const CuspElements at = elementsAtCusps(r.mesh, r.quality, cusps);
  ASSERT_EQ(at.perCusp.size(), 2u);
  EXPECT_GE(at.perCusp[0], 1u);
  EXPECT_GE(at.perCusp[1], 1u);
  // Each is flagged and has a node at a cusp's vertex.
  const std::vector<FlaggedElement> flagged =
      flaggedElements(r.mesh, r.quality, r.quality.invalid + r.quality.undecided);
  for (const std::size_t e : at.elements) {
    const auto f = std::find_if(flagged.begin(), flagged.end(),
                                [e](const FlaggedElement& x) { return x.index == e; });
    ASSERT_NE(f, flagged.end()) << e;
    EXPECT_TRUE(std::any_of(cusps.begin(), cusps.end(), [&](const FaceCusp& c) {
      return std::binary_search(f->cadVertices.begin(), f->cadVertices.end(), c.vertex);
    })) << e;
  }
  // The closing note says how many and where.
  const auto note = std::find_if(r.notes.begin(), r.notes.end(), [](const std::string& n) {
    return n.find("not proven valid") != std::string::npos;
  });
  ASSERT_NE(note, r.notes.end());
  // (Order 3 without the optimiser leaves other elements invalid too, along the side faces'
  // tangent edge: "N of them have".)
  const std::size_t n = at.elements.size();
  ASSERT_LT(n, r.quality.invalid + r.quality.undecided);
  EXPECT_NE(
      note->find("; " + std::to_string(n) + " of them " + (n == 1 ? "has" : "have") +
                 " a corner at a cusp of the CAD, where two edges of a face leave a vertex "
                 "in the same direction (Face" +
                 std::to_string(cusps[0].face) + " at Vertex" + std::to_string(cusps[0].vertex) +
                 " between Edge" + std::to_string(cusps[0].edgeA) + " and Edge" +
                 std::to_string(cusps[0].edgeB)),
      std::string::npos)
      << *note;
  // Without a flagged element at a cusp the note says nothing of cusps: a box.
  const MeshResult box =
      runMeshPipeline(CadSource::brepText(test::brepText(test::box(1, 1, 1))), options);
  for (const std::string& line : box.notes) EXPECT_EQ(line.find("cusp"), std::string::npos) << line;
}

}  // namespace
}  // namespace homesh
