// User refinement sources: regions where the mesh size may not exceed a given delta.
//
// A source acts in two places: the octree is refined inside it (so that the graded field around
// it is smooth and the element-count prediction sees it), and the query delta(x) takes the
// minimum with the source's delta wherever x lies inside it (so that the size there is exact).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace homesh {

class CadModel;

struct RefinementSource {
  // Segment: points within `radius` of the segment a-b (a capsule; a == b gives a ball).
  // Sphere: points within `radius` of a. Box: the axis-aligned box [a, b].
  // Curve: points within `radius` of CAD edge `edge` (1-based, FreeCAD's EdgeN); resolved to
  // segments by resolveCurveSources before use.
  enum class Kind { Segment, Sphere, Box, Curve };
  Kind kind = Kind::Segment;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double radius = 0.0;
  double delta = 0.0;  // the size inside (> 0)
  int edge = 0;

  static RefinementSource segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                                  double delta);
  static RefinementSource sphere(const Eigen::Vector3d& centre, double radius, double delta);
  static RefinementSource box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double delta);
  static RefinementSource curve(int edge, double radius, double delta);

  // Distance from x to the source's region (0 inside). Not for Curve (resolve it first).
  double distance(const Eigen::Vector3d& x) const;
  bool contains(const Eigen::Vector3d& x) const { return distance(x) <= 0.0; }
  // Whether the region meets the axis-aligned box centre +- half (conservative: may say yes
  // for a box that only comes close).
  bool mayMeetBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& half) const;

  // "segment (0, 0, 0)-(1, 0, 0) radius 0.1 delta 0.01", for messages and reports.
  std::string describe() const;
  // Throws ParameterError naming the source (`which`, e.g. "refinement source 2").
  void validate(const std::string& which) const;
};

// Replaces every Curve source by segments along a polyline of its CAD edge, close enough to the
// curve (chord error below a tenth of the radius) that the capsules cover the curve's
// neighbourhood. Throws CadError for a missing or degenerated edge.
std::vector<RefinementSource> resolveCurveSources(const std::vector<RefinementSource>& sources,
                                                  const CadModel& cad);

}  // namespace homesh
