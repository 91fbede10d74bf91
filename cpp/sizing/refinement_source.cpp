#include "sizing/refinement_source.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {
namespace {

double segmentDistance(const Eigen::Vector3d& x, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (x - (a + t * ab)).norm();
}

std::string point(const Eigen::Vector3d& p) {
  return "(" + formatNumber(p.x()) + ", " + formatNumber(p.y()) + ", " + formatNumber(p.z()) + ")";
}

}  // namespace

RefinementSource RefinementSource::segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           double radius, double delta) {
  RefinementSource s;
  s.kind = Kind::Segment;
  s.a = a;
  s.b = b;
  s.radius = radius;
  s.delta = delta;
  return s;
}

RefinementSource RefinementSource::sphere(const Eigen::Vector3d& centre, double radius,
                                          double delta) {
  RefinementSource s = segment(centre, centre, radius, delta);
  s.kind = Kind::Sphere;
  return s;
}

RefinementSource RefinementSource::box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                       double delta) {
  RefinementSource s;
  s.kind = Kind::Box;
  s.a = lo;
  s.b = hi;
  s.delta = delta;
  return s;
}

RefinementSource RefinementSource::curve(int edge, double radius, double delta) {
  RefinementSource s;
  s.kind = Kind::Curve;
  s.edge = edge;
  s.radius = radius;
  s.delta = delta;
  return s;
}

double RefinementSource::distance(const Eigen::Vector3d& x) const {
  switch (kind) {
    case Kind::Segment:
    case Kind::Sphere:
      return std::max(0.0, segmentDistance(x, a, b) - radius);
    case Kind::Box: {
      const Eigen::Vector3d d = (a - x).cwiseMax(x - b).cwiseMax(0.0);
      return d.norm();
    }
    case Kind::Curve:
      break;
  }
  throw Error("a curve refinement source was used before it was resolved to segments");
}

bool RefinementSource::mayMeetBox(const Eigen::Vector3d& centre,
                                  const Eigen::Vector3d& half) const {
  if (kind == Kind::Box)
    return ((a - half).array() <= centre.array()).all() &&
           ((b + half).array() >= centre.array()).all();
  // The box lies within |half| of its centre.
  return distance(centre) <= half.norm();
}

std::string RefinementSource::describe() const {
  std::ostringstream out;
  switch (kind) {
    case Kind::Segment:
      out << "segment " << point(a) << "-" << point(b) << " radius " << formatNumber(radius);
      break;
    case Kind::Sphere:
      out << "sphere " << point(a) << " radius " << formatNumber(radius);
      break;
    case Kind::Box:
      out << "box " << point(a) << "-" << point(b);
      break;
    case Kind::Curve:
      out << "curve " << cadEntityName(1, edge) << " radius " << formatNumber(radius);
      break;
  }
  out << " delta " << formatNumber(delta);
  return out.str();
}

void RefinementSource::validate(const std::string& which) const {
  const auto fail = [&](const std::string& what) {
    throw ParameterError(which + " (" + describe() + "): " + what);
  };
  if (!(delta > 0.0) || !std::isfinite(delta)) fail("delta must be a positive number");
  if (!a.allFinite() || !b.allFinite()) fail("its points must be finite");
  if (kind == Kind::Box) {
    if (!(a.array() < b.array()).all())
      fail("the first corner must be below the second in x, y and z");
  } else if (!(radius > 0.0) || !std::isfinite(radius)) {
    fail("radius must be a positive number");
  }
  if (kind == Kind::Curve && edge < 1) fail("the edge number must be 1 or more");
}

std::vector<RefinementSource> resolveCurveSources(const std::vector<RefinementSource>& sources,
                                                  const CadModel& cad) {
  std::vector<RefinementSource> out;
  for (const RefinementSource& s : sources) {
    if (s.kind != RefinementSource::Kind::Curve) {
      out.push_back(s);
      continue;
    }
    if (s.edge > cad.numEdges())
      throw CadError("refinement source on " + cadEntityName(1, s.edge) + ": " + cad.sourceName() +
                     " has " + std::to_string(cad.numEdges()) + " edges");
    if (cad.isDegenerated(s.edge))
      throw CadError("refinement source on " + cadEntityName(1, s.edge) +
                     ": the edge is degenerated (a point)");
    // Refine the polyline until each chord stays within radius/10 of the curve (checked at
    // the chord midpoints), so the union of capsules covers the curve's neighbourhood.
    const ParameterRange range = cad.edgeRange(s.edge);
    std::vector<double> ts{range.first, range.last};
    for (int pass = 0; pass < 20; ++pass) {
      std::vector<double> next{ts.front()};
      bool refined = false;
      for (std::size_t i = 1; i < ts.size(); ++i) {
        const double tm = 0.5 * (ts[i - 1] + ts[i]);
        const Eigen::Vector3d pa = cad.evaluateCurve(s.edge, ts[i - 1]).point;
        const Eigen::Vector3d pb = cad.evaluateCurve(s.edge, ts[i]).point;
        const Eigen::Vector3d pm = cad.evaluateCurve(s.edge, tm).point;
        if ((pm - 0.5 * (pa + pb)).norm() > 0.1 * s.radius || ts.size() < 3) {
          next.push_back(tm);
          refined = true;
        }
        next.push_back(ts[i]);
      }
      ts.swap(next);
      if (!refined) break;
    }
    for (std::size_t i = 1; i < ts.size(); ++i)
      out.push_back(RefinementSource::segment(cad.evaluateCurve(s.edge, ts[i - 1]).point,
                                              cad.evaluateCurve(s.edge, ts[i]).point, s.radius,
                                              s.delta));
  }
  return out;
}

}  // namespace homesh
