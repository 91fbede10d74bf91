// Where a point lies on a CAD model: the lowest-dimensional entity (vertex, curve, face) within a
// tolerance of it, and which faces or curves a run of such places share. A mesh made elsewhere is
// put on the CAD with it, node by node (linear/cad_classification.hpp), and so is a curved
// mesh's boundary before its distance to the CAD is measured (quality/boundary_on_cad.hpp).
//
// A point lies on a vertex within tolerance + the vertex's own tolerance, else on a curve within
// tolerance + the curve's, else on a face within tolerance + the face's with its foot inside the
// face's trimming; the nearest wins within a dimension. Boxes around sampled points of each curve
// and face (grown by a quarter of their diagonal) skip the entities a point cannot be on.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cad/cad_model.hpp"

namespace homesh {

// "(x, y, z)" with formatNumber's digits: where a point is, for messages about points off the CAD.
std::string describePoint(const Eigen::Vector3d& p);

// An axis-aligned box around points, grown by a margin.
struct PointBox {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(std::numeric_limits<double>::lowest());
  void add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Grows each side by `fraction` of the diagonal plus `absolute`.
  void grow(double fraction, double absolute) {
    const double m = fraction * (hi - lo).norm() + absolute;
    lo.array() -= m;
    hi.array() += m;
  }
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};

// Where a point lies: dim -1 (nowhere), 0 vertex, 1 curve (u = t), 2 face (u, v); `point` is the
// foot on the entity, `distance` the point's distance to it.
struct CadPlace {
  int dim = -1, index = 0;
  double u = std::numeric_limits<double>::quiet_NaN();
  double v = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0.0;
};

class CadPointClassifier {
 public:
  // `tolerance`: absolute, added to each entity's own tolerance. Keeps a reference to `cad`.
  CadPointClassifier(const CadModel& cad, double tolerance);

  // The lowest-dimensional entity `p` lies on, or dim -1; `nearestFace` gets the nearest face
  // (0 when no face's box holds p) and its distance when p lies on no vertex or curve.
  CadPlace classify(const Eigen::Vector3d& p, std::pair<int, double>& nearestFace) const;
  // The faces (curves) a point on entity (dim, index) may belong to: the face itself, the faces
  // a curve bounds, the faces of a vertex's curves.
  std::set<int> facesOf(int dim, int index) const;
  std::set<int> edgesOf(int dim, int index) const;
  // The face every one of `places` (dim, index) may belong to, the one nearest `centre` when
  // several do; 0 when none does.
  int sharedFace(const std::vector<std::pair<int, int>>& places,
                 const Eigen::Vector3d& centre) const;
  // The non-degenerated curve both ends of the segment (a, b), on (dim, index) `ea` and `eb`, may
  // lie on whose distance to the segment's midpoint is least, if that distance is within 0.3 of
  // the segment's length plus the tolerance (a chord of an arc up to 120 degrees; a segment across
  // a face between two vertices of one curve, a cap of two half circles, lies 0.5 away); else 0.
  int sharedEdge(std::pair<int, int> ea, std::pair<int, int> eb, const Eigen::Vector3d& a,
                 const Eigen::Vector3d& b) const;

 private:
  const CadModel& cad_;
  double tol_;
  std::vector<PointBox> edgeBoxes_, faceBoxes_;
  std::vector<std::vector<int>> vertexEdges_, edgeFaces_;
};

}  // namespace homesh
