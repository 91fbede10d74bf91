#include "sizing/boundary_sampling.hpp"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>

#include <Eigen/Geometry>

#include "cad/cad_model.hpp"
#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "sizing/narrow_face.hpp"
#include "sizing/sizing_parameters.hpp"

namespace homesh {
namespace {

constexpr int kCurvedSamples = 40;  // per direction on a curved entity, at least (as NekMesh)
constexpr int kMaxSamples = 400;    // per direction: bounds the cost of a huge, finely curved face
constexpr double kSpacing = 0.25;

// Size for curvature k (1/length), or 0 where the boundary is flat enough for maxDelta.
double sizeForCurvature(double k, const SizingParameters& params) {
  if (!(k > 0.0)) return 0.0;
  const double delta = chordSize(1.0 / k, params.eps);
  if (delta >= params.maxDelta) return 0.0;
  return std::max(delta, params.minDelta);
}

// Largest absolute principal curvature from the fundamental forms at a regular point.
// The mean curvature against du x dv and the largest absolute principal curvature.
std::pair<double, double> surfaceCurvatures(const SurfaceDerivatives& d) {
  const double E = d.du.dot(d.du), F = d.du.dot(d.dv), G = d.dv.dot(d.dv);
  const double det = E * G - F * F;
  if (!(det > 0.0)) return {0.0, 0.0};
  const Eigen::Vector3d n = d.du.cross(d.dv) / std::sqrt(det);
  const double L = d.duu.dot(n), M = d.duv.dot(n), N = d.dvv.dot(n);
  const double mean = (E * N - 2.0 * F * M + G * L) / (2.0 * det);
  const double gauss = (L * N - M * M) / det;
  return {mean, std::abs(mean) + std::sqrt(std::max(0.0, mean * mean - gauss))};
}

int samplesAlong(double length, double spacing, int atLeast) {
  const double n = std::ceil(length / spacing);
  return static_cast<int>(std::clamp(n, double(atLeast), double(kMaxSamples)));
}

double smallestSize(const std::vector<BoundarySample>& samples, const SizingParameters& params) {
  double smallest = params.maxDelta;
  for (const BoundarySample& s : samples)
    if (s.delta > 0.0) smallest = std::min(smallest, s.delta);
  return smallest;
}

// Physical length of a parameter line of a face (alongU: v fixed), from 16 chords.
// Length of the polyline through point(s) at s = 0, 1/16, ..., 1.
template <class F>
double chordLength(F&& point) {
  double length = 0.0;
  Eigen::Vector3d prev = point(0.0);
  for (int i = 1; i <= 16; ++i) {
    const Eigen::Vector3d p = point(i / 16.0);
    length += (p - prev).norm();
    prev = p;
  }
  return length;
}

// Physical length of a parameter line of a face (alongU: v fixed).
double isoLength(const CadModel& cad, int face, const SurfaceBounds& b, bool alongU, double fixed) {
  return chordLength([&](double s) {
    const double u = alongU ? b.uMin + s * (b.uMax - b.uMin) : fixed;
    const double v = alongU ? fixed : b.vMin + s * (b.vMax - b.vMin);
    return cad.evaluateSurface(face, u, v).point;
  });
}

double curveLength(const CadModel& cad, int edge, const ParameterRange& r) {
  return chordLength(
      [&](double s) { return cad.evaluateCurve(edge, r.first + s * (r.last - r.first)).point; });
}

// Which points of a (u, v) grid lie inside a trimmed face: the face's boundary in parameter
// space (its edges' p-curves, 64 chords each) against each grid row by the even-odd rule. One
// pass per row instead of a point-in-face test per point.
class FaceGridMask {
 public:
  FaceGridMask(const TopoDS_Face& face) {
    for (TopExp_Explorer x(face, TopAbs_EDGE); x.More(); x.Next()) {
      const TopoDS_Edge edge = TopoDS::Edge(x.Current());
      double first = 0.0, last = 0.0;
      const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(edge, face, first, last);
      if (pcurve.IsNull()) throw CadError("an edge of the face has no curve on the face");
      constexpr int kChords = 64;
      gp_Pnt2d prev = pcurve->Value(first);
      for (int i = 1; i <= kChords; ++i) {
        const gp_Pnt2d next = pcurve->Value(first + (last - first) * i / kChords);
        segments_.push_back({prev.X(), prev.Y(), next.X(), next.Y()});
        prev = next;
      }
    }
  }

  // inside[i] for the points (u[i], v) of one row.
  void row(double v, const std::vector<double>& u, std::vector<bool>& inside) const {
    crossings_.clear();
    for (const auto& s : segments_)
      if ((s[1] <= v) != (s[3] <= v))
        crossings_.push_back(s[0] + (v - s[1]) / (s[3] - s[1]) * (s[2] - s[0]));
    std::sort(crossings_.begin(), crossings_.end());
    inside.assign(u.size(), false);
    for (std::size_t i = 0; i < u.size(); ++i) {
      const auto below = std::upper_bound(crossings_.begin(), crossings_.end(), u[i]);
      inside[i] = (below - crossings_.begin()) % 2 == 1;
    }
  }

 private:
  std::vector<std::array<double, 4>> segments_;
  mutable std::vector<double> crossings_;
};

// One face's samples on an nu x nv grid of cell centres (never exactly on a seam or a pole).
std::vector<BoundarySample> faceGrid(const CadModel& cad, int face, const FaceGridMask& mask,
                                     int nu, int nv, bool internal,
                                     const SizingParameters& params) {
  const SurfaceBounds b = cad.faceBounds(face);
  const bool curved = !cad.isPlanar(face);
  const bool reversed = occtFace(cad, face).Orientation() == TopAbs_REVERSED;
  std::vector<BoundarySample> found;
  const double du = (b.uMax - b.uMin) / nu, dv = (b.vMax - b.vMin) / nv;
  std::vector<double> us(nu);
  std::vector<bool> inside;
  for (int i = 0; i < nu; ++i) us[i] = b.uMin + (i + 0.5) * du;
  for (int j = 0; j < nv; ++j) {
    const double v = b.vMin + (j + 0.5) * dv;
    mask.row(v, us, inside);
    for (int i = 0; i < nu; ++i) {
      if (!inside[i]) continue;
      const SurfaceDerivatives d = cad.evaluateSurface(face, us[i], v);
      const Eigen::Vector3d n = d.du.cross(d.dv);
      const double area = n.norm();
      if (!(area > 0.0)) continue;
      BoundarySample s;
      s.x = d.point;
      s.outward = (reversed ? -n : n) / area;
      s.weight = area * du * dv;
      s.spacing = std::hypot(d.du.norm() * du, d.dv.norm() * dv);
      s.internal = internal;
      s.cadIndex = face;
      if (curved) {
        const auto [mean, largest] = surfaceCurvatures(d);
        s.curvature = largest;
        s.meanCurvature = reversed ? -mean : mean;
        s.delta = sizeForCurvature(s.curvature, params);
      }
      found.push_back(s);
    }
  }
  return found;
}

// Physical lengths of a face's parameter lines (the longest of three in each direction).
std::pair<double, double> faceSpans(const CadModel& cad, int face) {
  const SurfaceBounds b = cad.faceBounds(face);
  double lu = 0.0, lv = 0.0;
  for (const double s : {0.0, 0.5, 1.0}) {
    lu = std::max(lu, isoLength(cad, face, b, true, b.vMin + s * (b.vMax - b.vMin)));
    lv = std::max(lv, isoLength(cad, face, b, false, b.uMin + s * (b.uMax - b.uMin)));
  }
  return {lu, lv};
}

// Samples a face with at most kSpacing times its smallest size (maxDelta where flat) between
// neighbours: a 40 x 40 grid first (curved faces), finer where that grid finds small sizes.
void sampleFace(const CadModel& cad, int face, bool internal, const SizingParameters& params,
                std::vector<BoundarySample>& out) {
  const auto [lu, lv] = faceSpans(cad, face);
  const bool curved = !cad.isPlanar(face);
  const int atLeast = curved ? kCurvedSamples : 2;
  const FaceGridMask mask(occtFace(cad, face));
  const double coarse = kSpacing * params.maxDelta;
  const int nu = samplesAlong(lu, coarse, atLeast), nv = samplesAlong(lv, coarse, atLeast);
  std::vector<BoundarySample> found = faceGrid(cad, face, mask, nu, nv, internal, params);
  if (curved) {
    const double spacing = kSpacing * smallestSize(found, params);
    const int fu = samplesAlong(lu, spacing, atLeast), fv = samplesAlong(lv, spacing, atLeast);
    if (fu > nu || fv > nv)
      found = faceGrid(cad, face, mask, std::max(fu, nu), std::max(fv, nv), internal, params);
  }
  out.insert(out.end(), found.begin(), found.end());
}

// The parameter intervals of a curve's samples: n equal ones, each halved while the curve's
// tangent turns by more than `turn` radians along it and it is longer than `shortest`. A
// uniform grid alone steps over a bend much tighter than the curve is long (T106's trailing
// edge, radius 0.0047 on a 1.5 long spline: 40 samples found none of it), and a size the
// samples never see is a size the mesh never gets.
std::vector<std::pair<double, double>> curveIntervals(const CadModel& cad, int edge,
                                                      const ParameterRange& r, int n, double turn,
                                                      double shortest) {
  constexpr int kMaxDepth = 16;  // a corner inside a curve (a C0 spline) stops here
  const auto tangent = [&](double t) -> Eigen::Vector3d {
    const Eigen::Vector3d d1 = cad.evaluateCurve(edge, t).d1;
    const double speed = d1.norm();
    return speed > 0.0 ? Eigen::Vector3d(d1 / speed) : Eigen::Vector3d::Zero();
  };
  std::vector<std::pair<double, double>> out;
  struct Pending {
    double a, b;
    Eigen::Vector3d ta, tb;
    int depth;
  };
  const double dt = (r.last - r.first) / n;
  Eigen::Vector3d previous = tangent(r.first);
  for (int i = 0; i < n; ++i) {
    const double a = r.first + i * dt, b = i + 1 == n ? r.last : r.first + (i + 1) * dt;
    const Eigen::Vector3d next = tangent(b);
    std::vector<Pending> stack{{a, b, previous, next, 0}};
    previous = next;
    while (!stack.empty()) {
      const Pending p = stack.back();
      stack.pop_back();
      const double angle = p.ta.isZero() || p.tb.isZero()
                               ? 0.0
                               : std::atan2(p.ta.cross(p.tb).norm(), p.ta.dot(p.tb));
      const double length =
          (cad.evaluateCurve(edge, p.b).point - cad.evaluateCurve(edge, p.a).point).norm();
      if (angle <= turn || length <= shortest || p.depth >= kMaxDepth) {
        out.emplace_back(p.a, p.b);
        continue;
      }
      const double m = 0.5 * (p.a + p.b);
      const Eigen::Vector3d tm = tangent(m);
      stack.push_back({m, p.b, tm, p.tb, p.depth + 1});  // popped after the first half
      stack.push_back({p.a, m, p.ta, tm, p.depth + 1});
    }
  }
  return out;
}

// Samples of a curve; with `normal` (2D: the face's oriented normal) they bound the domain.
// In 3D, `narrow` (when given) bounds the size where the curve's faces are narrow.
void sampleCurve(const CadModel& cad, int edge, bool reversed, const Eigen::Vector3d* normal,
                 bool internal, const SizingParameters& params, const NarrowFaces* narrow,
                 std::vector<BoundarySample>& out) {
  const ParameterRange r = cad.edgeRange(edge);
  const double length = curveLength(cad, edge, r);
  // A sample stands for at most kSpacing times the size its curvature asks for: along a
  // radius R that is an arc turning kSpacing chordSize(R, eps) / R radians, whatever R is.
  const double turn = kSpacing * chordSize(1.0, params.eps);
  const double shortest = kSpacing * params.minDelta;
  const auto along = [&](int n) {
    std::vector<BoundarySample> found;
    for (const auto& [a, b] : curveIntervals(cad, edge, r, n, turn, shortest)) {
      const double dt = b - a;
      const double t = 0.5 * (a + b);
      const CurveDerivatives d = cad.evaluateCurve(edge, t);
      const double speed = d.d1.norm();
      if (!(speed > 0.0)) continue;
      BoundarySample s;
      s.x = d.point;
      s.curvature = d.d1.cross(d.d2).norm() / (speed * speed * speed);
      s.delta = sizeForCurvature(s.curvature, params);
      s.spacing = speed * dt;
      s.internal = internal;
      s.cadIndex = edge;
      if (normal != nullptr) {
        // The face lies on the left of its oriented edges, seen from its oriented normal.
        const Eigen::Vector3d tangent = (reversed ? -d.d1 : d.d1) / speed;
        s.outward = tangent.cross(*normal).normalized();
        s.weight = speed * dt;
      } else {
        if (narrow != nullptr && s.curvature > 0.0) {
          const double radius = 1.0 / s.curvature;
          const double current = s.delta > 0.0 ? s.delta : params.maxDelta;
          const double width =
              narrow->width(edge, s.x, NarrowFaces::reach(radius, current, params));
          const double bounded = NarrowFaces::size(radius, width, current, params);
          if (bounded < current) {
            s.delta = bounded;
            s.narrowFace = true;
          }
        }
        if (s.delta <= 0.0) continue;  // a 3D curve only contributes sizes
      }
      found.push_back(s);
    }
    return found;
  };
  const double coarse = kSpacing * params.maxDelta;
  const int n = samplesAlong(length, coarse, kCurvedSamples);
  std::vector<BoundarySample> found = along(n);
  const double spacing = kSpacing * smallestSize(found, params);
  if (spacing < coarse) {
    const int fine = samplesAlong(length, spacing, kCurvedSamples);
    if (fine > n) found = along(fine);
  }
  out.insert(out.end(), found.begin(), found.end());
}

}  // namespace

std::vector<BoundarySample> sampleBoundary(const CadModel& cad, int dim,
                                           const SizingParameters& params) {
  std::vector<BoundarySample> samples;
  withOcctErrors("sampling " + cad.sourceName(), [&] {
    if (dim == 3) {
      std::vector<int> solidsOfFace(cad.numFaces() + 1, 0);
      for (int s = 1; s <= cad.numSolids(); ++s)
        for (const int f : cad.subShapeIndices(3, s, 2)) ++solidsOfFace[f];
      for (int f = 1; f <= cad.numFaces(); ++f)
        sampleFace(cad, f, solidsOfFace[f] != 1, params, samples);
      std::optional<NarrowFaces> narrow;
      if (params.narrowFace > 0.0) narrow.emplace(cad);
      for (int e = 1; e <= cad.numEdges(); ++e)
        if (!cad.isDegenerated(e))
          sampleCurve(cad, e, false, nullptr, false, params, narrow ? &*narrow : nullptr, samples);
      return;
    }
    std::map<int, int> facesOfEdge;
    for (int f = 1; f <= cad.numFaces(); ++f)
      for (const int e : cad.subShapeIndices(2, f, 1)) ++facesOfEdge[e];
    for (int f = 1; f <= cad.numFaces(); ++f) {
      const Eigen::Vector3d normal = cad.plane(f).second;  // oriented like the face
      const TopoDS_Face face = occtFace(cad, f);
      const std::vector<int> edges = cad.subShapeIndices(2, f, 1);
      for (TopExp_Explorer x(face, TopAbs_EDGE); x.More(); x.Next()) {
        const TopoDS_Edge edge = TopoDS::Edge(x.Current());
        if (BRep_Tool::Degenerated(edge)) continue;
        for (const int e : edges)
          if (occtEdge(cad, e).IsSame(edge)) {
            const bool internal = facesOfEdge[e] != 1;
            // An internal curve is sampled once, from its first face.
            if (internal && facesOfEdge[e] < 0) break;
            sampleCurve(cad, e, edge.Orientation() == TopAbs_REVERSED, &normal, internal, params,
                        nullptr, samples);
            if (internal) facesOfEdge[e] = -1;
            break;
          }
      }
    }
  });
  return samples;
}

}  // namespace homesh
