#include "cad/face_apexes.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/error.hpp"

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Samples of the degenerate parameter over its range, and the step off the vertex along the
// other one (a share of its range).
constexpr int kSamples = 16;
constexpr double kStep = 1e-3;

}  // namespace

bool isFaceApex(const CadModel& cad, int face, int vertex) {
  try {
    const Eigen::Vector3d p = cad.vertexPoint(vertex);
    const SurfaceProjection at = cad.projectOnSurface(face, p);
    if (!(at.distance <= std::max(cad.tolerance(0, vertex), 1e-7 * cad.boundingDiagonal())))
      return false;
    const auto [uDegenerate, vDegenerate] = cad.evaluateSurface(face, at.u, at.v).degenerate();
    if (uDegenerate == vDegenerate) return false;  // regular (or no derivative at all)
    const SurfaceBounds b = cad.faceBounds(face);
    // Around the vertex: the degenerate parameter over its whole range, the other one stepped
    // off the vertex to the side where the face is.
    const double range[2] = {b.uMax - b.uMin, b.vMax - b.vMin};
    const int along = uDegenerate ? 0 : 1, off = 1 - along;
    const double lo[2] = {b.uMin, b.vMin};
    const double base[2] = {at.u, at.v};
    std::vector<Eigen::Vector3d> normals;
    for (const double sign : {1.0, -1.0}) {
      for (int k = 0; k < kSamples; ++k) {
        double uv[2];
        uv[along] = lo[along] + range[along] * (k + 0.5) / kSamples;
        uv[off] = base[off] + sign * kStep * range[off];
        if (!cad.faceContains(face, cad.wrapIntoPeriod(face, uv[0], 0),
                              cad.wrapIntoPeriod(face, uv[1], 1)))
          continue;
        const std::optional<Eigen::Vector3d> n =
            cad.evaluateSurface(face, uv[0], uv[1]).normalDirection();
        if (n) normals.push_back(n->normalized());
      }
      if (!normals.empty()) break;  // the face lies on this side
    }
    double spread = 0.0;
    for (std::size_t i = 0; i < normals.size(); ++i)
      for (std::size_t j = i + 1; j < normals.size(); ++j)
        spread = std::max(
            spread, std::atan2(normals[i].cross(normals[j]).norm(), normals[i].dot(normals[j])));
    return spread * 180.0 / kPi > kApexSpreadDeg;
  } catch (const CadError&) {
    return false;
  }
}

}  // namespace homesh
