// The parts both boundary-layer growers share (internal to boundary_layer/: layer_grower_3d,
// layer_grower_2d, wall_segment_split): the constants they follow, node positions and points
// for messages, a node's parameter and a curve's tangent on the CAD, the shrink loop that
// lowers heights until no check flags a node, and the record of the heights grown.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "boundary_layer/layer_parameters.hpp"
#include "boundary_layer/layer_record.hpp"
#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/mesh.hpp"

namespace homesh::layer_growth {

using Vec = Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr int kNormalSmoothing = 10;  // relaxation passes of the growth directions
constexpr double kVisibility = 0.2;   // a direction must see every facet around it this much
// A layer face and a face without a layer whose CAD normals at a common node are within 6
// degrees (|cos| above this) meet tangentially: the layer cannot climb the other face there.
constexpr double kTangentFaces = 0.9945;
constexpr int kMaxShrinkPasses = 40;  // 0.7^40 ~ 6e-7: a layer that thin is no layer
constexpr double kShrinkStep = 0.7;   // height factor of a node flagged in a pass
constexpr double kGrading = 1.25;     // neighbouring heights differ at most by this ratio
// Every corner of a 3D macro prism: its Jacobian over the wall's area times the column's length
// (prismCornerQuality); a 2D quadrilateral's: its scaled Jacobian.
constexpr double kMinPrismCorner = 0.1;
constexpr double kRayReach = 2.5;  // thicknesses along the normal that must stay clear
// A column leaning from a layer face's normal is lengthened by 1 / cos of the lean, at most this
// much (a lean of 60 degrees): beyond, at sharper edges, it stays short of the thickness there.
constexpr double kMaxStretch = 2.0;
// Away from sharp edges, only a lean of more than 10 degrees (cos below this) is made up for: a
// smaller one is the discrete normal of a curved wall (the facets' angle, 8 degrees on NekMesh's
// 3d_bl_cyl), whose lengthening would overshoot the height measured along the CAD normal.
constexpr double kStretchLean = 0.985;

// Node i's position.
inline Vec at(const Mesh& m, std::int64_t i) {
  return {m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]};
}

// Throws ParameterError for a layer face (`faces`) that `cad` does not have, or that no
// boundary triangle of the mesh lies on (`meshed`: the faces some lie on).
void requireLayerFaces(const CadModel& cad, const std::vector<int>& faces,
                       const std::set<int>& meshed);

// "(x, y, z)" for messages.
std::string pointText(const Vec& x);

// Node `id`'s parameter on CAD curve `curve`: its own where it lies on that curve, the
// vertex's on the curve where it is a CAD vertex (the end nearest `near` on a closed curve),
// else its projection's.
double parameterOnCurve(const Mesh& mesh, const CadModel& cad, int curve, std::int64_t id,
                        std::optional<double> near = std::nullopt);

// The CAD curve's unit tangent at parameter t, pointing towards parameter `towards`: a chord a
// thousandth of the span long (not the derivative, which vanishes where the parametrisation
// does: the NACA splines' cosine spacing at their ends; shorter chords there drown in rounding).
Vec curveTangent(const CadModel& cad, int curve, double t, double towards);

// The power of kShrinkStep that the shrink loop's clearance rule (the normal, extended to
// kRayReach heights, must cross no other wall) would bring a height to, given `clearance`, the
// distance along the normal to the first wall it crosses, and `full`, the height asked: 1 when the
// height fits. Reached in one step, so that a layer far thicker than the space around it
// (a thickness of 1e9 in a unit box) leaves the loop's passes to the other rules.
double clearanceFactor(double clearance, double full);

// Grades the heights (Node: factor, full, neighbours): none more than kGrading times a
// neighbour's.
template <class Node>
void gradeHeights(std::vector<Node>& nodes) {
  for (bool changed = true; changed;) {
    changed = false;
    for (Node& w : nodes)
      for (const std::size_t n : w.neighbours) {
        const double cap = kGrading * nodes[n].factor * nodes[n].full;
        if (w.factor * w.full > cap * (1.0 + 1e-12)) {
          w.factor = cap / w.full;
          changed = true;
        }
      }
  }
}

// Shrinks the flagged wall nodes (Node: factor, full, neighbours) by kShrinkStep and grades the
// rest (gradeHeights; first of all too, when a node starts below its full height), re-placing
// every node with `placeAll`, until `offenders` (node index -> why) flags none. Returns the
// passes taken; throws MeshingError with `describe(node)` (where the layer is and the thickness
// asked there) after kMaxShrinkPasses.
template <class Node, class Offenders, class PlaceAll, class Describe>
int shrinkUntilClear(std::vector<Node>& nodes, Offenders offenders, PlaceAll placeAll,
                     Describe describe) {
  if (std::any_of(nodes.begin(), nodes.end(), [](const Node& w) { return w.factor < 1.0; }))
    gradeHeights(nodes);
  placeAll();
  for (int pass = 0;; ++pass) {
    const std::map<std::size_t, std::string> bad = offenders();
    if (bad.empty()) return pass;
    if (pass == kMaxShrinkPasses) {
      const Node& w = nodes[bad.begin()->first];
      throw MeshingError("the boundary layer on " + describe(w) + ": " + bad.begin()->second +
                         " even at " + formatNumber(w.factor) + " of its height");
    }
    for (const auto& [i, why] : bad) nodes[i].factor *= kShrinkStep;
    gradeHeights(nodes);
    placeAll();
  }
}

// The record's macro heights and per layer face or curve (`entity(node)`) its columns, how many
// were shrunk, the smallest factor and where, and the narrowest gap that held one down (Node:
// clearance, full; `asked(node)`: the thickness asked there; `across(node)`: the face or curve
// across), from the grown wall nodes.
template <class Node, class Entity, class Asked, class Across>
void recordHeights(BoundaryLayerRecord& record, const BoundaryLayerParameters& p, const Mesh& mesh,
                   const std::vector<Node>& nodes, Entity entity, Asked asked, Across across) {
  record.parameters = p;
  record.wallNodes = nodes.size();
  record.thicknessMin = std::numeric_limits<double>::infinity();
  record.thicknessMax = 0.0;
  std::map<int, LayerShrink> faces;
  for (const Node& w : nodes) {
    const double h = (w.top - at(mesh, w.id)).norm();
    record.thicknessMin = std::min(record.thicknessMin, h);
    record.thicknessMax = std::max(record.thicknessMax, h);
    LayerShrink& s = faces[entity(w)];
    s.face = entity(w);
    ++s.columns;
    const double allowed = clearanceFactor(w.clearance, w.full);
    if (across(w) != 0 && allowed < 1.0 && (s.gap.across == 0 || w.clearance < s.gap.width)) {
      const Vec x = at(mesh, w.id);
      s.gap = {w.clearance, across(w), {x.x(), x.y(), x.z()}, asked(w), allowed * asked(w)};
    }
    if (w.factor >= 0.999) continue;
    ++s.nodes;
    if (s.nodes == 1 || w.factor < s.factor) {
      s.factor = w.factor;
      const Vec x = at(mesh, w.id);
      s.where = {x.x(), x.y(), x.z()};
    }
  }
  record.faces.clear();
  for (auto& [face, s] : faces) record.faces.push_back(s);
}

}  // namespace homesh::layer_growth
