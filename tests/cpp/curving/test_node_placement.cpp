// High-order boundary nodes on the CAD: arc-length spacing on curves, monotone parameters along
// every mesh edge, nodes on their entity within the CAD tolerance, across seams and poles, and a
// coarse torus where plain closest-point projection folds the parameters.
#include <gtest/gtest.h>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <gp_Elips.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "core/error.hpp"
#include "curving/curve_node_placement.hpp"
#include "curving/face_node_placement.hpp"
#include "curving/order_elevation.hpp"
#include "element/reference_element.hpp"
#include "linear/linear_mesher.hpp"
#include "quality/mesh_quality.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::nodePoint;

// Arc length of curve `edge` between t0 and t1 by composite Gauss-Legendre (5 points on 64
// pieces: the error is far below the spacing bounds tested, the speed being smooth).
double arcLength(const CadModel& cad, int edge, double t0, double t1) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                              0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                              0.4786286704993665, 0.2369268850561891};
  const int pieces = 64;
  double sum = 0.0;
  const double h = (t1 - t0) / pieces;
  for (int k = 0; k < pieces; ++k)
    for (int q = 0; q < 5; ++q)
      sum += 0.5 * h * w[q] * cad.evaluateCurve(edge, t0 + h * (k + 0.5 * (1.0 + x[q]))).d1.norm();
  return std::abs(sum);
}

// An ellipse with semi-axes 2 and 0.25 as one closed edge: curvature from b/a^2 = 0.0625 to
// a/b^2 = 32 (the blunt nose of a thin aerofoil-like section).
CadModel ellipseModel() {
  const gp_Elips ellipse(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0, 0.25);
  const TopoDS_Edge edge = BRepBuilderAPI_MakeEdge(ellipse).Edge();
  return test::toModel(BRepBuilderAPI_MakeFace(BRepBuilderAPI_MakeWire(edge).Wire()).Face());
}

TEST(CurveNodePlacement, SpacesNodesInArcLengthAroundAStronglyCurvedNose) {
  const CadModel cad = ellipseModel();
  ASSERT_EQ(cad.numEdges(), 1);
  // A coarse edge over the nose (t = pi is the vertex (-2, 0) of curvature 32).
  const double ta = M_PI - 0.5, tb = M_PI + 0.4;
  for (const int order : {4, 6, 8}) {
    const std::vector<double> z = equispacedPositions(order);
    const CurvePlacement placement = placeOnCurve(cad, 1, ta, tb, z);
    ASSERT_TRUE(placement.optimised) << "order " << order;
    ASSERT_TRUE(strictlyMonotone(placement.t));
    EXPECT_EQ(placement.t.front(), ta);
    EXPECT_EQ(placement.t.back(), tb);
    // The same edge run the other way gives the same nodes (equispaced z are symmetric); the
    // solves stop within about sqrt(1e-14) of the span (see CircleNodesAreEquallySpaced).
    const CurvePlacement reversed = placeOnCurve(cad, 1, tb, ta, z);
    for (int i = 0; i <= order; ++i)
      EXPECT_NEAR(reversed.t[order - i], placement.t[i], 1e-6 * (tb - ta)) << "order " << order;
    std::vector<double> arcs;
    double kMax = 0.0;
    for (int i = 0; i < order; ++i) {
      arcs.push_back(arcLength(cad, 1, placement.t[i], placement.t[i + 1]));
      for (int s = 0; s <= 8; ++s) {
        const auto c =
            cad.evaluateCurve(1, placement.t[i] + (placement.t[i + 1] - placement.t[i]) * s / 8.0);
        kMax = std::max(kMax, c.d1.cross(c.d2).norm() / std::pow(c.d1.norm(), 3));
      }
    }
    const double total = arcLength(cad, 1, ta, tb), mean = total / order;
    // The optimum has equal chords up to terms of relative order (kh)^2 (a chord of an arc of
    // length h and curvature k is h (1 - (kh)^2 / 24)); the arcs then agree to (k_max h)^2 / 12
    // relatively, k_max the largest curvature over the sub-arcs and h the longest sub-arc.
    const double hMax = *std::max_element(arcs.begin(), arcs.end());
    const double bound = std::pow(kMax * hMax, 2) / 12.0;
    for (const double a : arcs) EXPECT_LE(std::abs(a / mean - 1.0), bound) << "order " << order;
    // Plain projection of the chord's equispaced points (the previous placement) folds: the
    // chord crosses the thin nose behind its tip, so its middle points land on the flanks,
    // some beyond the edge's end parameter.
    const Eigen::Vector3d xa = cad.evaluateCurve(1, ta).point, xb = cad.evaluateCurve(1, tb).point;
    std::vector<double> projected{ta};
    for (int i = 1; i < order; ++i)
      projected.push_back(cad.projectOnCurve(1, xa + (xb - xa) * z[i]).t);
    projected.push_back(tb);
    EXPECT_FALSE(strictlyMonotone(projected)) << "order " << order;
  }
}

TEST(CurveNodePlacement, CircleNodesAreEquallySpaced) {
  const CadModel cad = test::toModel(test::cylinder(1.0, 1.0));
  int circle = 0;
  for (int e = 1; e <= cad.numEdges(); ++e)
    if (!cad.isDegenerated(e) && std::abs(cad.evaluateCurve(e, 0.0).d1.norm() - 1.0) < 1e-12 &&
        cad.evaluateCurve(e, 0.0).d1.z() == 0.0)
      circle = e;
  ASSERT_GT(circle, 0);
  const CurvePlacement placement = placeOnCurve(cad, circle, 0.3, 2.9, equispacedPositions(7));
  ASSERT_TRUE(placement.optimised);
  // On a circle equal chords are equal arcs; t is arc length. The solve stops when a step gains
  // less than 1e-14 of the energy, which leaves parameter errors near sqrt(1e-14) * span.
  const double h = (2.9 - 0.3) / 7;
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(placement.t[i + 1] - placement.t[i], h, 1e-6);
}

// A 2D layer's wall edge over the ellipse's nose (radius 1/32) under a layer 0.5 thick: its
// nodes are spaced as their images on the offset curve at that height (where arc length
// bunches them: the offset turns fastest where the wall is most curved), so the offset's
// sub-arcs are equal to the same second-order bound as the wall's are without the offset.
TEST(CurveNodePlacement, OnAnOffsetTheImagesAreSpacedInItsArcLength) {
  const CadModel cad = ellipseModel();
  const double ta = M_PI - 0.5, tb = M_PI + 0.4;
  CurveOffset offset;
  offset.height = 0.5;  // t x z: outward on the counter-clockwise ellipse, the convex side
  offset.planeNormal = Eigen::Vector3d::UnitZ();
  const auto offsetPoint = [&](double t) {
    return offsetCurve(cad.evaluateCurve(1, t), offset)->point;
  };
  ASSERT_GT((offsetPoint(M_PI) - cad.evaluateCurve(1, M_PI).point).dot(Eigen::Vector3d(-1, 0, 0)),
            0.49);
  // Offset arc length by the same composite rule as arcLength, on |o'(t)|.
  const auto offsetArc = [&](double t0, double t1) {
    double sum = 0.0;
    const int pieces = 256;
    for (int k = 0; k < pieces; ++k) {
      const double a = t0 + (t1 - t0) * k / pieces, b = t0 + (t1 - t0) * (k + 1) / pieces;
      sum += (offsetPoint(b) - offsetPoint(a)).norm();  // chords: 2e-5 relative at 256 pieces
    }
    return sum;
  };
  for (const int order : {4, 6}) {
    const std::vector<double> z = equispacedPositions(order);
    const CurvePlacement on = placeOnCurve(cad, 1, ta, tb, z, offset);
    const CurvePlacement plain = placeOnCurve(cad, 1, ta, tb, z);
    ASSERT_TRUE(on.optimised && plain.optimised) << "order " << order;
    ASSERT_TRUE(strictlyMonotone(on.t));
    std::vector<double> arcs, plainArcs;
    double kMax = 0.0;  // of the offset: k / (1 + k H) for wall curvature k on the convex side
    for (int i = 0; i < order; ++i) {
      arcs.push_back(offsetArc(on.t[i], on.t[i + 1]));
      plainArcs.push_back(offsetArc(plain.t[i], plain.t[i + 1]));
      for (int s = 0; s <= 8; ++s) {
        const auto c = cad.evaluateCurve(1, on.t[i] + (on.t[i + 1] - on.t[i]) * s / 8.0);
        const double k = c.d1.cross(c.d2).norm() / std::pow(c.d1.norm(), 3);
        kMax = std::max(kMax, k / (1.0 + k * offset.height));
      }
    }
    const double mean = offsetArc(ta, tb) / order;
    const double hMax = *std::max_element(arcs.begin(), arcs.end());
    // As SpacesNodesInArcLengthAroundAStronglyCurvedNose's bound, plus the chord rule's 2e-5.
    const double bound = std::pow(kMax * hMax, 2) / 12.0 + 2e-5;
    for (const double a : arcs) EXPECT_LE(std::abs(a / mean - 1.0), bound) << "order " << order;
    // Arc-length nodes leave the offset's pieces unequal by far more (measured 17 to 20x).
    const auto [lo, hi] = std::minmax_element(plainArcs.begin(), plainArcs.end());
    EXPECT_GT(*hi / *lo, 1.3) << "order " << order;
  }
}

TEST(CurveNodePlacement, RejectsBadInput) {
  const CadModel cad = ellipseModel();
  EXPECT_THROW(placeOnCurve(cad, 1, 0.2, 0.2, equispacedPositions(4)), ParameterError);
  EXPECT_THROW(placeOnCurve(cad, 1, 0.0, 1.0, {0.0, 0.7, 0.5, 1.0}), ParameterError);
}

// Node lists of every mesh edge of a high-order mesh's boundary cells (triangles and lines),
// from the first vertex to the second, in Gmsh node order.
std::map<std::array<std::int64_t, 2>, std::vector<std::int64_t>> meshEdges(const Mesh& mesh) {
  std::map<std::array<std::int64_t, 2>, std::vector<std::int64_t>> edges;
  const int p = mesh.order;
  for (const ElementBlock& b : mesh.blocks) {
    if (b.type != CellType::Triangle && b.type != CellType::Line) continue;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      std::map<std::pair<int, int>, std::int64_t> at;
      for (int n = 0; n < ref.numNodes(); ++n)
        at[{ref.lattice()[n][0], ref.lattice()[n][1]}] = v[n];
      const auto add = [&](std::vector<std::int64_t> nodes) {
        if (nodes.front() > nodes.back()) std::reverse(nodes.begin(), nodes.end());
        edges[{nodes.front(), nodes.back()}] = nodes;
      };
      std::vector<std::int64_t> a, c, d;
      for (int k = 0; k <= p; ++k) {
        a.push_back(at[{k, 0}]);
        if (b.type == CellType::Triangle) {
          c.push_back(at[{0, k}]);
          d.push_back(at[{p - k, k}]);
        }
      }
      add(a);
      if (b.type == CellType::Triangle) {
        add(c);
        add(d);
      }
    }
  }
  return edges;
}

struct EdgeCheck {
  std::size_t curveEdges = 0, faceEdges = 0, nonMonotone = 0;
};

// Every new boundary node on its entity within the CAD tolerance, and parameters monotone along
// every mesh edge on a curve (t) or inside a face ((u, v), unwrapped node by node).
EdgeCheck checkBoundary(const Mesh& mesh, const CadModel& cad) {
  EdgeCheck check;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) {
    const int dim = mesh.nodeCadDim[i], index = mesh.nodeCadIndex[i];
    const Eigen::Vector3d x = nodePoint(mesh, i);
    // The entity's own tolerance: how far OCCT lets its points stray from the exact geometry.
    if (dim == 1) {
      const double tol = cad.tolerance(1, index);
      EXPECT_LE(cad.projectOnCurve(index, x).distance, tol) << "node " << i;
      EXPECT_LE((cad.evaluateCurve(index, mesh.nodeCadParam[2 * i]).point - x).norm(), tol);
    } else if (dim == 2) {
      const double tol = cad.tolerance(2, index);
      const double u = mesh.nodeCadParam[2 * i], v = mesh.nodeCadParam[2 * i + 1];
      EXPECT_LE(cad.projectOnSurface(index, x).distance, tol) << "node " << i;
      EXPECT_LE((cad.evaluateSurface(index, u, v).point - x).norm(), tol) << "node " << i;
      EXPECT_TRUE(cad.faceContains(index, u, v)) << "node " << i << " outside Face" << index;
    }
  }
  for (const auto& [key, nodes] : meshEdges(mesh)) {
    const std::int64_t mid = nodes[1];
    const int dim = mesh.nodeCadDim[mid], index = mesh.nodeCadIndex[mid];
    if (dim == 1) {
      ++check.curveEdges;
      std::vector<double> t;
      for (std::size_t k = 1; k + 1 < nodes.size(); ++k)
        t.push_back(mesh.nodeCadParam[2 * nodes[k]]);
      // The ends' parameters follow from their neighbours (a vertex of a closed curve has two).
      const auto endT = [&](std::int64_t node, double near) {
        if (mesh.nodeCadDim[node] == 1) return mesh.nodeCadParam[2 * node];
        return cad.vertexParameter(mesh.nodeCadIndex[node], index, near);
      };
      t.insert(t.begin(), endT(nodes.front(), t.front()));
      t.push_back(endT(nodes.back(), t.back()));
      if (!strictlyMonotone(t)) ++check.nonMonotone;
    } else if (dim == 2) {
      ++check.faceEdges;
      const FaceChart chart(cad, index);
      std::vector<FaceParameter> uv;
      for (std::size_t k = 1; k + 1 < nodes.size(); ++k) {
        FaceParameter q{mesh.nodeCadParam[2 * nodes[k]], mesh.nodeCadParam[2 * nodes[k] + 1]};
        uv.push_back(uv.empty() ? q : chart.unwrapNear(q, uv.back()));
      }
      if (!advancesAlongChord(uv)) ++check.nonMonotone;
    }
  }
  return check;
}

TEST(FaceNodePlacement, SphereAcrossItsSeamAndPoles) {
  const CadModel cad =
      CadModel::fromFile(std::string(HOMESH_SOURCE_DIR) + "/tests/data/sphere.brep");
  const Mesh linear = generateLinearMesh(cad, LinearMeshOptions::uniform(0.5));
  for (const int order : {4, 6}) {
    CurvingStats stats;
    const Mesh mesh = elevateOrder(linear, order, &cad, &stats);
    const EdgeCheck check = checkBoundary(mesh, cad);
    EXPECT_GT(check.curveEdges, 0u);  // the seam
    EXPECT_GT(check.faceEdges, 0u);
    EXPECT_EQ(check.nonMonotone, 0u);
    EXPECT_EQ(stats.faceEdgesProjected, 0u);
    EXPECT_EQ(stats.faceInteriorsProjected, 0u);
    EXPECT_GT(stats.faceInteriors, 0u);
    EXPECT_EQ(evaluateQuality(mesh).invalid, 0u) << "order " << order;
    const QualitySummary q = evaluateQuality(mesh);
    for (std::size_t e = 0; e < q.scaledJacobian.size(); ++e)
      std::printf("elem %zu sj %g\n", e, q.scaledJacobian[e]);
    for (std::size_t i = 0; i < mesh.numNodes(); ++i)
      std::printf("node %zu %g %g dim %d t %g\n", i, mesh.xyz[3 * i], mesh.xyz[3 * i + 1],
                  mesh.nodeCadDim[i], mesh.nodeCadParam[2 * i]);
  }
}

// A coarse triangulation of a whole torus's surface (a 3D mesh of boundary triangles only):
// an nu x nv grid in (u, v) placed off the seams, every cell split into two triangles, so
// that edges cross both seams.
Mesh torusSurfaceMesh(const CadModel& cad, int nu, int nv) {
  Mesh mesh;
  mesh.dim = 3;
  const SurfaceBounds b = cad.faceBounds(1);
  const double du = (b.uMax - b.uMin) / nu, dv = (b.vMax - b.vMin) / nv;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double u = b.uMin + (i + 0.5) * du, v = b.vMin + (j + 0.5) * dv;
      const Eigen::Vector3d x = cad.evaluateSurface(1, u, v).point;
      mesh.addNode(x.data(), 2, 1, u, v);
    }
  ElementBlock tris;
  tris.type = CellType::Triangle;
  const auto id = [&](int i, int j) { return static_cast<std::int64_t>(j % nv) * nu + i % nu; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::int64_t a = id(i, j), c = id(i + 1, j + 1);
      for (const std::int64_t n : {a, id(i + 1, j), c, a, c, id(i, j + 1)}) tris.nodes.push_back(n);
      tris.entity.insert(tris.entity.end(), 2, 1);
    }
  mesh.blocks.push_back(std::move(tris));
  return mesh;
}

TEST(FaceNodePlacement, CoarseTorusAcrossBothSeams) {
  // Edges span 90 degrees in u and v and cross both seams; the tube is thin, so the surface
  // bends strongly across an element.
  const CadModel cad = test::toModel(test::torus(1.0, 0.25));
  ASSERT_EQ(cad.numFaces(), 1);
  const Mesh linear = torusSurfaceMesh(cad, 4, 4);
  for (const int order : {4, 6}) {
    CurvingStats stats;
    const Mesh mesh = elevateOrder(linear, order, &cad, &stats);

    const EdgeCheck check = checkBoundary(mesh, cad);
    EXPECT_EQ(check.faceEdges, 48u);  // 3 edges per grid cell
    EXPECT_EQ(check.nonMonotone, 0u) << "order " << order;
    EXPECT_EQ(stats.faceEdges, 48u);
    EXPECT_EQ(stats.faceEdgesProjected, 0u);
    EXPECT_EQ(stats.faceInteriors, 32u);
    EXPECT_EQ(stats.faceInteriorsProjected, 0u);
  }
}

// A coarse planar mesh of the thin ellipse: a fan of triangles from the centre to seven nodes on
// the curve (the first is the curve's vertex, t = 0), one edge spanning the blunt nose at t = pi
// from pi - 0.5 to pi + 0.4 (like a thin aerofoil's leading edge between two coarse nodes).
Mesh ellipseFanMesh(const CadModel& cad) {
  Mesh mesh;
  mesh.dim = 2;
  const double centre[3] = {0.0, 0.0, 0.0};
  const SurfaceProjection c = cad.projectOnSurface(1, Eigen::Vector3d::Zero());
  mesh.addNode(centre, 2, 1, c.u, c.v);
  const double ts[] = {0.0, 1.0, 1.9, M_PI - 0.5, M_PI + 0.4, 4.4, 5.3};
  const int n = 7;
  for (int k = 0; k < n; ++k) {
    const double t = ts[k];
    const Eigen::Vector3d x = cad.evaluateCurve(1, t).point;
    if (k == 0) {
      mesh.addNode(x.data(), 0, 1, std::nan(""), std::nan(""));
    } else {
      mesh.addNode(x.data(), 1, 1, t, std::nan(""));
    }
  }
  ElementBlock tris, lines;
  tris.type = CellType::Triangle;
  lines.type = CellType::Line;
  for (int k = 0; k < n; ++k) {
    const std::int64_t a = 1 + k, b = 1 + (k + 1) % n;
    for (const std::int64_t id : {std::int64_t{0}, a, b}) tris.nodes.push_back(id);
    tris.entity.push_back(1);
    lines.nodes.push_back(a);
    lines.nodes.push_back(b);
    lines.entity.push_back(1);
  }
  mesh.blocks.push_back(std::move(tris));
  mesh.blocks.push_back(std::move(lines));
  return mesh;
}

TEST(CurveNodePlacement, CoarseThinNoseWherePlainProjectionFolds) {
  const CadModel cad = ellipseModel();
  ASSERT_EQ(cad.numVertices(), 1);
  const Mesh linear = ellipseFanMesh(cad);
  for (const int order : {4, 6}) {
    CurvingStats stats;
    const Mesh mesh = elevateOrder(linear, order, &cad, &stats);
    EXPECT_EQ(stats.curveEdges, 7u);
    EXPECT_EQ(stats.curveEdgesAtStart, 0u);
    // The previous placement, closest-point projection of the straight edge's nodes, folds
    // the nose edge's parameters; `projected` is the mesh it gives.
    Mesh projected = mesh;
    std::size_t folds = 0;
    for (const auto& [key, nodes] : meshEdges(mesh)) {
      if (mesh.nodeCadDim[nodes[1]] != 1) continue;
      const Eigen::Vector3d xa = nodePoint(mesh, key[0]), xb = nodePoint(mesh, key[1]);
      std::vector<double> t;
      for (int i = 1; i < order; ++i) {
        const CurveProjection p = cad.projectOnCurve(1, xa + (xb - xa) * (i / double(order)));
        t.push_back(p.t);
        for (int k = 0; k < 3; ++k) projected.xyz[3 * nodes[i] + k] = p.point[k];
      }
      const auto endT = [&](std::int64_t node, double near) {
        if (mesh.nodeCadDim[node] == 1) return mesh.nodeCadParam[2 * node];
        return cad.vertexParameter(mesh.nodeCadIndex[node], 1, near);
      };
      t.insert(t.begin(), endT(key[0], t.front()));
      t.push_back(endT(key[1], t.back()));
      if (!strictlyMonotone(t)) ++folds;
    }
    EXPECT_GT(folds, 0u) << "order " << order;
    // The new placement: monotone along every edge and on the curve. The nose element, a
    // sliver from the centre round a nose of radius 0.03, stays invalid at this coarseness, but
    // less so than with the folded projection.
    const EdgeCheck check = checkBoundary(mesh, cad);
    EXPECT_EQ(check.curveEdges, 7u);
    EXPECT_EQ(check.nonMonotone, 0u) << "order " << order;
    EXPECT_GT(evaluateQuality(mesh).scaled.min, evaluateQuality(projected).scaled.min);
  }
}

}  // namespace
}  // namespace homesh
