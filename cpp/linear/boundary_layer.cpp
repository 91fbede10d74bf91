#include "linear/boundary_layer.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/expression.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"
#include "linear/edge_split.hpp"

namespace homesh {

void BoundaryLayerParameters::validate() const {
  if (faces.empty())
    throw ParameterError("boundary layer: no faces given (--bl-faces, BndLayerSurfaces)");
  for (const int f : faces)
    if (f < 1)
      throw ParameterError("boundary-layer face " + std::to_string(f) +
                           " does not exist (faces are numbered from 1)");
  if (thickness.empty())
    throw ParameterError("boundary layer: no thickness given (--bl-thickness, BndLayerThickness)");
  Expression::parse(thickness, "boundary-layer thickness");
  checkParameter("layers", layers);
  checkParameter("progression", progression);
}

const char* layerReleaseName(LayerRelease release) {
  switch (release) {
    case LayerRelease::Parallel:
      return "parallel";
    case LayerRelease::Sides:
      return "parallel_and_sides";
    case LayerRelease::Free:
      return "free";
    case LayerRelease::None:
      break;
  }
  return "none";
}

std::vector<double> BoundaryLayerParameters::splitCoordinates() const {
  std::vector<double> z(static_cast<std::size_t>(layers) + 1, 0.0);
  double step = 1.0, total = 0.0;
  for (int k = 0; k < layers; ++k) {
    z[static_cast<std::size_t>(k) + 1] = z[static_cast<std::size_t>(k)] + step;
    total += step;
    step *= progression;
  }
  for (double& v : z) v /= total;
  z.back() = 1.0;
  return z;
}

std::vector<int> parseIndexList(const std::string& text, const std::string& what) {
  std::set<int> out;
  std::stringstream in(text);
  std::string item;
  const auto number = [&](std::string s) {
    s.erase(0, s.find_first_not_of(" \t"));
    s.erase(s.find_last_not_of(" \t") + 1);
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (s.empty() || used != s.size() || v < 1)
      throw ParameterError(what + " '" + text + "': '" + s +
                           "' is not a positive integer (give a list like 1,8 or 11-12)");
    return v;
  };
  while (std::getline(in, item, ',')) {
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) {
      out.insert(number(item));
      continue;
    }
    const int a = number(item.substr(0, dash)), b = number(item.substr(dash + 1));
    if (b < a || b - a > 100000) {
      std::string message = what;
      message.append(" '").append(text).append("': range '").append(item);
      throw ParameterError(message.append("' is empty or too long"));
    }
    for (int v = a; v <= b; ++v) out.insert(v);
  }
  if (out.empty()) throw ParameterError(what + " is empty");
  return {out.begin(), out.end()};
}

namespace {

using Tri = std::array<std::int64_t, 3>;
using Vec = Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

constexpr int kNormalSmoothing = 10;  // relaxation passes of the growth directions
constexpr double kVisibility = 0.2;   // a direction must see every facet around it this much
// A layer face and a face without a layer whose CAD normals at a common node are within 6
// degrees (|cos| above this) meet tangentially: the layer cannot climb the other face there.
constexpr double kTangentFaces = 0.9945;
constexpr int kMaxShrinkPasses = 40;      // 0.7^40 ~ 6e-7: a layer that thin is no layer
constexpr double kShrinkStep = 0.7;       // height factor of a node flagged in a pass
constexpr double kGrading = 1.25;         // neighbouring heights differ at most by this ratio
constexpr double kMinPrismCorner = 0.1;   // scaled Jacobian at every prism corner
constexpr double kRayReach = 2.5;         // thicknesses along the normal that must stay clear
constexpr double kMinSideTriangle = 0.2;  // a moved neighbour triangle keeps this share of shape
constexpr int kSideRings = 3;             // side-face nodes this many edges from the layer relax
constexpr int kSideRelaxation = 10;       // relaxation passes of those nodes
// 2D: a wall node where the normals of the two layer curves meeting there spread by more than
// 30 degrees (cosine below this) at a convex corner (a sharp trailing edge) gets a fan of
// columns instead of one along the bisector, each fan triangle at most kFanStep wide.
constexpr double kFanSpread = 0.866;
constexpr double kFanStep = 40.0 * 3.14159265358979323846 / 180.0;

Vec at(const Mesh& m, std::int64_t i) {
  return {m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]};
}

double triangleShape(const Vec& a, const Vec& b, const Vec& c) {
  const double area2 = (b - a).cross(c - a).norm();
  const double edges = (b - a).squaredNorm() + (c - b).squaredNorm() + (a - c).squaredNorm();
  return edges > 0.0 ? 2.0 * std::sqrt(3.0) * area2 / edges : 0.0;
}

// Whether segment p-q crosses triangle abc (Moller-Trumbore, the end points excluded).
bool segmentCrosses(const Vec& p, const Vec& q, const Vec& a, const Vec& b, const Vec& c) {
  const Vec d = q - p, e1 = b - a, e2 = c - a;
  const Vec h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::fabs(det) <= 1e-14 * e1.norm() * e2.norm() * d.norm()) return false;
  const double inv = 1.0 / det;
  const Vec s = p - a;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) return false;
  const Vec qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = inv * e2.dot(qv);
  return t > 1e-9 && t < 1.0;
}

// Scaled Jacobian at the six corners of the linear prism (wall a, b, c; tops A, B, C), smallest.
double prismCornerQuality(const std::array<Vec, 6>& v) {
  double worst = 1.0;
  for (std::size_t top = 0; top < 2; ++top) {
    const Vec& o = v[3 * top];
    const Vec dx = v[3 * top + 1] - o;
    const Vec dy = v[3 * top + 2] - o;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec dz = v[3 + k] - v[k];
      const double scale = dx.norm() * dy.norm() * dz.norm();
      worst = std::min(worst, scale > 0.0 ? dx.cross(dy).dot(dz) / scale : -1.0);
    }
  }
  return worst;
}

// "(x, y, z)" for messages.
std::string pointText(const Vec& x) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

// Shrinks the flagged wall nodes (Node: factor, full, neighbours) by kShrinkStep and grades the
// rest (no height more than kGrading times a neighbour's), re-placing every node with
// `placeAll`, until `offenders` (node index -> why) flags none. Returns the passes taken; throws
// MeshingError with `describe(node)` (where the layer is) after kMaxShrinkPasses.
template <class Node, class Offenders, class PlaceAll, class Describe>
int shrinkUntilClear(std::vector<Node>& nodes, Offenders offenders, PlaceAll placeAll,
                     Describe describe) {
  placeAll();
  for (int pass = 0;; ++pass) {
    const std::map<std::size_t, std::string> bad = offenders();
    if (bad.empty()) return pass;
    if (pass == kMaxShrinkPasses) {
      const Node& w = nodes[bad.begin()->first];
      throw MeshingError("the boundary layer on " + describe(w) + ": " + bad.begin()->second +
                         " even at " + formatNumber(w.factor) + " of the thickness");
    }
    for (const auto& [i, why] : bad) nodes[i].factor *= kShrinkStep;
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
    placeAll();
  }
}

// The record's macro heights, first-layer heights and shrink entries (per layer face or curve,
// `entity(node)`: the smallest factor, where, how many nodes) from the grown wall nodes.
template <class Node, class Entity>
void recordHeights(BoundaryLayerRecord& record, const BoundaryLayerParameters& p, const Mesh& mesh,
                   const std::vector<Node>& nodes, Entity entity) {
  record.parameters = p;
  record.wallNodes = nodes.size();
  record.thicknessMin = std::numeric_limits<double>::infinity();
  record.thicknessMax = 0.0;
  std::map<int, LayerShrink> shrunk;
  for (const Node& w : nodes) {
    const double h = (w.top - at(mesh, w.id)).norm();
    record.thicknessMin = std::min(record.thicknessMin, h);
    record.thicknessMax = std::max(record.thicknessMax, h);
    if (w.factor >= 0.999) continue;
    LayerShrink& s = shrunk[entity(w)];
    s.face = entity(w);
    ++s.nodes;
    if (s.nodes == 1 || w.factor < s.factor) {
      s.factor = w.factor;
      const Vec x = at(mesh, w.id);
      s.where = {x.x(), x.y(), x.z()};
    }
  }
  for (auto& [face, s] : shrunk) record.shrunk.push_back(s);
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
    shrink();
    return assemble(fill);
  }

 private:
  // How a wall node may move: freely, on one face without a layer, or on the curve where two
  // such faces meet.
  struct WallNode {
    std::int64_t id = 0;                  // node of out_
    std::vector<int> sideFaces;           // faces without a layer through the node
    int curve = 0;                        // with two side faces: their common curve
    int face = 0;                         // a layer face the node lies on (for the report)
    Vec d = Vec::Zero();                  // unit growth direction (into the solid)
    double full = 0.0, factor = 1.0;      // asked thickness, share of it grown
    Vec top = Vec::Zero();                // the top node's position
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
  // the nodes that climb it instead of folding.
  struct SideNode {
    std::int64_t id = 0;
    int face = 0;
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
    const int nf = cad_.numFaces();
    std::set<int> layer;
    for (const int f : p_.faces) {
      if (f > nf)
        throw ParameterError("boundary-layer face " + std::to_string(f) + " does not exist: " +
                             cad_.sourceName() + " has " + std::to_string(nf) + " faces");
      layer.insert(f);
    }
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
    std::set<int> seen;
    lines_.type = CellType::Line;
    for (const ElementBlock& b : volume.blocks) {
      if (b.type == CellType::Triangle) {
        for (std::size_t e = 0; e < b.count(); ++e) {
          const std::int64_t* t = b.element(e);
          const Tri tri{remap(t[0]), remap(t[1]), remap(t[2])};
          if (layer.count(b.entity[e]) != 0) {
            layerTris_.push_back(tri);
            layerFace_.push_back(b.entity[e]);
            seen.insert(b.entity[e]);
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
    for (const int f : layer)
      if (seen.count(f) == 0)
        throw ParameterError("boundary-layer face " + std::to_string(f) + " of " +
                             cad_.sourceName() +
                             " has no boundary triangles (not a face of the solid?)");
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

  // The side faces' inner nodes within kSideRings edges of a wall node that climbs them.
  void findSideNodes() {
    std::map<std::int64_t, std::set<std::int64_t>> adjacent;
    for (const Tri& t : sideTris_)
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          if (j != k)
            adjacent[t[static_cast<std::size_t>(k)]].insert(t[static_cast<std::size_t>(j)]);
    std::set<std::int64_t> front, reached;
    for (const WallNode& w : wall_)
      if (!w.sideFaces.empty()) front.insert(w.id);
    for (int ring = 0; ring < kSideRings; ++ring) {
      std::set<std::int64_t> next;
      for (const std::int64_t v : front)
        for (const std::int64_t n : adjacent[v]) {
          const auto i = static_cast<std::size_t>(n);
          if (out_.nodeCadDim[i] != 2 || wallIndex_.count(n) != 0 || !reached.insert(n).second)
            continue;
          next.insert(n);
        }
      front = std::move(next);
    }
    for (const std::int64_t n : reached) {
      SideNode s;
      s.id = n;
      s.face = out_.nodeCadIndex[static_cast<std::size_t>(n)];
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
  }

  void heights() {
    for (WallNode& w : wall_) {
      const Vec x = at(out_, w.id);
      w.full = thickness_(x.x(), x.y(), x.z());
      if (!(w.full > 0.0) || !std::isfinite(w.full))
        throw ParameterError("boundary-layer thickness '" + p_.thickness + "' is " +
                             formatNumber(w.full) + " at " + where(w) + " on Face" +
                             std::to_string(w.face) + ": it must be positive on every layer face");
    }
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
    const std::vector<Tri>& all = walls_.triangles;
    const std::vector<int>& allFace = walls_.faces;
    const std::vector<std::pair<Vec, Vec>>& boxes = walls_.boxes;
    for (std::size_t i = 0; i < wall_.size(); ++i) {
      const WallNode& w = wall_[i];
      const Vec p = at(out_, w.id);
      const Vec q = p + kRayReach * (w.top - p);
      const Vec lo = p.cwiseMin(q), hi = p.cwiseMax(q);
      for (std::size_t t = 0; t < all.size(); ++t) {
        if ((boxes[t].first.array() > hi.array()).any() ||
            (boxes[t].second.array() < lo.array()).any())
          continue;
        const Tri& f = all[t];
        if (std::find(f.begin(), f.end(), w.id) != f.end()) continue;
        if (std::find(w.sideFaces.begin(), w.sideFaces.end(), allFace[t]) != w.sideFaces.end())
          continue;
        if (segmentCrosses(p, q, at(out_, f[0]), at(out_, f[1]), at(out_, f[2]))) {
          bad.emplace(i, "the layer would reach Face" + std::to_string(allFace[t]));
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
          return "Face" + std::to_string(w.face) + " cannot be grown at " + where(w);
        });
  }

  Mesh assemble(const LinearMeshOptions& fill) {
    recordHeights(record_, p_, out_, wall_, [](const WallNode& w) { return w.face; });
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

    ElementBlock tets = fillTetrahedra(out_, closure, fill, solid_);
    out_.blocks = {std::move(tets), std::move(prisms), std::move(tris)};
    if (quads.count() > 0) out_.blocks.push_back(std::move(quads));
    out_.blocks.push_back(std::move(lines));
    out_.checkConsistency();
    return std::move(out_);
  }
};

// Node `id`'s parameter on CAD curve `curve`: its own where it lies on that curve, the
// vertex's on the curve where it is a CAD vertex (the end nearest `near` on a closed curve),
// else its projection's.
double parameterOnCurve(const Mesh& mesh, const CadModel& cad, int curve, std::int64_t id,
                        std::optional<double> near = std::nullopt) {
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
    for (std::size_t s = 0; s < all.size(); ++s) {
      if (all[s][0] == w.id || all[s][1] == w.id) continue;
      if (s >= wallSegs_.size() && sideCurve_[s - wallSegs_.size()] == w.sideCurve) continue;
      const Vec a = at(out_, all[s][0]), b = at(out_, all[s][1]);
      // p + u (q - p) = a + v (b - a), in the plane.
      const Vec r = q - p, e = b - a;
      const double den = r.cross(e).dot(normal_);
      if (std::fabs(den) <= 1e-14 * r.norm() * e.norm()) continue;
      const double u = (a - p).cross(e).dot(normal_) / den;
      const double v = (a - p).cross(r).dot(normal_) / den;
      if (u > 1e-9 && u < 1.0 && v >= 0.0 && v <= 1.0)
        return s < wallSegs_.size() ? wallCurve_[s] : sideCurve_[s - wallSegs_.size()];
    }
    return std::nullopt;
  }

  void shrink() {
    record_.shrinkPasses = shrinkUntilClear(
        wall_, [this] { return offenders(); },
        [this] {
          for (WallNode& w : wall_) place(w);
        },
        [this](const WallNode& w) {
          return "Edge" + std::to_string(w.curve) + " cannot be grown at " + where(w);
        });
  }

  Mesh assemble(const LinearMeshOptions& fill) {
    recordHeights(record_, p_, out_, wall_, [](const WallNode& w) { return w.curve; });
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

// 2D: a wall segment on a layer curve whose CAD tangent turns by more than this between its
// ends (30 degrees, the turn at which a corner counts as sharp) is halved before the layer
// grows, up to kWallSplitPasses times. A cell whose wall turns further has a top arc that
// bulges far beyond its straight linear top into the triangles outside: T106's trailing edge
// (radius 0.0047 under a layer 0.053 thick) had cells turning 85 and 110 degrees and left
// triangles there invalid with the layer fixed (the release that followed cost the first layer
// 12 % of its height). Cells around such a tip stay slender whatever the split, min J / max J
// about R / (R + T) (0.08 there): the split does not make that worse.
constexpr double kMaxWallTurn = 0.8660254037844386;  // cosine of 30 degrees
constexpr int kWallSplitPasses = 3;

// The parameter between t0 and t1 where the curve's tangent has turned half way from `a` (its
// tangent at t0, towards t1) to `b` (at t1, away from t0): bisection on the difference of the
// two angles, which grows along a curve that turns one way.
double halfTurn(const CadModel& cad, int curve, double t0, double t1, const Vec& a, const Vec& b) {
  double lo = t0, hi = t1;
  for (int i = 0; i < 40; ++i) {
    const double m = 0.5 * (lo + hi);
    const Vec d = cad.evaluateCurve(curve, m).d1;
    const Vec tm = (t1 > t0 ? d : Vec(-d)).normalized();
    const double fromA = std::atan2(a.cross(tm).norm(), a.dot(tm));
    const double toB = std::atan2(tm.cross(b).norm(), tm.dot(b));
    (fromA < toB ? lo : hi) = m;
  }
  return 0.5 * (lo + hi);
}

// Halves the wall segments of layer curves along which the curve turns too much for one cell
// (also the NACA 0012's nose, radius 0.0158 against segments 0.1 long: the two cells' order-4
// walls met there at more than 30 degrees, and the first layer's height along their normals
// was 5.8 % off). The new node is where the curve has turned half way: on a spline whose
// curvature peaks at one end of a segment (T106's shoulders), the mean parameter left one half
// still turning most of the way (worst element at order 4 0.054 against 0.084).
// Returns the halvings.
int splitTightWallSegments(Mesh& planar, const CadModel& cad, const BoundaryLayerParameters& p) {
  const std::set<int> layer(p.faces.begin(), p.faces.end());
  int made = 0;
  for (int pass = 0; pass < kWallSplitPasses; ++pass) {
    std::vector<std::pair<MeshEdge, SplitNode>> splits;
    for (const ElementBlock& b : planar.blocks) {
      if (b.type != CellType::Line) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const int curve = b.entity[e];
        if (layer.count(curve) == 0) continue;
        const std::int64_t* l = b.element(e);
        double t[2];
        t[0] = parameterOnCurve(planar, cad, curve, l[0]);
        t[1] = parameterOnCurve(planar, cad, curve, l[1], t[0]);
        if (t[0] == t[1]) continue;
        const Vec a = curveTangent(cad, curve, t[0], t[1]);
        const Vec b1 = -curveTangent(cad, curve, t[1], t[0]);
        if (a.dot(b1) >= kMaxWallTurn) continue;
        const double m = halfTurn(cad, curve, t[0], t[1], a, b1);
        SplitNode node;
        node.point = cad.evaluateCurve(curve, m).point;
        node.cadDim = 1;
        node.cadIndex = curve;
        node.param0 = m;
        splits.emplace_back(meshEdge(l[0], l[1]), node);
      }
    }
    int now = 0;
    for (const auto& [edge, node] : splits) now += splitEdge(planar, edge, node) ? 1 : 0;
    made += now;
    if (now == 0) break;
  }
  return made;
}

}  // namespace

Mesh growBoundaryLayer(const Mesh& volume, const CadModel& cad,
                       const BoundaryLayerParameters& parameters, const LinearMeshOptions& fill,
                       BoundaryLayerRecord& record) {
  parameters.validate();
  const auto start = std::chrono::steady_clock::now();
  record = BoundaryLayerRecord();
  Mesh mesh;
  if (volume.dim == 2) {
    Mesh planar = volume;
    record.wallSplits = static_cast<std::size_t>(splitTightWallSegments(planar, cad, parameters));
    mesh = LayerGrower2D(planar, cad, parameters, record).run(fill);
  } else {
    mesh = LayerGrower(volume, cad, parameters, record).run(fill);
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

}  // namespace homesh
