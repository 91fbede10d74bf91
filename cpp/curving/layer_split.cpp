#include "curving/layer_split.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include "core/error.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace {

constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();

// A node of the split layer: up to three wall vertices with integer weights (summing to the
// order P) and the level across the layer, 0 (wall) .. n P (top).
using NodeKey = std::array<std::int64_t, 7>;

NodeKey makeKey(std::array<std::pair<std::int64_t, int>, 3> w, std::int64_t level) {
  for (auto& [id, weight] : w)
    if (weight == 0) id = kNone;
  std::sort(w.begin(), w.end());
  NodeKey k{};
  for (std::size_t i = 0; i < 3; ++i) {
    k[2 * i] = w[i].first;
    k[2 * i + 1] = w[i].first == kNone ? 0 : w[i].second;
  }
  k[6] = level;
  return k;
}

std::map<LatticePoint, int> latticeIndex(const ReferenceElement& ref) {
  std::map<LatticePoint, int> index;
  for (int r = 0; r < ref.numNodes(); ++r) index[ref.lattice()[static_cast<std::size_t>(r)]] = r;
  return index;
}

class LayerSplitter {
 public:
  LayerSplitter(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                LayerSplitStats& stats)
      : macro_(macro),
        z_(z),
        cad_(cad),
        stats_(stats),
        p_(macro.order),
        n_(static_cast<int>(z.size()) - 1) {
    if (n_ < 1) throw ParameterError("a layer split needs at least one layer");
    out_ = macro;
    out_.blocks.clear();
  }

  Mesh run() {
    for (const ElementBlock& b : macro_.blocks)
      if (b.type == CellType::Prism) pairWallAndTop(b);
    for (const ElementBlock& b : macro_.blocks) {
      if (b.type == CellType::Prism)
        out_.blocks.push_back(splitPrisms(b));
      else if (b.type != CellType::Quadrilateral && b.type != CellType::Line)
        out_.blocks.push_back(b);
    }
    // Faces, then curves: a node on both ends on its curve.
    for (const ElementBlock& b : macro_.blocks)
      if (b.type == CellType::Quadrilateral) out_.blocks.push_back(splitSides(b));
    for (const ElementBlock& b : macro_.blocks)
      if (b.type == CellType::Line) out_.blocks.push_back(splitSides(b));
    compactNodes(out_);
    out_.checkConsistency();
    return std::move(out_);
  }

 private:
  const Mesh& macro_;
  const std::vector<double>& z_;
  const CadModel* cad_;
  LayerSplitStats& stats_;
  int p_, n_;
  Mesh out_;
  std::map<std::int64_t, std::int64_t> topOf_;  // wall vertex -> top vertex
  std::map<NodeKey, std::int64_t> nodes_;
  std::map<std::int64_t, double> height_;  // wall vertex -> macro layer height there
  std::vector<char> projected_;

  void pairWallAndTop(const ElementBlock& b) {
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < 3; ++k) {
        const auto [it, fresh] = topOf_.emplace(v[k], v[k + 3]);
        if (!fresh && it->second != v[k + 3])
          throw MeshingError("boundary-layer split: wall node " + std::to_string(v[k]) +
                             " has two top nodes");
        const double h =
            (Eigen::Vector3d(&macro_.xyz[3 * v[k + 3]]) - Eigen::Vector3d(&macro_.xyz[3 * v[k]]))
                .norm();
        height_[v[k]] = h;
      }
    }
  }

  double zAt(int k, int a) const {
    const auto kk = static_cast<std::size_t>(k);
    return z_[kk] + (z_[kk + 1] - z_[kk]) * a / p_;
  }

  ElementBlock splitPrisms(const ElementBlock& b) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Prism, p_);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    const int nn = ref.numNodes();
    ElementBlock out;
    out.type = CellType::Prism;
    out.order = p_;
    out.nodes.resize(b.count() * static_cast<std::size_t>(n_) * static_cast<std::size_t>(nn));
    out.entity.resize(b.count() * static_cast<std::size_t>(n_));
    Eigen::MatrixXd x(nn, 3);
    for (int k = 0; k < n_; ++k) {
      // Basis of the macro prism at the k-th thin prism's nodes.
      Eigen::MatrixXd points(nn, 3);
      for (int r = 0; r < nn; ++r) {
        const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
        points.row(r) << double(c[0]) / p_, double(c[1]) / p_, zAt(k, c[2]);
      }
      const Eigen::MatrixXd values = ref.valuesAt(points);
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        bool gathered = false;
        const std::size_t sub = e * static_cast<std::size_t>(n_) + static_cast<std::size_t>(k);
        out.entity[sub] = b.entity[e];
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const std::int64_t level = std::int64_t(k) * p_ + c[2];
          const NodeKey key =
              makeKey({{{v[0], p_ - c[0] - c[1]}, {v[1], c[0]}, {v[2], c[1]}}}, level);
          std::int64_t id = 0;
          if (level == 0 || level == std::int64_t(n_) * p_) {
            id = v[index.at({c[0], c[1], level == 0 ? 0 : p_})];
            nodes_.emplace(key, id);
          } else {
            const auto it = nodes_.find(key);
            if (it != nodes_.end()) {
              id = it->second;
            } else {
              if (!gathered) {
                for (int i = 0; i < nn; ++i)
                  for (int d = 0; d < 3; ++d) x(i, d) = macro_.xyz[3 * v[i] + d];
                gathered = true;
              }
              const Eigen::RowVector3d p = values.row(r) * x;
              const double xyz[3] = {p(0), p(1), p(2)};
              id = out_.addNode(xyz, 3, b.entity[e], std::nan(""), std::nan(""));
              nodes_.emplace(key, id);
            }
          }
          out.nodes[sub * static_cast<std::size_t>(nn) + static_cast<std::size_t>(r)] = id;
        }
      }
    }
    stats_.prisms += b.count();
    return out;
  }

  // A side quadrilateral's or climbing line's frame: which corner is the wall side's start,
  // the lattice axis across the layer and whether it points away from the wall.
  struct Frame {
    std::array<std::int64_t, 2> wall{};  // wall vertices at along = 0 and along = P
    int alongAxis = 0, acrossAxis = 1;
    bool away = true;
  };

  std::optional<Frame> quadFrame(const std::int64_t* q) const {
    const auto top = [&](std::int64_t a, std::int64_t t) {
      const auto it = topOf_.find(a);
      return it != topOf_.end() && it->second == t;
    };
    if (top(q[0], q[3]) && top(q[1], q[2])) return Frame{{q[0], q[1]}, 0, 1, true};
    if (top(q[3], q[0]) && top(q[2], q[1])) return Frame{{q[3], q[2]}, 0, 1, false};
    if (top(q[0], q[1]) && top(q[3], q[2])) return Frame{{q[0], q[3]}, 1, 0, true};
    if (top(q[1], q[0]) && top(q[2], q[3])) return Frame{{q[1], q[2]}, 1, 0, false};
    return std::nullopt;
  }

  std::optional<Frame> lineFrame(const std::int64_t* l) const {
    const auto it0 = topOf_.find(l[0]), it1 = topOf_.find(l[1]);
    if (it0 != topOf_.end() && it0->second == l[1]) return Frame{{l[0], l[0]}, 1, 0, true};
    if (it1 != topOf_.end() && it1->second == l[0]) return Frame{{l[1], l[1]}, 1, 0, false};
    return std::nullopt;
  }

  ElementBlock splitSides(const ElementBlock& b) {
    const bool quad = b.type == CellType::Quadrilateral;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    const int nn = ref.numNodes();
    ElementBlock out;
    out.type = b.type;
    out.order = p_;
    projected_.resize(out_.numNodes(), 0);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      const std::optional<Frame> frame = quad ? quadFrame(v) : lineFrame(v);
      if (!frame) {  // not a side of the layer: kept
        out.nodes.insert(out.nodes.end(), v, v + nn);
        out.entity.push_back(b.entity[e]);
        continue;
      }
      ++(quad ? stats_.quadrilaterals : stats_.lines);
      for (int k = 0; k < n_; ++k) {
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const int along = quad ? c[static_cast<std::size_t>(frame->alongAxis)] : 0;
          const int acrossLocal = c[static_cast<std::size_t>(frame->acrossAxis)];
          const int a = frame->away ? acrossLocal : p_ - acrossLocal;
          const std::int64_t level = std::int64_t(k) * p_ + a;
          const NodeKey key =
              quad ? makeKey({{{frame->wall[0], p_ - along}, {frame->wall[1], along}, {kNone, 0}}},
                             level)
                   : makeKey({{{frame->wall[0], p_}, {kNone, 0}, {kNone, 0}}}, level);
          const auto it = nodes_.find(key);
          if (it == nodes_.end())
            throw MeshingError(std::string("boundary-layer split: a side ") +
                               (quad ? "quadrilateral" : "line") + " of the layer on " +
                               (quad ? "Face" : "Edge") + std::to_string(b.entity[e]) +
                               " is not a side of its prisms");
          out.nodes.push_back(it->second);
          if (level != 0 && level != std::int64_t(n_) * p_) {
            // The macro side's node nearest in level gives the projection's start.
            LatticePoint m{0, 0, 0};
            const int macroAcross = static_cast<int>(std::lround(zAt(k, a) * p_));
            m[static_cast<std::size_t>(frame->acrossAxis)] =
                frame->away ? macroAcross : p_ - macroAcross;
            if (quad) m[static_cast<std::size_t>(frame->alongAxis)] = along;
            project(it->second, quad ? 2 : 1, b.entity[e], v[index.at(m)], frame->wall[0]);
          }
        }
        out.entity.push_back(b.entity[e]);
      }
    }
    return out;
  }

  void project(std::int64_t id, int dim, int entity, std::int64_t hint, std::int64_t wall) {
    auto i = static_cast<std::size_t>(id);
    if (cad_ == nullptr || (projected_[i] != 0 && dim == 2)) return;
    projected_[i] = 1;
    const Eigen::Vector3d x(&out_.xyz[3 * i]);
    const auto h = static_cast<std::size_t>(hint);
    const bool same = macro_.nodeCadDim[h] == dim && macro_.nodeCadIndex[h] == entity;
    Eigen::Vector3d p;
    double u = 0.0, v = std::nan("");
    if (dim == 2) {
      std::optional<std::array<double, 2>> guess;
      if (same && std::isfinite(macro_.nodeCadParam[2 * h]))
        guess = std::array<double, 2>{macro_.nodeCadParam[2 * h], macro_.nodeCadParam[2 * h + 1]};
      const SurfaceProjection proj = cad_->projectOnSurface(entity, x, guess);
      p = proj.point;
      u = proj.u;
      v = proj.v;
    } else {
      std::optional<double> guess;
      if (same && std::isfinite(macro_.nodeCadParam[2 * h])) guess = macro_.nodeCadParam[2 * h];
      const CurveProjection proj = cad_->projectOnCurve(entity, x, guess);
      p = proj.point;
      u = proj.t;
    }
    const double height = height_.count(wall) != 0 ? height_.at(wall) : 0.0;
    if (height > 0.0)
      stats_.maxProjection = std::max(stats_.maxProjection, (p - x).norm() / height);
    ++stats_.projected;
    for (int d = 0; d < 3; ++d) out_.xyz[3 * i + static_cast<std::size_t>(d)] = p(d);
    out_.nodeCadDim[i] = static_cast<std::uint8_t>(dim);
    out_.nodeCadIndex[i] = entity;
    out_.nodeCadParam[2 * i] = u;
    out_.nodeCadParam[2 * i + 1] = v;
  }
};

}  // namespace

void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops) {
  std::vector<char> done(mesh.numNodes(), 0);
  const auto setOnCad = [&](std::size_t id, const Eigen::Vector3d& x) {
    if (mesh.nodeCadDim[id] == 2 && cad != nullptr) {
      std::optional<std::array<double, 2>> guess;
      if (std::isfinite(mesh.nodeCadParam[2 * id]) && std::isfinite(mesh.nodeCadParam[2 * id + 1]))
        guess = std::array<double, 2>{mesh.nodeCadParam[2 * id], mesh.nodeCadParam[2 * id + 1]};
      const SurfaceProjection proj = cad->projectOnSurface(mesh.nodeCadIndex[id], x, guess);
      for (std::size_t d = 0; d < 3; ++d)
        mesh.xyz[3 * id + d] = proj.point(static_cast<Eigen::Index>(d));
      mesh.nodeCadParam[2 * id] = proj.u;
      mesh.nodeCadParam[2 * id + 1] = proj.v;
      return;
    }
    for (std::size_t d = 0; d < 3; ++d) mesh.xyz[3 * id + d] = x(static_cast<Eigen::Index>(d));
  };
  // Nodes this pass may place: inside the solid, or on a face (projected back onto it).
  const auto movable = [&](std::size_t id) {
    return mesh.nodeCadDim[id] == 3 || (mesh.nodeCadDim[id] == 2 && cad != nullptr);
  };
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (int pass = tops ? 0 : 1; pass < 2; ++pass)  // tops first: the inner levels blend to them
    for (const ElementBlock& b : mesh.blocks) {
      if (b.type != CellType::Prism || b.order < 2) continue;
      const int p = b.order;
      const ReferenceElement& ref = ReferenceElement::get(CellType::Prism, p);
      const std::map<LatticePoint, int> index = latticeIndex(ref);
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        const auto x = [&](std::int64_t n) {
          return Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(n)]);
        };
        for (int r = 0; r < ref.numNodes(); ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const auto id = static_cast<std::size_t>(v[r]);
          const bool vertex =
              (c[0] == 0 || c[0] == p) && (c[1] == 0 || c[1] == p) && c[0] + c[1] <= p;
          if (c[2] == 0 || !movable(id) || done[id] != 0 || (pass == 0) != (c[2] == p)) continue;
          if (pass == 0 && vertex) continue;
          done[id] = 1;
          const std::int64_t w = v[index.at({c[0], c[1], 0})];
          if (pass == 0) {
            // The top is the wall offset along the wall's own normal by the height interpolated
            // from the vertices: parallel to the curved wall at every node.
            const double xi[3] = {double(c[0]) / p, double(c[1]) / p, 0.0};
            ref.evaluate(xi, values, gradients);
            Eigen::Vector3d du = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
            for (int i = 0; i < ref.numNodes(); ++i) {
              du += gradients(i, 0) * x(v[i]);
              dv += gradients(i, 1) * x(v[i]);
            }
            const double l[3] = {double(p - c[0] - c[1]) / p, double(c[0]) / p, double(c[1]) / p};
            Eigen::Vector3d rise = Eigen::Vector3d::Zero();
            double h = 0.0;
            for (int k = 0; k < 3; ++k) {
              rise += l[k] * (x(v[k + 3]) - x(v[k]));
              h += l[k] * (x(v[k + 3]) - x(v[k])).norm();
            }
            Eigen::Vector3d n = du.cross(dv);
            if (!(n.norm() > 0.0)) continue;
            n.normalize();
            if (n.dot(rise) < 0.0) n = -n;
            setOnCad(id, x(w) + h * n);
            continue;
          }
          const std::int64_t t = v[index.at({c[0], c[1], p})];
          const double s = double(c[2]) / p;
          setOnCad(id, (1.0 - s) * x(w) + s * x(t));
        }
      }
    }
}

Mesh splitBoundaryLayer(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                        LayerSplitStats* stats) {
  LayerSplitStats local;
  return LayerSplitter(macro, z, cad, stats != nullptr ? *stats : local).run();
}

}  // namespace homesh
