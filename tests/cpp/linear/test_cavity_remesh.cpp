// Local remeshing of cavities: on Gmsh's meshes of a box and of two boxes side by side, the cells
// around the requested ones are meshed again and nothing else changes: the same hull
// and boundary triangles, the same volume, every cell positive and meeting its neighbours face to
// face, the cells far from the request as they were, the other solid untouched.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "linear/cavity_remesh.hpp"
#include "linear/edge_split.hpp"
#include "linear/linear_mesher.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using Cell = std::array<std::int64_t, 4>;
using Face = std::array<std::int64_t, 3>;

const ElementBlock& tetBlock(const Mesh& mesh) {
  for (const ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Tetrahedron) return b;
  throw Error("no tetrahedra");
}

Cell sortedCell(const std::int64_t* v) {
  Cell c{v[0], v[1], v[2], v[3]};
  std::sort(c.begin(), c.end());
  return c;
}

// Per solid: every cell positive, every face on one or two of its cells; the faces on one cell.
std::map<int, std::set<Face>> checkConforming(const Mesh& mesh) {
  const ElementBlock& b = tetBlock(mesh);
  std::map<std::pair<int, Face>, int> faces;
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* v = b.element(e);
    EXPECT_GT(simplexVolume(mesh, v), 0.0) << "cell " << e;
    for (int skip = 0; skip < 4; ++skip) {
      Face f{};
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[static_cast<std::size_t>(k++)] = v[i];
      std::sort(f.begin(), f.end());
      ++faces[{b.entity[e], f}];
    }
  }
  std::map<int, std::set<Face>> hull;
  for (const auto& [key, count] : faces) {
    EXPECT_LE(count, 2);
    if (count == 1) hull[key.first].insert(key.second);
  }
  return hull;
}

std::map<int, double> volumes(const Mesh& mesh) {
  const ElementBlock& b = tetBlock(mesh);
  std::map<int, double> v;
  for (std::size_t e = 0; e < b.count(); ++e) v[b.entity[e]] += simplexVolume(mesh, b.element(e));
  return v;
}

std::vector<std::int64_t> lowerBlocks(const Mesh& mesh) {
  std::vector<std::int64_t> nodes;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) < 3) nodes.insert(nodes.end(), b.nodes.begin(), b.nodes.end());
  return nodes;
}

// What must hold after remeshing `original` into `mesh` around `cells`.
void checkRemesh(const Mesh& original, const std::vector<std::size_t>& cells, const Mesh& mesh,
                 const CavityOutcome& out) {
  EXPECT_EQ(checkConforming(mesh), checkConforming(original));
  // Volumes: sums over the same polyhedra, equal up to rounding of each cell's volume.
  const auto before = volumes(original), after = volumes(mesh);
  EXPECT_EQ(before.size(), after.size());
  for (const auto& [solid, v] : before) EXPECT_NEAR(after.at(solid), v, 1e-12 * (1.0 + v));
  EXPECT_EQ(lowerBlocks(mesh), lowerBlocks(original));  // boundary triangles untouched
  // The cavity holds every cell that shares a vertex with a requested one of its solid; the cells
  // it does not
  // hold stay as they were, in their order, at the front.
  const ElementBlock& a = tetBlock(original);
  const ElementBlock& b = tetBlock(mesh);
  std::set<std::pair<int, std::int64_t>> near;
  for (const std::size_t c : cells)
    for (int i = 0; i < 4; ++i) near.insert({a.entity[c], a.element(c)[i]});
  // (A fill may make a cell that was there before: compare the kept cells by order.)
  const std::size_t keptCount = a.count() - out.cellsRemoved;
  ASSERT_LE(keptCount, b.count());
  std::size_t next = 0;
  for (std::size_t e = 0; e < keptCount; ++e) {
    const Cell cell = sortedCell(b.element(e));
    while (next < a.count() && sortedCell(a.element(next)) != cell) ++next;
    ASSERT_LT(next, a.count()) << "kept cell " << e << " is not an original cell in order";
    const std::int64_t* v = a.element(next);
    EXPECT_FALSE(std::any_of(v, v + 4,
                             [&](std::int64_t n) {
                               return near.count({a.entity[next], n}) > 0;
                             }))
        << "cell " << next << " shares a vertex with a requested cell of its solid";
    ++next;
  }
  EXPECT_EQ(b.count(), a.count() - out.cellsRemoved + out.cellsAdded);
  // New nodes lie inside the solid of their cells, with no CAD parameters.
  for (std::size_t n = original.numNodes(); n < mesh.numNodes(); ++n) {
    EXPECT_EQ(mesh.nodeCadDim[n], 3);
    EXPECT_TRUE(std::isnan(mesh.nodeCadParam[2 * n]));
  }
}

// Remeshes around `cells` and checks what must hold; returns the outcome.
CavityOutcome remeshAndCheck(const Mesh& original, const std::vector<std::size_t>& cells,
                             Mesh& mesh) {
  mesh = original;
  const CavityOutcome out = remeshCavities(mesh, cells, LinearMeshOptions::uniform(0.1));
  checkRemesh(original, cells, mesh, out);
  return out;
}

TEST(CavityRemesh, ACavityInABoxIsMeshedAgainAndNothingElseChanges) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh original = generateLinearMesh(cad, LinearMeshOptions::uniform(0.25));
  const ElementBlock& cells = tetBlock(original);
  // The cell nearest the centre, and one with a vertex on the boundary.
  std::size_t centre = 0, boundary = 0;
  double best = 1e300;
  std::vector<char> onBoundary(original.numNodes(), 0);
  for (const std::int64_t n : lowerBlocks(original)) onBoundary[static_cast<std::size_t>(n)] = 1;
  for (std::size_t e = 0; e < cells.count(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) c += nodePoint(original, cells.element(e)[i]) / 4;
    const double d = (c - Eigen::Vector3d(0.5, 0.5, 0.5)).norm();
    if (d < best) {
      best = d;
      centre = e;
    }
    if (onBoundary[static_cast<std::size_t>(cells.element(e)[0])] != 0 && boundary == 0)
      boundary = e;
  }
  Mesh mesh;
  const CavityOutcome out = remeshAndCheck(original, {centre}, mesh);
  EXPECT_EQ(out.cavities, 1u);
  EXPECT_GT(out.cellsAdded, 0u);
  const CavityOutcome atWall = remeshAndCheck(original, {boundary}, mesh);
  EXPECT_EQ(atWall.cavities, 1u);
}

// Random requests of one to four cells: cavities that touch or overlap are merged or grown until
// their surfaces are closed manifolds; whatever Gmsh makes of them must keep every invariant.
TEST(CavityRemesh, RandomRequestsKeepTheMeshConforming) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh original = generateLinearMesh(cad, LinearMeshOptions::uniform(0.2));
  const std::size_t count = tetBlock(original).count();
  std::mt19937 random(7);
  std::size_t cavities = 0, requested = 0;
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<std::size_t> cells(static_cast<std::size_t>(1 + trial % 4));
    for (std::size_t& c : cells) c = random() % count;
    Mesh mesh;
    const CavityOutcome out = remeshAndCheck(original, cells, mesh);
    EXPECT_GE(out.cavities, 1u);
    EXPECT_LE(out.cavities, cells.size());
    cavities += out.cavities;
    requested += cells.size();
  }
  EXPECT_LE(cavities, requested);
}

// Two boxes sharing a face (a general fuse keeps both solids and the face once). A cavity around
// a cell of one solid at the shared face stays in that solid; the other's cells are as they were.
TEST(CavityRemesh, ACavityStaysInItsSolid) {
  const CadModel cad = test::toModel(test::twoBoxes());
  ASSERT_EQ(cad.numSolids(), 2);
  const Mesh original = generateLinearMesh(cad, LinearMeshOptions::uniform(0.3));
  const ElementBlock& cells = tetBlock(original);
  std::map<int, std::set<std::int64_t>> nodesOf;
  for (std::size_t e = 0; e < cells.count(); ++e)
    nodesOf[cells.entity[e]].insert(cells.element(e), cells.element(e) + 4);
  ASSERT_EQ(nodesOf.size(), 2u);
  // A cell of the first solid with a vertex shared with the other.
  const int solid = nodesOf.begin()->first, other = std::next(nodesOf.begin())->first;
  std::size_t pick = cells.count();
  for (std::size_t e = 0; e < cells.count() && pick == cells.count(); ++e)
    if (cells.entity[e] == solid)
      for (int i = 0; i < 4; ++i)
        if (nodesOf[other].count(cells.element(e)[i]) > 0) pick = e;
  ASSERT_LT(pick, cells.count());
  Mesh mesh;
  const CavityOutcome out = remeshAndCheck(original, {pick}, mesh);
  EXPECT_EQ(out.cavities, 1u);
  std::multiset<Cell> before, after;
  for (std::size_t e = 0; e < cells.count(); ++e)
    if (cells.entity[e] == other) before.insert(sortedCell(cells.element(e)));
  const ElementBlock& b = tetBlock(mesh);
  for (std::size_t e = 0; e < b.count(); ++e)
    if (b.entity[e] == other) after.insert(sortedCell(b.element(e)));
  EXPECT_EQ(after, before);
}

TEST(CavityRemesh, BadRequestsAreRefusedAndLeaveTheMeshAsItWas) {
  const CadModel cad = test::toModel(test::box(1, 1, 1));
  const Mesh original = generateLinearMesh(cad, LinearMeshOptions::uniform(0.5));
  const std::size_t count = tetBlock(original).count();
  const LinearMeshOptions options = LinearMeshOptions::uniform(0.1);
  Mesh mesh = original;
  EXPECT_THROW(remeshCavities(mesh, {count}, options), ParameterError);
  EXPECT_THROW(remeshCavities(mesh, {0, count + 5}, options), ParameterError);
  Mesh secondOrder = original;
  secondOrder.order = 2;
  EXPECT_THROW(remeshCavities(secondOrder, {0}, options), ParameterError);
  EXPECT_EQ(mesh.xyz, original.xyz);
  EXPECT_EQ(tetBlock(mesh).nodes, tetBlock(original).nodes);
  EXPECT_EQ(remeshCavities(mesh, {}, options).cavities, 0u);
}

}  // namespace
}  // namespace homesh
