#include "boundary_layer/layer_grower_2d.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "boundary_layer/layer_growth.hpp"
#include "core/error.hpp"
#include "core/expression.hpp"

namespace homesh::layer_growth {
namespace {

// 2D: a wall node where the normals of the two layer curves meeting there spread by more than
// 30 degrees (cosine below this) at a convex corner (a sharp trailing edge) gets a fan of
// columns instead of one along the bisector, each fan triangle at most kFanStep wide.
constexpr double kFanSpread = 0.866;
constexpr double kFanStep = 40.0 * 3.14159265358979323846 / 180.0;

// The 2D layer: quadrilaterals grown from chosen CAD curves of a planar triangle mesh, the
// rest refilled with triangles. The same steps as in 3D, one dimension down: a wall node on a
// curve without a layer climbs it, and the climb becomes a line of that curve.
class LayerGrower2D {
 public:
  LayerGrower2D(const Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p,
                BoundaryLayerRecord& record)
      : cad_(cad),
        p_(p),
        record_(record),
        thickness_(Expression::parse(p.thickness, "boundary-layer thickness")),
        normal_(planar.planeNormal[0], planar.planeNormal[1], planar.planeNormal[2]) {
    extract(planar);
  }

  Mesh run(const LinearMeshOptions& fill) {
    directions();
    fitToClearance();
    shrink();
    return assemble(fill);
  }

 private:
  struct WallNode {
    std::int64_t id = 0;
    int curve = 0;      // a layer curve through the node (for the report)
    int sideCurve = 0;  // the curve without a layer it climbs (0: none)
    Vec d = Vec::Zero();
    double full = 0.0, factor = 1.0;
    Vec top = Vec::Zero();
    double t = kNaN;  // the top's parameter on sideCurve
    std::vector<std::size_t> neighbours;
    std::vector<Vec> inward;        // inward unit normals of its wall segments
    std::vector<std::size_t> segs;  // its wall segments
    // A fan (a sharp convex corner between two wall segments): the directions from the first
    // segment's curve normal (fan.front(), used by that segment's cell) to the second's
    // (fan.back()), the segments in that order and the tops; empty elsewhere. `d` is then the
    // bisector (the neighbours' relaxation uses the fan's end on their side).
    std::vector<Vec> fan, fanTops;
    std::array<std::size_t, 2> fanSegs{};
    // Along its directions, the distance to the first other boundary segment, and its curve (0:
    // none within kRayReach heights asked).
    double clearance = std::numeric_limits<double>::infinity();
    int clearanceCurve = 0;
  };
  using Seg = std::array<std::int64_t, 2>;

  const CadModel& cad_;
  const BoundaryLayerParameters& p_;
  BoundaryLayerRecord& record_;
  Expression thickness_;
  Vec normal_;
  Mesh out_;
  int face_ = 1;
  std::vector<Seg> wallSegs_, sideSegs_;
  std::vector<int> wallCurve_, sideCurve_;
  std::vector<WallNode> wall_;
  std::map<std::int64_t, std::size_t> wallIndex_;
  std::vector<Vec> wallInward_;  // per wall segment, its inward unit normal

  std::string where(const WallNode& w) const { return pointText(at(out_, w.id)); }

  void extract(const Mesh& planar) {
    std::set<int> faces;
    for (const ElementBlock& b : planar.blocks)
      if (b.type == CellType::Triangle) faces.insert(b.entity.begin(), b.entity.end());
    if (faces.size() != 1)
      throw ParameterError("2D boundary layers need a model with one face; " + cad_.sourceName() +
                           " has " + std::to_string(faces.size()));
    face_ = *faces.begin();
    const int ne = cad_.numEdges();
    std::set<int> layer;
    for (const int f : p_.faces) {
      if (f > ne)
        throw ParameterError("boundary-layer curve " + std::to_string(f) +
                             " does not exist: " + cad_.sourceName() + " has " +
                             std::to_string(ne) + " edges (a 2D layer grows from curves, EdgeN)");
      layer.insert(f);
    }
    // Each boundary segment's inward side: the third vertex of its triangle.
    std::map<Seg, std::int64_t> opposite;
    for (const ElementBlock& b : planar.blocks)
      if (b.type == CellType::Triangle)
        for (std::size_t e = 0; e < b.count(); ++e) {
          const std::int64_t* t = b.element(e);
          for (int k = 0; k < 3; ++k) {
            Seg s{t[k], t[(k + 1) % 3]};
            std::sort(s.begin(), s.end());
            opposite[s] = t[(k + 2) % 3];
          }
        }
    std::vector<std::int64_t> newId(planar.numNodes(), -1);
    out_.dim = 2;
    out_.order = 1;
    out_.planeNormal = planar.planeNormal;
    for (std::size_t i = 0; i < planar.numNodes(); ++i)
      if (planar.nodeCadDim[i] < 2)
        newId[i] = out_.addNode(&planar.xyz[3 * i], planar.nodeCadDim[i], planar.nodeCadIndex[i],
                                planar.nodeCadParam[2 * i], planar.nodeCadParam[2 * i + 1]);
    std::set<int> seen;
    std::vector<Vec> inward;
    for (const ElementBlock& b : planar.blocks) {
      if (b.type != CellType::Line) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* l = b.element(e);
        const Seg s{newId[static_cast<std::size_t>(l[0])], newId[static_cast<std::size_t>(l[1])]};
        if (s[0] < 0 || s[1] < 0) throw MeshingError("a boundary line uses a node inside the face");
        if (layer.count(b.entity[e]) == 0) {
          sideSegs_.push_back(s);
          sideCurve_.push_back(b.entity[e]);
          continue;
        }
        Seg key{l[0], l[1]};
        std::sort(key.begin(), key.end());
        const auto it = opposite.find(key);
        if (it == opposite.end()) throw MeshingError("a boundary line has no triangle");
        const Vec a = at(planar, l[0]), t = at(planar, l[1]) - a;
        Vec n = normal_.cross(t).normalized();
        if (n.dot(at(planar, it->second) - a) < 0.0) n = -n;
        wallSegs_.push_back(s);
        wallCurve_.push_back(b.entity[e]);
        inward.push_back(n);
        seen.insert(b.entity[e]);
      }
    }
    for (const int f : layer)
      if (seen.count(f) == 0)
        throw ParameterError("boundary-layer curve " + std::to_string(f) + " of " +
                             cad_.sourceName() + " has no boundary lines (not on the face?)");
    for (std::size_t s = 0; s < wallSegs_.size(); ++s)
      for (const std::int64_t v : wallSegs_[s]) {
        const auto [it, fresh] = wallIndex_.emplace(v, wall_.size());
        if (fresh) {
          WallNode w;
          w.id = v;
          w.curve = wallCurve_[s];
          wall_.push_back(w);
        }
        wall_[it->second].inward.push_back(inward[s]);
        wall_[it->second].segs.push_back(s);
      }
    wallInward_ = std::move(inward);
    for (const Seg& s : wallSegs_) {
      wall_[wallIndex_.at(s[0])].neighbours.push_back(wallIndex_.at(s[1]));
      wall_[wallIndex_.at(s[1])].neighbours.push_back(wallIndex_.at(s[0]));
    }
    for (std::size_t s = 0; s < sideSegs_.size(); ++s)
      for (int k = 0; k < 2; ++k) {
        const auto it = wallIndex_.find(sideSegs_[s][static_cast<std::size_t>(k)]);
        if (it == wallIndex_.end()) continue;
        WallNode& w = wall_[it->second];
        if (w.sideCurve != 0 && w.sideCurve != sideCurve_[s])
          throw MeshingError("no boundary layer can grow at " + where(w) + ": Edge" +
                             std::to_string(w.sideCurve) + " and Edge" +
                             std::to_string(sideCurve_[s]) + ", which have no layer, meet there");
        w.sideCurve = sideCurve_[s];
        // The climb's direction: along the side segment, away from the node.
        w.d =
            (at(out_, sideSegs_[s][static_cast<std::size_t>(1 - k)]) - at(out_, w.id)).normalized();
      }
  }

  double visibility(const WallNode& w, const Vec& d) const {
    double worst = 1.0;
    for (const Vec& n : w.inward) worst = std::min(worst, n.dot(d));
    return worst;
  }

  void directions() {
    for (WallNode& w : wall_) {
      if (w.sideCurve != 0) {
        if (visibility(w, w.d) < 1.0 - kTangentFaces)
          throw MeshingError("no boundary layer can grow at " + where(w) + " on Edge" +
                             std::to_string(w.curve) + ": it meets Edge" +
                             std::to_string(w.sideCurve) +
                             ", which has no layer, (nearly) tangentially; put the layer on "
                             "that curve too");
        continue;
      }
      Vec sum = Vec::Zero();
      for (const Vec& n : w.inward) sum += n;
      w.d = sum.normalized();
      makeFan(w);
    }
    for (int pass = 0; pass < kNormalSmoothing; ++pass) {
      std::vector<Vec> next(wall_.size());
      for (std::size_t i = 0; i < wall_.size(); ++i) {
        const WallNode& w = wall_[i];
        Vec sum = w.d;
        for (const std::size_t n : w.neighbours) sum += towards(n, i);
        const Vec d = sum.normalized();
        next[i] = w.sideCurve == 0 && w.fan.empty() &&
                          visibility(w, d) >= std::min(kVisibility, visibility(w, w.d))
                      ? d
                      : w.d;
      }
      for (std::size_t i = 0; i < wall_.size(); ++i) wall_[i].d = next[i];
    }
    // Inside a layer curve the wall is smooth: the curve's own normal there is the direction
    // the curved wall will have, so the layer's height holds along it once curved (the
    // segments' mean, relaxed, leaned by up to 49 degrees at the NACA 0012's coarse nose, and
    // the first layer's height fell by up to 22 % there). In 3D the same on the cylinder's
    // faces left an element invalid at order 4: not done there.
    // The same where two layer curves meet smoothly (the NACA's leading edge): their normals'
    // mean.
    for (WallNode& w : wall_) {
      const auto id = static_cast<std::size_t>(w.id);
      if (w.sideCurve != 0 || !w.fan.empty() || w.segs.size() != 2 || out_.nodeCadDim[id] != 0)
        continue;
      const std::optional<Vec> n0 = curveNormal(w, w.segs[0]), n1 = curveNormal(w, w.segs[1]);
      if (!n0 || !n1 || n0->dot(*n1) < kFanSpread) continue;
      const Vec n = (*n0 + *n1).normalized();
      if (visibility(w, n) >= std::min(kVisibility, visibility(w, w.d))) w.d = n;
    }
    for (WallNode& w : wall_) {
      const auto id = static_cast<std::size_t>(w.id);
      if (w.sideCurve != 0 || !w.fan.empty() || out_.nodeCadDim[id] != 1 ||
          !std::isfinite(out_.nodeCadParam[2 * id]))
        continue;
      const CurveDerivatives c =
          cad_.evaluateCurve(out_.nodeCadIndex[id], out_.nodeCadParam[2 * id]);
      Vec n = normal_.cross(c.d1);
      if (!(n.norm() > 0.0)) continue;
      n.normalize();
      if (n.dot(w.d) < 0.0) n = -n;
      if (visibility(w, n) >= std::min(kVisibility, visibility(w, w.d))) w.d = n;
    }
    for (WallNode& w : wall_) {
      const Vec x = at(out_, w.id);
      w.full = thickness_(x.x(), x.y(), x.z());
      if (!(w.full > 0.0) || !std::isfinite(w.full))
        throw ParameterError("boundary-layer thickness '" + p_.thickness + "' is " +
                             formatNumber(w.full) + " at " + where(w) + " on Edge" +
                             std::to_string(w.curve) +
                             ": it must be positive on every layer curve");
    }
  }

  // The unit normal of wall segment s's CAD curve at its node w, on the face's side (nullopt
  // where the projection fails). The side comes from the segment's inward normal and which way
  // the curve runs from w to the segment's other node, by their parameters: the segment's chord
  // itself may turn away from the curve's tangent at w by more than a right angle (around
  // T106's trailing edge, whose radius is a fraction of a segment).
  std::optional<Vec> curveNormal(const WallNode& w, std::size_t s) const {
    const Seg& seg = wallSegs_[s];
    const std::int64_t other = seg[0] == w.id ? seg[1] : seg[0];
    const int curve = wallCurve_[s];
    try {
      const double to = parameterOnCurve(out_, cad_, curve, other);
      const double t = parameterOnCurve(out_, cad_, curve, w.id, to);
      const Vec tangent = curveTangent(cad_, curve, t, to);  // from w into the curve
      Vec n = normal_.cross(tangent);
      if (!(n.norm() > 0.0) || to == t) return std::nullopt;
      n.normalize();
      // The face lies on the same side of the curve as of the segment from w to its other node.
      const double side = normal_.cross(at(out_, other) - at(out_, w.id)).dot(wallInward_[s]);
      return side < 0.0 ? Vec(-n) : n;
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }

  // A fan at a node between two wall segments whose curves' normals spread by more than
  // kFanSpread where the wall turns away from the layer (convex): directions rotating from one
  // normal to the other through the bisector, ceil(angle / kFanStep) triangles.
  void makeFan(WallNode& w) const {
    if (w.sideCurve != 0 || w.segs.size() != 2 ||
        wallCurve_[w.segs[0]] == wallCurve_[w.segs[1]])  // a fan joins two curves
      return;
    const std::optional<Vec> n0 = curveNormal(w, w.segs[0]), n1 = curveNormal(w, w.segs[1]);
    if (!n0 || !n1) return;
    const std::array<Vec, 2> n{*n0, *n1};
    const double c = std::clamp(n[0].dot(n[1]), -1.0, 1.0);
    // At a cusp (normals opposite) no rotation is singled out: no fan.
    if (c >= kFanSpread || n[0].cross(n[1]).norm() < 1e-6) return;
    const Seg& first = wallSegs_[w.segs[0]];
    const Vec along = at(out_, first[0] == w.id ? first[1] : first[0]) - at(out_, w.id);
    if (n[1].dot(along) >= 0.0) return;  // concave: the columns converge, no fan
    const double angle = std::acos(c);
    const int k = static_cast<int>(std::ceil(angle / kFanStep));
    const Vec axis = n[0].cross(n[1]).normalized();
    w.fan.clear();
    for (int j = 0; j <= k; ++j) w.fan.push_back(Eigen::AngleAxisd(angle * j / k, axis) * n[0]);
    w.fan.back() = n[1];
    w.fanSegs = {w.segs[0], w.segs[1]};
    w.d = (n[0] + n[1]).normalized();
  }

  // The direction wall node n lends the relaxation of its neighbour i: its own, or at a fan the
  // fan's end on i's side.
  Vec towards(std::size_t n, std::size_t i) const {
    const WallNode& w = wall_[n];
    if (w.fan.empty()) return w.d;
    for (int j = 0; j < 2; ++j) {
      const Seg& s = wallSegs_[w.fanSegs[static_cast<std::size_t>(j)]];
      if (s[0] == wall_[i].id || s[1] == wall_[i].id) return j == 0 ? w.fan.front() : w.fan.back();
    }
    return w.d;
  }

  // The top of wall node w in the cell of wall segment s (at a fan: its end on s's side).
  const Vec& topIn(const WallNode& w, std::size_t s) const {
    if (w.fan.empty()) return w.top;
    return s == w.fanSegs[0] ? w.fanTops.front() : w.fanTops.back();
  }

  void place(WallNode& w) const {
    const Vec target = at(out_, w.id) + w.factor * w.full * w.d;
    w.fanTops.clear();
    for (const Vec& d : w.fan) w.fanTops.emplace_back(at(out_, w.id) + w.factor * w.full * d);
    if (w.sideCurve == 0) {
      w.top = target;
      return;
    }
    const CurveProjection proj = cad_.projectOnCurve(w.sideCurve, target);
    w.top = proj.point;
    w.t = proj.t;
  }

  // Corner Jacobians of the quadrilateral (a, b, B, A) in the plane, scaled, smallest.
  double quadCorners(const Vec& a, const Vec& b, const Vec& tb, const Vec& ta) const {
    const std::array<Vec, 4> v{a, b, tb, ta};
    double worst = 1.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec e1 = v[(k + 1) % 4] - v[k], e2 = v[(k + 3) % 4] - v[k];
      const double scale = e1.norm() * e2.norm();
      worst = std::min(worst, scale > 0.0 ? e1.cross(e2).dot(normal_) / scale : -1.0);
    }
    return worst;
  }

  std::map<std::size_t, std::string> offenders() const {
    std::map<std::size_t, std::string> bad;
    for (std::size_t si = 0; si < wallSegs_.size(); ++si) {
      const Seg& s = wallSegs_[si];
      const std::size_t i = wallIndex_.at(s[0]), j = wallIndex_.at(s[1]);
      const Vec a = at(out_, s[0]), b = at(out_, s[1]);
      const Vec &ta = topIn(wall_[i], si), &tb = topIn(wall_[j], si);
      double q = quadCorners(a, b, tb, ta);
      q = std::max(q, quadCorners(b, a, ta, tb));  // either orientation
      if (q < kMinPrismCorner)
        for (const std::size_t n : {i, j}) bad.emplace(n, "a quadrilateral folds");
    }
    for (std::size_t s = 0; s < sideSegs_.size(); ++s)
      for (int k = 0; k < 2; ++k) {
        const auto it = wallIndex_.find(sideSegs_[s][static_cast<std::size_t>(k)]);
        if (it == wallIndex_.end() || wall_[it->second].sideCurve != sideCurve_[s]) continue;
        const Vec v = at(out_, sideSegs_[s][static_cast<std::size_t>(k)]);
        const Vec w = at(out_, sideSegs_[s][static_cast<std::size_t>(1 - k)]);
        if ((w - wall_[it->second].top).dot(w - v) < 0.3 * (w - v).squaredNorm())
          bad.emplace(it->second, "the layer reaches past the next node of Edge" +
                                      std::to_string(sideCurve_[s]));
      }
    // The normal, extended, must not cross a boundary segment that is not around the node.
    std::vector<Seg> all = wallSegs_;
    all.insert(all.end(), sideSegs_.begin(), sideSegs_.end());
    for (std::size_t i = 0; i < wall_.size(); ++i) {
      const WallNode& w = wall_[i];
      const Vec p = at(out_, w.id);
      for (const Vec& top : w.fan.empty() ? std::vector<Vec>{w.top} : w.fanTops) {
        const Vec q = p + kRayReach * (top - p);
        const std::optional<int> reached = crossedCurve(w, p, q, all);
        if (reached) {
          bad.emplace(i, "the layer would reach Edge" + std::to_string(*reached));
          break;
        }
      }
    }
    return bad;
  }

  // The curve of the first boundary segment of `all` (wall segments, then side segments) that the
  // ray p -> q crosses, but those around wall node w and the side curve it climbs.
  std::optional<int> crossedCurve(const WallNode& w, const Vec& p, const Vec& q,
                                  const std::vector<Seg>& all) const {
    for (std::size_t s = 0; s < all.size(); ++s)
      if (!std::isnan(segmentHit(w, p, q, all, s))) return curveOf(s);
    return std::nullopt;
  }

  // The curve of segment s of wall segments then side segments.
  int curveOf(std::size_t s) const {
    return s < wallSegs_.size() ? wallCurve_[s] : sideCurve_[s - wallSegs_.size()];
  }

  // Where the ray p -> q crosses segment s of `all`, as the share of p -> q; NaN where it does not
  // or where the segment is around wall node w or on the side curve it climbs.
  double segmentHit(const WallNode& w, const Vec& p, const Vec& q, const std::vector<Seg>& all,
                    std::size_t s) const {
    if (all[s][0] == w.id || all[s][1] == w.id) return kNaN;
    if (s >= wallSegs_.size() && sideCurve_[s - wallSegs_.size()] == w.sideCurve) return kNaN;
    const Vec a = at(out_, all[s][0]), b = at(out_, all[s][1]);
    // p + u (q - p) = a + v (b - a), in the plane.
    const Vec r = q - p, e = b - a;
    const double den = r.cross(e).dot(normal_);
    if (std::fabs(den) <= 1e-14 * r.norm() * e.norm()) return kNaN;
    const double u = (a - p).cross(e).dot(normal_) / den;
    const double v = (a - p).cross(r).dot(normal_) / den;
    return u > 1e-9 && u < 1.0 && v >= 0.0 && v <= 1.0 ? u : kNaN;
  }

  // Each node's clearance along its directions (the fan's, at a fan), and its height brought at
  // once to what the shrink loop's ray rule would make of it (clearanceFactor).
  void fitToClearance() {
    std::vector<Seg> all = wallSegs_;
    all.insert(all.end(), sideSegs_.begin(), sideSegs_.end());
    for (WallNode& w : wall_) {
      const Vec p = at(out_, w.id);
      // No farther than the model's diagonal: a wall within it is met as well, and the hit's
      // share of the ray stays clear of segmentHit's end-point margin.
      const double reach = std::min(kRayReach * w.full, cad_.boundingDiagonal());
      for (const Vec& d : w.fan.empty() ? std::vector<Vec>{w.d} : w.fan)
        for (std::size_t s = 0; s < all.size(); ++s) {
          const double hit = segmentHit(w, p, p + reach * d, all, s);
          if (!std::isnan(hit) && hit * reach < w.clearance) {
            w.clearance = hit * reach;
            w.clearanceCurve = curveOf(s);
          }
        }
      w.factor = clearanceFactor(w.clearance, w.full);
    }
  }

  void shrink() {
    record_.shrinkPasses = shrinkUntilClear(
        wall_, [this] { return offenders(); },
        [this] {
          for (WallNode& w : wall_) place(w);
        },
        [this](const WallNode& w) {
          std::string text = "Edge" + std::to_string(w.curve) + " (thickness " +
                             formatNumber(w.full) + ") cannot be grown at " + where(w);
          if (w.clearanceCurve != 0)
            text += " (Edge" + std::to_string(w.clearanceCurve) + " is " +
                    formatNumber(w.clearance) + " away along the layer's normal)";
          return text;
        });
  }

  Mesh assemble(const LinearMeshOptions& fill) {
    recordHeights(
        record_, p_, out_, wall_, [](const WallNode& w) { return w.curve; },
        [](const WallNode& w) { return w.full; },
        [](const WallNode& w) { return w.clearanceCurve; });
    std::vector<std::int64_t> topId(wall_.size());
    std::vector<std::vector<std::int64_t>> fanIds(wall_.size());
    const auto addTop = [&](const Vec& x) {
      const double xyz[3] = {x.x(), x.y(), x.z()};
      return out_.addNode(xyz, 2, face_, kNaN, kNaN);
    };
    for (std::size_t i = 0; i < wall_.size(); ++i) {
      const WallNode& w = wall_[i];
      const double xyz[3] = {w.top.x(), w.top.y(), w.top.z()};
      if (!w.fan.empty())
        for (const Vec& t : w.fanTops) fanIds[i].push_back(addTop(t));
      else
        topId[i] = w.sideCurve != 0 ? out_.addNode(xyz, 1, w.sideCurve, w.t, kNaN) : addTop(w.top);
    }
    // The top of node v in the cell of wall segment s (v itself off the wall).
    const auto topIn = [&](std::int64_t v, std::size_t s) {
      const auto it = wallIndex_.find(v);
      if (it == wallIndex_.end()) return v;
      const WallNode& w = wall_[it->second];
      if (w.fan.empty()) return topId[it->second];
      return s == w.fanSegs[0] ? fanIds[it->second].front() : fanIds[it->second].back();
    };
    const auto top = [&](std::int64_t v) { return topIn(v, wallSegs_.size()); };
    ElementBlock quads, lines, fans;
    quads.type = CellType::Quadrilateral;
    lines.type = CellType::Line;
    fans.type = CellType::Triangle;
    std::vector<std::array<std::int64_t, 2>> closure;
    for (std::size_t s = 0; s < wallSegs_.size(); ++s) {
      std::int64_t a = wallSegs_[s][0], b = wallSegs_[s][1];
      // Counter-clockwise around the plane normal: wall a -> b, then the tops back.
      const Vec e1 = at(out_, b) - at(out_, a), e2 = at(out_, topIn(a, s)) - at(out_, a);
      if (e1.cross(e2).dot(normal_) < 0.0) std::swap(a, b);
      for (const std::int64_t v : {a, b, topIn(b, s), topIn(a, s)}) quads.nodes.push_back(v);
      quads.entity.push_back(face_);
      closure.push_back({topIn(a, s), topIn(b, s)});
      lines.nodes.insert(lines.nodes.end(), {wallSegs_[s][0], wallSegs_[s][1]});
      lines.entity.push_back(wallCurve_[s]);
    }
    for (std::size_t s = 0; s < sideSegs_.size(); ++s) {
      const std::array<std::int64_t, 2> moved{top(sideSegs_[s][0]), top(sideSegs_[s][1])};
      closure.push_back(moved);
      lines.nodes.insert(lines.nodes.end(), moved.begin(), moved.end());
      lines.entity.push_back(sideCurve_[s]);
    }
    for (std::size_t i = 0; i < wall_.size(); ++i)
      if (wall_[i].sideCurve != 0) {
        lines.nodes.insert(lines.nodes.end(), {wall_[i].id, topId[i]});
        lines.entity.push_back(wall_[i].sideCurve);
      }
    // The fans: triangles (corner, top j, top j + 1), counter-clockwise, the corner first.
    for (std::size_t i = 0; i < wall_.size(); ++i)
      for (std::size_t j = 0; j + 1 < fanIds[i].size(); ++j) {
        std::int64_t a = fanIds[i][j], b = fanIds[i][j + 1];
        closure.push_back({a, b});
        const Vec c = at(out_, wall_[i].id);
        if ((at(out_, a) - c).cross(at(out_, b) - c).dot(normal_) < 0.0) std::swap(a, b);
        fans.nodes.insert(fans.nodes.end(), {wall_[i].id, a, b});
        fans.entity.push_back(face_);
      }
    record_.cells = quads.count();
    record_.fanTriangles = fans.count();
    ElementBlock tris = fillTriangles(out_, closure, fill, face_);
    tris.nodes.insert(tris.nodes.end(), fans.nodes.begin(), fans.nodes.end());
    tris.entity.insert(tris.entity.end(), fans.entity.begin(), fans.entity.end());
    out_.blocks = {std::move(tris), std::move(quads), std::move(lines)};
    out_.checkConsistency();
    return std::move(out_);
  }
};

}  // namespace

Mesh growLayer2D(const Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p,
                 const LinearMeshOptions& fill, BoundaryLayerRecord& record) {
  return LayerGrower2D(planar, cad, p, record).run(fill);
}

}  // namespace homesh::layer_growth
