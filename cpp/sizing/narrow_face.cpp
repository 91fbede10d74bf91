#include "sizing/narrow_face.hpp"

#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>
#include <TopoDS_Edge.hxx>
#include <algorithm>
#include <cmath>
#include <limits>

#include "cad/cad_model.hpp"
#include "cad/occt_access.hpp"
#include "cad/occt_errors.hpp"

namespace homesh {

NarrowFaces::NarrowFaces(const CadModel& cad)
    : cad_(cad),
      across_(static_cast<std::size_t>(cad.numEdges()) + 1),
      boxLo_(across_.size(), Eigen::Vector3d::Zero()),
      boxHi_(across_.size(), Eigen::Vector3d::Zero()) {
  std::vector<std::vector<int>> vertices(across_.size());
  for (int e = 1; e <= cad.numEdges(); ++e) {
    vertices[e] = cad.subShapeIndices(1, e, 0);
    if (cad.isDegenerated(e)) continue;
    withOcctErrors("the bounding box of " + cadEntityName(1, e), [&] {
      Bnd_Box box;
      BRepBndLib::Add(occtEdge(cad, e), box, /*useTriangulation=*/false);
      if (box.IsVoid()) return;
      double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
      box.Get(x0, y0, z0, x1, y1, z1);
      boxLo_[e] = {x0, y0, z0};
      boxHi_[e] = {x1, y1, z1};
    });
  }
  const auto meets = [&](int a, int b) {
    for (const int v : vertices[a])
      if (std::find(vertices[b].begin(), vertices[b].end(), v) != vertices[b].end()) return true;
    return false;
  };
  for (int f = 1; f <= cad.numFaces(); ++f) {
    const std::vector<int> edges = cad.subShapeIndices(2, f, 1);
    for (const int a : edges) {
      if (cad.isDegenerated(a)) continue;
      for (const int b : edges)
        if (b != a && !cad.isDegenerated(b) && !meets(a, b) &&
            std::find(across_[a].begin(), across_[a].end(), b) == across_[a].end())
          across_[a].push_back(b);
    }
  }
}

double NarrowFaces::width(int edge, const Eigen::Vector3d& x, double reach) const {
  double best = std::numeric_limits<double>::infinity();
  for (const int b : across_[static_cast<std::size_t>(edge)]) {
    // The box test first: most edges across a face are farther than `reach`.
    const Eigen::Vector3d gap =
        (boxLo_[b] - x).cwiseMax(x - boxHi_[b]).cwiseMax(Eigen::Vector3d::Zero());
    if (gap.norm() > std::min(reach, best)) continue;
    const double d = cad_.projectOnCurve(b, x).distance;
    if (d <= reach) best = std::min(best, d);
  }
  return best;
}

double NarrowFaces::size(double radius, double width, double current,
                         const SizingParameters& params) {
  if (!(params.narrowFace > 0.0) || !(width < std::numeric_limits<double>::infinity()) ||
      !(radius > 0.0))
    return current;
  const double bound = chordSize(radius, std::min(1.0, params.narrowFace * width / radius));
  return bound < current ? std::max(bound, params.minDelta) : current;
}

double NarrowFaces::reach(double radius, double current, const SizingParameters& params) {
  if (!(params.narrowFace > 0.0)) return 0.0;
  // The sagitta of a chord `current` long on radius R (R itself beyond a half circle).
  const double half = 0.5 * current;
  const double sagitta = half < radius ? radius - std::sqrt(radius * radius - half * half) : radius;
  return 1.1 * sagitta / params.narrowFace;
}

}  // namespace homesh
