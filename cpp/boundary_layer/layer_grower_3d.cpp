#include "boundary_layer/layer_grower_3d.hpp"

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
#include "boundary_layer/layer_normals.hpp"
#include "core/error.hpp"
#include "core/expression.hpp"

namespace homesh::layer_growth {
namespace {

using Tri = std::array<std::int64_t, 3>;

constexpr double kMinSideTriangle = 0.2;  // a moved neighbour triangle keeps this share of shape
constexpr int kSideRings = 3;             // side-face nodes this many edges from the layer relax
constexpr int kSideRelaxation = 10;       // relaxation passes of those nodes

double triangleShape(const Vec& a, const Vec& b, const Vec& c) {
  const double area2 = (b - a).cross(c - a).norm();
  const double edges = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return edges > 0.0 ? 2.0 * std::sqrt(3.0) * area2 / edges : 0.0;
}

// Where segment p-q crosses triangle abc, as the share t of p-q (Moller-Trumbore, the end
// points excluded); NaN where it does not.
double segmentHit(const Vec& p, const Vec& q, const Vec& a, const Vec& b, const Vec& c) {
  const Vec d = q - p, e1 = b - a, e2 = c - a;
  const Vec h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::fabs(det) <= 1e-14 * e1.norm() * e2.norm() * d.norm()) return kNaN;
  const double inv = 1.0 / det;
  const Vec s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) return kNaN;
  const Vec qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0.0 || u + v > 1.0) return kNaN;
  const double t = inv * e2.dot(qv);
  return t > 1e-9 && t < 1.0 ? t : kNaN;
}

bool segmentCrosses(const Vec& p, const Vec& q, const Vec& a, const Vec& b, const Vec& c) {
  return !std::isnan(segmentHit(p, q, a, b, c));
}

// The Jacobian at the six corners of the linear prism (wall a, b, c; tops A, B, C), smallest,
// as (e1 x e2) . dz / (|A_wall| |dz|): e1, e2 the edges of the corner's triangle (wall or top)
// from its first vertex, dz the corner's column, A_wall the wall triangle's area vector. At the
// wall that is the cosine of the column's lean from the wall's normal; at the top, the top
// triangle's area projected across the column over the wall's area. The wall triangle's own
// angles are the linear mesh's and no height changes them: a sliver (a thin trailing-edge
// face, a wing tip's corner) must not read as a fold. An inverted or collapsed top or wall gives
// 0 or less.
double prismCornerQuality(const std::array<Vec, 6>& v) {
  const double wall = (v[1] - v[0]).cross(v[2] - v[0]).norm();
  if (!(wall > 0.0)) return -1.0;
  double worst = 1.0;
  for (std::size_t top = 0; top < 2; ++top) {
    const Vec& o = v[3 * top];
    const Vec area = (v[3 * top + 1] - o).cross(v[3 * top + 2] - o);
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec dz = v[3 + k] - v[k];
      const double scale = wall * dz.norm();
      worst = std::min(worst, scale > 0.0 ? area.dot(dz) / scale : -1.0);
    }
  }
  return worst;
}

class LayerGrower {
 public:
  LayerGrower(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p,
              BoundaryLayerRecord& record)
      : cad_(cad),
        p_(p),
        record_(record),
        thickness_(Expression::parse(p.thickness, "boundary-layer thickness")) {
    extractSurface(volume);
  }

  Mesh run(const LinearMeshOptions& fill) {
    directions();
    heights();
    fitToClearance();
    shrink();
    return assemble(fill);
  }

 private:
  // How a wall node may move: freely, on one face without a layer, or on the curve where two
  // such faces meet.
  struct WallNode {
    std::int64_t id = 0;              // node of out_
    std::vector<int> sideFaces;       // faces without a layer through the node
    int curve = 0;                    // with two side faces: their common curve
    int face = 0;                     // a layer face the node lies on (for the report)
    Vec d = Vec::Zero();              // unit growth direction (into the solid)
    double full = 0.0, factor = 1.0;  // asked height along d, share of it grown
    double stretch = 1.0;             // full / the thickness asked (stretch())
    bool sharp = false;               // layer faces meet at a sharp edge or corner here
    std::vector<Vec> faceNormals;     // layerFaceNormals, set by offsetAtEdges
    Vec top = Vec::Zero();            // the top node's position
    // Along d, the distance to the first other wall, and its face (0: none within kRayReach
    // heights asked).
    double clearance = std::numeric_limits<double>::infinity();
    int clearanceFace = 0;
    double u = kNaN, v = kNaN;            // its CAD parameters (side face or curve)
    std::vector<std::size_t> facets;      // layer triangles around it
    std::vector<std::size_t> neighbours;  // wall nodes sharing a layer edge
  };

  const CadModel& cad_;
  const BoundaryLayerParameters& p_;
  BoundaryLayerRecord& record_;
  Expression thickness_;
  Mesh out_;
  int solid_ = 1;
  std::vector<Tri> layerTris_, sideTris_;  // outward triangles on layer / other faces
  std::vector<int> layerFace_, sideFace_;
  ElementBlock lines_;
  std::vector<WallNode> wall_;
  std::map<std::int64_t, std::size_t> wallIndex_;  // node -> wall_ index
  // Nodes inside the faces without a layer, near the layer's foot: relaxed (each the mean of
  // its neighbours on the face, projected onto it) so that the face's triangles make room for
  // the nodes that climb it instead of folding. Nodes on a curve between such faces (a
  // cylinder's seam, the edge between two of them) slide along it the same way: held, they
  // fold the triangles beside them where the layer climbs a face a few elements tall (a stilt).
  struct SideNode {
    std::int64_t id = 0;
    int face = 0;   // the face it lies inside, or 0 on a curve
    int curve = 0;  // the curve it lies on, or 0 inside a face
    std::vector<std::int64_t> neighbours;
    Vec at = Vec::Zero();
    double u = kNaN, v = kNaN;
  };
  std::vector<SideNode> side_;
  std::map<std::int64_t, std::size_t> sideIndex_;
  // Every surface triangle where it was, its face and bounding box: what the layer's normals
  // must not cross (built once; the shrink passes test against it).
  struct Walls {
    std::vector<Tri> triangles;
    std::vector<int> faces;
    std::vector<std::pair<Vec, Vec>> boxes;
  } walls_;

  void extractSurface(const Mesh& volume) {
    if (volume.dim != 3)
      throw ParameterError("boundary layers on a 2D model are not made yet (" + cad_.sourceName() +
                           " is planar)");
    std::set<int> solids;
    for (const ElementBlock& b : volume.blocks)
      if (b.type == CellType::Tetrahedron) solids.insert(b.entity.begin(), b.entity.end());
    if (solids.size() != 1)
      throw ParameterError("boundary layers need a model with one solid; " + cad_.sourceName() +
                           " has " + std::to_string(solids.size()));
    solid_ = *solids.begin();
    std::set<int> meshed;
    for (const ElementBlock& b : volume.blocks)
      if (b.type == CellType::Triangle) meshed.insert(b.entity.begin(), b.entity.end());
    requireLayerFaces(cad_, p_.faces, meshed);
    const std::set<int> layer(p_.faces.begin(), p_.faces.end());
    std::vector<std::int64_t> newId(volume.numNodes(), -1);
    out_.dim = 3;
    out_.order = 1;
    for (std::size_t i = 0; i < volume.numNodes(); ++i) {
      if (volume.nodeCadDim[i] >= 3) continue;
      newId[i] = out_.addNode(&volume.xyz[3 * i], volume.nodeCadDim[i], volume.nodeCadIndex[i],
                              volume.nodeCadParam[2 * i], volume.nodeCadParam[2 * i + 1]);
    }
    const auto remap = [&](std::int64_t v) {
      const std::int64_t n = newId[static_cast<std::size_t>(v)];
      if (n < 0) throw MeshingError("a boundary element uses a node inside the solid");
      return n;
    };
    lines_.type = CellType::Line;
    for (const ElementBlock& b : volume.blocks) {
      if (b.type == CellType::Triangle) {
        for (std::size_t e = 0; e < b.count(); ++e) {
          const std::int64_t* t = b.element(e);
          const Tri tri{remap(t[0]), remap(t[1]), remap(t[2])};
          if (layer.count(b.entity[e]) != 0) {
            layerTris_.push_back(tri);
            layerFace_.push_back(b.entity[e]);
          } else {
            sideTris_.push_back(tri);
            sideFace_.push_back(b.entity[e]);
          }
        }
      } else if (b.type == CellType::Line) {
        for (const std::int64_t v : b.nodes) lines_.nodes.push_back(remap(v));
        lines_.entity.insert(lines_.entity.end(), b.entity.begin(), b.entity.end());
      }
    }
    // Wall nodes, their facets and neighbours.
    for (std::size_t t = 0; t < layerTris_.size(); ++t)
      for (const std::int64_t v : layerTris_[t]) {
        auto [it, fresh] = wallIndex_.emplace(v, wall_.size());
        if (fresh) {
          WallNode w;
          w.id = v;
          w.face = layerFace_[t];
          wall_.push_back(w);
        }
        wall_[it->second].facets.push_back(t);
      }
    for (const Tri& t : layerTris_)
      for (int k = 0; k < 3; ++k) {
        WallNode& w = wall_[wallIndex_.at(t[static_cast<std::size_t>(k)])];
        const std::size_t n = wallIndex_.at(t[static_cast<std::size_t>((k + 1) % 3)]);
        if (std::find(w.neighbours.begin(), w.neighbours.end(), n) == w.neighbours.end())
          w.neighbours.push_back(n);
        wall_[n].neighbours.push_back(wallIndex_.at(t[static_cast<std::size_t>(k)]));
      }
    for (WallNode& w : wall_) {
      std::sort(w.neighbours.begin(), w.neighbours.end());
      w.neighbours.erase(std::unique(w.neighbours.begin(), w.neighbours.end()), w.neighbours.end());
    }
    for (std::size_t t = 0; t < sideTris_.size(); ++t)
      for (const std::int64_t v : sideTris_[t]) {
        const auto it = wallIndex_.find(v);
        if (it == wallIndex_.end()) continue;
        std::vector<int>& faces = wall_[it->second].sideFaces;
        if (std::find(faces.begin(), faces.end(), sideFace_[t]) == faces.end())
          faces.push_back(sideFace_[t]);
      }
    findSideNodes();
    walls_.triangles = layerTris_;
    walls_.triangles.insert(walls_.triangles.end(), sideTris_.begin(), sideTris_.end());
    walls_.faces = layerFace_;
    walls_.faces.insert(walls_.faces.end(), sideFace_.begin(), sideFace_.end());
    for (const Tri& t : walls_.triangles) {
      Vec lo = at(out_, t[0]), hi = lo;
      for (std::size_t k = 1; k < 3; ++k) {
        lo = lo.cwiseMin(at(out_, t[k]));
        hi = hi.cwiseMax(at(out_, t[k]));
      }
      walls_.boxes.emplace_back(lo, hi);
    }
  }

  // The side faces' inner nodes, and those of the curves between them, within kSideRings edges
  // of a wall node that climbs them.
  void findSideNodes() {
    std::map<std::int64_t, std::set<std::int64_t>> adjacent;
    for (const Tri& t : sideTris_)
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          if (j != k)
            adjacent[t[static_cast<std::size_t>(k)]].insert(t[static_cast<std::size_t>(j)]);
    // A curve that also bounds a face this solid's mesh does not hold (another solid's) stays:
    // that face's triangles are not checked here.
    std::set<int> held(layerFace_.begin(), layerFace_.end()), foreign;
    held.insert(sideFace_.begin(), sideFace_.end());
    for (int f = 1; f <= cad_.numFaces(); ++f)
      if (held.count(f) == 0)
        for (const int c : cad_.subShapeIndices(2, f, 1)) foreign.insert(c);
    std::set<std::int64_t> front, reached;
    for (const WallNode& w : wall_)
      if (!w.sideFaces.empty()) front.insert(w.id);
    for (int ring = 0; ring < kSideRings; ++ring) {
      std::set<std::int64_t> next;
      for (const std::int64_t v : front)
        for (const std::int64_t n : adjacent[v]) {
          const auto i = static_cast<std::size_t>(n);
          const int dim = out_.nodeCadDim[i];
          const bool slides = dim == 2 || (dim == 1 && foreign.count(out_.nodeCadIndex[i]) == 0);
          if (!slides || wallIndex_.count(n) != 0 || !reached.insert(n).second) continue;
          next.insert(n);
        }
      front = std::move(next);
    }
    for (const std::int64_t n : reached) {
      SideNode s;
      s.id = n;
      const auto i = static_cast<std::size_t>(n);
      (out_.nodeCadDim[i] == 2 ? s.face : s.curve) = out_.nodeCadIndex[i];
      s.neighbours.assign(adjacent[n].begin(), adjacent[n].end());
      sideIndex_[n] = side_.size();
      side_.push_back(std::move(s));
    }
  }

  void relaxSide() {
    for (SideNode& s : side_) {
      s.at = at(out_, s.id);
      s.u = out_.nodeCadParam[2 * static_cast<std::size_t>(s.id)];
      s.v = out_.nodeCadParam[2 * static_cast<std::size_t>(s.id) + 1];
    }
    bool climbing = false;
    for (const WallNode& w : wall_) climbing = climbing || !w.sideFaces.empty();
    if (!climbing) return;
    for (int pass = 0; pass < kSideRelaxation; ++pass)
      for (SideNode& s : side_) {
        Vec mean = Vec::Zero();
        for (const std::int64_t n : s.neighbours) mean += moved(n);
        mean /= static_cast<double>(s.neighbours.size());
        if (s.curve != 0) {
          std::optional<double> guess;
          if (std::isfinite(s.u)) guess = s.u;
          const CurveProjection proj = cad_.projectOnCurve(s.curve, mean, guess);
          s.at = proj.point;
          s.u = proj.t;
          continue;
        }
        std::optional<std::array<double, 2>> guess;
        if (std::isfinite(s.u) && std::isfinite(s.v)) guess = std::array<double, 2>{s.u, s.v};
        const SurfaceProjection proj = cad_.projectOnSurface(s.face, mean, guess);
        s.at = proj.point;
        s.u = proj.u;
        s.v = proj.v;
      }
  }

  Vec facetNormal(std::size_t t) const {
    const Tri& f = layerTris_[t];
    return (at(out_, f[1]) - at(out_, f[0])).cross(at(out_, f[2]) - at(out_, f[0])).normalized();
  }

  std::string where(const WallNode& w) const { return pointText(at(out_, w.id)); }

  Vec faceNormal(int face, const Vec& x) const {
    const SurfaceProjection proj = cad_.projectOnSurface(face, x);
    const SurfaceDerivatives d = cad_.evaluateSurface(face, proj.u, proj.v);
    const Vec n = d.du.cross(d.dv);
    return n.norm() > 0.0 ? Vec(n.normalized()) : Vec::Zero();
  }

  // The direction d kept on what the node may move along.
  Vec constrain(const WallNode& w, const Vec& d) const {
    const Vec x = at(out_, w.id);
    if (w.sideFaces.empty()) return d.normalized();
    if (w.sideFaces.size() == 1) {
      const Vec n = faceNormal(w.sideFaces[0], x);
      const Vec t = d - d.dot(n) * n;
      return t.norm() > 1e-12 ? Vec(t.normalized()) : Vec::Zero();
    }
    const Vec t = faceNormal(w.sideFaces[0], x).cross(faceNormal(w.sideFaces[1], x));
    if (t.norm() < 1e-9) return Vec::Zero();
    return t.dot(d) >= 0.0 ? Vec(t.normalized()) : Vec(-t.normalized());
  }

  double visibility(const WallNode& w, const Vec& d) const {
    double worst = 1.0;
    for (const std::size_t t : w.facets) worst = std::min(worst, -facetNormal(t).dot(d));
    return worst;
  }

  void directions() {
    for (WallNode& w : wall_) {
      if (w.sideFaces.size() > 2)
        throw MeshingError("no boundary layer can grow at " + where(w) + " on Face" +
                           std::to_string(w.face) + ": " + std::to_string(w.sideFaces.size()) +
                           " faces without a layer meet there");
      if (w.sideFaces.size() == 2) {
        std::vector<int> common;
        const std::vector<int> a = cad_.subShapeIndices(2, w.sideFaces[0], 1);
        const std::vector<int> b = cad_.subShapeIndices(2, w.sideFaces[1], 1);
        std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
        const int dim = out_.nodeCadDim[static_cast<std::size_t>(w.id)];
        const int index = out_.nodeCadIndex[static_cast<std::size_t>(w.id)];
        for (const int c : common) {
          const std::vector<int> ends = cad_.subShapeIndices(1, c, 0);
          if ((dim == 0 && std::find(ends.begin(), ends.end(), index) != ends.end()) ||
              (dim == 1 && c == index)) {
            w.curve = c;
            break;
          }
        }
        if (w.curve == 0)
          throw MeshingError("no boundary layer can grow at " + where(w) + ": Face" +
                             std::to_string(w.sideFaces[0]) + " and Face" +
                             std::to_string(w.sideFaces[1]) + " meet there without a common edge");
      }
      Vec sum = Vec::Zero();
      for (const std::size_t t : w.facets) {
        const Tri& f = layerTris_[t];
        int k = 0;
        while (f[static_cast<std::size_t>(k)] != w.id) ++k;
        const Vec o = at(out_, w.id);
        const Vec a = at(out_, f[static_cast<std::size_t>((k + 1) % 3)]) - o;
        const Vec b = at(out_, f[static_cast<std::size_t>((k + 2) % 3)]) - o;
        const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
        sum -= angle * facetNormal(t);
      }
      w.d = constrain(w, sum);
      // Kept on a face without a layer that continues the layer face smoothly (a fillet's
      // neighbour), the direction runs along the wall: no height makes such prisms valid.
      bool tangent = w.d.isZero();
      const Vec x = at(out_, w.id);
      for (const int s : w.sideFaces)
        tangent = tangent || std::fabs(faceNormal(w.face, x).dot(faceNormal(s, x))) > kTangentFaces;
      if (tangent) {
        std::string faces;
        for (const int f : w.sideFaces)
          faces.append(faces.empty() ? "Face" : " and Face").append(std::to_string(f));
        throw MeshingError(
            "no boundary layer can grow at " + where(w) + " on Face" + std::to_string(w.face) +
            ": it meets " + faces +
            (w.sideFaces.size() == 1 ? ", which has no layer," : ", which have no layer,") +
            " (nearly) tangentially; put the layer on " +
            (w.sideFaces.size() == 1 ? "that face" : "those faces") + " too");
      }
    }
    // Relax: each direction towards the mean of its neighbours', kept where every facet around
    // still sees it.
    for (int pass = 0; pass < kNormalSmoothing; ++pass) {
      std::vector<Vec> next(wall_.size());
      for (std::size_t i = 0; i < wall_.size(); ++i) {
        const WallNode& w = wall_[i];
        Vec sum = w.d;
        for (const std::size_t n : w.neighbours) sum += wall_[n].d;
        const Vec d = w.sideFaces.size() == 2 ? w.d : constrain(w, sum);
        next[i] =
            !d.isZero() && visibility(w, d) >= std::min(kVisibility, visibility(w, w.d)) ? d : w.d;
      }
      for (std::size_t i = 0; i < wall_.size(); ++i) wall_[i].d = next[i];
    }
    offsetAtEdges();
  }

  // Every node's layer face normals (WallNode::faceNormals); then, at a free node where layer
  // faces meet at a sharp edge or corner (their CAD normals spread as the split's
  // NormalSum::sharp says), the direction whose component along each face's inward normal is the
  // same (the least-norm solution of N d = 1): its column, lengthened by stretch(), ends at the
  // thickness from every face, where each face's plane offset by the thickness passes. Kept
  // where every facet around still sees it.
  void offsetAtEdges() {
    for (WallNode& w : wall_) {
      w.faceNormals = layerFaceNormals(w);
      if (!w.sideFaces.empty()) continue;
      NormalSum inward;  // into the solid
      for (const Vec& n : w.faceNormals) inward.add(n.dot(w.d) < 0.0 ? Vec(-n) : n);
      if (inward.normals.size() < 2 || !inward.sharp()) continue;
      Eigen::MatrixXd normals(static_cast<Eigen::Index>(inward.normals.size()), 3);
      for (std::size_t k = 0; k < inward.normals.size(); ++k)
        normals.row(static_cast<Eigen::Index>(k)) = inward.normals[k].transpose();
      const Eigen::VectorXd ones = Eigen::VectorXd::Ones(normals.rows());
      const Vec d = normals.completeOrthogonalDecomposition().solve(ones);
      if (!(d.norm() > 0.0) || !d.allFinite()) continue;
      const Vec unit = d.normalized();
      if (visibility(w, unit) < std::min(kVisibility, visibility(w, w.d))) continue;
      w.d = unit;
      w.sharp = true;
    }
  }

  // The CAD unit normals (either way round) at w of the layer faces through it, but where a
  // face has none (a pole).
  std::vector<Vec> layerFaceNormals(const WallNode& w) const {
    std::set<int> faces;
    for (const std::size_t t : w.facets) faces.insert(layerFace_[t]);
    std::vector<Vec> normals;
    for (const int f : faces) {
      const Vec n = faceNormal(f, at(out_, w.id));
      if (!n.isZero()) normals.push_back(n);
    }
    return normals;
  }

  // Each node's clearance along its direction, and its height brought at once to what the
  // shrink loop's ray rule would make of it (clearanceFactor).
  void fitToClearance() {
    for (WallNode& w : wall_) {
      const Vec p = at(out_, w.id);
      // No farther than the model's diagonal: a wall within it is met as well, and the hit's
      // share of the ray stays clear of segmentHit's end-point margin.
      const Vec q = p + std::min(kRayReach * w.full, cad_.boundingDiagonal()) * w.d;
      const Vec lo = p.cwiseMin(q), hi = p.cwiseMax(q);
      for (std::size_t t = 0; t < walls_.triangles.size(); ++t) {
        if (aroundNode(w, t, lo, hi)) continue;
        const Tri& f = walls_.triangles[t];
        const double hit = segmentHit(p, q, at(out_, f[0]), at(out_, f[1]), at(out_, f[2]));
        if (!std::isnan(hit) && hit * (q - p).norm() < w.clearance) {
          w.clearance = hit * (q - p).norm();
          w.clearanceFace = walls_.faces[t];
        }
      }
      w.factor = clearanceFactor(w.clearance, w.full);
    }
  }

  // Whether wall triangle t is left out of w's ray test: outside the ray's box [lo, hi], around
  // the node, or on a face the node climbs.
  bool aroundNode(const WallNode& w, std::size_t t, const Vec& lo, const Vec& hi) const {
    const std::pair<Vec, Vec>& box = walls_.boxes[t];
    if ((box.first.array() > hi.array()).any() || (box.second.array() < lo.array()).any())
      return true;
    const Tri& f = walls_.triangles[t];
    if (std::find(f.begin(), f.end(), w.id) != f.end()) return true;
    return std::find(w.sideFaces.begin(), w.sideFaces.end(), walls_.faces[t]) != w.sideFaces.end();
  }

  void heights() {
    for (WallNode& w : wall_) {
      const Vec x = at(out_, w.id);
      const double thickness = thickness_(x.x(), x.y(), x.z());
      if (!(thickness > 0.0) || !std::isfinite(thickness))
        throw ParameterError("boundary-layer thickness '" + p_.thickness + "' is " +
                             formatNumber(thickness) + " at " + where(w) + " on Face" +
                             std::to_string(w.face) + ": it must be positive on every layer face");
      w.stretch = stretch(w);
      w.full = thickness * w.stretch;
    }
  }

  // How much longer than the thickness w's column must be for its top to lie at the thickness
  // from every layer face through the node, measured along that face's CAD normal: 1 / the
  // smallest |cos| between the direction and those normals (at most kMaxStretch), at a sharp
  // edge or corner (offsetAtEdges) or where the direction leans by more than kStretchLean (the
  // smoothing tilts it near such edges); 1 elsewhere. A column of the bare thickness would leave
  // the first layer short by that cosine (29 % at a cube's edge, 42 % at its corner).
  double stretch(const WallNode& w) const {
    double lean = 1.0;
    for (const Vec& n : w.faceNormals) lean = std::min(lean, std::fabs(n.dot(w.d)));
    if (!w.sharp && lean > kStretchLean) return 1.0;
    return 1.0 / std::max(lean, 1.0 / kMaxStretch);
  }

  // Puts w's top at the grown height, on its side face or curve.
  void place(WallNode& w) const {
    const Vec target = at(out_, w.id) + w.factor * w.full * w.d;
    if (w.sideFaces.size() == 1) {
      const SurfaceProjection proj = cad_.projectOnSurface(w.sideFaces[0], target);
      w.top = proj.point;
      w.u = proj.u;
      w.v = proj.v;
    } else if (w.sideFaces.size() == 2) {
      const CurveProjection proj = cad_.projectOnCurve(w.curve, target);
      w.top = proj.point;
      w.u = proj.t;
      w.v = kNaN;
    } else {
      w.top = target;
    }
  }

  // Where a node of a side face's triangle goes: a climbing wall node to its top, a relaxed
  // inner node to its new place.
  Vec moved(std::int64_t v) const {
    const auto s = sideIndex_.find(v);
    if (s != sideIndex_.end()) return side_[s->second].at;
    const auto it = wallIndex_.find(v);
    if (it == wallIndex_.end() || wall_[it->second].sideFaces.empty()) return at(out_, v);
    return wall_[it->second].top;
  }

  // The wall nodes that must grow less, and why (for the message if they cannot).
  std::map<std::size_t, std::string> offenders() const {
    std::map<std::size_t, std::string> bad;
    for (const Tri& t : layerTris_) {
      const std::size_t a = wallIndex_.at(t[0]), b = wallIndex_.at(t[2]), c = wallIndex_.at(t[1]);
      const std::array<Vec, 6> v{at(out_, t[0]), at(out_, t[2]), at(out_, t[1]),
                                 wall_[a].top,   wall_[b].top,   wall_[c].top};
      if (prismCornerQuality(v) < kMinPrismCorner)
        for (const std::size_t n : {a, b, c}) bad.emplace(n, "a prism folds");
    }
    for (const Tri& t : sideTris_) {
      bool touched = false;
      for (const std::int64_t v : t) touched = touched || moved(v) != at(out_, v);
      if (!touched) continue;
      const Vec a0 = at(out_, t[0]), b0 = at(out_, t[1]), c0 = at(out_, t[2]);
      const Vec a1 = moved(t[0]), b1 = moved(t[1]), c1 = moved(t[2]);
      const Vec n0 = (b0 - a0).cross(c0 - a0), n1 = (b1 - a1).cross(c1 - a1);
      const bool folded = n1.dot(n0) < 0.5 * n0.norm() * n1.norm() ||
                          triangleShape(a1, b1, c1) < kMinSideTriangle * triangleShape(a0, b0, c0);
      if (!folded) continue;
      for (const std::int64_t v : t) {
        const auto it = wallIndex_.find(v);
        if (it != wallIndex_.end() && !wall_[it->second].sideFaces.empty())
          bad.emplace(it->second, "the neighbouring face's triangles fold");
      }
      // A folded triangle of relaxed nodes only: its nearest climbing wall nodes give way.
      for (const std::int64_t v : t)
        if (sideIndex_.count(v) != 0)
          for (const std::int64_t n : side_[sideIndex_.at(v)].neighbours) {
            const auto it = wallIndex_.find(n);
            if (it != wallIndex_.end() && !wall_[it->second].sideFaces.empty())
              bad.emplace(it->second, "the neighbouring face's triangles fold");
          }
    }
    for (std::size_t e = 0; e < lines_.count(); ++e) {
      const std::int64_t* l = lines_.element(e);
      for (int k = 0; k < 2; ++k) {
        const auto it = wallIndex_.find(l[k]);
        if (it == wallIndex_.end() || wall_[it->second].curve != lines_.entity[e]) continue;
        const Vec v = at(out_, l[k]), w = at(out_, l[1 - k]), q = wall_[it->second].top;
        if ((w - q).dot(w - v) < 0.3 * (w - v).squaredNorm())
          bad.emplace(it->second, "the layer reaches past the next node of Edge" +
                                      std::to_string(lines_.entity[e]));
      }
    }
    // The normal, extended, must not cross a wall that is not around the node.
    for (std::size_t i = 0; i < wall_.size(); ++i) {
      const WallNode& w = wall_[i];
      const Vec p = at(out_, w.id);
      const Vec q = p + kRayReach * (w.top - p);
      const Vec lo = p.cwiseMin(q), hi = p.cwiseMax(q);
      for (std::size_t t = 0; t < walls_.triangles.size(); ++t) {
        if (aroundNode(w, t, lo, hi)) continue;
        const Tri& f = walls_.triangles[t];
        if (segmentCrosses(p, q, at(out_, f[0]), at(out_, f[1]), at(out_, f[2]))) {
          bad.emplace(i, "the layer would reach Face" + std::to_string(walls_.faces[t]));
          break;
        }
      }
    }
    return bad;
  }

  void shrink() {
    record_.shrinkPasses = shrinkUntilClear(
        wall_, [this] { return offenders(); },
        [this] {
          for (WallNode& w : wall_) place(w);
          relaxSide();
        },
        [this](const WallNode& w) {
          std::string text = "Face" + std::to_string(w.face) + " (thickness " +
                             formatNumber(w.full / w.stretch) + ") cannot be grown at " + where(w);
          if (w.clearanceFace != 0)
            text += " (Face" + std::to_string(w.clearanceFace) + " is " +
                    formatNumber(w.clearance) + " away along the layer's normal)";
          return text;
        });
  }

  Mesh assemble(const LinearMeshOptions& fill) {
    recordHeights(
        record_, p_, out_, wall_, [](const WallNode& w) { return w.face; },
        [](const WallNode& w) { return w.full / w.stretch; },
        [](const WallNode& w) { return w.clearanceFace; });
    std::vector<std::int64_t> topId(wall_.size());
    for (std::size_t i = 0; i < wall_.size(); ++i) {
      const WallNode& w = wall_[i];
      const double xyz[3] = {w.top.x(), w.top.y(), w.top.z()};
      if (w.sideFaces.size() == 1)
        topId[i] = out_.addNode(xyz, 2, w.sideFaces[0], w.u, w.v);
      else if (w.sideFaces.size() == 2)
        topId[i] = out_.addNode(xyz, 1, w.curve, w.u, kNaN);
      else
        topId[i] = out_.addNode(xyz, 3, solid_, kNaN, kNaN);
    }
    for (const SideNode& s : side_) {
      const auto i = static_cast<std::size_t>(s.id);
      for (int d = 0; d < 3; ++d) out_.xyz[3 * i + static_cast<std::size_t>(d)] = s.at(d);
      out_.nodeCadParam[2 * i] = s.u;
      out_.nodeCadParam[2 * i + 1] = s.v;
    }
    const auto top = [&](std::int64_t v) {
      const auto it = wallIndex_.find(v);
      return it == wallIndex_.end() ? v : topId[it->second];
    };

    ElementBlock prisms, tris, quads, lines = lines_;
    prisms.type = CellType::Prism;
    tris.type = CellType::Triangle;
    quads.type = CellType::Quadrilateral;
    std::vector<Tri> closure;  // the surface the tetrahedra fill
    for (std::size_t t = 0; t < layerTris_.size(); ++t) {
      const Tri& f = layerTris_[t];
      // Wall (a, c, b) turns the outward facet inwards, towards the top: positive volume.
      for (const std::int64_t v : {f[0], f[2], f[1]}) prisms.nodes.push_back(v);
      for (const std::int64_t v : {f[0], f[2], f[1]}) prisms.nodes.push_back(top(v));
      prisms.entity.push_back(solid_);
      closure.push_back({top(f[0]), top(f[1]), top(f[2])});
      tris.nodes.insert(tris.nodes.end(), f.begin(), f.end());
      tris.entity.push_back(layerFace_[t]);
    }
    // The other faces' triangles follow their nodes up the side; the strip they leave is covered
    // by the layer's side quadrilaterals.
    std::map<std::array<std::int64_t, 2>, std::size_t> sideEdge;
    for (std::size_t t = 0; t < sideTris_.size(); ++t) {
      const Tri& f = sideTris_[t];
      const Tri moved{top(f[0]), top(f[1]), top(f[2])};
      closure.push_back(moved);
      tris.nodes.insert(tris.nodes.end(), moved.begin(), moved.end());
      tris.entity.push_back(sideFace_[t]);
      for (int k = 0; k < 3; ++k) {
        std::array<std::int64_t, 2> e{f[static_cast<std::size_t>(k)],
                                      f[static_cast<std::size_t>((k + 1) % 3)]};
        std::sort(e.begin(), e.end());
        sideEdge[e] = t;
      }
    }
    for (const Tri& f : layerTris_)
      for (int k = 0; k < 3; ++k) {
        const std::int64_t a = f[static_cast<std::size_t>(k)];
        const std::int64_t b = f[static_cast<std::size_t>((k + 1) % 3)];
        std::array<std::int64_t, 2> e{a, b};
        std::sort(e.begin(), e.end());
        const auto it = sideEdge.find(e);
        if (it == sideEdge.end()) continue;
        // Outward like the side face's triangle there: the facet's edge a->b runs the other way
        // round the side triangle, so (b, a, a', b') faces the same way as the side face.
        std::array<std::int64_t, 4> q{b, a, top(a), top(b)};
        const Tri& s = sideTris_[it->second];
        const Vec ns = (at(out_, s[1]) - at(out_, s[0])).cross(at(out_, s[2]) - at(out_, s[0]));
        const Vec nq = (at(out_, q[1]) - at(out_, q[0])).cross(at(out_, q[3]) - at(out_, q[0]));
        if (nq.dot(ns) < 0.0) q = {a, b, top(b), top(a)};
        quads.nodes.insert(quads.nodes.end(), q.begin(), q.end());
        quads.entity.push_back(sideFace_[it->second]);
      }
    // Lines on the curve a node climbs: the first segment starts at the top node, and the
    // climb itself becomes a line of that curve.
    for (std::size_t e = 0; e < lines.count(); ++e)
      for (int k = 0; k < 2; ++k) {
        std::int64_t& v = lines.nodes[2 * e + static_cast<std::size_t>(k)];
        const auto it = wallIndex_.find(v);
        if (it != wallIndex_.end() && wall_[it->second].curve == lines.entity[e])
          v = topId[it->second];
      }
    for (std::size_t i = 0; i < wall_.size(); ++i)
      if (wall_[i].curve != 0) {
        lines.nodes.push_back(wall_[i].id);
        lines.nodes.push_back(topId[i]);
        lines.entity.push_back(wall_[i].curve);
      }
    record_.cells = prisms.count();
    record_.sideQuadrilaterals = quads.count();
    for (const WallNode& w : wall_) {
      if (w.stretch > 1.0) record_.lengthened[w.id] = w.stretch;
      if (w.stretch > 1.0 && w.sharp) record_.sharpColumns.insert(w.id);
    }

    ElementBlock tets = fillTetrahedra(out_, closure, fill, solid_);
    out_.blocks = {std::move(tets), std::move(prisms), std::move(tris)};
    if (quads.count() > 0) out_.blocks.push_back(std::move(quads));
    out_.blocks.push_back(std::move(lines));
    out_.checkConsistency();
    return std::move(out_);
  }
};

}  // namespace

Mesh growLayer3D(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p,
                 const LinearMeshOptions& fill, BoundaryLayerRecord& record) {
  return LayerGrower(volume, cad, p, record).run(fill);
}

}  // namespace homesh::layer_growth
