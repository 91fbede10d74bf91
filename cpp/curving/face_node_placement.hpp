// High-order nodes on a CAD face: edges inside the face and the interior of its triangles,
// placed in the face's (u, v) and evaluated through r(u, v), so every node lies on the surface.
//
// - A FaceChart gives the face's (u, v) a local, unwrapped view: values across a periodic seam
//   are shifted by whole periods next to a reference, poles (a parameter direction along which r
//   does not move, like u at a sphere's pole) are detected, and stored values are wrapped back
//   into the face's bounds.
// - Edge nodes minimise the spacing energy of curve_node_placement.hpp with points r(u_i, v_i),
//   which pulls them towards the geodesic between the ends (DESIGN.md section 5).
// - Triangle-interior nodes start from the discrete harmonic blend of the (curved) edge nodes in
//   (u, v), which reproduces the equispaced lattice of a straight triangle exactly, and relax the
//   spring energy of the node lattice measured on the surface, which keeps them spread.
// Every result is checked: edge nodes ordered along the edge in (u, v), lattice triangles not
// flipped on the surface (against its normal), every node inside the face's trimming. A failed
// optimum falls back to its start, a failed start to the caller (who projects).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "curving/spring_energy.hpp"

namespace homesh {

using FaceParameter = std::array<double, 2>;

class FaceChart {
 public:
  FaceChart(const CadModel& cad, int face);

  int face() const { return face_; }
  const CadModel& cad() const { return cad_; }
  // `uv` shifted by whole periods to the copy nearest `reference`.
  FaceParameter unwrapNear(FaceParameter uv, const FaceParameter& reference) const;
  // `uv` shifted by whole periods into the face's parameter bounds where it can be.
  FaceParameter wrap(FaceParameter uv) const;
  // Per direction: whether r does not move along it at uv (a pole, a cone's apex).
  std::array<bool, 2> singular(const FaceParameter& uv) const;
  // Whether uv (after wrapping) lies on the face, inside its trimming.
  bool contains(const FaceParameter& uv) const;
  MappedPoint map(const double* uv) const;
  Eigen::Vector3d point(const FaceParameter& uv) const;

 private:
  const CadModel& cad_;
  int face_;
  std::array<double, 2> period_;
  SurfaceBounds bounds_;
};

// (u, v) on the chart's face of mesh node `node`: its own (u, v) for a node on the face (checked
// against its position), through the curve's p-curve for a node on a bounding curve, else its
// projection (started from `near` when given). Not unwrapped.
FaceParameter nodeFaceParameter(const FaceChart& chart, const Mesh& mesh, std::int64_t node,
                                std::optional<FaceParameter> near);

struct FaceEdgePlacement {
  std::vector<FaceParameter> uv;  // P+1 unwrapped parameters, ends included
  bool optimised = false;         // false: uv is the start (linear in (u, v))
  bool valid = false;             // false: neither optimum nor start passed the checks
};

// Nodes of a mesh edge inside the face from `a` to `b` (unwrapped next to each other, poles
// resolved) at reference positions z; xa, xb are the end nodes' positions.
FaceEdgePlacement placeOnFaceEdge(const FaceChart& chart, const FaceParameter& a,
                                  const FaceParameter& b, const Eigen::Vector3d& xa,
                                  const Eigen::Vector3d& xb, const std::vector<double>& z);

// Resolves the ends of an edge inside the face: b unwrapped next to a, and a pole's undefined
// parameter taken from the other end.
std::array<FaceParameter, 2> edgeEnds(const FaceChart& chart, FaceParameter a, FaceParameter b);

// Whether the nodes advance strictly along the chord from the first to the last in (u, v).
bool advancesAlongChord(const std::vector<FaceParameter>& uv);

// The lattice of an order-P triangle: node (i, j), i, j >= 0, i + j <= P, is at barycentric
// weights (P - i - j, i, j) of corners 0, 1, 2; latticeIndex gives its position in the arrays.
inline int latticeIndex(int order, int i, int j) {
  return j * (order + 1) - j * (j - 1) / 2 + i;
}

struct TrianglePlacement {
  std::vector<FaceParameter> uv;  // all lattice nodes (boundary ones as given), unwrapped
  bool relaxed = false;           // false: the interior is the harmonic start
  bool valid = false;             // false: neither relaxed nor start passed the checks
};

// Interior nodes of an order-P triangle on the face from its boundary nodes' (u, v) (`uv`,
// lattice-indexed, unwrapped into one chart; interior entries ignored) and positions `x`
// (boundary entries used). A corner's (u, v) is not used (it may be a pole, where u is arbitrary).
TrianglePlacement placeTriangleInterior(const FaceChart& chart, int order,
                                        const std::vector<FaceParameter>& uv,
                                        const std::vector<Eigen::Vector3d>& x);

}  // namespace homesh
