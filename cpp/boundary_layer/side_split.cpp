#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "boundary_layer/layer_splitter.hpp"
#include "core/error.hpp"

namespace homesh::layer_splitting {

std::optional<Frame> LayerSplitter::quadFrame(const std::int64_t* q) const {
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

std::optional<Frame> LayerSplitter::lineFrame(const std::int64_t* l) const {
  const auto it0 = topOf_.find(l[0]), it1 = topOf_.find(l[1]);
  if (it0 != topOf_.end() && it0->second == l[1]) return Frame{{l[0], l[0]}, 1, 0, true};
  if (it1 != topOf_.end() && it1->second == l[0]) return Frame{{l[1], l[1]}, 1, 0, false};
  return std::nullopt;
}

ElementBlock LayerSplitter::splitSides(const ElementBlock& b) {
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
        const std::int64_t t0 = topOf_.at(frame->wall[0]), t1 = topOf_.at(frame->wall[1]);
        const NodeKey key = makeKey(
            {{{t0, quad ? p_ - along : p_}, {t1, quad ? along : 0}, {kNone, 0}, {kNone, 0}}},
            level);
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

void LayerSplitter::project(std::int64_t id, int dim, int entity, std::int64_t hint,
                            std::int64_t wall) {
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
  if (height > 0.0) stats_.maxProjection = std::max(stats_.maxProjection, (p - x).norm() / height);
  ++stats_.projected;
  for (int d = 0; d < 3; ++d) out_.xyz[3 * i + static_cast<std::size_t>(d)] = p(d);
  out_.nodeCadDim[i] = static_cast<std::uint8_t>(dim);
  out_.nodeCadIndex[i] = entity;
  out_.nodeCadParam[2 * i] = u;
  out_.nodeCadParam[2 * i + 1] = v;
}

}  // namespace homesh::layer_splitting
