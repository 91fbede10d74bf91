// Flips that take flat tetrahedra away: the shape measure, edge removal on rings of 3 to 7
// cells, face removal, and what must stop a flip (no gain, the boundary, a chord of one boundary
// face, cells of two solids). Every flipped mesh is checked to fill the same volume with cells
// of positive volume that meet face to face.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "core/error.hpp"
#include "linear/edge_split.hpp"
#include "linear/linear_mesher.hpp"
#include "linear/tet_flips.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

Mesh pointsOnly(const std::vector<Eigen::Vector3d>& points) {
  Mesh mesh;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Vector3d& p : points) {
    const double x[3] = {p.x(), p.y(), p.z()};
    mesh.addNode(x, 3, 1, nan, nan);
  }
  return mesh;
}

void addTets(Mesh& mesh, const std::vector<std::array<std::int64_t, 4>>& tets,
             std::int32_t entity = 1) {
  ElementBlock block;
  for (auto t : tets) {
    if (simplexVolume(mesh, t.data()) < 0.0) std::swap(t[2], t[3]);
    block.nodes.insert(block.nodes.end(), t.begin(), t.end());
    block.entity.push_back(entity);
  }
  mesh.blocks.insert(mesh.blocks.begin(), block);
}

void addTriangles(Mesh& mesh, const std::vector<std::array<std::int64_t, 3>>& tris,
                  const std::vector<std::int32_t>& faces = {}) {
  ElementBlock block;
  block.type = CellType::Triangle;
  for (std::size_t k = 0; k < tris.size(); ++k) {
    block.nodes.insert(block.nodes.end(), tris[k].begin(), tris[k].end());
    block.entity.push_back(faces.empty() ? 1 : faces[k]);
  }
  mesh.blocks.push_back(block);
}

const ElementBlock& tetBlock(const Mesh& mesh) {
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Tetrahedron) return b;
  throw Error("no tetrahedra");
}

double totalVolume(const Mesh& mesh) {
  const ElementBlock& b = tetBlock(mesh);
  double v = 0.0;
  for (std::size_t e = 0; e < b.count(); ++e) v += simplexVolume(mesh, b.element(e));
  return v;
}

double worstShape(const Mesh& mesh) {
  const ElementBlock& b = tetBlock(mesh);
  double worst = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* v = b.element(e);
    worst = std::min(worst, tetShape(nodePoint(mesh, v[0]), nodePoint(mesh, v[1]),
                                     nodePoint(mesh, v[2]), nodePoint(mesh, v[3])));
  }
  return worst;
}

// Every cell positive, and every face on one or two cells: a cell meets its neighbours face to
// face. Returns the faces that lie on one cell (the hull), sorted.
std::vector<std::array<std::int64_t, 3>> checkConforming(const Mesh& mesh) {
  const ElementBlock& b = tetBlock(mesh);
  std::map<std::array<std::int64_t, 3>, int> faces;
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* v = b.element(e);
    EXPECT_GT(simplexVolume(mesh, v), 0.0) << "cell " << e;
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::int64_t, 3> f{};
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[static_cast<std::size_t>(k++)] = v[i];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  std::vector<std::array<std::int64_t, 3>> hull;
  for (const auto& [f, count] : faces) {
    EXPECT_LE(count, 2);
    if (count == 1) hull.push_back(f);
  }
  return hull;
}

// n points on the unit circle in z = 0 and the poles (0, 0, +-h), the n cells around the axis.
Mesh bipyramid(int n, double h) {
  std::vector<Eigen::Vector3d> points{{0, 0, h}, {0, 0, -h}};
  for (int i = 0; i < n; ++i)
    points.emplace_back(std::cos(2 * kPi * i / n), std::sin(2 * kPi * i / n), 0.0);
  Mesh mesh = pointsOnly(points);
  std::vector<std::array<std::int64_t, 4>> tets(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) tets[static_cast<std::size_t>(i)] = {0, 1, 2 + i, 2 + (i + 1) % n};
  addTets(mesh, tets);
  return mesh;
}

std::array<std::int64_t, 4> sortedCell(const std::int64_t* v) {
  std::array<std::int64_t, 4> cell{v[0], v[1], v[2], v[3]};
  std::sort(cell.begin(), cell.end());
  return cell;
}

bool hasEdge(const Mesh& mesh, std::int64_t a, std::int64_t b) {
  const ElementBlock& t = tetBlock(mesh);
  for (std::size_t e = 0; e < t.count(); ++e) {
    const std::int64_t* v = t.element(e);
    if (std::count(v, v + 4, a) > 0 && std::count(v, v + 4, b) > 0) return true;
  }
  return false;
}

TEST(TetShape, IsOneForTheRegularTetrahedronZeroWhenFlatAndNegativeWhenInverted) {
  const Eigen::Vector3d a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  const double regular = tetShape(a, b, c, d);
  EXPECT_NEAR(std::abs(regular), 1.0, 1e-14);
  EXPECT_NEAR(tetShape(a, b, d, c), -regular, 1e-14);
  EXPECT_NEAR(tetShape(7.5 * a, 7.5 * b, 7.5 * c, 7.5 * d), regular, 1e-13);  // scale-free
  const Eigen::Vector3d flat(0.2, 0.3, 0.0);
  EXPECT_EQ(
      tetShape(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), flat),
      0.0);
}

// A tall axis: the needles around it give way to the ring's triangles joined to the poles, for
// every ring size the flips handle.
TEST(TetFlips, EdgeRemovalReplacesTheCellsAroundALongAxis) {
  for (int n = 3; n <= 7; ++n) {
    SCOPED_TRACE("ring of " + std::to_string(n));
    Mesh mesh = bipyramid(n, 3.0);
    const double volume = totalVolume(mesh), before = worstShape(mesh);
    const auto hull = checkConforming(mesh);
    const FlipOutcome out = flipAwayCells(mesh, {0});
    EXPECT_EQ(out.flips, 1u);
    EXPECT_EQ(out.cellsFlipped, 1u);
    EXPECT_EQ(mesh.numElements(), static_cast<std::size_t>(2 * (n - 2)));
    EXPECT_FALSE(hasEdge(mesh, 0, 1));
    EXPECT_GT(worstShape(mesh), before + kFlipShapeGain);
    // Sum of positive volumes equal to the hull's: rounding of a few determinants of unit size.
    EXPECT_NEAR(totalVolume(mesh), volume, 1e-13 * n);
    EXPECT_EQ(checkConforming(mesh), hull);  // the same hull: the outside is untouched
    mesh.checkConsistency();
  }
}

// One flip can take several of the cells asked for away: each is counted once, and those it
// took are not tried again.
TEST(TetFlips, OneFlipTakesEveryCellAroundTheAxis) {
  Mesh mesh = bipyramid(5, 3.0);
  const FlipOutcome out = flipAwayCells(mesh, {0, 1, 2, 3, 4});
  EXPECT_EQ(out.flips, 1u);
  EXPECT_EQ(out.cellsFlipped, 5u);
  EXPECT_EQ(mesh.numElements(), 6u);
}

// Poles near the ring: the cells around the axis are the best there is; nothing changes.
TEST(TetFlips, NoFlipWithoutAGain) {
  for (int n = 3; n <= 7; ++n) {
    Mesh mesh = bipyramid(n, 0.5);
    const std::vector<std::int64_t> nodes = tetBlock(mesh).nodes;
    std::vector<std::size_t> all(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = static_cast<std::size_t>(i);
    EXPECT_EQ(flipAwayCells(mesh, all).flips, 0u) << n;
    EXPECT_EQ(tetBlock(mesh).nodes, nodes) << n;
  }
}

// Two flat cells on one face: the 2-3 flip joins their far vertices.
Mesh twoFlatCells() {
  Mesh mesh = pointsOnly({{0, 0, 0.1},
                          {0, 0, -0.1},
                          {1, 0, 0},
                          {std::cos(2 * kPi / 3), std::sin(2 * kPi / 3), 0},
                          {std::cos(4 * kPi / 3), std::sin(4 * kPi / 3), 0}});
  addTets(mesh, {{0, 2, 3, 4}, {1, 2, 3, 4}});
  return mesh;
}

TEST(TetFlips, FaceRemovalJoinsTheFarVerticesOfTwoFlatCells) {
  Mesh mesh = twoFlatCells();
  const double volume = totalVolume(mesh), before = worstShape(mesh);
  const auto hull = checkConforming(mesh);
  const FlipOutcome out = flipAwayCells(mesh, {1});
  EXPECT_EQ(out.flips, 1u);
  EXPECT_EQ(out.cellsFlipped, 1u);
  EXPECT_EQ(mesh.numElements(), 3u);
  EXPECT_TRUE(hasEdge(mesh, 0, 1));
  EXPECT_GT(worstShape(mesh), before + kFlipShapeGain);
  EXPECT_NEAR(totalVolume(mesh), volume, 1e-15);
  EXPECT_EQ(checkConforming(mesh), hull);
}

TEST(TetFlips, TheBoundaryAChordOfOneFaceAndTwoSolidsStopAFlip) {
  {  // the shared face is a boundary triangle (an interface)
    Mesh mesh = twoFlatCells();
    addTriangles(mesh, {{2, 3, 4}});
    EXPECT_EQ(flipAwayCells(mesh, {0, 1}).flips, 0u);
  }
  {  // the far vertices both on one boundary face: their new edge would be a chord of it
    Mesh mesh = twoFlatCells();
    addTriangles(mesh, {{0, 2, 3}, {1, 2, 3}});
    EXPECT_EQ(flipAwayCells(mesh, {0, 1}).flips, 0u);
  }
  {  // on two different faces (across a thin wall): allowed
    Mesh mesh = twoFlatCells();
    addTriangles(mesh, {{0, 2, 3}, {1, 2, 3}}, {1, 2});
    EXPECT_EQ(flipAwayCells(mesh, {0, 1}).flips, 1u);
  }
  {  // only one of them on the boundary: allowed
    Mesh mesh = twoFlatCells();
    addTriangles(mesh, {{0, 2, 3}});
    EXPECT_EQ(flipAwayCells(mesh, {0, 1}).flips, 1u);
  }
  {  // an axis on the boundary is not removed
    Mesh mesh = bipyramid(4, 3.0);
    addTriangles(mesh, {{0, 1, 2}});
    EXPECT_EQ(flipAwayCells(mesh, {0}).flips, 0u);
  }
  {  // the three vertices of a 3-2 flip's new face on one CAD face: it would be a chord face
    Mesh mesh = bipyramid(3, 3.0);
    addTriangles(mesh, {{0, 2, 3}, {0, 3, 4}});
    EXPECT_EQ(flipAwayCells(mesh, {0}).flips, 0u);
  }
  {  // ... on two faces, none holding all three: allowed
    Mesh mesh = bipyramid(3, 3.0);
    addTriangles(mesh, {{0, 2, 3}, {0, 3, 4}}, {1, 2});
    EXPECT_EQ(flipAwayCells(mesh, {0}).flips, 1u);
  }
  {  // a ring of cells of two solids around the axis
    Mesh mesh = bipyramid(4, 3.0);
    mesh.blocks[0].entity[0] = 2;
    EXPECT_EQ(flipAwayCells(mesh, {0}).flips, 0u);
  }
  {  // cells of two solids on one face
    Mesh mesh = twoFlatCells();
    mesh.blocks[0].entity[1] = 2;
    EXPECT_EQ(flipAwayCells(mesh, {0, 1}).flips, 0u);
  }
}

// The shapes are judged where `positions` puts the nodes: the same cells, flat there, flip.
TEST(TetFlips, ShapesAreJudgedAtTheGivenPositions) {
  Mesh mesh = bipyramid(5, 0.5);  // no gain at its own coordinates
  std::vector<double> tall = mesh.xyz;
  tall[2] = 3.0;
  tall[5] = -3.0;
  const FlipOutcome out = flipAwayCells(mesh, {2}, tall);
  EXPECT_EQ(out.flips, 1u);
  EXPECT_FALSE(hasEdge(mesh, 0, 1));
  checkConforming(mesh);
  EXPECT_THROW(flipAwayCells(mesh, {0}, std::vector<double>(3)), ParameterError);
  EXPECT_THROW(flipAwayCells(mesh, {99}), ParameterError);
}

// On Gmsh's mesh of a box: an interior cell made flat at the judging positions (one vertex moved
// almost onto its opposite face, as an optimiser that could not inflate it leaves it) is flipped
// away; the mesh stays conforming with the same boundary, its cells positive at their own
// coordinates, and the new cells better than the flat one.
TEST(TetFlips, FlatInteriorCellsOfAGmshMeshAreFlippedAway) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh original = generateLinearMesh(cad, LinearMeshOptions::uniform(0.15));
  std::vector<char> onBoundary(original.numNodes(), 0);
  for (const ElementBlock& b : original.blocks)
    if (b.type == CellType::Triangle)
      for (const std::int64_t n : b.nodes) onBoundary[static_cast<std::size_t>(n)] = 1;
  const ElementBlock& cells = tetBlock(original);
  const auto hull = checkConforming(original);
  const double volume = totalVolume(original);
  std::set<std::array<std::int64_t, 4>> originalCells;
  for (std::size_t e = 0; e < cells.count(); ++e)
    originalCells.insert(sortedCell(cells.element(e)));
  std::size_t tried = 0, flipped = 0;
  for (std::size_t c = 0; c < cells.count() && tried < 20; ++c) {
    const std::int64_t* v = cells.element(c);
    if (std::any_of(v, v + 4,
                    [&](std::int64_t n) { return onBoundary[static_cast<std::size_t>(n)]; }))
      continue;
    ++tried;
    const Eigen::Vector3d p1 = nodePoint(original, v[1]), p2 = nodePoint(original, v[2]),
                          p3 = nodePoint(original, v[3]);
    const Eigen::Vector3d normal = (p2 - p1).cross(p3 - p1).normalized();
    const Eigen::Vector3d p0 = nodePoint(original, v[0]);
    const double height = (p0 - p1).dot(normal);
    const Eigen::Vector3d flat = p0 - 0.97 * height * normal;  // 3 % of its height left
    std::vector<double> positions = original.xyz;
    for (int k = 0; k < 3; ++k) positions[3 * static_cast<std::size_t>(v[0]) + k] = flat[k];
    const double before = tetShape(flat, p1, p2, p3);
    ASSERT_GT(before, 0.0);
    const auto at = [&positions](std::int64_t n) {
      const std::size_t i = 3 * static_cast<std::size_t>(n);
      return Eigen::Vector3d(positions[i], positions[i + 1], positions[i + 2]);
    };
    Mesh mesh = original;
    const FlipOutcome out = flipAwayCells(mesh, {c}, positions);
    if (out.flips == 0) continue;
    ++flipped;
    EXPECT_EQ(out.cellsFlipped, 1u);
    EXPECT_EQ(checkConforming(mesh), hull);
    EXPECT_NEAR(totalVolume(mesh), volume, 1e-12);
    // The flat cell is gone, and every cell the flip made beats it by the gain.
    const ElementBlock& after = tetBlock(mesh);
    std::size_t made = 0;
    for (std::size_t e = 0; e < after.count(); ++e) {
      const std::array<std::int64_t, 4> cell = sortedCell(after.element(e));
      EXPECT_NE(cell, sortedCell(v));
      if (originalCells.count(cell) > 0) continue;
      ++made;
      const std::int64_t* w = after.element(e);
      EXPECT_GT(tetShape(at(w[0]), at(w[1]), at(w[2]), at(w[3])), before + kFlipShapeGain);
    }
    EXPECT_GE(made, 2u);
    mesh.checkConsistency();
  }
  EXPECT_EQ(tried, 20u);
  EXPECT_GE(flipped, 15u);  // most such cells have a flip that takes them away
}

}  // namespace
}  // namespace homesh
