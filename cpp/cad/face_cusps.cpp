#include "cad/face_cusps.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An edge leaving a vertex: its unit direction there and the parameter at the vertex, with the
// sign of the parameter step that moves into the edge.
struct Leaving {
  int edge = 0;
  double t = 0.0, step = 0.0;  // step: the parameter range, signed towards the edge's inside
  Eigen::Vector3d direction;
  double length = 0.0;  // chord between the edge's ends (a scale, not the arc length)
};

std::optional<Leaving> leaving(const CadModel& cad, int edge, int vertex) {
  if (cad.isDegenerated(edge)) return std::nullopt;
  const ParameterRange range = cad.edgeRange(edge);
  Leaving l;
  l.edge = edge;
  l.t = cad.vertexParameter(vertex, edge);
  const bool atFirst = std::abs(l.t - range.first) <= std::abs(l.t - range.last);
  l.step = atFirst ? range.last - range.first : range.first - range.last;
  const Eigen::Vector3d d1 = cad.evaluateCurve(edge, l.t).d1;
  if (!(d1.norm() > 0.0)) return std::nullopt;
  l.direction = (l.step > 0.0 ? 1.0 : -1.0) * d1.normalized();
  l.length =
      (cad.evaluateCurve(edge, range.last).point - cad.evaluateCurve(edge, range.first).point)
          .norm();
  if (!(l.length > 0.0)) return std::nullopt;  // (closed edges are skipped before)
  return l;
}

// The point of the edge about `distance` from its vertex (a first-order step along its
// parameter, corrected once by the chord it gives).
Eigen::Vector3d pointAt(const CadModel& cad, const Leaving& l, double distance) {
  const Eigen::Vector3d start = cad.evaluateCurve(l.edge, l.t).point;
  const double speed = cad.evaluateCurve(l.edge, l.t).d1.norm();
  double dt = std::min(distance / speed, std::abs(l.step));
  Eigen::Vector3d p = cad.evaluateCurve(l.edge, l.t + std::copysign(dt, l.step)).point;
  const double chord = (p - start).norm();
  if (chord > 0.0) dt = std::min(dt * distance / chord, std::abs(l.step));
  return cad.evaluateCurve(l.edge, l.t + std::copysign(dt, l.step)).point;
}

}  // namespace

std::vector<FaceCusp> findFaceCusps(const CadModel& cad, double maxAngleDeg) {
  std::vector<FaceCusp> cusps;
  const double maxAngle = maxAngleDeg * kPi / 180.0;
  std::vector<std::vector<int>> endsOf(static_cast<std::size_t>(cad.numEdges()) + 1);
  for (int edge = 1; edge <= cad.numEdges(); ++edge)
    endsOf[static_cast<std::size_t>(edge)] = cad.subShapeIndices(1, edge, 0);
  for (int face = 1; face <= cad.numFaces(); ++face) {
    const std::vector<int> edges = cad.subShapeIndices(2, face, 1);
    for (const int vertex : cad.subShapeIndices(2, face, 0)) {
      std::vector<Leaving> around;
      for (const int edge : edges) {
        const std::vector<int>& ends = endsOf[static_cast<std::size_t>(edge)];
        if (std::find(ends.begin(), ends.end(), vertex) == ends.end()) continue;
        if (ends.size() == 1) continue;  // a closed edge meets itself: no corner
        if (const auto l = leaving(cad, edge, vertex)) around.push_back(*l);
      }
      for (std::size_t i = 0; i < around.size(); ++i)
        for (std::size_t j = i + 1; j < around.size(); ++j) {
          const Leaving& a = around[i];
          const Leaving& b = around[j];
          // (atan2 keeps the precision of small angles, which acos of the cosine loses.)
          const double angle =
              std::atan2(a.direction.cross(b.direction).norm(), a.direction.dot(b.direction));
          if (angle > maxAngle) continue;
          // The face between them near the vertex (a cusp), or all around (a slit)?
          const double reach = 0.05 * std::min(a.length, b.length);
          const Eigen::Vector3d mid = 0.5 * (pointAt(cad, a, reach) + pointAt(cad, b, reach));
          const SurfaceProjection foot = cad.projectOnSurface(face, mid);
          if (!cad.faceContains(face, cad.wrapIntoPeriod(face, foot.u, 0),
                                cad.wrapIntoPeriod(face, foot.v, 1)))
            continue;
          FaceCusp cusp;
          cusp.face = face;
          cusp.vertex = vertex;
          cusp.edgeA = std::min(a.edge, b.edge);
          cusp.edgeB = std::max(a.edge, b.edge);
          cusp.angleDeg = angle * 180.0 / kPi;
          cusps.push_back(cusp);
        }
    }
  }
  return cusps;
}

}  // namespace homesh
