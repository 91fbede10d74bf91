#include "boundary_layer/layer_growth.hpp"

#include <cmath>
#include <sstream>

namespace homesh::layer_growth {

void requireLayerFaces(const CadModel& cad, const std::vector<int>& faces,
                       const std::set<int>& meshed) {
  const int nf = cad.numFaces();
  for (const int f : faces) {
    if (f > nf)
      throw ParameterError("boundary-layer face " + std::to_string(f) + " does not exist: " +
                           cad.sourceName() + " has " + std::to_string(nf) + " faces");
    if (meshed.count(f) == 0)
      throw ParameterError("boundary-layer face " + std::to_string(f) + " of " + cad.sourceName() +
                           " has no boundary triangles (not a face of the solid?)");
  }
}

std::string pointText(const Vec& x) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

double parameterOnCurve(const Mesh& mesh, const CadModel& cad, int curve, std::int64_t id,
                        std::optional<double> near) {
  const auto i = static_cast<std::size_t>(id);
  if (mesh.nodeCadDim[i] == 1 && mesh.nodeCadIndex[i] == curve &&
      std::isfinite(mesh.nodeCadParam[2 * i]))
    return mesh.nodeCadParam[2 * i];
  if (mesh.nodeCadDim[i] == 0) return cad.vertexParameter(mesh.nodeCadIndex[i], curve, near);
  return cad.projectOnCurve(curve, at(mesh, id)).t;
}

// The CAD curve's unit tangent at parameter t, pointing towards parameter `towards`: a chord a
// thousandth of the span long (not the derivative, which vanishes where the parametrisation
// does: the NACA splines' cosine spacing at their ends; shorter chords there drown in rounding).
Vec curveTangent(const CadModel& cad, int curve, double t, double towards) {
  const Vec d =
      cad.evaluateCurve(curve, t + 1e-3 * (towards - t)).point - cad.evaluateCurve(curve, t).point;
  return d.norm() > 0.0 ? Vec(d.normalized()) : Vec(Vec::Zero());
}

double clearanceFactor(double clearance, double full) {
  const double reach = kRayReach * full;
  if (!(clearance > 0.0) || !(clearance < reach)) return 1.0;
  return std::pow(kShrinkStep, std::ceil(std::log(clearance / reach) / std::log(kShrinkStep)));
}

}  // namespace homesh::layer_growth
