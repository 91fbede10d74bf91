// Boundary layers: parameters, the macro layer's growth and shrinking, the split into thin
// layers, and NekMesh's cylinder case end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/expression.hpp"
#include "curving/layer_split.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "io/mesh_readers.hpp"
#include "io/mesh_writers.hpp"
#include "linear/boundary_layer.hpp"
#include "optimise/optimiser.hpp"
#include "peer_data.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// The .mcf case at `path` (boundary layer included) at `order` with the optimiser (100 sweeps,
// 2 threads): the acceptance's path.
MeshResult meshCase(const std::string& path, int order) {
  CaseSetup setup = setupCase(path);
  setup.options.order = order;
  setup.options.optimiseIterations = 100;
  setup.options.threads = 2;
  return runMeshPipeline(setup.source, setup.options);
}

// NekMesh's meshgen case `name`.mcf (peer files: call HOMESH_REQUIRE_PEER_FILES first).
MeshResult meshPeerCase(const std::string& name, int order) {
  return meshCase(test::peerFile("meshgen/" + name + ".mcf"), order);
}

TEST(Expression, EvaluatesNekMeshThicknessesAndNamesWhatIsWrong) {
  const Expression t = Expression::parse("0.01+0.05*x", "BndLayerThickness");
  EXPECT_EQ(t(2.0, 7.0, 9.0), 0.01 + 0.05 * 2.0);  // the same operations: exact
  EXPECT_FALSE(t.isConstant());
  EXPECT_TRUE(Expression::parse(" 4e-2 ", "t").isConstant());
  EXPECT_EQ(Expression::parse("2^3^2", "t")(0, 0, 0), 512.0);  // right-associative
  EXPECT_EQ(Expression::parse("-2^2", "t")(0, 0, 0), -4.0);    // minus binds looser
  EXPECT_EQ(Expression::parse("max(x, y) - min(1, z) / (2)", "t")(3, 5, 4), 5.0 - 0.5);
  EXPECT_EQ(Expression::parse("sqrt(abs(-z))", "t")(0, 0, 16), 4.0);
  for (const char* bad : {"0.01+", "x*q", "sin x", "(x", "max(1)", "1 2", ""}) {
    try {
      Expression::parse(bad, "BndLayerThickness");
      ADD_FAILURE() << bad;
    } catch (const ParameterError& e) {
      EXPECT_NE(std::string(e.what()).find("BndLayerThickness"), std::string::npos) << e.what();
    }
  }
}

TEST(BoundaryLayerParameters, FaceListsSplitCoordinatesAndRanges) {
  EXPECT_EQ(parseIndexList("1,8", "f"), (std::vector<int>{1, 8}));
  EXPECT_EQ(parseIndexList("11-12", "f"), (std::vector<int>{11, 12}));
  EXPECT_EQ(parseIndexList(" 5, 1-3 ,2", "f"), (std::vector<int>{1, 2, 3, 5}));
  for (const char* bad : {"", "a", "0", "3-1", "1,,2", "-2"})
    EXPECT_THROW(parseIndexList(bad, "f"), ParameterError) << bad;

  BoundaryLayerParameters p;
  p.faces = {1};
  p.thickness = "0.04";
  p.layers = 6;
  p.progression = 1.5;
  EXPECT_NO_THROW(p.validate());
  const std::vector<double> z = p.splitCoordinates();
  ASSERT_EQ(z.size(), 7U);
  EXPECT_EQ(z.front(), 0.0);
  EXPECT_EQ(z.back(), 1.0);
  // z_1 = (1 - r) / (1 - r^n); each step r times the one before (rounding: a few ulps).
  EXPECT_NEAR(z[1], (1 - 1.5) / (1 - std::pow(1.5, 6)), 1e-15);
  for (std::size_t k = 1; k + 1 < z.size(); ++k)
    EXPECT_NEAR((z[k + 1] - z[k]) / (z[k] - z[k - 1]), 1.5, 1e-12);
  for (auto change : std::vector<void (*)(BoundaryLayerParameters&)>{
           [](BoundaryLayerParameters& q) { q.faces.clear(); },
           [](BoundaryLayerParameters& q) { q.thickness = "0.04*"; },
           [](BoundaryLayerParameters& q) { q.layers = 0; },
           [](BoundaryLayerParameters& q) { q.progression = -1; }}) {
    BoundaryLayerParameters q = p;
    change(q);
    EXPECT_THROW(q.validate(), ParameterError);
  }
}

Eigen::Vector3d point(const Mesh& m, std::int64_t i) {
  return {m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]};
}

// Checks shared by the peer cases and their siblings on shapes the tests make, on a MeshResult.

// The wall cells (3D: triangles, 2D: lines) on the CAD faces (curves) `walls`, by their sorted
// vertices.
template <std::size_t N>
std::set<std::array<std::int64_t, N>> wallCells(const Mesh& m, const std::set<int>& walls) {
  const CellType type = N == 3 ? CellType::Triangle : CellType::Line;
  std::set<std::array<std::int64_t, N>> out;
  for (const ElementBlock& b : m.blocks)
    if (b.type == type)
      for (std::size_t e = 0; e < b.count(); ++e)
        if (walls.count(b.entity[e]) != 0) {
          std::array<std::int64_t, N> key;
          std::copy(b.element(e), b.element(e) + N, key.begin());
          std::sort(key.begin(), key.end());
          out.insert(key);
        }
  return out;
}

// 3D: certified valid, nothing shrunk, and `layers` prisms in the column on every wall triangle
// of `walls` (prisms stacked bottom (0, 1, 2) to top (3, 4, 5)), every prism in one column.
void expectValidWithLayersInEveryWallColumn(const MeshResult& r, const std::set<int>& walls,
                                            int layers) {
  ASSERT_TRUE(r.boundaryLayer.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk.empty());
  const Mesh& m = r.mesh;
  std::map<std::array<std::int64_t, 3>, const std::int64_t*> byBottom;
  std::size_t prisms = 0;
  for (const ElementBlock& b : m.blocks)
    if (b.type == CellType::Prism)
      for (std::size_t e = 0; e < b.count(); ++e, ++prisms) {
        std::array<std::int64_t, 3> key{b.element(e)[0], b.element(e)[1], b.element(e)[2]};
        std::sort(key.begin(), key.end());
        EXPECT_TRUE(byBottom.emplace(key, b.element(e)).second);
      }
  EXPECT_EQ(prisms, static_cast<std::size_t>(layers) * r.boundaryLayer->cells);
  const auto bottoms = wallCells<3>(m, walls);
  for (std::array<std::int64_t, 3> key : bottoms) {
    int found = 0;
    for (;;) {
      std::sort(key.begin(), key.end());
      const auto it = byBottom.find(key);
      if (it == byBottom.end()) break;
      ++found;
      key = {it->second[3], it->second[4], it->second[5]};
    }
    EXPECT_EQ(found, layers);
  }
  EXPECT_EQ(bottoms.size(), r.boundaryLayer->cells);
}

// 3D: the first layer's height along the wall's normal at the quadrature points (degree 2P) of
// the wall triangles on `walls`: the distance from the wall point to where its normal line meets
// the first prism's top, found by Newton on (a, b, t) together (the report projects onto the
// tangent plane instead). `visit(wall point, height)` for each point.
void forEachFirstLayerHeight(const MeshResult& r, const std::set<int>& walls,
                             const std::function<void(const Eigen::Vector3d&, double)>& visit) {
  const Mesh& m = r.mesh;
  const ReferenceElement& ref = ReferenceElement::get(CellType::Prism, m.order);
  const QuadratureRule rule = quadratureRule(CellType::Triangle, 2 * m.order);
  const auto bottoms = wallCells<3>(m, walls);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (const ElementBlock& b : m.blocks) {
    if (b.type != CellType::Prism) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      std::array<std::int64_t, 3> key{v[0], v[1], v[2]};
      std::sort(key.begin(), key.end());
      if (bottoms.count(key) == 0) continue;
      for (std::size_t q = 0; q < rule.weights.size(); ++q) {
        Eigen::Vector3d bottom = Eigen::Vector3d::Zero(), top = Eigen::Vector3d::Zero();
        Eigen::Vector3d dxi = Eigen::Vector3d::Zero(), deta = Eigen::Vector3d::Zero();
        for (const double zeta : {0.0, 1.0}) {
          const double xi[3] = {rule.points[2 * q], rule.points[2 * q + 1], zeta};
          ref.evaluate(xi, values, gradients);
          for (int i = 0; i < ref.numNodes(); ++i) {
            const Eigen::Vector3d x = point(m, v[i]);
            (zeta == 0.0 ? bottom : top) += values(i) * x;
            if (zeta == 0.0) {
              dxi += gradients(i, 0) * x;
              deta += gradients(i, 1) * x;
            }
          }
        }
        Eigen::Vector3d normal = dxi.cross(deta).normalized();
        if ((top - bottom).dot(normal) < 0.0) normal = -normal;
        // Where the normal line meets the top: top(a, b) = bottom + t normal.
        Eigen::Vector3d abt(rule.points[2 * q], rule.points[2 * q + 1], 0.0);
        for (int it = 0; it < 50; ++it) {
          const double xi[3] = {abt[0], abt[1], 1.0};
          ref.evaluate(xi, values, gradients);
          Eigen::Matrix3d jac = Eigen::Matrix3d::Zero();
          Eigen::Vector3d x = Eigen::Vector3d::Zero();
          for (int i = 0; i < ref.numNodes(); ++i) {
            x += values(i) * point(m, v[i]);
            jac.col(0) += gradients(i, 0) * point(m, v[i]);
            jac.col(1) += gradients(i, 1) * point(m, v[i]);
          }
          jac.col(2) = -normal;
          abt -= jac.fullPivLu().solve(x - bottom - abt[2] * normal);
        }
        ASSERT_GE(abt[0], -1e-9);
        ASSERT_GE(abt[1], -1e-9);
        ASSERT_LE(abt[0] + abt[1], 1 + 1e-9);
        visit(bottom, abt[2]);
      }
    }
  }
}

// 3D: the split's new nodes were put on the CAD and the report says so (`input` names the case
// in the JSON report, `layers` the layers asked for). The split's side nodes lie on the curved
// macro quadrilaterals (on the planar side faces), but the first level's shift (onto the wall
// normal, layer_split.hpp) follows the curved wall's interpolated normal, which leans off the
// side plane by the wall's interpolation error; `maxProjection` bounds that move, relative to
// the layer's height. Then every node on a CAD face lies on it: to the precision of the
// projections that put it there (found to 1e-9 of the bounding diagonal, CadModel).
void expectSplitNodesOnTheCad(const MeshResult& r, const std::string& input, int layers,
                              double maxProjection) {
  ASSERT_TRUE(r.layerSplit.has_value());
  ASSERT_TRUE(r.cad);
  EXPECT_GT(r.layerSplit->projected, 0U);
  EXPECT_LT(r.layerSplit->maxProjection, maxProjection);
  const Mesh& m = r.mesh;
  double worst = 0.0;
  for (std::size_t i = 0; i < m.numNodes(); ++i)
    if (m.nodeCadDim[i] == 2) {
      const Eigen::Vector3d x = point(m, static_cast<std::int64_t>(i));
      const std::array<double, 2> uv{m.nodeCadParam[2 * i], m.nodeCadParam[2 * i + 1]};
      worst = std::max(worst, r.cad->projectOnSurface(m.nodeCadIndex[i], x, uv).distance);
    }
  EXPECT_LE(worst, 1e-8 * r.cad->boundingDiagonal()) << "a node off its CAD face";
  const std::string json = meshReportJson(r, input);
  const std::string count = "\"layers\": " + std::to_string(layers);
  for (const char* key :
       {"\"boundary_layer\"", "\"first_height\"", "\"shrunk\": []", "\"prism\": "})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  EXPECT_NE(json.find(count), std::string::npos) << count;
}

// The mesh written as Nektar++ XML and as Gmsh .msh, read back: the same 3D elements by type, the
// same order, still certified valid.
void expectNektarAndGmshFilesReadBack(const MeshResult& r, const std::string& stem) {
  const auto dir = test::tempDir();
  for (const std::string& name : {stem + ".xml", stem + ".msh"}) {
    const std::string path = (dir / name).string();
    writeMeshFiles(r, {path});
    const Mesh back = readMesh(path);
    std::map<CellType, std::size_t> a, b;
    for (const ElementBlock& blk : r.mesh.blocks)
      if (cellDimension(blk.type) == 3) a[blk.type] += blk.count();
    for (const ElementBlock& blk : back.blocks)
      if (cellDimension(blk.type) == 3) b[blk.type] += blk.count();
    EXPECT_EQ(a, b) << name;
    EXPECT_GT(b[CellType::Prism], 0U) << name;
    EXPECT_EQ(back.order, r.mesh.order);
    const QualitySummary q = evaluateQuality(back);
    EXPECT_EQ(q.invalid + q.undecided, 0U) << name;
  }
}

// The Nektar++ XML of a split 3D layer read back: the same elements, and every node the file
// stores (vertices, edge and face points: all but the interior of each 3D element, which
// Nektar++ rebuilds from the faces itself) bit for bit among the same element's nodes.
// Nektar++'s own reader refused such files until the writer numbered the layer's columns as
// runs (a prism's triangles need their apex vertices to carry their highest ids); NekMesh's
// jac module now reads them and finds no negative Jacobian (bench/boundary_layer with NEKMESH).
void expectNektarXmlStoresEveryNodeExactly(const MeshResult& r, const std::string& stem) {
  const Mesh& a = r.mesh;
  const int p = a.order;
  const auto dir = test::tempDir();
  const std::string path = (dir / (stem + ".xml")).string();
  writeMeshFiles(r, {path});
  const Mesh b = readMesh(path);
  ASSERT_EQ(b.order, p);
  // a's 3D elements by their sorted vertex coordinates.
  using Key = std::vector<std::array<double, 3>>;
  const auto key = [](const Mesh& m, const std::int64_t* v, int nv) {
    Key k;
    for (int i = 0; i < nv; ++i)
      k.push_back({m.xyz[3 * v[i]], m.xyz[3 * v[i] + 1], m.xyz[3 * v[i] + 2]});
    std::sort(k.begin(), k.end());
    return k;
  };
  std::map<Key, const std::int64_t*> elements;
  std::map<CellType, std::size_t> countA, countB;
  for (const ElementBlock& blk : a.blocks)
    if (cellDimension(blk.type) == 3)
      for (std::size_t e = 0; e < blk.count(); ++e, ++countA[blk.type])
        elements[key(a, blk.element(e), cellNumVertices(blk.type))] = blk.element(e);
  std::size_t stored = 0, interior = 0;
  for (const ElementBlock& blk : b.blocks) {
    if (cellDimension(blk.type) != 3) continue;
    const ReferenceElement& ref = ReferenceElement::get(blk.type, p);
    for (std::size_t e = 0; e < blk.count(); ++e, ++countB[blk.type]) {
      const std::int64_t* v = blk.element(e);
      const auto it = elements.find(key(b, v, cellNumVertices(blk.type)));
      ASSERT_NE(it, elements.end()) << "an element of the file is not in the mesh written";
      std::set<std::array<double, 3>> nodesA;
      for (int i = 0; i < ref.numNodes(); ++i) {
        const std::int64_t n = it->second[i];
        nodesA.insert({a.xyz[3 * n], a.xyz[3 * n + 1], a.xyz[3 * n + 2]});
      }
      for (int i = 0; i < ref.numNodes(); ++i) {
        const LatticePoint& l = ref.lattice()[static_cast<std::size_t>(i)];
        const bool inside = blk.type == CellType::Prism
                                ? l[0] > 0 && l[1] > 0 && l[0] + l[1] < p && l[2] > 0 && l[2] < p
                                : l[0] > 0 && l[1] > 0 && l[2] > 0 && l[0] + l[1] + l[2] < p;
        if (inside) {
          ++interior;
          continue;
        }
        ++stored;
        const std::int64_t n = v[i];
        EXPECT_EQ(nodesA.count({b.xyz[3 * n], b.xyz[3 * n + 1], b.xyz[3 * n + 2]}), 1U)
            << "node " << i << " of a " << cellShortName(blk.type);
      }
    }
  }
  EXPECT_EQ(countA, countB);
  EXPECT_GT(countB[CellType::Prism], 0U);
  EXPECT_GT(stored, 0U);
  if (p >= 3) {
    EXPECT_GT(interior, 0U);  // a prism has interior nodes from order 3 on
  }
}

// The optimiser's stop rule: "stalled" also needs the worst element to have stopped rising
// within the window, the pipeline's stall of 1e-3 over 3 sweeps (pipelineOptimiserOptions in
// mesh_pipeline.cpp).
void expectStalledOnlyOnceTheWorstStoppedRising(const OptimiserResult& o) {
  const std::vector<IterationRecord>& h = o.history;
  ASSERT_FALSE(h.empty());
  if (o.stopReason != "stalled") return;
  double low = h.back().worst;
  for (std::size_t k = h.size() >= 4 ? h.size() - 4 : 0; k + 1 < h.size(); ++k)
    low = std::min(low, h[k].worst);
  EXPECT_LT(h.back().worst - low, 1e-3) << "stopped after sweep " << h.back().iteration;
}

// A case meshed at order 6 through the continuation (optimised at order 4, raised, optimised
// again): certified valid, the first layer's height within 5 % after the raise, and the
// optimiser's stop rule.
void expectRaisedToOrderSixKeepingTheFirstHeight(const MeshResult& r) {
  ASSERT_EQ(r.mesh.order, 6);
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_TRUE(r.lowOrderOptimiser.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_GT(r.layerSplit->firstHeightMeasured, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  ::testing::Test::RecordProperty("first_layer_height_worst_deviation",
                                  std::to_string(r.layerSplit->firstHeightDeviation));
  ASSERT_TRUE(r.optimiser.has_value());
  expectStalledOnlyOnceTheWorstStoppedRising(*r.optimiser);
}

// 2D: `layers` quadrilaterals in the column on every wall line of `walls` (wall (0, 1), top
// (3, 2)), every quadrilateral in one column, and in `worst` the largest relative deviation of
// the first layer's height, the top's component along the wall's normal at the wall's quadrature
// points (degree 2P), from `firstHeight`.
void expectQuadrilateralColumnsOnEveryWallLine(const MeshResult& r, const std::set<int>& walls,
                                               int layers, double firstHeight, double& worst) {
  worst = 0.0;
  ASSERT_TRUE(r.boundaryLayer.has_value());
  const Mesh& m = r.mesh;
  std::map<std::array<std::int64_t, 2>, const std::int64_t*> byWall;
  std::size_t quads = 0;
  for (const ElementBlock& b : m.blocks)
    if (b.type == CellType::Quadrilateral)
      for (std::size_t e = 0; e < b.count(); ++e, ++quads) {
        std::array<std::int64_t, 2> key{b.element(e)[0], b.element(e)[1]};
        std::sort(key.begin(), key.end());
        EXPECT_TRUE(byWall.emplace(key, b.element(e)).second);
      }
  EXPECT_EQ(quads, static_cast<std::size_t>(layers) * r.boundaryLayer->cells);
  const ReferenceElement& ref = ReferenceElement::get(CellType::Quadrilateral, m.order);
  const QuadratureRule rule = quadratureRule(CellType::Line, 2 * m.order);
  const Eigen::Vector3d plane(m.planeNormal[0], m.planeNormal[1], m.planeNormal[2]);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  const auto lines = wallCells<2>(m, walls);
  for (std::array<std::int64_t, 2> key : lines) {
    int found = 0;
    const std::int64_t* first = nullptr;
    for (;;) {
      std::sort(key.begin(), key.end());
      const auto it = byWall.find(key);
      if (it == byWall.end()) break;
      if (found++ == 0) first = it->second;
      key = {it->second[3], it->second[2]};
    }
    EXPECT_EQ(found, layers);
    ASSERT_NE(first, nullptr);
    for (int q = 0; q < rule.size(); ++q) {
      Eigen::Vector3d bottom = Eigen::Vector3d::Zero(), top = Eigen::Vector3d::Zero();
      Eigen::Vector3d tangent = Eigen::Vector3d::Zero();
      for (const double eta : {0.0, 1.0}) {
        const double xi[2] = {rule.points[static_cast<std::size_t>(q)], eta};
        ref.evaluate(xi, values, gradients);
        for (int i = 0; i < ref.numNodes(); ++i) {
          const Eigen::Vector3d x = point(m, first[i]);
          (eta == 0.0 ? bottom : top) += values(i) * x;
          if (eta == 0.0) tangent += gradients(i, 0) * x;
        }
      }
      const Eigen::Vector3d normal = plane.cross(tangent).normalized();
      worst = std::max(worst, std::fabs(std::fabs((top - bottom).dot(normal)) / firstHeight - 1));
    }
  }
  EXPECT_EQ(lines.size(), r.boundaryLayer->cells);
}

// 2D: the fan at the sharp convex corner at CAD vertex `vertex`: its first layer's triangles
// (a vertex at the corner), each at most 40 degrees wide (the fan's step, kFanStep in
// boundary_layer.cpp), and the first layers on either side (quadrilaterals with a wall vertex at
// the corner) with the largest relative deviation of their height along the wall normal (the
// top's component) from `firstHeight`.
struct CornerFan {
  std::size_t pieces = 0, sides = 0;
  double angle = 0.0;  // radians, summed over the pieces
  double worstSideHeight = 0.0;
};
void measureCornerFan(const MeshResult& r, int vertex, double firstHeight, CornerFan& fan) {
  fan = CornerFan();
  ASSERT_TRUE(r.cad);
  const Mesh& m = r.mesh;
  const Eigen::Vector3d corner = r.cad->vertexPoint(vertex);
  std::int64_t at = -1;
  for (std::size_t i = 0; i < m.numNodes(); ++i)
    if ((point(m, static_cast<std::int64_t>(i)) - corner).norm() < 1e-9)
      at = static_cast<std::int64_t>(i);
  ASSERT_GE(at, 0);
  const Eigen::Vector3d plane(m.planeNormal[0], m.planeNormal[1], m.planeNormal[2]);
  const auto angleAt = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).dot(plane), a.dot(b));
  };
  for (const ElementBlock& b : m.blocks) {
    if (b.type != CellType::Triangle) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < 3; ++k)
        if (v[k] == at) {
          const double a =
              angleAt(point(m, v[(k + 1) % 3]) - corner, point(m, v[(k + 2) % 3]) - corner);
          EXPECT_GT(a, 0.0);
          EXPECT_LE(a, 40.0 * M_PI / 180.0 + 1e-9);
          fan.angle += a;
          ++fan.pieces;
        }
    }
  }
  const ReferenceElement& ref = ReferenceElement::get(CellType::Quadrilateral, m.order);
  const QuadratureRule rule = quadratureRule(CellType::Line, 2 * m.order);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (const ElementBlock& b : m.blocks) {
    if (b.type != CellType::Quadrilateral) continue;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      if (v[0] != at && v[1] != at) continue;
      ++fan.sides;
      for (int q = 0; q < rule.size(); ++q) {
        Eigen::Vector3d bottom = Eigen::Vector3d::Zero(), top = bottom, tangent = bottom;
        for (const double eta : {0.0, 1.0}) {
          const double xi[2] = {rule.points[static_cast<std::size_t>(q)], eta};
          ref.evaluate(xi, values, gradients);
          for (int i = 0; i < ref.numNodes(); ++i) {
            (eta == 0.0 ? bottom : top) += values(i) * point(m, v[i]);
            if (eta == 0.0) tangent += gradients(i, 0) * point(m, v[i]);
          }
        }
        const double h = std::fabs((top - bottom).dot(plane.cross(tangent).normalized()));
        fan.worstSideHeight = std::max(fan.worstSideHeight, std::fabs(h / firstHeight - 1.0));
      }
    }
  }
}

// A plate 2 x 2 x 0.1 with a layer of 0.06 asked on both large faces (5: z = 0, 6: z = 0.1):
// the two layers would overlap, so both are shrunk, and the report says where and by how much.
TEST(BoundaryLayer, AThinGapShrinksTheLayerAndTheRecordSaysWhere) {
  const CadModel cad = test::toModel(test::box(2.0, 2.0, 0.1));
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.4);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {5, 6};
  p.thickness = "0.06";
  BoundaryLayerRecord record;
  const Mesh mesh = growBoundaryLayer(volume, cad, p, fill, record);
  ASSERT_EQ(record.shrunk.size(), 2U);
  for (const LayerShrink& s : record.shrunk) {
    EXPECT_TRUE(s.face == 5 || s.face == 6);
    EXPECT_LT(s.factor, 0.7);  // 2.5 heights must fit in the 0.1 gap: at most 0.04 of 0.06
    EXPECT_GT(s.factor, 0.0);
    EXPECT_GT(s.nodes, 0U);
    EXPECT_NEAR(s.where[2], s.face == 5 ? 0.0 : 0.1, 1e-12);
  }
  EXPECT_LE(record.thicknessMax, 0.04);
  EXPECT_GT(record.thicknessMin, 0.0);
  // Every prism positive at its corners, the tops of both layers apart, the whole linear mesh
  // certified valid, and the sides on the plate's edges as quadrilaterals.
  std::size_t prisms = 0, quads = 0;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type == CellType::Quadrilateral) quads += b.count();
    if (b.type != CellType::Prism) continue;
    prisms += b.count();
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < 3; ++k) {
        const double wallZ = point(mesh, v[k]).z();
        const double topZ = point(mesh, v[k + 3]).z();
        EXPECT_GT(std::fabs(topZ - wallZ), 0.0);
        EXPECT_LT(std::fabs(topZ - 0.05), 0.05 - 1e-3);  // the top inside the plate
      }
    }
  }
  EXPECT_EQ(prisms, record.cells);
  EXPECT_GT(quads, 0U);
  EXPECT_EQ(quads, record.sideQuadrilaterals);
  const QualitySummary q = evaluateQuality(mesh);
  EXPECT_EQ(q.invalid + q.undecided, 0U);
}

TEST(BoundaryLayer, MissingFacesAndBadThicknessesAreNamed) {
  const CadModel cad = test::toModel(test::box(1.0, 1.0, 1.0));
  const LinearMeshOptions fill = LinearMeshOptions::uniform(0.5);
  const Mesh volume = generateLinearMesh(cad, fill);
  BoundaryLayerParameters p;
  p.faces = {9};
  p.thickness = "0.1";
  BoundaryLayerRecord record;
  try {
    growBoundaryLayer(volume, cad, p, fill, record);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("face 9"), std::string::npos) << e.what();
  }
  p.faces = {1};
  p.thickness = "0.1 - x";  // negative beyond x = 0.1: face 1 lies at x = 0, so fine there
  EXPECT_NO_THROW(growBoundaryLayer(volume, cad, p, fill, record));
  p.faces = {2};  // x = 1: the thickness is -0.9 there
  try {
    growBoundaryLayer(volume, cad, p, fill, record);
    ADD_FAILURE();
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("Face2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("must be positive"), std::string::npos) << e.what();
  }
}

// The bracket's hole (Face3) runs into Face1 tangentially: no height of prism is valid there,
// and the message says which face should carry the layer too.
TEST(BoundaryLayer, ATangentNeighbourWithoutALayerIsNamed) {
  MeshingOptions options;  // automatic sizing, as `homesh mesh` without sizes
  options.order = 1;
  BoundaryLayerParameters p;
  p.faces = {3, 6};
  p.thickness = "0.5";
  options.boundaryLayer = p;
  try {
    runMeshPipeline(CadSource::file(std::string(HOMESH_SOURCE_DIR) + "/examples/bracket.step"),
                    options);
    ADD_FAILURE();
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("meets Face1, which has no layer, (nearly) tangentially"),
              std::string::npos)
        << e.what();
  }
}

// NekMesh's 3d_bl_cyl case: a cylinder (faces 1 and 8) in a box, thickness 0.04, 6 layers,
// progression 1.5, at order 2 with the optimiser (as docs/boundary-layers.md's example runs it).
// The meshing runs once for the suite, and only where the peer files are (SetUp skips each test
// otherwise).
class CylinderCase : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (test::havePeerFiles()) result_ = new MeshResult(meshPeerCase("3d_bl_cyl", 2));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
  }
  void SetUp() override {
    HOMESH_REQUIRE_PEER_FILES();
    ASSERT_NE(result_, nullptr);
  }
  static MeshResult* result_;
};
MeshResult* CylinderCase::result_ = nullptr;

TEST_F(CylinderCase, IsCertifiedValidWithTheRequestedLayersInEveryWallColumn) {
  expectValidWithLayersInEveryWallColumn(*result_, {1, 8}, 6);
}

TEST_F(CylinderCase, SplitNodesLieOnTheCadAndTheReportSaysSo) {
  // The side nodes' move onto the end planes: measured 0.27 % of the layer's height at order 2
  // (rounding alone before the first level's shift).
  expectSplitNodesOnTheCad(*result_, "3d_bl_cyl.mcf", 6, 0.01);
}

TEST_F(CylinderCase, NektarAndGmshFilesCarryThePrismsAndReadBack) {
  expectNektarAndGmshFilesReadBack(*result_, "cyl");
}

// The order-4 cylinder, without the optimiser (the geometry as split; the optimiser is not the
// point), written as Nektar++ XML and read back.
TEST(BoundaryLayer, NektarXmlOfTheSplitLayerReadsBackEveryStoredNodeExactly) {
  HOMESH_REQUIRE_PEER_FILES();
  CaseSetup setup = setupCase(test::peerFile("meshgen/3d_bl_cyl.mcf"));
  setup.options.order = 4;
  setup.options.optimiseIterations = 0;
  setup.options.repairRounds = 0;
  const MeshResult r = runMeshPipeline(setup.source, setup.options);
  ASSERT_EQ(r.mesh.order, 4);
  expectNektarXmlStoresEveryNodeExactly(r, "cyl4");
}

// The first layer's height, measured along the wall's normal at the wall triangles' quadrature
// points, against thickness x (1 - r) / (1 - r^n): within the issue's 5 % everywhere, on the
// acceptance's path (order 4, the optimiser on). This coarse case leaves one tetrahedron on the
// layer's top invalid with the layer fixed, so the optimiser lets the top slide parallel to the
// wall around it, and the split sets each column's levels from the grown height (measured:
// 4.1 %, against 9.7 % with the levels alone and 13 % with the top moving freely). The
// report's own figure (LayerSplitStats) is checked against this independent one.
constexpr double kEndBand = 0.05;
TEST(BoundaryLayer, FirstLayerHeightAlongTheWallNormalIsWithinFivePercent) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("3d_bl_cyl", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  const double expected = 0.04 * (1 - 1.5) / (1 - std::pow(1.5, 6));
  double worst = 0.0, worstNearEnds = 0.0;
  std::size_t measured = 0;
  forEachFirstLayerHeight(r, {1, 8}, [&](const Eigen::Vector3d& bottom, double height) {
    const double dev = std::fabs(height / expected - 1);
    const bool nearEnd = bottom.z() < kEndBand || bottom.z() > 0.5 - kEndBand;
    (nearEnd ? worstNearEnds : worst) = std::max(nearEnd ? worstNearEnds : worst, dev);
    ++measured;
  });
  EXPECT_GT(measured, 0U);
  EXPECT_LE(worst, 0.05) << "worst relative deviation of the first-layer height";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_LE(worstNearEnds, 0.05) << "near the end planes";
  RecordProperty("first_layer_height_worst_near_the_ends", std::to_string(worstNearEnds));
  // The report measures the same at the same points (with its own normals and its own search):
  // equal to what rounding and the searches' tolerance (1e-12 in reference coordinates) leave.
  EXPECT_NEAR(r.layerSplit->firstHeightDeviation, std::max(worst, worstNearEnds), 1e-9);
  EXPECT_EQ(r.layerSplit->firstHeightOffNormal, 0U);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);  // the cylinder's wall has no sharp corner
  EXPECT_LE(r.layerSplit->firstHeightMin, expected * (1 + 0.05));
  EXPECT_GE(r.layerSplit->firstHeightMin, expected * (1 - 0.05));
}

// NekMesh's 2d_bl_aerofoil case: a layer of thickness 0.1 on the aerofoil's two curves (Edge2,
// Edge4), 6 layers, progression 1.5, at order 4 with the optimiser.
TEST(BoundaryLayer2D, AerofoilIsValidWithSixQuadrilateralsOnEveryWallLineAndItsFirstHeight) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_aerofoil", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  EXPECT_EQ(r.mesh.dim, 2);
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk.empty());
  ASSERT_EQ(r.boundaryLayer->release, LayerRelease::None);  // the layer as grown: heights hold
  double worst = 0.0;
  expectQuadrilateralColumnsOnEveryWallLine(r, {2, 4}, 6, 0.1 * (1 - 1.5) / (1 - std::pow(1.5, 6)),
                                            worst);
  EXPECT_LE(worst, 0.05) << "first-layer height, worst relative deviation";
  std::ostringstream figure;
  figure << worst;
  RecordProperty("first_layer_height_worst_relative_deviation", figure.str());
}

// Above order 4 the pipeline optimises at order 4 and raises the order after; the layer's inner
// nodes are then placed straight between the raised wall and the top again, which the split's
// levels assume, and the raise keeps the top's edges on the layer's sides (the cylinder's end
// faces) as the low order shaped them, parallel to the wall. Without the first the cylinder's
// first layer at order 6 was 47 % off its height; without the second 16 %, where the raise had
// placed those edges afresh, straight across the end faces: the top sagged to 0.018 above the
// wall where the layer is 0.04 thick. With both, 0.00 % (the levels are set per column, and the
// columns now have the height grown); 0.05 is what the 2D cases hold.
TEST(BoundaryLayer, AtOrderSixTheFirstLayerFollowsTheRaisedWall) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("3d_bl_cyl", 6);
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_GT(r.layerSplit->firstHeightMeasured, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  RecordProperty("first_layer_height_worst_deviation",
                 std::to_string(r.layerSplit->firstHeightDeviation));
  // The order-6 optimiser's first sweep after the raise lifts the worst element from 0.24 to
  // 0.29; the second lowers it to 0.27 while it lowers the energy elsewhere, and it climbs back
  // from there (0.35 after 37 sweeps). The stall rule used to stop at the fourth sweep, the worst
  // still rising, because three sweeps had not beaten the first's. "stalled" now also needs the
  // worst to have stopped rising within the window: the pipeline's stall of 1e-3 over 3 sweeps
  // (pipelineOptimiserOptions in mesh_pipeline.cpp).
  ASSERT_TRUE(r.optimiser.has_value());
  expectStalledOnlyOnceTheWorstStoppedRising(*r.optimiser);
  EXPECT_GT(r.optimiser->worstAfter, r.optimiser->worstBefore);
}

// NekMesh's 2d_bl_t106 case at order 4 with the optimiser: a layer of thickness 0.01 + 0.05 x
// on the blade (Edge11, Edge12), whose rounded edges (radius about 0.005, with wiggles in the
// splines' curvature) lie under a layer 1 to 11 times thicker. The wall segments there are
// halved until each turns by at most 30 degrees, and the wall's high-order nodes are spaced on
// the offset at a quarter of the height; the top then stays fixed or at most slides parallel to
// the wall (heights kept), the split is certified valid, and the first layer keeps its height
// within the issue's 5 % on the whole wall, tip cells included (10.5 % at the trailing edge's
// tip before, with segments 0.04 long there turning up to 110 degrees).
TEST(BoundaryLayer2D, T106KeepsItsFirstLayerHeightAroundItsRoundedEdges) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_t106", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  std::size_t quads = 0;
  for (const ElementBlock& b : r.mesh.blocks)
    if (b.type == CellType::Quadrilateral) quads += b.count();
  EXPECT_EQ(quads, 2 * r.boundaryLayer->cells);
  EXPECT_LE(r.boundaryLayer->release, LayerRelease::Parallel);
  EXPECT_GT(r.boundaryLayer->wallSplits, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  EXPECT_LE(r.layerSplit->firstHeightCornerDeviation, 0.05);
  // The thinnest first layer is the leading edge's, 0.01 / 3 (2 layers, progression 2), within
  // the deviation the report gives.
  EXPECT_GE(r.layerSplit->firstHeightMin,
            0.01 / 3 *
                (1 - std::max(r.layerSplit->firstHeightDeviation,
                              r.layerSplit->firstHeightCornerDeviation)));
  RecordProperty("first_layer_height_worst_deviation",
                 std::to_string(r.layerSplit->firstHeightDeviation));
  RecordProperty("first_layer_height_worst_deviation_at_corners",
                 std::to_string(r.layerSplit->firstHeightCornerDeviation));
  RecordProperty("plain_columns", std::to_string(r.layerSplit->plainColumns));
}

// NekMesh's 2d_bl_naca0012 case (a layer of 0.05 on the aerofoil's curves Edge5 and Edge6, 2
// layers, progression 2) at order 4. Its trailing edge (Vertex6) is sharp: the curves' normals
// there are 163.5 degrees apart (the closed trailing edge's 16.5 degree wedge). A fan of columns
// fills that angle, each fan triangle at most 40 degrees wide and split into 2 n - 1 = 3
// triangles, so the cells on either side keep a column along their own wall's normal at the
// edge, and their first layer the height asked for, 0.05 / 3, along the wall normal at every
// wall quadrature point (with one column on the edge's bisector it fell 25 % short there, by
// the top's component along the normal 64 %). The tolerance: the component along the normal
// differs from the height along the normal line by the first layer's lean against a wall whose
// curvature is small there, well under 1 %; 5 % is the issue's bound.
TEST(BoundaryLayer2D, NacaSharpTrailingEdgeGrowsAFanAndItsCellsKeepTheFirstHeight) {
  HOMESH_REQUIRE_PEER_FILES();
  const MeshResult r = meshPeerCase("2d_bl_naca0012", 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  CornerFan fan;
  measureCornerFan(r, 6, 0.05 / 3, fan);
  EXPECT_EQ(fan.pieces, r.boundaryLayer->fanTriangles);
  EXPECT_EQ(fan.pieces, 5U);  // ceil(163.5 / 40)
  EXPECT_NEAR(fan.angle * 180.0 / M_PI, 163.5, 1.0);
  EXPECT_EQ(fan.sides, 2U);
  const double worst = fan.worstSideHeight;
  EXPECT_LE(worst, 0.05) << "first-layer height beside the trailing edge, worst deviation";
  // The nose (radius 0.0158 against the case's MinDelta of 0.1): its two wall segments, along
  // which the curves turn by more than 60 degrees, are halved before the growth, and their
  // four halves again (each still turning by more than 30), so no cell's wall meets its
  // neighbour's at a corner and the whole wall keeps its first height (5.8 % off at the nose
  // without the halving), measured by the split along the normal line.
  EXPECT_EQ(r.boundaryLayer->wallSplits, 6U);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  RecordProperty("first_layer_height_worst_deviation_at_trailing_edge", std::to_string(worst));
}

// Siblings of the peer cases on shapes the tests make themselves, so that the boundary layer
// stays covered where NekMesh's files are not: the same properties, with bounds that follow from
// the method (or the issue's 5 % on the first layer's height), not from the peer cases.

// A 1.0 x 0.8 x 0.4 box with a vertical cylindrical hole of radius 0.15 through it, off its
// centre (OCCT's cylinder: one periodic wall face with a seam), the layer on the hole's wall:
// 0.05 thick (the hole's wall is 0.25 from the box's sides, more than the 2.5 thicknesses the
// growth keeps clear: nothing shrinks), 4 layers, progression 1.3, the octree's sizes (MinDelta
// 0.03, MaxDelta 0.12, EPS 0.1: some 70 wall triangles, 1,400 elements), the optimiser as
// meshCase runs it. Meshed once per order for the tests that share it.
constexpr double kHoleHeight = 0.4, kHoleThickness = 0.05, kHoleProgression = 1.3;
constexpr int kHoleLayers = 4;

struct HoleCase {
  MeshResult result;
  std::set<int> walls;  // the curved faces: the hole's wall
};

const HoleCase& holeInABox(int order) {
  static std::map<int, std::unique_ptr<HoleCase>> meshed;
  std::unique_ptr<HoleCase>& slot = meshed[order];
  if (slot) return *slot;
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(1.0, 0.8, kHoleHeight).Shape();
  const TopoDS_Shape drill =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.45, 0.4, -0.1), gp_Dir(0, 0, 1)), 0.15,
                               kHoleHeight + 0.2)
          .Shape();
  const std::string brep = test::brepText(BRepAlgoAPI_Cut(box, drill).Shape());
  const CadModel cad = CadModel::fromBrepText(brep);
  std::set<int> walls;
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) walls.insert(f);
  MeshingOptions options;
  options.order = order;
  options.optimiseIterations = 100;
  options.threads = 2;
  SizingParameters sizes;
  sizes.minDelta = 0.03;
  sizes.maxDelta = 0.12;
  sizes.eps = 0.1;
  options.sizing = sizes;
  BoundaryLayerParameters layer;
  layer.faces.assign(walls.begin(), walls.end());
  layer.thickness = "0.05";
  layer.layers = kHoleLayers;
  layer.progression = kHoleProgression;
  options.boundaryLayer = layer;
  slot = std::make_unique<HoleCase>(
      HoleCase{runMeshPipeline(CadSource::brepText(brep, "hole in a box"), options), walls});
  return *slot;
}

TEST(BoundaryLayerOnAHole, IsCertifiedValidWithTheRequestedLayersInEveryWallColumn) {
  const HoleCase& c = holeInABox(2);
  ASSERT_FALSE(c.walls.empty());
  for (const int f : c.walls) EXPECT_FALSE(c.result.cad->isPlanar(f)) << "Face" << f;
  expectValidWithLayersInEveryWallColumn(c.result, c.walls, kHoleLayers);
}

TEST(BoundaryLayerOnAHole, SplitNodesLieOnTheCadAndTheReportSaysSo) {
  // The side nodes' move onto the end planes: the first level's shift, at most its share z_1 =
  // 0.16 of the height, times the sine of the wall normal's lean off the plane, the order-2
  // wall's normal error (the geometry stage finds 1.5 degrees on this wall): below 0.5 %.
  expectSplitNodesOnTheCad(holeInABox(2).result, "hole in a box", kHoleLayers, 0.01);
}

TEST(BoundaryLayerOnAHole, NektarAndGmshFilesCarryThePrismsAndReadBack) {
  expectNektarAndGmshFilesReadBack(holeInABox(2).result, "hole");
}

TEST(BoundaryLayerOnAHole, NektarXmlOfTheSplitLayerReadsBackEveryStoredNodeExactly) {
  const MeshResult& r = holeInABox(4).result;
  ASSERT_EQ(r.mesh.order, 4);
  expectNektarXmlStoresEveryNodeExactly(r, "hole4");
}

// As FirstLayerHeightAlongTheWallNormalIsWithinFivePercent: at order 4 with the optimiser, the
// first layer's height along the wall normal against thickness x (1 - r) / (1 - r^n) within the
// issue's 5 % (the method's aim: the split sets each column's first level at z_1 times the
// height grown, and nothing here is shrunk), and the report's own figure equal to this
// independent one (the same points, its own normals and search: rounding and the searches'
// 1e-12 in reference coordinates).
TEST(BoundaryLayerOnAHole, FirstLayerHeightAlongTheWallNormalIsWithinFivePercentAtOrderFour) {
  const HoleCase& c = holeInABox(4);
  const MeshResult& r = c.result;
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk.empty());
  const double expected =
      kHoleThickness * (1 - kHoleProgression) / (1 - std::pow(kHoleProgression, kHoleLayers));
  double worst = 0.0;
  std::size_t measured = 0;
  forEachFirstLayerHeight(r, c.walls, [&](const Eigen::Vector3d&, double height) {
    worst = std::max(worst, std::fabs(height / expected - 1));
    ++measured;
  });
  EXPECT_GT(measured, 0U);
  EXPECT_LE(worst, 0.05) << "worst relative deviation of the first-layer height";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_NEAR(r.layerSplit->firstHeightDeviation, worst, 1e-9);
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);  // a cylinder's wall has no sharp corner
  EXPECT_GE(r.layerSplit->firstHeightMin, expected * (1 - 0.05));
  EXPECT_LE(r.layerSplit->firstHeightMax, expected * (1 + 0.05));
}

// As AtOrderSixTheFirstLayerFollowsTheRaisedWall: above order 4 the pipeline optimises at order
// 4 and raises the order after (kContinuationOrder); the split's levels then follow the raised
// wall, so the first layer keeps its height within the issue's 5 % (the report's measure, along
// the wall normal), and the mesh is certified valid. The optimiser's stop rule holds for any
// run: "stalled" only once the worst element stopped rising over the stall window (3 sweeps,
// by 1e-3: pipelineOptimiserOptions in mesh_pipeline.cpp).
TEST(BoundaryLayerOnAHole, AtOrderSixTheFirstLayerFollowsTheRaisedWall) {
  const MeshResult& r = holeInABox(6).result;
  expectRaisedToOrderSixKeepingTheFirstHeight(r);
}

// A NACA 2412 at 6 degrees in its own box, as a .mcf the test writes into a fresh folder (its
// path returned): a layer 0.03 thick on the aerofoil (Edge5, Edge6), 3 layers, progression 1.5.
std::string writeOwnNacaCase() {
  const auto dir = test::tempDir();
  std::string path = (dir / "naca2412.mcf").string();
  std::ofstream(path) << R"(<NEKTAR>
  <MESHING>
    <INFORMATION>
      <I PROPERTY="CADFile" VALUE="2412" />
      <I PROPERTY="MeshType" VALUE="2DBndLayer" />
    </INFORMATION>
    <PARAMETERS>
      <P PARAM="MinDelta" VALUE="0.04" />
      <P PARAM="MaxDelta" VALUE="1.0" />
      <P PARAM="EPS" VALUE="0.1" />
      <P PARAM="Order" VALUE="4" />
      <P PARAM="BndLayerSurfaces" VALUE="5,6" />
      <P PARAM="BndLayerThickness" VALUE="0.03" />
      <P PARAM="BndLayerLayers" VALUE="3" />
      <P PARAM="BndLayerProgression" VALUE="1.5" />
      <P PARAM="Xmin" VALUE="-1.5" />
      <P PARAM="Ymin" VALUE="-1.25" />
      <P PARAM="Xmax" VALUE="2.5" />
      <P PARAM="Ymax" VALUE="1.25" />
      <P PARAM="AOA" VALUE="6.0" />
    </PARAMETERS>
  </MESHING>
</NEKTAR>
)";
  return path;
}

// writeOwnNacaCase at order 4 with the optimiser. The same properties as the aerofoil and NACA
// 0012 peer cases: certified valid, 3 quadrilaterals on every wall line, the first layer's height,
// and the fan at the sharp trailing edge (Vertex6).
TEST(BoundaryLayer2D, OwnNacaCaseHasItsLayersItsFirstHeightAndATrailingEdgeFan) {
  constexpr double kThickness = 0.03, kProgression = 1.5;  // as writeOwnNacaCase says
  constexpr int kLayers = 3;
  const std::string path = writeOwnNacaCase();
  const MeshResult r = meshCase(path, 4);
  ASSERT_TRUE(r.boundaryLayer.has_value());
  ASSERT_TRUE(r.layerSplit.has_value());
  EXPECT_EQ(r.mesh.dim, 2);
  EXPECT_EQ(r.mesh.order, 4);
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk.empty());
  const double first = kThickness * (1 - kProgression) / (1 - std::pow(kProgression, kLayers));
  // The top fixed or at most sliding parallel to the wall: the heights as grown, so the first
  // layer's (the top's component along the wall normal; the split's, along the normal line)
  // within the issue's 5 % on every wall line.
  EXPECT_LE(r.boundaryLayer->release, LayerRelease::Parallel);
  double worst = 0.0;
  expectQuadrilateralColumnsOnEveryWallLine(r, {5, 6}, kLayers, first, worst);
  EXPECT_LE(worst, 0.05) << "first-layer height, worst relative deviation";
  RecordProperty("first_layer_height_worst_relative_deviation", std::to_string(worst));
  EXPECT_LE(r.layerSplit->firstHeightDeviation, 0.05);
  // No cell at a corner: the wall segments are halved until none turns by more than 30 degrees
  // (the nose), and the one sharp corner, the trailing edge, has its fan.
  EXPECT_EQ(r.layerSplit->cornerCells, 0U);
  // The fan: NACA MPTT's surfaces leave the trailing edge at atan(yt'(1) cos theta) either side
  // of the camber line, theta its slope there (naca_aerofoil.hpp's formulas: yt'(1) = -1.21125
  // t, tan theta = -2 M / (1 - P)), so the curves' normals there are 180 degrees less that
  // wedge apart (163.5 here), which the fan fills in ceil(angle / 40 degrees) triangles. Within
  // a degree: the method reads each curve's direction off a short chord of its B-spline at the
  // edge (curveTangent), and the splines interpolate the formula's points without its end
  // tangents (their parametrisation is even stationary there): hundredths of a degree apart.
  const double camber = std::atan(2 * 0.02 / (1 - 0.4));
  const double spread = M_PI - 2 * std::atan(1.21125 * 0.12 * std::cos(camber));
  CornerFan fan;
  measureCornerFan(r, 6, first, fan);
  EXPECT_EQ(fan.pieces, r.boundaryLayer->fanTriangles);
  EXPECT_EQ(fan.pieces, static_cast<std::size_t>(std::ceil(spread / (40.0 * M_PI / 180.0))));
  EXPECT_NEAR(fan.angle, spread, M_PI / 180.0);
  EXPECT_EQ(fan.sides, 2U);
  // The cells beside the edge keep a column along their own wall's normal there: their first
  // layer's component along the normal differs from its height by the layer's lean against a
  // wall of small curvature (well under 1 %), within the issue's 5 %.
  EXPECT_LE(fan.worstSideHeight, 0.05) << "first-layer height beside the trailing edge";
  RecordProperty("fan_angle_degrees", std::to_string(fan.angle * 180.0 / M_PI));
  RecordProperty("first_layer_height_worst_deviation_at_trailing_edge",
                 std::to_string(fan.worstSideHeight));
}

// writeOwnNacaCase at order 6: optimised at order 4, raised, optimised again (as
// AtOrderSixTheFirstLayerFollowsTheRaisedWall): certified valid, the first layer's height within
// the issue's 5 % after the raise, and the optimiser's stop rule.
TEST(BoundaryLayer2D, OwnNacaCaseAtOrderSixKeepsItsFirstHeightAfterTheRaise) {
  const MeshResult r = meshCase(writeOwnNacaCase(), 6);
  expectRaisedToOrderSixKeepingTheFirstHeight(r);
}

// A 2D macro layer that fans out: four order-4 quadrilaterals on an annulus of inner radius
// R = 0.1 and thickness H = 1 (ten times R), each spanning 1 rad, whose lines across the layer
// lean: node (xi, zeta) at angle theta0 + xi + s zeta, s = 0.08. Split in two layers of half
// the height, the first layer's top is the circle of radius R + H/2, so its height along the
// wall normal is H/2 everywhere; the top point at the wall point's own reference coordinate is
// 0.04 rad to the side (inside the cell from the first quadrature point, xi = 0.047, on), and
// its component along the normal is (R + H/2) cos 0.04 - R, 4.8e-4 short. The map's degree-5
// remainder on five equispaced nodes, |d^5 x / d xi^5| max|prod (xi - xi_i)| / 5! <= 0.6 * 0.0046
// / 120 = 2.3e-5 (2e-8 across the layer), bounds the error of the heights: 1e-4 holds them and
// tells them from the component.
TEST(BoundaryLayerSplit, TheFirstHeightIsMeasuredWhereTheWallNormalMeetsTheLayersTop) {
  constexpr double kR = 0.1, kH = 1.0, kDTheta = 1.0, kLean = 0.08;
  constexpr int kCells = 4, kOrder = 4;
  Mesh macro;
  macro.dim = 2;
  macro.order = kOrder;
  const ReferenceElement& ref = ReferenceElement::get(CellType::Quadrilateral, kOrder);
  ElementBlock quads;
  quads.type = CellType::Quadrilateral;
  quads.order = kOrder;
  std::map<std::pair<long long, long long>, std::int64_t> ids;  // shared nodes by position
  for (int c = 0; c < kCells; ++c) {
    for (int i = 0; i < ref.numNodes(); ++i) {
      const double xi = ref.nodes()(i, 0), zeta = ref.nodes()(i, 1);
      const double theta = (c + xi) * kDTheta + zeta * kLean;
      const double r = kR + zeta * kH;
      const double p[3] = {r * std::cos(theta), r * std::sin(theta), 0.0};
      const auto key = std::make_pair(std::llround(p[0] * 1e9), std::llround(p[1] * 1e9));
      auto [it, added] = ids.try_emplace(key, 0);
      if (added) it->second = macro.addNode(p, 2, 1, std::nan(""), std::nan(""));
      quads.nodes.push_back(it->second);
    }
    quads.entity.push_back(1);
  }
  macro.blocks.push_back(quads);
  macro.checkConsistency();
  LayerSplitStats stats;
  splitBoundaryLayer(macro, {0.0, 0.5, 1.0}, nullptr, &stats);
  ASSERT_GT(stats.firstHeightMeasured, 0U);
  EXPECT_EQ(stats.firstHeightOffNormal, 0U);
  EXPECT_NEAR(stats.firstHeightMin, kH / 2, 1e-4);
  EXPECT_NEAR(stats.firstHeightMax, kH / 2, 1e-4);
}

// A hand-made macro layer around a convex corner, at order 2: walls from A = (-1, 0) to the
// corner C = (0, 0) (layer above, normal +y) and from C down to B = (0, -1) (layer to the right,
// normal +x), each with one quadrilateral of height H = 0.5, and between their columns at C a fan
// of three straight triangles, 30 degrees each. Split in two layers (z = 0, 1/3, 1): each fan
// triangle becomes 2 n - 1 = 3 triangles, sub-maps of an affine map (so straight, their edge
// nodes at the midpoints, to rounding), the nodes on the columns shared with the quadrilaterals
// and the neighbouring fan triangles (no two nodes at one point), every column's first level at
// z_1 H from C; keepColumnsPlain names a fan piece's macro columns by their tops.
TEST(BoundaryLayerSplit, AFanAtAConvexCornerSplitsIntoConformingSubTriangles) {
  constexpr double kH = 0.5;
  constexpr int kOrder = 2;
  Mesh macro;
  macro.dim = 2;
  macro.order = kOrder;
  std::map<std::pair<long long, long long>, std::int64_t> ids;
  const auto node = [&](const Eigen::Vector2d& x) {
    const auto key = std::make_pair(std::llround(x.x() * 1e9), std::llround(x.y() * 1e9));
    auto [it, added] = ids.try_emplace(key, 0);
    const double p[3] = {x.x(), x.y(), 0.0};
    if (added) it->second = macro.addNode(p, 2, 1, std::nan(""), std::nan(""));
    return it->second;
  };
  ElementBlock quads, tris;
  quads.type = CellType::Quadrilateral;
  tris.type = CellType::Triangle;
  quads.order = tris.order = kOrder;
  const ReferenceElement& quadRef = ReferenceElement::get(CellType::Quadrilateral, kOrder);
  const ReferenceElement& triRef = ReferenceElement::get(CellType::Triangle, kOrder);
  const auto addQuad = [&](std::array<Eigen::Vector2d, 4> c) {  // wall 0, 1; tops 3, 2
    for (int i = 0; i < quadRef.numNodes(); ++i) {
      const double u = quadRef.nodes()(i, 0), w = quadRef.nodes()(i, 1);
      quads.nodes.push_back(
          node((1 - u) * (1 - w) * c[0] + u * (1 - w) * c[1] + u * w * c[2] + (1 - u) * w * c[3]));
    }
    quads.entity.push_back(1);
  };
  const Eigen::Vector2d a(-1, 0), c(0, 0), b(0, -1);
  addQuad({a, c, Eigen::Vector2d(0, kH), Eigen::Vector2d(-1, kH)});
  addQuad({c, b, Eigen::Vector2d(kH, -1), Eigen::Vector2d(kH, 0)});
  std::vector<Eigen::Vector2d> tops;
  for (int j = 0; j <= 3; ++j) {
    const double angle = j * M_PI / 6;  // 0 (+x) .. 90 degrees (+y)
    tops.emplace_back(kH * std::cos(angle), kH * std::sin(angle));
  }
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < triRef.numNodes(); ++i) {
      const double u = triRef.nodes()(i, 0), w = triRef.nodes()(i, 1);
      tris.nodes.push_back(node(c + u * (tops[j] - c) + w * (tops[j + 1] - c)));
    }
    tris.entity.push_back(1);
  }
  macro.blocks = {tris, quads};
  macro.checkConsistency();
  const std::vector<char> fans = layerFanTriangles(macro, macro.blocks[0]);
  EXPECT_EQ(std::count(fans.begin(), fans.end(), 1), 3);
  LayerSplitStats stats;
  const Mesh split = splitBoundaryLayer(macro, {0.0, 1.0 / 3, 1.0}, nullptr, &stats);
  EXPECT_EQ(stats.fanTriangles, 3U);
  ASSERT_EQ(split.blocks.size(), 2U);
  EXPECT_EQ(split.blocks[0].count(), 9U);
  EXPECT_EQ(split.blocks[1].count(), 4U);
  std::set<std::pair<long long, long long>> places;
  for (std::size_t i = 0; i < split.numNodes(); ++i) {
    const Eigen::Vector3d x = point(split, static_cast<std::int64_t>(i));
    EXPECT_TRUE(places.emplace(std::llround(x.x() * 1e9), std::llround(x.y() * 1e9)).second)
        << "two nodes at " << x.transpose();
  }
  // Straight sub-triangles: positive area, edge nodes at the midpoints (rounding: 1e-12).
  const ElementBlock& pieces = split.blocks[0];
  for (std::size_t e = 0; e < pieces.count(); ++e) {
    const std::int64_t* v = pieces.element(e);
    const Eigen::Vector3d p0 = point(split, v[0]), p1 = point(split, v[1]), p2 = point(split, v[2]);
    EXPECT_GT((p1 - p0).cross(p2 - p0).z(), 0.0);
    EXPECT_LT((point(split, v[3]) - (p0 + p1) / 2).norm(), 1e-12);
    EXPECT_LT((point(split, v[4]) - (p1 + p2) / 2).norm(), 1e-12);
    EXPECT_LT((point(split, v[5]) - (p2 + p0) / 2).norm(), 1e-12);
  }
  for (const Eigen::Vector2d& t : tops) {
    const Eigen::Vector2d first = c + (t - c) / 3;
    EXPECT_EQ(places.count({std::llround(first.x() * 1e9), std::llround(first.y() * 1e9)}), 1U)
        << "no node at the first level of the column to " << t.transpose();
  }
  EXPECT_EQ(evaluateQuality(split, 1).invalid, 0U);
  // Split element 4 is the second fan triangle's second piece: its columns end at tops 1, 2.
  LayerHeights heights;
  keepColumnsPlain(macro, 2, 4, heights);
  const std::set<std::int64_t> expected{node(tops[1]), node(tops[2])};
  EXPECT_EQ(heights.plain, expected);
}

}  // namespace
}  // namespace homesh
