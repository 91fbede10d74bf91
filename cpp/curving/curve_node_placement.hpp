// High-order nodes of a mesh edge that lies on a CAD curve, spaced in arc length.
//
// DESIGN.md section 5: the P-1 interior nodes of an edge from parameter ta to tb sit at the
// parameters t_1..t_{P-1} that minimise sum_i |c(t_{i+1}) - c(t_i)|^2 / (z_{i+1} - z_i), z being
// the element's reference node positions along the edge, subject to t strictly between ta and
// tb; the search starts from t linear in z. Unlike projecting the straight edge's points onto
// the curve, this cannot jump to another branch of a strongly curved curve: the result is checked
// strictly monotone and replaced by the (monotone) start where it is not.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// The parameter on CAD curve `edge` of mesh node `node`, an end of a mesh edge along it: its own
// t for a node on that curve (checked against its position), the vertex's parameter for a CAD
// vertex (the end of a closed curve nearer `near`), else its projection.
double nodeCurveParameter(const CadModel& cad, const Mesh& mesh, std::int64_t node, int edge,
                          std::optional<double> near);

struct CurvePlacement {
  std::vector<double> t;   // P+1 parameters, ends included
  bool optimised = false;  // false: the optimum was not monotone, t is the linear start
};

// A curve's offset in a plane: the points at signed distance `height` along the unit normal
// t x planeNormal (t the curve's unit tangent in increasing parameter).
struct CurveOffset {
  double height = 0.0;
  Eigen::Vector3d planeNormal = Eigen::Vector3d::UnitZ();
};

// The offset's point and first derivative (d2 left zero) where the curve has `c`; std::nullopt
// where c' is zero or along the plane normal.
std::optional<CurveDerivatives> offsetCurve(const CurveDerivatives& c, const CurveOffset& offset);

// Places the nodes between ta and tb (ta != tb) at reference positions z (z.front() = 0 <
// ... < z.back() = 1). With `offset`, the spacing is that of the nodes' images on the offset
// curve instead. Throws ParameterError for bad z or ta == tb.
CurvePlacement placeOnCurve(const CadModel& cad, int edge, double ta, double tb,
                            const std::vector<double>& z,
                            const std::optional<CurveOffset>& offset = std::nullopt);

// Whether the values strictly increase or strictly decrease.
bool strictlyMonotone(const std::vector<double>& t);

// The reference positions of the P+1 equispaced nodes of an order-P edge: i / P.
std::vector<double> equispacedPositions(int order);

}  // namespace homesh
