#include "boundary_layer/wall_segment_split.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "boundary_layer/layer_growth.hpp"
#include "linear/edge_split.hpp"

namespace homesh::layer_growth {
namespace {

// 2D: a wall segment on a layer curve whose CAD tangent turns by more than this between its
// ends (30 degrees, the turn at which a corner counts as sharp) is halved before the layer
// grows, up to kWallSplitPasses times. A cell whose wall turns further has a top arc that
// bulges far beyond its straight linear top into the triangles outside: T106's trailing edge
// (radius 0.0047 under a layer 0.053 thick) had cells turning 85 and 110 degrees and left
// triangles there invalid with the layer fixed (the release that followed cost the first layer
// 12 % of its height). Cells around such a tip stay slender whatever the split, min J / max J
// about R / (R + T) (0.08 there): the split does not make that worse.
constexpr double kMaxWallTurn = 0.8660254037844386;  // cosine of 30 degrees
constexpr int kWallSplitPasses = 3;

// The parameter between t0 and t1 where the curve's tangent has turned half way from `a` (its
// tangent at t0, towards t1) to `b` (at t1, away from t0): bisection on the difference of the
// two angles, which grows along a curve that turns one way.
double halfTurn(const CadModel& cad, int curve, double t0, double t1, const Vec& a, const Vec& b) {
  double lo = t0, hi = t1;
  for (int i = 0; i < 40; ++i) {
    const double m = 0.5 * (lo + hi);
    const Vec d = cad.evaluateCurve(curve, m).d1;
    const Vec tm = (t1 > t0 ? d : Vec(-d)).normalized();
    const double fromA = std::atan2(a.cross(tm).norm(), a.dot(tm));
    const double toB = std::atan2(tm.cross(b).norm(), tm.dot(b));
    (fromA < toB ? lo : hi) = m;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

int splitTightWallSegments(Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p) {
  const std::set<int> layer(p.faces.begin(), p.faces.end());
  int made = 0;
  for (int pass = 0; pass < kWallSplitPasses; ++pass) {
    std::vector<std::pair<MeshEdge, SplitNode>> splits;
    for (const ElementBlock& b : planar.blocks) {
      if (b.type != CellType::Line) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const int curve = b.entity[e];
        if (layer.count(curve) == 0) continue;
        const std::int64_t* l = b.element(e);
        double t[2];
        t[0] = parameterOnCurve(planar, cad, curve, l[0]);
        t[1] = parameterOnCurve(planar, cad, curve, l[1], t[0]);
        if (t[0] == t[1]) continue;
        const Vec a = curveTangent(cad, curve, t[0], t[1]);
        const Vec b1 = -curveTangent(cad, curve, t[1], t[0]);
        if (a.dot(b1) >= kMaxWallTurn) continue;
        const double m = halfTurn(cad, curve, t[0], t[1], a, b1);
        SplitNode node;
        node.point = cad.evaluateCurve(curve, m).point;
        node.cadDim = 1;
        node.cadIndex = curve;
        node.param0 = m;
        splits.emplace_back(meshEdge(l[0], l[1]), node);
      }
    }
    int now = 0;
    for (const auto& [edge, node] : splits) now += splitEdge(planar, edge, node) ? 1 : 0;
    made += now;
    if (now == 0) break;
  }
  return made;
}

}  // namespace homesh::layer_growth
