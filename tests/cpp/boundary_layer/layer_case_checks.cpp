#include "layer_case_checks.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "io/mesh_readers.hpp"
#include "io/mesh_writers.hpp"
#include "optimise/optimiser.hpp"
#include "peer_data.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {

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

namespace {

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

}  // namespace

// 3D: certified valid, nothing shrunk, and `layers` prisms in the column on every wall triangle
// of `walls` (prisms stacked bottom (0, 1, 2) to top (3, 4, 5)), every prism in one column.
void expectValidWithLayersInEveryWallColumn(const MeshResult& r, const std::set<int>& walls,
                                            int layers) {
  ASSERT_TRUE(r.boundaryLayer.has_value());
  EXPECT_EQ(r.quality.invalid + r.quality.undecided, 0U);
  EXPECT_TRUE(r.boundaryLayer->shrunk().empty());
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

}  // namespace homesh
